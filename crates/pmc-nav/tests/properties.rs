//! Invariants of the navigation grid on real terrain (the presets, small layouts, random seeds and
//! edits): nodes are exactly the surface voxels with head room, sampled as the mesher samples;
//! steps are symmetric for a symmetric agent; A* finds the shortest path; a rebuild after an
//! edit equals a fresh build.

use pmc_density::Density;
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, Layout};
use pmc_nav::{find_path, Agent, NavGrid, NoPath, NodeId};
use pmc_planet::{Planet, PresetKind};
use proptest::prelude::*;
use std::collections::BinaryHeap;

fn layout() -> Layout {
    Layout::new(2, 8, 100.0, 2.0, 2).unwrap()
}

fn planet(kind: PresetKind, seed: u64) -> Planet {
    Planet::new(kind, seed, layout())
}

/// Every node id of the grid.
fn all_nodes(g: &NavGrid) -> impl Iterator<Item = NodeId> {
    (0..g.node_count() as u32).map(NodeId)
}

/// Dijkstra's shortest distance (the reference for A*).
fn dijkstra(g: &NavGrid, from: NodeId, to: NodeId) -> Option<f64> {
    #[derive(PartialEq)]
    struct E(f64, u32);
    impl Eq for E {}
    impl Ord for E {
        fn cmp(&self, o: &Self) -> std::cmp::Ordering {
            o.0.total_cmp(&self.0)
        }
    }
    impl PartialOrd for E {
        fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(o))
        }
    }
    let mut dist = vec![f64::INFINITY; g.node_count()];
    let mut heap = BinaryHeap::from([E(0.0, from.0)]);
    dist[from.0 as usize] = 0.0;
    while let Some(E(d, n)) = heap.pop() {
        if n == to.0 {
            return Some(d);
        }
        if d > dist[n as usize] {
            continue;
        }
        for s in g.steps(NodeId(n)) {
            let nd = d + s.cost;
            if nd < dist[s.to.0 as usize] {
                dist[s.to.0 as usize] = nd;
                heap.push(E(nd, s.to.0));
            }
        }
    }
    None
}

#[test]
fn nodes_are_exactly_the_surface_voxels_with_head_room_sampled_as_the_mesher_samples() {
    let p = planet(PresetKind::Earthlike, 5);
    let g = NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap();
    let l = *p.layout();
    let depth = l.depth_tiles();
    let clearance = (Agent::default().clearance / l.l_d()).ceil() as i64;
    let mut checked = 0;
    let mut cave_floors = 0;
    for key in l.chunks(0) {
        let grid = ChunkGrid::new(&l, key);
        let mut d = vec![0.0f32; grid.sample_count()];
        p.density().sample_shell(&grid.dirs, &grid.radii, &mut d);
        for b in 1..grid.padded - 1 {
            for a in 1..grid.padded - 1 {
                let column = g.columns().index_of_lattice(grid.lattice[b * grid.padded + a]);
                for c in 1..grid.padded - 1 {
                    let k = grid.k0 + (c as i64 - 1);
                    let want = if k == 0 {
                        true
                    } else if k == depth {
                        false
                    } else {
                        d[grid.index(a, b, c)] > 0.0
                    };
                    assert_eq!(g.is_filled(column, k), want, "{key} ({a}, {b}, {c})");
                    checked += 1;
                }
                // Nodes: every surface voxel whose clearance is air, and nothing else.
                let want: Vec<u32> = (0..depth)
                    .filter(|k| g.is_filled(column, *k) && (k + 1..=k + clearance).all(|x| !g.is_filled(column, x)))
                    .map(|k| k as u32)
                    .collect();
                let got: Vec<u32> = g.column_nodes(column).map(|(_, n)| n.layer).collect();
                assert_eq!(got, want, "column {column}");
                cave_floors += got.len().saturating_sub(1);
                for (_, n) in g.column_nodes(column) {
                    let (lo, hi) = (
                        l.layer_radius(i64::from(n.layer)),
                        l.layer_radius(i64::from(n.layer) + 1),
                    );
                    assert!(n.radius >= lo && n.radius <= hi, "{n:?}");
                }
            }
        }
    }
    assert_eq!(
        checked,
        l.chunk_count() as usize * 9 * 9 * 9,
        "every voxel of every chunk"
    );
    assert!(
        cave_floors > 0,
        "the earthlike caves give columns with more than one floor"
    );
}

