//! Edit latency: from a brush operation to every affected chunk remeshed (density with the edit,
//! shell contract, marching cubes, shading), on one core, on the default planet (earthlike,
//! seed 7).
//!
//! The brushes are removes at the terrain surface, labelled with the number of chunks they touch:
//! - at the land surface above latitude 20, longitude 30: the 4 m brush there falls between voxel
//!   columns (about 12 m apart) and changes no sample, so it is also measured centred on the
//!   nearest voxel column; and a 16 m brush;
//! - a 16 m brush on the North face where four chunks meet laterally (chunk corner (2, 4), latitude
//!   0, longitude 159.3) and the sea floor lies 0.1 m above the radius where the two depth chunks
//!   meet: it touches 8 chunks, the most a 16 m brush touches away from cube corners.
//!
//! Each brush is measured four ways: `remesh` without a base cache (the terrain noise sampled again
//! for every chunk), `remesh_reusing` without a cache (from the meshes before the edit: only the
//! cubes around the brush marched again, from a box of samples, the rest copied, and only the
//! vertices the edit moved shaded anew; same bytes), and `remesh_reusing` with the planet's base
//! density cache (`Planet::with_base_cache`) warm, the steady state of a user editing (the chunks
//! around the user were meshed already), and cold (a fresh, empty cache every iteration).
//!
//! For the 16 m brushes the breakdown benchmarks split the work of meshing whole chunks (as
//! `remesh` does) over the same chunks: finding them, the base terrain's density batch, the batch
//! with the edit applied, density plus shell plus meshing without shading; and, on the cached
//! path, copying the cached base batches, applying the edit over them, and shell plus meshing
//! from the edited batches.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::{chunk_corner, default_planet, nearest_column, surface_along, surface_point};
use pmc_density::Density;
use pmc_edit::{affected_chunks, BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Face};
use pmc_mesh::{close_shell, ChunkMesh, Mesher};
use pmc_planet::Planet;
use std::collections::HashMap;
use std::hint::black_box;

/// Chunks the base cache holds in these benchmarks: more than any brush here touches.
const CACHE_CHUNKS: usize = 64;

/// Benchmarks the whole latency of one remove brush and returns its label.
fn latency(c: &mut Criterion, planet: &Planet, name: &str, center: DVec3, radius: f64) -> (String, BrushOp) {
    let op = BrushOp::new(BrushKind::Remove, center, radius, 1.0).expect("a valid brush");
    let keys = affected_chunks(planet.layout(), &op);
    let label = format!("edit/{name}/chunks={}", keys.len());
    let edits = EditSnapshot::from(vec![op]);
    let after = planet.clone().with_edits(edits.clone()).remesh(&op);
    let tris: Vec<usize> = after.iter().map(|m| m.triangle_count()).collect();
    eprintln!(
        "{label}: chunks {keys:?}, {} triangles after the edit ({tris:?})",
        tris.iter().sum::<usize>()
    );
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
    // With the base density cache, warm: the affected chunks were meshed before the edit (that is
    // how `before` came to be), so their base batches are held.
    let mut cached = planet.clone().with_base_cache(CACHE_CHUNKS);
    for k in &keys {
        let _ = cached.chunk_mesh(*k);
    }
    cached.set_edits(edits.clone());
    let check = cached.remesh_reusing(&op, |k| before.get(k));
    assert!(check == after, "the cache changed a mesh");
    c.bench_function(&format!("{label}/warm_cache+reuse_shading"), |b| {
        b.iter(|| {
            cached.set_edits(edits.clone());
            black_box(cached.remesh_reusing(black_box(&op), |k| before.get(k)))
        })
    });
    // Cold: a fresh, empty cache every iteration (each chunk sampled, then stored).
    c.bench_function(&format!("{label}/cold_cache+reuse_shading"), |b| {
        b.iter(|| {
            let mut cold = planet.clone().with_base_cache(CACHE_CHUNKS);
            cold.set_edits(edits.clone());
            black_box(cold.remesh_reusing(black_box(&op), |k| before.get(k)))
        })
    });
    (label, op)
}

/// Where the time of one brush goes, stage by stage over its affected chunks.
fn breakdown(c: &mut Criterion, planet: &Planet, label: String, op: BrushOp) {
    let edited = planet.clone().with_edits(vec![op].into());
    let overlay = EditedDensity::new(planet.terrain().density.clone(), vec![op].into());
    let keys = affected_chunks(planet.layout(), &op);
    let grids: Vec<ChunkGrid> = keys.iter().map(|k| ChunkGrid::new(planet.layout(), *k)).collect();
    let mut d = vec![0.0f32; grids.first().map_or(0, |g| g.sample_count())];
    let bases: Vec<Vec<f32>> = grids
        .iter()
        .map(|grid| {
            let mut b = d.clone();
            planet.terrain().density.sample_shell(&grid.dirs, &grid.radii, &mut b);
            b
        })
        .collect();
    let edited_batches: Vec<Vec<f32>> = grids
        .iter()
        .map(|grid| {
            let mut b = d.clone();
            edited.density().sample_shell(&grid.dirs, &grid.radii, &mut b);
            close_shell(grid, planet.layout().depth_tiles(), &mut b);
            b
        })
        .collect();
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
    // The cached path: copy the base batch, apply the edit over it, close the shell and mesh.
    g.bench_function("cached/stage=copy_base", |b| {
        b.iter(|| {
            for base in &bases {
                d.copy_from_slice(base);
                black_box(&d);
            }
        })
    });
    g.bench_function("cached/stage=apply_edits", |b| {
        b.iter(|| {
            for (grid, base) in grids.iter().zip(&bases) {
                d.copy_from_slice(base);
                overlay.apply_edits(&grid.dirs, &grid.radii, &mut d);
            }
            black_box(&d);
        })
    });
    g.bench_function("cached/stage=shell+mesh", |b| {
        b.iter(|| {
            for (grid, batch) in grids.iter().zip(&edited_batches) {
                d.copy_from_slice(batch);
                close_shell(grid, planet.layout().depth_tiles(), &mut d);
                mesher.mesh(grid, &d, &mut out);
            }
            black_box(&out);
        })
    });
    g.finish();
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
    let layout = planet.layout();
    let corner = surface_along(&planet, chunk_corner(layout, Face::North, 2, 4));
    let depth_boundary = layout.layer_radius(i64::from(layout.n_t()));
    eprintln!(
        "North chunk corner (2, 4): surface {:.2} m above sea level, {:.2} m above the depth chunks' boundary",
        corner.length() - sea,
        corner.length() - depth_boundary
    );
    latency(c, &planet, "remove_4m", center, 4.0);
    latency(c, &planet, "remove_4m_on_column", on_column, 4.0);
    let (label, op) = latency(c, &planet, "remove_16m", center, 16.0);
    breakdown(c, &planet, label, op);
    let (label, op) = latency(c, &planet, "remove_16m_chunk_corner", corner, 16.0);
    breakdown(c, &planet, label, op);
}

criterion_group!(benches, edit);
criterion_main!(benches);
