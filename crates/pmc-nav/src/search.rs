//! A* over the navigation grid with a great-circle heuristic.

use crate::grid::{NavGrid, NodeId};
use pmc_geometry::glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A path found by [`find_path`].
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    /// The nodes walked, start and goal included.
    pub nodes: Vec<NodeId>,
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
    /// search.
    DifferentComponents {
        /// The start's component.
        from: u32,
        /// The goal's component.
        to: u32,
    },
    /// Same component, but every way needs a step the agent can only take the other way (a drop
    /// it cannot climb back); found by the search.
    OneWay,
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
        }
    }
}

/// An open-set entry, ordered by smallest `f` first.
#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    node: u32,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other.f.total_cmp(&self.f).then(other.node.cmp(&self.node))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The angle between two directions, accurate for small angles too.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The shortest path from `from` to `to` (both nodes of `grid`), or why there is none.
///
/// Nodes in different components are answered at once, without a search. Otherwise A* runs with
/// a great-circle heuristic: `2 r_min sin(angle / 2)`, the straight line between the two columns
/// at the grid's smallest surface radius `r_min` (the great-circle distance's chord). A step
/// between columns at angle `t` and radii `ra, rb >= r_min` costs at least its horizontal part
/// `(ra + rb) / 2 * 2 sin(t / 2) >= 2 r_min sin(t / 2)`, and chords at one radius obey the
/// triangle inequality, so the heuristic is admissible and consistent: the path is a shortest one.
pub fn find_path(grid: &NavGrid, from: NodeId, to: NodeId) -> Result<Path, NoPath> {
    let (Some(ca), Some(cb)) = (grid.component(from), grid.component(to)) else {
        return Err(NoPath::OneWay);
    };
    if ca != cb {
        return Err(NoPath::DifferentComponents { from: ca, to: cb });
    }
    let n = grid.node_count();
    let r_min = grid.min_radius();
    let goal_dir = match grid.node(to) {
        Some((c, _)) => grid.columns().direction(c),
        None => return Err(NoPath::OneWay),
    };
    let h = |id: u32| -> f64 {
        grid.node(NodeId(id))
            .map(|(c, _)| 2.0 * r_min * (0.5 * angle(grid.columns().direction(c), goal_dir)).sin())
            .unwrap_or(0.0)
    };
    let mut g = vec![f64::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut closed = vec![false; n];
    let mut open = BinaryHeap::new();
    g[from.0 as usize] = 0.0;
    open.push(Open {
        f: h(from.0),
        node: from.0,
    });
    let mut expanded = 0;
    while let Some(Open { node, .. }) = open.pop() {
        if closed[node as usize] {
            continue;
        }
        closed[node as usize] = true;
        expanded += 1;
        if node == to.0 {
            let mut nodes = vec![to];
            let mut at = node;
            while at != from.0 {
                at = parent[at as usize];
                nodes.push(NodeId(at));
            }
            nodes.reverse();
            let points = nodes.iter().filter_map(|id| grid.position(*id)).collect();
            return Ok(Path {
                nodes,
                points,
                length: g[node as usize],
                expanded,
            });
        }
        for s in grid.steps(NodeId(node)) {
            let next = s.to.0 as usize;
            let cost = g[node as usize] + s.cost;
            if cost < g[next] {
                g[next] = cost;
                parent[next] = node;
                open.push(Open {
                    f: cost + h(s.to.0),
                    node: s.to.0,
                });
            }
        }
    }
    Err(NoPath::OneWay)
}