#[test]
fn components_partition_the_nodes_and_steps_stay_inside_them() {
    let p = planet(PresetKind::Moon, 2);
    let g = NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap();
    let total: u32 = g.component_sizes().iter().sum();
    assert_eq!(total as usize, g.node_count());
    for id in all_nodes(&g) {
        for s in g.steps(id) {
            assert_eq!(g.component(id), g.component(s.to));
        }
    }
    assert!(
        g.component_sizes().iter().any(|s| *s as usize > g.node_count() / 2),
        "one main grid"
    );
}

/// The components are exactly the nodes joined by steps (either way), labelled in order of
/// their first node: no two components a step joins, and no component whose nodes no steps
/// join (a union-find over every node's steps is the reference).
#[test]
fn components_are_exactly_the_nodes_joined_by_steps() {
    for (kind, seed) in [
        (PresetKind::Moon, 2),
        (PresetKind::Mars, 88),
        (PresetKind::Earthlike, 7),
    ] {
        let p = planet(kind, seed);
        let g = NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap();
        let n = g.node_count();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn find(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        for id in all_nodes(&g) {
            for s in g.steps(id) {
                let (a, b) = (find(&mut parent, id.0), find(&mut parent, s.to.0));
                parent[a.max(b) as usize] = a.min(b);
            }
        }
        let mut label = vec![u32::MAX; n];
        let mut next = 0;
        for id in all_nodes(&g) {
            let r = find(&mut parent, id.0) as usize;
            if label[r] == u32::MAX {
                label[r] = next;
                next += 1;
            }
            assert_eq!(g.component(id), Some(label[r]), "{kind:?} seed {seed}, {id:?}");
        }
        assert_eq!(g.component_sizes().len(), next as usize, "{kind:?} seed {seed}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    fn steps_are_symmetric_and_a_star_is_shortest(seed in 0u64..1000, picks in proptest::collection::vec((0.0f64..1.0, 0.0f64..1.0), 6)) {
        let kind = [PresetKind::Earthlike, PresetKind::Mars, PresetKind::Moon][(seed % 3) as usize];
        let p = planet(kind, seed);
        let g = NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap();
        for id in all_nodes(&g) {
            for s in g.steps(id) {
                let back = g.steps(s.to);
                let b = back.iter().find(|b| b.to == id);
                prop_assert!(b.is_some(), "a step {id:?} -> {:?} has no way back", s.to);
                prop_assert!((b.unwrap().cost - s.cost).abs() < 1e-9);
            }
        }
        let n = g.node_count() as f64;
        for (a, b) in picks {
            let (from, to) = (NodeId((a * n) as u32), NodeId((b * n) as u32));
            match find_path(&g, from, to) {
                Ok(path) => {
                    let reference = dijkstra(&g, from, to).expect("Dijkstra finds it too");
                    prop_assert!((path.length - reference).abs() < 1e-6 * reference.max(1.0), "{} vs {reference}", path.length);
                    prop_assert_eq!(path.nodes.first(), Some(&from));
                    prop_assert_eq!(path.nodes.last(), Some(&to));
                    let mut sum = 0.0;
                    for w in path.nodes.windows(2) {
                        let s = g.steps(w[0]).into_iter().find(|s| s.to == w[1]);
                        prop_assert!(s.is_some(), "consecutive path nodes are steps");
                        sum += s.unwrap().cost;
                    }
                    prop_assert!((sum - path.length).abs() < 1e-6);
                }
                Err(NoPath::DifferentComponents { .. }) => {
                    prop_assert_ne!(g.component(from), g.component(to));
                    prop_assert!(dijkstra(&g, from, to).is_none());
                }
                Err(NoPath::OneWay) => prop_assert!(false, "a symmetric agent has no one-way steps"),
                Err(other) => prop_assert!(false, "the whole-planet grid answers {other:?}"),
            }
        }
    }

    #[test]
    fn a_rebuild_after_edits_equals_a_fresh_build(seed in 0u64..1000, edits in proptest::collection::vec((0.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, 3.0f64..14.0, any::<bool>()), 1..4)) {
        let p = planet(PresetKind::Earthlike, seed);
        let base = p.density().clone();
        let mut g = NavGrid::build(base.as_ref(), p.layout(), Agent::default()).unwrap();
        let mut ops = Vec::new();
        for (face_pick, x, y, radius, add) in edits {
            // Centres near the ground, anywhere, including face edges and corners.
            let dir = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z][(face_pick * 6.0) as usize % 6];
            let t = dir.any_orthogonal_vector();
            let s = dir.cross(t);
            let c = (dir + t * x + s * y).normalize() * (p.terrain().sea_radius.unwrap_or(120.0) + 1.0);
            let kind = if add { BrushKind::Add } else { BrushKind::Remove };
            let op = BrushOp::new(kind, c, radius, 1.0).unwrap();
            ops.push(op);
            let edited = EditedDensity::new(base.clone(), EditSnapshot::from(ops.clone()));
            g.rebuild_for(&edited, &op);
        }
        let edited = EditedDensity::new(base.clone(), EditSnapshot::from(ops.clone()));
        let fresh = NavGrid::build(&edited, p.layout(), Agent::default()).unwrap();
        prop_assert_eq!(fresh.node_count(), g.node_count());
        for id in all_nodes(&g) {
            prop_assert_eq!(fresh.node(id), g.node(id));
            prop_assert_eq!(fresh.component(id), g.component(id));
        }
        prop_assert_eq!(fresh.component_sizes(), g.component_sizes());
    }
}

#[test]
fn one_way_drops_are_reported_as_such() {
    // An agent that can drop 8 m but climb none: going down a slope works, coming back does not.
    let agent = Agent {
        step_up: 0.0,
        ..Agent::default()
    };
    let p = planet(PresetKind::Earthlike, 5);
    let g = NavGrid::build(p.density().as_ref(), p.layout(), agent).unwrap();
    let mut found_one_way = false;
    'outer: for id in all_nodes(&g) {
        for s in g.steps(id) {
            let (_, a) = g.node(id).unwrap();
            let (_, b) = g.node(s.to).unwrap();
            if b.radius < a.radius - 1e-6 {
                assert!(find_path(&g, id, s.to).is_ok());
                match find_path(&g, s.to, id) {
                    Err(NoPath::OneWay) => {
                        found_one_way = true;
                        break 'outer;
                    }
                    Ok(path) => assert!(path.nodes.len() > 2, "not straight back up"),
                    Err(e) => panic!("{e:?}: a step joins them, so they share a component"),
                }
            }
        }
    }
    assert!(found_one_way);
}

