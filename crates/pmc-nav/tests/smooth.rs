//! Path smoothing: on open ground the smoothed path is within 5% of the great circle at the
//! surface radius (the best any-angle path), and every leg, checked densely and independently of
//! the smoother, passes only over columns holding a walkable node near its height with head room
//! in air: never through a filled voxel.

use crate::common;

use common::{default_grid, leg_point};
use pmc_density::{Density, Sphere};
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use pmc_nav::{find_path, smooth_path, Agent, NavGrid, NodeId, SmoothPath};
use proptest::prelude::*;
use std::sync::{Arc, OnceLock};

/// A smooth sphere of radius 115 m in a shell from 100 m to 132 m, 6 x 65^2 columns.
fn sphere_grid() -> &'static NavGrid {
    static GRID: OnceLock<NavGrid> = OnceLock::new();
    GRID.get_or_init(|| {
        let layout = Layout::new(4, 16, 100.0, 2.0, 1).unwrap();
        NavGrid::build(&Sphere { radius: 115.0 }, &layout, Agent::default()).unwrap()
    })
}

/// Checks every leg of `s` at `per_column` samples per column spacing: the column under each
/// sample holds a node within the agent's step height of the leg's radius whose clearance is air.
fn assert_walkable(g: &NavGrid, s: &SmoothPath, per_column: f64) {
    let layout = *g.columns().layout();
    let agent = g.agent();
    let tol = agent.step_up.max(agent.step_down);
    let clearance = ((agent.clearance / layout.l_d()).ceil() as i64).max(1);
    let spacing = g.columns().min_step_chord() / per_column;
    for w in s.points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let n = ((a.angle_between(b) / spacing).ceil() as usize).max(1);
        for i in 0..=n {
            let p = leg_point(a, b, i as f64 / n as f64);
            let col = g.columns().nearest(p).expect("a column");
            let ok = g.column_nodes(col).any(|(_, node)| {
                let k = i64::from(node.layer);
                (node.radius - p.length()).abs() <= tol && (k + 1..=k + clearance).all(|l| !g.is_filled(col, l))
            });
            assert!(
                ok,
                "the leg {a} -> {b} passes at {p} (radius {:.2}) over column {col} with no walkable node near it",
                p.length()
            );
        }
    }
}

