//! The geometric error of each level of detail, measured on a planet.
//!
//! A level-`L` chunk samples the density every `2^L` level-0 steps and marching cubes draws, in
//! each cell, flat triangles between points interpolated linearly along the cell's edges: the
//! level represents the density by the trilinear interpolant of its cell corners, placed in space
//! by the same interpolation of the corner positions. Where the cell holds surface, the distance
//! in metres between that representation and the true surface is about
//! `|interpolant - density| / |gradient|` at points inside the cell.
//!
//! [`measure_level_errors`] measures it for every level `L >= 1`:
//!
//! 1. **Where the surface is.** Directions are spread evenly over the sphere: the R2
//!    low-discrepancy sequence, offset by the seed, mapped by Archimedes' equal-area projection.
//!    Places are drawn in proportion to their area, and any prefix of the sequence covers the
//!    planet evenly, so rough regions get their share of a few hundred directions (with
//!    independent random directions, estimates from as many cells scatter about twice as much).
//!    Along each direction, a batch call over 32 radii spanning the density's
//!    [`radial_bounds`](pmc_density::Density::radial_bounds) within the shell brackets a sign
//!    change (below the first radius everything is solid, above the last everything is air; one
//!    bracket is picked at random when there are several), and regula falsi (Illinois) narrows
//!    it to `n_t / 8` cells of the level. Where the window of step 2 holds the whole
//!    range of the radial bounds, no search is needed and the window sits in its middle.
//! 2. **The cells there.** The direction lies in one column of level-`L` cells (the face cell of
//!    stride `2^L` around it). One batch call samples the column's four corner columns, with the
//!    canonical directions and layer radii every chunk uses, at the `n_t + 1` layers of a window
//!    of `n_t` cells (a chunk's depth) centred on the crossing, and applies the shell contract
//!    (layers `<= 0` solid, layers `>= D` air, NaN air), as the mesher does. Every cell there
//!    whose eight corners change sign holds surface of the level's mesh; up to
//!    [`CELLS_PER_CHUNK`] of them (a random subset when there are more) are measured. A column
//!    where the surface is steep, folded or hollowed by caves holds more surface and has more
//!    such cells, so cells are measured about in proportion to the surface they hold. Cells
//!    touching the shell's boundary layers count like any other: on the coarsest levels one
//!    cell spans the whole shell.
//! 3. **The distance in a cell.** At the cell's centre, the midpoints of its six faces and of its
//!    twelve edges (points halfway between level-`L` voxels), compare the interpolant of the
//!    eight corner densities with the true density at the interpolated position, and divide by
//!    the length of the true density's gradient there, from central differences along the radius
//!    and along two tangent directions (steps of `min(l_d, d_b / N) / 4`, longer far from the
//!    surface, where the `f32` rounding of large densities would otherwise show). The true
//!    density comes from batch calls: one per lateral position of the cell grid over the radii
//!    of every measured cell of the column there and their radial steps (the vertical edge
//!    midpoints near the crossing come with the corners' call), and one over the four tangent
//!    offsets. Points where the gradient is below [`MIN_GRADIENT`] are skipped. The
//!    corners are placed in space by the grid's curved columns but the triangles are flat, so
//!    the curvature of the sphere is part of the error: the exact sphere measures the sagitta of
//!    a cell's chords, not zero.
//!
//!    The radial derivative alone is a lower bound of the gradient's length, so
//!    `|interpolant - density| / |radial derivative|` bounds the distance from above. When that
//!    bound is at most a threshold `t` (the previous level's error, or a quarter of the level's
//!    running estimate, updated every 32 cells, if larger), the bound is recorded and the
//!    tangent samples are skipped. The distances above `t` are then all exact and the others
//!    stay at most `t`, so the 99th percentile is exact whenever it is at least `t`; below the
//!    previous level's error it is replaced by that error anyway (step 5).
//! 4. **The level's error** is the 99th percentile (nearest rank) of the distances. Cells are
//!    measured until `samples_per_level` of them were, or earlier once the estimate has settled:
//!    from [`FIRST_CHECK`] cells on, and again whenever the count has grown by half, the 99th
//!    percentiles of the distances from the even- and from the odd-numbered directions (two
//!    interleaved halves, each spread over the whole planet) are compared, and measuring stops
//!    when they differ by at most [`AGREEMENT`] of the whole's.
//! 5. The table is made non-decreasing in `L` by a running maximum (a coarser level is never
//!    promised to be more accurate than a finer one), and `errors[0] = 0` (level 0 is the
//!    reference). A level where no cell was measured keeps the previous level's error.
//!
//! The cost is in the density's batch calls, which evaluate a terrain's height field once per
//! direction they are given: about ten directions per measured cell.