#[test]
fn invalid_agents_and_huge_layouts_are_refused() {
    let sphere = pmc_density::Sphere { radius: 120.0 };
    for bad in [
        Agent {
            clearance: 0.0,
            ..Agent::default()
        },
        Agent {
            clearance: f64::NAN,
            ..Agent::default()
        },
        Agent {
            step_up: -1.0,
            ..Agent::default()
        },
        Agent {
            step_down: f64::INFINITY,
            ..Agent::default()
        },
        Agent {
            max_slope: 0.0,
            ..Agent::default()
        },
        Agent {
            max_slope: 91.0,
            ..Agent::default()
        },
    ] {
        assert!(NavGrid::build(&sphere, &layout(), bad).is_err(), "{bad:?}");
    }
    let huge = Layout::new(128, 32, 1000.0, 1.0, 1).unwrap();
    let e = NavGrid::build(&sphere, &huge, Agent::default()).unwrap_err();
    assert!(e.to_string().contains("columns"), "{e}");
}

#[test]
fn nodes_near_a_point_are_exactly_those_within_range() {
    let p = planet(PresetKind::Earthlike, 9);
    let g = NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap();
    // Points on faces, on a face edge and at a cube corner, at and above the ground.
    let r = p.terrain().sea_radius.unwrap();
    for (dir, range) in [
        (DVec3::new(0.2, 1.0, 0.1), 30.0),
        (DVec3::new(1.0, 1.0, 0.3), 45.0),
        (DVec3::new(1.0, -1.0, 1.0), 40.0),
        (DVec3::new(-0.3, 0.1, -1.0), 5.0),
    ] {
        let point = dir.normalize() * (r + 3.0);
        let (mut got, truncated) = g.nodes_near(point, range, usize::MAX);
        assert!(!truncated);
        got.sort();
        let want: Vec<NodeId> = all_nodes(&g)
            .filter(|id| (g.position(*id).unwrap() - point).length() <= range)
            .collect();
        assert_eq!(got, want, "{dir} {range}");
        assert!(range < 10.0 || want.len() > 3, "{dir}: {} nodes", want.len());
        let (few, truncated) = g.nodes_near(point, range, 3);
        assert_eq!((few.len(), truncated), (3.min(want.len()), want.len() > 3));
    }
}
