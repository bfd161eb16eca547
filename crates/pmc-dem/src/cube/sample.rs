//! Heights anywhere on the sphere: interpolated data plus detail noise. Version 2 files take the
//! data from the source grid (`source_sample.rs`), exact at every source sample; version 1 files
//! from the face samples (this file), exact at every face sample.

use super::detail::{DetailNoise, MAX_DETAIL_OCTAVES};
use super::lattice::{home_face, indices_on, unfold};
use super::reader::CubeDem;
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{face_uv_to_cube, sphere_to_face_uv, Face, FaceGrid};

pub use pmc_density::terrain::Interpolation;

/// The relief weight at `(fs, ft)` in a cell from its corners' weights, bilinearly.
#[inline]
pub(crate) fn lerp_reliefs(r: &[f64; 4], fs: f64, ft: f64) -> f64 {
    let (a, bb, c, d) = (r[0], r[1], r[2], r[3]);
    let lo = a + fs * (bb - a);
    let hi = c + fs * (d - c);
    lo + ft * (hi - lo)
}

/// The largest lattice resolution [`CubeDem::height_at_lattice`] accepts: `2^30`.
pub const MAX_LATTICE_RESOLUTION: i32 = 1 << 30;

/// Catmull-Rom weights at `t` in `[0, 1]`: exactly `(0, 1, 0, 0)` at 0 and `(0, 0, 1, 0)` at 1.
#[inline]
pub(crate) fn catmull_rom(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        -0.5 * t3 + t2 - 0.5 * t,
        1.5 * t3 - 2.5 * t2 + 1.0,
        -1.5 * t3 + 2.0 * t2 + 0.5 * t,
        0.5 * t3 - 0.5 * t2,
    ]
}

impl CubeDem {
    /// The value of data sample `(i, j)` of `face` (level 0), `NaN` if its tile cannot be read.
    #[inline]
    fn data(&self, face: Face, i: i32, j: i32) -> f64 {
        self.value(0, face.index(), i as u32, j as u32)
            .map_or(f64::NAN, f64::from)
    }

    /// The data at face indices that may lie one step past an edge: unfolded onto the
    /// neighbouring face, or clamped onto the corner along the edges through a cube corner.
    fn stencil(&self, face: Face, i: i32, j: i32) -> f64 {
        let r = 1i32 << self.header.n;
        let in_i = (0..=r).contains(&i);
        let in_j = (0..=r).contains(&j);
        if in_i && in_j {
            return self.data(face, i, j);
        }
        let inner = |x: i32| 0 < x && x < r;
        if (in_i && inner(i)) || (in_j && inner(j)) {
            if let Some(p) = unfold(face, r, i, j) {
                return self.data_at_lattice(p, r);
            }
        }
        self.data(face, i.clamp(0, r), j.clamp(0, r))
    }

    /// The data at lattice point `p` of the data resolution `r`, from its home face.
    fn data_at_lattice(&self, p: IVec3, r: i32) -> f64 {
        match home_face(p, r) {
            Some(f) => {
                let (i, j) = indices_on(f, p, r);
                self.data(f, i, j)
            }
            None => f64::NAN,
        }
    }

    /// The relief weight of data sample `(i, j)` of `face`: its largest difference to its four
    /// neighbours (unfolded across edges; at a cube corner the three edge neighbours).
    fn relief(&self, face: Face, i: i32, j: i32, detail: &DetailNoise) -> f64 {
        let r = 1i32 << self.header.n;
        let h = self.data(face, i, j);
        let mut most = 0.0f64;
        for (a, b) in [(i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)] {
            let v = if (0..=r).contains(&a) && (0..=r).contains(&b) {
                self.data(face, a, b)
            } else {
                unfold(face, r, a, b).map_or(f64::NAN, |p| self.data_at_lattice(p, r))
            };
            most = most.max((v - h).abs());
        }
        if h.is_nan() {
            return f64::NAN;
        }
        detail.relief_weight(most, self.data_spacing())
    }

