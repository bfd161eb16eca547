//! Path smoothing: a walk of grid steps (four neighbours, up to `sqrt(2)` times the straight
//! line across the grid's diagonal) pulled taut into straight walks on the sphere wherever the
//! agent can walk straight, and never where it cannot.
//!
//! # A straight leg
//!
//! Between two nodes `a` and `b` of a path, the straight walk goes along the great circle between
//! their columns, its radius linear in the angle from `a`'s surface radius to `b`'s. It is
//! walkable when the columns it crosses, in order, each hold a node such that
//!
//! - the agent can step from the node of the column before to it ([`NavGrid::steps_into`]: the
//!   step limits, head room in both columns, the slope limit, and one-way drops taken only
//!   downhill, the rules of the grid), and
//! - its surface lies within the agent's step height (the larger of `step_up` and `step_down`) of
//!   the leg's radius at every sample of the leg over that column,
//!
//! and the column of `b` is reached on `b` itself. The leg is sampled every quarter of the
//! shortest step between columns, so no column it crosses is missed, except where it clips the
//! corner of one: two samples in a row then lie in columns that are not neighbours but share
//! neighbours, and the leg must pass through **every** such shared neighbour (a walk that
//! grazes a corner must not graze a blocked voxel). The height check is tightened by what the
//! leg's radius changes between two samples, so that it holds between the samples too. When in
//! doubt the leg is refused: a column that is not found, a jump of more than one diagonal, a leg
//! over more than 3 radians (172 degrees, where the great circle is nearly ill-defined).
//!
//! # String pulling
//!
//! From the start, the farthest node of the path that a straight leg reaches is taken as the
//! next corner, and so on to the goal: first the goal itself, then nodes at 1, 2, 4, ... steps
//! until a leg fails, then a bisection between the last leg that held and the first that did
//! not. Every leg kept has been checked; one that is not the farthest possible only leaves a
//! corner more. A leg of one step that fails the check (its radius strays from the ground by
//! more than a step height, which a grid step cannot do) is kept as the step it is.

use crate::grid::{NavGrid, Node, NodeId};
use crate::search::Path;
use pmc_geometry::glam::DVec3;

/// A path pulled into straight legs on the sphere by [`smooth_path`].
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothPath {
    /// The corners: the nodes of the grid path where the walk turns, start and goal included.
    pub corners: Vec<NodeId>,
    /// Their surface points, metres, planet-centred.
    pub points: Vec<DVec3>,
    /// Metres walked: the length of each leg along its great circle, the radius linear between
    /// the corners' surface radii (within the agent's step height of the ground walked).
    pub length: f64,
}

impl SmoothPath {
    /// Points along the legs, at most `spacing` metres apart along each (at least one point a
    /// leg), the corners included exactly: on each leg's great circle at its interpolated radius, for
    /// drawing the legs over a curved planet. A `spacing` that is not a number above 0 gives the
    /// corners alone.
    pub fn densify(&self, spacing: f64) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = self.points.first().copied().into_iter().collect();
        for w in self.points.windows(2) {
            let (a, b) = (w[0], w[1]);
            let n = if spacing > 0.0 && spacing.is_finite() {
                ((leg_length(a, b, 1) / spacing).ceil() as usize).clamp(1, 1 << 20)
            } else {
                1
            };
            let leg = Leg::new(a, b);
            out.extend((1..n).map(|i| leg.at(i as f64 / n as f64)));
            out.push(b);
        }
        out
    }

    /// The ground the legs walk, for drawing the path on the terrain: the start, then for each
    /// column a leg crosses, the point where the leg enters it lifted or lowered to the surface
    /// of the node it walks on there (the walkable floor, within the agent's step height of the
    /// leg), each corner exactly. A leg kept as the grid step it is (one that fails the check,
    /// see the module docs) gives its end alone. `grid` must be the grid the path was smoothed
    /// on.
    pub fn ground(&self, grid: &NavGrid) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = self.points.first().copied().into_iter().collect();
        for (w, p) in self.corners.windows(2).zip(self.points.windows(2)) {
            let mut entries = Vec::new();
            if walk_leg(grid, w[0], w[1], |dir, node| entries.push(dir * node.radius)).is_some() {
                // The last entry is the goal's column: its corner, exactly.
                entries.pop();
                out.extend(entries);
            }
            out.push(p[1]);
        }
        out
    }
}

/// A straight leg: along the great circle from `a`'s direction to `b`'s, the radius linear in
/// the angle.
#[derive(Clone, Copy, Debug)]
struct Leg {
    da: DVec3,
    db: DVec3,
    ra: f64,
    rb: f64,
    theta: f64,
}

