//! The mars preset: rust-red plains and highlands, canyons, a couple of large shield volcanoes,
//! dune fields, polar ice caps and caves, no sea.
//!
//! | feature      | height (fractions of `T`, around `d_b + 0.5 T`) | horizontal scale |
//! |--------------|------------------------------------------------|------------------|
//! | plains/highlands | +-0.05 T                                     | 1.5 cells/radian |
//! | hills        | +-0.015 T                                       | 0.08 R down to 2 tiles |
//! | canyons      | down to -0.16 T (inverted ridged noise, in canyon regions) | 0.12 R |
//! | volcanoes    | up to +0.28 T, with a caldera; they replace the terrain under them | 0.22-0.34 R in radius |
//! | dunes        | up to 1.2 `l_d`, in the lowlands               | crests 4 tiles apart |
//! | polar caps   | an ice dome of 0.03 T, white                   | poleward of about 74 degrees |
//! | caves        | band from 2.5 `l_d` to 0.1 T under the surface, mouths in canyon walls | tubes about 2 tiles wide |
//! | overhangs    | displacement up to 3 `l_d` on canyon walls      | 3 tiles across, 3 `l_d` deep |

use super::features::{carved_voxels, smoothstep, CaveBand, ColumnModel, Overhang, Scales, Spaghetti};
use super::material::{
    column_terrain, Cap, CapLine, CaveRock, Cover, Feature, Ground, GroundModel, MaterialRules, SteepRock,
    VertexColumns,
};
use super::shading::Look;
use super::{PresetKind, Terrain};
use crate::noise::{derive_seed, gradient3, mix64, unit_f64, Fbm, FbmParams, Ridged, RidgedParams};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`super::Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["dust", "rock", "sand", "ice", "cave"];
const DUST: u8 = 0;
const ROCK: u8 = 1;
const SAND: u8 = 2;
const ICE: u8 = 3;
const CAVE: u8 = 4;

/// Mean surface, as a fraction of the shell above `d_b`.
const DATUM: f64 = 0.5;
/// Terrain and hill amplitudes (fractions of `T`; the fBm values are doubled).
const TERRAIN: f64 = 0.05;
const HILLS: f64 = 0.015;
/// Canyon depth (fraction of `T`) and ridge wavelength (fraction of the radius).
const CANYON_DEPTH: f64 = 0.16;
const CANYON_WAVELENGTH: f64 = 0.12;
/// Volcanoes: count, height (fraction of `T`), caldera depth (fraction of `T`).
const VOLCANOES: usize = 2;
const VOLCANO_HEIGHT: f64 = 0.28;
const CALDERA_DEPTH: f64 = 0.06;
/// Dunes: height (`l_d`) and crest spacing (tiles).
const DUNE_HEIGHT: f64 = 1.2;
const DUNE_SPACING: f64 = 4.0;
/// Polar ice dome (fraction of `T`) and where it starts (`|sin latitude|`).
const ICE_DOME: f64 = 0.03;
const ICE_START: f64 = 0.96;
/// Caves: noise lengths (tiles across, `l_d` deep), threshold, band depth (fraction of `T`), roof.
const CAVE_ACROSS: f64 = 12.0;
const CAVE_DEEP: f64 = 14.0;
const CAVE_THRESHOLD: f64 = 0.1;
const CAVE_BAND: f64 = 0.10;
const CAVE_ROOF: f64 = 2.5;
/// Overhangs on canyon walls: amplitude (`l_d`, at most 4% of `T`).
const OVERHANG_AMPLITUDE: f64 = 3.0;

/// One volcano: centre direction, base radius (chord length on the unit sphere), height.
#[derive(Clone, Copy, Debug)]
struct Volcano {
    centre: DVec3,
    reach: f64,
    height: f64,
}

/// What a Mars column computes once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MarsColumn {
    h: f64,
    amp: f64,
    band: CaveBand,
    canyon: f64,
    dunes: f64,
}

/// The Mars density model.
pub(crate) struct MarsModel {
    s: Scales,
    datum: f64,
    terrain: Fbm,
    hills: Fbm,
    canyon_region: Fbm,
    canyons: Ridged,
    volcanoes: [Volcano; VOLCANOES],
    wind: DVec3,
    dune_freq: f64,
    warp_seed: u64,
    warp_freq: f64,
    region_seed: u64,
    region_freq: f64,
    caves: Spaghetti,
    overhang: Overhang,
    overhang_amp: f64,
    bounds: (f64, f64),
}

/// A random unit vector from `seed` (uniform on the sphere).
fn random_dir(seed: u64) -> DVec3 {
    let y = unit_f64(mix64(seed ^ 1)) * 2.0 - 1.0;
    let a = unit_f64(mix64(seed ^ 2)) * std::f64::consts::TAU;
    let rho = (1.0 - y * y).sqrt();
    DVec3::new(rho * a.cos(), y, rho * a.sin())
}

impl MarsModel {
    pub(crate) fn new(seed: u64, layout: &Layout) -> Self {
        let s = Scales::new(layout);
        let t = s.thickness;
        let datum = s.shell(DATUM);
        let volcanoes = std::array::from_fn(|i| {
            let vs = derive_seed(seed, 70 + i as u64);
            // Keep volcanoes off the polar caps.
            let mut centre = random_dir(vs);
            centre.y *= 0.6;
            Volcano {
                centre: centre.normalize(),
                reach: 0.22 + 0.12 * unit_f64(mix64(vs ^ 3)),
                height: VOLCANO_HEIGHT * t * (0.75 + 0.25 * unit_f64(mix64(vs ^ 4))),
            }
        });
        let caves = Spaghetti::new(
            (derive_seed(seed, 80), derive_seed(seed, 81)),
            CAVE_ACROSS * s.tile,
            (CAVE_DEEP * s.l_d).min(0.25 * t),
            datum,
            CAVE_THRESHOLD,
            8.0,
            t,
        );
        let overhang_amp = (OVERHANG_AMPLITUDE * s.l_d).min(0.04 * t);
        // Bounds. The volcano profile s in [0, 1] scales the terrain by (1 - s) and adds s H, so
        // together they stay within [min(terrain), max(terrain max, H)]; canyons only cut, the ice
        // dome and dunes only add.
        let terrain_max = 2.0 * (TERRAIN + HILLS) * t;
        let dune_max = DUNE_HEIGHT * s.l_d;
        let highest = datum + terrain_max.max(VOLCANO_HEIGHT * t) + dune_max + ICE_DOME * t + overhang_amp;
        // (The volcano term is a maximum starting from 0, so calderas never cut below the ground.)
        let lowest_ground = datum - terrain_max - CANYON_DEPTH * t - overhang_amp;
        let lowest = lowest_ground - CAVE_BAND * t - caves.reach_below();
        let margin = 1e-6 * t;
        MarsModel {
            s,
            datum,
            terrain: Fbm::new(derive_seed(seed, 82), FbmParams::new(1.5, 4)),
            hills: Fbm::new(
                derive_seed(seed, 83),
                FbmParams::new(1.0 / 0.08, s.octaves(0.08 * s.radius, 2.0 * s.tile, 12)),
            ),
            canyon_region: Fbm::new(derive_seed(seed, 84), FbmParams::new(2.0, 2)),
            // Two octaves with a low gain keep the crests long and continuous.
            canyons: Ridged::new(
                derive_seed(seed, 85),
                RidgedParams {
                    gain: 0.3,
                    ..RidgedParams::new(1.0 / CANYON_WAVELENGTH, 2)
                },
            ),
            volcanoes,
            wind: random_dir(derive_seed(seed, 86)),
            dune_freq: s.radius / (DUNE_SPACING * s.tile),
            warp_seed: derive_seed(seed, 87),
            warp_freq: s.freq(15.0 * s.tile),
            region_seed: derive_seed(seed, 88),
            region_freq: s.freq(40.0 * s.tile),
            caves,
            overhang: Overhang::new(derive_seed(seed, 89), 3.0 * s.tile, 3.0 * s.l_d, datum, s.l_d),
            overhang_amp,
            bounds: (lowest - margin, highest + margin),
        }
    }

    /// The volcanoes at `dir`: the largest cone share in `[0, 1]` and the highest cone there (with
    /// the caldera cut into the summit). Both are maxima of continuous functions, so the terrain
    /// stays continuous where cones overlap, and the height is at most the tallest volcano's
    /// height times the share.
    fn volcano(&self, dir: DVec3) -> (f64, f64) {
        let (mut share, mut height) = (0.0f64, 0.0f64);
        for v in &self.volcanoes {
            let x = (dir - v.centre).length() / v.reach;
            if x >= 1.0 {
                continue;
            }
            let cone = (1.0 - x).powf(1.6);
            let caldera = CALDERA_DEPTH * self.s.thickness * (1.0 - smoothstep(0.05, 0.09, x));
            share = share.max(cone);
            height = height.max(v.height * cone - caldera);
        }
        (share, height)
    }
}

impl ColumnModel for MarsModel {
    type Column = MarsColumn;

    fn column(&self, dir: DVec3) -> MarsColumn {
        let t = self.s.thickness;
        let l_d = self.s.l_d;
        let tv = self.terrain.sample(dir);
        let mut ground = 2.0 * TERRAIN * t * tv + 2.0 * HILLS * t * self.hills.sample(dir);
        // Canyons: the crests of ridged noise, inverted, inside canyon regions (the ridged noise
        // is skipped where the region factor is exactly zero).
        let region = smoothstep(0.0, 0.12, self.canyon_region.sample(dir));
        let canyon = if region > 0.0 {
            region * smoothstep(0.80, 0.93, self.canyons.sample(dir))
        } else {
            0.0
        };
        ground -= CANYON_DEPTH * t * canyon;
        // Dunes in the lowlands, away from canyons.
        let dunes = smoothstep(-0.12, -0.2, tv) * (1.0 - canyon);
        if dunes > 0.0 {
            let phase = dir.dot(self.wind) * self.dune_freq + 0.8 * gradient3(dir * self.warp_freq, self.warp_seed);
            let crest = 1.0 - (std::f64::consts::PI * phase).sin().abs();
            ground += DUNE_HEIGHT * l_d * dunes * crest;
        }
        // Volcanoes replace the terrain under them.
        let (share, cone) = self.volcano(dir);
        let mut h = self.datum + ground * (1.0 - share) + cone;
        h += ICE_DOME * t * smoothstep(ICE_START - 0.06, ICE_START + 0.06, dir.y.abs());
        // Overhangs on canyon walls (where the canyon factor is half-way).
        let wall = 4.0 * canyon * (1.0 - canyon);
        let amp = self.overhang_amp * wall;
        // Caves in regions; their mouths open in canyon walls.
        let reg = gradient3(dir * self.region_freq, self.region_seed);
        let gate = smoothstep(-0.2, 0.0, reg).max(wall);
        let roof = l_d * (CAVE_ROOF - 5.0 * smoothstep(0.3, 0.6, wall));
        let band = self.caves.band(h - CAVE_BAND * t, h - roof, gate);
        MarsColumn {
            h,
            amp,
            band,
            canyon,
            dunes,
        }
    }

    #[inline]
    fn voxel(&self, col: &MarsColumn, dir: DVec3, _p: DVec3, r: f64) -> f64 {
        let d0 = self.overhang.displace(col.h, col.amp, dir, r);
        self.caves.carve(d0, &col.band, dir, r)
    }

    /// [`voxel`](Self::voxel) at every voxel of the columns, the same bits
    /// ([`carved_voxels`]).
    fn voxels(&self, cols: &[MarsColumn], dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        carved_voxels(
            Some(&self.overhang),
            &self.caves,
            cols,
            |c| (c.h, c.amp, c.band),
            dirs,
            radii,
            out,
        );
    }

    fn ground_radius(&self, col: &MarsColumn) -> f64 {
        col.h
    }

    fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

impl GroundModel for MarsModel {
    fn scales(&self) -> &Scales {
        &self.s
    }

    fn datum(&self) -> f64 {
        self.datum
    }

    /// The dunes are the feature field, the canyons the roughness.
    fn ground(col: &MarsColumn) -> Ground {
        Ground {
            h: col.h,
            amp: col.amp,
            feature: col.dunes,
            rough: col.canyon,
        }
    }
}

/// Mars's colours: rust dust, darker rock, dark dune sand, white ice, cave rock.
const LOOK: Look = Look {
    names: MATERIALS,
    colors: &[
        [[196, 108, 66], [168, 86, 52]],    // dust
        [[118, 70, 52], [150, 94, 66]],     // rock
        [[108, 62, 46], [132, 78, 54]],     // sand
        [[238, 238, 242], [212, 216, 226]], // ice
        [[60, 38, 30], [86, 56, 42]],       // cave
    ],
    mix_salt: 90,
    mix_tiles: 1.5,
    blend_colors: [[0.62, 0.27, 0.12], [0.44, 0.20, 0.13]],
};

/// Where Mars's materials lie: cave rock under the surface, polar ice on flat ground, rock on
/// slopes and canyon floors, sand on the dune fields, dust elsewhere.
const RULES: MaterialRules = MaterialRules {
    cave: CaveRock {
        id: CAVE,
        depth: 2.0,
        margin: 1.0,
    },
    cap: Some(Cap {
        id: ICE,
        flat: 0.5,
        line: CapLine::Polar {
            from: ICE_START - 0.03,
            jitter: 0.03,
        },
    }),
    steep: SteepRock {
        id: ROCK,
        up_below: 0.7,
        rough_above: Some(0.6),
    },
    feature: Some(Feature {
        id: SAND,
        above: 0.5,
        jitter: 0.3,
    }),
    cover: Cover::Bare(DUST),
    jitter_salt: 91,
    jitter_tiles: 3.0,
    height_jitter: 0.0,
    vertices: VertexColumns::Own,
};

/// Builds the Mars terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    let model = Arc::new(MarsModel::new(seed, layout));
    column_terrain(PresetKind::Mars, seed, model, None, &LOOK, RULES)
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
        assert_eq!(t.spec.preset_kind(), Some(PresetKind::Mars));
        check_surface_within_bounds(&t, &layout);
    }

    #[test]
    fn has_canyons_volcanoes_dunes_and_caves() {
        let layout = Layout::default();
        let m = MarsModel::new(4, &layout);
        let t = m.s.thickness;
        let dirs = sphere_dirs(20_000);
        let cols: Vec<MarsColumn> = dirs.iter().map(|d| m.column(*d)).collect();
        assert!(cols.iter().filter(|c| c.canyon > 0.8).count() > 50, "canyons");
        assert!(cols.iter().filter(|c| c.dunes > 0.8).count() > 100, "dunes");
        let top = cols.iter().map(|c| c.h).fold(f64::MIN, f64::max);
        assert!(top - m.datum > 0.18 * t, "volcanoes rise {} T", (top - m.datum) / t);
        let density = ColumnDensity(Arc::new(m));
        let m = &*density.0;
        let mut cave_air = 0;
        for (d, c) in dirs.iter().zip(&cols).step_by(5) {
            let mut r = c.h - CAVE_BAND * t;
            while r < c.h - 3.0 * m.s.l_d - c.amp {
                if density.density(*d * r) <= 0.0 {
                    cave_air += 1;
                }
                r += 1.0;
            }
        }
        assert!(cave_air > 20, "cave samples {cave_air}");
    }

    #[test]
    fn batch_matches_points_and_seeds_differ() {
        let layout = Layout::default();
        let m = MarsModel::new(9, &layout);
        let d = sphere_dirs(5000)
            .into_iter()
            .find(|d| m.column(*d).canyon > 0.5)
            .expect("a canyon");
        let t = build(9, &layout);
        check_batch_matches_points(
            &*t.density,
            &patch(d, m.s.tile, 12, m.column(d).h - 60.0, m.s.l_d, 30),
            1e-3,
        );
        check_seeds_differ(&*t.density, &*build(10, &layout).density, &layout);
    }

    #[test]
    fn shader_has_polar_ice_and_red_dust() {
        let layout = Layout::default();
        let t = build(2, &layout);
        let m = MarsModel::new(2, &layout);
        let pole = DVec3::new(0.01, 1.0, 0.02).normalize();
        let ice = t.shader.shade(pole * m.column(pole).h, pole);
        assert_eq!(MATERIALS[usize::from(ice.material)], "ice");
        let plain = sphere_dirs(5000)
            .into_iter()
            .find(|d| {
                let c = m.column(*d);
                d.y.abs() < 0.5 && c.dunes == 0.0 && c.canyon == 0.0
            })
            .expect("a plain");
        let dust = t.shader.shade(plain * m.column(plain).h, plain);
        assert_eq!(MATERIALS[usize::from(dust.material)], "dust");
        assert!(dust.color[0] > 2 * dust.color[2], "rust red: {:?}", dust.color);
    }
}
