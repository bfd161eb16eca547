//! The whole default planet (earthlike, seed 7, 768 chunks) on the current thread pool.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::default_planet;

fn planet(c: &mut Criterion) {
    let planet = default_planet();
    let tris: usize = planet.generate(|_| {}).iter().map(|m| m.triangle_count()).sum();
    let mut g = c.benchmark_group("planet");
    g.sample_size(10);
    g.bench_function(format!("earthlike/default/tris={tris}"), |b| {
        b.iter(|| planet.generate(|_| {}))
    });
    g.finish();
}

criterion_group!(benches, planet);
criterion_main!(benches);
