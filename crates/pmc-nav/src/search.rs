//! A* over a navigation grid with a great-circle and lattice heuristic, shared by the whole-planet
//! grid ([`find_path`]) and the lazy grid ([`crate::LazyGrid::find_path`]).
//!
//! # The heuristic
//!
//! A step between columns whose unit directions are a chord `c` apart, at surface radii
//! `ra, rb >= r_min`, costs at least its horizontal part `c (ra + rb) / 2 >= c r_min`. Lower
//! bounds on what is left from a node to the goal follow, and A* takes the largest:
//!
//! - the chord between the node's column and the goal's, times `r_min` (chords at one radius obey
//!   the triangle inequality);
//! - the number of steps any walk needs, `l`: half the L1 distance between the two columns'
//!   lattice points (each step moves one lattice coordinate by 2, across face edges too), times
//!   the shortest chord of any step, `c_min` ([`crate::Columns::min_step_chord`]), and `r_min`.
//!   On a four-neighbour grid a walk along the grid's diagonal is about `sqrt(2)` times the
//!   straight line, which this bound sees and the first does not;
//! - near the goal, the same with the shortest chord among the steps within `S` steps of the
//!   goal, `c_S` ([`crate::Columns::min_step_chord_near`]; `S` is twice the start's `l`, at
//!   least 64): the grid is nearly uniform there, so `c_S` is within a hair of the steps' own
//!   chords, where `c_min` may be 40% shorter. A walk from a node with `l <= S` either stays
//!   within `S` steps of the goal (at least `l` steps of at least `c_S`) or leaves (at least
//!   `S - l` steps of `c_S` out and `S + 1` of `c_min` back), so the bound is `r_min` times the
//!   smaller of `c_S l` and `c_S (S - l) + c_min (S + 1)`.
//!
//! Each changes by at most one step's cost along a step (across the edge of the region too, where
//! the third is at most the second beyond it), so the largest is consistent: with weight 1 the
//! path found is a shortest one. A weight `w > 1` multiplies the heuristic: the search goes more
//! directly at the goal and the path found is at most `w` times the shortest.

use crate::columns::Columns;
use crate::grid::{NavError, NavGrid, NodeId};
use pmc_geometry::glam::{DVec3, IVec3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A path found by [`find_path`] (node ids of the whole-planet grid) or by
/// [`crate::LazyGrid::find_path`] (node keys of the lazy grid).
#[derive(Clone, Debug, PartialEq)]
pub struct Path<N = NodeId> {
    /// The nodes walked, start and goal included.
    pub nodes: Vec<N>,
    /// Their surface points, metres, planet-centred.
    pub points: Vec<DVec3>,
    /// Metres walked: the sum of the steps' costs.
    pub length: f64,
    /// Nodes expanded by the search.
    pub expanded: usize,
}

/// Why there is no path: an answer, not an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoPath {
    /// The two nodes lie in different components (detached grids, Fig. 10): known without a
    /// search. Only the whole-planet grid has components.
    DifferentComponents {
        /// The start's component.
        from: u32,
        /// The goal's component.
        to: u32,
    },
    /// Same component, but every way needs a step the agent can only take the other way (a drop
    /// it cannot climb back); found by the search.
    OneWay,
    /// No path exists, proven by exhausting a closed region of the lazy grid: the start can
    /// reach only `nodes` nodes and the goal is not one of them (`start_side`), or only `nodes`
    /// nodes can reach the goal and the start is not one of them.
    Enclosed {
        /// Nodes in the closed region.
        nodes: usize,
        /// Whether the region is the start's (what it can reach) or the goal's (what can reach
        /// it).
        start_side: bool,
    },
    /// The search of the lazy grid stopped at its bound ([`SearchOptions`]) before it reached
    /// the goal or proved that no path exists: a path may exist.
    SearchBound {
        /// Nodes expanded when it stopped.
        expanded: usize,
        /// Tiles built when it stopped.
        tiles_built: usize,
    },
}

impl NoPath {
    /// A short name for the reason, for documents: `different_components`, `one_way`,
    /// `enclosed` or `search_bound`.
    pub fn cause(&self) -> &'static str {
        match self {
            NoPath::DifferentComponents { .. } => "different_components",
            NoPath::OneWay => "one_way",
            NoPath::Enclosed { .. } => "enclosed",
            NoPath::SearchBound { .. } => "search_bound",
        }
    }
}

