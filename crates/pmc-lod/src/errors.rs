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
//! 1. Pick level-`L` chunks at random among those that may hold surface
//!    ([`Planet::may_hold_surface`]), deterministically from the seed.
//! 2. Sample each chunk's own grid with the batch call the mesher uses, and pick at random up to
//!    [`CELLS_PER_CHUNK`] cells whose corners change sign, with every corner strictly inside the
//!    shell (layers `1..D`; the shell contract overrides layers `0` and `D`).
//! 3. In each cell, at its centre and at the midpoints of its twelve edges (points halfway
//!    between level-`L` voxels), compare the interpolant of the eight corner densities with the
//!    true density at the interpolated position, and divide by the true density's gradient
//!    length from central differences (points where it is below [`MIN_GRADIENT`] are skipped).
//!    The corners are placed in space by the grid's curved columns but the triangles are flat, so
//!    the curvature of the sphere is part of the error: the exact sphere measures the sagitta of
//!    a cell's chords, not zero.
//! 4. The level's error is the 99th percentile of those distances; then the table is made
//!    non-decreasing in `L` by a running maximum (a coarser level is never promised to be more
//!    accurate than a finer one), and `errors[0] = 0` (level 0 is the reference).
//!
//! A level where no sampled cell holds surface keeps the previous level's error.

use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Face, Layout};
use pmc_planet::Planet;

/// Most cells measured in one sampled chunk (so that the measurement spreads over the planet).
pub const CELLS_PER_CHUNK: usize = 8;
/// Gradient lengths (density units per metre) below this are too flat to convert a density
/// difference into a distance; such points are skipped.
pub const MIN_GRADIENT: f64 = 1e-3;

/// The measured geometric error of each level, in metres: index = level, `0..=max_level`, with
/// `errors[0] = 0` and the table non-decreasing (see the module docs for the method).
///
/// `samples_per_level` is how many cells to measure per level (each at 13 points); chunks are
/// drawn until that many cells are found or `4 ceil(samples_per_level / CELLS_PER_CHUNK)`
/// chunks were tried. The result depends only on the planet, `samples_per_level` and `seed`.
pub fn measure_level_errors(planet: &Planet, samples_per_level: usize, seed: u64) -> Vec<f64> {
    let layout = *planet.layout();
    let max_level = layout.max_level();
    let mut errors = vec![0.0; usize::from(max_level) + 1];
    for level in 1..=max_level {
        let mut rng = SplitMix64::new(seed ^ (u64::from(level)).wrapping_mul(0xa076_1d64_78bd_642f));
        let measured = measure_level(planet, &layout, level, samples_per_level, &mut rng);
        let previous = errors[usize::from(level) - 1];
        errors[usize::from(level)] = measured.map_or(previous, |e| e.max(previous));
    }
    errors
}

/// The 99th percentile of the distances measured at `level`, `None` when no cell was found.
fn measure_level(planet: &Planet, layout: &Layout, level: u8, samples: usize, rng: &mut SplitMix64) -> Option<f64> {
    if samples == 0 {
        return None;
    }
    let per_side = layout.chunks_per_side(level);
    let tries = 4 * samples.div_ceil(CELLS_PER_CHUNK);
    let mut distances = Vec::new();
    let mut cells_done = 0;
    let mut densities = Vec::new();
    for _ in 0..tries {
        if cells_done >= samples {
            break;
        }
        let column = ChunkKey {
            face: Face::ALL[rng.below(6) as usize],
            level,
            i: rng.below(u64::from(per_side)) as u32,
            j: rng.below(u64::from(per_side)) as u32,
            k: 0,
        };
        let depths: Vec<u32> = (0..layout.depth_chunks(level))
            .filter(|&k| planet.may_hold_surface(&ChunkKey { k, ..column }))
            .collect();
        if depths.is_empty() {
            continue;
        }
        let key = ChunkKey {
            k: depths[rng.below(depths.len() as u64) as usize],
            ..column
        };
        let grid = ChunkGrid::new(layout, key);
        densities.resize(grid.sample_count(), 0.0f32);
        planet.density().sample_shell(&grid.dirs, &grid.radii, &mut densities);
        let mut cells = surface_cells(layout, &grid, &densities);
        let take = cells.len().min(CELLS_PER_CHUNK).min(samples - cells_done);
        // A partial Fisher-Yates shuffle: the first `take` cells are a uniform random subset.
        for n in 0..take {
            let m = n + rng.below((cells.len() - n) as u64) as usize;
            cells.swap(n, m);
        }
        for &(a, b, c) in &cells[..take] {
            measure_cell(
                planet.density().as_ref(),
                layout,
                &grid,
                &densities,
                (a, b, c),
                &mut distances,
            );
        }
        cells_done += take;
    }
    percentile_99(&mut distances)
}