use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{sphere_to_face_uv, Layout};
use pmc_planet::Planet;

/// Most cells measured per sampled direction: among the `n_t` cells (a chunk's depth) of the
/// direction's column of cells centred where it meets the surface, those whose corners change
/// sign (a random subset of this many when there are more).
pub const CELLS_PER_CHUNK: usize = 8;
/// Gradient lengths (density units per metre) below this are too flat to convert a density
/// difference into a distance; such points are skipped.
pub const MIN_GRADIENT: f64 = 1e-3;
/// Cells measured at a level before the estimate may stop early.
const FIRST_CHECK: usize = 384;
/// The two halves' 99th percentiles must agree to within this fraction of the whole's for the
/// measurement of a level to stop before `samples_per_level` cells.
const AGREEMENT: f64 = 0.2;

/// Radii sampled along a direction, in one batch call, to bracket where the surface crosses it.
const SCAN_RADII: usize = 32;
/// The most regula falsi steps spent narrowing a crossing.
const MAX_STEPS: usize = 40;
/// Cells on either side of the crossing's whose vertical edge midpoints are sampled with the
/// corners.
const NEAR_CELLS: usize = 4;
/// Cells measured between two updates of the threshold under which distances need no exact
/// gradient.
const FLOOR_REFRESH: usize = 32;
/// That threshold's share of the level's running estimate.
const FLOOR_SHARE: f64 = 0.25;
/// Density written by the shell contract into forced-solid samples (`pmc_mesh::shell`).
const FORCED_SOLID: f32 = 1.0;
/// Density written by the shell contract into forced-air samples (`pmc_mesh::shell`).
const FORCED_AIR: f32 = -1.0;

/// The measured geometric error of each level, in metres: index = level, `0..=max_level`, with
/// `errors[0] = 0` and the table non-decreasing.
///
/// For each level `L >= 1`: directions spread evenly over the sphere find where the surface is;
/// the level-`L` cells there whose corners change sign are measured at their centre, face and
/// edge midpoints, where `|trilinear interpolant of the corner densities - true density| /
/// |gradient of the true density|` estimates the distance between the level's surface and the
/// true one; the level's error is the 99th percentile of those distances, then the running
/// maximum over the levels. Cells are drawn about in proportion to the surface they hold, and
/// every density evaluation goes through the batch call [`Density::sample_shell`].
///
/// `samples_per_level` is the most cells measured per level (each at 19 points); fewer are when
/// the estimate settles first (from 384 cells on, when the estimates from two interleaved halves
/// of the directions agree within 20%). At most `4 samples_per_level` directions are drawn per
/// level. The result depends only on the planet, `samples_per_level` and `seed`.
pub fn measure_level_errors(planet: &Planet, samples_per_level: usize, seed: u64) -> Vec<f64> {
    if let Some(h) = planet.heightfield_mode() {
        // Patches: the height-field's own measure (the same percentile, on its cells).
        return h.level_errors().to_vec();
    }
    let layout = *planet.layout();
    let max_level = layout.max_level();
    let mut errors = vec![0.0; usize::from(max_level) + 1];
    let sampler = Sampler::new(planet);
    for level in 1..=max_level {
        let mut rng = SplitMix64::new(seed ^ (u64::from(level)).wrapping_mul(0xa076_1d64_78bd_642f));
        let previous = errors[usize::from(level) - 1];
        let measured = sampler.measure_level(level, samples_per_level, previous, &mut rng);
        errors[usize::from(level)] = measured.map_or(previous, |e| e.max(previous));
    }
    errors
}

