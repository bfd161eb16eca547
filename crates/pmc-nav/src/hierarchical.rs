//! Hierarchical search (HPA*-style) on the whole-planet grid: a search of the abstract graph of
//! tiles and their local components picks the tiles a path crosses, then a weighted A* over the
//! nodes of those tiles and the tiles next to them (the corridor) finds the walk.
//!
//! # How it answers
//!
//! 1. Nodes in different components: [`NoPath::DifferentComponents`], without a search (as
//!    [`find_path`]).
//! 2. A* over the abstract graph (a node per (tile, local component) pair at the mean surface
//!    point of its nodes, a link where a border step joins two pairs, each link costing the
//!    distance between the points; the straight distance to the goal's point as heuristic). No
//!    walk of pairs means no walk of nodes: [`NoPath::OneWay`].
//! 3. The corridor: the tiles of the pair walk, and every tile a link leaves them for. A* over
//!    the grid's own steps, restricted to the corridor's nodes, with [`find_path`]'s heuristic
//!    weighted by [`HIERARCHICAL_WEIGHT`]: the walk found is at most that many times the
//!    shortest walk inside the corridor, and heads for the goal instead of flooding every node
//!    whose cost could still beat the shortest walk (what makes the exact search slow on rough
//!    ground). Its records are numbered within the corridor, so a search costs what the
//!    corridor holds, not what the planet does.
//! 4. When the corridor holds no walk (a local component crossed one way only, say), the exact
//!    [`find_path`] answers: never a wrong answer, only a slower one.
//!
//! The walk is a walk of the grid (each consecutive pair a step the agent can take, one-way drops
//! only downhill); [`crate::smooth_path`] then pulls it straight.

use crate::grid::{NavGrid, NodeId};
use crate::search::{astar, find_path, Eager, Halt, NoPath, Outcome, Path, SearchGraph};

/// The heuristic weight of the corridor search: its walk is at most this many times the
/// shortest walk within the corridor (in practice within a few percent of the shortest walk; see
/// the tests and docs/BENCHMARKS.md).
pub const HIERARCHICAL_WEIGHT: f64 = 1.5;

/// The grid restricted to the corridor's tiles, records numbered within it.
struct Corridor<'a> {
    eager: Eager<'a>,
    /// For each tile of the grid, the first record slot of its nodes, or `u32::MAX` outside.
    slot_base: Vec<u32>,
    /// (first slot, tile) of each corridor tile, by first slot.
    tiles: Vec<(u32, usize)>,
}

impl SearchGraph for Corridor<'_> {
    type Key = NodeId;
    fn slot(&mut self, key: NodeId) -> usize {
        let t = self.eager.grid.tile_of_node(key);
        (self.slot_base[t] + (key.0 - self.eager.grid.tile_first_node(t))) as usize
    }
    fn key(&self, slot: usize) -> NodeId {
        let at = self.tiles.partition_point(|(s, _)| *s as usize <= slot) - 1;
        let (first, t) = self.tiles[at];
        NodeId(self.eager.grid.tile_first_node(t) + (slot as u32 - first))
    }
    fn successors(&mut self, key: NodeId, out: &mut Vec<(NodeId, f64, f64)>) -> Result<(), Halt> {
        for s in self.eager.grid.steps(key) {
            if self.slot_base[self.eager.grid.tile_of_node(s.to)] != u32::MAX {
                let h = self.eager.heuristic(s.to);
                out.push((s.to, s.cost, h));
            }
        }
        Ok(())
    }
    fn heuristic(&mut self, key: NodeId) -> f64 {
        self.eager.heuristic(key)
    }
}

/// A walk from `from` to `to` (both nodes of `grid`) found by the hierarchical search of the
/// module docs, or why there is none (the same answer as [`find_path`]). The walk is at most
/// [`HIERARCHICAL_WEIGHT`] times the shortest walk within the corridor it searched; `expanded`
/// counts the corridor search's nodes (and the exact search's, when it had to answer).
pub fn find_path_hierarchical(grid: &NavGrid, from: NodeId, to: NodeId) -> Result<Path, NoPath> {
    let eager = Eager::towards(grid, from, to)?;
    let (Some((pa, _)), Some((pb, _))) = (grid.pair_of(from), grid.pair_of(to)) else {
        return Err(NoPath::OneWay);
    };
    let (Some(route), _) = grid.abstract_route(pa, pb) else {
        return Err(NoPath::OneWay);
    };
    let mut slot_base = vec![u32::MAX; grid.tile_count()];
    let mut tiles = Vec::new();
    let mut slots = 0u32;
    let mut add = |t: usize, slot_base: &mut Vec<u32>| {
        if slot_base[t] == u32::MAX {
            slot_base[t] = slots;
            tiles.push((slots, t));
            slots += grid.tile_node_count(t);
        }
    };
    for t in &route {
        add(*t, &mut slot_base);
        for u in grid.linked_tiles(*t) {
            add(u, &mut slot_base);
        }
    }
    let mut corridor = Corridor {
        eager,
        slot_base,
        tiles,
    };
    match astar(&mut corridor, from, to, HIERARCHICAL_WEIGHT, usize::MAX, |_| None) {
        (Outcome::Found { nodes, length }, expanded) => Ok(corridor.eager.path(nodes, length, expanded)),
        (_, expanded) => find_path(grid, from, to).map(|mut p| {
            p.expanded += expanded;
            p
        }),
    }
}
