//! Level-of-detail chunks: a surface chunk at each level, and the cost of closing seams toward
//! coarser neighbours (transition patches) against the same chunk meshed without them.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::default_planet;
use pmc_geometry::{ChunkSide, SideMask};
use pmc_mesh::ChunkMesh;
use pmc_planet::ChunkScratch;

fn lod(c: &mut Criterion) {
    let planet = default_planet();
    let layout = *planet.layout();
    let mut scratch = ChunkScratch::default();
    let mut out = ChunkMesh::default();
    let mut g = c.benchmark_group("lod");
    for level in 0..=layout.max_level() {
        // The level's chunk holding the most triangles.
        let key = layout
            .chunks(level)
            .into_iter()
            .filter(|k| planet.may_hold_surface(k))
            .max_by_key(|k| planet.chunk_mesh_lod(*k, SideMask::NONE).triangle_count())
            .expect("a surface chunk");
        planet.chunk_mesh_lod_into(key, SideMask::NONE, &mut scratch, &mut out);
        g.bench_function(
            format!("earthlike/level{level}/no-seams/tris={}", out.triangle_count()),
            |b| b.iter(|| planet.chunk_mesh_lod_into(key, SideMask::NONE, &mut scratch, &mut out)),
        );
        if level < layout.max_level() {
            let three = SideMask::NONE
                .with(ChunkSide::UMax)
                .with(ChunkSide::VMax)
                .with(ChunkSide::Outer);
            planet.chunk_mesh_lod_into(key, three, &mut scratch, &mut out);
            g.bench_function(
                format!("earthlike/level{level}/3-seams/tris={}", out.triangle_count()),
                |b| b.iter(|| planet.chunk_mesh_lod_into(key, three, &mut scratch, &mut out)),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, lod);
criterion_main!(benches);
