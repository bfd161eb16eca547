//! Building blocks shared by the presets: layout scales, masks, the column/voxel split behind
//! every preset's batch sampling, spaghetti caves and overhang displacement.
//!
//! # Exact skipping
//!
//! A preset's density is `min(D0, C)`: the displaced terrain `D0` carved by the cave field `C`.
//! Both 3D noise terms are only evaluated where they can matter, and every shortcut returns the
//! bits the full formula would give:
//!
//! - The overhang displacement is multiplied by a radial window that is exactly zero more than
//!   `reach` from the column's surface, so there the formula is `(h - r) + 0 = h - r`.
//! - The cave field has a lower bound that needs no noise, `-t S + P(r)`. Where that bound is at
//!   least `D0`, `min(D0, C) = D0`.

use crate::noise::{gradient3, gradient3_accumulate, gradient3_pair, octaves_for, wide, DEFAULT_LACUNARITY};
use crate::{Density, ShellColumns};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

pub(crate) use pmc_geometry::math::{lerp, smoothstep};

/// The scales of a layout that the presets express their features in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scales {
    /// Planet radius (the outermost voxel layer), metres.
    pub radius: f64,
    /// Radius of voxel layer 0 (`d_b`), metres.
    pub base: f64,
    /// Shell thickness `T = l_d n_t d_c`, metres: relief is expressed as fractions of it.
    pub thickness: f64,
    /// Voxel depth `l_d`, metres.
    pub l_d: f64,
    /// Horizontal tile size at the planet radius, `(pi / 2) R / (n_c n_t)`, metres.
    pub tile: f64,
}

impl Scales {
    /// The scales of `layout`.
    pub fn new(layout: &Layout) -> Self {
        let radius = layout.radius();
        Scales {
            radius,
            base: layout.d_b(),
            thickness: layout.l_d() * layout.depth_tiles() as f64,
            l_d: layout.l_d(),
            tile: std::f64::consts::FRAC_PI_2 * radius / layout.face_tiles() as f64,
        }
    }

    /// The radius at fraction `f` of the shell (`d_b + f T`).
    pub fn shell(&self, f: f64) -> f64 {
        self.base + f * self.thickness
    }

    /// Noise frequency (lattice cells per unit of direction) for features of `wavelength` metres
    /// at the planet surface.
    pub fn freq(&self, wavelength: f64) -> f64 {
        self.radius / wavelength
    }

    /// Octaves from features of `coarsest` metres down to about `finest` metres, at most `cap`.
    pub fn octaves(&self, coarsest: f64, finest: f64, cap: u32) -> u32 {
        octaves_for(coarsest, finest, DEFAULT_LACUNARITY).min(cap)
    }
}

/// `(|p|, p / |p|)`: a point's radius and direction from the planet's centre, the direction
/// `+y` at the centre itself.
#[inline]
pub(crate) fn radial(p: DVec3) -> (f64, DVec3) {
    let r = p.length();
    (r, if r > 0.0 { p / r } else { DVec3::Y })
}

/// A density split into per-direction work (the column) and per-radius work (the voxel).
pub(crate) trait ColumnModel: Send + Sync + 'static {
    /// What a column computes once for all its radii.
    type Column: Send + Sync + 'static;
    /// The column along unit direction `dir`.
    fn column(&self, dir: DVec3) -> Self::Column;
    /// The columns along many unit directions into `out` (cleared first): the same values as
    /// [`column`](Self::column) one by one. Models whose columns sum noise override it to sample
    /// each fractal sum over all the directions at once.
    fn columns(&self, dirs: &[DVec3], out: &mut Vec<Self::Column>) {
        out.clear();
        out.extend(dirs.iter().map(|d| self.column(*d)));
    }
    /// The density at `p = dir * r` (with `r = |p|`) in that column.
    fn voxel(&self, col: &Self::Column, dir: DVec3, p: DVec3, r: f64) -> f64;
    /// The densities of a chunk's columns `cols` (along `dirs`) at every radius of `radii`:
    /// `out[k * dirs.len() + d]` is `voxel(cols[d], dirs[d], p, |p|) as f32` with
    /// `p = dirs[d] * radii[k]`, the same bits. Models whose voxels read noise override it to
    /// sample the noise of all the voxels that need it at once.
    fn voxels(&self, cols: &[Self::Column], dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        let n = dirs.len();
        for (d, (dir, col)) in dirs.iter().zip(cols).enumerate() {
            for (k, r) in radii.iter().enumerate() {
                let p = *dir * *r;
                out[k * n + d] = self.voxel(col, *dir, p, p.length()) as f32;
            }
        }
    }
    /// Sound radial bounds (see [`Density::radial_bounds`]).
    fn bounds(&self) -> (f64, f64);
    /// The radius of the column's ground before the 3D features move it (see
    /// [`Density::ground_radii`]).
    fn ground_radius(&self, col: &Self::Column) -> f64;
}

