//! Heights of a version 2 file: the stored source grid interpolated in its own (column, row)
//! index space (exact at every source sample), plus detail noise faded to zero at every source
//! sample.
//!
//! A place's height is a function of its direction alone: the same at every lattice resolution
//! and every level of detail, whatever face or patch asks (`docs/specs/pmcdem-v2.md`, "Heights").

use super::detail::DetailNoise;
use super::lattice::home_face;
use super::reader::CubeDem;
use super::sample::{catmull_rom, lerp_reliefs, Interpolation, MAX_LATTICE_RESOLUTION};
use super::source_grid::SourceGrid;
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{cube_to_sphere, face_uv_to_cube, sphere_to_face_uv};
use std::collections::HashMap;

/// Radius, in source cells, of the disc round each source sample within which the detail noise
/// fades to zero (smoothly: the fade and its slope are zero at the sample).
pub const SAMPLE_FADE_RADIUS: f64 = 0.25;

/// The fade of the detail at fractions `(fx, fy)` of a source cell: 0 at the four corners (the
/// source samples), rising smoothly to 1 at [`SAMPLE_FADE_RADIUS`] cells from the nearest one.
#[inline]
pub(crate) fn sample_fade(fx: f64, fy: f64) -> f64 {
    let dx = fx.min(1.0 - fx);
    let dy = fy.min(1.0 - fy);
    let t = ((dx * dx + dy * dy) / (SAMPLE_FADE_RADIUS * SAMPLE_FADE_RADIUS)).min(1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The weight of the detail at a place whose interpolated height is `above` metres above the
/// datum, where the detail moves heights by at most `bound` metres: `smoothstep(0, 2 bound,
/// |above|)`. The weighted detail is then smaller in size than `|above|` everywhere
/// (`bound s(y) < 2 bound y` for `y` in `(0, 1]`), so it never lifts the sea floor above the
/// datum nor sinks land below it: the shoreline is the interpolated data's 0 m contour, at
/// every level of detail.
#[inline]
pub(crate) fn shore_weight(above: f64, bound: f64) -> f64 {
    if bound <= 0.0 {
        return 1.0;
    }
    let t = (above.abs() / (2.0 * bound)).min(1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The 4 x 4 source samples round a cell (columns `c0 - 1 ..= c0 + 2`, rows `r0 - 1 ..= r0 + 2`,
/// at `[row * 4 + column]`; wrapped in longitude for a global grid, clamped onto the edge rows
/// and columns otherwise) and the relief weights of its four corners.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SourceCell {
    pub values: [f64; 16],
    pub reliefs: [f64; 4],
}

/// Where a direction falls on the source grid.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SourcePlace {
    /// The cell's lower column and row.
    pub c0: u32,
    pub r0: u32,
    /// The fractions within the cell.
    pub fx: f64,
    pub fy: f64,
    /// How far outside the grid's extent, in cells (0 inside; past a regional grid's edge).
    pub outside: f64,
}

/// Detail smaller than this many metres is not summed by [`CubeDem::height`] (its result agrees
/// with [`CubeDem::height_at_lattice`] to about 1e-6 m, not to the bit).
const NEGLIGIBLE_DETAIL_M: f64 = 1e-9;

/// Cells over which heights pass from a regional grid's edge values to the cube faces' fill
/// outside it.
pub const OUTSIDE_BLEND_CELLS: f64 = 1.0;

impl CubeDem {
    /// The source cell of direction `dir` (any length) and the fractions within it; `None` for
    /// a version 1 file, a zero or a non-finite direction. Outside a regional grid the place is
    /// clamped onto the nearest edge (the edge's values extend outward).
    pub(crate) fn source_place(&self, dir: DVec3) -> Option<SourcePlace> {
        let g = self.source_grid.as_ref()?;
        let (lat, lon) = SourceGrid::lat_lon_of(dir)?;
        let p = g.position(lat, lon);
        let r0 = (p.y.floor().max(0.0) as usize).min(g.h - 2);
        let c0 = if g.wraps {
            (p.x.floor().max(0.0) as usize).min(g.w - 1)
        } else {
            (p.x.floor().max(0.0) as usize).min(g.w - 2)
        };
        Some(SourcePlace {
            c0: c0 as u32,
            r0: r0 as u32,
            fx: p.x - c0 as f64,
            fy: p.y - r0 as f64,
            outside: if p.inside { 0.0 } else { g.outside_cells(lat, lon) },
        })
    }

    /// The source sample nearest (in column and row) to direction `dir`: its column, row,
    /// latitude and longitude; `None` for a version 1 file or a zero or non-finite direction.
    pub(crate) fn nearest_source_sample(&self, dir: DVec3) -> Option<(u32, u32, f64, f64)> {
        let g = self.source_grid.as_ref()?;
        let (lat, lon) = SourceGrid::lat_lon_of(dir)?;
        let p = g.position(lat, lon);
        let r = (p.y.round().max(0.0) as usize).min(g.h - 1);
        let c = p.x.round().max(0.0) as usize;
        let c = if g.wraps { c % g.w } else { c.min(g.w - 1) };
        let (lat, lon) = g.lat_lon(c, r);
        Some((c as u32, r as u32, lat, lon))
    }

    /// `value` (interpolated from the source at `place`) and the detail's `weight`, passed
    /// outside a regional grid's extent, over [`OUTSIDE_BLEND_CELLS`], to the cube faces'
    /// interpolated samples (which hold the fill there) and no detail.
    fn blend_outside(
        &self,
        place: &SourcePlace,
        dir: DVec3,
        interp: Interpolation,
        value: f64,
        weight: f64,
    ) -> (f64, f64) {
        if place.outside <= 0.0 {
            return (value, weight);
        }
        let Some((face, u, v)) = sphere_to_face_uv(dir) else {
            return (f64::NAN, f64::NAN);
        };
        let half = f64::from(1u32 << self.header.n) * 0.5;
        let (fill, _) = self.interpolate(face, (u + 1.0) * half, (v + 1.0) * half, interp, &DetailNoise::OFF);
        let t = (place.outside / OUTSIDE_BLEND_CELLS).min(1.0);
        let t = t * t * (3.0 - 2.0 * t);
        (value + t * (fill - value), weight * (1.0 - t))
    }

    /// The 4 x 4 samples round cell `(c0, r0)` and its corners' relief weights (1 when the
    /// detail is off). Read from one tile when the block lies in one (most cells), else sample
    /// by sample; the values are the same either way. `NaN` where a tile cannot be read.
    pub(crate) fn source_cell(&self, c0: u32, r0: u32, detail: &DetailNoise) -> SourceCell {
        let src = self.header.source.as_ref().expect("a version 2 file");
        let mut values = [f64::NAN; 16];
        let t = src.tile;
        let whole = c0 >= 1
            && r0 >= 1
            && c0 + 2 < src.width
            && r0 + 2 < src.height
            && (c0 - 1) / t == (c0 + 2) / t
            && (r0 - 1) / t == (r0 + 2) / t;
        if whole {
            let (c, r) = (c0 - 1, r0 - 1);
            if let Ok(tile) = self.tile(self.grid.total + src.index_of(c, r)) {
                if tile.len() == 1 {
                    values.fill(f64::from(tile[0]));
                } else {
                    let tw = (src.width.min((c / t) * t + t) - (c / t) * t) as usize;
                    let (ci, ri) = ((c % t) as usize, (r % t) as usize);
                    for dr in 0..4 {
                        let row = (ri + dr) * tw + ci;
                        for dc in 0..4 {
                            values[dr * 4 + dc] = f64::from(tile[row + dc]);
                        }
                    }
                }
            }
        } else {
            let (w, h) = (i64::from(src.width), i64::from(src.height));
            for dr in 0..4i64 {
                let r = (i64::from(r0) - 1 + dr).clamp(0, h - 1) as u32;
                for dc in 0..4i64 {
                    let c = i64::from(c0) - 1 + dc;
                    let c = if src.wraps { c.rem_euclid(w) } else { c.clamp(0, w - 1) } as u32;
                    values[(dr * 4 + dc) as usize] = self.source_value(c, r).map_or(f64::NAN, f64::from);
                }
            }
        }
        let reliefs = if detail.is_on() {
            let relief = |x: usize, y: usize| -> f64 {
                let h = values[y * 4 + x];
                let mut most = 0.0f64;
                for v in [
                    values[y * 4 + x - 1],
                    values[y * 4 + x + 1],
                    values[(y - 1) * 4 + x],
                    values[(y + 1) * 4 + x],
                ] {
                    most = most.max((v - h).abs());
                }
                if h.is_nan() {
                    return f64::NAN;
                }
                detail.relief_weight(most, self.source_spacing)
            };
            [relief(1, 1), relief(2, 1), relief(1, 2), relief(2, 2)]
        } else {
            [1.0; 4]
        };
        SourceCell { values, reliefs }
    }

    /// The interpolated source value at fractions `(fx, fy)` of a cell, and the weight of the
    /// detail there (the corners' relief weights interpolated bilinearly, times
    /// [`sample_fade`] and [`shore_weight`] for a detail of at most `detail_bound` metres; 1
    /// when the detail is off). Exact at the corners: the bilinear and the Catmull-Rom weights
    /// are exactly 1 and 0 there.
    #[inline]
    pub(crate) fn source_interpolate(
        &self,
        cell: &SourceCell,
        fx: f64,
        fy: f64,
        interp: Interpolation,
        detail_on: bool,
        detail_bound: f64,
    ) -> (f64, f64) {
        let b = &cell.values;
        let value = match interp {
            Interpolation::Bilinear => {
                let (a, bb, c, d) = (b[5], b[6], b[9], b[10]);
                let lo = a + fx * (bb - a);
                let hi = c + fx * (d - c);
                lo + fy * (hi - lo)
            }
            Interpolation::Bicubic => {
                let (ws, wt) = (catmull_rom(fx), catmull_rom(fy));
                let mut total = 0.0;
                for (dr, wr) in wt.iter().enumerate() {
                    let row: f64 = ws.iter().enumerate().map(|(dc, wc)| wc * b[dr * 4 + dc]).sum();
                    total += wr * row;
                }
                // Clamped to the data's range as the face interpolation is (a continuous
                // operation, the identity at every sample).
                total.clamp(self.header.min, self.header.max)
            }
        };
        if !detail_on {
            return (value, 1.0);
        }
        let shore = shore_weight(value - self.header.datum, detail_bound);
        (value, lerp_reliefs(&cell.reliefs, fx, fy) * sample_fade(fx, fy) * shore)
    }

    /// The interpolated source value in direction `dir` and the detail's weight there.
    fn source_at(&self, dir: DVec3, interp: Interpolation, detail: &DetailNoise) -> (f64, f64) {
        let Some(place) = self.source_place(dir) else {
            return (f64::NAN, f64::NAN);
        };
        let cell = self.source_cell(place.c0, place.r0, detail);
        let (value, weight) = self.source_interpolate(
            &cell,
            place.fx,
            place.fy,
            interp,
            detail.is_on(),
            detail.bound(self.data_spacing()),
        );
        self.blend_outside(&place, dir, interp, value, weight)
    }

    /// [`CubeDem::height_at_lattice`] of a version 2 file at a valid lattice point: the source
    /// interpolated at the point's direction (`cube_to_sphere(lattice / m)`, the same bits for
    /// `(2 lattice, 2 m)`) plus the detail octaves coarser than the point's spacing (the finer
    /// ones are exactly zero at it), weighted.
    pub(crate) fn source_height_at_lattice(
        &self,
        lattice: IVec3,
        m: i32,
        interp: Interpolation,
        detail: &DetailNoise,
    ) -> f64 {
        let dir = cube_to_sphere(lattice.as_dvec3() * (1.0 / f64::from(m)));
        let (value, weight) = self.source_at(dir, interp, detail);
        if !detail.is_on() {
            return value;
        }
        let (octaves, scale) = self.lattice_octaves(m);
        value + weight * detail.sum(lattice.as_dvec3() * scale, octaves, self.data_spacing())
    }

    /// The detail octaves that are not zero at lattice points of resolution `m`, and the scale
    /// from lattice coordinates to octave-0 noise coordinates.
    fn lattice_octaves(&self, m: i32) -> (u32, f64) {
        let n = self.header.n;
        let octaves = m.trailing_zeros().saturating_sub(n);
        (octaves, f64::from(1u32 << n) / (2.0 * f64::from(m)))
    }

    /// [`CubeDem::heights_at_lattice`] of a version 2 file, with the bits of
    /// [`CubeDem::source_height_at_lattice`]: points in one source cell share one read of its
    /// 4 x 4 samples and relief weights, and the detail of all points is summed at once.
    pub(crate) fn source_heights_at_lattice(
        &self,
        points: &[IVec3],
        m: i32,
        interp: Interpolation,
        detail: &DetailNoise,
        out: &mut [f64],
    ) {
        assert_eq!(points.len(), out.len(), "one output per point");
        let detail_on = detail.is_on();
        let bound = detail.bound(self.data_spacing());
        let mut cells: Vec<SourceCell> = Vec::new();
        let mut index: HashMap<(u32, u32), usize> = HashMap::new();
        let mut last: Option<((u32, u32), usize)> = None;
        let mut pending: Vec<(usize, f64)> = Vec::new();
        let mut noise_at: Vec<DVec3> = Vec::new();
        let (octaves, scale) = if lattice_resolution_ok(m) {
            self.lattice_octaves(m)
        } else {
            (0, 1.0)
        };
        for (at, (lattice, h)) in points.iter().zip(out.iter_mut()).enumerate() {
            if !lattice_point_ok(*lattice, m) {
                *h = f64::NAN;
                continue;
            }
            let dir = cube_to_sphere(lattice.as_dvec3() * (1.0 / f64::from(m)));
            let Some(place) = self.source_place(dir) else {
                *h = f64::NAN;
                continue;
            };
            let key = (place.c0, place.r0);
            let k = match last {
                Some((k, i)) if k == key => i,
                _ => {
                    let i = *index.entry(key).or_insert_with(|| {
                        cells.push(self.source_cell(place.c0, place.r0, detail));
                        cells.len() - 1
                    });
                    last = Some((key, i));
                    i
                }
            };
            let (value, weight) = self.source_interpolate(&cells[k], place.fx, place.fy, interp, detail_on, bound);
            let (value, weight) = self.blend_outside(&place, dir, interp, value, weight);
            *h = value;
            if detail_on {
                pending.push((at, weight));
                noise_at.push(lattice.as_dvec3() * scale);
            }
        }
        if !pending.is_empty() {
            let mut sums = vec![0.0; noise_at.len()];
            detail.sum_many(&noise_at, octaves, self.data_spacing(), &mut sums);
            for ((at, weight), sum) in pending.into_iter().zip(sums) {
                out[at] += weight * sum;
            }
        }
    }

    /// [`CubeDem::height`] of a version 2 file.
    pub(crate) fn source_height(&self, dir: DVec3, interp: Interpolation, detail: &DetailNoise, octaves: u32) -> f64 {
        let (value, weight) = self.source_at(dir, interp, detail);
        // No detail where it cannot move the height by a nanometre (at and right next to the
        // source samples, on flat data): the octaves are not summed for nothing.
        if !detail.is_on() || weight.abs() * detail.bound(self.data_spacing()) < NEGLIGIBLE_DETAIL_M {
            return value;
        }
        let Some((face, u, v)) = sphere_to_face_uv(dir) else {
            return f64::NAN;
        };
        let half = f64::from(1u32 << self.header.n) * 0.5;
        value + weight * detail.sum(face_uv_to_cube(face, u, v) * half, octaves, self.data_spacing())
    }
}

/// Whether `m` is a lattice resolution [`CubeDem::height_at_lattice`] accepts.
#[inline]
pub(crate) fn lattice_resolution_ok(m: i32) -> bool {
    m > 0 && m <= MAX_LATTICE_RESOLUTION && m.count_ones() == 1
}

/// Whether `lattice` is a canonical lattice point of resolution `m` on the cube's surface.
#[inline]
pub(crate) fn lattice_point_ok(lattice: IVec3, m: i32) -> bool {
    lattice_resolution_ok(m)
        && lattice.abs().max_element() <= m
        && (lattice + IVec3::splat(m)) % 2 == IVec3::ZERO
        && home_face(lattice, m).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fade_is_zero_at_the_samples_and_one_away_from_them() {
        for (fx, fy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            assert_eq!(sample_fade(fx, fy), 0.0);
        }
        assert_eq!(sample_fade(0.5, 0.5), 1.0);
        assert_eq!(sample_fade(0.5, 0.0), 1.0);
        assert_eq!(sample_fade(SAMPLE_FADE_RADIUS, 0.0), 1.0);
        assert!(sample_fade(1e-9, 0.0) < 1e-30);
        // Continuous across cell borders: fractions 1 and 0 meet.
        assert_eq!(sample_fade(1.0, 0.3), sample_fade(0.0, 0.3));
    }
}
