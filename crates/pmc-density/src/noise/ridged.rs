//! Ridged multifractal (after Musgrave): sharp crests where the noise crosses zero, with rougher
//! detail on the crests than in the valleys.

#[cfg(test)]
use super::gradient::gradient3;
use super::lanes::gradient3_accumulate_offset;
use super::octave::{octave_noise, table, Octave, MAX_OCTAVES};
use super::{DEFAULT_FREQUENCY, DEFAULT_GAIN, DEFAULT_LACUNARITY, DEFAULT_OCTAVES};
use pmc_geometry::glam::DVec3;

/// Default ridge offset: the signal of an octave is `(offset - |n|)^2`.
pub const DEFAULT_RIDGE_OFFSET: f64 = 1.0;
/// Default feedback gain: an octave's weight is its predecessor's signal times this, clamped to
/// `[0, 1]`, so detail concentrates on the crests.
pub const DEFAULT_RIDGE_FEEDBACK: f64 = 2.0;

/// The parameters of a [`Ridged`] multifractal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RidgedParams {
    /// Number of octaves, `1..=MAX_OCTAVES` (clamped).
    pub octaves: u32,
    /// Frequency of the first octave (the input is multiplied by it).
    pub frequency: f64,
    /// Frequency ratio between successive octaves.
    pub lacunarity: f64,
    /// Amplitude ratio between successive octaves.
    pub gain: f64,
    /// Ridge offset: an octave's signal is `(offset - |n|)^2` (1 puts the crest at the noise's zero
    /// crossing).
    pub offset: f64,
    /// Feedback gain: how strongly an octave's signal weights the next octave.
    pub feedback: f64,
}

impl Default for RidgedParams {
    fn default() -> Self {
        RidgedParams {
            octaves: DEFAULT_OCTAVES,
            frequency: DEFAULT_FREQUENCY,
            lacunarity: DEFAULT_LACUNARITY,
            gain: DEFAULT_GAIN,
            offset: DEFAULT_RIDGE_OFFSET,
            feedback: DEFAULT_RIDGE_FEEDBACK,
        }
    }
}

impl RidgedParams {
    /// The default parameters at `frequency` with `octaves` octaves.
    pub fn new(frequency: f64, octaves: u32) -> Self {
        RidgedParams {
            octaves,
            frequency,
            ..Default::default()
        }
    }
}

/// Ridged multifractal over [`gradient3`], normalised to `[0, 1]`: 1 on a perfect crest of every
/// octave, lower in the valleys between crests.
#[derive(Clone, Debug)]
pub struct Ridged {
    params: RidgedParams,
    octaves: [Octave; MAX_OCTAVES as usize],
    count: usize,
    norm: f64,
}

impl Ridged {
    /// Builds the multifractal for `seed` and `params`.
    pub fn new(seed: u64, params: RidgedParams) -> Self {
        let (octaves, count, total) = table(seed, params.octaves, params.frequency, params.lacunarity, params.gain);
        // An octave's signal is at most max(offset^2, (offset - 1)^2) (|n| <= 1) and its weight at
        // most 1, so this normalises the sum into [0, 1].
        let peak = (params.offset * params.offset)
            .max((params.offset - 1.0).powi(2))
            .max(f64::MIN_POSITIVE);
        Ridged {
            params,
            octaves,
            count,
            norm: 1.0 / (total * peak),
        }
    }

    /// The parameters it was built with.
    pub fn params(&self) -> &RidgedParams {
        &self.params
    }

    /// The value at `p`, in `[0, 1]`.
    #[inline]
    pub fn sample(&self, p: DVec3) -> f64 {
        let octaves = &self.octaves[..self.count];
        let mut noise = [0.0; MAX_OCTAVES as usize];
        octave_noise(octaves, p, &mut noise);
        let mut sum = 0.0;
        let mut weight = 1.0;
        for (o, n) in octaves.iter().zip(noise) {
            let s = self.params.offset - n.abs();
            let s = s * s * weight;
            weight = (s * self.params.feedback).clamp(0.0, 1.0);
            sum += s * o.amplitude;
        }
        sum * self.norm
    }