/// The key of a model shared by a terrain's density and shader, for [`ShellColumns`]: its
/// address, unique among the models alive.
pub(crate) fn model_key<M>(model: &Arc<M>) -> usize {
    Arc::as_ptr(model) as *const () as usize
}

/// A [`ColumnModel`] as a [`Density`]: the batch call evaluates each column once.
///
/// Point calls normalise `p` to find the column; the batch uses the given unit directions. Both
/// use `r = |p|` with `p = dir * r` computed the same way, so they differ only by the rounding of
/// the direction (a few `1e-16` relative), which the `f32` output almost always hides.
pub(crate) struct ColumnDensity<M>(pub Arc<M>);

impl<M: ColumnModel> Density for ColumnDensity<M> {
    fn density(&self, p: DVec3) -> f64 {
        let (r, dir) = radial(p);
        let col = self.0.column(dir);
        self.0.voxel(&col, dir, p, r)
    }

    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        let n = dirs.len();
        let mut cols = Vec::with_capacity(n);
        self.0.columns(dirs, &mut cols);
        self.0.voxels(&cols, dirs, radii, out);
    }

    /// The batch, keeping its columns (`Vec<M::Column>`, one per direction) for the shader.
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        let owner = model_key(&self.0);
        columns.keep(owner, dirs, |cols| self.0.columns(dirs, cols));
        let cols = columns.get::<M::Column>(owner, dirs).expect("the columns just kept");
        self.0.voxels(cols, dirs, radii, out);
    }

    fn radial_bounds(&self) -> Option<(f64, f64)> {
        Some(self.0.bounds())
    }

    /// The columns' heights (their fractal sums run to the model's finest octave whatever
    /// `detail` asks: a column is one batch of them).
    fn ground_radii(&self, dirs: &[DVec3], _detail: f64, out: &mut [f64]) -> bool {
        assert_eq!(out.len(), dirs.len(), "output buffer has the wrong size");
        let mut cols = Vec::with_capacity(dirs.len());
        self.0.columns(dirs, &mut cols);
        for (o, c) in out.iter_mut().zip(&cols) {
            *o = self.0.ground_radius(c);
        }
        true
    }
}

/// Maps a point of a column to 3D noise coordinates with separate horizontal and vertical
/// lengths: `dir * (r0 / lh + (r - r0) / lv)`. Horizontally the noise varies over `lh` metres
/// (near `r0`), radially over `lv`, so features can be sized in tiles across and voxels deep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stretch {
    r0_h: f64,
    r0: f64,
    inv_v: f64,
}

impl Stretch {
    /// Horizontal length `lh` and vertical length `lv` (metres), about reference radius `r0`.
    pub fn new(lh: f64, lv: f64, r0: f64) -> Self {
        Stretch {
            r0_h: r0 / lh,
            r0,
            inv_v: 1.0 / lv,
        }
    }

    /// Noise coordinates of radius `r` along `dir`.
    #[inline]
    pub fn at(&self, dir: DVec3, r: f64) -> DVec3 {
        dir * (self.r0_h + (r - self.r0) * self.inv_v)
    }
}

/// Points at which one noise field is wanted, gathered as coordinate slices, with the noise
/// then evaluated over all of them at once ([`gradient3_accumulate`], eight per vector
/// operation).
#[derive(Default)]
pub(crate) struct NoiseBatch {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl NoiseBatch {
    /// Sets the points to `point(0)`, ..., `point(len - 1)` (one write per coordinate into
    /// slices sized once: a tighter loop than pushing).
    #[inline]
    pub fn set_points(&mut self, len: usize, point: impl Fn(usize) -> DVec3) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.clear();
            c.resize(len, 0.0);
        }
        for (j, ((x, y), z)) in self.x.iter_mut().zip(&mut self.y).zip(&mut self.z).enumerate() {
            let p = point(j);
            (*x, *y, *z) = (p.x, p.y, p.z);
        }
    }

    /// `gradient3(point, seed)` at every point, in order, except that a negative zero comes out
    /// as a positive one (`0 + 1 n`): for callers that square the value or add it, scaled, to a
    /// nonzero sum.
    pub fn values(&self, seed: u64, out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.x.len(), 0.0);
        gradient3_accumulate(&self.x, &self.y, &self.z, 1.0, seed, 1.0, out);
    }
}

