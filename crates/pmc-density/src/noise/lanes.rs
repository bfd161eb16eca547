//! Eight gradient-noise evaluations at once: [`gradient3_x8`], bit for bit the same as eight
//! calls of [`gradient3`].
//!
//! Callers batch evaluations that do not depend on each other: the octaves of a fractal sum
//! ([`super::Fbm`], [`super::Ridged`]), or the next entries of the earth preset's octave ladder.
//!
//! # Same bits on every machine
//!
//! On x86-64 processors with AVX-512 (F and DQ: 64-bit lane multiplies and two-table permutes)
//! the eight evaluations run in the lanes of 512-bit registers; elsewhere they are eight scalar
//! calls. The vector kernel performs, lane by lane, exactly the scalar kernel's IEEE operations in
//! the same order: the `1.5 * 2^52` split, the wrapping 64-bit lattice hash, the gradient
//! coefficients (`-1`, `0` or `1`) multiplied and summed as `(gx x + gy y) + gz z`, the quintic
//! fades, the trilinear blend, the final scale; no fused multiply-add, no reassociation. So the
//! results are the same bits on both paths (tested on random and adversarial points), and a
//! planet is byte-identical whatever the processor.
//!
//! The vector path is chosen at run time (`is_x86_feature_detected!`, cached by the standard
//! library), so one binary runs everywhere.

use super::gradient::gradient3;
use pmc_geometry::glam::DVec3;

/// Evaluations per call.
pub const LANES: usize = 8;

/// Fractal sums batch their octaves from this many on: one call costs about as much as four
/// scalar evaluations on the vector path.
pub(crate) const BATCH_FROM: usize = 4;

/// Eight points (lattice units) and a seed for each: the input of [`gradient3_x8`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lanes8 {
    /// The x coordinates.
    pub x: [f64; LANES],
    /// The y coordinates.
    pub y: [f64; LANES],
    /// The z coordinates.
    pub z: [f64; LANES],
    /// The seeds.
    pub seed: [u64; LANES],
}

impl Lanes8 {
    /// Sets lane `l` to point `p` with seed `seed`.
    #[inline(always)]
    pub fn set(&mut self, l: usize, p: DVec3, seed: u64) {
        self.x[l] = p.x;
        self.y[l] = p.y;
        self.z[l] = p.z;
        self.seed[l] = seed;
    }
}

/// `gradient3(p_l, seed_l)` for the eight lanes of `q`, bit for bit (see the module docs).
#[inline]
pub fn gradient3_x8(q: &Lanes8) -> [f64; LANES] {
    #[cfg(target_arch = "x86_64")]
    if let Some(n) = x86::gradient3_x8(q) {
        return n;
    }
    scalar(q)
}

/// The eight evaluations by the scalar kernel.
#[inline]
pub(crate) fn scalar(q: &Lanes8) -> [f64; LANES] {
    std::array::from_fn(|l| gradient3(DVec3::new(q.x[l], q.y[l], q.z[l]), q.seed[l]))
}

/// The AVX-512 kernel.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
pub(crate) mod x86 {
    use super::{Lanes8, LANES};
    use crate::noise::gradient::{GX, GY, GZ, ROUND_MAGIC, SCALE};
    use crate::noise::hash::{FINAL_MUL, LATTICE_X, LATTICE_Y, LATTICE_Z};
    use std::arch::x86_64::*;

    /// Whether this processor runs the kernel (AVX-512 F and DQ).
    #[inline]
    fn available() -> bool {
        std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512dq")
    }

    /// The eight evaluations in 512-bit lanes, or `None` on a processor without AVX-512 F and
    /// DQ.
    #[inline]
    pub(crate) fn gradient3_x8(q: &Lanes8) -> Option<[f64; LANES]> {
        if !available() {
            return None;
        }
        let mut out = [0.0; LANES];
        // SAFETY: the processor has AVX-512 F and DQ (checked above), the only features
        // `kernel` is compiled for; its loads and stores stay inside `q` and `out` (arrays of
        // exactly eight lanes).
        unsafe { kernel(q, &mut out) };
        Some(out)
    }