    /// The 4 x 4 data samples `(i0 - 1 + di, j0 - 1 + dj)` at `[dj * 4 + di]`, when they all lie
    /// on `face` in one tile (most calls): one cache lookup instead of one per sample. `None`
    /// near face edges and tile borders, where the per-sample path (with its unfolding) runs.
    fn block(&self, face: Face, i0: i32, j0: i32) -> Option<[f64; 16]> {
        let r = 1i32 << self.header.n;
        if i0 < 1 || j0 < 1 || i0 + 2 > r || j0 + 2 > r {
            return None;
        }
        let t = self.header.tile as i32;
        if (i0 - 1) / t != (i0 + 2) / t || (j0 - 1) / t != (j0 + 2) / t {
            return None;
        }
        let (i, j) = ((i0 - 1) as u32, (j0 - 1) as u32);
        let idx = self.grid.index_of(0, face.index(), i, j);
        let tile = self.tile(idx).ok()?;
        let mut out = [0.0; 16];
        if tile.len() == 1 {
            out.fill(f64::from(tile[0]));
            return Some(out);
        }
        let t = self.header.tile;
        let w = (self.grid.levels[0].side.min((i / t) * t + t) - (i / t) * t) as usize;
        let (ci, cj) = ((i % t) as usize, (j % t) as usize);
        for dj in 0..4 {
            let row = (cj + dj) * w + ci;
            for di in 0..4 {
                out[dj * 4 + di] = f64::from(tile[row + di]);
            }
        }
        Some(out)
    }

    /// [`CubeDem::interpolate`] from a 4 x 4 block of samples (see [`CubeDem::block`]): the same
    /// operations in the same order, so the same bits.
    fn interpolate_block(
        &self,
        b: &[f64; 16],
        fs: f64,
        ft: f64,
        interp: Interpolation,
        detail: &DetailNoise,
    ) -> (f64, f64) {
        let value = self.block_value(b, fs, ft, interp);
        if !detail.is_on() {
            return (value, 1.0);
        }
        (value, lerp_reliefs(&self.block_reliefs(b, detail), fs, ft))
    }

    /// The interpolated data at `(fs, ft)` within the middle cell of a 4 x 4 block.
    fn block_value(&self, b: &[f64; 16], fs: f64, ft: f64, interp: Interpolation) -> f64 {
        match interp {
            Interpolation::Bilinear => {
                let (a, bb, c, d) = (b[5], b[6], b[9], b[10]);
                let lo = a + fs * (bb - a);
                let hi = c + fs * (d - c);
                lo + ft * (hi - lo)
            }
            Interpolation::Bicubic => self.bicubic_block(b, &catmull_rom(fs), &catmull_rom(ft)),
        }
    }

    /// The bicubic value of a 4 x 4 block with the Catmull-Rom weights `ws` (along `s`) and `wt`
    /// (along `t`), clamped to the data's range.
    #[inline]
    fn bicubic_block(&self, b: &[f64; 16], ws: &[f64; 4], wt: &[f64; 4]) -> f64 {
        let mut total = 0.0;
        for (dj, wj) in wt.iter().enumerate() {
            let row: f64 = ws.iter().enumerate().map(|(di, wi)| wi * b[dj * 4 + di]).sum();
            total += wj * row;
        }
        total.clamp(self.header.min, self.header.max)
    }

    /// The relief weights of the middle cell's four corners (in `relief`'s order of neighbours).
    fn block_reliefs(&self, b: &[f64; 16], detail: &DetailNoise) -> [f64; 4] {
        let relief = |x: usize, y: usize| -> f64 {
            let h = b[y * 4 + x];
            let mut most = 0.0f64;
            for v in [
                b[y * 4 + x - 1],
                b[y * 4 + x + 1],
                b[(y - 1) * 4 + x],
                b[(y + 1) * 4 + x],
            ] {
                most = most.max((v - h).abs());
            }
            if h.is_nan() {
                return f64::NAN;
            }
            detail.relief_weight(most, self.data_spacing())
        };
        [relief(1, 1), relief(2, 1), relief(1, 2), relief(2, 2)]
    }

    /// The cell of fractional sample indices `(s, t)`: its lower corner and the fractions.
    fn cell(&self, s: f64, t: f64) -> Option<(i32, i32, f64, f64)> {
        let r = 1i32 << self.header.n;
        let rf = f64::from(r);
        if !(s.is_finite() && t.is_finite()) {
            return None;
        }
        let (s, t) = (s.clamp(0.0, rf), t.clamp(0.0, rf));
        let i0 = (s.floor() as i32).min(r - 1);
        let j0 = (t.floor() as i32).min(r - 1);
        Some((i0, j0, s - f64::from(i0), t - f64::from(j0)))
    }

