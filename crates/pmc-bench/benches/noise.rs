//! The noise kernels: eight gradient-noise evaluations one by one and in one vector call, and a
//! 6-octave fBm sample with its octaves batched against the same sum written with scalar calls
//! (the reference, in the same run). Points near Earth radius, where the terrain samples them.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pmc_density::noise::{gradient3, gradient3_x8, Fbm, FbmParams, Lanes8, LANES};
use pmc_geometry::glam::DVec3;

fn points(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let t = i as f64;
            DVec3::new(
                6.4e6 * (t * 1e-3).sin() + t * 0.37,
                1.3e5 + t * 0.011,
                -2.2e4 + t * 0.73,
            )
        })
        .collect()
}

fn noise(c: &mut Criterion) {
    let pts = points(1024);
    let mut g = c.benchmark_group("noise");
    g.bench_function("gradient3/scalar/evals=1024", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for p in &pts {
                s += gradient3(*p, 12345);
            }
            black_box(s)
        })
    });
    g.bench_function("gradient3/x8/evals=1024", |b| {
        b.iter(|| {
            let mut s = 0.0;
            let mut q = Lanes8::default();
            for group in pts.chunks_exact(LANES) {
                for (l, p) in group.iter().enumerate() {
                    q.set(l, *p, 12345);
                }
                s += gradient3_x8(&q).iter().sum::<f64>();
            }
            black_box(s)
        })
    });
    // 6-octave fBm on the unit sphere at a continent-to-hills frequency.
    let dirs: Vec<DVec3> = pts.iter().map(|p| p.normalize()).collect();
    let fbm = Fbm::new(7, FbmParams::new(1.15, 6));
    g.bench_function("fbm6/batched/samples=1024", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for d in &dirs {
                s += fbm.sample(*d);
            }
            black_box(s)
        })
    });
    // The reference: the same kind of sum with one scalar call per octave.
    let octaves: Vec<(f64, f64, u64, DVec3)> = (0..6)
        .map(|i| {
            let f = 1.15 * 2.03f64.powi(i);
            (f, 0.5f64.powi(i), 1000 + i as u64, DVec3::splat(0.3 * f64::from(i)))
        })
        .collect();
    g.bench_function("fbm6/scalar-reference/samples=1024", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for d in &dirs {
                let mut sum = 0.0;
                for (f, a, seed, off) in &octaves {
                    sum += a * gradient3(*d * *f + *off, *seed);
                }
                s += sum;
            }
            black_box(s)
        })
    });
    g.finish();
}

criterion_group!(benches, noise);
criterion_main!(benches);
