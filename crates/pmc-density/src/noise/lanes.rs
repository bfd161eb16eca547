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
//! the same order: the split into cell and fraction (here one `floor` instruction and a
//! conversion, there the `1.5 * 2^52` rounding, which gives the same cell and fraction, and
//! beyond `2^51` lattice cells `floor` and the conversion's result), the wrapping 64-bit lattice
//! hash, the gradient coefficients (`-1`, `0` or `1`) multiplied and summed as
//! `(gx x + gy y) + gz z`, the quintic fades, the trilinear blend, the final scale; no
//! reassociation, and fused multiply-adds only where the product is exact (a gradient
//! coefficient times an offset), so that they round as the separate multiply and add do. So the
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

/// `out[i] += amp * gradient3((x[i], y[i], z[i]) * scale, seed)` for every `i`, bit for bit:
/// one octave of one field at many points (a height-field patch's thousands of vertices), added
/// to a running fractal sum.
///
/// On the vector path the points go through the lanes eight at a time inside one loop: no
/// per-call feature test, inputs read straight from the slices, the scaling and the sum done in
/// registers (a multiply, then an add: the scalar order), two groups of eight at a time so that
/// their chains overlap. Points on an axis-aligned plane of the noise lattice (a cube face's
/// points, whose third coordinate is a lattice integer) need only four of a cell's eight
/// corners: where two whole groups have a zero fraction along one axis, the four corners on that
/// plane give the same value (a fade of 0 leaves the lerps' first terms) up to the sign of a
/// zero, which the dropped corners decide: it is lost when added to a nonzero sum, and a group
/// where a zero value meets a zero sum is redone with all eight corners. The last `len % 8`
/// points take the scalar kernel.
///
/// Panics when the four slices differ in length (a caller's bug).
pub fn gradient3_accumulate(x: &[f64], y: &[f64], z: &[f64], scale: f64, seed: u64, amp: f64, out: &mut [f64]) {
    assert!(
        x.len() == out.len() && y.len() == out.len() && z.len() == out.len(),
        "one output per point"
    );
    #[cfg(target_arch = "x86_64")]
    let done = x86::gradient3_accumulate::<false>(x, y, z, scale, DVec3::ZERO, seed, amp, out);
    #[cfg(not(target_arch = "x86_64"))]
    let done = 0;
    for i in done..out.len() {
        out[i] += amp * gradient3(DVec3::new(x[i], y[i], z[i]) * scale, seed);
    }
}

/// `out[i] += amp * gradient3((x[i], y[i], z[i]) * scale + offset, seed)` for every `i`, bit for
/// bit: [`gradient3_accumulate`] with the lattice shifted by `offset` (a multiply, then an add,
/// as the scalar expression), which is how a fractal sum's octaves sample (each its own scale,
/// offset and seed). The fractal sums' slice methods ([`super::Fbm::sample_slices`],
/// [`super::Ridged::sample_slices`]) run one call per octave.
///
/// Panics when the four slices differ in length (a caller's bug).
#[allow(clippy::too_many_arguments)]
pub fn gradient3_accumulate_offset(
    x: &[f64],
    y: &[f64],
    z: &[f64],
    scale: f64,
    offset: DVec3,
    seed: u64,
    amp: f64,
    out: &mut [f64],
) {
    assert!(
        x.len() == out.len() && y.len() == out.len() && z.len() == out.len(),
        "one output per point"
    );
    #[cfg(target_arch = "x86_64")]
    let done = x86::gradient3_accumulate::<true>(x, y, z, scale, offset, seed, amp, out);
    #[cfg(not(target_arch = "x86_64"))]
    let done = 0;
    for i in done..out.len() {
        out[i] += amp * gradient3(DVec3::new(x[i], y[i], z[i]) * scale + offset, seed);
    }
}

