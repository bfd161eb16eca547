//! The moon preset: grey cratered highlands, dark smooth maria, lava tubes under the maria, no sea.
//!
//! | feature    | height (fractions of `T`, around `d_b + 0.62 T`) | horizontal scale |
//! |------------|-----------------------------------------------|------------------|
//! | highlands  | +-0.05 T (rolling), 0.3 of that in maria       | 0.25 R down to 2 tiles |
//! | maria      | -0.08 T, flooding the large craters            | 1.3 cells/radian |
//! | craters    | bowls up to 0.1 T deep with rims, several levels (each smaller level at most 0.65 times as deep) | cells from 0.5 R down to about 8 tiles |
//! | lava tubes | band from 3 `l_d` to 0.1 T under the maria, skylights where the roof opens | tubes about 2.5 tiles wide |

use super::craters::CraterLevel;
use super::features::{carved_voxels, smoothstep, CaveBand, ColumnModel, Scales, Spaghetti};
use super::material::{
    column_terrain, CaveRock, Cover, Feature, Ground, GroundModel, MaterialRules, SteepRock, VertexColumns,
};
use super::shading::Look;
use super::{PresetKind, Terrain};
use crate::noise::{derive_seed, gradient3, Fbm, FbmParams};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`super::Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["regolith", "mare", "rock", "cave"];
const REGOLITH: u8 = 0;
const MARE: u8 = 1;
const ROCK: u8 = 2;
const CAVE: u8 = 3;

/// Mean surface, as a fraction of the shell above `d_b`.
const DATUM: f64 = 0.62;
/// Highland roughness (fraction of `T`, the fBm is doubled).
const HIGHLANDS: f64 = 0.05;
/// Depth of the maria (fraction of `T`).
const MARE_DEPTH: f64 = 0.08;
/// Crater levels: the largest cell (fraction of the radius), the ratio between levels, the
/// smallest cell (tiles), the most levels.
const CRATER_LARGEST: f64 = 0.5;
const CRATER_RATIO: f64 = 1.8;
const CRATER_SMALLEST: f64 = 6.0;
const CRATER_LEVELS: usize = 7;
/// Bowl depth over crater radius, and the deepest a crater of the largest level goes (fraction of
/// `T`); each smaller level may go `CRATER_CAP_DECAY` times as deep, so all levels together stay
/// within 0.29 T however many a large planet has.
const CRATER_DEPTH_RATIO: f64 = 0.25;
const CRATER_DEPTH_CAP: f64 = 0.1;
const CRATER_CAP_DECAY: f64 = 0.65;
/// Lava tubes: noise lengths (tiles across, `l_d` deep), threshold, band depth (fraction of `T`),
/// roof (`l_d`).
const TUBE_ACROSS: f64 = 14.0;
const TUBE_DEEP: f64 = 12.0;
const TUBE_THRESHOLD: f64 = 0.09;
const TUBE_BAND: f64 = 0.10;
const TUBE_ROOF: f64 = 3.0;

/// What a moon column computes once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MoonColumn {
    h: f64,
    mare: f64,
    band: CaveBand,
}

/// The moon density model.
pub(crate) struct MoonModel {
    s: Scales,
    datum: f64,
    highlands: Fbm,
    maria: Fbm,
    craters: Vec<CraterLevel>,
    skylight_seed: u64,
    skylight_freq: f64,
    tubes: Spaghetti,
    bounds: (f64, f64),
}

impl MoonModel {
    pub(crate) fn new(seed: u64, layout: &Layout) -> Self {
        let s = Scales::new(layout);
        let t = s.thickness;
        let datum = s.shell(DATUM);
        let mut craters = Vec::new();
        let mut cell = CRATER_LARGEST * s.radius;
        while cell >= CRATER_SMALLEST * s.tile && craters.len() < CRATER_LEVELS {
            let exist = 0.6 + 0.1 * craters.len() as f64;
            craters.push(CraterLevel::new(
                derive_seed(seed, 40 + craters.len() as u64),
                s.radius,
                cell,
                exist.min(0.9),
                CRATER_DEPTH_RATIO,
                CRATER_DEPTH_CAP * t * CRATER_CAP_DECAY.powi(craters.len() as i32),
            ));
            cell /= CRATER_RATIO;
        }
        let tubes = Spaghetti::new(
            (derive_seed(seed, 50), derive_seed(seed, 51)),
            TUBE_ACROSS * s.tile,
            (TUBE_DEEP * s.l_d).min(0.25 * t),
            datum,
            TUBE_THRESHOLD,
            8.0,
            t,
        );
        let deepest: f64 = craters.iter().map(|c| c.extremes().0).sum();
        let highest: f64 = craters.iter().map(|c| c.extremes().1).sum();
        let lowest_ground = datum - 2.0 * HIGHLANDS * t - MARE_DEPTH * t - deepest;
        let lo = lowest_ground - TUBE_BAND * t - tubes.reach_below();
        let hi = datum + 2.0 * HIGHLANDS * t + highest;
        let margin = 1e-6 * t;
        MoonModel {
            s,
            datum,
            highlands: Fbm::new(
                derive_seed(seed, 52),
                FbmParams::new(4.0, s.octaves(0.25 * s.radius, 2.0 * s.tile, 12)),
            ),
            maria: Fbm::new(derive_seed(seed, 53), FbmParams::new(1.3, 3)),
            craters,
            skylight_seed: derive_seed(seed, 54),
            skylight_freq: s.freq(20.0 * s.tile),
            tubes,
            bounds: (lo - margin, hi + margin),
        }
    }
}

impl ColumnModel for MoonModel {
    type Column = MoonColumn;

    fn column(&self, dir: DVec3) -> MoonColumn {
        let t = self.s.thickness;
        let mare = smoothstep(0.0, 0.1, self.maria.sample(dir));
        let rough = 2.0 * HIGHLANDS * t * self.highlands.sample(dir) * (1.0 - 0.7 * mare);
        let mut h = self.datum + rough - MARE_DEPTH * t * mare;
        for (i, level) in self.craters.iter().enumerate() {
            // The maria flooded the two largest crater levels.
            let keep = if i < 2 { 1.0 - 0.85 * mare } else { 1.0 };
            h += keep * level.height(dir);
        }
        // Lava tubes under the maria; skylights where the roof rises above the surface.
        let (band_gate, roof) = if mare > 0.0 {
            let sky = smoothstep(0.25, 0.4, gradient3(dir * self.skylight_freq, self.skylight_seed));
            (mare, self.s.l_d * (TUBE_ROOF - 5.0 * sky))
        } else {
            (0.0, self.s.l_d * TUBE_ROOF)
        };
        let band = self.tubes.band(h - TUBE_BAND * t, h - roof, band_gate);
        MoonColumn { h, mare, band }
    }

    #[inline]
    fn voxel(&self, col: &MoonColumn, dir: DVec3, _p: DVec3, r: f64) -> f64 {
        self.tubes.carve(col.h - r, &col.band, dir, r)
    }

    /// [`voxel`](Self::voxel) at every voxel of the columns, the same bits
    /// ([`carved_voxels`], no overhangs).
    fn voxels(&self, cols: &[MoonColumn], dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        carved_voxels(None, &self.tubes, cols, |c| (c.h, 0.0, c.band), dirs, radii, out);
    }

    fn ground_radius(&self, col: &MoonColumn) -> f64 {
        col.h
    }

    fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

impl GroundModel for MoonModel {
    fn scales(&self) -> &Scales {
        &self.s
    }

    fn datum(&self) -> f64 {
        self.datum
    }

    /// The maria are the feature field; no overhangs, no roughness.
    fn ground(col: &MoonColumn) -> Ground {
        Ground {
            h: col.h,
            amp: 0.0,
            feature: col.mare,
            rough: 0.0,
        }
    }
}

/// The moon's greys: light regolith, dark maria, rock, dark tube walls.
const LOOK: Look = Look {
    names: MATERIALS,
    colors: &[
        [[172, 170, 164], [140, 139, 134]], // regolith
        [[84, 84, 88], [106, 105, 104]],    // mare
        [[118, 116, 112], [150, 148, 142]], // rock
        [[48, 48, 50], [70, 69, 68]],       // cave
    ],
    mix_salt: 60,
    mix_tiles: 1.5,
    blend_colors: [[0.52, 0.52, 0.52], [0.36, 0.36, 0.40]],
};

/// Where the moon's materials lie: tube walls under the surface, rock on steep crater walls,
/// the maria, regolith elsewhere.
const RULES: MaterialRules = MaterialRules {
    cave: CaveRock {
        id: CAVE,
        depth: 2.0,
        margin: 1.0,
    },
    cap: None,
    steep: SteepRock {
        id: ROCK,
        up_below: 0.75,
        rough_above: None,
    },
    feature: Some(Feature {
        id: MARE,
        above: 0.5,
        jitter: 0.15,
    }),
    cover: Cover::Bare(REGOLITH),
    jitter_salt: 61,
    jitter_tiles: 3.0,
    height_jitter: 0.0,
    vertices: VertexColumns::Own,
};

/// Builds the moon terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    let model = Arc::new(MoonModel::new(seed, layout));
    column_terrain(PresetKind::Moon, seed, model, None, &LOOK, RULES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::features::ColumnDensity;
    use crate::presets::testing::*;
    use crate::Density;

    #[test]
    fn no_sea_and_surface_within_bounds() {
        let layout = Layout::default();
        let t = build(4, &layout);
        assert!(t.sea_radius.is_none());
        assert_eq!(t.spec.preset_kind(), Some(PresetKind::Moon));
        check_surface_within_bounds(&t, &layout);
    }

    #[test]
    fn has_craters_maria_and_tubes() {
        let layout = Layout::default();
        let m = MoonModel::new(4, &layout);
        assert!(m.craters.len() >= 3, "crater levels: {}", m.craters.len());
        let dirs = sphere_dirs(20_000);
        let mare = dirs.iter().filter(|d| m.column(**d).mare > 0.5).count() as f64 / dirs.len() as f64;
        assert!((0.05..0.6).contains(&mare), "mare fraction {mare}");
        let bowls = dirs
            .iter()
            .filter(|d| m.craters.iter().any(|c| c.height(**d) < 0.0))
            .count();
        assert!(bowls > dirs.len() / 10, "crater bowls: {bowls}");
        let d = ColumnDensity(Arc::new(m));
        let m = &*d.0;
        let mut tube_air = 0;
        for dir in dirs.iter().step_by(4) {
            let col = m.column(*dir);
            let mut r = col.h - TUBE_BAND * m.s.thickness;
            while r < col.h - 2.0 * m.s.l_d {
                if d.density(*dir * r) <= 0.0 {
                    tube_air += 1;
                    assert!(col.mare > 0.0, "lava tube outside the maria");
                }
                r += 1.0;
            }
        }
        assert!(tube_air > 20, "lava tube samples: {tube_air}");
    }

    #[test]
    fn batch_matches_points_and_seeds_differ() {
        let layout = Layout::default();
        let m = MoonModel::new(9, &layout);
        let d = dirs_with(&m, |c| c.mare > 0.5);
        let t = build(9, &layout);
        check_batch_matches_points(&*t.density, &patch(d, m.s.tile, 12, m.datum - 60.0, m.s.l_d, 30), 1e-3);
        check_seeds_differ(&*t.density, &*build(10, &layout).density, &layout);
    }

    #[test]
    fn shader_greys() {
        let layout = Layout::default();
        let t = build(2, &layout);
        let m = MoonModel::new(2, &layout);
        let mare = dirs_with(&m, |c| c.mare > 0.99);
        let high = dirs_with(&m, |c| c.mare == 0.0);
        let a = t.shader.shade(mare * m.column(mare).h, mare);
        let b = t.shader.shade(high * m.column(high).h, high);
        assert_eq!(MATERIALS[usize::from(a.material)], "mare");
        assert_eq!(MATERIALS[usize::from(b.material)], "regolith");
        let lum = |c: [u8; 4]| u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]);
        assert!(lum(a.color) < lum(b.color), "maria are darker");
        for c in [a.color, b.color] {
            assert!(c[0].abs_diff(c[2]) < 12, "grey: {c:?}");
        }
    }

    fn dirs_with(m: &MoonModel, f: impl Fn(&MoonColumn) -> bool) -> DVec3 {
        sphere_dirs(5000)
            .into_iter()
            .find(|d| f(&m.column(*d)))
            .expect("such a place")
    }
}