/// What every level's measurement shares.
struct Sampler<'a> {
    density: &'a dyn Density,
    layout: Layout,
    /// Radii between which the surface lies, within the shell.
    range: (f64, f64),
    /// The smallest central-difference step, in metres.
    step: f64,
}

/// The four corner columns of a level's column of cells, sampled around where a direction meets
/// the surface.
struct Column {
    /// Unit directions of the corners, index `n = x + 2 y` (`x` along the face's `u`).
    dirs: [DVec3; 4],
    /// Layer radii, index `m` for the window's `m`-th layer.
    radii: Vec<f64>,
    /// Closed densities, index `m * 4 + n`.
    densities: Vec<f32>,
    /// The radius where the direction meets the surface.
    crossing: f64,
    /// The window cells (cell `m` lies between layers `m` and `m + 1`) whose vertical edge
    /// midpoints were sampled with the corners.
    near: std::ops::Range<usize>,
    /// The density at those midpoints and one step below and above them (see
    /// [`Sampler::step_for`]), index `((m - near.start) * 3 + j) * 4 + n`, `j` = below, at, above.
    edges: Vec<f32>,
}

impl Column {
    /// Whether the cell between layers `m` and `m + 1` has solid and air corners.
    fn changes_sign(&self, m: usize) -> bool {
        let corners = &self.densities[m * 4..m * 4 + 8];
        let solid = corners.iter().filter(|d| **d > 0.0).count();
        solid != 0 && solid != 8
    }
}