#[test]
fn on_a_smooth_sphere_a_path_smooths_to_the_great_circle() {
    let g = sphere_grid();
    let a = g.node_near(DVec3::new(-0.9, 1.0, -0.9), None, 0).unwrap();
    let b = g.node_near(DVec3::new(0.9, 1.0, 0.9), None, 0).unwrap();
    let path = find_path(g, a, b).unwrap();
    let s = smooth_path(g, &path);
    let (pa, pb) = (g.position(a).unwrap(), g.position(b).unwrap());
    let best = pa.angle_between(pb) * 0.5 * (pa.length() + pb.length());
    assert_eq!(s.corners, vec![a, b], "one straight leg across open ground");
    assert!(
        s.length <= 1.05 * best && s.length >= 0.999 * best,
        "{} vs {best}",
        s.length
    );
    assert!(
        path.length > 1.2 * best,
        "the grid walk is a staircase: {} vs {best}",
        path.length
    );
    assert_walkable(g, &s, 8.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn on_open_ground_the_smoothed_path_is_within_5_percent_of_the_great_circle(
        a in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        b in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
    ) {
        let (da, db) = (DVec3::new(a.0, a.1, a.2), DVec3::new(b.0, b.1, b.2));
        prop_assume!(da.length() > 0.1 && db.length() > 0.1 && da.angle_between(db) < 2.0);
        let g = sphere_grid();
        let from = g.node_near(da, None, 0).unwrap();
        let to = g.node_near(db, None, 0).unwrap();
        let path = find_path(g, from, to).unwrap();
        let s = smooth_path(g, &path);
        let (pa, pb) = (g.position(from).unwrap(), g.position(to).unwrap());
        let best = pa.angle_between(pb) * 0.5 * (pa.length() + pb.length());
        prop_assert!(s.length <= 1.05 * best + 1e-9, "{} vs {best} ({} corners)", s.length, s.corners.len());
        // Legs are arcs where steps cost chords: on a straight walk along the grid the smoothed
        // length is the grid walk's, plus a few parts in 10^5.
        prop_assert!(s.length <= path.length * 1.0001, "{} vs {}", s.length, path.length);
        prop_assert_eq!(s.corners.first(), Some(&from));
        prop_assert_eq!(s.corners.last(), Some(&to));
        assert_walkable(g, &s, 8.0);
    }
}

/// Corners are nodes of the path, in its order.
fn corners_follow_the_path(path: &[NodeId], corners: &[NodeId]) -> bool {
    let mut it = path.iter();
    corners.iter().all(|c| it.any(|p| p == c))
}

#[test]
fn on_the_default_planet_smoothed_legs_never_cross_a_filled_voxel_or_a_column_without_ground() {
    let g = default_grid();
    let mut rng = common::Lcg(11);
    let (mut checked, mut drawn) = (0, 0);
    while checked < 40 {
        let a = rng.dir();
        let b = (a + rng.dir() * 0.15).normalize();
        let (Some(from), Some(to)) = (g.node_near(a, None, 8), g.node_near(b, None, 8)) else {
            continue;
        };
        let Ok(path) = find_path(g, from, to) else { continue };
        let s = smooth_path(g, &path);
        assert!(corners_follow_the_path(&path.nodes, &s.corners));
        assert!(s.length <= path.length * 1.0001, "{} vs {}", s.length, path.length);
        assert_walkable(g, &s, 8.0);
        drawn += assert_ground_is_walked(g, &s);
        checked += 1;
    }
    assert!(drawn > 200, "only {drawn} ground points between corners in 40 paths");
}

/// The ground drawn under a smoothed path ([`SmoothPath::ground`]) starts and ends at the path's
/// ends and passes its corners in order; every other point lies on the surface of a node of the
/// column under it, within the agent's step height of its leg. Returns how many such points.
fn assert_ground_is_walked(g: &NavGrid, s: &SmoothPath) -> usize {
    let ground = s.ground(g);
    assert_eq!((ground.first(), ground.last()), (s.points.first(), s.points.last()));
    let mut at = 0;
    for c in &s.points {
        at += ground[at..]
            .iter()
            .position(|p| p == c)
            .expect("a corner missing from the ground line");
    }
    let step = g.agent().step_up.max(g.agent().step_down);
    let legs: Vec<(DVec3, DVec3)> = s.points.windows(2).map(|w| (w[0], w[1])).collect();
    for p in ground.iter().filter(|p| !s.points.contains(p)) {
        let col = g.columns().nearest(*p).unwrap();
        let on_node = g.column_nodes(col).any(|(_, n)| (n.radius - p.length()).abs() < 1e-9);
        assert!(on_node, "a ground point {p} on no node's surface");
        let off = legs
            .iter()
            .map(|(a, b)| {
                let t = (a.angle_between(*p) / a.angle_between(*b)).clamp(0.0, 1.0);
                (leg_point(*a, *b, t).length() - p.length()).abs()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(off <= step + 1e-6, "a ground point {off} m off its leg");
    }
    ground.len() - s.points.len()
}

#[test]
fn on_flat_ground_of_the_default_planet_the_smoothed_path_is_within_5_percent_of_the_great_circle() {
    let g = default_grid();
    let mut rng = common::Lcg(5);
    let mut checked = 0;
    let mut tries = 0;
    while checked < 12 {
        tries += 1;
        assert!(tries < 20_000, "found only {checked} flat places");
        let a = rng.dir();
        let b = (a + rng.dir() * 0.1).normalize();
        let (Some(from), Some(to)) = (g.node_near(a, None, 0), g.node_near(b, None, 0)) else {
            continue;
        };
        let (pa, pb) = (g.position(from).unwrap(), g.position(to).unwrap());
        // Flat ground: the highest node of every column under the great circle within a layer
        // of the line between the two ends' radii.
        let best = pa.angle_between(pb) * 0.5 * (pa.length() + pb.length());
        let n = (best / 3.0).ceil() as usize;
        let flat = (0..=n).all(|i| {
            let p = leg_point(pa, pb, i as f64 / n as f64);
            let col = g.columns().nearest(p).unwrap();
            g.column_nodes(col)
                .last()
                .is_some_and(|(_, top)| (top.radius - p.length()).abs() < 4.0)
        });
        if !flat || best < 100.0 {
            continue;
        }
        let path = find_path(g, from, to).unwrap();
        let s = smooth_path(g, &path);
        assert!(
            s.length <= 1.05 * best,
            "{} vs {best}: corners {:?}",
            s.length,
            s.points
        );
        assert_walkable(g, &s, 8.0);
        checked += 1;
    }
}

#[test]
fn a_leg_does_not_cut_through_a_pillar_in_the_way() {
    // A pillar 12 m wide and 20 m high on the smooth sphere, on the straight line between the
    // two ends: the smoothed path goes around it.
    let layout = Layout::new(4, 16, 100.0, 2.0, 1).unwrap();
    let (da, db) = (
        DVec3::new(-0.3, 1.0, -0.3).normalize(),
        DVec3::new(0.3, 1.0, 0.3).normalize(),
    );
    let mid = (da + db).normalize();
    let pillar = BrushOp::new(BrushKind::Add, mid * 120.0, 6.0, 1.0).unwrap();
    let d = EditedDensity::new(
        Arc::new(Sphere { radius: 115.0 }) as Arc<dyn Density>,
        EditSnapshot::from(vec![pillar]),
    );
    let g = NavGrid::build(&d, &layout, Agent::default()).unwrap();
    let (a, b) = (g.node_near(da, None, 0).unwrap(), g.node_near(db, None, 0).unwrap());
    let path = find_path(&g, a, b).unwrap();
    let s = smooth_path(&g, &path);
    let (pa, pb) = (g.position(a).unwrap(), g.position(b).unwrap());
    let best = pa.angle_between(pb) * 0.5 * (pa.length() + pb.length());
    assert!(s.corners.len() > 2, "the way round the pillar has a corner");
    assert!(
        s.length > best * 1.001 && s.length < path.length,
        "{} vs {best}",
        s.length
    );
    assert_walkable(&g, &s, 8.0);
    // No leg comes within the pillar's radius of its axis.
    for w in s.points.windows(2) {
        for i in 0..=200 {
            let p = leg_point(w[0], w[1], i as f64 / 200.0);
            assert!(
                p.normalize().angle_between(mid) * 115.0 > 5.0,
                "a leg passes through the pillar at {p}"
            );
        }
    }
}
