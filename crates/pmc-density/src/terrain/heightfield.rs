//! Volumetric terrain over any height field (an elevation model): the height field as a signed
//! distance, with caves and rock bumps under and on its land, meshed like every other terrain.

use super::spec::TerrainSpec;
use crate::noise::{derive_seed, gradient3};
use crate::presets::features::{radial, smoothstep, ColumnDensity, ColumnModel, Scales, Spaghetti, Stretch};
use crate::presets::shading::{Look, MaterialMap};
use crate::presets::Terrain;
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Heights over the sphere: what a volumetric height-field terrain is built from.
///
/// Contract: [`height`](Self::height) is a pure, thread-safe function of the direction's bits
/// (every chunk that samples a voxel gets the same value), finite for every unit vector, and
/// within [`bounds`](Self::bounds).
pub trait HeightField: Send + Sync {
    /// The height above the datum (the sea level), metres, along the unit direction `dir`.
    fn height(&self, dir: DVec3) -> f64;
    /// The lowest and highest heights [`height`](Self::height) can return, metres.
    fn bounds(&self) -> (f64, f64);
}

/// Material names of height-field terrains, indexed by [`crate::presets::Shade::material`].
pub const HEIGHTFIELD_MATERIALS: &[&str] = &[
    "deep seabed",
    "shelf",
    "sand",
    "grass",
    "forest",
    "rock",
    "snow",
    "cave",
];
const DEEP: u8 = 0;
const SHELF: u8 = 1;
const SAND: u8 = 2;
const GRASS: u8 = 3;
const FOREST: u8 = 4;
const ROCK: u8 = 5;
const SNOW: u8 = 6;
const CAVE: u8 = 7;

/// Depth (true-scale metres) above which the seabed is shelf, below which it is deep ocean.
pub const SHELF_DEPTH: f64 = 200.0;
/// Snow line at the equator (true-scale metres), falling towards the poles as `1 - sin^4(lat)`
/// (about 5 200 m at 30 degrees, 2 400 m at 60, sea level at the poles).
const SNOW_LINE: f64 = 5500.0;
/// Tree line, as a fraction of the snow line.
const TREE_LINE: f64 = 0.7;

/// Caves: tube lengths (tiles across, `l_d` deep), threshold, band depth under the surface
/// (`l_d`, at most a fraction of `T`), roof (`l_d`), how far above the surface an open roof
/// goes (`l_d`), the region size (tiles) and how fast the field closes outside its band.
const CAVE_ACROSS: f64 = 26.0;
const CAVE_DEEP: f64 = 24.0;
const CAVE_THRESHOLD: f64 = 0.1;
const CAVE_BAND: f64 = 56.0;
const CAVE_BAND_CAP: f64 = 0.08;
const CAVE_ROOF: f64 = 4.0;
const CAVE_MOUTH: f64 = 3.0;
const CAVE_REGION: f64 = 300.0;
const CAVE_SLOPE: f64 = 8.0;
/// Rock bumps on land: amplitude (`l_d`, at most a fraction of `T`), lengths (tiles, `l_d`).
const ROCK_AMP: f64 = 0.8;
const ROCK_CAP: f64 = 0.005;
const ROCK_ACROSS: f64 = 4.0;
const ROCK_DEEP: f64 = 3.0;

/// Why a height field does not fit a layout.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReliefError {
    /// The relief (scaled to the layout) is taller than the layout's shell can hold around the
    /// sea level. Fix: choose a layout with a thicker shell (more depth chunks or deeper voxels).
    #[error(
        "the relief from {low:.0} m to {high:.0} m (scaled to this layout) does not fit in the shell of {thickness:.0} m around the sea level; choose a layout with a thicker shell"
    )]
    TooTall {
        /// Lowest height, metres, scaled.
        low: f64,
        /// Highest height, metres, scaled.
        high: f64,
        /// Shell thickness of the layout, metres.
        thickness: f64,
    },
    /// The height field's bounds are not finite numbers with low <= high.
    #[error("the height field's bounds ({0}, {1}) are not finite numbers in order")]
    BadBounds(f64, f64),
}