    /// The values at many points given as coordinate slices (structure of arrays): `out[i]`
    /// gets exactly the bits of [`sample`](Self::sample) at `(x[i], y[i], z[i])`, one octave at
    /// a time over blocks of points (see [`super::Fbm::sample_slices`]).
    ///
    /// Panics when the slices differ in length (a caller's bug).
    pub fn sample_slices(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut [f64]) {
        assert!(
            x.len() == out.len() && y.len() == out.len() && z.len() == out.len(),
            "one output per point"
        );
        const BLOCK: usize = 256;
        let (mut noise, mut weight) = ([0.0; BLOCK], [0.0; BLOCK]);
        for start in (0..out.len()).step_by(BLOCK) {
            let end = (start + BLOCK).min(out.len());
            let (x, y, z, out) = (&x[start..end], &y[start..end], &z[start..end], &mut out[start..end]);
            let (noise, weight) = (&mut noise[..out.len()], &mut weight[..out.len()]);
            out.fill(0.0);
            weight.fill(1.0);
            for o in &self.octaves[..self.count] {
                // `0 + 1 n` is `n` (a negative zero becomes a positive one, which `abs` ignores).
                noise.fill(0.0);
                gradient3_accumulate_offset(x, y, z, o.frequency, o.offset, o.seed, 1.0, noise);
                for ((sum, w), n) in out.iter_mut().zip(weight.iter_mut()).zip(noise.iter()) {
                    let s = self.params.offset - n.abs();
                    let s = s * s * *w;
                    *w = (s * self.params.feedback).clamp(0.0, 1.0);
                    *sum += s * o.amplitude;
                }
            }
            for v in out.iter_mut() {
                *v *= self.norm;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_give_the_point_by_point_bits() {
        let (x, y, z) = crate::noise::fbm::tests::slice_points(1003);
        for octaves in [1, 5, 12] {
            let r = Ridged::new(8, RidgedParams::new(2.1, octaves));
            for len in [0, 9, 256, 257, 1003] {
                let mut out = vec![f64::NAN; len];
                r.sample_slices(&x[..len], &y[..len], &z[..len], &mut out);
                for i in 0..len {
                    let want = r.sample(DVec3::new(x[i], y[i], z[i]));
                    assert_eq!(out[i].to_bits(), want.to_bits(), "{octaves} octaves, point {i}");
                }
            }
        }
    }

    #[test]
    fn batched_octaves_give_the_scalar_sum_bit_for_bit() {
        for octaves in [2, 4, 6, 9, 16] {
            let r = Ridged::new(
                4,
                RidgedParams {
                    octaves,
                    ..RidgedParams::default()
                },
            );
            for i in 0..500 {
                let t = f64::from(i);
                let p = DVec3::new(6.4e6 + t * 3.7, -t * 0.91, 1.0e3 + t * t * 0.013);
                let (mut want, mut weight) = (0.0, 1.0);
                for o in &r.octaves[..r.count] {
                    let n = gradient3(p * o.frequency + o.offset, o.seed);
                    let s = r.params.offset - n.abs();
                    let s = s * s * weight;
                    weight = (s * r.params.feedback).clamp(0.0, 1.0);
                    want += s * o.amplitude;
                }
                assert_eq!(
                    r.sample(p).to_bits(),
                    (want * r.norm).to_bits(),
                    "{octaves} octaves at {p:?}"
                );
            }
        }
    }

    #[test]
    fn bounded_deterministic_and_seeded() {
        let a = Ridged::new(1, RidgedParams::default());
        let b = Ridged::new(2, RidgedParams::default());
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        let mut diff = 0;
        for i in 0..20_000 {
            let p = DVec3::new(
                (i % 37) as f64 * 0.31,
                (i / 37 % 29) as f64 * 0.43,
                (i / 1073) as f64 * 0.27,
            );
            let v = a.sample(p);
            assert_eq!(v.to_bits(), a.sample(p).to_bits());
            assert!((0.0..=1.0 + 1e-12).contains(&v), "{v}");
            lo = lo.min(v);
            hi = hi.max(v);
            if (v - b.sample(p)).abs() > 1e-3 {
                diff += 1;
            }
        }
        assert!(hi - lo > 0.3, "range [{lo}, {hi}]");
        assert!(diff > 18_000, "{diff}");
    }

    #[test]
    fn crest_on_the_zero_crossing() {
        // One octave: the value is (1 - |n|)^2, so it is 1 exactly where the noise is zero (at
        // lattice points, minus the offset).
        let r = Ridged::new(4, RidgedParams::new(1.0, 1));
        let p = DVec3::new(3.0, -2.0, 7.0) - r.octaves[0].offset;
        assert!((r.sample(p) - 1.0).abs() < 1e-9);
        assert!(r.sample(p + DVec3::splat(0.4)) < 1.0);
    }

    #[test]
    fn offset_above_one_stays_normalised() {
        let r = Ridged::new(
            4,
            RidgedParams {
                offset: 1.5,
                ..RidgedParams::new(1.3, 5)
            },
        );
        for i in 0..5000 {
            let v = r.sample(DVec3::new(i as f64 * 0.173, (i * 7 % 13) as f64, 0.5));
            assert!((0.0..=1.0 + 1e-12).contains(&v));
        }
        assert_eq!(r.params().offset, 1.5);
    }
}
