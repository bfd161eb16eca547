//! The hierarchical search against the exact A* on the default planet: it finds a walk exactly
//! when A* finds a path (across face edges and cube corners too, and with one-way drops), each
//! walk is made of the grid's steps, its length is within a stated bound of the shortest, and
//! after an edit it sees the change.

use crate::common::{default_grid, default_planet, Lcg};
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_nav::{find_path, find_path_hierarchical, Agent, NavGrid, NoPath, NodeId, Path, HIERARCHICAL_WEIGHT};

/// What the hierarchical walk may be at most, against the shortest: [`HIERARCHICAL_WEIGHT`]
/// times, the corridor search's guarantee within its corridor (the corridor could in principle
/// leave out every walk that short; on the pairs below it never does, and the walks measure at
/// most about 1.09 times the shortest for the default agent, 1.18 with one-way drops, 1.01 on
/// average).
const BOUND: f64 = HIERARCHICAL_WEIGHT;

/// Checks that `p` walks from `from` to `to` by steps of `g` and that its length is their sum.
fn assert_walk(g: &NavGrid, p: &Path, from: NodeId, to: NodeId) {
    assert_eq!(p.nodes.first(), Some(&from));
    assert_eq!(p.nodes.last(), Some(&to));
    let mut sum = 0.0;
    for w in p.nodes.windows(2) {
        let s = g.steps(w[0]).into_iter().find(|s| s.to == w[1]);
        let s = s.unwrap_or_else(|| panic!("{:?} -> {:?} is not a step", w[0], w[1]));
        sum += s.cost;
    }
    assert!((sum - p.length).abs() < 1e-6 * sum.max(1.0), "{sum} vs {}", p.length);
    assert_eq!(p.points.len(), p.nodes.len());
}

/// Compares the two searches from `from` to `to`; returns the length ratio when both found one.
fn compare(g: &NavGrid, from: NodeId, to: NodeId) -> Option<f64> {
    let exact = find_path(g, from, to);
    let fast = find_path_hierarchical(g, from, to);
    match (&exact, &fast) {
        (Ok(e), Ok(f)) => {
            assert_walk(g, f, from, to);
            let ratio = f.length / e.length.max(1e-9);
            assert!(
                f.length >= e.length - 1e-6,
                "shorter than the shortest: {} vs {}",
                f.length,
                e.length
            );
            assert!(
                ratio <= BOUND,
                "{from:?} -> {to:?}: {} vs {} ({ratio})",
                f.length,
                e.length
            );
            Some(ratio)
        }
        (Err(a), Err(b)) => {
            assert_eq!(a, b, "{from:?} -> {to:?}");
            None
        }
        _ => panic!(
            "{from:?} -> {to:?}: A* says {:?}, the hierarchical search {:?}",
            exact.map(|p| p.length),
            fast.map(|p| p.length)
        ),
    }
}

/// Pairs of directions: near each other anywhere, across face edges, around the cube's corners,
/// and far apart.
fn pairs(rng: &mut Lcg, n: usize) -> Vec<(DVec3, DVec3)> {
    let mut out = Vec::new();
    for i in 0..n {
        let a = match i % 4 {
            // On a face edge.
            0 => {
                let axes = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z];
                let (u, v) = (axes[i / 4 % 6], axes[(i / 4 + 1) % 6]);
                (u + v + u.cross(v) * (rng.unit() * 1.6 - 0.8)).normalize()
            }
            // At a cube corner.
            1 => DVec3::new(
                if rng.unit() < 0.5 { 1.0 } else { -1.0 },
                if rng.unit() < 0.5 { 1.0 } else { -1.0 },
                if rng.unit() < 0.5 { 1.0 } else { -1.0 },
            )
            .normalize(),
            _ => rng.dir(),
        };
        let spread = if i % 4 == 3 { 0.6 } else { 0.12 };
        let b = (a + rng.dir() * spread).normalize();
        out.push((a, b));
    }
    out
}

