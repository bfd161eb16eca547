//! A whole chunk: density batch, shell contract, marching cubes and shading.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::{default_planet, surface_chunk};
use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use pmc_planet::ChunkScratch;

fn chunk(c: &mut Criterion) {
    let planet = default_planet();
    let key = surface_chunk(&planet);
    let mut scratch = ChunkScratch::default();
    let mut out = ChunkMesh::default();
    planet.chunk_mesh_into(key, &mut scratch, &mut out);
    let mut g = c.benchmark_group("chunk");
    g.bench_function(format!("earthlike/full/tris={}", out.triangle_count()), |b| {
        b.iter(|| planet.chunk_mesh_into(key, &mut scratch, &mut out))
    });
    // The target pair: density (6-octave noise plus caves) plus meshing, no shading.
    let grid = pmc_geometry::ChunkGrid::new(planet.layout(), key);
    let mut d = vec![0.0f32; grid.sample_count()];
    let mut mesher = pmc_mesh::Mesher::new();
    g.bench_function(format!("earthlike/density+mesh/tris={}", out.triangle_count()), |b| {
        b.iter(|| {
            planet.terrain().density.sample_shell(&grid.dirs, &grid.radii, &mut d);
            pmc_mesh::close_shell(&grid, planet.layout().depth_tiles(), &mut d);
            mesher.mesh(&grid, &d, &mut out);
        })
    });
    // The shading alone: the shader over the chunk's vertices, as the pipeline shades them (from
    // the density batch's columns at each vertex's edge).
    let mut kept = pmc_density::ShellColumns::default();
    planet
        .terrain()
        .density
        .sample_shell_keeping(&grid.dirs, &grid.radii, &mut d, &mut kept);
    pmc_mesh::close_shell(&grid, planet.layout().depth_tiles(), &mut d);
    mesher.mesh(&grid, &d, &mut out);
    let points: Vec<DVec3> = (0..out.vertex_count()).map(|i| out.world_position(i)).collect();
    let normals: Vec<DVec3> = out.normals.iter().map(|n| n.map(f64::from).into()).collect();
    let edges: Vec<_> = (0..out.vertex_count())
        .map(|i| grid.vertex_edge(out.vertex_edges[i], points[i]))
        .collect();
    let vertices = pmc_density::presets::EdgeVertices {
        points: &points,
        normals: &normals,
        edges: &edges,
        dirs: &grid.dirs,
        columns: &kept,
    };
    let mut shades = Vec::new();
    g.bench_function(format!("earthlike/shading/vertices={}", points.len()), |b| {
        b.iter(|| planet.terrain().shader.shade_edges(&vertices, &mut shades))
    });
    // The same vertices shaded point by point in one batch (the columns evaluated at every vertex).
    g.bench_function(format!("earthlike/shading-points/vertices={}", points.len()), |b| {
        b.iter(|| {
            planet
                .terrain()
                .shader
                .shade_many(&points, &normals, false, &mut shades)
        })
    });
    g.finish();
}

criterion_group!(benches, chunk);
criterion_main!(benches);