/// The densities of columns whose voxel is `caves.carve(overhang.displace(h, a, dir, r), band,
/// dir, r)` (no overhangs: `caves.carve(h - r, band, dir, r)`), `parts` giving each column's
/// `(h, a, band)`: [`ColumnModel::voxels`] for such models, the same bits as the voxel calls.
///
/// One layer of radius at a time, in passes over the layer's columns as slices: the radii and
/// `h - r` with the overhang windows' test (straight-line arithmetic the compiler vectorises),
/// the displacement noise of the voxels inside a window sampled at once, the caves' noise-free
/// bound and test, their two noises sampled at once where they can carve, the conversion to
/// `f32`.
// The negated comparisons keep `Overhang::window`'s tests exactly, NaN included.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(crate) fn carved_voxels<C>(
    overhang: Option<&Overhang>,
    caves: &Spaghetti,
    cols: &[C],
    parts: impl Fn(&C) -> (f64, f64, CaveBand),
    dirs: &[DVec3],
    radii: &[f64],
    out: &mut [f32],
) {
    let n = dirs.len();
    assert_eq!(cols.len(), n, "one column a direction");
    assert_eq!(out.len(), n * radii.len(), "output buffer has the wrong size");
    if n == 0 {
        return;
    }
    // Eleven arrays of a value per column in one allocation, at a fixed stride (the same layout
    // every call).
    let mut store = vec![0.0; 11 * n];
    let [dx, dy, dz, h, amp, reach, mid, half, rs, d0, pen] = {
        let mut parts = store.chunks_exact_mut(n);
        std::array::from_fn(|_| parts.next().expect("eleven arrays"))
    };
    for (d, c) in cols.iter().enumerate() {
        let (ch, a, band) = parts(c);
        (dx[d], dy[d], dz[d]) = (dirs[d].x, dirs[d].y, dirs[d].z);
        (h[d], amp[d]) = (ch, a);
        // `Overhang::window` gives no weight where `a <= 0` or `|h - r| >= reach`: an infinite
        // reach that no `|h - r|` is below stands for the first.
        reach[d] = match overhang {
            Some(o) if !(a <= 0.0) => o.reach(a),
            _ => f64::NEG_INFINITY,
        };
        (mid[d], half[d]) = (band.mid, band.half);
    }
    let mut flags = vec![0u8; n];
    let (mut noise, mut slots, mut n1, mut n2) = (NoiseBatch::default(), Vec::<u32>::new(), Vec::new(), Vec::new());
    // The gathered amplitudes, reaches and values of the voxels an overhang window holds.
    let (mut wa, mut wr, mut wz) = (Vec::<f64>::new(), Vec::<f64>::new(), Vec::<f64>::new());
    let (seed_a, seed_b) = caves.seeds();
    let (slope, neg_ts) = (caves.slope, caves.neg_ts);
    for (k, &rk) in radii.iter().enumerate() {
        // One pass: r = |dir * rk| as glam computes it, `h - r`, whether an overhang window
        // holds it (flag bit 0), the caves' bound without noise `-t S + P(r)` and whether it is
        // below `h - r` (bit 1; tested again where a displacement moves `h - r`).
        wide(|| {
            let (rs, d0, pen, flags) = (&mut rs[..n], &mut d0[..n], &mut pen[..n], &mut flags[..n]);
            let (dx, dy, dz, h, reach) = (&dx[..n], &dy[..n], &dz[..n], &h[..n], &reach[..n]);
            let (mid, half) = (&mid[..n], &half[..n]);
            for d in 0..n {
                let (x, y, z) = (dx[d] * rk, dy[d] * rk, dz[d] * rk);
                let r = (x * x + y * y + z * z).sqrt();
                let b = h[d] - r;
                let p = slope * ((r - mid[d]).abs() - half[d]).max(0.0);
                rs[d] = r;
                d0[d] = b;
                pen[d] = p;
                flags[d] = (!(b.abs() >= reach[d]) as u8) | (((neg_ts + p < b) as u8) << 1);
            }
        });
        if let Some(o) = overhang {
            let at = flagged(&flags, 1, &mut slots);
            noise.set_points(at.len(), |j| {
                let d = at[j] as usize;
                o.point(dirs[d], rs[d])
            });
            if !at.is_empty() {
                noise.values(o.seed(), &mut n1);
                // The window's weight `a w` only where it holds the voxel (a division each, on
                // the gathered values eight lanes wide), and the caves' test again at the
                // displaced value.
                let m = at.len();
                for (slot, src) in [(&mut wa, &amp[..]), (&mut wr, &reach[..]), (&mut wz, &d0[..])] {
                    slot.clear();
                    slot.extend(at.iter().map(|&d| src[d as usize]));
                }
                wide(|| {
                    let (wa, wr, wz, n1) = (&wa[..m], &wr[..m], &mut wz[..m], &n1[..m]);
                    for j in 0..m {
                        wz[j] = Overhang::weight(wa[j], wr[j], wz[j].abs()) * n1[j];
                    }
                });
                for (&d, shift) in at.iter().zip(&wz) {
                    let d = d as usize;
                    d0[d] += shift;
                    flags[d] = 1 | (((neg_ts + pen[d] < d0[d]) as u8) << 1);
                }
            }
        }
        let at = flagged(&flags, 2, &mut slots);
        noise.set_points(at.len(), |j| {
            let d = at[j] as usize;
            caves.point(dirs[d], rs[d])
        });
        if !at.is_empty() {
            noise.values(seed_a, &mut n1);
            noise.values(seed_b, &mut n2);
            for (j, &d) in at.iter().enumerate() {
                let d = d as usize;
                d0[d] = caves.carve_with(d0[d], pen[d], n1[j], n2[j]);
            }
        }
        for (o, v) in out[k * n..(k + 1) * n].iter_mut().zip(d0.iter()) {
            *o = *v as f32;
        }
    }
}