impl Leg {
    fn new(a: DVec3, b: DVec3) -> Leg {
        Leg::from_parts(a.normalize_or_zero(), a.length(), b.normalize_or_zero(), b.length())
    }

    fn from_parts(da: DVec3, ra: f64, db: DVec3, rb: f64) -> Leg {
        Leg {
            da,
            db,
            ra,
            rb,
            theta: da.angle_between(db),
        }
    }

    /// The unit direction at `t` in `[0, 1]`.
    fn dir(&self, t: f64) -> DVec3 {
        let s = self.theta.sin();
        if s < 1e-12 {
            return self.da.lerp(self.db, t).normalize_or_zero();
        }
        (self.da * ((1.0 - t) * self.theta).sin() + self.db * (t * self.theta).sin()) / s
    }

    /// The radius at `t`.
    fn radius(&self, t: f64) -> f64 {
        self.ra + t * (self.rb - self.ra)
    }

    /// The point at `t`.
    fn at(&self, t: f64) -> DVec3 {
        self.dir(t) * self.radius(t)
    }
}

/// The length of the leg from `a` to `b` summed over `n` pieces (and more on long legs: at least
/// one piece per milliradian).
fn leg_length(a: DVec3, b: DVec3, n: usize) -> f64 {
    let leg = Leg::new(a, b);
    let n = n.max((leg.theta * 1000.0).ceil() as usize).max(1);
    let mut prev = a;
    let mut sum = 0.0;
    for i in 1..=n {
        let p = leg.at(i as f64 / n as f64);
        sum += (p - prev).length();
        prev = p;
    }
    sum
}

/// `path` (a walk of grid steps on `grid`, as [`crate::find_path`] gives) pulled into straight
/// legs: see the module docs. Node ids the grid does not hold are kept as corners.
pub fn smooth_path(grid: &NavGrid, path: &Path) -> SmoothPath {
    let nodes = &path.nodes;
    let position = |id: NodeId| grid.position(id).unwrap_or(DVec3::ZERO);
    let Some(first) = nodes.first() else {
        return SmoothPath {
            corners: Vec::new(),
            points: Vec::new(),
            length: 0.0,
        };
    };
    let mut corners = vec![*first];
    let mut length = 0.0;
    let mut anchor = 0;
    while anchor + 1 < nodes.len() {
        let (next, leg) = farthest(grid, nodes, anchor);
        corners.push(nodes[next]);
        length += leg;
        anchor = next;
    }
    let points = corners.iter().map(|c| position(*c)).collect();
    SmoothPath {
        corners,
        points,
        length,
    }
}

/// The farthest node after `anchor` that a checked straight leg reaches, and the leg's length.
fn farthest(grid: &NavGrid, nodes: &[NodeId], anchor: usize) -> (usize, f64) {
    let last = nodes.len() - 1;
    let leg = |j: usize| straight_leg(grid, nodes[anchor], nodes[j]);
    if let Some(l) = leg(last) {
        return (last, l);
    }
    let step_leg = |j: usize| {
        leg(j).unwrap_or_else(|| {
            let p = |id| grid.position(id).unwrap_or(DVec3::ZERO);
            leg_length(p(nodes[anchor]), p(nodes[j]), 1)
        })
    };
    let mut good = (anchor + 1, step_leg(anchor + 1));
    let mut bad = last;
    let mut j = anchor + 2;
    while j < bad {
        match leg(j) {
            Some(l) => {
                good = (j, l);
                j = anchor + 2 * (j - anchor);
            }
            None => bad = j,
        }
    }
    let (mut lo, mut hi) = (good.0, bad);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        match leg(mid) {
            Some(l) => {
                good = (mid, l);
                lo = mid;
            }
            None => hi = mid,
        }
    }
    good
}

/// Legs over a larger angle are refused (near 180 degrees the great circle is ill-defined).
const MAX_LEG_ANGLE: f64 = 3.0;

/// The length of the straight leg from node `a` to node `b` when the agent can walk it (module
/// docs), else `None`.
fn straight_leg(grid: &NavGrid, a: NodeId, b: NodeId) -> Option<f64> {
    walk_leg(grid, a, b, |_, _| {})
}