    /// `(cell, fraction)` of each lane, as the scalar `split`: the `1.5 * 2^52` rounding, one
    /// subtracted from cells (one added to fractions) where the rounding went up.
    #[inline(always)]
    unsafe fn split(x: __m512d) -> (__m512i, __m512d) {
        let magic = _mm512_set1_pd(ROUND_MAGIC);
        let t = _mm512_add_pd(x, magic);
        let rounded = _mm512_sub_pd(t, magic);
        let below = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(rounded, x);
        let cell = _mm512_sub_epi64(_mm512_castpd_si512(t), _mm512_set1_epi64(ROUND_MAGIC.to_bits() as i64));
        let cell = _mm512_mask_sub_epi64(cell, below, cell, _mm512_set1_epi64(1));
        let one = _mm512_maskz_mov_pd(below, _mm512_set1_pd(1.0));
        (cell, _mm512_add_pd(_mm512_sub_pd(x, rounded), one))
    }

    /// The quintic fade `t t t (t (t 6 - 15) + 10)`, in the scalar order.
    #[inline(always)]
    unsafe fn fade(t: __m512d) -> __m512d {
        let t3 = _mm512_mul_pd(_mm512_mul_pd(t, t), t);
        let inner = _mm512_sub_pd(_mm512_mul_pd(t, _mm512_set1_pd(6.0)), _mm512_set1_pd(15.0));
        let inner = _mm512_add_pd(_mm512_mul_pd(t, inner), _mm512_set1_pd(10.0));
        _mm512_mul_pd(t3, inner)
    }

    /// `a + t (b - a)`.
    #[inline(always)]
    unsafe fn lerp(t: __m512d, a: __m512d, b: __m512d) -> __m512d {
        _mm512_add_pd(a, _mm512_mul_pd(t, _mm512_sub_pd(b, a)))
    }

    /// The sixteen gradient components of one axis, as two registers of eight.
    struct Table {
        lo: __m512d,
        hi: __m512d,
    }

    impl Table {
        #[inline(always)]
        unsafe fn new(v: &[f64; 16]) -> Table {
            Table {
                lo: _mm512_loadu_pd(v.as_ptr()),
                hi: _mm512_loadu_pd(v.as_ptr().add(8)),
            }
        }
        /// Entry `idx` (0..16) of each lane.
        #[inline(always)]
        unsafe fn get(&self, idx: __m512i) -> __m512d {
            _mm512_permutex2var_pd(self.lo, idx, self.hi)
        }
    }

