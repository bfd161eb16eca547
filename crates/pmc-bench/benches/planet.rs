//! The whole default planet (earthlike, seed 7, 768 chunks) on one thread and on every core, in
//! the same run: the parallel scaling of generation (the ratio of the two).
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_bench::default_planet;

fn planet(c: &mut Criterion) {
    let planet = default_planet();
    let tris: usize = planet.generate(|_| {}).iter().map(|m| m.triangle_count()).sum();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut g = c.benchmark_group("planet");
    g.sample_size(10);
    for threads in [1, cores] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        g.bench_function(format!("earthlike/default/threads={threads}/tris={tris}"), |b| {
            b.iter(|| pool.install(|| planet.generate(|_| {})))
        });
    }
    g.finish();
}

criterion_group!(benches, planet);
criterion_main!(benches);
