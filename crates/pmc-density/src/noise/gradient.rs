//! 3D gradient noise (Perlin's "improved" noise: quintic fade, cube-edge gradients) in `f64`.
//!
//! Differences from the textbook version:
//!
//! - The lattice is hashed from the full `i64` cell coordinates and a seed by an integer mixer
//!   ([`super::hash`]), not looked up in a 256-entry permutation table, so the pattern never
//!   repeats (a table repeats every 256 cells, which shows at planetary scale).
//! - The cell index and the fraction are split in `f64` (`x - floor(x)` is exact), so the noise
//!   keeps full resolution at coordinates of `1e7` and beyond: at Earth radius (6.4e6 m) the
//!   fraction is still resolved to about `1e-9` cells.
//! - The output is scaled by `1 / GRADIENT_RAW_MAX` so that it provably lies in `[-1, 1]`.
//!
//! # Range
//!
//! With the twelve cube-edge gradients `g`, the raw value at fraction `f` is
//! `sum_c w_c(f) (g_c . (f - c))` over the eight corners `c`, with weights `w_c >= 0` summing to
//! one. Whatever gradients the hash picks, its magnitude is at most
//! `sum_c w_c(f) max_g |g . (f - c)|`, and `max_g |g . d|` is the sum of the two largest `|d_i|`.
//! Maximising that envelope over the unit cell (a fine grid search refined around the maximum,
//! at `f = (0.35526, 0.48149, 0.5)` and its mirror images) gives [`GRADIENT_RAW_MAX`]
//! `= 1.0363538...`; the envelope is reached when every corner's gradient points the worst way,
//! so the bound is tight.

use super::hash::{corner_hash, LATTICE_X, LATTICE_Y, LATTICE_Z};
use pmc_geometry::glam::DVec3;
use pmc_geometry::math::lerp;

/// The largest magnitude the unscaled noise can reach (see the module docs for the derivation).
pub const GRADIENT_RAW_MAX: f64 = 1.036_353_811_211_803;

/// Scale applied to the raw value so that the output lies in `[-1, 1]`.
pub(super) const SCALE: f64 = 1.0 / GRADIENT_RAW_MAX;

/// Gradient components indexed by the top four hash bits: the twelve cube-edge directions, then
/// four of them again (a regular tetrahedron, so the repeats add no directional bias on average).
pub(super) const GX: [f64; 16] = [1., -1., 1., -1., 1., -1., 1., -1., 0., 0., 0., 0., 1., -1., 0., 0.];
pub(super) const GY: [f64; 16] = [1., 1., -1., -1., 0., 0., 0., 0., 1., -1., 1., -1., 1., 1., -1., -1.];
pub(super) const GZ: [f64; 16] = [0., 0., 0., 0., 1., 1., -1., -1., 1., 1., -1., -1., 0., 0., 1., -1.];

/// `1.5 * 2^52`: adding it to a double of magnitude below `2^51` rounds to an integer, whose
/// value then sits in the low mantissa bits.
pub(super) const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// Splits `x` into its lattice cell `floor(x)` and the fraction `x - floor(x)` in `[0, 1]`.
///
/// Rounds with the `1.5 * 2^52` trick rather than a float-to-int conversion (which needs
/// saturation fix-ups) or a libm `floor` call (targets without SSE4.1): a handful of branchless
/// instructions. `x - round(x)` is exact (Sterbenz). The rounding holds for `|x| < 2^51` (2e15
/// lattice cells, far beyond any planet); beyond, where coordinates no longer resolve a cell, the
/// cell is `floor(x)` converted as the vector kernel's instruction does (out of the range of
/// `i64`: `i64::MIN`), so that both kernels agree on every input. The fraction is 1 only when `x`
/// is a hair below an integer, where the noise is continuous across the cell face, so the value
/// is still right.
#[cfg(test)]
fn split(x: f64) -> (i64, f64) {
    if x.abs() >= SPLIT_LIMIT {
        split_far(x)
    } else {
        split_near(x)
    }
}

/// [`split`] for `|x| < 2^51`, the rounding (see there).
#[inline(always)]
fn split_near(x: f64) -> (i64, f64) {
    let t = x + ROUND_MAGIC;
    let rounded = t - ROUND_MAGIC;
    let below = rounded > x;
    let i = (t.to_bits() as i64).wrapping_sub(ROUND_MAGIC.to_bits() as i64) - i64::from(below);
    let f = (x - rounded) + f64::from(u8::from(below));
    (i, f)
}

/// `2^51`: the coordinates `split` rounds with [`ROUND_MAGIC`].
const SPLIT_LIMIT: f64 = 2_251_799_813_685_248.0;