    /// Interpolated data at fractional sample indices `(s, t)` of `face`, and the relief weight
    /// of the detail there (1 when the detail is off).
    pub(crate) fn interpolate(
        &self,
        face: Face,
        s: f64,
        t: f64,
        interp: Interpolation,
        detail: &DetailNoise,
    ) -> (f64, f64) {
        let Some((i0, j0, fs, ft)) = self.cell(s, t) else {
            return (f64::NAN, f64::NAN);
        };
        if let Some(b) = self.block(face, i0, j0) {
            return self.interpolate_block(&b, fs, ft, interp, detail);
        }
        self.interpolate_samples(face, i0, j0, fs, ft, interp, detail)
    }

    /// [`CubeDem::interpolate`] sample by sample, unfolding past face edges.
    #[allow(clippy::too_many_arguments)]
    fn interpolate_samples(
        &self,
        face: Face,
        i0: i32,
        j0: i32,
        fs: f64,
        ft: f64,
        interp: Interpolation,
        detail: &DetailNoise,
    ) -> (f64, f64) {
        let value = match interp {
            Interpolation::Bilinear => {
                let a = self.data(face, i0, j0);
                let b = self.data(face, i0 + 1, j0);
                let c = self.data(face, i0, j0 + 1);
                let d = self.data(face, i0 + 1, j0 + 1);
                let lo = a + fs * (b - a);
                let hi = c + fs * (d - c);
                lo + ft * (hi - lo)
            }
            Interpolation::Bicubic => {
                let ws = catmull_rom(fs);
                let wt = catmull_rom(ft);
                let mut total = 0.0;
                for (dj, wj) in wt.iter().enumerate() {
                    let j = j0 - 1 + dj as i32;
                    let row: f64 = ws
                        .iter()
                        .enumerate()
                        .map(|(di, wi)| wi * self.stencil(face, i0 - 1 + di as i32, j))
                        .sum();
                    total += wj * row;
                }
                // Catmull-Rom may overshoot the data; clamped to the data's range (a
                // continuous operation, the identity at every sample) the heights stay within
                // known bounds, so a planet's shell need not make room for the overshoot.
                total.clamp(self.header.min, self.header.max)
            }
        };
        if !detail.is_on() {
            return (value, 1.0);
        }
        let a = self.relief(face, i0, j0, detail);
        let b = self.relief(face, i0 + 1, j0, detail);
        let c = self.relief(face, i0, j0 + 1, detail);
        let d = self.relief(face, i0 + 1, j0 + 1, detail);
        let lo = a + fs * (b - a);
        let hi = c + fs * (d - c);
        (value, lo + ft * (hi - lo))
    }

