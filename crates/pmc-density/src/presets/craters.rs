//! A cellular crater function on the sphere.
//!
//! Space around the unit sphere, scaled by a frequency `f` (so the sphere has radius `f` cells), is
//! cut into unit cells. Each cell holds a crater candidate at a random point of the cell; it
//! becomes a crater with some probability if the point lies within `DELTA` cells of the sphere,
//! and is centred at the point's projection onto the sphere. Around it the height gets a bowl
//! with a raised rim (`x = s / R`, `s` the chord from the crater centre):
//!
//! ```text
//! x <= 1:      max(D (x^2 - 1), -0.8 D) + H      bowl with a flat floor, rim height H = 0.3 D at x = 1
//! 1 < x < 1.8: H (1 - smoothstep(1, 1.8, x))     rim falling off outside
//! ```
//!
//! Only the 2 x 2 x 2 cells nearest to a point can reach it: a crater reaches `q` only if
//! `s < 1.8 R`, and then the candidate point is within `sqrt(s^2 (1 + DELTA / f) + DELTA^2)` of
//! `q`, below half a cell for `R <= 0.22`, `DELTA = 0.25`, `f >= 2` (so every coordinate is within
//! half a cell, which the 2 x 2 x 2 choice covers). The sum over a level is clamped to
//! `[-D_max, H_max]`, which keeps the relief bounded where craters overlap.

use super::features::smoothstep;
use crate::noise::{mix64, unit_f64};
use pmc_geometry::glam::DVec3;

/// Outer edge of the rim, in crater radii.
const RIM_OUTER: f64 = 1.8;
/// Rim height as a fraction of the bowl depth.
const RIM_HEIGHT: f64 = 0.3;
/// Flat floor, as a fraction of the bowl depth.
const FLOOR: f64 = 0.8;
/// How far from the sphere (cells) a candidate point may lie.
const DELTA: f64 = 0.25;
/// Largest crater radius (cells), see the module docs.
const MAX_RADIUS: f64 = 0.22;

/// One scale of craters.
#[derive(Clone, Debug)]
pub(crate) struct CraterLevel {
    seed: u64,
    freq: f64,
    exist: f64,
    radius: (f64, f64),
    depth_per_cell: f64,
    depth_cap: f64,
}

impl CraterLevel {
    /// Craters in cells of `cell` metres on a planet of `radius` metres: each cell holds one with
    /// probability `exist`, of radius `0.08..0.22` cells, bowl depth `depth_ratio` times its
    /// radius in metres, at most `depth_cap` metres. The cell must be at most half the radius.
    pub fn new(seed: u64, radius: f64, cell: f64, exist: f64, depth_ratio: f64, depth_cap: f64) -> Self {
        assert!(
            cell <= 0.5 * radius,
            "crater cells must be at most half the planet radius"
        );
        CraterLevel {
            seed,
            freq: radius / cell,
            exist,
            radius: (0.08, MAX_RADIUS),
            depth_per_cell: depth_ratio * cell,
            depth_cap,
        }
    }

    /// The deepest this level can go (metres, positive) and the highest its rims can rise.
    pub fn extremes(&self) -> (f64, f64) {
        let d = (self.depth_per_cell * self.radius.1).min(self.depth_cap);
        (d, RIM_HEIGHT * d)
    }

    /// Relief (metres) of this level along unit direction `dir`.
    pub fn height(&self, dir: DVec3) -> f64 {
        let q = dir * self.freq;
        // Per axis, the two cells whose points can be within half a cell of q: the lower one and
        // its successor, with their pre-multiplied hash terms.
        let axis = |x: f64, mul: u64| -> (f64, [u64; 2]) {
            let mut i = x as i64;
            i -= i64::from((i as f64) > x);
            if x - (i as f64) < 0.5 {
                i -= 1;
            }
            let h = (i as u64).wrapping_mul(mul);
            (i as f64, [h, h.wrapping_add(mul)])
        };
        let (lx, hx) = axis(q.x, 0x9E37_79B9_7F4A_7C15);
        let (ly, hy) = axis(q.y, 0xC2B2_AE3D_27D4_EB4F);
        let (lz, hz) = axis(q.z, 0x1656_67B1_9E37_79F9);
        let mut sum = 0.0;
        for k in 0..8usize {
            let (a, b, c) = (k & 1, (k >> 1) & 1, k >> 2);
            let h = mix64(hx[a] ^ hy[b] ^ hz[c] ^ self.seed);
            if unit_f64(h) >= self.exist {
                continue;
            }
            let j = mix64(h);
            let bits = |s: u32| ((j >> s) & 0x1F_FFFF) as f64 * (1.0 / (1u64 << 21) as f64);
            let point = DVec3::new(
                lx + a as f64 + bits(0),
                ly + b as f64 + bits(21),
                lz + c as f64 + bits(42),
            );
            // A crater that reaches q has its point within half a cell of q (module docs).
            if (q - point).length_squared() > 0.25 {
                continue;
            }
            let len = point.length();
            if (len - self.freq).abs() > DELTA {
                continue;
            }
            let centre = point * (self.freq / len);
            let t = f64::from((h & 0xFFFF) as u16) / 65535.0;
            let radius = self.radius.0 + (self.radius.1 - self.radius.0) * t;
            let d2 = (q - centre).length_squared();
            let outer = RIM_OUTER * radius;
            if d2 >= outer * outer {
                continue;
            }
            let x = d2.sqrt() / radius;
            let depth = (self.depth_per_cell * radius).min(self.depth_cap);
            let rim = RIM_HEIGHT * depth;
            sum += if x <= 1.0 {
                (depth * (x * x - 1.0)).max(-FLOOR * depth) + rim
            } else {
                rim * (1.0 - smoothstep(1.0, RIM_OUTER, x))
            };
        }
        let (d, r) = self.extremes();
        sum.clamp(-d, r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::testing::sphere_dirs;

    #[test]
    fn craters_are_bounded_continuous_and_present() {
        let level = CraterLevel::new(7, 2000.0, 200.0, 0.7, 0.25, 30.0);
        let (deep, high) = level.extremes();
        let mut bowls = 0;
        let mut rims = 0;
        for d in sphere_dirs(20_000) {
            let h = level.height(d);
            assert!(h >= -deep && h <= high);
            if h < 0.0 {
                bowls += 1;
            }
            if h > 0.5 * high {
                rims += 1;
            }
            let e = (d + DVec3::new(1e-7, -2e-7, 1e-7)).normalize();
            assert!((level.height(e) - h).abs() < 1e-2, "crater relief jumps");
        }
        assert!(bowls > 200 && rims > 200, "bowls {bowls}, rims {rims}");
    }

    #[test]
    fn seeds_move_craters() {
        let a = CraterLevel::new(1, 2000.0, 200.0, 0.7, 0.25, 30.0);
        let b = CraterLevel::new(2, 2000.0, 200.0, 0.7, 0.25, 30.0);
        let differ = sphere_dirs(2000)
            .into_iter()
            .filter(|d| a.height(*d) != b.height(*d))
            .count();
        assert!(differ > 200, "{differ}");
    }
}
