//! Density for one chunk: the earthlike batch call over a 32^3-tile chunk (35^3 padded samples).
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pmc_bench::{default_planet, surface_chunk};
use pmc_geometry::{ChunkGrid, ChunkKey, Face};

fn density(c: &mut Criterion) {
    let planet = default_planet();
    let surface = surface_chunk(&planet);
    let deep = ChunkKey::new(Face::Top, surface.i, surface.j, 0);
    let mut g = c.benchmark_group("density");
    for (name, key) in [("surface_chunk", surface), ("deep_chunk", deep)] {
        let grid = ChunkGrid::new(planet.layout(), key);
        let mut out = vec![0.0f32; grid.sample_count()];
        g.bench_function(format!("earthlike/{name}/samples={}", grid.sample_count()), |b| {
            b.iter(|| {
                planet
                    .terrain()
                    .density
                    .sample_shell(black_box(&grid.dirs), &grid.radii, &mut out)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, density);
criterion_main!(benches);