/// [`split`] beyond `2^51` lattice cells: `floor(x)`, converted to `i64` as x86's `cvtpd2qq`
/// does (`i64::MIN` where it does not fit), and `x - floor(x)`. Below `2^51` it gives
/// [`split_near`]'s cell and fraction.
#[cold]
fn split_far(x: f64) -> (i64, f64) {
    let floor = x.floor();
    let cell = if floor.abs() < 9_223_372_036_854_775_808.0 {
        floor as i64
    } else {
        i64::MIN
    };
    (cell, x - floor)
}

/// The quintic fade `6t^5 - 15t^4 + 10t^3` (zero first and second derivative at 0 and 1).
#[inline(always)]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Dot product of the gradient chosen by hash `h` with the offset `(x, y, z)`.
#[inline(always)]
fn grad(h: u64, x: f64, y: f64, z: f64) -> f64 {
    let i = (h >> 60) as usize;
    GX[i] * x + GY[i] * y + GZ[i] * z
}

/// Gradient noise at `p` (lattice units) for `seed`: a value in `[-1, 1]`, zero at lattice points,
/// smooth (C2) everywhere, deterministic.
///
/// Any `u64` works as a seed; seeds that come out of [`super::derive_seed`] are the best
/// separated.
#[inline]
pub fn gradient3(p: DVec3, seed: u64) -> f64 {
    let c = Cell::new(p);
    c.eval(seed)
}

/// Two independent noise fields at the same point: `(gradient3(p, seed_a), gradient3(p, seed_b))`
/// bit for bit, sharing the lattice split and the fade weights (about 1.6 times the cost of
/// one).
#[inline]
pub fn gradient3_pair(p: DVec3, seed_a: u64, seed_b: u64) -> (f64, f64) {
    let c = Cell::new(p);
    (c.eval(seed_a), c.eval(seed_b))
}

/// The lattice cell of a point: pre-multiplied corner coordinates, fractions and fade weights.
struct Cell {
    x0: u64,
    x1: u64,
    y0: u64,
    y1: u64,
    z0: u64,
    z1: u64,
    f: [f64; 3],
    g: [f64; 3],
    w: [f64; 3],
}

impl Cell {
    #[inline(always)]
    fn new(p: DVec3) -> Cell {
        // One test for the three coordinates: below 2^51 both splits agree, so a point with any
        // coordinate beyond takes `split_far` for all three.
        let far = p.x.abs().max(p.y.abs()).max(p.z.abs()) >= SPLIT_LIMIT;
        let [(ix, fx), (iy, fy), (iz, fz)] = if far {
            [split_far(p.x), split_far(p.y), split_far(p.z)]
        } else {
            [split_near(p.x), split_near(p.y), split_near(p.z)]
        };
        let x0 = (ix as u64).wrapping_mul(LATTICE_X);
        let y0 = (iy as u64).wrapping_mul(LATTICE_Y);
        let z0 = (iz as u64).wrapping_mul(LATTICE_Z);
        Cell {
            x0,
            x1: x0.wrapping_add(LATTICE_X),
            y0,
            y1: y0.wrapping_add(LATTICE_Y),
            z0,
            z1: z0.wrapping_add(LATTICE_Z),
            f: [fx, fy, fz],
            g: [fx - 1.0, fy - 1.0, fz - 1.0],
            w: [fade(fx), fade(fy), fade(fz)],
        }
    }

    #[inline(always)]
    fn eval(&self, seed: u64) -> f64 {
        let [fx, fy, fz] = self.f;
        let [gx, gy, gz] = self.g;
        let (y0, y1) = (self.y0 ^ seed, self.y1 ^ seed);
        let (x0, x1, z0, z1) = (self.x0, self.x1, self.z0, self.z1);
        let n000 = grad(corner_hash(x0 ^ y0 ^ z0), fx, fy, fz);
        let n100 = grad(corner_hash(x1 ^ y0 ^ z0), gx, fy, fz);
        let n010 = grad(corner_hash(x0 ^ y1 ^ z0), fx, gy, fz);
        let n110 = grad(corner_hash(x1 ^ y1 ^ z0), gx, gy, fz);
        let n001 = grad(corner_hash(x0 ^ y0 ^ z1), fx, fy, gz);
        let n101 = grad(corner_hash(x1 ^ y0 ^ z1), gx, fy, gz);
        let n011 = grad(corner_hash(x0 ^ y1 ^ z1), fx, gy, gz);
        let n111 = grad(corner_hash(x1 ^ y1 ^ z1), gx, gy, gz);
        let [u, v, w] = self.w;
        let a = lerp(lerp(n000, n100, u), lerp(n010, n110, u), v);
        let b = lerp(lerp(n001, n101, u), lerp(n011, n111, u), v);
        lerp(a, b, w) * SCALE
    }
}

