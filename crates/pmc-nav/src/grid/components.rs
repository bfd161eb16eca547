//! Components: the nodes joined by steps, labelled per tile by a union-find over the steps inside
//! it, then joined across tile borders by a union-find over (tile, local component) pairs along
//! the abstract graph's links (the border steps, each pair of pairs once).

use super::{BorderStep, NavGrid, NodeId};
use crate::columns::Neighbours;
use pmc_geometry::glam::DVec3;

/// A union-find over `0..n`.
struct UnionFind(Vec<u32>);

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind((0..n as u32).collect())
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    /// Joins two sets; the smaller root stays root.
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }

    /// Dense labels in order of each set's first member, and the sets' sizes.
    fn labels(&mut self) -> (Vec<u32>, Vec<u32>) {
        let n = self.0.len();
        let mut root_label = vec![u32::MAX; n];
        let mut labels = Vec::with_capacity(n);
        let mut sizes = Vec::new();
        for x in 0..n as u32 {
            let r = self.find(x) as usize;
            if root_label[r] == u32::MAX {
                root_label[r] = sizes.len() as u32;
                sizes.push(0);
            }
            labels.push(root_label[r]);
        }
        for l in &labels {
            sizes[*l as usize] += 1;
        }
        (labels, sizes)
    }
}

impl NavGrid {
    /// The tiles that own a neighbour of one of tile `t`'s columns (`t` excluded).
    pub(super) fn neighbour_tiles(&self, t: usize) -> Vec<usize> {
        let mut out = Vec::new();
        for c in self.tiles[t].columns.iter().filter(|c| self.on_tile_edge(t, **c)) {
            for q in self.columns.neighbours(*c).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u != t && !out.contains(&u) {
                    out.push(u);
                }
            }
        }
        out
    }

    /// The components of tile `t` among the steps that stay inside it: each node's label, each
    /// component's size, and each component's mean surface point (the abstract graph's nodes).
    pub(super) fn inner_components(&self, t: usize) -> (Vec<u32>, Vec<u32>, Vec<DVec3>) {
        let tile = &self.tiles[t];
        let dirs: Vec<DVec3> = tile.columns.iter().map(|c| self.columns.direction(*c)).collect();
        let mut uf = UnionFind::new(tile.nodes.len());
        let side = (self.columns.face_tiles() + 1) as u32;
        for (lc, column) in tile.columns.iter().enumerate() {
            let a = self.view(*column);
            // Inside the tile a column's neighbours are the next ones along the face's rows and
            // columns (the index is `face (N + 1)^2 + j (N + 1) + i`).
            let neighbours = if self.on_tile_edge(t, *column) {
                self.columns.neighbours(*column)
            } else {
                Neighbours::of([column + 1, column - 1, column + side, column - side])
            };
            for q in neighbours.iter() {
                // Each pair of columns once: the steps read the same from either end, but not
                // when the agent's climbs and drops differ, so both ways are tried from the
                // lower index.
                let Ok(lq) = tile.columns.binary_search(q) else {
                    continue;
                };
                if lq < lc {
                    continue;
                }
                let b = self.view(*q);
                let (from, to) = (
                    tile.starts[lc]..tile.starts[lc + 1],
                    tile.starts[lq]..tile.starts[lq + 1],
                );
                for i in from {
                    let ni = tile.nodes[i as usize];
                    for j in to.clone() {
                        let nj = tile.nodes[j as usize];
                        if self.rules.step(a, dirs[lc], ni, b, dirs[lq], nj).is_some()
                            || self.rules.step(b, dirs[lq], nj, a, dirs[lc], ni).is_some()
                        {
                            uf.union(i, j);
                        }
                    }
                }
            }
        }
        let (local, sizes) = uf.labels();
        let mut sums = vec![DVec3::ZERO; sizes.len()];
        for (lc, dir) in dirs.iter().enumerate() {
            for i in tile.starts[lc]..tile.starts[lc + 1] {
                sums[local[i as usize] as usize] += *dir * tile.nodes[i as usize].radius;
            }
        }
        let points = sums
            .iter()
            .zip(&sizes)
            .map(|(s, n)| *s / f64::from((*n).max(1)))
            .collect();
        (local, sizes, points)
    }

    /// The steps from tile `t`'s nodes into the other tiles `u` for which `into(u)`: (local
    /// node, tile, local node there).
    pub(super) fn border_steps(&self, t: usize, into: impl Fn(usize) -> bool) -> Vec<BorderStep> {
        let tile = &self.tiles[t];
        let mut out = Vec::new();
        for (lc, column) in tile.columns.iter().enumerate() {
            if !self.on_tile_edge(t, *column) {
                continue;
            }
            for q in self.columns.neighbours(*column).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u == t || !into(u) {
                    continue;
                }
                for i in tile.starts[lc]..tile.starts[lc + 1] {
                    for s in self.steps_into(*column, tile.nodes[i as usize], *q) {
                        out.push((i, u as u32, s.to.0 - self.tile_base[u]));
                    }
                }
            }
        }
        out
    }

    /// Joins the tiles' local components along the border steps into the grid's components,
    /// labelled in order of their first node.
    pub(super) fn merge_components(&mut self) {
        let mut pair_base = Vec::with_capacity(self.tiles.len() + 1);
        let mut pairs = 0u32;
        for t in &self.tiles {
            pair_base.push(pairs);
            pairs += t.local_sizes.len() as u32;
        }
        pair_base.push(pairs);
        let mut uf = UnionFind::new(pairs as usize);
        // The links are the border steps, each pair of pairs once.
        for (t, tile) in self.tiles.iter().enumerate() {
            for (from, u, to) in &tile.links {
                uf.union(pair_base[t] + from, pair_base[*u as usize] + to);
            }
        }
        // Pairs are numbered in node order (tiles in order, local components by first node), so
        // labelling pairs in order labels components by their first node.
        let (labels, _) = uf.labels();
        let mut sizes = vec![0u32; labels.iter().max().map_or(0, |m| *m as usize + 1)];
        for (t, tile) in self.tiles.iter().enumerate() {
            for (lc, size) in tile.local_sizes.iter().enumerate() {
                sizes[labels[pair_base[t] as usize + lc] as usize] += size;
            }
        }
        self.pair_base = pair_base;
        self.pair_label = labels;
        self.component_sizes = sizes;
    }

    /// The component of node `id`.
    pub fn component(&self, id: NodeId) -> Option<u32> {
        if id.0 as usize >= self.node_count() {
            return None;
        }
        let t = self.tile_base.partition_point(|b| *b <= id.0) - 1;
        let local = self.tiles[t].local[(id.0 - self.tile_base[t]) as usize];
        self.pair_label.get((self.pair_base[t] + local) as usize).copied()
    }

    /// Node count of each component, by label.
    pub fn component_sizes(&self) -> &[u32] {
        &self.component_sizes
    }
}