/// Runs `f`, compiled for AVX-512 (F and DQ) where the processor has it: for straight-line
/// arithmetic over slices (`f` and what it inlines), which the compiler then vectorises eight
/// lanes wide instead of two. Lane-wise IEEE operations give the same bits at any width (and the
/// compiler fuses no multiply-add), so the results do not depend on the processor.
#[inline]
pub(crate) fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if x86::available() {
        return x86::wide(f);
    }
    f()
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
    use crate::noise::gradient::{GX, GY, GZ, SCALE};
    use crate::noise::hash::{FINAL_MUL, LATTICE_X, LATTICE_Y, LATTICE_Z};
    use pmc_geometry::glam::DVec3;
    use std::arch::x86_64::*;

    /// Whether this processor runs the kernel (AVX-512 F and DQ).
    #[inline]
    pub(crate) fn available() -> bool {
        std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512dq")
    }

    /// [`super::wide`] on a processor with AVX-512 F and DQ.
    #[inline]
    pub(crate) fn wide<R>(f: impl FnOnce() -> R) -> R {
        #[target_feature(enable = "avx512f,avx512dq")]
        unsafe fn run<R>(f: impl FnOnce() -> R) -> R {
            align_frame();
            f()
        }
        // SAFETY: only called where `available()` holds, the features `run` is compiled for.
        unsafe { run(f) }
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

    /// [`super::gradient3_accumulate`] for the leading multiple of eight points; returns how
    /// many were done (0 on a processor without AVX-512 F and DQ).
    /// With `OFFSET`, the points are shifted by `offset` after scaling.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn gradient3_accumulate<const OFFSET: bool>(
        x: &[f64],
        y: &[f64],
        z: &[f64],
        scale: f64,
        offset: DVec3,
        seed: u64,
        amp: f64,
        out: &mut [f64],
    ) -> usize {
        if !available() {
            return 0;
        }
        let n = out.len().min(x.len()).min(y.len()).min(z.len()) / LANES * LANES;
        // SAFETY: the processor has AVX-512 F and DQ (checked above); `accumulate_kernel` reads
        // and writes the first `n` entries only, and every slice holds at least `n`.
        unsafe {
            accumulate_kernel::<OFFSET>(
                x.as_ptr(),
                y.as_ptr(),
                z.as_ptr(),
                scale,
                [offset.x, offset.y, offset.z],
                seed,
                amp,
                out.as_mut_ptr(),
                n,
            )
        };
        n
    }

    /// `(cell, fraction)` of each lane, the scalar `split`'s bits: `floor(x)` by one rounding
    /// instruction, converted to an integer (exactly below `2^63`), and the fraction
    /// `x - floor(x)`. Below `2^51` the scalar `(x - round(x)) + 1` (where the rounding went up)
    /// rounds the same exact real once, since `x - round(x)` is exact; both give `+0` at
    /// integers, `-0` included. Beyond, the scalar kernel takes `floor` too.
    #[inline(always)]
    unsafe fn split(x: __m512d) -> (__m512i, __m512d) {
        let floor = _mm512_roundscale_pd::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x);
        (_mm512_cvtpd_epi64(floor), _mm512_sub_pd(x, floor))
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

    /// A corner's `(gx dx + gy dy) + gz dz` with the scalar kernel's bits: a multiply, then
    /// two fused multiply-adds. Each product of a gradient component (`-1`, `0` or `1`) by an
    /// offset is exact, so a fused `g d + t` rounds the same exact sum once, as the scalar
    /// `g d` then `+ t` does, and IEEE 754 gives its zeros the sign rules of that addition:
    /// the same number, the same bits, in three operations instead of five.
    #[inline(always)]
    unsafe fn dot(g: [__m512d; 3], dx: __m512d, dy: __m512d, dz: __m512d) -> __m512d {
        let t = _mm512_mul_pd(g[0], dx);
        let t = _mm512_fmadd_pd(g[1], dy, t);
        _mm512_fmadd_pd(g[2], dz, t)
    }

    #[target_feature(enable = "avx512f,avx512dq")]
    unsafe fn kernel(q: &Lanes8, out: &mut [f64; LANES]) {
        align_frame();
        let r = eval(
            _mm512_loadu_pd(q.x.as_ptr()),
            _mm512_loadu_pd(q.y.as_ptr()),
            _mm512_loadu_pd(q.z.as_ptr()),
            _mm512_loadu_si512(q.seed.as_ptr().cast()),
        );
        _mm512_storeu_pd(out.as_mut_ptr(), r);
    }

    /// Points `0..n` (a multiple of eight) of the slices, eight at a time, with one seed.
    #[target_feature(enable = "avx512f,avx512dq")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn accumulate_kernel<const OFFSET: bool>(
        x: *const f64,
        y: *const f64,
        z: *const f64,
        scale: f64,
        offset: [f64; 3],
        seed: u64,
        amp: f64,
        out: *mut f64,
        n: usize,
    ) {
        let seed = _mm512_set1_epi64(seed as i64);
        let (scale, amp) = (_mm512_set1_pd(scale), _mm512_set1_pd(amp));
        let (ox, oy, oz) = (
            _mm512_set1_pd(offset[0]),
            _mm512_set1_pd(offset[1]),
            _mm512_set1_pd(offset[2]),
        );
        // A multiply, then (with an offset) an add: the scalar `p * scale + offset`.
        macro_rules! place {
            ($v:expr, $o:expr) => {{
                let v = _mm512_mul_pd($v, scale);
                if OFFSET {
                    _mm512_add_pd(v, $o)
                } else {
                    v
                }
            }};
        }
        macro_rules! load {
            ($i:expr) => {
                [
                    place!(_mm512_loadu_pd(x.add($i)), ox),
                    place!(_mm512_loadu_pd(y.add($i)), oy),
                    place!(_mm512_loadu_pd(z.add($i)), oz),
                ]
            };
        }
        macro_rules! add {
            ($i:expr, $r:expr) => {
                let sum = _mm512_add_pd(_mm512_loadu_pd(out.add($i)), _mm512_mul_pd(amp, $r));
                _mm512_storeu_pd(out.add($i), sum);
            };
        }
        align_frame();
        let mut cache = PlaneCache::new();
        let mut corners = CornerCache::new();
        let mut i = 0;
        // Two groups at a time: their independent chains overlap in the processor.
        while i + 2 * LANES <= n {
            let (p, q) = (load!(i), load!(i + LANES));
            let groups = [
                [split(p[0]), split(p[1]), split(p[2])],
                [split(q[0]), split(q[1]), split(q[2])],
            ];
            // Shifted octaves (the fractal sums') have an offset that is no lattice integer, so
            // their points are not worth testing for a lattice plane.
            let planar = if OFFSET {
                None
            } else {
                eval_planar_x2(&groups, seed, &mut cache)
            };
            match planar {
                Some([(r, zr), (s, zs)]) => {
                    // A zero's sign is lost in a nonzero sum; where the sum so far is zero too,
                    // the full kernel decides it.
                    let zero = _mm512_setzero_pd();
                    let (o, t) = (_mm512_loadu_pd(out.add(i)), _mm512_loadu_pd(out.add(i + LANES)));
                    let r = if zr & _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(o, zero) != 0 {
                        eval_cells_cached(groups[0], seed, &mut corners)
                    } else {
                        r
                    };
                    let s = if zs & _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(t, zero) != 0 {
                        eval_cells_cached(groups[1], seed, &mut corners)
                    } else {
                        s
                    };
                    add!(i, r);
                    add!(i + LANES, s);
                }
                None => {
                    let (r, s) = eval_pair_cached(groups, seed, &mut corners);
                    add!(i, r);
                    add!(i + LANES, s);
                }
            }
            i += 2 * LANES;
        }
        if i < n {
            let p = load!(i);
            add!(i, eval(p[0], p[1], p[2], seed));
        }
    }

    /// Aligns the frame of the function it is inlined into to 64 bytes: a 64-byte aligned local
    /// whose address escapes makes the compiler align the whole frame. Kernels that spill
    /// 512-bit registers call it first, so that no spill slot straddles two cache lines (as in
    /// a frame aligned to 16 bytes only, the ABI's), which cost the slice kernel 15%, depending
    /// on where the caller's stack happened to lie.
    #[inline(always)]
    fn align_frame() {
        #[repr(align(64))]
        struct Align64(#[allow(dead_code)] [u8; 64]);
        std::hint::black_box(&mut Align64([0; 64]));
    }

    /// Two groups of eight evaluations when every lane of both has a zero fraction along the same
    /// axis, from the four corners on that lattice plane, each with the mask of its lanes whose
    /// value is zero (the sign of those zeros is the dropped corners' to decide); `None` when
    /// the groups do not lie on one plane.
    ///
    /// The full kernel's value there is the same number: with a zero fraction the fade is `+0`,
    /// so each lerp across that axis is `a + 0 (b - a)`, which is `a` unless `a` is zero, and the
    /// corner dots lose a `g 0` term, which changes a sum only when it is zero. IEEE additions
    /// and multiplications turn a difference in the sign of a zero only into another zero, so
    /// a nonzero result has the same bits, and a zero one may differ in its sign only.
    #[inline(always)]
    unsafe fn eval_planar_x2(
        groups: &[[(__m512i, __m512d); 3]; 2],
        seed: __m512i,
        cache: &mut PlaneCache,
    ) -> Option<[(__m512d, __mmask8); 2]> {
        let zero = _mm512_setzero_pd();
        let flat = |c: usize| {
            (_mm512_cmp_pd_mask::<_CMP_EQ_OQ>(groups[0][c].1, zero)
                & _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(groups[1][c].1, zero))
                == 0xFF
        };
        let axis = if flat(2) {
            2
        } else if flat(1) {
            1
        } else if flat(0) {
            0
        } else {
            return None;
        };
        let mut r = [zero; 2];
        for (g, [x, y, z]) in groups.iter().enumerate() {
            let hit = cache.axis == axis
                && (_mm512_cmpeq_epi64_mask(x.0, cache.cells[0])
                    & _mm512_cmpeq_epi64_mask(y.0, cache.cells[1])
                    & _mm512_cmpeq_epi64_mask(z.0, cache.cells[2]))
                    == 0xFF;
            if !hit {
                // The flat axis's cells, then the two free axes in the kernel's lerp order.
                cache.grads = match axis {
                    2 => plane_gradients::<LATTICE_Z, LATTICE_X, LATTICE_Y>(z.0, x.0, y.0, seed, &GX, &GY),
                    1 => plane_gradients::<LATTICE_Y, LATTICE_X, LATTICE_Z>(y.0, x.0, z.0, seed, &GX, &GZ),
                    _ => plane_gradients::<LATTICE_X, LATTICE_Y, LATTICE_Z>(x.0, y.0, z.0, seed, &GY, &GZ),
                };
                cache.cells = [x.0, y.0, z.0];
                cache.axis = axis;
            }
            let (fa, fb) = match axis {
                2 => (x.1, y.1),
                1 => (x.1, z.1),
                _ => (y.1, z.1),
            };
            r[g] = plane_value(&cache.grads, fa, fb);
        }
        let scale = _mm512_set1_pd(SCALE);
        Some([
            (_mm512_mul_pd(r[0], scale), _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(r[0], zero)),
            (_mm512_mul_pd(r[1], scale), _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(r[1], zero)),
        ])
    }

    /// The corner gradients of the last group evaluated on a lattice plane: consecutive groups
    /// of a row mostly share their cells in the coarser octaves, and so their corners' hashes.
    pub(super) struct PlaneCache {
        /// The flat axis (3: nothing cached yet).
        axis: u8,
        /// The lanes' cells along x, y and z.
        cells: [__m512i; 3],
        /// The gradient components along the two free axes at the four corners, in the order
        /// `(0, 0), (1, 0), (0, 1), (1, 1)`.
        grads: [(__m512d, __m512d); 4],
    }

    impl PlaneCache {
        #[inline(always)]
        unsafe fn new() -> PlaneCache {
            let (zi, zd) = (_mm512_setzero_si512(), _mm512_setzero_pd());
            PlaneCache {
                axis: 3,
                cells: [zi; 3],
                grads: [(zd, zd); 4],
            }
        }
    }

    /// The four corner gradients (components along the free axes) of a group's cells on the
    /// lattice plane of cells `across` (key step `K`), with cells `a` and `b` along the free
    /// axes (key steps `A` and `B`, gradient components `ga` and `gb`).
    #[inline(always)]
    unsafe fn plane_gradients<const K: u64, const A: u64, const B: u64>(
        across: __m512i,
        a: __m512i,
        b: __m512i,
        seed: __m512i,
        ga: &[f64; 16],
        gb: &[f64; 16],
    ) -> [(__m512d, __m512d); 4] {
        let a0 = _mm512_mullo_epi64(a, _mm512_set1_epi64(A as i64));
        let b0 = _mm512_mullo_epi64(b, _mm512_set1_epi64(B as i64));
        let a1 = _mm512_add_epi64(a0, _mm512_set1_epi64(A as i64));
        let b1 = _mm512_add_epi64(b0, _mm512_set1_epi64(B as i64));
        // The seed goes with the y key in the kernel; xor is associative, so it can go anywhere.
        let k = _mm512_xor_si512(_mm512_mullo_epi64(across, _mm512_set1_epi64(K as i64)), seed);
        let (ta, tb) = (Table::new(ga), Table::new(gb));
        [
            plane_gradient(a0, b0, k, &ta, &tb),
            plane_gradient(a1, b0, k, &ta, &tb),
            plane_gradient(a0, b1, k, &ta, &tb),
            plane_gradient(a1, b1, k, &ta, &tb),
        ]
    }

    /// A group's unscaled value on a lattice plane from its corner gradients and its fractions
    /// along the free axes.
    #[inline(always)]
    unsafe fn plane_value(g: &[(__m512d, __m512d); 4], fa: __m512d, fb: __m512d) -> __m512d {
        let one = _mm512_set1_pd(1.0);
        let (da, db) = (_mm512_sub_pd(fa, one), _mm512_sub_pd(fb, one));
        let n00 = plane_dot(g[0], fa, fb);
        let n10 = plane_dot(g[1], da, fb);
        let n01 = plane_dot(g[2], fa, db);
        let n11 = plane_dot(g[3], da, db);
        let (u, v) = (fade(fa), fade(fb));
        lerp(v, lerp(u, n00, n10), lerp(u, n01, n11))
    }

    /// The gradient components along a plane's two free axes at the corner with keys `p` and
    /// `q` along them and `k` (seeded) across: [`corner_gradients`]' hash and table lookups.
    #[inline(always)]
    unsafe fn plane_gradient(p: __m512i, q: __m512i, k: __m512i, ta: &Table, tb: &Table) -> (__m512d, __m512d) {
        let idx = corner_index(_mm512_xor_si512(p, q), k);
        (ta.get(idx), tb.get(idx))
    }

    /// A corner's value on a plane: `ga da + gb db`, the second product fused into the sum
    /// (exact products: the same bits, as in [`dot`]).
    #[inline(always)]
    unsafe fn plane_dot(g: (__m512d, __m512d), da: __m512d, db: __m512d) -> __m512d {
        _mm512_fmadd_pd(g.1, db, _mm512_mul_pd(g.0, da))
    }

    /// The eight evaluations of the points `(x, y, z)` with seeds `seed`, lane by lane.
    #[inline(always)]
    unsafe fn eval(x: __m512d, y: __m512d, z: __m512d, seed: __m512i) -> __m512d {
        eval_cells([split(x), split(y), split(z)], seed)
    }

    /// [`eval`] from the points' cells and fractions along x, y and z: [`eval_gradients`] of
    /// [`corner_gradients`] (the same operations on the same numbers, so the same bits), with
    /// each corner hashed, looked up and dotted in turn and each blend taken as soon as its two
    /// values are there, so that a few corners' values are live at once instead of all 24
    /// gradient components.
    #[inline(always)]
    unsafe fn eval_cells(cells: [(__m512i, __m512d); 3], seed: __m512i) -> __m512d {
        let [(ix, fx), (iy, fy), (iz, fz)] = cells;
        let keys = CornerKeys::new(ix, iy, iz, seed);
        let (tx, ty, tz) = (Table::new(&GX), Table::new(&GY), Table::new(&GZ));
        let one = _mm512_set1_pd(1.0);
        let (gx, gy, gz) = (_mm512_sub_pd(fx, one), _mm512_sub_pd(fy, one), _mm512_sub_pd(fz, one));
        let (u, v, w) = (fade(fx), fade(fy), fade(fz));
        // (A macro, not a closure: a closure would be compiled without the kernel's features.)
        macro_rules! corner {
            ($xy:expr, $z:expr, $dx:expr, $dy:expr, $dz:expr) => {{
                let idx = corner_index($xy, $z);
                dot([tx.get(idx), ty.get(idx), tz.get(idx)], $dx, $dy, $dz)
            }};
        }
        // One layer of four corners (`z` the layer's key part, `dz` its offset), blended along
        // x, then y.
        macro_rules! layer {
            ($z:expr, $dz:expr) => {{
                let l0 = lerp(
                    u,
                    corner!(keys.k00, $z, fx, fy, $dz),
                    corner!(keys.k10, $z, gx, fy, $dz),
                );
                let l1 = lerp(
                    u,
                    corner!(keys.k01, $z, fx, gy, $dz),
                    corner!(keys.k11, $z, gx, gy, $dz),
                );
                lerp(v, l0, l1)
            }};
        }
        let a = layer!(keys.z0, fz);
        let b = layer!(keys.z1, gz);
        _mm512_mul_pd(lerp(w, a, b), _mm512_set1_pd(SCALE))
    }

    /// [`eval_cells`] of two groups, reusing corner gradients where a group lies in the same
    /// cells as the group before it (every lane): the second group the first's, the first those
    /// kept in `cache`.
    ///
    /// Gradients are kept (24 register stores) only where the two groups of a pair share their
    /// cells, so that points which rarely do (scattered ones, fine octaves) do not pay the
    /// stores for nothing, while a run of groups in the same cells (nearby points in a coarse
    /// octave) computes its gradients once. The values are the same whichever gradients are
    /// reused: the same numbers.
    #[inline(always)]
    unsafe fn eval_pair_cached(
        groups: [[(__m512i, __m512d); 3]; 2],
        seed: __m512i,
        cache: &mut CornerCache,
    ) -> (__m512d, __m512d) {
        let [[(ix, fx), (iy, fy), (iz, fz)], [(jx, gx), (jy, gy), (jz, gz)]] = groups;
        // (A macro, not a closure: a closure would be compiled without the kernel's features.)
        macro_rules! same {
            ($a:expr, $b:expr, $c:expr, $cells:expr) => {
                (_mm512_cmpeq_epi64_mask($a, $cells[0])
                    & _mm512_cmpeq_epi64_mask($b, $cells[1])
                    & _mm512_cmpeq_epi64_mask($c, $cells[2]))
                    == 0xFF
            };
        }
        let hit = cache.valid && same!(ix, iy, iz, cache.cells);
        let pair = same!(jx, jy, jz, [ix, iy, iz]);
        if hit {
            let r = eval_gradients(&cache.grads, fx, fy, fz);
            if pair {
                return (r, eval_gradients(&cache.grads, gx, gy, gz));
            }
            cache.valid = false;
            return (r, eval_cells(groups[1], seed));
        }
        if pair {
            cache.grads = corner_gradients(ix, iy, iz, seed);
            cache.cells = [ix, iy, iz];
            cache.valid = true;
            return (
                eval_gradients(&cache.grads, fx, fy, fz),
                eval_gradients(&cache.grads, gx, gy, gz),
            );
        }
        cache.valid = false;
        (eval_cells(groups[0], seed), eval_cells(groups[1], seed))
    }

    /// [`eval_cells`] reusing the corner gradients of the last group when every lane lies in
    /// the same cells as that group's (a batch of nearby points in a coarse octave), else
    /// computing and keeping them.
    #[inline(always)]
    unsafe fn eval_cells_cached(cells: [(__m512i, __m512d); 3], seed: __m512i, cache: &mut CornerCache) -> __m512d {
        let [(ix, fx), (iy, fy), (iz, fz)] = cells;
        let hit = cache.valid
            && (_mm512_cmpeq_epi64_mask(ix, cache.cells[0])
                & _mm512_cmpeq_epi64_mask(iy, cache.cells[1])
                & _mm512_cmpeq_epi64_mask(iz, cache.cells[2]))
                == 0xFF;
        if !hit {
            cache.grads = corner_gradients(ix, iy, iz, seed);
            cache.cells = [ix, iy, iz];
            cache.valid = true;
        }
        eval_gradients(&cache.grads, fx, fy, fz)
    }

    /// The corner gradients of the last group evaluated with one seed (see
    /// [`eval_cells_cached`]).
    pub(super) struct CornerCache {
        /// Whether `cells` and `grads` hold a group's.
        valid: bool,
        /// The lanes' cells along x, y and z.
        cells: [__m512i; 3],
        /// The gradients `(gx, gy, gz)` of the eight corners, in [`corner_gradients`]' order.
        grads: [[__m512d; 3]; 8],
    }

    impl CornerCache {
        #[inline(always)]
        unsafe fn new() -> CornerCache {
            CornerCache {
                valid: false,
                cells: [_mm512_setzero_si512(); 3],
                grads: [[_mm512_setzero_pd(); 3]; 8],
            }
        }
    }

    /// The parts of a group's corner keys: the four `x ^ y` (seeded) pairs and the two `z`
    /// terms, each corner's key `x ^ y ^ z` (xor is associative: any grouping gives the same
    /// bits as the scalar `corner_hash` input).
    struct CornerKeys {
        k00: __m512i,
        k10: __m512i,
        k01: __m512i,
        k11: __m512i,
        z0: __m512i,
        z1: __m512i,
    }

    impl CornerKeys {
        #[inline(always)]
        unsafe fn new(ix: __m512i, iy: __m512i, iz: __m512i, seed: __m512i) -> CornerKeys {
            let x0 = _mm512_mullo_epi64(ix, _mm512_set1_epi64(LATTICE_X as i64));
            let y0 = _mm512_mullo_epi64(iy, _mm512_set1_epi64(LATTICE_Y as i64));
            let z0 = _mm512_mullo_epi64(iz, _mm512_set1_epi64(LATTICE_Z as i64));
            let x1 = _mm512_add_epi64(x0, _mm512_set1_epi64(LATTICE_X as i64));
            let y1 = _mm512_add_epi64(y0, _mm512_set1_epi64(LATTICE_Y as i64));
            let z1 = _mm512_add_epi64(z0, _mm512_set1_epi64(LATTICE_Z as i64));
            let (y0, y1) = (_mm512_xor_si512(y0, seed), _mm512_xor_si512(y1, seed));
            CornerKeys {
                k00: _mm512_xor_si512(x0, y0),
                k10: _mm512_xor_si512(x1, y0),
                k01: _mm512_xor_si512(x0, y1),
                k11: _mm512_xor_si512(x1, y1),
                z0,
                z1,
            }
        }
    }

    /// The gradient index (the top four bits of `corner_hash`) of the corner with key parts
    /// `xy` and `z`.
    #[inline(always)]
    unsafe fn corner_index(xy: __m512i, z: __m512i) -> __m512i {
        let key = _mm512_xor_si512(xy, z);
        let h = _mm512_mullo_epi64(
            _mm512_xor_si512(key, _mm512_srli_epi64::<32>(key)),
            _mm512_set1_epi64(FINAL_MUL as i64),
        );
        _mm512_srli_epi64::<60>(h)
    }

    /// The gradients `(gx, gy, gz)` of the eight corners of the cells `(ix, iy, iz)`, in the
    /// order `000, 100, 010, 110, 001, 101, 011, 111` (bits x, y, z): each corner's key hashed
    /// (`corner_hash`) and its top four bits looked up in the gradient tables.
    #[inline(always)]
    unsafe fn corner_gradients(ix: __m512i, iy: __m512i, iz: __m512i, seed: __m512i) -> [[__m512d; 3]; 8] {
        let k = CornerKeys::new(ix, iy, iz, seed);
        let (tx, ty, tz) = (Table::new(&GX), Table::new(&GY), Table::new(&GZ));
        // (Macros, not closures: a closure would be compiled without the kernel's features.)
        macro_rules! grad {
            ($xy:expr, $z:expr) => {{
                let idx = corner_index($xy, $z);
                [tx.get(idx), ty.get(idx), tz.get(idx)]
            }};
        }
        [
            grad!(k.k00, k.z0),
            grad!(k.k10, k.z0),
            grad!(k.k01, k.z0),
            grad!(k.k11, k.z0),
            grad!(k.k00, k.z1),
            grad!(k.k10, k.z1),
            grad!(k.k01, k.z1),
            grad!(k.k11, k.z1),
        ]
    }

    /// The eight lanes' values from their corner gradients and fractions: each corner's
    /// [`dot`], the fades, the trilinear blend and the scale, in the scalar order.
    #[inline(always)]
    unsafe fn eval_gradients(g: &[[__m512d; 3]; 8], fx: __m512d, fy: __m512d, fz: __m512d) -> __m512d {
        let one = _mm512_set1_pd(1.0);
        let (gx, gy, gz) = (_mm512_sub_pd(fx, one), _mm512_sub_pd(fy, one), _mm512_sub_pd(fz, one));
        let n000 = dot(g[0], fx, fy, fz);
        let n100 = dot(g[1], gx, fy, fz);
        let n010 = dot(g[2], fx, gy, fz);
        let n110 = dot(g[3], gx, gy, fz);
        let n001 = dot(g[4], fx, fy, gz);
        let n101 = dot(g[5], gx, fy, gz);
        let n011 = dot(g[6], fx, gy, gz);
        let n111 = dot(g[7], gx, gy, gz);
        let (u, v, w) = (fade(fx), fade(fy), fade(fz));
        let a = lerp(v, lerp(u, n000, n100), lerp(u, n010, n110));
        let b = lerp(v, lerp(u, n001, n101), lerp(u, n011, n111));
        _mm512_mul_pd(lerp(w, a, b), _mm512_set1_pd(SCALE))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::hash::{mix64, unit_f64};

    /// Points that stress the split and the hash: random ones at several scales (up to Earth
    /// radius and far beyond), exact integers, halves, values a hair off integers, negative zero.
    fn hard_points(n: usize) -> Vec<(DVec3, u64)> {
        let mut out = Vec::new();
        for i in 0..n as u64 {
            let r = |k: u64| unit_f64(mix64(i * 7 + k)) * 2.0 - 1.0;
            // Up to 2e15 (about 2^51 lattice cells, where the scalar kernel's rounding stops)
            // and far beyond, out of the range of `i64`.
            let scale = [1.0, 37.0, 1e3, 6.4e6, 3e9, 2e15, 1e17, 1e300][(i % 8) as usize];
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

    /// The accumulated octave of many points, by the scalar kernel.
    fn accumulate_scalar(pts: &[DVec3], scale: f64, seed: u64, amp: f64, out: &mut [f64]) {
        for (p, o) in pts.iter().zip(out) {
            *o += amp * gradient3(*p * scale, seed);
        }
    }

    fn check_accumulate(pts: &[DVec3], scale: f64, seed: u64, amp: f64) {
        let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            pts.iter().map(|p| p.x).collect(),
            pts.iter().map(|p| p.y).collect(),
            pts.iter().map(|p| p.z).collect(),
        );
        let start: Vec<f64> = (0..pts.len()).map(|i| [0.0, -0.0, 1.5, -2.25][i % 4]).collect();
        let (mut got, mut want) = (start.clone(), start);
        gradient3_accumulate(&x, &y, &z, scale, seed, amp, &mut got);
        accumulate_scalar(pts, scale, seed, amp, &mut want);
        for i in 0..pts.len() {
            assert_eq!(
                got[i].to_bits(),
                want[i].to_bits(),
                "{:?} x {scale}, seed {seed}",
                pts[i]
            );
        }
    }

    #[test]
    fn offset_slices_equal_scalar_calls_bit_for_bit() {
        let pts: Vec<DVec3> = hard_points(4_005).into_iter().map(|p| p.0).collect();
        let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            pts.iter().map(|p| p.x).collect(),
            pts.iter().map(|p| p.y).collect(),
            pts.iter().map(|p| p.z).collect(),
        );
        let offsets = [
            DVec3::ZERO,
            DVec3::new(-0.0, 0.0, -0.0),
            DVec3::new(517.25, -0.5, 1023.999),
            DVec3::new(-6.4e6, 3.0, 0.125),
        ];
        for (k, offset) in offsets.into_iter().enumerate() {
            for scale in [1.0, 2.03, 1e-3] {
                let start: Vec<f64> = (0..pts.len()).map(|i| [0.0, -0.0, 0.5][i % 3]).collect();
                let (mut got, mut want) = (start.clone(), start);
                gradient3_accumulate_offset(&x, &y, &z, scale, offset, 99 + k as u64, 0.25, &mut got);
                for (p, w) in pts.iter().zip(want.iter_mut()) {
                    *w += 0.25 * gradient3(*p * scale + offset, 99 + k as u64);
                }
                for i in 0..pts.len() {
                    assert_eq!(
                        got[i].to_bits(),
                        want[i].to_bits(),
                        "{:?} x {scale} + {offset:?}",
                        pts[i]
                    );
                }
            }
        }
    }

    #[test]
    fn accumulated_slices_equal_scalar_calls_bit_for_bit() {
        let pts: Vec<DVec3> = hard_points(20_003).into_iter().map(|p| p.0).collect();
        for (len, seed) in [(0, 1u64), (5, 2), (8, 3), (20_003, 0xDEAD_BEEF)] {
            check_accumulate(&pts[..len], 1.0, seed, 0.75);
            check_accumulate(&pts[..len], 0.125, seed, -3.0);
        }
    }

    /// Points on lattice planes (the fast path) and on lattice lines and points (where values
    /// are zero and the sign of a zero is decided by all eight corners), on each axis, with
    /// negative zeros and huge coordinates: the bits of the scalar kernel.
    #[test]
    fn points_on_lattice_planes_equal_scalar_calls_bit_for_bit() {
        let mut pts = Vec::new();
        for axis in 0..3 {
            for plane in [-7.0, -0.0, 0.0, 3.0, 1e6, -4.5e6] {
                for i in 0..64 {
                    for j in 0..24 {
                        // Free coordinates on a grid of quarter and eighth steps, and some
                        // random ones.
                        let (a, b) = if j < 16 {
                            (f64::from(i) * 0.125 - 3.0, f64::from(j) * 0.25 - 2.0)
                        } else {
                            let r = |k: u64| unit_f64(mix64(k ^ (i as u64) << 8 ^ (j as u64) << 20)) * 40.0 - 20.0;
                            (r(1), r(2))
                        };
                        let p = match axis {
                            0 => DVec3::new(plane, a, b),
                            1 => DVec3::new(a, plane, b),
                            _ => DVec3::new(a, b, plane),
                        };
                        pts.push(p);
                    }
                }
            }
        }
        for seed in [0u64, 7, u64::MAX] {
            check_accumulate(&pts, 1.0, seed, 0.5);
            check_accumulate(&pts, 4.0, seed, 1.0);
            check_accumulate(&pts, 0.5, seed, 1.0);
        }
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