impl std::fmt::Display for NoPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoPath::DifferentComponents { from, to } => write!(
                f,
                "no path: the start is on navigation component {from} and the goal on component {to}, which no step joins"
            ),
            NoPath::OneWay => write!(
                f,
                "no path: the goal can only be left toward the start, not reached from it (a drop the agent cannot climb back)"
            ),
            NoPath::Enclosed { nodes, start_side: true } => write!(
                f,
                "no path: the start can reach only {nodes} nodes of the navigation grid, and the goal is not one of them"
            ),
            NoPath::Enclosed { nodes, start_side: false } => write!(
                f,
                "no path: only {nodes} nodes of the navigation grid can reach the goal, and the start is not one of them"
            ),
            NoPath::SearchBound { expanded, tiles_built } => write!(
                f,
                "no path found within the search bound ({expanded} nodes expanded, {tiles_built} tiles built); a path may still exist beyond it"
            ),
        }
    }
}

/// How far a search of the lazy grid may go, and how directly it heads for the goal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchOptions {
    /// Most nodes expanded before the search answers [`NoPath::SearchBound`].
    pub max_expanded: usize,
    /// Most tiles built (sampled from the density, rebuilds after eviction included) before the
    /// search answers [`NoPath::SearchBound`].
    pub max_tiles_built: usize,
    /// Heuristic weight, at least 1: the path found is at most this many times the shortest.
    /// 1 finds a shortest path, but on ground that is not flat A* must then expand every node
    /// whose cost through it could still beat the shortest path, a region that widens with the
    /// walk's length: a few hundred metres are fine, a shortest 10 km walk on the Earth's layout
    /// passes the default bounds. Above 1 the search heads for the goal and expands about as
    /// many nodes as the path has, but only once the weight covers what the ground adds to a
    /// walk over the bound of the module docs: on the earth preset 1.05 and 1.2 still flood the
    /// ground in front of ridges on many 10 km walks, 1.5 does not, and its paths were within
    /// half a percent of those found at 1.2 where that finished.
    pub weight: f64,
}

impl Default for SearchOptions {
    /// Two million nodes, 16 384 tiles (at 4 columns a side about 260 000 columns, some
    /// 0.4 km^2 of ground at the Earth's 1.2 m columns, enough for walks of about 30 km),
    /// weight 1.5.
    fn default() -> Self {
        SearchOptions {
            max_expanded: 2_000_000,
            max_tiles_built: 16_384,
            weight: 1.5,
        }
    }
}

impl SearchOptions {
    /// Checks the options: bounds at least 1, a finite weight of at least 1.
    pub fn validate(&self) -> Result<(), NavError> {
        let bad = |m: String| Err(NavError::Options(m));
        if self.max_expanded == 0 {
            return bad("the search bound on nodes expanded must be at least 1".into());
        }
        if self.max_tiles_built == 0 {
            return bad("the search bound on tiles built must be at least 1".into());
        }
        if !(self.weight.is_finite() && self.weight >= 1.0) {
            return bad(format!(
                "the search weight must be a finite number of at least 1, got {}",
                self.weight
            ));
        }
        Ok(())
    }
}

/// What a search of the lazy grid did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SearchStats {
    /// Nodes expanded by A* from the start.
    pub expanded: usize,
    /// Nodes visited by the search backward from the goal (which proves "no path" when the
    /// goal lies in a closed region).
    pub backward: usize,
    /// Tiles built from the density during the search (the ends' tiles included).
    pub tiles_built: usize,
}

/// Why a search stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Halt {
    /// A bound was reached.
    Bound,
    /// No path exists: the goal's closed region, of this many nodes, was exhausted.
    GoalEnclosed(usize),
}

