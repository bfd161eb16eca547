//! Fractional Brownian motion: a sum of gradient-noise octaves of rising frequency and falling
//! amplitude.

#[cfg(test)]
use super::gradient::gradient3;
use super::octave::{octave_noise, table, Octave, MAX_OCTAVES};
use pmc_geometry::glam::DVec3;

/// Default number of octaves.
pub const DEFAULT_OCTAVES: u32 = 6;
/// Default frequency (lattice cells per unit of input).
pub const DEFAULT_FREQUENCY: f64 = 1.0;
/// Default frequency ratio between successive octaves. Slightly off 2 so that the octaves'
/// lattices do not line up.
pub const DEFAULT_LACUNARITY: f64 = 2.03;
/// Default amplitude ratio between successive octaves.
pub const DEFAULT_GAIN: f64 = 0.5;

/// The parameters of a fractal sum ([`Fbm`]; [`super::Ridged`] adds its own).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FbmParams {
    /// Number of octaves, `1..=MAX_OCTAVES` (clamped).
    pub octaves: u32,
    /// Frequency of the first octave: the input is multiplied by it. For a height field sampled
    /// on the unit sphere this is about `planet radius / feature wavelength`.
    pub frequency: f64,
    /// Frequency ratio between successive octaves (usually about 2).
    pub lacunarity: f64,
    /// Amplitude ratio between successive octaves (0.5 gives the classic 1/f spectrum; lower is
    /// smoother).
    pub gain: f64,
}

impl Default for FbmParams {
    fn default() -> Self {
        FbmParams {
            octaves: DEFAULT_OCTAVES,
            frequency: DEFAULT_FREQUENCY,
            lacunarity: DEFAULT_LACUNARITY,
            gain: DEFAULT_GAIN,
        }
    }
}

impl FbmParams {
    /// The default parameters at `frequency` with `octaves` octaves.
    pub fn new(frequency: f64, octaves: u32) -> Self {
        FbmParams {
            octaves,
            frequency,
            ..Default::default()
        }
    }
}

/// Fractional Brownian motion over [`gradient3`]: `sum_i gain^i n_i(p lacunarity^i frequency)`,
/// divided by the sum of the amplitudes, so the value lies in `[-1, 1]` (its standard deviation is
/// about 0.15 with the defaults). Every octave uses its own derived seed and lattice offset.
#[derive(Clone, Debug)]
pub struct Fbm {
    params: FbmParams,
    octaves: [Octave; MAX_OCTAVES as usize],
    count: usize,
    norm: f64,
}

impl Fbm {
    /// Builds the sum for `seed` and `params` (precomputes the per-octave seeds and offsets).
    pub fn new(seed: u64, params: FbmParams) -> Self {
        let (octaves, count, total) = table(seed, params.octaves, params.frequency, params.lacunarity, params.gain);
        Fbm {
            params,
            octaves,
            count,
            norm: 1.0 / total,
        }
    }

    /// The parameters it was built with.
    pub fn params(&self) -> &FbmParams {
        &self.params
    }

    /// The value at `p`, in `[-1, 1]`.
    #[inline]
    pub fn sample(&self, p: DVec3) -> f64 {
        let octaves = &self.octaves[..self.count];
        let mut noise = [0.0; MAX_OCTAVES as usize];
        octave_noise(octaves, p, &mut noise);
        let mut sum = 0.0;
        for (o, n) in octaves.iter().zip(noise) {
            sum += o.amplitude * n;
        }
        sum * self.norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: i32, step: f64) -> impl Iterator<Item = DVec3> {
        (0..n * n * n).map(move |i| {
            DVec3::new((i % n) as f64, ((i / n) % n) as f64, (i / (n * n)) as f64) * step + DVec3::splat(0.123)
        })
    }

    #[test]
    fn batched_octaves_give_the_scalar_sum_bit_for_bit() {
        for octaves in [1, 3, 4, 7, 8, 9, 16] {
            let f = Fbm::new(9, FbmParams::new(1.7, octaves));
            for p in grid(12, 0.731).map(|p| p * 1.0e4 + DVec3::new(6.4e6, -3.0e5, 1.0)) {
                let mut want = 0.0;
                for o in &f.octaves[..f.count] {
                    want += o.amplitude * gradient3(p * o.frequency + o.offset, o.seed);
                }
                assert_eq!(
                    f.sample(p).to_bits(),
                    (want * f.norm).to_bits(),
                    "{octaves} octaves at {p:?}"
                );
            }
        }
    }

    #[test]
    fn deterministic_and_bounded() {
        let f = Fbm::new(42, FbmParams::default());
        let g = Fbm::new(42, FbmParams::default());
        let mut sum2 = 0.0;
        let mut n = 0.0;
        for p in grid(40, 0.37) {
            let v = f.sample(p);
            assert_eq!(v.to_bits(), g.sample(p).to_bits());
            assert!(v.abs() <= 1.0 + 1e-12);
            sum2 += v * v;
            n += 1.0;
        }
        let std = (sum2 / n).sqrt();
        assert!(std > 0.08 && std < 0.3, "std {std}");
    }

    #[test]
    fn seeds_differ_and_octaves_add_detail() {
        let a = Fbm::new(1, FbmParams::default());
        let b = Fbm::new(2, FbmParams::default());
        let one = Fbm::new(
            1,
            FbmParams {
                octaves: 1,
                ..Default::default()
            },
        );
        let mut diff = 0;
        let (mut rough, mut rough_size) = (0.0, 0.0);
        let (mut smooth, mut smooth_size) = (0.0, 0.0);
        for p in grid(20, 0.51) {
            if (a.sample(p) - b.sample(p)).abs() > 1e-3 {
                diff += 1;
            }
            let q = p + DVec3::X * 0.05;
            rough += (a.sample(p) - a.sample(q)).abs();
            rough_size += a.sample(p).abs();
            smooth += (one.sample(p) - one.sample(q)).abs();
            smooth_size += one.sample(p).abs();
        }
        assert!(diff > 7000, "{diff}");
        // Relative to its size, the six-octave sum changes faster over a short step.
        assert!(
            rough / rough_size > 1.5 * smooth / smooth_size,
            "more octaves should add small-scale variation"
        );
    }

    #[test]
    fn continuous() {
        let f = Fbm::new(3, FbmParams::new(1.7, 8));
        for p in grid(15, 0.77) {
            let d = f.sample(p) - f.sample(p + DVec3::splat(1e-7));
            assert!(d.abs() < 1e-4);
        }
    }

    #[test]
    fn frequency_scales_the_input() {
        let f = Fbm::new(3, FbmParams::new(4.0, 1));
        let g = Fbm::new(3, FbmParams::new(1.0, 1));
        let p = DVec3::new(0.1, 0.2, 0.3);
        let lattice_offset = f.octaves[0].offset;
        assert_eq!(f.octaves[0].offset, g.octaves[0].offset);
        assert!((f.sample(p) - gradient3(p * 4.0 + lattice_offset, f.octaves[0].seed)).abs() < 1e-15);
        assert_eq!(f.params().frequency, 4.0);
    }
}