    /// The height, in metres above the datum's zero (the data's metres), at the canonical
    /// lattice point `lattice` of resolution `m` (a power of two; coordinates in `[-m, m]`, on
    /// the cube surface: one coordinate `= ±m`, all of the parity of `m`).
    ///
    /// In a version 2 file the height is the source grid interpolated at the point's direction
    /// `cube_to_sphere(lattice / m)` (exact at every source sample), plus the detail octaves
    /// `0 .. log2(m) - n` (none when `m <= 2^n`) faded to zero at the source samples: a function
    /// of the place alone, the same bits for `(2 lattice, 2m)`. In a version 1 file:
    ///
    /// When `m <= 2^n` the point is a data sample: its stored value is returned exactly (read
    /// from the stored level of resolution `m`, or the coarsest overview when `m` is coarser;
    /// all levels hold the same bits), with no noise. When `m > 2^n` the point lies between
    /// samples: the interpolated data plus detail octaves `0 .. log2(m) - n` (the finer ones are
    /// exactly zero at the point, so a coarse vertex is cheap and still exact). Face edge and
    /// corner points are computed on one face chosen from the point alone (the first of
    /// [`Face::ALL`] that holds it), so every caller gets the same bits.
    ///
    /// `NaN` for an invalid point or resolution, or when a tile cannot be read (see
    /// [`CubeDem::verify`]).
    pub fn height_at_lattice(&self, lattice: IVec3, m: i32, interp: Interpolation, detail: &DetailNoise) -> f64 {
        if m <= 0 || m > MAX_LATTICE_RESOLUTION || m.count_ones() != 1 {
            return f64::NAN;
        }
        if lattice.abs().max_element() > m || (lattice + IVec3::splat(m)) % 2 != IVec3::ZERO {
            return f64::NAN;
        }
        let Some(face) = home_face(lattice, m) else {
            return f64::NAN;
        };
        if self.source_grid.is_some() {
            return self.source_height_at_lattice(lattice, m, interp, detail);
        }
        let n = self.header.n;
        let big_n = 1i32 << n;
        if m <= big_n {
            let coarsest = big_n >> (self.header.levels - 1);
            let r = m.max(coarsest);
            let p = lattice * (r / m);
            let level = n - r.trailing_zeros();
            let Some(f) = home_face(p, r) else {
                return f64::NAN;
            };
            let (i, j) = indices_on(f, p, r);
            return self
                .value(level, f.index(), i as u32, j as u32)
                .map_or(f64::NAN, f64::from);
        }
        // Sample indices at the data resolution: exact (a power-of-two scale of integers).
        let scale = f64::from(big_n) / (2.0 * f64::from(m));
        let fr = face.frame();
        let s = f64::from(fr.u.dot(lattice) + m) * scale;
        let t = f64::from(fr.v.dot(lattice) + m) * scale;
        let (value, weight) = self.interpolate(face, s, t, interp, detail);
        if !detail.is_on() {
            return value;
        }
        let octaves = m.trailing_zeros() - n;
        value + weight * detail.sum(lattice.as_dvec3() * scale, octaves, self.data_spacing())
    }

    /// [`CubeDem::height_at_lattice`] for every point of `points` (one resolution `m`) into `out`,
    /// with the same bits: points that share a data cell (a height-field patch's thousands of
    /// vertices lie in a few dozen) share one read of its 4 x 4 samples and their relief weights.
    ///
    /// Panics when `out` and `points` differ in length (a caller's bug).
    pub fn heights_at_lattice(
        &self,
        points: &[IVec3],
        m: i32,
        interp: Interpolation,
        detail: &DetailNoise,
        out: &mut [f64],
    ) {
        assert_eq!(points.len(), out.len(), "one output per point");
        if self.source_grid.is_some() {
            return self.source_heights_at_lattice(points, m, interp, detail, out);
        }
        let n = self.header.n;
        let big_n = 1i32 << n;
        let fine = m > big_n && m <= MAX_LATTICE_RESOLUTION && m.count_ones() == 1;
        // The cells seen, with their samples and relief weights (None: near an edge or a tile
        // border, computed point by point).
        type Cell = ((Face, i32, i32), Option<([f64; 16], [f64; 4])>);
        let mut cells: Vec<Cell> = Vec::new();
        let mut last = 0usize;
        let detail_on = detail.is_on();
        // Pass 1 finds each point's cell. The points inside a whole 4 x 4 block (nearly all) are
        // listed with their cell and fractions, and evaluated in the tight loop of pass 2, where
        // consecutive points' arithmetic overlaps; the others are done here.
        let mut blocked: Vec<(u32, u32, f64, f64)> = Vec::with_capacity(points.len());
        // The points that get detail: their index, interpolated value and relief weight.
        let mut pending: Vec<(usize, f64, f64)> = Vec::new();
        let scale = f64::from(big_n) / (2.0 * f64::from(m));
        for (at, (lattice, h)) in points.iter().zip(out.iter_mut()).enumerate() {
            let valid = lattice.abs().max_element() <= m && (*lattice + IVec3::splat(m)) % 2 == IVec3::ZERO;
            let face = if fine && valid { home_face(*lattice, m) } else { None };
            let Some(face) = face else {
                *h = self.height_at_lattice(*lattice, m, interp, detail);
                continue;
            };
            let fr = face.frame();
            let s = f64::from(fr.u.dot(*lattice) + m) * scale;
            let t = f64::from(fr.v.dot(*lattice) + m) * scale;
            let Some((i0, j0, fs, ft)) = self.cell(s, t) else {
                *h = f64::NAN;
                continue;
            };
            let key = (face, i0, j0);
            if cells.get(last).is_none_or(|c| c.0 != key) {
                last = match cells.iter().position(|c| c.0 == key) {
                    Some(at) => at,
                    None => {
                        let block = self.block(face, i0, j0).map(|b| {
                            let r = if detail_on {
                                self.block_reliefs(&b, detail)
                            } else {
                                [1.0; 4]
                            };
                            (b, r)
                        });
                        cells.push((key, block));
                        cells.len() - 1
                    }
                };
            }
            if cells[last].1.is_some() {
                blocked.push((at as u32, last as u32, fs, ft));
            } else {
                let (value, weight) = self.interpolate_samples(face, i0, j0, fs, ft, interp, detail);
                *h = value;
                if detail_on {
                    pending.push((at, value, weight));
                }
            }
        }
        // Pass 2: the blocked points.
        for &(at, cell, fs, ft) in &blocked {
            let Some((b, r)) = &cells[cell as usize].1 else {
                unreachable!("only points of whole blocks are listed")
            };
            let value = self.block_value(b, fs, ft, interp);
            out[at as usize] = value;
            if detail_on {
                pending.push((at as usize, value, lerp_reliefs(r, fs, ft)));
            }
        }
        // Pass 3: the detail of all of them at once.
        if !pending.is_empty() {
            let octaves = m.trailing_zeros() - n;
            let noise_at: Vec<DVec3> = pending
                .iter()
                .map(|(at, _, _)| points[*at].as_dvec3() * scale)
                .collect();
            let mut sums = vec![0.0; noise_at.len()];
            detail.sum_many(&noise_at, octaves, self.data_spacing(), &mut sums);
            for ((at, value, weight), sum) in pending.into_iter().zip(sums) {
                out[at] = value + weight * sum;
            }
        }
    }