/// The cells (by their lowest padded corner index) of the chunk's own grid whose corners change
/// sign, with every corner layer strictly inside the shell.
fn surface_cells(layout: &Layout, grid: &ChunkGrid, densities: &[f32]) -> Vec<(usize, usize, usize)> {
    let d = layout.depth_tiles();
    let layer = |c: usize| grid.k0 + (c as i64 - 1) * grid.stride;
    let mut out = Vec::new();
    for c in 1..=grid.tiles {
        if layer(c) <= 0 || layer(c + 1) >= d {
            continue;
        }
        for b in 1..=grid.tiles {
            for a in 1..=grid.tiles {
                let mut solid = 0;
                for n in 0..8 {
                    let v = densities[grid.index(a + (n & 1), b + (n >> 1 & 1), c + (n >> 2 & 1))];
                    if v > 0.0 {
                        solid += 1;
                    }
                }
                if solid != 0 && solid != 8 {
                    out.push((a, b, c));
                }
            }
        }
    }
    out
}

/// Measures one cell at its centre and its twelve edge midpoints, pushing distances in metres.
fn measure_cell(
    density: &dyn Density,
    layout: &Layout,
    grid: &ChunkGrid,
    densities: &[f32],
    (a, b, c): (usize, usize, usize),
    out: &mut Vec<f64>,
) {
    let corner = |n: usize| (a + (n & 1), b + (n >> 1 & 1), c + (n >> 2 & 1));
    let pos: [DVec3; 8] = std::array::from_fn(|n| {
        let (x, y, z) = corner(n);
        grid.position(x, y, z)
    });
    let den: [f64; 8] = std::array::from_fn(|n| {
        let (x, y, z) = corner(n);
        f64::from(densities[grid.index(x, y, z)])
    });
    // Central differences over a quarter of the smallest level-0 step.
    let h = 0.25 * layout.l_d().min(layout.d_b() / layout.face_tiles() as f64);
    let mut points = vec![[0.5, 0.5, 0.5]];
    for axis in 0..3 {
        for p in 0..2 {
            for q in 0..2 {
                let mut t = [0.0; 3];
                t[axis] = 0.5;
                t[(axis + 1) % 3] = f64::from(p);
                t[(axis + 2) % 3] = f64::from(q);
                points.push(t);
            }
        }
    }
    for t in points {
        let weight = |n: usize| {
            let w = |bit: usize, s: f64| if bit == 1 { s } else { 1.0 - s };
            w(n & 1, t[0]) * w(n >> 1 & 1, t[1]) * w(n >> 2 & 1, t[2])
        };
        let (mut p, mut interp) = (DVec3::ZERO, 0.0);
        for n in 0..8 {
            p += pos[n] * weight(n);
            interp += den[n] * weight(n);
        }
        let truth = density.density(p);
        let diff = |e: DVec3| (density.density(p + e * h) - density.density(p - e * h)) / (2.0 * h);
        let gradient = DVec3::new(diff(DVec3::X), diff(DVec3::Y), diff(DVec3::Z)).length();
        if gradient.is_nan() || gradient < MIN_GRADIENT || !truth.is_finite() || !interp.is_finite() {
            continue;
        }
        let metres = (interp - truth).abs() / gradient;
        if metres.is_finite() {
            out.push(metres);
        }
    }
}

/// The 99th percentile (nearest rank) of `v`, `None` when empty.
fn percentile_99(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let rank = (0.99 * v.len() as f64).ceil() as usize;
    Some(v[rank.clamp(1, v.len()) - 1])
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
}