#[test]
fn the_hierarchical_search_finds_a_walk_exactly_when_a_star_finds_a_path() {
    let g = default_grid();
    let mut rng = Lcg(3);
    let (mut found, mut none, mut worst, mut sum) = (0u32, 0, 1.0f64, 0.0);
    for (a, b) in pairs(&mut rng, 120) {
        let (Some(from), Some(to)) = (g.node_near(a, None, 8), g.node_near(b, None, 8)) else {
            continue;
        };
        match compare(g, from, to) {
            Some(r) => {
                found += 1;
                worst = worst.max(r);
                sum += r;
            }
            None => none += 1,
        }
    }
    eprintln!(
        "{found} walks (worst {worst:.4}, mean {:.4} of the shortest), {none} without",
        sum / found.max(1) as f64
    );
    assert!(
        found > 100 && sum / f64::from(found) < 1.03,
        "{found} found, mean {}",
        sum / f64::from(found)
    );
    // Nodes of the small components (pits, ledges, cave pockets): to the main component (no
    // path, known without a search) and within their own.
    let sizes = g.component_sizes();
    let main = (0..sizes.len()).max_by_key(|c| sizes[*c]).unwrap() as u32;
    let mut first_of = std::collections::HashMap::new();
    let mut within = 0;
    let n = g.node_count() as u32;
    let step = (n / 4000).max(1);
    for id in (0..n).step_by(step as usize).map(NodeId) {
        let c = g.component(id).unwrap();
        if c == main {
            continue;
        }
        let other = NodeId((u64::from(id.0) * 7919 % u64::from(n)) as u32);
        compare(g, id, other);
        if let Some(first) = first_of.insert(c, id) {
            if compare(g, first, id).is_some() {
                within += 1;
            }
        } else {
            none += 1;
        }
    }
    assert!(
        none > 20 && within > 0,
        "{none} without, {within} within small components"
    );
}

#[test]
fn with_one_way_drops_the_answer_is_still_a_star_s() {
    // Drops of 8 m, climbs of 1 m: many steps go one way only, so a local component may be
    // crossed one way only and the corridor search must fall back to the exact one.
    let agent = Agent {
        step_up: 1.0,
        ..Agent::default()
    };
    let p = default_planet();
    let g = NavGrid::build(p.density().as_ref(), p.layout(), agent).unwrap();
    let mut rng = Lcg(9);
    let (mut found, mut one_way, mut worst) = (0, 0, 1.0f64);
    for (a, b) in pairs(&mut rng, 60) {
        let (Some(from), Some(to)) = (g.node_near(a, None, 8), g.node_near(b, None, 8)) else {
            continue;
        };
        if let Some(r) = compare(&g, from, to) {
            found += 1;
            worst = worst.max(r);
        } else if find_path(&g, from, to) == Err(NoPath::OneWay) {
            one_way += 1;
        }
    }
    eprintln!("{found} walks (worst {worst:.4} of the shortest), {one_way} one way");
    assert!(found > 0 && one_way > 0, "{found} found, {one_way} one way");
}

#[test]
fn after_an_edit_the_hierarchical_search_sees_the_change() {
    let p = default_planet();
    let base = p.density().clone();
    let mut g = default_grid().clone();
    // A walk of about 300 m on land, then a wall across its middle, then a pit around its goal.
    let mut rng = Lcg(21);
    let (from, to, path) = loop {
        let a = rng.dir();
        let b = (a + rng.dir() * 0.15).normalize();
        let (Some(from), Some(to)) = (g.node_near(a, None, 0), g.node_near(b, None, 0)) else {
            continue;
        };
        let (pa, pb) = (g.position(from).unwrap(), g.position(to).unwrap());
        if (pa - pb).length() < 200.0 || pa.length() < p.terrain().sea_radius.unwrap_or(0.0) + 5.0 {
            continue;
        }
        if let Ok(path) = find_path_hierarchical(&g, from, to) {
            break (from, to, path);
        }
    };
    let mid = path.points[path.points.len() / 2];
    let wall = BrushOp::new(BrushKind::Add, mid + mid.normalize() * 4.0, 40.0, 1.0).unwrap();
    let (goal_point, goal_column) = (g.position(to).unwrap(), g.node(to).unwrap().0);
    let pit = BrushOp::new(BrushKind::Remove, goal_point, 30.0, 1.0).unwrap();
    let mut ops = Vec::new();
    for op in [wall, pit] {
        ops.push(op);
        let edited = EditedDensity::new(base.clone(), EditSnapshot::from(ops.clone()));
        g.rebuild_for(&edited, &op);
        let fresh = NavGrid::build(&edited, p.layout(), Agent::default()).unwrap();
        let (from, to) = (g.node_near(path.points[0], None, 8).unwrap(), {
            let column = g.columns().direction(goal_column);
            g.node_near(column, None, 8).unwrap()
        });
        let on_rebuilt = find_path_hierarchical(&g, from, to);
        let on_fresh = find_path(&fresh, from, to);
        assert_eq!(
            on_rebuilt.is_ok(),
            on_fresh.is_ok(),
            "{:?} vs {:?}",
            on_rebuilt.as_ref().err(),
            on_fresh.as_ref().err()
        );
        if let (Ok(r), Ok(f)) = (&on_rebuilt, &on_fresh) {
            assert_walk(&fresh, r, from, to);
            assert!(r.length >= f.length - 1e-6 && r.length <= BOUND * f.length);
            assert!(r.nodes != path.nodes, "the walk changed with the edit");
        }
    }
    let _ = (from, to);
}
