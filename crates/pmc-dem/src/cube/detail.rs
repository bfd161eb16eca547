//! Detail noise below the data resolution (seed 003 Sec. 4.6): octaves of gradient noise whose
//! lattices line up with the cube lattice, so that every octave is exactly zero at every data
//! sample.

use pmc_density::noise::{derive_seed, gradient3, gradient3_accumulate, gradient3_x8, Lanes8, LANES};
use pmc_geometry::glam::DVec3;

/// Default noise seed of [`DetailNoise`].
pub const DEFAULT_DETAIL_SEED: u64 = 0x003d_e7a1_1000_0003;
/// Default roughness: octave `k` has amplitude `0.05 x` its lattice spacing in metres (slopes of
/// a few per cent, a gently rough surface).
pub const DEFAULT_ROUGHNESS: f64 = 0.05;
/// Default relief slope: where the data rise or fall by at least 2 % of the data spacing between
/// neighbouring samples, the detail has its full amplitude; flatter data (a sea floor, a plain)
/// get proportionally less, perfectly flat data none.
pub const DEFAULT_RELIEF_SLOPE: f64 = 0.02;
/// The most detail octaves evaluated (octave 30 has a spacing a billionth of the data's).
pub const MAX_DETAIL_OCTAVES: u32 = 30;

/// Procedural detail added between the data samples.
///
/// Octave `k` (from 0) is gradient noise on a lattice of spacing `data spacing / 2^k`, aligned
/// with the cube lattice of resolution `2^(n+k)`: it is evaluated at the cube-surface point
/// `c` (in `[-1, 1]^3`) scaled to `c 2^(n-1+k)`, so its lattice points are the cube lattice
/// points of resolution `2^(n+k)` and coarser, where it is exactly zero: the data samples stay
/// exact, and a lattice point of resolution `2^(n+j)` gets only octaves `0 .. j`.
///
/// Octave `k` has amplitude `roughness x data spacing / 2^k` (metres; the data spacing at a face
/// centre; octave 0 at most `max_amplitude`), times a relief weight in `[0, 1]`: at each data sample the largest height
/// difference to its four neighbours divided by `relief_slope x data spacing` (capped at 1),
/// interpolated bilinearly between the samples, so flat areas stay smooth. `relief_slope <= 0`
/// turns the weighting off (weight 1 everywhere).
#[derive(Clone, Debug, PartialEq)]
pub struct DetailNoise {
    /// Noise seed; octave `k` uses `derive_seed(seed, k)`.
    pub seed: u64,
    /// Amplitude of each octave as a fraction of its lattice spacing; 0 turns the detail off.
    pub roughness: f64,
    /// Slope of the data at and above which the detail has its full amplitude; 0 or less: no
    /// relief weighting.
    pub relief_slope: f64,
    /// The largest amplitude of octave 0, metres: coarse data (a sample every 100 km) gets
    /// hills, not mountain ranges, between its samples. Infinite: no cap.
    pub max_amplitude: f64,
}

/// Default cap on the amplitude of octave 0, metres (so the detail moves the surface by at most
/// twice this).
pub const DEFAULT_MAX_AMPLITUDE: f64 = 400.0;

impl Default for DetailNoise {
    fn default() -> Self {
        DetailNoise {
            seed: DEFAULT_DETAIL_SEED,
            roughness: DEFAULT_ROUGHNESS,
            relief_slope: DEFAULT_RELIEF_SLOPE,
            max_amplitude: DEFAULT_MAX_AMPLITUDE,
        }
    }
}

impl DetailNoise {
    /// No detail: heights are the interpolated data.
    pub const OFF: DetailNoise = DetailNoise {
        seed: DEFAULT_DETAIL_SEED,
        roughness: 0.0,
        relief_slope: 0.0,
        max_amplitude: 0.0,
    };

    /// Whether any detail is added.
    pub fn is_on(&self) -> bool {
        self.roughness != 0.0 && self.roughness.is_finite()
    }

    /// The amplitude of octave 0, metres, for data spacing `spacing` metres: `roughness x
    /// spacing`, at most `max_amplitude` in size.
    pub fn amplitude(&self, spacing: f64) -> f64 {
        let a = self.roughness * spacing;
        let cap = self.max_amplitude.abs();
        if cap.is_nan() {
            a
        } else {
            a.clamp(-cap, cap)
        }
    }

    /// The most the detail can add or remove, in metres, for data spacing `spacing` metres:
    /// `|amplitude| x (1 + 1/2 + 1/4 + ...) = 2 |amplitude|` (each octave lies in `[-1, 1]`
    /// times its amplitude, the weight in `[0, 1]`).
    pub fn bound(&self, spacing: f64) -> f64 {
        if self.is_on() {
            2.0 * self.amplitude(spacing).abs()
        } else {
            0.0
        }
    }