/// The per-planet model behind the density and the shader.
struct Model {
    field: Arc<dyn HeightField>,
    s: Scales,
    sea: f64,
    vert: f64,
    caves: Spaghetti,
    cave_band: f64,
    region_seed: u64,
    region_freq: f64,
    rock: Stretch,
    rock_seed: u64,
    rock_amp: f64,
    bounds: (f64, f64),
}

/// A column: its surface radius and the 3D terms that apply there.
struct Column {
    h: f64,
    land: f64,
    cave_gate: f64,
    roof: f64,
}

impl Model {
    fn new(field: Arc<dyn HeightField>, seed: u64, layout: &Layout, vert: f64) -> Result<Model, ReliefError> {
        let (lo, hi) = field.bounds();
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(ReliefError::BadBounds(lo, hi));
        }
        let s = Scales::new(layout);
        let t = s.thickness;
        let l_d = s.l_d;
        let (low, high) = (lo * vert, hi * vert);
        // The sea in the middle of the shell, moved when the relief is lopsided (Mars), keeping
        // a few voxels of room at both ends.
        let room = 8.0 * l_d;
        if high - low + 2.0 * room > t {
            return Err(ReliefError::TooTall {
                low,
                high,
                thickness: t,
            });
        }
        let mid = s.shell(0.5);
        let sea = mid.clamp(s.base + room - low, s.base + t - room - high);
        let cave_deep = (CAVE_DEEP * l_d).min(0.25 * t);
        let caves = Spaghetti::new(
            (derive_seed(seed, 160), derive_seed(seed, 161)),
            CAVE_ACROSS * s.tile,
            cave_deep,
            sea,
            CAVE_THRESHOLD,
            CAVE_SLOPE,
            t,
        );
        let cave_band = (CAVE_BAND * l_d).min(CAVE_BAND_CAP * t);
        let rock_amp = (ROCK_AMP * l_d).min(ROCK_CAP * t);
        let margin = 1e-6 * t;
        let lowest_cave = sea + 2.0 * l_d + caves.floor() / CAVE_SLOPE;
        let bounds = (
            (sea + low - rock_amp).min(lowest_cave) - margin,
            sea + high + rock_amp + CAVE_MOUTH * l_d + margin,
        );
        Ok(Model {
            field,
            sea,
            vert,
            caves,
            cave_band,
            region_seed: derive_seed(seed, 162),
            region_freq: s.freq(CAVE_REGION * s.tile),
            rock: Stretch::new(ROCK_ACROSS * s.tile, (ROCK_DEEP * l_d).min(0.25 * t), sea),
            rock_seed: derive_seed(seed, 163),
            rock_amp,
            bounds,
            s,
        })
    }

    /// The surface radius of the height field alone along `dir`.
    fn surface(&self, dir: DVec3) -> f64 {
        let h = self.field.height(dir);
        // A field breaking its contract must not open the planet: NaN becomes the sea level.
        let h = if h.is_finite() { h } else { 0.0 };
        self.sea + self.vert * h
    }
}

impl ColumnModel for Model {
    type Column = Column;

    fn column(&self, dir: DVec3) -> Column {
        let h = self.surface(dir);
        let l_d = self.s.l_d;
        // Land a couple of voxels above the sea gets rock bumps and, in cave regions, caves.
        let land = smoothstep(self.sea + 0.5 * l_d, self.sea + 3.0 * l_d, h);
        let (cave_gate, roof) = if land > 0.0 {
            let region = gradient3(dir * self.region_freq, self.region_seed);
            let mouth = smoothstep(0.25, 0.45, region);
            (
                land * smoothstep(-0.15, 0.05, region),
                l_d * (CAVE_ROOF - (CAVE_ROOF + CAVE_MOUTH) * mouth),
            )
        } else {
            (0.0, 0.0)
        };
        Column {
            h,
            land,
            cave_gate,
            roof,
        }
    }

    #[inline]
    fn voxel(&self, col: &Column, dir: DVec3, _p: DVec3, r: f64) -> f64 {
        let base = col.h - r;
        let mut d = base;
        let a = self.rock_amp * col.land;
        if a > 0.0 {
            let reach = 1.5 * a + self.s.l_d;
            let z = base.abs();
            if z < reach {
                let w = 1.0 - smoothstep(a, reach, z);
                d = base + a * w * gradient3(self.rock.at(dir, r), self.rock_seed);
            }
        }
        if col.cave_gate > 0.0 {
            let bottom = (self.sea + 2.0 * self.s.l_d).max(col.h - self.cave_band);
            let band = self.caves.band(bottom, col.h - col.roof, col.cave_gate);
            d = self.caves.carve(d, &band, dir, r);
        }
        d
    }

