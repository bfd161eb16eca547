//! The cases of seed 000 Sec. 4.5 (Fig. 10 and 11), pinned on small planets whose terrain is
//! drawn in the Top face's grid coordinates: an overhang blocks a step, a cave is reachable only
//! through its entrance, a path crosses a face edge near a cube corner, an island has no path to
//! the mainland, and a tunnel dug through a ridge makes the path shorter.

use pmc_density::{Density, FnDensity};
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{sphere_to_face_uv, Face, Layout};
use pmc_nav::{find_path, Agent, ColumnPlace, NavGrid, NoPath, NodeId};
use std::sync::Arc;

/// 16 columns per face side (about 16 m apart at the ground), 2 m layers from 100 m to 164 m.
fn layout() -> Layout {
    Layout::new(2, 8, 100.0, 2.0, 4).unwrap()
}

/// Ground radius of the plain planet.
const GROUND: f64 = 130.0;

/// A point's place in the Top face's grid (continuous `i`, `j` in `0..=16`) and radius, or `None`
/// off the Top face.
fn top_grid(p: DVec3) -> Option<(f64, f64, f64)> {
    let (face, u, v) = sphere_to_face_uv(p)?;
    (face == Face::Top).then(|| ((u + 1.0) * 8.0, (v + 1.0) * 8.0, p.length()))
}

/// A density drawn on the Top face: `solid(i, j, r)` gives a signed density there (positive
/// solid); elsewhere the plain ground.
fn terrain(solid: impl Fn(f64, f64, f64) -> f64 + Send + Sync + 'static) -> Arc<dyn Density> {
    Arc::new(FnDensity(move |p: DVec3| match top_grid(p) {
        Some((i, j, r)) => solid(i, j, r),
        None => GROUND - p.length(),
    }))
}

fn grid(d: &dyn Density) -> NavGrid {
    NavGrid::build(d, &layout(), Agent::default()).unwrap()
}

/// Column index of Top face grid point `(i, j)`.
fn column(g: &NavGrid, i: i64, j: i64) -> u32 {
    let c = g.columns();
    c.index_of_lattice(c.lattice(ColumnPlace { face: Face::Top, i, j }))
}

/// The nodes of Top column `(i, j)`, lowest first.
fn nodes(g: &NavGrid, i: i64, j: i64) -> Vec<(NodeId, pmc_nav::Node)> {
    g.column_nodes(column(g, i, j)).collect()
}

/// The highest node of Top column `(i, j)`.
fn top_node(g: &NavGrid, i: i64, j: i64) -> NodeId {
    nodes(g, i, j).last().expect("a node").0
}

#[test]
fn an_overhang_blocks_a_step_that_is_open_without_it() {
    // A 5 m cliff up from column 8 to column 9 (along i).
    let cliff = |i: f64, r: f64| if i >= 8.5 { 135.0 - r } else { GROUND - r };
    let open = terrain(move |i, _, r| cliff(i, r));
    // The same cliff with a slab jutting out over column 8 at 133..137 m.
    let roofed = terrain(move |i, _, r| {
        let slab = (r - 133.0).min(137.0 - r).min(i - 7.5);
        cliff(i, r).max(slab)
    });
    for (d, walkable) in [(open, true), (roofed, false)] {
        let g = grid(d.as_ref());
        let (from, to) = (column(&g, 8, 8), column(&g, 9, 8));
        let (id, ground) = nodes(&g, 8, 8)[0];
        assert!((ground.radius - GROUND).abs() < 1e-9, "{ground:?}");
        let steps: Vec<_> = g.steps_into(from, ground, to).collect();
        assert_eq!(!steps.is_empty(), walkable, "{steps:?}");
        if walkable {
            let s = steps[0];
            assert_eq!(s.to, top_node(&g, 9, 8));
            assert!(s.cost > 5.0);
        } else {
            // The slab's top is a floor of its own, above the ground of column 8.
            assert_eq!(nodes(&g, 8, 8).len(), 2);
            // Under the overhang the ground still joins its other neighbours.
            assert!(g.steps(id).iter().any(|s| s.to == top_node(&g, 7, 8)));
            // And the cliff top is still reached, around the slab.
            let path = find_path(&g, id, top_node(&g, 9, 8)).expect("a way around");
            assert!(path.nodes.len() > 2);
        }
    }
}

/// A one-column-wide tunnel along `i` at row `j = 8`, floor 118 m, 8.5 m high (2 m layers: rock at 128 m closes its roof), under columns
/// 4..12, reached by a ramp rising 6 m per column from column 4 to the ground at column 2 (when
/// `entrance`).
fn cave(entrance: bool) -> Arc<dyn Density> {
    terrain(move |i, j, r| {
        let floor = if (4.0..=12.0).contains(&i) {
            118.0
        } else if entrance && (1.5..4.0).contains(&i) {
            118.0 + (4.0 - i) * 6.0
        } else {
            return GROUND - r;
        };
        let inside = (r - floor).min(floor + 8.5 - r).min((0.5 - (j - 8.0).abs()) * 12.0);
        (GROUND - r).min(-inside)
    })
}