    /// The relief weight of a data sample whose largest height difference to its neighbours is
    /// `relief` metres, for data spacing `spacing` metres.
    pub fn relief_weight(&self, relief: f64, spacing: f64) -> f64 {
        if self.relief_slope <= 0.0 || self.relief_slope.is_nan() {
            return 1.0;
        }
        (relief / (self.relief_slope * spacing)).clamp(0.0, 1.0)
    }

    /// The sum of octaves `0 .. octaves` at octave-0 noise coordinates `p` (the cube point times
    /// `2^(n-1)`), unweighted, for data spacing `spacing` metres.
    pub(crate) fn sum(&self, p: DVec3, octaves: u32, spacing: f64) -> f64 {
        // Eight octaves per call of the vector kernel (the scalar kernel's bits), added in
        // octave order: the same sum as one octave at a time.
        let octaves = octaves.min(MAX_DETAIL_OCTAVES) as usize;
        let mut total = 0.0;
        let mut scale = 1.0;
        let mut amp = self.amplitude(spacing);
        let mut k = 0;
        while k < octaves {
            let lanes = (octaves - k).min(LANES);
            let mut q = Lanes8::default();
            let mut s = scale;
            for l in 0..lanes {
                q.set(l, p * s, derive_seed(self.seed, (k + l) as u64));
                s *= 2.0;
            }
            let g = if lanes > 1 {
                gradient3_x8(&q)
            } else {
                [gradient3(p * scale, q.seed[0]); LANES]
            };
            for v in g.iter().take(lanes) {
                total += amp * v;
                amp *= 0.5;
            }
            scale = s;
            k += lanes;
        }
        total
    }
}

impl DetailNoise {
    /// [`DetailNoise::sum`] at every point of `points` (one octave count), into `out`, with the
    /// same bits: one octave at a time over all the points ([`gradient3_accumulate`]), each point's
    /// octaves still added in octave order.
    ///
    /// Panics when `out` and `points` differ in length (a caller's bug).
    pub(crate) fn sum_many(&self, points: &[DVec3], octaves: u32, spacing: f64, out: &mut [f64]) {
        assert_eq!(points.len(), out.len(), "one output per point");
        out.fill(0.0);
        let x: Vec<f64> = points.iter().map(|p| p.x).collect();
        let y: Vec<f64> = points.iter().map(|p| p.y).collect();
        let z: Vec<f64> = points.iter().map(|p| p.z).collect();
        let mut scale = 1.0;
        let mut amp = self.amplitude(spacing);
        for k in 0..octaves.min(MAX_DETAIL_OCTAVES) {
            gradient3_accumulate(&x, &y, &z, scale, derive_seed(self.seed, u64::from(k)), amp, out);
            scale *= 2.0;
            amp *= 0.5;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn many_points_at_once_give_the_bits_of_one_at_a_time() {
        let d = DetailNoise::default();
        let points: Vec<DVec3> = (0..203)
            .map(|i| {
                DVec3::new(
                    12.3 + 0.37 * f64::from(i),
                    -45.6 - 0.11 * f64::from(i),
                    789.01 + f64::from(i % 7),
                )
            })
            .collect();
        for octaves in [0u32, 1, 4, 9, 31] {
            let mut out = vec![f64::NAN; points.len()];
            d.sum_many(&points, octaves, 9000.0, &mut out);
            for (p, o) in points.iter().zip(&out) {
                assert_eq!(
                    o.to_bits(),
                    d.sum(*p, octaves, 9000.0).to_bits(),
                    "{octaves} octaves at {p}"
                );
            }
        }
    }

    #[test]
    fn eight_octaves_at_once_add_up_to_the_octave_by_octave_sum() {
        let d = DetailNoise::default();
        for (i, octaves) in [0u32, 1, 2, 7, 8, 9, 13, 24, 30].into_iter().enumerate() {
            let p = DVec3::new(12.3 + i as f64, -45.6, 789.01);
            let mut total = 0.0;
            let (mut scale, mut amp) = (1.0, d.amplitude(9000.0));
            for k in 0..octaves {
                total += amp * gradient3(p * scale, derive_seed(d.seed, u64::from(k)));
                scale *= 2.0;
                amp *= 0.5;
            }
            assert_eq!(
                d.sum(p, octaves, 9000.0).to_bits(),
                total.to_bits(),
                "{octaves} octaves"
            );
        }
    }
}