impl<'a> Sampler<'a> {
    /// The sampler of `planet`'s (edited) density on its layout.
    fn new(planet: &'a Planet) -> Sampler<'a> {
        let layout = *planet.layout();
        let density = planet.density().as_ref();
        let (bottom, top) = (layout.d_b(), layout.radius());
        let (lo, hi) = density.radial_bounds().unwrap_or((bottom, top));
        let lo = lo.clamp(bottom, top);
        let hi = hi.clamp(lo, top);
        Sampler {
            density,
            layout,
            range: (lo, hi),
            step: 0.25 * layout.l_d().min(layout.d_b() / layout.face_tiles() as f64),
        }
    }

    /// The central-difference step for the points of a cell between radii `r0` and `r1`: the
    /// smallest step, grown with the distance from the surface so that the `f32` rounding of
    /// large densities (far from the surface on coarse levels) stays small against the
    /// difference.
    fn step_for(&self, crossing: f64, r0: f64, r1: f64) -> f64 {
        let far = (r0 - crossing).abs().max((r1 - crossing).abs());
        self.step.max(1e-5 * far)
    }

    /// The 99th percentile of the distances measured at `level`, `None` when no cell was
    /// measured.
    fn measure_level(&self, level: u8, samples: usize, previous: f64, rng: &mut SplitMix64) -> Option<f64> {
        if samples == 0 {
            return None;
        }
        // Distances from the cells of even and of odd directions.
        let mut halves: [Vec<f64>; 2] = Default::default();
        let mut cells = 0;
        let mut check = FIRST_CHECK;
        let mut floor = previous;
        let mut refresh = FLOOR_REFRESH;
        let mut spread = Spread::new(rng);
        for n in 0..4 * samples {
            if cells >= samples {
                break;
            }
            let dir = spread.next();
            cells += self.measure_direction(level, dir, samples - cells, floor, rng, &mut halves[n & 1]);
            if cells >= refresh {
                let mut all: Vec<f64> = halves.concat();
                floor = previous.max(FLOOR_SHARE * percentile_99(&mut all).unwrap_or(0.0));
                refresh = cells + FLOOR_REFRESH;
            }
            if cells >= check && cells < samples {
                if agree(&halves) {
                    break;
                }
                check = cells + cells.div_ceil(2);
            }
        }
        let [mut all, odd] = halves;
        all.extend(odd);
        percentile_99(&mut all)
    }

    /// Measures up to `most` (and [`CELLS_PER_CHUNK`]) cells of `level` holding surface where
    /// `dir` meets it, pushing their distances to `out` (those whose radial bound is at most
    /// `floor` as that bound, see the module docs); returns how many cells were measured.
    fn measure_direction(
        &self,
        level: u8,
        dir: DVec3,
        most: usize,
        floor: f64,
        rng: &mut SplitMix64,
        out: &mut Vec<f64>,
    ) -> usize {
        let layout = &self.layout;
        let stride = 1i64 << level;
        let cell_height = layout.l_d() * stride as f64;
        let n_t = i64::from(layout.n_t());
        let Some((face, u, v)) = sphere_to_face_uv(dir) else {
            return 0;
        };
        // Where the surface is along `dir`, closely enough to centre the window on it; when the
        // window holds the whole range where the surface may lie, its middle will do.
        let (lo, hi) = self.range;
        let crossing = if hi - lo <= (n_t - 2) as f64 * cell_height {
            0.5 * (lo + hi)
        } else {
            match self.crossing(dir, (n_t / 8).max(1) as f64 * cell_height, rng) {
                Some(r) => r,
                None => return 0,
            }
        };
        // The column of cells holding `dir`, and a window of `n_t` cells around the crossing.
        let per_side = layout.face_tiles() / stride;
        let index = |x: f64| ((0.5 * (x + 1.0) * per_side as f64).floor() as i64).clamp(0, per_side - 1);
        let (a, b) = (index(u), index(v));
        let dirs: [DVec3; 4] = std::array::from_fn(|n| {
            let lattice = layout
                .lattice(face, (a + (n & 1) as i64) * stride, (b + (n >> 1) as i64) * stride)
                .expect("a cell corner lies on its face");
            layout.lattice_direction(lattice)
        });
        let depth_cells = i64::from(layout.depth_chunks(level)) * n_t;
        let centre = (((crossing - layout.d_b()) / cell_height).floor() as i64).clamp(0, depth_cells - 1);
        let first = (centre - n_t / 2).max(0);
        let last = (centre + n_t / 2).min(depth_cells - 1);
        let layers: Vec<i64> = (first..=last + 1).map(|c| c * stride).collect();
        let mut radii: Vec<f64> = layers.iter().map(|&k| layout.layer_radius(k)).collect();
        let window = radii.len();
        // The vertical edge midpoints of the cells nearest the crossing (where the cells that
        // change sign mostly are) come with the same call: no column is evaluated twice.
        let centre = (centre - first) as usize;
        let near = centre.saturating_sub(NEAR_CELLS)..(centre + NEAR_CELLS + 1).min(window - 1);
        for m in near.clone() {
            let (r0, r1) = (radii[m], radii[m + 1]);
            let h = self.step_for(crossing, r0, r1);
            let mid = 0.5 * (r0 + r1);
            radii.extend([mid - h, mid, mid + h]);
        }
        let mut densities = vec![0.0f32; 4 * radii.len()];
        self.density.sample_shell(&dirs, &radii, &mut densities);
        let edges = densities.split_off(4 * window);
        radii.truncate(window);
        let d = layout.depth_tiles();
        for (row, &k) in densities.chunks_exact_mut(4).zip(&layers) {
            for x in row {
                *x = close(k, d, *x);
            }
        }
        let column = Column {
            dirs,
            radii,
            densities,
            crossing,
            near,
            edges,
        };
        let mut cells: Vec<usize> = (0..window - 1).filter(|&m| column.changes_sign(m)).collect();
        let take = cells.len().min(CELLS_PER_CHUNK).min(most);
        // A partial Fisher-Yates shuffle: the first `take` cells are a uniform random subset.
        for n in 0..take {
            let m = n + rng.below((cells.len() - n) as u64) as usize;
            cells.swap(n, m);
        }
        if take > 0 {
            self.measure_cells(&column, &cells[..take], floor, out);
        }
        take
    }

    /// A radius where the density changes sign along `dir`, to within `tolerance` metres (or the
    /// regula falsi's step limit); `None` only for a non-finite direction.
    fn crossing(&self, dir: DVec3, tolerance: f64, rng: &mut SplitMix64) -> Option<f64> {
        if !dir.is_finite() {
            return None;
        }
        let (lo, hi) = self.range;
        let radii: Vec<f64> = (0..SCAN_RADII)
            .map(|m| lo + (hi - lo) * m as f64 / (SCAN_RADII - 1) as f64)
            .collect();
        let mut values = vec![0.0f32; SCAN_RADII];
        self.density.sample_shell(&[dir], &radii, &mut values);
        // Solid below the range and air above it, whatever the end samples say.
        let solid = |m: usize| m == 0 || (m + 1 < SCAN_RADII && values[m] > 0.0);
        let brackets: Vec<usize> = (0..SCAN_RADII - 1).filter(|&m| solid(m) != solid(m + 1)).collect();
        let m = brackets[rng.below(brackets.len() as u64) as usize];
        // Signed values that agree with the sides (the ends may have been overridden).
        let signed = |is_solid: bool, v: f64| {
            if is_solid {
                v.max(f64::MIN_POSITIVE)
            } else if v.is_nan() {
                -f64::MIN_POSITIVE
            } else {
                v.min(-f64::MIN_POSITIVE)
            }
        };
        let (mut ra, mut fa) = (radii[m], signed(solid(m), f64::from(values[m])));
        let (mut rb, mut fb) = (radii[m + 1], signed(solid(m + 1), f64::from(values[m + 1])));
        let mut last_side = None;
        let mut value = [0.0f32];
        for _ in 0..MAX_STEPS {
            if rb - ra <= tolerance {
                break;
            }
            // The secant root lies strictly inside the bracket (the values have opposite signs);
            // keep it clear of the ends so that the bracket shrinks.
            let margin = 1e-3 * (rb - ra);
            let r = ((ra * fb - rb * fa) / (fb - fa)).clamp(ra + margin, rb - margin);
            self.density.sample_shell(&[dir], &[r], &mut value);
            let f = f64::from(value[0]);
            let is_solid = f > 0.0;
            if is_solid == (fa > 0.0) {
                ra = r;
                fa = signed(is_solid, f);
                // Illinois: halve the end that stayed twice in a row.
                if last_side == Some(0) {
                    fb *= 0.5;
                }
                last_side = Some(0);
            } else {
                rb = r;
                fb = signed(is_solid, f);
                if last_side == Some(1) {
                    fa *= 0.5;
                }
                last_side = Some(1);
            }
        }
        Some(((ra * fb - rb * fa) / (fb - fa)).clamp(ra, rb))
    }

    /// Measures cells `cells` of `column` (cell `m` lies between window layers `m` and `m + 1`)
    /// at their centres, face midpoints and edge midpoints, pushing distances in metres. The
    /// cells lie above one another, so each lateral position is one column of the density for
    /// all of them.
    fn measure_cells(&self, column: &Column, cells: &[usize], floor: f64, out: &mut Vec<f64>) {
        // Lateral positions (s, t) on a 3 x 3 grid; the corners of the grid need only the middle
        // depth (vertical edge midpoints), the others the bottom, middle and top.
        let mut points = Vec::with_capacity(3 * cells.len());
        for y in 0..3 {
            for x in 0..3 {
                let depths: &[f64] = if x != 1 && y != 1 { &[0.5] } else { &[0.0, 0.5, 1.0] };
                points.clear();
                self.measure_lateral(column, cells, (x, y), depths, floor, &mut points, out);
            }
        }
    }

    /// Measures the points of `cells` at lateral grid position `(x, y)` (`0..3` each: `(s, t) =
    /// (x / 2, y / 2)`) and depth fractions `depths` (0 = bottom layer), pushing distances.
    /// `points` is scratch.
    #[allow(clippy::too_many_arguments)]
    fn measure_lateral(
        &self,
        column: &Column,
        cells: &[usize],
        (x, y): (usize, usize),
        depths: &[f64],
        floor: f64,
        points: &mut Vec<Point>,
        out: &mut Vec<f64>,
    ) {
        let (s, t) = (0.5 * x as f64, 0.5 * y as f64);
        let lateral = [(1.0 - s) * (1.0 - t), s * (1.0 - t), (1.0 - s) * t, s * t];
        // The corner columns keep their own directions; elsewhere positions are trilinear in the
        // corner positions `direction x layer radius`: the blend of the directions (shorter than
        // a unit vector) times the blend of the radii.
        let corner = (x != 1 && y != 1).then_some(x / 2 + y);
        let (dir, stretch) = match corner {
            Some(n) => (column.dirs[n], 1.0),
            None => {
                let blend: DVec3 = (0..4).map(|n| column.dirs[n] * lateral[n]).sum();
                let stretch = blend.length();
                (blend / stretch, stretch)
            }
        };
        let blend = |m: usize| -> f64 {
            (0..4)
                .map(|n| f64::from(column.densities[m * 4 + n]) * lateral[n])
                .sum()
        };
        for &m in cells {
            let (r0, r1) = (column.radii[m], column.radii[m + 1]);
            let (below, above) = (blend(m), blend(m + 1));
            let h = self.step_for(column.crossing, r0, r1);
            for &w in depths {
                points.push(Point {
                    interp: (1.0 - w) * below + w * above,
                    radius: stretch * ((1.0 - w) * r0 + w * r1),
                    h,
                    // The corner columns' vertical edge midpoints near the crossing were
                    // sampled with the corners.
                    edge: corner
                        .filter(|_| column.near.contains(&m))
                        .map(|n| 12 * (m - column.near.start) + n),
                    along: [0.0; 3],
                });
            }
        }
        // The true density at each point and one step below and above it.
        let mut radii = Vec::with_capacity(3 * points.len());
        for p in points.iter_mut() {
            match p.edge {
                Some(e) => p.along = [column.edges[e], column.edges[e + 4], column.edges[e + 8]],
                None => radii.extend([p.radius - p.h, p.radius, p.radius + p.h]),
            }
        }
        if !radii.is_empty() {
            let mut values = vec![0.0f32; radii.len()];
            self.density.sample_shell(&[dir], &radii, &mut values);
            for (p, v) in points
                .iter_mut()
                .filter(|p| p.edge.is_none())
                .zip(values.chunks_exact(3))
            {
                p.along.copy_from_slice(v);
            }
        }
        let delta = points.iter().fold(0.0f64, |d, p| d.max(p.h / p.radius));
        // Each point's difference and radial derivative. The radial derivative alone is a lower
        // bound of the gradient's length: a point whose distance with it is at most `floor` is
        // recorded with that bound (see the module docs); the others need the tangent samples.
        points.retain(|p| {
            let diff = p.diff();
            let radial = p.radial();
            if !diff.is_finite() || radial.is_nan() {
                return false;
            }
            if radial.abs() >= MIN_GRADIENT && diff / radial.abs() <= floor {
                out.push(diff / radial.abs());
                return false;
            }
            true
        });
        if points.is_empty() {
            return;
        }
        // Two unit tangents, and directions turned by `delta` either way along each: at least
        // every point's step at its radius (taken over every point here, so that no distance
        // depends on which others needed the tangent samples).
        let (t1, t2) = tangents(dir);
        let turned = [
            (dir + t1 * delta).normalize(),
            (dir - t1 * delta).normalize(),
            (dir + t2 * delta).normalize(),
            (dir - t2 * delta).normalize(),
        ];
        let radii: Vec<f64> = points.iter().map(|p| p.radius).collect();
        let mut across = vec![0.0f32; 4 * radii.len()];
        self.density.sample_shell(&turned, &radii, &mut across);
        // `turned[0] r - turned[1] r` is `2 r delta / sqrt(1 + delta^2)` along the tangent.
        let chord = 2.0 * delta / (1.0 + delta * delta).sqrt();
        for (p, row) in points.iter().zip(across.chunks_exact(4)) {
            let span = chord * p.radius;
            let g1 = (f64::from(row[0]) - f64::from(row[1])) / span;
            let g2 = (f64::from(row[2]) - f64::from(row[3])) / span;
            let gradient = (p.radial().powi(2) + g1 * g1 + g2 * g2).sqrt();
            if gradient.is_nan() || gradient < MIN_GRADIENT {
                continue;
            }
            let metres = p.diff() / gradient;
            if metres.is_finite() {
                out.push(metres);
            }
        }
    }
}

/// One point of a cell being measured.
#[derive(Clone, Copy, Debug)]
struct Point {
    /// The interpolant of the cell's corner densities there.
    interp: f64,
    /// Its radius (along the lateral position's direction).
    radius: f64,
    /// The central-difference step, in metres.
    h: f64,
    /// Where its samples are in [`Column::edges`], when they came with the corners.
    edge: Option<usize>,
    /// The true density one step below it, at it and one step above it.
    along: [f32; 3],
}

impl Point {
    /// `|interpolant - true density|`.
    fn diff(&self) -> f64 {
        (self.interp - f64::from(self.along[1])).abs()
    }

