//! Navigation on the default planet (earthlike, seed 7, 6 x 257^2 columns, 65 layers), default
//! agent: building the whole grid, rebuilding one tile (the columns under one chunk footprint,
//! through the whole depth, with the components relabelled), rebuilding after a 4 m and a 16 m
//! remove brush, and A* from corner to corner of a face and over a shorter walk.
//!
//! `nav_lazy`: the lazy grid on the Earth at true scale (the earth preset on its own layout, seed
//! 7: 1 m layers, 6 x 8 388 608^2 columns), from a cold cache, tiles built and searched on the
//! calling thread, default agent and search options (4-column tiles, weight 1.5): between two
//! places 10 km apart on land, east of each other and north-east (across the grid's diagonal),
//! the first also with chunk-footprint tiles for comparison; and 500 m.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::{default_planet, nearest_column, surface_along, surface_point};
use pmc_density::presets::{build, PresetKind};
use pmc_density::Density;
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{LatLon, Layout};
use pmc_nav::{
    find_path, find_path_hierarchical, smooth_path, Agent, End, LazyGrid, LazyOptions, NavGrid, PathAnswer,
    SearchOptions,
};
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

fn nav(c: &mut Criterion) {
    let planet = default_planet();
    let density = planet.density().clone();
    let grid = NavGrid::build(density.as_ref(), planet.layout(), Agent::default()).expect("a grid");
    eprintln!(
        "grid: {} nodes, {} components, {} tiles",
        grid.node_count(),
        grid.component_sizes().len(),
        grid.tile_keys().len()
    );
    let mut g = c.benchmark_group("nav");
    g.sample_size(10).measurement_time(Duration::from_secs(6));
    g.bench_function("build/whole_planet", |b| {
        b.iter(|| black_box(NavGrid::build(density.as_ref(), planet.layout(), Agent::default())))
    });
    g.finish();

    let mut g = c.benchmark_group("nav");
    let mut work = grid.clone();
    let tile = work.tile_keys()[work.tile_keys().len() / 3];
    g.bench_function("rebuild/one_tile", |b| {
        b.iter(|| work.rebuild_tiles(density.as_ref(), black_box(&[tile])))
    });
    // The same tile read from the planet's base cache (warm: its chunks were meshed or read
    // before, as the chunks around a user editing always are).
    let cached = default_planet().with_base_cache(64);
    work.rebuild_tiles_from(&cached, &[tile]);
    g.bench_function("rebuild/one_tile/base_cache", |b| {
        b.iter(|| work.rebuild_tiles_from(&cached, black_box(&[tile])))
    });
    // The 4 m brush on the nearest voxel column (between columns it changes no sample), as in
    // the edit benchmark.
    let at = surface_point(&planet, 20.0, 30.0);
    let on_column = surface_along(&planet, nearest_column(planet.layout(), at));
    for (name, center, radius) in [("remove_4m_on_column", on_column, 4.0), ("remove_16m", at, 16.0)] {
        let op = BrushOp::new(BrushKind::Remove, center, radius, 1.0).expect("a brush");
        let edited = EditedDensity::new(density.clone(), EditSnapshot::from(vec![op]));
        eprintln!("{name}: {} tiles", work.tiles_for(&op).len());
        g.bench_function(
            format!("rebuild/after_{name}/tiles={}", work.tiles_for(&op).len()),
            |b| b.iter(|| black_box(work.rebuild_for(&edited, black_box(&op)))),
        );
        let cached_edited = cached.clone().with_edits(EditSnapshot::from(vec![op]));
        work.rebuild_for_from(&cached_edited, &op);
        g.bench_function(
            format!("rebuild/after_{name}/tiles={}/base_cache", work.tiles_for(&op).len()),
            |b| b.iter(|| black_box(work.rebuild_for_from(&cached_edited, black_box(&op)))),
        );
    }
    // Corner to corner of the Top face (about 4.4 km of walking), and a walk of about 500 m.
    for (name, a, b) in [
        ("across_face", DVec3::new(-0.9, 1.0, -0.9), DVec3::new(0.9, 1.0, 0.9)),
        (
            "500m",
            surface_point(&planet, 20.0, 30.0),
            surface_point(&planet, 25.0, 40.0),
        ),
    ] {
        let (from, to) = (
            grid.node_near(a, None, 8).expect("ground"),
            grid.node_near(b, None, 8).expect("ground"),
        );
        let path = find_path(&grid, from, to).expect("a path");
        eprintln!(
            "{name}: {:.0} m, {} steps, {} nodes expanded",
            path.length,
            path.nodes.len() - 1,
            path.expanded
        );
        let fast = find_path_hierarchical(&grid, from, to).expect("a path");
        let smooth = smooth_path(&grid, &fast);
        let (pa, pb) = (grid.position(from).expect("a node"), grid.position(to).expect("a node"));
        eprintln!(
            "{name} hierarchical: {:.0} m ({:.4} of the exact), {} steps, {} nodes expanded; smoothed {:.0} m in {} legs ({:.4} of the great circle at the ends' mean radius, {:.0} m)",
            fast.length,
            fast.length / path.length,
            fast.nodes.len() - 1,
            fast.expanded,
            smooth.length,
            smooth.corners.len() - 1,
            smooth.length / (pa.angle_between(pb) * 0.5 * (pa.length() + pb.length())),
            pa.angle_between(pb) * 0.5 * (pa.length() + pb.length()),
        );
        g.bench_function(format!("astar/{name}"), |bch| {
            bch.iter(|| black_box(find_path(&grid, from, to)))
        });
        g.bench_function(format!("hierarchical/{name}"), |bch| {
            bch.iter(|| black_box(find_path_hierarchical(&grid, from, to)))
        });
        g.bench_function(format!("hierarchical_smoothed/{name}"), |bch| {
            bch.iter(|| black_box(find_path_hierarchical(&grid, from, to).map(|p| smooth_path(&grid, &p))))
        });
    }
    g.finish();
}