/// [`straight_leg`], calling `on_column(dir, node)` for each column the leg enters after `a`'s,
/// in order, with the leg's direction where it enters and the node it walks onto there (the
/// last call is `b`'s column, when the leg holds).
fn walk_leg(grid: &NavGrid, a: NodeId, b: NodeId, mut on_column: impl FnMut(DVec3, &Node)) -> Option<f64> {
    let columns = grid.columns();
    let (ca, na) = grid.node(a)?;
    let (cb, nb) = grid.node(b)?;
    let leg = Leg::from_parts(columns.direction(ca), na.radius, columns.direction(cb), nb.radius);
    if leg.theta > MAX_LEG_ANGLE {
        return None;
    }
    let agent = grid.agent();
    let n = ((leg.theta / (0.25 * columns.min_step_chord())).ceil() as usize).max(1);
    // The leg's radius changes by `dr` between samples: the ground must be within the step
    // height of it at the samples by that much more, to hold between them too.
    let dr = (nb.radius - na.radius).abs() / n as f64;
    let tol = agent.step_up.max(agent.step_down) - dr;
    let (mut col, mut at) = (ca, (a, na));
    let mut prev = leg.at(0.0);
    let mut length = 0.0;
    for i in 1..=n {
        let t = i as f64 / n as f64;
        let dir = leg.dir(t);
        let r = leg.radius(t);
        let p = dir * r;
        length += (p - prev).length();
        prev = p;
        let c = if i == n { cb } else { columns.nearest(dir)? };
        if c != col {
            at = cross(grid, col, at, c, r, tol, b)?;
            col = c;
            on_column(dir, &at.1);
        }
        if (at.1.radius - r).abs() > tol {
            return None;
        }
    }
    (at.0 == b).then_some(length)
}

/// The node of column `to` the leg walks onto from node `at` of column `from`, the leg being at
/// radius `r` there: through one step when the columns are neighbours, else through each
/// neighbour they share (all must be walkable; the first one's way is taken).
fn cross(
    grid: &NavGrid,
    from: u32,
    at: (NodeId, Node),
    to: u32,
    r: f64,
    tol: f64,
    goal: NodeId,
) -> Option<(NodeId, Node)> {
    let columns = grid.columns();
    let near = columns.neighbours(from);
    if near.contains(&to) {
        return step_onto(grid, from, at.1, to, r, tol, goal);
    }
    let far = columns.neighbours(to);
    let mut found = None;
    for m in near.iter().filter(|m| far.contains(m)) {
        let mid = step_onto(grid, from, at.1, *m, r, tol, goal)?;
        let end = step_onto(grid, *m, mid.1, to, r, tol, goal)?;
        found.get_or_insert(end);
    }
    found
}

/// The node of column `to` reached by a step from `node` of column `from` whose surface is
/// nearest to radius `r` (the goal when it is one of them), if within `tol` of it.
fn step_onto(grid: &NavGrid, from: u32, node: Node, to: u32, r: f64, tol: f64, goal: NodeId) -> Option<(NodeId, Node)> {
    let mut best: Option<(f64, NodeId, Node)> = None;
    for s in grid.steps_into(from, node, to) {
        let Some((_, n)) = grid.node(s.to) else { continue };
        let off = if s.to == goal { -1.0 } else { (n.radius - r).abs() };
        if off <= tol && best.is_none_or(|(o, _, _)| off < o) {
            best = Some((off, s.to, n));
        }
    }
    best.map(|(_, id, n)| (id, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leg_follows_the_great_circle_with_its_radius_linear() {
        let leg = Leg::new(DVec3::X * 100.0, DVec3::Y * 120.0);
        let mid = leg.at(0.5);
        assert!((mid.length() - 110.0).abs() < 1e-9);
        assert!((mid.normalize() - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-12);
        // A quarter circle at radius 100: 50 pi.
        let l = leg_length(DVec3::X * 100.0, DVec3::Y * 100.0, 1);
        assert!((l - 50.0 * std::f64::consts::PI).abs() < 1e-3, "{l}");
    }

    #[test]
    fn densify_keeps_the_corners_and_spacing() {
        let s = SmoothPath {
            corners: vec![NodeId(0), NodeId(1), NodeId(2)],
            points: vec![DVec3::X * 100.0, DVec3::Y * 100.0, DVec3::Z * 100.0],
            length: 0.0,
        };
        let d = s.densify(10.0);
        assert_eq!(d.first(), Some(&(DVec3::X * 100.0)));
        assert!((d[d.len() - 1] - DVec3::Z * 100.0).length() < 1e-9);
        assert!(d.windows(2).all(|w| (w[1] - w[0]).length() <= 10.0 + 1e-9));
        assert_eq!(s.densify(f64::NAN).len(), 3);
    }
}
