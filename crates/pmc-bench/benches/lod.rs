//! Level-of-detail chunks: a surface chunk at each level, and the cost of closing seams toward
//! coarser neighbours (transition patches) against the same chunk meshed without them; and the
//! search for the chunks near a point (`GET /api/v1/chunks`) on the Earth at true scale.
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

/// `chunks_near` on `earth` (1 m voxels, a 32.8 km shell): 50 m at level 0 (about 60 chunks) and
/// 20 km at level 4 (about 175 000 chunks), the two queries the API once refused.
fn chunks_near(c: &mut Criterion) {
    use pmc_planet::{Planet, PresetKind};
    let layout = PresetKind::Earth.default_layout(None).expect("the earth's layout");
    let planet = Planet::new(PresetKind::Earth, 7, layout);
    let p = pmc_geometry::LatLon::new(39.0, 0.0).expect("a place").to_unit() * planet.datum_radius();
    let mut g = c.benchmark_group("chunks_near");
    g.sample_size(20);
    for (level, range) in [(0u8, 50.0), (4, 20_000.0)] {
        let total = pmc_lod::bounds::chunks_near(&planet, level, p, range, 512, 200_000)
            .expect("in budget")
            .1;
        g.bench_function(format!("earth/level{level}/range={range}m/chunks={total}"), |b| {
            b.iter(|| pmc_lod::bounds::chunks_near(&planet, level, p, range, 512, 200_000))
        });
    }
    g.finish();
}

criterion_group!(benches, lod, chunks_near);
criterion_main!(benches);