    /// The radial derivative of the true density, by central differences.
    fn radial(&self) -> f64 {
        (f64::from(self.along[2]) - f64::from(self.along[0])) / (2.0 * self.h)
    }
}

/// The shell contract for one sample at depth index `k` of a shell `depth_tiles` deep: what the
/// mesher makes of density `d` (layers `<= 0` solid, layers `>= D` air, NaN air).
fn close(k: i64, depth_tiles: i64, d: f32) -> f32 {
    if k <= 0 {
        if d > 0.0 {
            d
        } else {
            FORCED_SOLID
        }
    } else if k >= depth_tiles {
        if d.is_nan() || d > 0.0 {
            FORCED_AIR
        } else {
            d
        }
    } else if d.is_nan() {
        FORCED_AIR
    } else {
        d
    }
}

/// Two unit vectors perpendicular to the unit vector `d` and to each other.
fn tangents(d: DVec3) -> (DVec3, DVec3) {
    let a = d.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let t1 = (axis - d * d.dot(axis)).normalize();
    (t1, d.cross(t1))
}

/// Whether the 99th percentiles of the two halves differ by at most [`AGREEMENT`] of the
/// whole's.
fn agree(halves: &[Vec<f64>; 2]) -> bool {
    let mut a = halves[0].clone();
    let mut b = halves[1].clone();
    let mut all = halves.concat();
    match (percentile_99(&mut a), percentile_99(&mut b), percentile_99(&mut all)) {
        (Some(a), Some(b), Some(all)) => (a - b).abs() <= AGREEMENT * all,
        _ => false,
    }
}

/// The 99th percentile (nearest rank) of `v`, `None` when empty.
fn percentile_99(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let rank = (0.99 * v.len() as f64).ceil() as usize;
    let (_, value, _) = v.select_nth_unstable_by(rank.clamp(1, v.len()) - 1, f64::total_cmp);
    Some(*value)
}

/// Directions spread evenly over the sphere, and every prefix of them too: the R2
/// low-discrepancy sequence (the additive recurrence on the plastic number) from a random
/// offset, mapped to the sphere by Archimedes' area-preserving projection (height uniform in
/// `[-1, 1]`, longitude uniform).
struct Spread {
    /// The last point of the sequence in the unit square.
    point: [f64; 2],
}

impl Spread {
    /// Steps of the R2 sequence: `1 / g` and `1 / g^2` for the plastic number `g`.
    const STEP: [f64; 2] = [0.754_877_666_246_692_8, 0.569_840_290_998_053_3];