/// The indices of the flags with a bit of `mask` set, in order, written into `slots` (grown to
/// `flags.len() + 8` once and not cleared: every index returned is written first): eight flags
/// without one are skipped at a time, and a group of eight with any is compacted without a
/// branch per flag (the flags' pattern is irregular, so per-flag branches mispredict).
#[inline]
fn flagged<'a>(flags: &[u8], mask: u8, slots: &'a mut Vec<u32>) -> &'a [u32] {
    if slots.len() < flags.len() + 8 {
        slots.resize(flags.len() + 8, 0);
    }
    let idx = &mut slots[..];
    let mut m = 0;
    let word_mask = u64::from_le_bytes([mask; 8]);
    let mut chunks = flags.chunks_exact(8);
    for (c, eight) in chunks.by_ref().enumerate() {
        let word = u64::from_le_bytes(eight.try_into().expect("eight flags"));
        if word & word_mask != 0 {
            // `m + 8 <= c * 8 + 8 <= idx.len()`: the eight stores stay inside.
            let group = &mut idx[m..m + 8];
            let mut k = 0;
            for (j, &b) in eight.iter().enumerate() {
                group[k] = (c * 8 + j) as u32;
                k += usize::from(b & mask != 0);
            }
            m += k;
        }
    }
    let start = flags.len() / 8 * 8;
    for (j, &b) in chunks.remainder().iter().enumerate() {
        if b & mask != 0 {
            idx[m] = (start + j) as u32;
            m += 1;
        }
    }
    &slots[..m]
}

/// Mean gradient magnitude of [`gradient3`] per lattice unit (measured: 1.1), used to turn noise
/// values into approximate metres.
const MEAN_NOISE_GRADIENT: f64 = 1.1;

/// Where caves may open in one column: the band `|r - mid| <= half`. Outside it the cave field
/// rises by `slope` per metre, so tunnels end with a ceiling or floor within a few metres. A
/// negative `half` closes the band; `-closed` closes it everywhere in the shell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CaveBand {
    mid: f64,
    half: f64,
}