    /// The contribution of one corner: the hash of its key picks a gradient, dotted with the
    /// offset `(dx, dy, dz)` as `(gx dx + gy dy) + gz dz`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn corner(
        key: __m512i,
        dx: __m512d,
        dy: __m512d,
        dz: __m512d,
        tx: &Table,
        ty: &Table,
        tz: &Table,
    ) -> __m512d {
        let h = _mm512_mullo_epi64(
            _mm512_xor_si512(key, _mm512_srli_epi64::<32>(key)),
            _mm512_set1_epi64(FINAL_MUL as i64),
        );
        let idx = _mm512_srli_epi64::<60>(h);
        let xy = _mm512_add_pd(_mm512_mul_pd(tx.get(idx), dx), _mm512_mul_pd(ty.get(idx), dy));
        _mm512_add_pd(xy, _mm512_mul_pd(tz.get(idx), dz))
    }

    #[target_feature(enable = "avx512f,avx512dq")]
    unsafe fn kernel(q: &Lanes8, out: &mut [f64; LANES]) {
        let (ix, fx) = split(_mm512_loadu_pd(q.x.as_ptr()));
        let (iy, fy) = split(_mm512_loadu_pd(q.y.as_ptr()));
        let (iz, fz) = split(_mm512_loadu_pd(q.z.as_ptr()));
        let seed = _mm512_loadu_si512(q.seed.as_ptr().cast());
        let x0 = _mm512_mullo_epi64(ix, _mm512_set1_epi64(LATTICE_X as i64));
        let y0 = _mm512_mullo_epi64(iy, _mm512_set1_epi64(LATTICE_Y as i64));
        let z0 = _mm512_mullo_epi64(iz, _mm512_set1_epi64(LATTICE_Z as i64));
        let x1 = _mm512_add_epi64(x0, _mm512_set1_epi64(LATTICE_X as i64));
        let y1 = _mm512_add_epi64(y0, _mm512_set1_epi64(LATTICE_Y as i64));
        let z1 = _mm512_add_epi64(z0, _mm512_set1_epi64(LATTICE_Z as i64));
        let (y0, y1) = (_mm512_xor_si512(y0, seed), _mm512_xor_si512(y1, seed));
        let one = _mm512_set1_pd(1.0);
        let (gx, gy, gz) = (_mm512_sub_pd(fx, one), _mm512_sub_pd(fy, one), _mm512_sub_pd(fz, one));
        let (tx, ty, tz) = (Table::new(&GX), Table::new(&GY), Table::new(&GZ));
        let key = |a: __m512i, b: __m512i, c: __m512i| _mm512_xor_si512(_mm512_xor_si512(a, b), c);
        let n000 = corner(key(x0, y0, z0), fx, fy, fz, &tx, &ty, &tz);
        let n100 = corner(key(x1, y0, z0), gx, fy, fz, &tx, &ty, &tz);
        let n010 = corner(key(x0, y1, z0), fx, gy, fz, &tx, &ty, &tz);
        let n110 = corner(key(x1, y1, z0), gx, gy, fz, &tx, &ty, &tz);
        let n001 = corner(key(x0, y0, z1), fx, fy, gz, &tx, &ty, &tz);
        let n101 = corner(key(x1, y0, z1), gx, fy, gz, &tx, &ty, &tz);
        let n011 = corner(key(x0, y1, z1), fx, gy, gz, &tx, &ty, &tz);
        let n111 = corner(key(x1, y1, z1), gx, gy, gz, &tx, &ty, &tz);
        let (u, v, w) = (fade(fx), fade(fy), fade(fz));
        let a = lerp(v, lerp(u, n000, n100), lerp(u, n010, n110));
        let b = lerp(v, lerp(u, n001, n101), lerp(u, n011, n111));
        let r = _mm512_mul_pd(lerp(w, a, b), _mm512_set1_pd(SCALE));
        _mm512_storeu_pd(out.as_mut_ptr(), r);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::hash::{mix64, unit_f64};

    /// Points that stress the split and the hash: random ones at several scales (up to Earth
    /// radius and beyond), exact integers, halves, values a hair off integers, negative zero.
    fn hard_points(n: usize) -> Vec<(DVec3, u64)> {
        let mut out = Vec::new();
        for i in 0..n as u64 {
            let r = |k: u64| unit_f64(mix64(i * 7 + k)) * 2.0 - 1.0;
            let scale = [1.0, 37.0, 1e3, 6.4e6, 3e9][(i % 5) as usize];
            let mut p = DVec3::new(r(0), r(1), r(2)) * scale;
            match i % 7 {
                1 => p = p.round(),
                2 => p = p.round() + DVec3::splat(0.5),
                3 => p = DVec3::new(p.x.round().next_down(), p.y.round().next_up(), -0.0),
                4 => p = DVec3::new(-p.x.abs(), 0.0, p.z),
                _ => {}
            }
            out.push((p, mix64(i ^ 0xABCD)));
        }
        out
    }

    #[test]
    fn eight_lanes_equal_eight_scalar_calls_bit_for_bit() {
        let pts = hard_points(40_000);
        for batch in pts.chunks_exact(LANES) {
            let mut q = Lanes8::default();
            for (l, (p, s)) in batch.iter().enumerate() {
                q.set(l, *p, *s);
            }
            let got = gradient3_x8(&q);
            let want = scalar(&q);
            for l in 0..LANES {
                assert_eq!(
                    got[l].to_bits(),
                    want[l].to_bits(),
                    "lane {l}: {:?} seed {}",
                    batch[l].0,
                    batch[l].1
                );
            }
        }
    }
}
