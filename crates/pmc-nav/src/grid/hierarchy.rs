//! The abstract graph of the hierarchical search ([`crate::find_path_hierarchical`]): one node
//! per (tile, local component) pair, placed at the mean surface point of the component's nodes,
//! and a directed link from a pair to another wherever a step leaves the first's tile from one
//! of its nodes to a node of the second. Kept with the tiles: a rebuild finds the pairs of the
//! rebuilt tiles and the links of them and of their neighbours again.
//!
//! Every walk of the grid maps onto a walk of pairs (a step inside a tile stays in its local
//! component; a step across a border is a link), so when no pair walk joins two nodes' pairs no
//! walk joins the nodes. The converse does not hold (a local component may be crossed only one
//! way when the agent's drops are deeper than its climbs), which the search handles by falling
//! back to the exact search.

use super::{BorderStep, Link, NavGrid, NodeId};
use pmc_geometry::glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// An open entry of the abstract search: smallest `f` first.
#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    pair: u32,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other.f.total_cmp(&self.f).then(other.pair.cmp(&self.pair))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl NavGrid {
    /// The links out of tile `t` from its border steps `border`: (local component, tile, local
    /// component there), sorted, each once.
    pub(super) fn links(&self, t: usize, border: &[BorderStep]) -> Vec<Link> {
        let tile = &self.tiles[t];
        let mut out: Vec<Link> = border
            .iter()
            .map(|(from, u, to)| {
                (
                    tile.local[*from as usize],
                    *u,
                    self.tiles[*u as usize].local[*to as usize],
                )
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The (tile, local component) pair of node `id`, as a global pair index, and its tile.
    pub(crate) fn pair_of(&self, id: NodeId) -> Option<(u32, usize)> {
        if id.0 as usize >= self.node_count() {
            return None;
        }
        let t = self.tile_of_node(id);
        Some((
            self.pair_base[t] + self.tiles[t].local[(id.0 - self.tile_base[t]) as usize],
            t,
        ))
    }

    /// The tile index of node `id` (which must be a node of the grid).
    #[inline]
    pub(crate) fn tile_of_node(&self, id: NodeId) -> usize {
        self.tile_base.partition_point(|b| *b <= id.0) - 1
    }

    /// Number of tiles.
    pub(crate) fn tile_count(&self) -> usize {
        self.tiles.len()
    }

    /// The id of tile `t`'s first node.
    #[inline]
    pub(crate) fn tile_first_node(&self, t: usize) -> u32 {
        self.tile_base[t]
    }

    /// The number of tile `t`'s nodes.
    pub(crate) fn tile_node_count(&self, t: usize) -> u32 {
        self.tile_base[t + 1] - self.tile_base[t]
    }

    /// The tiles a link leaves tile `t` for.
    pub(crate) fn linked_tiles(&self, t: usize) -> impl Iterator<Item = usize> + '_ {
        self.tiles[t].links.iter().map(|(_, u, _)| *u as usize)
    }

    /// The tile of a global pair index.
    fn pair_tile(&self, pair: u32) -> usize {
        self.pair_base.partition_point(|b| *b <= pair) - 1
    }

    /// The point of a global pair index.
    fn pair_point(&self, pair: u32) -> DVec3 {
        let t = self.pair_tile(pair);
        self.tiles[t].local_points[(pair - self.pair_base[t]) as usize]
    }

    /// The tiles of the shortest walk of pairs from pair `from` to pair `to` (A*: each link costs
    /// the distance between its pairs' points, the heuristic is the straight distance to the
    /// goal's point), in walk order; `None` when no walk of pairs joins them, and then no walk
    /// of the grid joins their nodes either. Also returns the pairs expanded.
    pub(crate) fn abstract_route(&self, from: u32, to: u32) -> (Option<Vec<usize>>, usize) {
        let pairs = self.pair_label.len();
        let mut g = vec![f64::INFINITY; pairs];
        let mut parent = vec![u32::MAX; pairs];
        let mut closed = vec![false; pairs];
        let goal = self.pair_point(to);
        let mut open = BinaryHeap::from([Open {
            f: (self.pair_point(from) - goal).length(),
            pair: from,
        }]);
        g[from as usize] = 0.0;
        let mut expanded = 0;
        while let Some(Open { pair, .. }) = open.pop() {
            if std::mem::replace(&mut closed[pair as usize], true) {
                continue;
            }
            if pair == to {
                let mut tiles = vec![self.pair_tile(to)];
                let mut at = to;
                while at != from {
                    at = parent[at as usize];
                    tiles.push(self.pair_tile(at));
                }
                tiles.reverse();
                tiles.dedup();
                return (Some(tiles), expanded);
            }
            expanded += 1;
            let t = self.pair_tile(pair);
            let local = pair - self.pair_base[t];
            let here = self.pair_point(pair);
            let links = &self.tiles[t].links;
            let first = links.partition_point(|l| l.0 < local);
            for (_, u, lc) in links[first..].iter().take_while(|l| l.0 == local) {
                let next = self.pair_base[*u as usize] + lc;
                let p = self.pair_point(next);
                let through = g[pair as usize] + (p - here).length();
                if through < g[next as usize] && !closed[next as usize] {
                    g[next as usize] = through;
                    parent[next as usize] = pair;
                    open.push(Open {
                        f: through + (p - goal).length(),
                        pair: next,
                    });
                }
            }
        }
        (None, expanded)
    }
}