/// Spaghetti caves: two 3D noise fields, air where both are near zero (the tubes along the
/// intersection of their zero sets). The field is
/// `C = (sqrt(n1^2 + n2^2) - t) S + slope max(0, |r - mid| - half)`, about metres from the tube
/// wall (`S = lv / 1.1`).
#[derive(Clone, Debug)]
pub(crate) struct Spaghetti {
    seed_a: u64,
    seed_b: u64,
    stretch: Stretch,
    threshold: f64,
    scale: f64,
    neg_ts: f64,
    slope: f64,
    closed: f64,
}

impl Spaghetti {
    /// Tubes whose noise varies over `lh` metres across and `lv` metres in depth, air where
    /// `sqrt(n1^2 + n2^2) < threshold` (tube radius about `threshold lh / 1.1` across and
    /// `threshold lv / 1.1` in depth, spacing about `lh`). `slope` closes the band;
    /// `closed` is the band half-width used for "no caves here" (a shell thickness is plenty).
    pub fn new(seeds: (u64, u64), lh: f64, lv: f64, r0: f64, threshold: f64, slope: f64, closed: f64) -> Self {
        let scale = lv / MEAN_NOISE_GRADIENT;
        Spaghetti {
            seed_a: seeds.0,
            seed_b: seeds.1,
            stretch: Stretch::new(lh, lv, r0),
            threshold,
            scale,
            neg_ts: -(threshold * scale),
            slope,
            closed,
        }
    }

    /// The band from `bottom` to `top` (radii), opened by `gate` in `[0, 1]` (0 closes it
    /// completely, continuously).
    #[inline]
    pub fn band(&self, bottom: f64, top: f64, gate: f64) -> CaveBand {
        let half = 0.5 * (top - bottom);
        CaveBand {
            mid: 0.5 * (top + bottom),
            half: gate * half - (1.0 - gate) * self.closed,
        }
    }

    /// The lowest value the tube part of the field takes, `-t S` (metres, negative): inside its
    /// band the field is never below it, so carving lowers the density by at most that much
    /// below zero.
    pub fn floor(&self) -> f64 {
        self.neg_ts
    }

    /// How far below a band's bottom a tube can still open air.
    pub fn reach_below(&self) -> f64 {
        self.threshold * self.scale / self.slope
    }

    /// `min(d0, C)` at radius `r` along `dir`, evaluating noise only where `C < d0` is possible.
    #[inline]
    pub fn carve(&self, d0: f64, band: &CaveBand, dir: DVec3, r: f64) -> f64 {
        match self.penalty(d0, band, r) {
            None => d0,
            Some(pen) => {
                let (n1, n2) = gradient3_pair(self.point(dir, r), self.seed_a, self.seed_b);
                self.carve_with(d0, pen, n1, n2)
            }
        }
    }

    /// The band's penalty at radius `r` when the tubes can go below `d0` there (their noise is
    /// needed), `None` when [`carve`](Self::carve) gives `d0` without noise.
    #[inline]
    pub fn penalty(&self, d0: f64, band: &CaveBand, r: f64) -> Option<f64> {
        let pen = self.slope * ((r - band.mid).abs() - band.half).max(0.0);
        // sqrt(..) >= 0, so C >= -t S + pen (the operations are monotone, also when rounded).
        (self.neg_ts + pen < d0).then_some(pen)
    }

    /// Where the two tube noises are sampled at radius `r` along `dir`.
    #[inline]
    pub fn point(&self, dir: DVec3, r: f64) -> DVec3 {
        self.stretch.at(dir, r)
    }

    /// The seeds of the two tube noises.
    pub fn seeds(&self) -> (u64, u64) {
        (self.seed_a, self.seed_b)
    }

    /// [`carve`](Self::carve) from the penalty and the two noise values (whose zero signs do
    /// not matter: they are squared).
    #[inline]
    pub fn carve_with(&self, d0: f64, pen: f64, n1: f64, n2: f64) -> f64 {
        let c = ((n1 * n1 + n2 * n2).sqrt() - self.threshold) * self.scale + pen;
        d0.min(c)
    }

    /// The full formula with no shortcuts (for tests).
    #[cfg(test)]
    pub fn carve_reference(&self, d0: f64, band: &CaveBand, dir: DVec3, r: f64) -> f64 {
        let pen = self.slope * ((r - band.mid).abs() - band.half).max(0.0);
        let q = self.stretch.at(dir, r);
        let (n1, n2) = (gradient3(q, self.seed_a), gradient3(q, self.seed_b));
        d0.min(((n1 * n1 + n2 * n2).sqrt() - self.threshold) * self.scale + pen)
    }
}

