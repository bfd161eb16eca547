//! The lazy grid: on small planets it is the whole-planet grid (nodes, steps, path lengths), tile
//! by tile; with band sampling every floor and step it keeps is exact; on large layouts it builds
//! tiles only near the path, keeps its cache within its bound, answers "no path found within the
//! search bound" apart from "no path exists", and forgets exactly the tiles an edit changes.

use pmc_density::{Density, FnDensity};
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{Face, LatLon, Layout};
use pmc_nav::{
    find_path, Agent, ColumnPlace, End, LazyGrid, LazyOptions, NavGrid, NoPath, NodeId, NodeKey, PathAnswer,
    SearchOptions,
};
use pmc_planet::{Planet, PresetKind};
use proptest::prelude::*;
use std::collections::BTreeSet;
use std::sync::Arc;

/// Exact searches with room enough to exhaust a small planet.
fn exact() -> SearchOptions {
    SearchOptions {
        max_expanded: usize::MAX,
        max_tiles_built: usize::MAX,
        weight: 1.0,
    }
}

/// Every canonical column place of a layout.
fn places(l: &Layout) -> Vec<ColumnPlace> {
    let c = pmc_nav::Columns::new(l);
    let n = l.face_tiles();
    let mut out = Vec::new();
    for face in Face::ALL {
        for j in 0..=n {
            for i in 0..=n {
                let p = ColumnPlace { face, i, j };
                if c.is_canonical(p) {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// The lazy key of a node of the whole-planet grid.
fn key_of(g: &NavGrid, id: NodeId) -> NodeKey {
    let (column, node) = g.node(id).unwrap();
    NodeKey {
        column: g.columns().place_of(column),
        layer: node.layer,
    }
}

/// The steps of a lazy node, as a sorted list of (node reached, cost bits).
fn lazy_steps(g: &mut LazyGrid, key: NodeKey) -> Vec<(NodeKey, u64)> {
    let mut s: Vec<(NodeKey, u64)> = g.steps(key).into_iter().map(|(k, c)| (k, c.to_bits())).collect();
    s.sort();
    s
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    fn on_small_planets_the_lazy_grid_is_the_whole_planet_grid(
        seed in 0u64..1000,
        side in prop::sample::select(vec![0u32, 1, 3, 4, 5, 16]),
        picks in proptest::collection::vec((0.0f64..1.0, 0.0f64..1.0), 5),
    ) {
        let kind = [PresetKind::Earthlike, PresetKind::Mars, PresetKind::Moon][(seed % 3) as usize];
        let planet = Planet::new(kind, seed, Layout::new(2, 8, 100.0, 2.0, 2).unwrap());
        let eager = NavGrid::build(planet.density().as_ref(), planet.layout(), Agent::default()).unwrap();
        let options = LazyOptions { tile_side: side, ..LazyOptions::default() };
        let mut lazy = LazyGrid::new(planet.density().clone(), planet.layout(), Agent::default(), options).unwrap();
        prop_assert!(lazy.samples_whole_window());
        // Nodes: the same floors, the same surface points to the bit.
        for place in places(planet.layout()) {
            let column = eager.columns().index_of(place);
            let want: Vec<_> = eager.column_nodes(column).map(|(_, n)| n).collect();
            let got: Vec<_> = lazy.column_nodes(place).into_iter().map(|(_, n)| n).collect();
            prop_assert_eq!(got, want, "{:?}", place);
        }
        // Steps: the same nodes reached at the same costs.
        for id in (0..eager.node_count() as u32).map(NodeId) {
            let mut want: Vec<(NodeKey, u64)> =
                eager.steps(id).iter().map(|s| (key_of(&eager, s.to), s.cost.to_bits())).collect();
            want.sort();
            prop_assert_eq!(lazy_steps(&mut lazy, key_of(&eager, id)), want);
        }
        // Paths: the same lengths; different components are a closed region of the lazy grid.
        let n = eager.node_count() as f64;
        for (a, b) in picks {
            let (from, to) = (NodeId((a * n) as u32), NodeId((b * n) as u32));
            let (lazy_path, _) = lazy.find_path(key_of(&eager, from), key_of(&eager, to), &exact());
            match (find_path(&eager, from, to), lazy_path) {
                (Ok(e), Ok(l)) => {
                    prop_assert!((e.length - l.length).abs() <= 1e-9 * e.length.max(1.0), "{} vs {}", e.length, l.length);
                    prop_assert_eq!(l.nodes.first(), Some(&key_of(&eager, from)));
                    prop_assert_eq!(l.nodes.last(), Some(&key_of(&eager, to)));
                    for w in l.nodes.windows(2) {
                        prop_assert!(lazy.steps(w[0]).iter().any(|(k, _)| *k == w[1]), "a walk of steps");
                    }
                }
                (Err(NoPath::DifferentComponents { .. }), Err(NoPath::Enclosed { nodes, .. })) => {
                    prop_assert!(nodes > 0);
                }
                (e, l) => prop_assert!(false, "whole-planet {:?}, lazy {:?}", e.map(|p| p.length), l.map(|p| p.length)),
            }
        }
    }

    #[test]
    fn a_band_keeps_every_floor_and_step_in_it_exactly(
        seed in 0u64..1000,
        below in 2u32..40,
        probe in 1u32..24,
        side in prop::sample::select(vec![0u32, 2, 5]),
    ) {
        // 128 layers of 1 m: sampled in bands when the whole window is refused.
        let kind = [PresetKind::Earthlike, PresetKind::Mars, PresetKind::Moon][(seed % 3) as usize];
        let planet = Planet::new(kind, seed, Layout::new(2, 8, 200.0, 1.0, 16).unwrap());
        let eager = NavGrid::build(planet.density().as_ref(), planet.layout(), Agent::default()).unwrap();
        let options = LazyOptions { tile_side: side, full_window: 0, below, probe, ..LazyOptions::default() };
        let mut lazy = LazyGrid::new(planet.density().clone(), planet.layout(), Agent::default(), options).unwrap();
        prop_assert!(!lazy.samples_whole_window());
        let above = lazy.band_above();
        let mut columns = 0;
        let mut found_ground = 0;
        for place in places(planet.layout()) {
            let column = eager.columns().index_of(place);
            let want: Vec<_> = eager.column_nodes(column).map(|(_, n)| n).collect();
            let got: Vec<_> = lazy.column_nodes(place).into_iter().map(|(_, n)| n).collect();
            let (base, len) = lazy.column_band(place).unwrap();
            prop_assert!(len as i64 <= i64::from(below) + above + 1);
            // Within the band: exactly the whole grid's occupancy and floors.
            for k in base..base + i64::from(len) {
                prop_assert_eq!(lazy.is_filled(place, k), Some(eager.is_filled(column, k)));
            }
            let inside: Vec<_> = want
                .iter()
                .copied()
                .filter(|n| i64::from(n.layer) >= base && i64::from(n.layer) + 1 < base + i64::from(len))
                .collect();
            prop_assert_eq!(&got, &inside, "{:?}, band {}+{}", place, base, len);
            columns += 1;
            if want.last() == got.last() {
                found_ground += 1;
            }
        }
        // The band is around the top: the highest floor (the ground seen from above) is kept
        // nearly everywhere (not where it is thin rock floating over air the probes miss).
        prop_assert!(found_ground * 100 >= columns * 97, "{found_ground} of {columns}");
        // Steps between floors kept: exactly the whole grid's.
        for id in (0..eager.node_count() as u32).map(NodeId) {
            let key = key_of(&eager, id);
            if lazy.node(key).is_none() {
                continue;
            }
            let mut want: Vec<(NodeKey, u64)> = eager
                .steps(id)
                .iter()
                .map(|s| (key_of(&eager, s.to), s.cost.to_bits()))
                .filter(|(k, _)| lazy.node(*k).is_some())
                .collect();
            want.sort();
            prop_assert_eq!(lazy_steps(&mut lazy, key), want);
        }
    }
}

/// An earthlike planet of radius 300 km with 1 m layers: 1.6 trillion columns, 32 768 layers.
fn big() -> (Planet, Layout) {
    let r = 300_000.0;
    let layout = Layout::new(1 << 14, 32, r - 16_384.0, 1.0, 1 << 10).unwrap();
    (Planet::new(PresetKind::Earthlike, 3, layout), layout)
}

fn at(lat: f64, lon: f64) -> End {
    End {
        dir: LatLon { lat, lon }.to_unit(),
        radius: None,
    }
}

#[test]
fn on_a_large_planet_tiles_are_built_only_near_the_path() {
    let (planet, layout) = big();
    let mut g = LazyGrid::new(
        planet.density().clone(),
        &layout,
        Agent::default(),
        LazyOptions::default(),
    )
    .unwrap();
    assert!(!g.samples_whole_window());
    // About 330 m of walking over rough ground, heading straight for the goal.
    let options = SearchOptions {
        weight: 2.0,
        ..SearchOptions::default()
    };
    let found = g.query(at(-49.0, -106.0), at(-48.95, -105.97), 8, &options);
    let PathAnswer::Found(path) = &found.answer else {
        panic!("{:?}", found.answer)
    };
    assert!(path.length > 250.0, "{}", path.length);
    let side = g.tile_side();
    let path_tiles: BTreeSet<_> = path.nodes.iter().map(|k| g.tile_of(k.column)).collect();
    let built = g.cached_tiles();
    assert_eq!(
        built.len(),
        found.stats.tiles_built,
        "nothing evicted, nothing else built"
    );
    // Few: a handful of tiles for each tile the path crosses, of the planet's 6 x 131 072^2.
    assert!(
        built.len() <= 6 * path_tiles.len(),
        "{} tiles built for a path through {}",
        built.len(),
        path_tiles.len()
    );
    // Near: every tile built lies within four tiles of one the path crosses (the columns beside
    // the nodes expanded, and the few the search backward from the goal looked at).
    for t in &built {
        let near = path_tiles.iter().any(|p| {
            p.face == t.face
                && (i64::from(p.i) - i64::from(t.i)).abs() <= 4
                && (i64::from(p.j) - i64::from(t.j)).abs() <= 4
        });
        assert!(near, "{t:?} is far from the path ({side} columns a tile)");
    }
    // The path is a walk of steps, and the cache gives the same path again without building.
    for w in path.nodes.windows(2) {
        assert!(g.steps(w[0]).iter().any(|(k, _)| *k == w[1]));
    }
    let again = g.query(at(-49.0, -106.0), at(-48.95, -105.97), 8, &options);
    assert_eq!(again.answer, found.answer);
    assert_eq!(again.stats.tiles_built, 0);
}

#[test]
fn the_cache_stays_within_its_bound_and_tiles_built_again_are_the_same() {
    let (planet, layout) = big();
    let options = SearchOptions {
        weight: 2.0,
        ..SearchOptions::default()
    };
    let (a, b) = (at(-60.0, 79.0), at(-59.97, 79.02));
    let mut roomy = LazyGrid::new(
        planet.density().clone(),
        &layout,
        Agent::default(),
        LazyOptions::default(),
    )
    .unwrap();
    let want = roomy.query(a, b, 8, &options);
    assert!(matches!(want.answer, PathAnswer::Found(_)), "{:?}", want.answer);
    let one_tile = roomy.cache_stats().bytes / roomy.cache_stats().tiles;
    // Room for about twenty tiles: the search drops and builds tiles again as it goes.
    let bound = 20 * one_tile;
    let small = LazyOptions {
        cache_bytes: bound,
        ..LazyOptions::default()
    };
    let mut tight = LazyGrid::new(planet.density().clone(), &layout, Agent::default(), small).unwrap();
    let got = tight.query(a, b, 8, &options);
    let stats = tight.cache_stats();
    assert!(stats.bytes <= bound, "{stats:?}");
    assert!(
        stats.evicted > 0 && stats.built as usize > roomy.cache_stats().tiles,
        "{stats:?}"
    );
    assert_eq!(got.answer, want.answer, "the same path from tiles built again");
    assert!(got.stats.tiles_built > want.stats.tiles_built);
}

/// A sphere of radius 100 km (1 m layers) with an island: ground at 100 km, a moat 30 m deep
/// from 15 to 25 m around the column along `centre`. No radial bounds: the whole shell is the
/// window, sampled in bands.
fn island(centre: DVec3) -> (Arc<dyn Density>, Layout) {
    const R: f64 = 100_000.0;
    let c = centre.normalize();
    let d = FnDensity(move |p: DVec3| {
        let r = p.length();
        let s = (p / r).angle_between(c) * R;
        let ground = if (15.0..25.0).contains(&s) { R - 30.0 } else { R };
        ground - r
    });
    (Arc::new(d), Layout::new(1 << 12, 32, R - 1000.0, 1.0, 64).unwrap())
}

#[test]
fn no_path_is_proven_by_exhausting_a_closed_region_and_a_bound_is_reported_as_such() {
    let centre = DVec3::new(0.2, 1.0, 0.1);
    let (d, layout) = island(centre);
    let mut g = LazyGrid::new(d, &layout, Agent::default(), LazyOptions::default()).unwrap();
    assert!(!g.samples_whole_window());
    let on_island = End {
        dir: centre,
        radius: None,
    };
    // 60 m away on the mainland.
    let across = centre.normalize().cross(DVec3::X).normalize();
    let mainland = End {
        dir: centre.normalize() + across * (60.0 / 100_000.0),
        radius: None,
    };
    let options = SearchOptions::default();
    // From the island: A* runs out of nodes, every one the start can reach.
    let out = g.query(on_island, mainland, 8, &options);
    let PathAnswer::NoPath(NoPath::Enclosed {
        nodes,
        start_side: true,
    }) = out.answer
    else {
        panic!("{:?}", out.answer)
    };
    // The island: a disc of radius 15 m, about 1.2 m between columns.
    assert!((300..=900).contains(&nodes), "{nodes}");
    assert!(out.answer.reason().unwrap().contains("can reach only"));
    // To the island: the search backward from the goal runs out first, long before the bound.
    let back = g.query(mainland, on_island, 8, &options);
    let PathAnswer::NoPath(NoPath::Enclosed {
        nodes: inner,
        start_side: false,
    }) = back.answer
    else {
        panic!("{:?}", back.answer)
    };
    assert_eq!(inner, nodes, "the same island, walked backward");
    assert!(back.stats.expanded < options.max_expanded / 100, "{:?}", back.stats);
    // Across the mainland, around the moat: found.
    let far = End {
        dir: centre.normalize() - across * (60.0 / 100_000.0),
        radius: None,
    };
    let around = g.query(mainland, far, 8, &options);
    let PathAnswer::Found(path) = &around.answer else {
        panic!("{:?}", around.answer)
    };
    assert!(path.length > 120.0, "{}", path.length);
    // The same query within bounds too tight to get there: the bound, in words and in kind.
    for tight in [
        SearchOptions {
            max_expanded: 50,
            ..options
        },
        SearchOptions {
            max_tiles_built: 3,
            ..options
        },
    ] {
        let mut fresh = LazyGrid::new(g_density(centre), &layout, Agent::default(), LazyOptions::default()).unwrap();
        let stopped = fresh.query(mainland, far, 8, &tight);
        let PathAnswer::NoPath(NoPath::SearchBound { expanded, .. }) = stopped.answer else {
            panic!("{:?}", stopped.answer)
        };
        assert!(expanded <= tight.max_expanded);
        let reason = stopped.answer.reason().unwrap();
        assert!(reason.contains("within the search bound"), "{reason}");
        assert_eq!(stopped.answer.cause(), Some("search_bound"));
    }
}

fn g_density(centre: DVec3) -> Arc<dyn Density> {
    island(centre).0
}

#[test]
fn an_edit_forgets_exactly_the_tiles_it_changes() {
    let (planet, layout) = big();
    let base = planet.density().clone();
    let mut g = LazyGrid::new(base.clone(), &layout, Agent::default(), LazyOptions::default()).unwrap();
    let (a, b) = (at(-60.0, 42.0), at(-59.99, 42.01));
    let before = g.query(a, b, 8, &SearchOptions::default());
    let PathAnswer::Found(path) = &before.answer else {
        panic!("{:?}", before.answer)
    };
    // Dig a pit 6 m across in the middle of the path.
    let mid = g.position(path.nodes[path.nodes.len() / 2]).unwrap();
    let op = BrushOp::new(BrushKind::Remove, mid, 6.0, 1.0).unwrap();
    let edited: Arc<dyn Density> = Arc::new(EditedDensity::new(base.clone(), EditSnapshot::from(vec![op])));
    let cached: BTreeSet<_> = g.cached_tiles().into_iter().collect();
    let forgotten: BTreeSet<_> = g.apply_edit(edited.clone(), &op).into_iter().collect();
    let kept: BTreeSet<_> = g.cached_tiles().into_iter().collect();
    assert!(!forgotten.is_empty());
    assert_eq!(kept, cached.difference(&forgotten).copied().collect());
    // Every tile, kept or built again, equals a fresh grid's on the edited planet.
    let mut fresh = LazyGrid::new(edited, &layout, Agent::default(), LazyOptions::default()).unwrap();
    for t in cached {
        let columns = g.tile_side();
        let place = |di: i64, dj: i64| ColumnPlace {
            face: t.face,
            i: i64::from(t.i) * columns + di,
            j: i64::from(t.j) * columns + dj,
        };
        for dj in 0..columns {
            for di in 0..columns {
                assert_eq!(
                    g.column_nodes(place(di, dj)),
                    fresh.column_nodes(place(di, dj)),
                    "{t:?}"
                );
            }
        }
    }
    let after = g.query(a, b, 8, &SearchOptions::default());
    assert_eq!(after.answer, fresh.query(a, b, 8, &SearchOptions::default()).answer);
}

#[test]
fn bad_options_are_refused_and_foreign_nodes_are_no_path() {
    let layout = Layout::new(2, 8, 100.0, 2.0, 2).unwrap();
    let sphere: Arc<dyn Density> = Arc::new(pmc_density::Sphere { radius: 120.0 });
    let probe0 = LazyOptions {
        probe: 0,
        ..LazyOptions::default()
    };
    assert!(LazyGrid::new(sphere.clone(), &layout, Agent::default(), probe0).is_err());
    let bad_agent = Agent {
        clearance: -1.0,
        ..Agent::default()
    };
    assert!(LazyGrid::new(sphere.clone(), &layout, bad_agent, LazyOptions::default()).is_err());
    for bad in [
        SearchOptions {
            weight: 0.5,
            ..SearchOptions::default()
        },
        SearchOptions {
            weight: f64::NAN,
            ..SearchOptions::default()
        },
        SearchOptions {
            max_expanded: 0,
            ..SearchOptions::default()
        },
        SearchOptions {
            max_tiles_built: 0,
            ..SearchOptions::default()
        },
    ] {
        assert!(bad.validate().is_err(), "{bad:?}");
    }
    assert!(SearchOptions::default().validate().is_ok());
    let mut g = LazyGrid::new(sphere, &layout, Agent::default(), LazyOptions::default()).unwrap();
    let real = g.node_near(DVec3::Y, None, 0).unwrap();
    // A layer with no floor, and a column off the face.
    let not_a_floor = NodeKey { layer: 1, ..real };
    let off = NodeKey {
        column: ColumnPlace {
            face: Face::Top,
            i: 99,
            j: 0,
        },
        layer: real.layer,
    };
    for (from, to) in [(not_a_floor, real), (real, off)] {
        let (r, _) = g.find_path(from, to, &SearchOptions::default());
        assert!(matches!(r, Err(NoPath::Enclosed { nodes: 0, .. })), "{r:?}");
    }
    assert!(g.steps(off).is_empty() && g.node(off).is_none() && g.column_band(off.column).is_none());
}
