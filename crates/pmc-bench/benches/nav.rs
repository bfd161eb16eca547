//! Navigation on the default planet (earthlike, seed 7, 6 x 257^2 columns, 65 layers), default
//! agent: building the whole grid, rebuilding one tile (the columns under one chunk footprint,
//! through the whole depth, with the components relabelled), rebuilding after a 4 m and a 16 m
//! remove brush, and A* from corner to corner of a face and over a shorter walk.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::{default_planet, nearest_column, surface_along, surface_point};
use pmc_edit::{BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_nav::{find_path, Agent, NavGrid};
use std::hint::black_box;
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
        g.bench_function(format!("astar/{name}"), |bch| {
            bch.iter(|| black_box(find_path(&grid, from, to)))
        });
    }
    g.finish();
}

criterion_group!(benches, nav);
criterion_main!(benches);