/// Overhangs: a 3D noise displacement of the height field, `(h - r) + a w(|h - r|) n(p)`, with
/// the window `w` equal to 1 within `a` of the column's surface and falling to exactly 0 at
/// `a + falloff`. Where `a` is large compared with the noise's vertical length, the radial
/// derivative of the displacement exceeds 1 and the surface folds over (overhangs, arches).
///
/// The surface itself always lies within `a` of `h` (the displacement is at most `a`), so the
/// window never moves it; it only keeps the far field exactly `h - r`.
#[derive(Clone, Debug)]
pub(crate) struct Overhang {
    seed: u64,
    stretch: Stretch,
    min_falloff: f64,
}

impl Overhang {
    /// Displacement noise varying over `lh` metres across and `lv` in depth; the window falls
    /// off over `a / 2 + min_falloff`.
    pub fn new(seed: u64, lh: f64, lv: f64, r0: f64, min_falloff: f64) -> Self {
        Overhang {
            seed,
            stretch: Stretch::new(lh, lv, r0),
            min_falloff,
        }
    }

    /// The displaced terrain at radius `r` of a column with surface `h` and amplitude `a >= 0`.
    #[inline]
    pub fn displace(&self, h: f64, a: f64, dir: DVec3, r: f64) -> f64 {
        let (base, weight) = self.window(h, a, r);
        match weight {
            None => base,
            Some(aw) => base + aw * gradient3(self.point(dir, r), self.seed),
        }
    }

    /// `h - r` and, where the displacement can change it, its weight `a w` (the noise is then
    /// needed: the displaced value is `base + a w n`, and a zero `n`'s sign does not change it).
    #[inline]
    pub fn window(&self, h: f64, a: f64, r: f64) -> (f64, Option<f64>) {
        let base = h - r;
        if a <= 0.0 {
            return (base, None);
        }
        let reach = self.reach(a);
        let z = base.abs();
        if z >= reach {
            // w = 1 - smoothstep(a, reach, z) = 0: the formula gives base + 0.
            return (base, None);
        }
        (base, Some(Self::weight(a, reach, z)))
    }

    /// How far from the surface the window of amplitude `a` reaches (it is zero from there on).
    #[inline]
    pub fn reach(&self, a: f64) -> f64 {
        a + (0.5 * a + self.min_falloff)
    }

    /// The displacement's weight `a w` at distance `z < reach` from the surface.
    #[inline]
    pub fn weight(a: f64, reach: f64, z: f64) -> f64 {
        a * (1.0 - smoothstep(a, reach, z))
    }

    /// Where the displacement noise is sampled at radius `r` along `dir`.
    #[inline]
    pub fn point(&self, dir: DVec3, r: f64) -> DVec3 {
        self.stretch.at(dir, r)
    }