/// The place `north` and `east` metres from (`lat`, `lon`).
fn offset(lat: f64, lon: f64, north: f64, east: f64) -> End {
    const R: f64 = 6_371_000.0;
    End {
        dir: LatLon {
            lat: lat + (north / R).to_degrees(),
            lon: lon + (east / (R * lat.to_radians().cos())).to_degrees(),
        }
        .to_unit(),
        radius: None,
    }
}

/// The first place of a coarse scan whose ground, and the ground `north` and `east` metres from
/// it, lie at least 100 m above the sea.
fn land(d: &Arc<dyn Density>, layout: &Layout, sea: f64, (north, east): (f64, f64)) -> (End, End) {
    let mut g = LazyGrid::new(d.clone(), layout, Agent::default(), LazyOptions::default()).expect("a grid");
    let mut high = |e: End| {
        g.node_near(e.dir, None, 2)
            .and_then(|k| g.node(k))
            .is_some_and(|n| n.radius > sea + 100.0)
    };
    for lat in (-60..60).step_by(7) {
        for lon in (-180..180).step_by(13) {
            let (lat, lon) = (f64::from(lat) + 0.3, f64::from(lon) + 0.7);
            let (a, b) = (offset(lat, lon, 0.0, 0.0), offset(lat, lon, north, east));
            if high(a) && high(b) {
                return (a, b);
            }
        }
    }
    panic!("no land found")
}

fn nav_lazy(c: &mut Criterion) {
    let layout = PresetKind::Earth.default_layout(None).expect("the earth layout");
    let terrain = build(PresetKind::Earth, 7, &layout);
    let sea = terrain.sea_radius.expect("a sea");
    let d = terrain.density.clone();
    let mut g = c.benchmark_group("nav_lazy");
    g.sample_size(10).measurement_time(Duration::from_secs(30));
    let diagonal = 10_000.0 * std::f64::consts::FRAC_1_SQRT_2;
    for (name, offset, options) in [
        ("earth/10km_east", (0.0, 10_000.0), LazyOptions::default()),
        ("earth/10km_north_east", (diagonal, diagonal), LazyOptions::default()),
        (
            "earth/10km_east/chunk_tiles",
            (0.0, 10_000.0),
            LazyOptions {
                tile_side: 0,
                ..LazyOptions::default()
            },
        ),
        ("earth/500m_east", (0.0, 500.0), LazyOptions::default()),
    ] {
        let (a, b) = land(&d, &layout, sea, offset);
        let search = SearchOptions::default();
        let walk = || {
            let mut grid = LazyGrid::new(d.clone(), &layout, Agent::default(), options).expect("a grid");
            let found = grid.query(a, b, 8, &search);
            (found, grid.cache_stats())
        };
        let (found, cache) = walk();
        let PathAnswer::Found(path) = &found.answer else {
            panic!("{name}: {:?}", found.answer)
        };
        eprintln!(
            "{name}: {:.0} m apart, {:.0} m walked, {} steps, {} nodes expanded, {} tiles built ({} columns a side), {} KiB cached",
            a.dir.angle_between(b.dir) * sea,
            path.length,
            path.nodes.len() - 1,
            found.stats.expanded,
            found.stats.tiles_built,
            if options.tile_side == 0 {
                layout.n_t()
            } else {
                options.tile_side
            },
            cache.bytes / 1024
        );
        g.bench_function(name, |bch| bch.iter(|| black_box(walk())));
    }
    g.finish();
}

criterion_group!(benches, nav, nav_lazy);
criterion_main!(benches);