#[test]
fn a_cave_floor_is_walkable_and_reached_only_through_its_entrance() {
    let g = grid(cave(true).as_ref());
    let column_nodes = nodes(&g, 8, 8);
    assert_eq!(column_nodes.len(), 2, "a cave floor under the ground: {column_nodes:?}");
    let (floor, ground) = (column_nodes[0], column_nodes[1]);
    assert!((floor.1.radius - 118.0).abs() < 1e-9 && (ground.1.radius - GROUND).abs() < 1e-9);
    let path = find_path(&g, ground.0, floor.0).expect("through the entrance");
    let through: Vec<ColumnPlace> = path
        .nodes
        .iter()
        .map(|n| g.columns().place_of(g.node(*n).unwrap().0))
        .collect();
    assert!(through.iter().any(|p| p.i == 3 && p.j == 8), "the ramp: {through:?}");
    // Out to the ramp and back: at least the straight lines through it.
    let ramp = g.position(top_node(&g, 3, 8)).unwrap();
    let (p0, p1) = (g.position(ground.0).unwrap(), g.position(floor.0).unwrap());
    let via = (ramp - p0).length() + (p1 - ramp).length();
    assert!(path.length >= via, "{} < {via}", path.length);
    assert!(via > 4.0 * (p1 - p0).length(), "the detour is long: {via}");

    // With the entrance sealed the cave is a detached grid, known without a search.
    let sealed = grid(cave(false).as_ref());
    let column_nodes = nodes(&sealed, 8, 8);
    let (floor, ground) = (column_nodes[0].0, column_nodes[1].0);
    assert_ne!(sealed.component(floor), sealed.component(ground));
    assert!(matches!(
        find_path(&sealed, ground, floor),
        Err(NoPath::DifferentComponents { .. })
    ));
}

#[test]
fn an_island_has_no_path_to_the_mainland() {
    // A round island of radius 3 columns around (8, 8), a moat 20 m deep around it.
    let d = terrain(|i, j, r| {
        let q = ((i - 8.0).powi(2) + (j - 8.0).powi(2)).sqrt();
        if (3.0..5.5).contains(&q) {
            110.0 - r
        } else {
            GROUND - r
        }
    });
    let g = grid(d.as_ref());
    let island = top_node(&g, 8, 8);
    let mainland = top_node(&g, 1, 1);
    let far = top_node(&g, 15, 2);
    assert_ne!(g.component(island), g.component(mainland));
    assert_eq!(g.component(mainland), g.component(far));
    match find_path(&g, island, mainland) {
        Err(NoPath::DifferentComponents { from, to }) => {
            assert_eq!((Some(from), Some(to)), (g.component(island), g.component(mainland)))
        }
        other => panic!("{other:?}"),
    }
    assert!(find_path(&g, mainland, far).is_ok());
    // Components partition the nodes.
    let total: u32 = g.component_sizes().iter().sum();
    assert_eq!(total as usize, g.node_count());
}

#[test]
fn a_path_crosses_a_face_edge_next_to_a_cube_corner() {
    let sphere = pmc_density::Sphere { radius: GROUND };
    let g = grid(&sphere);
    let corner = DVec3::new(1.0, 1.0, -1.0).normalize();
    // On the East face (+X) and the North face (-Z), either side of their shared edge, just below
    // the corner they share with Top.
    let a = g.node_near(DVec3::new(1.0, 0.8, -0.6), None, 0).unwrap();
    let b = g.node_near(DVec3::new(0.6, 0.8, -1.0), None, 0).unwrap();
    let path = find_path(&g, a, b).unwrap();
    let faces: std::collections::BTreeSet<usize> = path
        .nodes
        .iter()
        .map(|n| g.columns().place_of(g.node(*n).unwrap().0).face.index())
        .collect();
    assert!(faces.len() >= 2, "the path crosses a face edge: {faces:?}");
    let nearest = path
        .points
        .iter()
        .map(|p| p.normalize().angle_between(corner))
        .fold(f64::INFINITY, f64::min);
    // Within two columns (about 0.1 rad at 16 columns per face side) of the corner.
    assert!(nearest < 0.2, "{nearest}");
    // On the sphere the walk is close to the great circle.
    let arc = GROUND * path.points[0].angle_between(*path.points.last().unwrap());
    assert!(
        path.length >= arc * 0.999 && path.length < arc * 1.5,
        "{} vs {arc}",
        path.length
    );
}

#[test]
fn a_tunnel_dug_through_a_ridge_makes_the_path_shorter() {
    // A ridge 20 m high (too steep to climb) across rows 2..14 at column 8.
    let ridge = terrain(|i, j, r| {
        if (7.5..8.5).contains(&i) && (2.0..14.0).contains(&j) {
            150.0 - r
        } else {
            GROUND - r
        }
    });
    let mut g = grid(ridge.as_ref());
    let (a, b) = (top_node(&g, 5, 8), top_node(&g, 11, 8));
    let around = find_path(&g, a, b).expect("around the ridge's end");
    // Dig through the ridge at ground level.
    let at = g.position(top_node(&g, 8, 8)).unwrap().normalize() * (GROUND + 4.0);
    let op = BrushOp::new(BrushKind::Remove, at, 8.0, 1.0).unwrap();
    let dug = EditedDensity::new(ridge.clone(), EditSnapshot::from(vec![op]));
    let rebuilt = g.rebuild_for(&dug, &op);
    assert!(
        !rebuilt.is_empty() && rebuilt.len() < g.tile_keys().len(),
        "{rebuilt:?}"
    );
    let (a, b) = (top_node(&g, 5, 8), top_node(&g, 11, 8));
    let through = find_path(&g, a, b).expect("through the tunnel");
    assert!(
        through.length < 0.6 * around.length,
        "{} through vs {} around",
        through.length,
        around.length
    );
    // Rebuilding only the touched tiles gives the grid a full build gives.
    let fresh = grid(&dug);
    assert_eq!(fresh.node_count(), g.node_count());
    assert_eq!(fresh.component_sizes(), g.component_sizes());
    let again = find_path(&fresh, top_node(&fresh, 5, 8), top_node(&fresh, 11, 8)).unwrap();
    assert_eq!(again.length, through.length);
}