/// A graph A* can search: nodes named by `Key`, each given a dense record slot.
pub(crate) trait SearchGraph {
    /// A node.
    type Key: Copy + Eq;
    /// The record slot of `key`, assigned on first sight (dense, from 0).
    fn slot(&mut self, key: Self::Key) -> usize;
    /// The node of a slot.
    fn key(&self, slot: usize) -> Self::Key;
    /// The steps from `key`: (node reached, cost, [`SearchGraph::heuristic`] of the node
    /// reached), appended to `out`.
    fn successors(&mut self, key: Self::Key, out: &mut Vec<(Self::Key, f64, f64)>) -> Result<(), Halt>;
    /// A consistent lower bound on the cost from `key` to the goal.
    fn heuristic(&mut self, key: Self::Key) -> f64;
}

/// How a search ended.
pub(crate) enum Outcome<K> {
    /// A path: its nodes and length.
    Found { nodes: Vec<K>, length: f64 },
    /// Every node reachable from the start was expanded.
    Exhausted,
    /// Stopped early.
    Halted(Halt),
}

/// An open-set entry: smallest `f` first, then largest `g` (deepest first among equals), then
/// smallest slot.
#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    g: f64,
    slot: u32,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then(self.g.total_cmp(&other.g))
            .then(other.slot.cmp(&self.slot))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// A search record.
#[derive(Clone, Copy)]
struct Record {
    g: f64,
    parent: u32,
    closed: bool,
}

const UNSEEN: Record = Record {
    g: f64::INFINITY,
    parent: u32::MAX,
    closed: false,
};

/// A* from `from` to `to` with heuristic weight `weight`, expanding at most `max_expanded`
/// nodes; after each expansion `each` may stop the search. Returns the outcome and the number
/// of nodes expanded.
pub(crate) fn astar<G: SearchGraph>(
    graph: &mut G,
    from: G::Key,
    to: G::Key,
    weight: f64,
    max_expanded: usize,
    mut each: impl FnMut(&mut G) -> Option<Halt>,
) -> (Outcome<G::Key>, usize) {
    let mut records: Vec<Record> = Vec::new();
    let mut open = BinaryHeap::new();
    let mut steps = Vec::new();
    let start = graph.slot(from);
    let goal = graph.slot(to);
    let grow = |records: &mut Vec<Record>, slot: usize| {
        if slot >= records.len() {
            records.resize(slot + 1, UNSEEN);
        }
    };
    grow(&mut records, start.max(goal));
    records[start].g = 0.0;
    open.push(Open {
        f: weight * graph.heuristic(from),
        g: 0.0,
        slot: start as u32,
    });
    let mut expanded = 0;
    while let Some(Open { slot, .. }) = open.pop() {
        let slot = slot as usize;
        if records[slot].closed {
            continue;
        }
        records[slot].closed = true;
        if slot == goal {
            let mut nodes = vec![to];
            let mut at = slot;
            while at != start {
                at = records[at].parent as usize;
                nodes.push(graph.key(at));
            }
            nodes.reverse();
            return (
                Outcome::Found {
                    nodes,
                    length: records[slot].g,
                },
                expanded,
            );
        }
        if expanded == max_expanded {
            return (Outcome::Halted(Halt::Bound), expanded);
        }
        expanded += 1;
        steps.clear();
        if let Err(halt) = graph.successors(graph.key(slot), &mut steps) {
            return (Outcome::Halted(halt), expanded);
        }
        let g = records[slot].g;
        for (next, cost, h) in steps.iter().copied() {
            let n = graph.slot(next);
            grow(&mut records, n);
            let through = g + cost;
            if through < records[n].g && !records[n].closed {
                records[n].g = through;
                records[n].parent = slot as u32;
                open.push(Open {
                    f: through + weight * h,
                    g: through,
                    slot: n as u32,
                });
            }
        }
        if let Some(halt) = each(graph) {
            return (Outcome::Halted(halt), expanded);
        }
    }
    (Outcome::Exhausted, expanded)
}

/// The heuristic of the module docs for one goal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Heuristic {
    r_min: f64,
    c_min: f64,
    goal_dir: DVec3,
    goal_lattice: IVec3,
    /// `S` and `c_S`.
    reach: i64,
    c_near: f64,
}

impl Heuristic {
    /// The heuristic toward the goal at `goal_dir` / `goal_lattice` for a search from the
    /// column at lattice point `start`, every surface radius being at least `r_min`.
    pub(crate) fn new(columns: &Columns, r_min: f64, start: IVec3, goal_dir: DVec3, goal_lattice: IVec3) -> Heuristic {
        let reach = (2 * Columns::min_steps(start, goal_lattice)).max(64);
        Heuristic {
            r_min,
            c_min: columns.min_step_chord(),
            goal_dir,
            goal_lattice,
            reach,
            c_near: columns.min_step_chord_near(goal_lattice, reach),
        }
    }

