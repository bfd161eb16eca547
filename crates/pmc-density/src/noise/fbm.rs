//! Fractional Brownian motion: a sum of gradient-noise octaves of rising frequency and falling
//! amplitude.

#[cfg(test)]
use super::gradient::gradient3;
use super::lanes::gradient3_accumulate_offset;
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

    /// The values at many points given as coordinate slices (structure of arrays): `out[i]`
    /// gets exactly the bits of [`sample`](Self::sample) at `(x[i], y[i], z[i])`.
    ///
    /// This is the fast way to sample a field at a chunk's or a patch's points: one octave at a
    /// time over all of them ([`super::gradient3_accumulate_offset`]), eight points per vector
    /// operation on processors with AVX-512, with no per-point call or packing.
    ///
    /// Panics when the slices differ in length (a caller's bug).
    pub fn sample_slices(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut [f64]) {
        assert!(
            x.len() == out.len() && y.len() == out.len() && z.len() == out.len(),
            "one output per point"
        );
        out.fill(0.0);
        for o in &self.octaves[..self.count] {
            gradient3_accumulate_offset(x, y, z, o.frequency, o.offset, o.seed, o.amplitude, out);
        }
        for v in out.iter_mut() {
            *v *= self.norm;
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
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

    /// Coordinate slices of random points near Earth radius, on lattice planes and at small
    /// coordinates, of a length that is not a multiple of the lanes.
    pub(crate) fn slice_points(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        use crate::noise::{mix64, unit_f64};
        let mut out = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n as u64 {
            let r = |k: u64| unit_f64(mix64(i * 3 + k)) * 2.0 - 1.0;
            let scale = [1.0, 6.4e6, 3.0e3][(i % 3) as usize];
            let mut p = DVec3::new(r(0), r(1), r(2)) * scale;
            if i % 11 == 5 {
                p.z = p.z.round();
            }
            if i % 13 == 7 {
                p = p.normalize();
            }
            out.0.push(p.x);
            out.1.push(p.y);
            out.2.push(p.z);
        }
        out
    }

    #[test]
    fn slices_give_the_point_by_point_bits() {
        let (x, y, z) = slice_points(1003);
        for octaves in [1, 2, 6, 9, 16] {
            let f = Fbm::new(21, FbmParams::new(1.3, octaves));
            for len in [0, 7, 8, 16, 1003] {
                let mut out = vec![f64::NAN; len];
                f.sample_slices(&x[..len], &y[..len], &z[..len], &mut out);
                for i in 0..len {
                    let want = f.sample(DVec3::new(x[i], y[i], z[i]));
                    assert_eq!(out[i].to_bits(), want.to_bits(), "{octaves} octaves, point {i}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "one output per point")]
    fn slices_of_different_lengths_are_refused() {
        let f = Fbm::new(1, FbmParams::default());
        f.sample_slices(&[0.0; 4], &[0.0; 4], &[0.0; 3], &mut [0.0; 4]);
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
