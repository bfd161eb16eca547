//! Edit latency: from a brush operation to every affected chunk remeshed (density with the edit,
//! shell contract, marching cubes, shading), on one core, on the default planet (earthlike,
//! seed 7).
//!
//! The brush is a remove at the land surface above latitude 20, longitude 30, labelled with the
//! number of chunks it touches. The 4 m brush there falls between voxel columns (about 12 m apart)
//! and changes no sample, so it is also measured centred on the nearest voxel column. For the
//! 16 m brush the breakdown benchmarks split the work over the same chunks: finding them, the
//! base terrain's density batch, the batch with the edit applied, and density plus shell plus
//! meshing without shading (the rest of the total is shading). Each brush is also measured with
//! `Planet::remesh_reusing`, which shades anew only the vertices the edit moved (same bytes).
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::{default_planet, nearest_column, surface_along, surface_point};
use pmc_edit::{affected_chunks, BrushKind, BrushOp, EditSnapshot};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey};
use pmc_mesh::{close_shell, ChunkMesh, Mesher};
use pmc_planet::Planet;
use std::collections::HashMap;
use std::hint::black_box;

/// Benchmarks the whole latency of one remove brush and returns its label.
fn latency(c: &mut Criterion, planet: &Planet, name: &str, center: DVec3, radius: f64) -> (String, BrushOp) {
    let op = BrushOp::new(BrushKind::Remove, center, radius, 1.0).expect("a valid brush");
    let keys = affected_chunks(planet.layout(), &op);
    let label = format!("edit/{name}/chunks={}", keys.len());
    let edits = EditSnapshot::from(vec![op]);
    let tris: usize = planet
        .clone()
        .with_edits(edits.clone())
        .remesh(&op)
        .iter()
        .map(|m| m.triangle_count())
        .sum();
    eprintln!("{label}: chunks {keys:?}, {tris} triangles after the edit");
    let mut p = planet.clone();
    c.bench_function(&label, |b| {
        b.iter(|| {
            // From the edit to every affected chunk remeshed: the edited density is built, the
            // chunks found and meshed one after the other on this thread.
            p.set_edits(edits.clone());
            black_box(p.remesh(black_box(&op)))
        })
    });
    // The same, shading anew only the vertices the edit moved (byte-identical meshes).
    let before: HashMap<ChunkKey, ChunkMesh> = keys.iter().map(|k| (*k, planet.chunk_mesh(*k))).collect();
    c.bench_function(&format!("{label}/reuse_shading"), |b| {
        b.iter(|| {
            p.set_edits(edits.clone());
            black_box(p.remesh_reusing(black_box(&op), |k| before.get(k)))
        })
    });
    (label, op)
}

fn edit(c: &mut Criterion) {
    let planet = default_planet();
    let center = surface_point(&planet, 20.0, 30.0);
    let sea = planet.terrain().sea_radius.unwrap_or(0.0);
    eprintln!(
        "surface at lat 20, lon 30: {:.2} m above sea level",
        center.length() - sea
    );
    let on_column = surface_along(&planet, nearest_column(planet.layout(), center));
    eprintln!(
        "nearest voxel column: {:.2} m away, surface {:.2} m above sea level",
        (on_column - center).length(),
        on_column.length() - sea
    );
    latency(c, &planet, "remove_4m", center, 4.0);
    latency(c, &planet, "remove_4m_on_column", on_column, 4.0);
    let (label, op) = latency(c, &planet, "remove_16m", center, 16.0);

    let edited = planet.clone().with_edits(vec![op].into());
    let keys = affected_chunks(planet.layout(), &op);
    let grids: Vec<ChunkGrid> = keys.iter().map(|k| ChunkGrid::new(planet.layout(), *k)).collect();
    let mut d = vec![0.0f32; grids.first().map_or(0, |g| g.sample_count())];
    let mut g = c.benchmark_group(label);
    g.bench_function("stage=find_chunks", |b| {
        b.iter(|| black_box(affected_chunks(planet.layout(), black_box(&op))))
    });
    g.bench_function("stage=base_density", |b| {
        b.iter(|| {
            for grid in &grids {
                planet.terrain().density.sample_shell(&grid.dirs, &grid.radii, &mut d);
            }
            black_box(&d);
        })
    });
    g.bench_function("stage=edited_density", |b| {
        b.iter(|| {
            for grid in &grids {
                edited.density().sample_shell(&grid.dirs, &grid.radii, &mut d);
            }
            black_box(&d);
        })
    });
    let mut mesher = Mesher::new();
    let mut out = ChunkMesh::default();
    g.bench_function("stage=density+shell+mesh", |b| {
        b.iter(|| {
            for grid in &grids {
                edited.density().sample_shell(&grid.dirs, &grid.radii, &mut d);
                close_shell(grid, planet.layout().depth_tiles(), &mut d);
                mesher.mesh(grid, &d, &mut out);
            }
            black_box(&out);
        })
    });
    g.finish();
}

criterion_group!(benches, edit);
criterion_main!(benches);