    /// The lower bound from the column at `dir` / `lattice`.
    #[inline]
    pub(crate) fn at(&self, dir: DVec3, lattice: IVec3) -> f64 {
        let chord = (dir - self.goal_dir).length();
        let l = Columns::min_steps(lattice, self.goal_lattice);
        let lf = l as f64;
        let mut h = chord.max(self.c_min * lf);
        if l <= self.reach {
            let s = self.reach as f64;
            h = h.max((self.c_near * lf).min(self.c_near * (s - lf) + self.c_min * (s + 1.0)));
        }
        self.r_min * h
    }
}

/// The whole-planet grid as a search graph: slots are node ids.
pub(crate) struct Eager<'a> {
    pub grid: &'a NavGrid,
    pub heuristic: Option<Heuristic>,
}

impl<'a> Eager<'a> {
    /// The grid searched from `from` toward `to`, with the heuristic of the module docs; nodes
    /// in different components are answered at once (the answer of [`find_path`] and of the
    /// hierarchical search alike).
    pub(crate) fn towards(grid: &'a NavGrid, from: NodeId, to: NodeId) -> Result<Eager<'a>, NoPath> {
        let (Some(ca), Some(cb)) = (grid.component(from), grid.component(to)) else {
            return Err(NoPath::OneWay);
        };
        if ca != cb {
            return Err(NoPath::DifferentComponents { from: ca, to: cb });
        }
        let mut graph = Eager { grid, heuristic: None };
        let (Some((_, start)), Some((goal_dir, goal_lattice))) = (graph.place(from), graph.place(to)) else {
            return Err(NoPath::OneWay);
        };
        graph.heuristic = Some(Heuristic::new(
            grid.columns(),
            grid.min_radius(),
            start,
            goal_dir,
            goal_lattice,
        ));
        Ok(graph)
    }

    /// The path of a walk `nodes` of `length` metres found after expanding `expanded` nodes.
    pub(crate) fn path(&self, nodes: Vec<NodeId>, length: f64, expanded: usize) -> Path {
        let points = nodes.iter().filter_map(|id| self.grid.position(*id)).collect();
        Path {
            nodes,
            points,
            length,
            expanded,
        }
    }

    pub(crate) fn place(&self, id: NodeId) -> Option<(DVec3, IVec3)> {
        let (c, _) = self.grid.node(id)?;
        let columns = self.grid.columns();
        Some((columns.direction(c), columns.lattice(columns.place_of(c))))
    }
}

impl SearchGraph for Eager<'_> {
    type Key = NodeId;
    fn slot(&mut self, key: NodeId) -> usize {
        key.0 as usize
    }
    fn key(&self, slot: usize) -> NodeId {
        NodeId(slot as u32)
    }
    fn successors(&mut self, key: NodeId, out: &mut Vec<(NodeId, f64, f64)>) -> Result<(), Halt> {
        for s in self.grid.steps(key) {
            let h = self.heuristic(s.to);
            out.push((s.to, s.cost, h));
        }
        Ok(())
    }
    fn heuristic(&mut self, key: NodeId) -> f64 {
        match (self.place(key), &self.heuristic) {
            (Some((dir, lattice)), Some(h)) => h.at(dir, lattice),
            _ => 0.0,
        }
    }
}

/// The shortest path from `from` to `to` (both nodes of `grid`), or why there is none.
///
/// Nodes in different components are answered at once, without a search. Otherwise A* runs
/// with the heuristic of the module docs, `r_min` being the grid's smallest surface radius, so
/// the path is a shortest one.
pub fn find_path(grid: &NavGrid, from: NodeId, to: NodeId) -> Result<Path, NoPath> {
    let mut graph = Eager::towards(grid, from, to)?;
    match astar(&mut graph, from, to, 1.0, usize::MAX, |_| None) {
        (Outcome::Found { nodes, length }, expanded) => Ok(graph.path(nodes, length, expanded)),
        _ => Err(NoPath::OneWay),
    }
}