    /// [`CubeDem::heights_at_lattice`] of the entries of a face grid (`points[b * side + a]` is
    /// the lattice point of the entry's face indices wherever one exists), with the same bits.
    ///
    /// Version 1: the entries strictly inside the face share their column's sample cell,
    /// fraction and bicubic weights along `u` and their row's along `v`, computed once; the
    /// others (on or past the face's edges, where several faces meet) go through
    /// [`CubeDem::heights_at_lattice`]. Version 2: [`CubeDem::heights_at_lattice`] of all of them
    /// (a point's place on the source grid depends on both of its indices).
    ///
    /// Panics when `points`, `out` and the grid differ in length (a caller's bug).
    #[allow(clippy::too_many_arguments)]
    pub fn heights_on_grid(
        &self,
        grid: &FaceGrid,
        points: &[IVec3],
        m: i32,
        interp: Interpolation,
        detail: &DetailNoise,
        out: &mut [f64],
    ) {
        assert!(
            points.len() == out.len() && points.len() == grid.len(),
            "one point and one output per grid entry"
        );
        if self.source_grid.is_some() {
            return self.source_heights_at_lattice(points, m, interp, detail, out);
        }
        let n = self.header.n;
        let big_n = 1i32 << n;
        let fine = m > big_n && m <= MAX_LATTICE_RESOLUTION && m.count_ones() == 1;
        if !fine {
            return self.heights_at_lattice(points, m, interp, detail, out);
        }
        let scale = f64::from(big_n) / (2.0 * f64::from(m));
        let rf = f64::from(big_n);
        // A column's or a row's cell, fraction and weights: the per-point path's `cell` of
        // `s = 2 i scale` (`fr.u . p + m = 2 i` for a point of the face), split by axis.
        let axis = |first: i64| -> Vec<Option<(i32, f64, [f64; 4])>> {
            (0..grid.side as i64)
                .map(|a| {
                    let i = first + a;
                    (0 < i && i < i64::from(m)).then(|| {
                        let s = (f64::from(2 * i as i32) * scale).clamp(0.0, rf);
                        let c = (s.floor() as i32).min(big_n - 1);
                        let f = s - f64::from(c);
                        (c, f, catmull_rom(f))
                    })
                })
                .collect()
        };
        let (cols, rows) = (axis(grid.i0), axis(grid.j0));
        let detail_on = detail.is_on();
        type Cell = ((i32, i32), Option<([f64; 16], [f64; 4])>);
        let mut cells: Vec<Cell> = Vec::new();
        let mut last = 0usize;
        let mut others: Vec<usize> = Vec::new();
        let mut pending: Vec<(usize, f64, f64)> = Vec::with_capacity(points.len());
        for (b, row) in rows.iter().enumerate() {
            for (a, col) in cols.iter().enumerate() {
                let at = b * grid.side + a;
                let (Some((j0, ft, wt)), Some((i0, fs, ws))) = (row, col) else {
                    others.push(at);
                    continue;
                };
                let key = (*i0, *j0);
                if cells.get(last).is_none_or(|c| c.0 != key) {
                    last = match cells.iter().position(|c| c.0 == key) {
                        Some(at) => at,
                        None => {
                            let block = self.block(grid.face, *i0, *j0).map(|b| {
                                let r = if detail_on {
                                    self.block_reliefs(&b, detail)
                                } else {
                                    [1.0; 4]
                                };
                                (b, r)
                            });
                            cells.push((key, block));
                            cells.len() - 1
                        }
                    };
                }
                let (value, weight) = match &cells[last].1 {
                    Some((blk, r)) => {
                        let value = match interp {
                            Interpolation::Bicubic => self.bicubic_block(blk, ws, wt),
                            Interpolation::Bilinear => self.block_value(blk, *fs, *ft, interp),
                        };
                        (value, if detail_on { lerp_reliefs(r, *fs, *ft) } else { 1.0 })
                    }
                    None => self.interpolate_samples(grid.face, *i0, *j0, *fs, *ft, interp, detail),
                };
                out[at] = value;
                if detail_on {
                    pending.push((at, value, weight));
                }
            }
        }
        if !pending.is_empty() {
            let octaves = m.trailing_zeros() - n;
            let noise_at: Vec<DVec3> = pending
                .iter()
                .map(|(at, _, _)| points[*at].as_dvec3() * scale)
                .collect();
            let mut sums = vec![0.0; noise_at.len()];
            detail.sum_many(&noise_at, octaves, self.data_spacing(), &mut sums);
            for ((at, value, weight), sum) in pending.into_iter().zip(sums) {
                out[at] = value + weight * sum;
            }
        }
        if !others.is_empty() {
            let subset: Vec<IVec3> = others.iter().map(|at| points[*at]).collect();
            let mut heights = vec![0.0; subset.len()];
            self.heights_at_lattice(&subset, m, interp, detail, &mut heights);
            for (at, h) in others.into_iter().zip(heights) {
                out[at] = h;
            }
        }
    }

