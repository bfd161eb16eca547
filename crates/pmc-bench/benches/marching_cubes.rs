//! Marching cubes alone for one 32^3-tile chunk given its densities, against fast-surface-nets
//! meshing the very same sample grid in the same run.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fast_surface_nets::ndshape::RuntimeShape;
use fast_surface_nets::{surface_nets, SurfaceNetsBuffer};
use pmc_bench::{chunk_densities, default_planet, surface_chunk, triangle_count};
use pmc_mesh::{ChunkMesh, Mesher};

fn marching_cubes(c: &mut Criterion) {
    let planet = default_planet();
    let key = surface_chunk(&planet);
    let (grid, d) = chunk_densities(&planet, key);
    let tris = triangle_count(&grid, &d);
    let mut g = c.benchmark_group("marching_cubes");
    let mut mesher = Mesher::new();
    let mut out = ChunkMesh::default();
    g.bench_function(format!("pmc/tris={tris}"), |b| {
        b.iter(|| mesher.mesh(&grid, black_box(&d), &mut out))
    });

    // fast-surface-nets treats negative as inside: negate, outside the timed loop.
    let p = grid.padded as u32;
    let sdf: Vec<f32> = d.iter().map(|v| -v).collect();
    let shape = RuntimeShape::<u32, 3>::new([p, p, p]);
    let mut buf = SurfaceNetsBuffer::default();
    surface_nets(&sdf, &shape, [0; 3], [p - 1; 3], &mut buf);
    let fsn_tris = buf.indices.len() / 3;
    g.bench_function(format!("fast-surface-nets/tris={fsn_tris}"), |b| {
        b.iter(|| surface_nets(black_box(&sdf), &shape, [0; 3], [p - 1; 3], &mut buf))
    });
    g.finish();
}

criterion_group!(benches, marching_cubes);
criterion_main!(benches);