    fn ground_radius(&self, col: &Column) -> f64 {
        col.h
    }

    fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

/// The height-field terrains' colours.
const LOOK: Look = Look {
    names: HEIGHTFIELD_MATERIALS,
    colors: &[
        [[46, 62, 92], [58, 70, 96]],       // deep seabed
        [[96, 120, 118], [120, 128, 110]],  // shelf
        [[222, 204, 150], [206, 178, 120]], // sand
        [[96, 140, 60], [128, 160, 72]],    // grass
        [[36, 80, 38], [56, 98, 46]],       // forest
        [[116, 108, 100], [148, 140, 128]], // rock
        [[244, 246, 252], [216, 224, 238]], // snow
        [[62, 56, 52], [90, 80, 72]],       // cave
    ],
    mix_salt: 170,
    mix_tiles: 3.0,
    blend_colors: [[0.36, 0.48, 0.24], [0.62, 0.52, 0.34]],
};

/// Materials by height above the sea: deep seabed, shelf, sand on the shore, grass and forest,
/// rock on steep slopes and high up, snow above a snow line falling towards the poles, cave rock
/// under the surface.
struct HeightMaterials {
    model: Arc<Model>,
    forest_seed: u64,
    jitter_seed: u64,
}

impl HeightMaterials {
    /// The material at `p` under (or on) the surface of radius `h` above it.
    fn material_under(&self, p: DVec3, normal: DVec3, h: f64) -> u8 {
        let m = &*self.model;
        let (r, dir) = radial(p);
        let l_d = m.s.l_d;
        if r < h - 1.5 * l_d - m.rock_amp {
            return CAVE;
        }
        let z = r - m.sea;
        // True-scale metres for the climate lines.
        let zt = (h - m.sea) / m.vert + 150.0 * gradient3(p / (8.0 * m.s.tile), self.jitter_seed);
        if z < -1.5 * l_d {
            return if (h - m.sea) / m.vert < -SHELF_DEPTH {
                DEEP
            } else {
                SHELF
            };
        }
        let up = normal.dot(dir);
        let y2 = dir.y * dir.y;
        let snow = SNOW_LINE * (1.0 - y2 * y2);
        if zt > snow && up > 0.5 {
            return SNOW;
        }
        if up < 0.68 {
            return ROCK;
        }
        if z < 2.0 * l_d + 4.0 * m.vert {
            return SAND;
        }
        if zt > TREE_LINE * snow {
            return ROCK;
        }
        if gradient3(dir * m.s.freq(40.0 * m.s.tile), self.forest_seed) > 0.1 {
            FOREST
        } else {
            GRASS
        }
    }
}

impl MaterialMap for HeightMaterials {
    fn material(&self, p: DVec3, normal: DVec3) -> u8 {
        self.material_under(p, normal, self.model.surface(radial(p).1))
    }

