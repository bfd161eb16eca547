//! Components: the nodes joined by steps, labelled per tile by a union-find over the steps inside
//! it, then joined across tile borders by a union-find over (tile, local component) pairs.

use super::{BorderStep, NavGrid, NodeId};

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
        for c in &self.tiles[t].columns {
            for q in self.columns.neighbours(*c).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u != t && !out.contains(&u) {
                    out.push(u);
                }
            }
        }
        out
    }

    /// The components of tile `t` among the steps that stay inside it.
    pub(super) fn inner_components(&self, t: usize) -> (Vec<u32>, Vec<u32>) {
        let tile = &self.tiles[t];
        let mut uf = UnionFind::new(tile.nodes.len());
        let base = self.tile_base[t];
        for (lc, column) in tile.columns.iter().enumerate() {
            for q in self.columns.neighbours(*column).iter() {
                if tile.columns.binary_search(q).is_err() {
                    continue;
                }
                for i in tile.starts[lc]..tile.starts[lc + 1] {
                    for s in self.steps_into(*column, tile.nodes[i as usize], *q) {
                        uf.union(i, s.to.0 - base);
                    }
                }
            }
        }
        uf.labels()
    }

    /// The steps from tile `t`'s nodes into other tiles: (local node, tile, local node there).
    pub(super) fn border_steps(&self, t: usize) -> Vec<BorderStep> {
        let tile = &self.tiles[t];
        let mut out = Vec::new();
        for (lc, column) in tile.columns.iter().enumerate() {
            for q in self.columns.neighbours(*column).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u == t {
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
        for (t, tile) in self.tiles.iter().enumerate() {
            for (from, u, to) in &tile.border {
                let a = pair_base[t] + tile.local[*from as usize];
                let b = pair_base[*u as usize] + self.tiles[*u as usize].local[*to as usize];
                uf.union(a, b);
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