    /// A sequence starting from a random point of the unit square.
    fn new(rng: &mut SplitMix64) -> Spread {
        Spread {
            point: [rng.unit(), rng.unit()],
        }
    }

    /// The next direction (a unit vector).
    fn next(&mut self) -> DVec3 {
        for (p, step) in self.point.iter_mut().zip(Self::STEP) {
            *p += step;
            if *p >= 1.0 {
                *p -= 1.0;
            }
        }
        let z = 2.0 * self.point[0] - 1.0;
        let phi = std::f64::consts::TAU * self.point[1];
        let ring = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(ring * phi.cos(), z, ring * phi.sin())
    }
}

/// SplitMix64: a small, fast, well-mixed deterministic generator.
#[derive(Clone, Debug)]
struct SplitMix64(u64);

impl SplitMix64 {
    fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n > 0`), by multiply-shift (bias below `n / 2^64`).
    fn below(&mut self, n: u64) -> u64 {
        ((u128::from(self.next()) * u128::from(n)) >> 64) as u64
    }

    /// A number in `[0, 1)` with 53 random bits.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_takes_the_nearest_rank() {
        let mut v: Vec<f64> = (1..=200).map(f64::from).collect();
        assert_eq!(percentile_99(&mut v), Some(198.0));
        assert_eq!(percentile_99(&mut [3.0]), Some(3.0));
        assert_eq!(percentile_99(&mut []), None);
    }

    #[test]
    fn the_generator_stays_below_its_bound() {
        let mut r = SplitMix64::new(7);
        let mut seen = [false; 5];
        for _ in 0..1000 {
            let x = r.below(5);
            assert!(x < 5);
            seen[x as usize] = true;
        }
        assert!(seen.iter().all(|s| *s));
    }

    #[test]
    fn the_shell_contract_is_the_meshers() {
        let samples = [
            -2.5f32,
            -0.0,
            0.0,
            1e-30,
            3.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for k in [-3i64, 0, 1, 7, 8, 9, 40] {
            for d in samples {
                let ours = close(k, 8, d);
                let theirs = pmc_mesh::shell::close_sample(k, 8, d);
                assert_eq!(ours.to_bits(), theirs.to_bits(), "k {k}, d {d}");
            }
        }
    }

    /// Every prefix is spread evenly: the counts per octant stay much closer to an eighth than
    /// independent random directions would (their standard deviation is about 10 at 1024).
    #[test]
    fn spread_directions_cover_the_sphere_evenly() {
        for seed in 0..8 {
            let mut spread = Spread::new(&mut SplitMix64::new(seed));
            let mut octants = [0i64; 8];
            for n in 1..=1024i64 {
                let d = spread.next();
                assert!((d.length() - 1.0).abs() < 1e-12, "{d:?}");
                let o = usize::from(d.x > 0.0) + 2 * usize::from(d.y > 0.0) + 4 * usize::from(d.z > 0.0);
                octants[o] += 1;
                if n % 256 == 0 {
                    for c in octants {
                        assert!((8 * c - n).abs() <= 8 * 6, "seed {seed}, {n} directions: {octants:?}");
                    }
                }
            }
        }
    }

    /// The crossing search brackets the surface of a ball to within the tolerance asked for.
    #[test]
    fn the_crossing_search_finds_a_balls_surface() {
        let layout = Layout::default();
        for radius in [1790.0, 1872.37, 1999.0] {
            let ball = pmc_density::Sphere { radius };
            let sampler = Sampler {
                density: &ball,
                layout,
                range: (layout.d_b(), layout.radius()),
                step: 0.25,
            };
            let mut spread = Spread::new(&mut SplitMix64::new(3));
            let mut rng = SplitMix64::new(4);
            for tolerance in [0.01, 4.0, 40.0] {
                let dir = spread.next();
                let r = sampler.crossing(dir, tolerance, &mut rng).unwrap();
                assert!((r - radius).abs() <= tolerance, "{radius}: {r} (tolerance {tolerance})");
            }
        }
    }

    /// The radial shortcut only ever replaces distances that are at most the threshold, by
    /// bounds that are at most the threshold: the values above it are the same either way.
    #[test]
    fn the_gradient_shortcut_keeps_every_distance_above_its_threshold() {
        let layout = Layout::default();
        let planet = Planet::new(pmc_planet::PresetKind::Earthlike, 5, layout);
        let sampler = Sampler::new(&planet);
        for level in 1..=layout.max_level() {
            let mut spread = Spread::new(&mut SplitMix64::new(u64::from(level)));
            let (mut exact, mut quick) = (Vec::new(), Vec::new());
            for _ in 0..64 {
                let dir = spread.next();
                let mut rng = SplitMix64::new(9);
                sampler.measure_direction(level, dir, CELLS_PER_CHUNK, 0.0, &mut rng.clone(), &mut exact);
                sampler.measure_direction(level, dir, CELLS_PER_CHUNK, 1.0, &mut rng, &mut quick);
            }
            assert_eq!(exact.len(), quick.len(), "level {level}");
            assert!(!exact.is_empty());
            let above = |v: &[f64]| {
                let mut a: Vec<u64> = v.iter().filter(|x| **x > 1.0).map(|x| x.to_bits()).collect();
                a.sort_unstable();
                a
            };
            assert_eq!(above(&exact), above(&quick), "level {level}");
            // Each bound is at least its exact distance, so the sorted values dominate.
            exact.sort_by(f64::total_cmp);
            quick.sort_by(f64::total_cmp);
            for (e, q) in exact.iter().zip(&quick) {
                assert!(q >= e, "level {level}: {e} became {q}");
            }
        }
    }
}