    /// The height, in metres, in direction `dir` (any length), with detail octaves down to a
    /// lattice spacing of `finest_spacing_m` metres (0 or less: all
    /// [`MAX_DETAIL_OCTAVES`](crate::cube::MAX_DETAIL_OCTAVES)). Agrees with
    /// [`CubeDem::height_at_lattice`] at lattice points to about 1e-6 m. `NaN` for a zero or
    /// non-finite direction, a `NaN` spacing, or a tile that cannot be read.
    pub fn height(&self, dir: DVec3, interp: Interpolation, detail: &DetailNoise, finest_spacing_m: f64) -> f64 {
        if finest_spacing_m.is_nan() {
            return f64::NAN;
        }
        let spacing = self.data_spacing();
        let mut octaves = 0;
        while octaves < MAX_DETAIL_OCTAVES && spacing / f64::from(1u32 << octaves) >= finest_spacing_m {
            octaves += 1;
        }
        if self.source_grid.is_some() {
            return self.source_height(dir, interp, detail, octaves);
        }
        let Some((face, u, v)) = sphere_to_face_uv(dir) else {
            return f64::NAN;
        };
        let half = f64::from(1u32 << self.header.n) * 0.5;
        let (value, weight) = self.interpolate(face, (u + 1.0) * half, (v + 1.0) * half, interp, detail);
        if !detail.is_on() {
            return value;
        }
        value + weight * detail.sum(face_uv_to_cube(face, u, v) * half, octaves, spacing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cube::{import_cube, ImportOptions};
    use crate::EquirectDem;

    #[test]
    fn a_block_gives_the_bits_of_sample_by_sample_interpolation() {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
        let dem = EquirectDem::read_netcdf(&src, None).unwrap();
        let dir = std::env::temp_dir().join(format!("pmc-dem-block-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("b.pmcdem");
        let options = ImportOptions {
            level: Some(7),
            tile_size: 16,
            ..ImportOptions::default()
        };
        import_cube(&dem, &out, &options, &|_, _| {}).unwrap();
        let cube = CubeDem::open(&out).unwrap();
        let detail = DetailNoise::default();
        let mut blocks = 0;
        for face in Face::ALL {
            for k in 0..400u32 {
                let s = f64::from(k % 20) * 6.37 + 0.25 * f64::from(k % 3);
                let t = f64::from(k / 20) * 6.41 + 0.5;
                let (i0, j0) = (s.floor() as i32, t.floor() as i32);
                let Some(b) = cube.block(face, i0, j0) else { continue };
                blocks += 1;
                let (fs, ft) = (s - f64::from(i0), t - f64::from(j0));
                for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
                    let fast = cube.interpolate_block(&b, fs, ft, interp, &detail);
                    let slow = cube.interpolate_samples(face, i0, j0, fs, ft, interp, &detail);
                    assert_eq!(
                        (fast.0.to_bits(), fast.1.to_bits()),
                        (slow.0.to_bits(), slow.1.to_bits()),
                        "{face:?} {s} {t}"
                    );
                }
            }
        }
        assert!(blocks > 1000, "{blocks}");
        // Whole batches of lattice points (patch-like grids over face edges, corners and tile
        // borders, at several resolutions) give the bits of one point at a time.
        for m in [64, 128, 512, 4096, 1 << 16] {
            for face in Face::ALL {
                let mut points = Vec::new();
                let step = (m / 64).max(1);
                for a in (0..=m).step_by(step as usize).take(70) {
                    for b in [0, 1, m / 3, m - 1, m] {
                        if let Some(p) = pmc_geometry::face_lattice(face, i64::from(a), i64::from(b), i64::from(m)) {
                            points.push(p);
                        }
                    }
                }
                points.push(IVec3::new(m + 2, 0, 0)); // off the cube: NaN either way
                for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
                    for detail in [DetailNoise::default(), DetailNoise::OFF] {
                        let mut batch = vec![0.0; points.len()];
                        cube.heights_at_lattice(&points, m, interp, &detail, &mut batch);
                        for (p, h) in points.iter().zip(&batch) {
                            let one = cube.height_at_lattice(*p, m, interp, &detail);
                            assert_eq!(h.to_bits(), one.to_bits(), "{face:?} {p} at {m}: {h} vs {one}");
                        }
                    }
                }
            }
        }
        // Face grids (patch-sized, with a border) inside faces, over face edges and cube corners
        // and across tile borders, at resolutions finer and coarser than the data: the bits of
        // one point at a time.
        let mut grids = 0;
        for m in [64, 512, 4096, 1 << 16, 1 << 20] {
            let side = 67usize;
            let starts = [
                -1i64,
                0,
                1,
                i64::from(m) / 2 - 33,
                i64::from(m) / 3,
                i64::from(m) - 66,
                i64::from(m) - 65,
            ];
            for face in Face::ALL {
                for (k, i0) in starts.iter().enumerate() {
                    let j0 = starts[(k * 3 + face.index()) % starts.len()];
                    let grid = FaceGrid {
                        face,
                        i0: *i0,
                        j0,
                        side,
                    };
                    let points: Vec<IVec3> = (0..grid.len())
                        .map(|e| {
                            let (i, j) = grid.indices(e % side, e / side);
                            pmc_geometry::face_lattice(face, i, j, i64::from(m)).unwrap_or(IVec3::new(m, m, m))
                        })
                        .collect();
                    for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
                        for detail in [DetailNoise::default(), DetailNoise::OFF] {
                            let mut on_grid = vec![0.0; points.len()];
                            cube.heights_on_grid(&grid, &points, m, interp, &detail, &mut on_grid);
                            for (p, h) in points.iter().zip(&on_grid) {
                                let one = cube.height_at_lattice(*p, m, interp, &detail);
                                assert_eq!(h.to_bits(), one.to_bits(), "{grid:?} {p} at {m}: {h} vs {one}");
                            }
                        }
                    }
                    grids += 1;
                }
            }
        }
        assert_eq!(grids, 5 * 6 * 7);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
