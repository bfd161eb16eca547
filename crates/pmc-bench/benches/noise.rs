//! The noise kernels: eight gradient-noise evaluations one by one and in one vector call, and a
//! 6-octave fBm sample four ways: over coordinate slices (`Fbm::sample_slices`), point by point
//! with the octaves batched (`Fbm::sample`), written with one scalar call per octave, and, as
//! references in the same run, the `simdnoise` (AVX2, f32) and `fastnoise-lite` (f64 inputs)
//! crates' 6-octave fBm at the same points. Points near Earth radius, where the terrain samples
//! them; the fBm on the unit sphere at a continent-to-hills frequency.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fastnoise_lite::{FastNoiseLite, FractalType, NoiseType};
use pmc_density::noise::{gradient3, gradient3_x8, Fbm, FbmParams, Lanes8, DEFAULT_LACUNARITY, LANES};
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

const SAMPLES: usize = 1024;
const FREQUENCY: f64 = 1.15;

fn noise(c: &mut Criterion) {
    let pts = points(SAMPLES);
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
    let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let fbm = Fbm::new(7, FbmParams::new(FREQUENCY, 6));
    let mut out = vec![0.0; SAMPLES];
    g.bench_function("fbm6/slices/samples=1024", |b| {
        b.iter(|| {
            fbm.sample_slices(&x, &y, &z, &mut out);
            black_box(out.iter().sum::<f64>())
        })
    });
    g.bench_function("fbm6/batched/samples=1024", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for d in &dirs {
                s += fbm.sample(*d);
            }
            black_box(s)
        })
    });
    // The same kind of sum with one scalar call per octave.
    let octaves: Vec<(f64, f64, u64, DVec3)> = (0..6)
        .map(|i| {
            let f = FREQUENCY * 2.03f64.powi(i);
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
    // References: fastnoise-lite's Perlin fBm (f64 coordinates) and simdnoise's simplex fBm
    // (f32, eight points per AVX2 call), 6 octaves, the same points and lacunarity.
    let mut fnl = FastNoiseLite::with_seed(7);
    fnl.set_noise_type(Some(NoiseType::Perlin));
    fnl.set_fractal_type(Some(FractalType::FBm));
    fnl.set_fractal_octaves(Some(6));
    fnl.set_fractal_lacunarity(Some(DEFAULT_LACUNARITY as f32));
    fnl.set_frequency(Some(FREQUENCY as f32));
    g.bench_function("fbm6/fastnoise-lite/samples=1024", |b| {
        b.iter(|| {
            let mut s = 0.0f32;
            for d in &dirs {
                s += fnl.get_noise_3d(d.x, d.y, d.z);
            }
            black_box(s)
        })
    });
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        let scaled = |v: &[f64]| -> Vec<f32> { v.iter().map(|c| (c * FREQUENCY) as f32).collect() };
        let (xs, ys, zs) = (scaled(&x), scaled(&y), scaled(&z));
        let mut out = vec![0.0f32; SAMPLES];
        g.bench_function("fbm6/simdnoise-avx2/samples=1024", |b| {
            b.iter(|| {
                simdnoise_fbm(&xs, &ys, &zs, &mut out);
                black_box(out.iter().sum::<f32>())
            })
        });
    }
    // The same sums at scattered points (no two neighbours in one cell, even in the coarsest
    // octave): the worst case for the slice kernel, which reuses a group's corner gradients
    // while the next group stays in its cells (as a chunk's or a patch's points do).
    let scattered: Vec<DVec3> = (0..SAMPLES as u64)
        .map(|i| {
            let h = |k: u64| pmc_density::noise::unit_f64(pmc_density::noise::mix64(i * 3 + k)) * 2.0 - 1.0;
            DVec3::new(h(1), h(2), h(3)).normalize()
        })
        .collect();
    let (sx, sy, sz): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        scattered.iter().map(|d| d.x).collect(),
        scattered.iter().map(|d| d.y).collect(),
        scattered.iter().map(|d| d.z).collect(),
    );
    g.bench_function("fbm6/slices/scattered/samples=1024", |b| {
        b.iter(|| {
            fbm.sample_slices(&sx, &sy, &sz, &mut out);
            black_box(out.iter().sum::<f64>())
        })
    });
    g.bench_function("fbm6/fastnoise-lite/scattered/samples=1024", |b| {
        b.iter(|| {
            let mut s = 0.0f32;
            for d in &scattered {
                s += fnl.get_noise_3d(d.x, d.y, d.z);
            }
            black_box(s)
        })
    });
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        let scaled = |v: &[f64]| -> Vec<f32> { v.iter().map(|c| (c * FREQUENCY) as f32).collect() };
        let (xs, ys, zs) = (scaled(&sx), scaled(&sy), scaled(&sz));
        let mut out = vec![0.0f32; SAMPLES];
        g.bench_function("fbm6/simdnoise-avx2/scattered/samples=1024", |b| {
            b.iter(|| {
                simdnoise_fbm(&xs, &ys, &zs, &mut out);
                black_box(out.iter().sum::<f32>())
            })
        });
    }
    g.finish();
}

/// simdnoise's 6-octave 3D fBm at each point, eight at a time.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
fn simdnoise_fbm(x: &[f32], y: &[f32], z: &[f32], out: &mut [f32]) {
    use std::arch::x86_64::*;
    assert!(std::is_x86_feature_detected!("avx2"));
    for (i, o) in out.chunks_exact_mut(8).enumerate() {
        let k = i * 8;
        // SAFETY: AVX2 is present (asserted above); each load and store reads or writes eight
        // f32 inside the slices (k + 8 <= len, by `chunks_exact_mut` over a slice as long).
        unsafe {
            let v = simdnoise::avx2::fbm_3d(
                _mm256_loadu_ps(x[k..k + 8].as_ptr()),
                _mm256_loadu_ps(y[k..k + 8].as_ptr()),
                _mm256_loadu_ps(z[k..k + 8].as_ptr()),
                _mm256_set1_ps(DEFAULT_LACUNARITY as f32),
                _mm256_set1_ps(0.5),
                6,
                7,
            );
            _mm256_storeu_ps(o.as_mut_ptr(), v);
        }
    }
}

criterion_group!(benches, noise);
criterion_main!(benches);