    /// The seed of the displacement noise.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The full formula with no shortcuts (for tests).
    #[cfg(test)]
    pub fn displace_reference(&self, h: f64, a: f64, dir: DVec3, r: f64) -> f64 {
        let base = h - r;
        let reach = a + (0.5 * a + self.min_falloff);
        let w = 1.0 - smoothstep(a, reach, base.abs());
        base + a * w * gradient3(self.stretch.at(dir, r), self.seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothstep_is_exact_outside_the_ramp() {
        assert_eq!(smoothstep(0.2, 0.4, 0.1), 0.0);
        assert_eq!(smoothstep(0.2, 0.4, 0.5), 1.0);
        assert_eq!(smoothstep(0.4, 0.2, 0.5), 0.0);
        assert!((smoothstep(0.2, 0.4, 0.3) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn scales_of_the_default_layout() {
        let s = Scales::new(&Layout::default());
        assert_eq!(s.thickness, 256.0);
        assert_eq!(s.radius, 2000.0);
        assert!((s.tile - 12.27).abs() < 0.01, "{}", s.tile);
        assert_eq!(s.shell(0.5), 1744.0 + 128.0);
    }

    #[test]
    fn cave_and_overhang_shortcuts_are_exact() {
        let caves = Spaghetti::new((1, 2), 120.0, 50.0, 1900.0, 0.1, 8.0, 256.0);
        let over = Overhang::new(3, 30.0, 16.0, 1900.0, 4.0);
        let mut carved = 0;
        for i in 0..4000 {
            let t = i as f64 * 0.0123;
            let dir = DVec3::new(t.cos(), (t * 0.37).sin(), t.sin() * 0.8).normalize();
            let h = 1900.0 + 30.0 * (t * 3.1).sin();
            let a = (12.0 * (t * 1.7).cos()).max(0.0);
            let band = caves.band(1880.0, h - 5.0, smoothstep(-0.5, 0.5, (t * 0.9).sin()));
            for k in 0..60 {
                let r = 1850.0 + k as f64 * 2.0;
                let d0 = over.displace(h, a, dir, r);
                assert_eq!(d0.to_bits(), over.displace_reference(h, a, dir, r).to_bits());
                let d = caves.carve(d0, &band, dir, r);
                assert_eq!(d.to_bits(), caves.carve_reference(d0, &band, dir, r).to_bits());
                if d < d0 {
                    carved += 1;
                }
            }
        }
        assert!(carved > 100, "the test should exercise the carving path: {carved}");
    }

    #[test]
    fn carved_voxels_give_the_voxel_formula_bit_for_bit() {
        let caves = Spaghetti::new((1, 2), 120.0, 50.0, 1900.0, 0.1, 8.0, 256.0);
        let over = Overhang::new(3, 30.0, 16.0, 1900.0, 4.0);
        // 203 columns (not a multiple of eight: the flag scan's tail is read too).
        let cols: Vec<(DVec3, f64, f64, CaveBand)> = (0..203)
            .map(|i| {
                let t = i as f64 * 0.0123;
                let dir = DVec3::new(t.cos(), (t * 0.37).sin(), t.sin() * 0.8).normalize();
                let h = 1900.0 + 30.0 * (t * 3.1).sin();
                let a = (12.0 * (t * 1.7).cos()).max(0.0);
                let band = caves.band(1880.0, h - 5.0, smoothstep(-0.5, 0.5, (t * 0.9).sin()));
                (dir, h, a, band)
            })
            .collect();
        let dirs: Vec<DVec3> = cols.iter().map(|c| c.0).collect();
        let radii: Vec<f64> = (0..60).map(|k| 1850.0 + k as f64 * 2.0).collect();
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        let (mut carved, mut displaced) = (0, 0);
        for overhang in [Some(&over), None] {
            carved_voxels(overhang, &caves, &cols, |c| (c.1, c.2, c.3), &dirs, &radii, &mut out);
            for (k, rk) in radii.iter().enumerate() {
                for (d, (dir, h, a, band)) in cols.iter().enumerate() {
                    let r = (*dir * *rk).length();
                    let d0 = match overhang {
                        Some(o) => o.displace(*h, *a, *dir, r),
                        None => h - r,
                    };
                    displaced += usize::from(d0 != h - r);
                    let want = caves.carve(d0, band, *dir, r);
                    carved += usize::from(want < d0);
                    let got = out[k * dirs.len() + d];
                    assert_eq!(got.to_bits(), (want as f32).to_bits(), "column {d}, radius {rk}");
                }
            }
        }
        assert!(
            carved > 100 && displaced > 100,
            "both noises are read: {carved} {displaced}"
        );
    }

    #[test]
    fn a_batch_of_no_columns_panicked_in_carved_voxels() {
        // The lazy navigation grid samples tiles with no columns in some layouts.
        let caves = Spaghetti::new((1, 2), 120.0, 50.0, 1900.0, 0.1, 8.0, 256.0);
        let over = Overhang::new(3, 30.0, 16.0, 1900.0, 4.0);
        let none: [(f64, f64, CaveBand); 0] = [];
        let mut out: [f32; 0] = [];
        carved_voxels(Some(&over), &caves, &none, |c| *c, &[], &[1900.0, 1901.0], &mut out);
        carved_voxels(None, &caves, &none, |c| *c, &[], &[], &mut out);
    }

    #[test]
    fn closed_band_never_carves() {
        let caves = Spaghetti::new((1, 2), 120.0, 50.0, 1900.0, 0.1, 8.0, 256.0);
        let band = caves.band(1880.0, 1950.0, 0.0);
        for k in 0..200 {
            let r = 1700.0 + k as f64;
            let d0 = 1920.0 - r;
            assert_eq!(caves.carve(d0, &band, DVec3::X, r), d0);
        }
    }
}