    /// The surface is `p` itself: no height lookup (a lookup is most of a height-field patch's
    /// cost).
    fn material_on_surface(&self, p: DVec3, normal: DVec3) -> u8 {
        self.material_under(p, normal, p.length())
    }
}

/// A volumetric terrain over `field`: density `sea + v h(dir) - r` (a signed distance), rock
/// bumps on land and caves in a band under the land's surface (opening in places), with the
/// sea level in the middle of the layout's shell (moved up or down when the relief is
/// lopsided). Heights are scaled by `vertical_scale` (1 at true scale; the layout's radius over
/// the body's for a planet shrunk onto a smaller layout). `spec` and `seed` are recorded in the
/// terrain; the seed drives the caves, bumps and colours.
///
/// Errors when the scaled relief does not fit in the shell.
pub fn heightfield_terrain(
    field: Arc<dyn HeightField>,
    spec: TerrainSpec,
    layout: &Layout,
    vertical_scale: f64,
) -> Result<Terrain, ReliefError> {
    let seed = spec.seed();
    let model = Arc::new(Model::new(field, seed, layout, vertical_scale)?);
    let map = HeightMaterials {
        model: model.clone(),
        forest_seed: derive_seed(seed, 171),
        jitter_seed: derive_seed(seed, 172),
    };
    let (sea, tile) = (model.sea, model.s.tile);
    Ok(LOOK.terrain(spec, Arc::new(ColumnDensity(model)), Some(sea), map, tile))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::testing::sphere_dirs;
    use crate::terrain::{DemSpec, Interpolation};

    /// A smooth test field: a continent, a trench and a mountain.
    struct Analytic;
    impl HeightField for Analytic {
        fn height(&self, dir: DVec3) -> f64 {
            3000.0 * (3.0 * dir.x).sin() * (2.0 * dir.z).cos() - 1000.0
        }
        fn bounds(&self) -> (f64, f64) {
            (-4000.0, 2000.0)
        }
    }

    fn spec() -> TerrainSpec {
        TerrainSpec::Dem(DemSpec {
            path: "test.pmcdem".into(),
            digest: "00".into(),
            interpolation: Interpolation::Bicubic,
            seed: 5,
        })
    }

    fn earth_layout() -> Layout {
        crate::presets::layout_for_radius(crate::presets::EARTH_RADIUS).unwrap()
    }

    /// The shades of a fixed field and seed, bit for bit: a change here changes how every
    /// elevation model looks, and must be deliberate.
    #[test]
    fn heightfield_shades_golden() {
        let layout = earth_layout();
        let t = heightfield_terrain(Arc::new(Analytic), spec(), &layout, 1.0).unwrap();
        let got = crate::presets::testing::shade_digest(&t, &layout);
        assert_eq!(got, 0x4166_1241_6f86_3073, "digest now {got:#x}");
    }

    #[test]
    fn the_surface_is_the_height_field_away_from_caves_and_bumps() {
        let layout = earth_layout();
        let t = heightfield_terrain(Arc::new(Analytic), spec(), &layout, 1.0).unwrap();
        let sea = t.sea_radius.unwrap();
        assert_eq!(sea, layout.d_b() + 0.5 * (layout.radius() - layout.d_b()));
        for d in sphere_dirs(200) {
            let h = sea + Analytic.height(d);
            // Far above and below: the radial distance.
            for z in [-500.0, -100.0, 100.0, 500.0] {
                let v = t.density.density(d * (h + z));
                assert!((v + z).abs() < 1e-6 * z.abs().max(1.0), "{v} vs {z}");
            }
            // At sea or under it there are no caves and no bumps: the zero is exactly h.
            if h < sea {
                assert!(t.density.density(d * (h - 0.01)) > 0.0);
                assert!(t.density.density(d * (h + 0.01)) <= 0.0);
            }
        }
    }

    #[test]
    fn bounds_hold_and_batches_match_points() {
        let layout = earth_layout();
        let t = heightfield_terrain(Arc::new(Analytic), spec(), &layout, 1.0).unwrap();
        let (lo, hi) = t.density.radial_bounds().unwrap();
        let dirs = sphere_dirs(64);
        let radii: Vec<f64> = (0..64)
            .map(|k| lo - 10.0 + (hi - lo + 20.0) * k as f64 / 63.0)
            .collect();
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        t.density.sample_shell(&dirs, &radii, &mut out);
        for (k, r) in radii.iter().enumerate() {
            for (i, d) in dirs.iter().enumerate() {
                let v = out[k * dirs.len() + i];
                if *r < lo {
                    assert!(v > 0.0);
                }
                if *r > hi {
                    assert!(v <= 0.0);
                }
                let p = t.density.density(*d * *r) as f32;
                assert!((p - v).abs() <= 1e-3 * p.abs().max(1.0), "{p} vs {v}");
            }
        }
    }

    #[test]
    fn land_has_caves_somewhere() {
        let layout = earth_layout();
        struct Plateau;
        impl HeightField for Plateau {
            fn height(&self, _: DVec3) -> f64 {
                800.0
            }
            fn bounds(&self) -> (f64, f64) {
                (800.0, 800.0)
            }
        }
        let t = heightfield_terrain(Arc::new(Plateau), spec(), &layout, 1.0).unwrap();
        let h = t.sea_radius.unwrap() + 800.0;
        let mut pockets = 0;
        for d in sphere_dirs(3000) {
            if (1..40).any(|k| t.density.density(d * (h - 3.0 * k as f64)) <= 0.0) {
                pockets += 1;
            }
        }
        assert!(pockets > 0, "no cave under 3000 columns of land");
    }

    #[test]
    fn materials_tell_deep_ocean_shelf_and_land_apart() {
        let layout = earth_layout();
        struct Steps;
        impl HeightField for Steps {
            fn height(&self, dir: DVec3) -> f64 {
                if dir.x > 0.5 {
                    -4000.0
                } else if dir.x > 0.0 {
                    -80.0
                } else {
                    300.0
                }
            }
            fn bounds(&self) -> (f64, f64) {
                (-4000.0, 300.0)
            }
        }
        let t = heightfield_terrain(Arc::new(Steps), spec(), &layout, 1.0).unwrap();
        let sea = t.sea_radius.unwrap();
        let at = |d: DVec3, h: f64| t.shader.shade(d * (sea + h), d).material;
        let d = |x: f64| DVec3::new(x, 0.3, (1.0 - x * x - 0.09).sqrt()).normalize();
        assert_eq!(at(d(0.8), -4000.0), DEEP);
        assert_eq!(at(d(0.3), -80.0), SHELF);
        assert!(![DEEP, SHELF, CAVE].contains(&at(d(-0.5), 300.0)));
    }

    /// A point on the surface shades the same whether the shader looks the surface up or is
    /// told it lies there (the height-field planet's shortcut).
    #[test]
    fn shading_on_the_surface_needs_no_lookup() {
        struct Waves;
        impl HeightField for Waves {
            fn height(&self, dir: DVec3) -> f64 {
                3000.0 * (dir.x * 9.0).sin() * (dir.z * 7.0).cos() - 500.0
            }
            fn bounds(&self) -> (f64, f64) {
                (-3500.0, 2500.0)
            }
        }
        let field = Arc::new(Waves);
        let t = heightfield_terrain(field.clone(), spec(), &earth_layout(), 1.0).unwrap();
        let sea = t.sea_radius.unwrap();
        let mut kinds = std::collections::BTreeSet::new();
        for k in 0..3000 {
            let f = f64::from(k);
            let d = DVec3::new((f * 0.37).sin(), (f * 0.11).cos(), (f * 0.73).sin() + 0.1).normalize();
            let p = d * (sea + field.height(d));
            let up = (d + DVec3::new(0.0, 0.2 * (f * 0.5).sin(), 0.0)).normalize();
            let a = t.shader.shade(p, up);
            let b = t.shader.shade_on_surface(p, up);
            assert_eq!(a, b, "at {p}");
            kinds.insert(a.material);
        }
        assert!(kinds.len() >= 4, "{kinds:?}");
    }

    #[test]
    fn relief_too_tall_for_the_shell_is_an_error() {
        struct Tall;
        impl HeightField for Tall {
            fn height(&self, _: DVec3) -> f64 {
                0.0
            }
            fn bounds(&self) -> (f64, f64) {
                (-20_000.0, 20_000.0)
            }
        }
        let e = heightfield_terrain(Arc::new(Tall), spec(), &earth_layout(), 1.0).unwrap_err();
        assert!(matches!(e, ReliefError::TooTall { .. }), "{e}");
        struct Nan;
        impl HeightField for Nan {
            fn height(&self, _: DVec3) -> f64 {
                f64::NAN
            }
            fn bounds(&self) -> (f64, f64) {
                (f64::NAN, 0.0)
            }
        }
        assert!(heightfield_terrain(Arc::new(Nan), spec(), &earth_layout(), 1.0).is_err());
    }

    #[test]
    fn lopsided_relief_moves_the_sea() {
        struct Mars;
        impl HeightField for Mars {
            fn height(&self, _: DVec3) -> f64 {
                0.0
            }
            fn bounds(&self) -> (f64, f64) {
                (-8000.0, 21_000.0)
            }
        }
        let layout = earth_layout();
        let t = heightfield_terrain(Arc::new(Mars), spec(), &layout, 1.0).unwrap();
        let (lo, hi) = t.density.radial_bounds().unwrap();
        assert!(lo >= layout.d_b() && hi <= layout.radius(), "{lo} {hi}");
    }
}