/// Single-octave gradient noise with a seed and a frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradientNoise {
    /// Lattice seed (any value; see [`gradient3`]).
    pub seed: u64,
    /// Lattice cells per unit of input (the input is multiplied by it).
    pub frequency: f64,
}

impl GradientNoise {
    /// Noise with `seed` at frequency 1.
    pub fn new(seed: u64) -> Self {
        GradientNoise {
            seed: super::derive_seed(seed, 0),
            frequency: 1.0,
        }
    }

    /// The noise at `p * frequency`, in `[-1, 1]`.
    #[inline]
    pub fn sample(&self, p: DVec3) -> f64 {
        gradient3(p * self.frequency, self.seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::hash::mix64;

    /// Deterministic pseudo-random points in a cube of half-size `scale` around `centre`.
    fn points(n: usize, centre: f64, scale: f64, salt: u64) -> impl Iterator<Item = DVec3> {
        (0..n as u64).map(move |i| {
            let h = |k: u64| crate::noise::hash::unit_f64(mix64(i * 3 + k + salt * 1_000_003)) * 2.0 - 1.0;
            DVec3::new(centre + h(0) * scale, centre + h(1) * scale, centre + h(2) * scale)
        })
    }

    #[test]
    fn split_is_floor_and_exact() {
        let xs = [
            0.0,
            0.5,
            -0.5,
            1.5,
            2.5,
            -1.5,
            -2.5,
            -1.0,
            1.0,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        let more = [
            1e7 + 0.25,
            -1e7 - 0.75,
            6.4e6 * 37.3,
            -3.0000001,
            1e15 + 0.5,
            -1e15 - 0.5,
            2251799813685247.5,
            // From 2^51 on, `floor` (as the vector kernel's instruction).
            2251799813685248.5,
            -2251799813685248.5,
            4503599627370497.0,
            -1e17,
            9.2e18,
        ];
        for x in xs.into_iter().chain(more) {
            let (i, f) = split(x);
            assert_eq!(i as f64, x.floor(), "{x}");
            assert_eq!(f, x - x.floor(), "{x}");
            assert!((0.0..1.0).contains(&f));
        }
        for k in 0..100_000u64 {
            let x = (crate::noise::hash::unit_f64(mix64(k)) - 0.5) * 10f64.powi((k % 16) as i32);
            let (i, f) = split(x);
            assert_eq!(i as f64, x.floor(), "{x}");
            assert_eq!(f, x - x.floor(), "{x}");
            // Below 2^51 both splits give the same bits (a point takes one split for all three
            // coordinates).
            let (j, g) = split_far(x);
            assert_eq!((j, g.to_bits()), (i, f.to_bits()), "{x}");
        }
        // Out of the range of i64 the cell is i64::MIN, as x86's conversion gives, and the
        // fraction 0.
        for x in [9.3e18, -9.3e18, 1e300, -1e300, f64::MAX] {
            assert_eq!(split(x), (i64::MIN, 0.0), "{x}");
        }
        // A hair below an integer the fraction may round to 1; the value is continuous there.
        let x = -1e-20;
        let (i, f) = split(x);
        assert_eq!((i, f), (-1, 1.0));
        assert!((gradient3(DVec3::new(x, 0.3, 0.4), 1) - gradient3(DVec3::new(0.0, 0.3, 0.4), 1)).abs() < 1e-12);
    }

    #[test]
    fn deterministic() {
        for p in points(1000, 0.0, 100.0, 1) {
            assert_eq!(gradient3(p, 7).to_bits(), gradient3(p, 7).to_bits());
        }
    }

    #[test]
    fn range_is_bounded_and_used() {
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        let (mut sum, mut sum2) = (0.0, 0.0);
        let n = 100_000;
        for p in points(n, 0.0, 1000.0, 2) {
            let v = gradient3(p, 99);
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            sum2 += v * v;
        }
        assert!(lo >= -1.0 - 1e-12 && hi <= 1.0 + 1e-12, "range [{lo}, {hi}]");
        assert!(lo < -0.6 && hi > 0.6, "range [{lo}, {hi}] is too narrow");
        let mean = sum / n as f64;
        let std = (sum2 / n as f64 - mean * mean).sqrt();
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!(std > 0.1 && std < 0.4, "std {std}");
    }

    #[test]
    fn worst_case_configuration_reaches_the_bound() {
        // Evaluate the envelope of the module docs directly: at its maximiser, with each corner's
        // gradient chosen the worst way, the raw value equals GRADIENT_RAW_MAX.
        let f = DVec3::new(0.355_256_69, 0.481_492_21, 0.5);
        let mut total = 0.0;
        for c in 0..8 {
            let corner = DVec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64);
            let d = f - corner;
            let w = |t: f64, k: f64| if k == 1.0 { fade(t) } else { 1.0 - fade(t) };
            let weight = w(f.x, corner.x) * w(f.y, corner.y) * w(f.z, corner.z);
            let best = (0..12)
                .map(|i| (GX[i] * d.x + GY[i] * d.y + GZ[i] * d.z).abs())
                .fold(0.0, f64::max);
            total += weight * best;
        }
        assert!((total - GRADIENT_RAW_MAX).abs() < 1e-9, "{total}");
    }

    #[test]
    fn continuous() {
        // The gradient of the scaled noise is bounded (a few units per cell): a step of 1e-6 cells
        // moves the value by far less than 1e-4.
        for p in points(10_000, 0.0, 50.0, 3) {
            for step in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE] {
                let a = gradient3(p, 5);
                let b = gradient3(p + step * 1e-6, 5);
                assert!((a - b).abs() < 1e-4, "jump {a} -> {b} at {p}");
            }
        }
    }

    #[test]
    fn zero_at_lattice_points_and_smooth_across_cells() {
        for i in -5..5 {
            let p = DVec3::new(i as f64, 2.0 * i as f64, -3.0);
            assert_eq!(gradient3(p, 11), 0.0);
            let eps = 1e-7;
            let l = gradient3(p - DVec3::X * eps, 11);
            let r = gradient3(p + DVec3::X * eps, 11);
            assert!((l + r).abs() < 1e-10, "derivative not continuous across the cell face");
        }
    }

    #[test]
    fn seeds_differ() {
        let mut differing = 0;
        for p in points(1000, 0.0, 100.0, 4) {
            if (gradient3(p, 1) - gradient3(p, 2)).abs() > 1e-3 {
                differing += 1;
            }
        }
        assert!(differing > 900, "{differing}");
    }

    #[test]
    fn no_period_of_256_cells() {
        // A permutation table would make x and x + 256 equal; hashing the full coordinate does not.
        let mut same = 0;
        for p in points(1000, 0.0, 100.0, 5) {
            for shift in [
                DVec3::X * 256.0,
                DVec3::Y * 256.0,
                DVec3::Z * 256.0,
                DVec3::ONE * 4096.0,
            ] {
                if (gradient3(p, 3) - gradient3(p + shift, 3)).abs() < 1e-6 {
                    same += 1;
                }
            }
        }
        assert!(same < 10, "{same} of 4000 values repeat with a shift of 256 cells");
    }

    #[test]
    fn works_at_large_coordinates() {
        // Near 1e7 cells (Earth radius times a frequency of ~1.5), steps of 1e-3 cells still give
        // smooth, distinct values, and the range holds.
        let mut prev = None;
        let mut distinct = 0;
        for k in 0..2000 {
            let p = DVec3::new(1.0e7 + k as f64 * 1e-3, -9.87e6, 6.4e6 + 0.3);
            let v = gradient3(p, 17);
            assert!(v.is_finite() && v.abs() <= 1.0 + 1e-12);
            if let Some(pv) = prev {
                let d: f64 = v - pv;
                assert!(d.abs() < 0.01, "jump at {p}");
                if d != 0.0 {
                    distinct += 1;
                }
            }
            prev = Some(v);
        }
        assert!(distinct > 1900, "the fraction is quantised: {distinct} distinct steps");
        // Far from the origin the statistics are those near the origin.
        let far: Vec<f64> = points(20_000, 1.0e7, 1000.0, 6).map(|p| gradient3(p, 17)).collect();
        let std = (far.iter().map(|v| v * v).sum::<f64>() / far.len() as f64).sqrt();
        assert!(std > 0.1 && std < 0.4, "std {std}");
    }

    #[test]
    fn pair_matches_two_calls() {
        for p in points(1000, 0.0, 300.0, 7) {
            let (a, b) = gradient3_pair(p, 3, 4);
            assert_eq!(a.to_bits(), gradient3(p, 3).to_bits());
            assert_eq!(b.to_bits(), gradient3(p, 4).to_bits());
        }
    }

    #[test]
    fn gradient_noise_struct_scales_its_input() {
        let n = GradientNoise {
            seed: 9,
            frequency: 2.0,
        };
        let p = DVec3::new(0.3, 0.7, -1.1);
        assert_eq!(n.sample(p), gradient3(p * 2.0, 9));
        assert_ne!(GradientNoise::new(1).seed, GradientNoise::new(2).seed);
    }
}
