//! The earthlike preset: continents and seas, coastal plains, ridged mountain belts, spaghetti
//! caves above sea level and overhangs in the mountains.
//!
//! Relief is set in fractions of the shell thickness `T`, horizontal scales relative to the
//! planet radius (height noise is 3D noise at the unit direction times a frequency) or in tiles,
//! cave and overhang depths in voxel depths `l_d`. Heights below are above the sea radius
//! `d_b + 0.55 T`:
//!
//! | feature            | height                            | horizontal scale             |
//! |--------------------|-----------------------------------|------------------------------|
//! | ocean floor        | down to -0.23 T (shelf, then deep) | continents, 1.4 cells/radian |
//! | lowlands           | up to +0.07 T inland               | continents                   |
//! | hills              | +-0.03 T on land, +-0.015 T at sea | 0.1 R down to 2 tiles        |
//! | mountain belts     | up to +0.24 T (ridged)             | belts 2 cells/radian, ridges 0.16 R |
//! | overhangs          | displacement up to 4 `l_d` (at most 0.065 T), on steep mountain slopes | 3 tiles across, 3 `l_d` deep |
//! | caves              | band from sea level + `l_d` to 2.5 `l_d` under the surface, at most 0.14 T deep; the roof opens in places (cave mouths) | tubes about 2 tiles wide and 3 `l_d` tall, about 12 tiles apart |

use super::features::{carved_voxels, lerp, smoothstep, CaveBand, ColumnModel, Overhang, Scales, Spaghetti};
use super::material::{
    column_terrain, Bands, Cap, CapLine, CaveRock, Cover, Ground, GroundModel, MaterialRules, SteepRock, VertexColumns,
};
use super::shading::Look;
use super::{PresetKind, Terrain};
use crate::noise::{derive_seed, gradient3, gradient3_accumulate, Fbm, FbmParams, Ridged, RidgedParams};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`super::Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["sand", "grass", "forest", "rock", "snow", "cave"];
const SAND: u8 = 0;
const GRASS: u8 = 1;
const FOREST: u8 = 2;
const ROCK: u8 = 3;
const SNOW: u8 = 4;
const CAVE: u8 = 5;

/// Sea radius, as a fraction of the shell above `d_b`.
pub(crate) const SEA_LEVEL: f64 = 0.55;
/// Depth of the continental shelf (fraction of `T`).
const SHELF_DEPTH: f64 = 0.03;
/// Extra depth of the deep ocean beyond the shelf (fraction of `T`).
const OCEAN_DEPTH: f64 = 0.20;
/// Rise of the lowlands from the coast inland (fraction of `T`).
const LOWLAND_RISE: f64 = 0.07;
/// Hill amplitude on land and at sea (fractions of `T`; the fBm is doubled, so this is about
/// its typical excursion and half its bound).
const HILLS_LAND: f64 = 0.03;
const HILLS_SEA: f64 = 0.015;
/// Height of the mountain ridges (fraction of `T`).
const MOUNTAIN_HEIGHT: f64 = 0.24;
/// Continents: noise cells per unit of direction, and the offset that sets the land fraction.
const CONTINENT_FREQ: f64 = 1.4;
const CONTINENT_BIAS: f64 = -0.02;
/// Mountain belts: cells per unit of direction.
const BELT_FREQ: f64 = 2.0;
/// Hills: largest wavelength (fraction of the radius).
const HILLS_WAVELENGTH: f64 = 0.1;
/// Ridges: largest wavelength (fraction of the radius).
const RIDGE_WAVELENGTH: f64 = 0.16;
/// Overhang displacement: amplitude in `l_d` (at most 6.5% of `T`), noise lengths in tiles across
/// and `l_d` deep.
const OVERHANG_AMPLITUDE: f64 = 4.0;
const OVERHANG_ACROSS: f64 = 3.0;
const OVERHANG_DEEP: f64 = 3.0;
/// Caves: tube noise lengths (tiles across, `l_d` deep), threshold, band depth (fraction of `T`),
/// roof thickness (`l_d`), region size (tiles).
const CAVE_ACROSS: f64 = 12.0;
const CAVE_DEEP: f64 = 14.0;
const CAVE_THRESHOLD: f64 = 0.1;
const CAVE_BAND: f64 = 0.14;
const CAVE_ROOF: f64 = 2.5;
const CAVE_REGION: f64 = 40.0;
/// How fast the cave field closes outside its band (density per metre).
const CAVE_SLOPE: f64 = 8.0;

/// Everything a column of the earthlike planet computes once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct EarthColumn {
    /// Surface radius of the height field (before overhang displacement).
    pub h: f64,
    /// Overhang displacement amplitude (metres).
    pub amp: f64,
    /// Where caves may open.
    pub band: CaveBand,
    /// Mountain mask in `[0, 1]`.
    pub mountains: f64,
}

/// The earthlike density model.
pub(crate) struct EarthModel {
    s: Scales,
    sea: f64,
    continents: Fbm,
    belts: Fbm,
    hills: Fbm,
    ridges: Ridged,
    region_seed: u64,
    region_freq: f64,
    overhang: Overhang,
    overhang_amp: f64,
    caves: Spaghetti,
    bounds: (f64, f64),
}

impl EarthModel {
    pub(crate) fn new(seed: u64, layout: &Layout) -> Self {
        let s = Scales::new(layout);
        let t = s.thickness;
        let sea = s.shell(SEA_LEVEL);
        let fine = 2.0 * s.tile;
        let cont_oct = s.octaves(s.radius / CONTINENT_FREQ, 10.0 * s.tile, 6);
        let hills_oct = s.octaves(HILLS_WAVELENGTH * s.radius, fine, 12);
        let ridge_oct = s.octaves(RIDGE_WAVELENGTH * s.radius, fine, 12);
        let overhang_amp = (OVERHANG_AMPLITUDE * s.l_d).min(0.065 * t);
        let caves = Spaghetti::new(
            (derive_seed(seed, 20), derive_seed(seed, 21)),
            CAVE_ACROSS * s.tile,
            (CAVE_DEEP * s.l_d).min(0.25 * t),
            sea,
            CAVE_THRESHOLD,
            CAVE_SLOPE,
            t,
        );
        // Bounds: every term at its extreme (noise is within [-1, 1], masks within [0, 1]); ocean
        // and land terms exclude each other, overhangs only occur on land (e > 0.015, where the
        // height is at least sea - 2 HILLS_LAND T).
        let hills_max = 2.0 * HILLS_LAND * t;
        let lowest_floor = sea - (SHELF_DEPTH + OCEAN_DEPTH) * t - hills_max;
        let lowest_land = sea - hills_max - overhang_amp;
        let lowest_cave = sea + s.l_d - caves.reach_below();
        let highest = sea + (LOWLAND_RISE + MOUNTAIN_HEIGHT) * t + hills_max + overhang_amp;
        let margin = 1e-6 * t;
        let bounds = (
            lowest_floor.min(lowest_land).min(lowest_cave) - margin,
            highest + margin,
        );
        EarthModel {
            s,
            sea,
            continents: Fbm::new(derive_seed(seed, 10), FbmParams::new(CONTINENT_FREQ, cont_oct)),
            belts: Fbm::new(derive_seed(seed, 11), FbmParams::new(BELT_FREQ, 2)),
            hills: Fbm::new(derive_seed(seed, 12), FbmParams::new(1.0 / HILLS_WAVELENGTH, hills_oct)),
            ridges: Ridged::new(
                derive_seed(seed, 13),
                RidgedParams::new(1.0 / RIDGE_WAVELENGTH, ridge_oct),
            ),
            region_seed: derive_seed(seed, 14),
            region_freq: s.freq(CAVE_REGION * s.tile),
            overhang: Overhang::new(
                derive_seed(seed, 15),
                OVERHANG_ACROSS * s.tile,
                OVERHANG_DEEP * s.l_d,
                sea,
                s.l_d,
            ),
            overhang_amp,
            caves,
            bounds,
        }
    }

    /// The sea radius.
    pub(crate) fn sea(&self) -> f64 {
        self.sea
    }
}

impl EarthModel {
    /// The continent value `e` and the land gate of a column from its continent noise.
    #[inline]
    fn land(continents: f64) -> (f64, f64) {
        let e = continents + CONTINENT_BIAS;
        (e, smoothstep(0.015, 0.07, e))
    }

    /// The mountain mask from the belt noise (read only where the land gate is open).
    #[inline]
    fn mountains(land_gate: f64, belt: impl FnOnce() -> f64) -> f64 {
        // Mountain belts along the zero set of a low-frequency noise, on land only. The belt and
        // ridge noises are skipped where their factor is exactly zero.
        if land_gate > 0.0 {
            (1.0 - smoothstep(0.02, 0.10, belt().abs())) * land_gate
        } else {
            0.0
        }
    }

    /// The column along `dir` from its continent value, hill noise and mountain mask, with the
    /// ridge noise read only where there are mountains.
    #[inline]
    fn finish(&self, e: f64, hills: f64, mountains: f64, ridge: impl FnOnce() -> f64, region: f64) -> EarthColumn {
        let t = self.s.thickness;
        // Ocean floor (e < 0) and lowlands (e > 0); both are 0 with zero slope at the coast.
        let ocean = -t * (SHELF_DEPTH * smoothstep(0.0, 0.025, -e) + OCEAN_DEPTH * smoothstep(0.02, 0.16, -e));
        let land = t * LOWLAND_RISE * smoothstep(0.0, 0.25, e);
        let hills_amp = t * lerp(HILLS_SEA, HILLS_LAND, smoothstep(-0.02, 0.05, e));
        let hills = 2.0 * hills_amp * hills;
        let (peaks, steep) = if mountains > 0.0 {
            let ridge = smoothstep(0.35, 0.95, ridge());
            (t * MOUNTAIN_HEIGHT * mountains * ridge, smoothstep(0.2, 0.6, ridge))
        } else {
            (0.0, 0.0)
        };
        let h = self.sea + ocean + land + hills + peaks;
        let amp = self.overhang_amp * mountains * steep;
        // Caves: between sea level and a roof under the surface, in regions; where the region
        // noise is high the roof goes above the surface, so tubes open as cave mouths (the
        // sign of a zero region value changes neither ramp).
        let gate = smoothstep(-0.25, -0.05, region);
        let mouth = smoothstep(0.15, 0.35, region);
        let roof = self.s.l_d * (CAVE_ROOF - 5.0 * mouth);
        let bottom = (self.sea + self.s.l_d).max(h - CAVE_BAND * t);
        let band = self.caves.band(bottom, h - roof, gate);
        EarthColumn {
            h,
            amp,
            band,
            mountains,
        }
    }
}

impl EarthModel {
    /// Where the cave-region noise is sampled along `dir`.
    #[inline]
    fn region_point(&self, dir: DVec3) -> DVec3 {
        dir * self.region_freq
    }
}

/// The coordinates of some of `dirs` (those at `idx`), as the slices the fractal sums take.
fn gather(dirs: &[DVec3], idx: &[usize], xyz: &mut [Vec<f64>; 3]) {
    for (k, c) in xyz.iter_mut().enumerate() {
        c.clear();
        c.extend(idx.iter().map(|&i| dirs[i][k]));
    }
}

impl ColumnModel for EarthModel {
    type Column = EarthColumn;

    fn column(&self, dir: DVec3) -> EarthColumn {
        let (e, land_gate) = Self::land(self.continents.sample(dir));
        let hills = self.hills.sample(dir);
        let mountains = Self::mountains(land_gate, || self.belts.sample(dir));
        let region = gradient3(self.region_point(dir), self.region_seed);
        self.finish(e, hills, mountains, || self.ridges.sample(dir), region)
    }

    /// The columns of many directions, the same bits as [`column`](Self::column) one by one:
    /// each fractal sum runs over the coordinate slices of the directions that read it
    /// ([`Fbm::sample_slices`]), the belts where there is land, the ridges where there are
    /// mountains.
    fn columns(&self, dirs: &[DVec3], out: &mut Vec<EarthColumn>) {
        let n = dirs.len();
        let all: Vec<usize> = (0..n).collect();
        let mut xyz = [Vec::new(), Vec::new(), Vec::new()];
        gather(dirs, &all, &mut xyz);
        let (mut continents, mut hills) = (vec![0.0; n], vec![0.0; n]);
        self.continents
            .sample_slices(&xyz[0], &xyz[1], &xyz[2], &mut continents);
        self.hills.sample_slices(&xyz[0], &xyz[1], &xyz[2], &mut hills);
        // The region noise at `dir * region_freq` (`region_point`): the same product, taken in
        // the kernel.
        let mut regions = vec![0.0; n];
        gradient3_accumulate(
            &xyz[0],
            &xyz[1],
            &xyz[2],
            self.region_freq,
            self.region_seed,
            1.0,
            &mut regions,
        );
        let land: Vec<(f64, f64)> = continents.iter().map(|c| Self::land(*c)).collect();
        let gated: Vec<usize> = (0..n).filter(|&i| land[i].1 > 0.0).collect();
        gather(dirs, &gated, &mut xyz);
        let mut belts = vec![0.0; gated.len()];
        self.belts.sample_slices(&xyz[0], &xyz[1], &xyz[2], &mut belts);
        let mut mountains = vec![0.0; n];
        for (&i, b) in gated.iter().zip(&belts) {
            mountains[i] = Self::mountains(land[i].1, || *b);
        }
        let ridged: Vec<usize> = (0..n).filter(|&i| mountains[i] > 0.0).collect();
        gather(dirs, &ridged, &mut xyz);
        let mut ridges = vec![0.0; n];
        let mut values = vec![0.0; ridged.len()];
        self.ridges.sample_slices(&xyz[0], &xyz[1], &xyz[2], &mut values);
        for (&i, v) in ridged.iter().zip(&values) {
            ridges[i] = *v;
        }
        out.clear();
        out.extend((0..n).map(|i| self.finish(land[i].0, hills[i], mountains[i], || ridges[i], regions[i])));
    }

    #[inline]
    fn voxel(&self, col: &EarthColumn, dir: DVec3, _p: DVec3, r: f64) -> f64 {
        let d0 = self.overhang.displace(col.h, col.amp, dir, r);
        self.caves.carve(d0, &col.band, dir, r)
    }

    /// [`voxel`](Self::voxel) at every voxel of the columns, the same bits
    /// ([`carved_voxels`]).
    fn voxels(&self, cols: &[EarthColumn], dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
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

    fn ground_radius(&self, col: &EarthColumn) -> f64 {
        col.h
    }

    fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

impl GroundModel for EarthModel {
    fn scales(&self) -> &Scales {
        &self.s
    }

    /// The sea level.
    fn datum(&self) -> f64 {
        self.sea
    }

    /// The mountain mask is the roughness; no feature field.
    fn ground(col: &EarthColumn) -> Ground {
        Ground {
            h: col.h,
            amp: col.amp,
            feature: 0.0,
            rough: col.mountains,
        }
    }
}

/// The earthlike colours.
const LOOK: Look = Look {
    names: MATERIALS,
    colors: &[
        [[222, 204, 150], [196, 176, 124]], // sand
        [[92, 138, 58], [124, 158, 70]],    // grass
        [[38, 84, 36], [58, 100, 44]],      // forest
        [[112, 106, 98], [146, 138, 126]],  // rock
        [[244, 246, 252], [218, 226, 240]], // snow
        [[62, 56, 52], [90, 80, 72]],       // cave
    ],
    mix_salt: 30,
    mix_tiles: 1.5,
    blend_colors: [[0.42, 0.50, 0.26], [0.56, 0.47, 0.32]],
};

/// Where the earthlike materials lie: cave rock under the surface, snow above a line that drops
/// toward the poles, rock on steep slopes, then height bands (sea-floor sand and beaches, grass
/// and forest, a forest belt bare on high mountains, rock). Vertices read the columns at their
/// edge's ends, which the density batch keeps.
const RULES: MaterialRules = MaterialRules {
    cave: CaveRock {
        id: CAVE,
        depth: 1.5,
        margin: 1.0,
    },
    cap: Some(Cap {
        id: SNOW,
        flat: 0.5,
        line: CapLine::SnowLine {
            equator: 0.25,
            fall: 0.32,
            floor: 0.004,
        },
    }),
    steep: SteepRock {
        id: ROCK,
        up_below: 0.62,
        rough_above: None,
    },
    feature: None,
    cover: Cover::Bands(Bands {
        shore: SAND,
        shore_below: 0.012,
        lowland_below: 0.10,
        woods: FOREST,
        open: GRASS,
        woods_above: 0.05,
        woods_salt: 32,
        woods_tiles: 8.0,
        tree_line: 0.18,
        bare_above: 0.13,
        bare_rough: 0.6,
        high: ROCK,
    }),
    jitter_salt: 31,
    jitter_tiles: 2.0,
    height_jitter: 0.012,
    vertices: VertexColumns::EdgeEnds,
};

/// Builds the earthlike terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    let model = Arc::new(EarthModel::new(seed, layout));
    let sea = model.sea();
    column_terrain(PresetKind::Earthlike, seed, model, Some(sea), &LOOK, RULES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::features::ColumnDensity;
    use crate::presets::testing::*;
    use crate::presets::EdgeVertices;
    use crate::{Density, ShellColumns};
    use pmc_geometry::VertexEdge;

    fn terrain(seed: u64) -> (Terrain, Arc<EarthModel>) {
        let layout = Layout::default();
        (build(seed, &layout), Arc::new(EarthModel::new(seed, &layout)))
    }

    #[test]
    fn shading_edges_from_kept_columns_gives_the_same_bits_as_computing_them() {
        let (ter, m) = terrain(3);
        let dirs = sphere_dirs(3000);
        let edges: Vec<VertexEdge> = (0..2400u32)
            .map(|i| VertexEdge {
                a: i,
                b: if i % 3 == 0 { i } else { (i * 7 + 1) % 3000 },
                t: f64::from(i % 10) / 9.0,
            })
            .collect();
        // Points on the surface and below it (cave rock), normals from flat to steep.
        let points: Vec<DVec3> = edges
            .iter()
            .map(|e| {
                let (a, b) = (dirs[e.a as usize], dirs[e.b as usize]);
                let depth = if e.a % 5 == 0 { 4.0 * m.s.l_d } else { 0.0 };
                (a + (b - a) * e.t).normalize() * (m.column(a).h - depth)
            })
            .collect();
        let normals: Vec<DVec3> = points
            .iter()
            .enumerate()
            .map(|(i, p)| (p.normalize() + DVec3::X * (i % 4) as f64 * 0.5).normalize())
            .collect();
        let mut kept = ShellColumns::default();
        let mut out = vec![0.0; dirs.len()];
        ter.density.sample_shell_keeping(&dirs, &[m.sea], &mut out, &mut kept);
        assert!(!kept.is_empty(), "the earthlike batch keeps its columns");
        let shade = |columns: &ShellColumns| {
            let v = EdgeVertices {
                points: &points,
                normals: &normals,
                edges: &edges,
                dirs: &dirs,
                columns,
            };
            let mut shades = Vec::new();
            ter.shader.shade_edges(&v, &mut shades);
            shades
        };
        let from_batch = shade(&kept);
        assert_eq!(from_batch, shade(&ShellColumns::default()));
        // Columns another terrain kept over the same directions are not read.
        let (other, _) = terrain(4);
        other.density.sample_shell_keeping(&dirs, &[m.sea], &mut out, &mut kept);
        assert_eq!(from_batch, shade(&kept));
        let materials: std::collections::HashSet<u8> = from_batch.iter().map(|s| s.material).collect();
        assert!(materials.len() >= 4, "{materials:?}");
    }

    #[test]
    fn land_and_sea() {
        let (_, m) = terrain(1);
        let dirs = sphere_dirs(4000);
        let land = dirs.iter().filter(|d| m.column(**d).h > m.sea).count() as f64 / dirs.len() as f64;
        assert!((0.2..0.6).contains(&land), "land fraction {land}");
    }

    #[test]
    fn mountains_reach_their_height() {
        let (_, m) = terrain(1);
        let top = sphere_dirs(20_000)
            .iter()
            .map(|d| m.column(*d).h)
            .fold(f64::MIN, f64::max);
        let t = m.s.thickness;
        assert!(
            top - m.sea > 0.2 * t && top - m.sea < 0.4 * t,
            "highest peak {} T",
            (top - m.sea) / t
        );
        let deep = sphere_dirs(20_000)
            .iter()
            .map(|d| m.column(*d).h)
            .fold(f64::MAX, f64::min);
        assert!(
            m.sea - deep > 0.15 * t && m.sea - deep < 0.3 * t,
            "deepest sea {} T",
            (m.sea - deep) / t
        );
    }

    #[test]
    fn has_caves_above_sea_level_only() {
        let (ter, m) = terrain(1);
        let mut cave_air = 0;
        for d in sphere_dirs(3000) {
            let col = m.column(d);
            let mut r = m.sea - 3.0 * m.s.l_d;
            while r < col.h - 3.0 * m.s.l_d - col.amp {
                if ter.density.density(d * r) <= 0.0 {
                    assert!(r > m.sea, "dry cave under the sea at {}", r - m.sea);
                    cave_air += 1;
                }
                r += 1.0;
            }
        }
        assert!(cave_air > 50, "found {cave_air} cave samples");
    }

    #[test]
    fn has_overhangs_and_cave_mouths() {
        let (ter, m) = terrain(1);
        let (lo, hi) = ter.density.radial_bounds().unwrap();
        let mut folds = 0;
        let mut mouths = 0;
        for d in sphere_dirs(6000) {
            let col = m.column(d);
            if sign_changes(&*ter.density, d, lo, hi, 0.5) > 1 {
                folds += 1;
            }
            // A cave mouth: air 1.5 l_d under the height-field surface where nothing displaces
            // it (the normal cave roof is thicker, so this is a tube breaking the surface).
            if col.amp == 0.0
                && col.h > m.sea + 3.0 * m.s.l_d
                && ter.density.density(d * (col.h - 1.5 * m.s.l_d)) <= 0.0
            {
                mouths += 1;
            }
        }
        assert!(folds > 20, "radial lines with more than one surface crossing: {folds}");
        assert!(mouths > 3, "cave mouths: {mouths}");
    }

    #[test]
    fn overhangs_fold_the_surface_in_the_mountains() {
        let (ter, m) = terrain(1);
        let (lo, hi) = ter.density.radial_bounds().unwrap();
        let mut folded = 0;
        for d in sphere_dirs(20_000) {
            let col = m.column(d);
            if col.amp > 0.0 {
                // Look only within the overhang window, above any cave band.
                let a = col.h - 1.6 * col.amp - m.s.l_d;
                if sign_changes(&*ter.density, d, a.max(lo), hi, 0.25) > 1 && ter.density.density(d * a) > 0.0 {
                    folded += 1;
                }
            }
        }
        assert!(folded > 5, "overhangs: {folded}");
    }

    /// The batched columns and shades are the point-by-point ones, bit for bit: over the whole
    /// sphere (sea, land, belts and mountains) and at points above, on and below the surface.
    #[test]
    fn batches_give_the_point_by_point_bits() {
        let (ter, m) = terrain(5);
        let dirs = sphere_dirs(3001);
        let mut cols = Vec::new();
        m.columns(&dirs, &mut cols);
        assert!(cols.iter().any(|c| c.mountains > 0.0) && cols.iter().any(|c| c.h < m.sea()));
        let bits = |c: &EarthColumn| {
            (
                c.h.to_bits(),
                c.amp.to_bits(),
                c.mountains.to_bits(),
                format!("{:?}", c.band),
            )
        };
        for (d, c) in dirs.iter().zip(&cols) {
            assert_eq!(bits(c), bits(&m.column(*d)), "column at {d:?}");
        }
        let (points, normals): (Vec<DVec3>, Vec<DVec3>) = dirs
            .iter()
            .zip(&cols)
            .enumerate()
            .map(|(i, (d, c))| {
                let r = c.h + [-30.0, -2.0, 0.0, 1.5][i % 4] * m.s.l_d;
                let n = (*d + DVec3::new(0.3, -0.2, 0.1) * (i % 3) as f64).normalize();
                (*d * r, n)
            })
            .unzip();
        // Voxels from deep under to high above the surface (caves, overhangs, open air).
        let radii: Vec<f64> = (0..48)
            .map(|k| m.sea() - 0.3 * m.s.thickness + f64::from(k) * 0.014 * m.s.thickness)
            .collect();
        let mut got = vec![0.0f32; dirs.len() * radii.len()];
        m.voxels(&cols, &dirs, &radii, &mut got);
        for (k, r) in radii.iter().enumerate() {
            for (d, dir) in dirs.iter().enumerate() {
                let p = *dir * *r;
                let want = m.voxel(&cols[d], *dir, p, p.length()) as f32;
                assert_eq!(got[k * dirs.len() + d].to_bits(), want.to_bits(), "voxel at {p:?}");
            }
        }
        let mut shades = Vec::new();
        ter.shader.shade_many(&points, &normals, false, &mut shades);
        for i in 0..points.len() {
            assert_eq!(
                shades[i],
                ter.shader.shade(points[i], normals[i]),
                "shade at {:?}",
                points[i]
            );
        }
    }

    #[test]
    fn shader_tells_beach_from_snowy_peak() {
        let (ter, m) = terrain(1);
        let mut beach = None;
        let mut peak = None;
        for d in sphere_dirs(20_000) {
            let col = m.column(d);
            let z = col.h - m.sea;
            let shade = ter.shader.shade(d * col.h, d);
            if z > 0.0 && z < 0.004 * m.s.thickness && d.y.abs() < 0.5 && beach.is_none() {
                beach = Some(shade);
            }
            if peak.is_none_or(|(best, _)| z > best) {
                peak = Some((z, shade));
            }
        }
        let beach = beach.expect("a beach");
        let peak = peak.unwrap().1;
        assert_eq!(MATERIALS[usize::from(beach.material)], "sand");
        assert_eq!(MATERIALS[usize::from(peak.material)], "snow");
        assert_ne!(beach.color, peak.color);
        // A cliff is rock.
        let d = sphere_dirs(10).remove(3);
        let col = m.column(d);
        let side = d.cross(DVec3::Z).normalize();
        assert_eq!(ter.shader.shade(d * col.h, side).material, ROCK);
    }

    #[test]
    fn batch_matches_points_and_is_deterministic() {
        let (ter, m) = terrain(7);
        check_batch_matches_points(&*ter.density, &land_patch(&m), 1e-3);
    }

    #[test]
    fn surface_within_bounds() {
        let (ter, _) = terrain(3);
        check_surface_within_bounds(&ter, &Layout::default());
    }

    #[test]
    fn seeds_differ() {
        let (a, _) = terrain(1);
        let (b, _) = terrain(2);
        check_seeds_differ(&*a.density, &*b.density, &Layout::default());
    }

    #[test]
    fn scales_follow_the_layout() {
        // A planet four times larger in every length: the same seed gives the same relief in
        // units of the shell, at about the same places.
        let small = Layout::default();
        let big = Layout::new(8, 32, 4.0 * 1744.0, 16.0, 2).unwrap();
        let (ms, mb) = (EarthModel::new(5, &small), EarthModel::new(5, &big));
        let mut close = 0;
        let dirs = sphere_dirs(500);
        for d in &dirs {
            let zs = (ms.column(*d).h - ms.sea) / ms.s.thickness;
            let zb = (mb.column(*d).h - mb.sea) / mb.s.thickness;
            if (zs - zb).abs() < 1e-9 {
                close += 1;
            }
        }
        assert_eq!(close, dirs.len());
        let (lo, hi) = ColumnDensity(Arc::new(mb)).radial_bounds().unwrap();
        assert!(lo > big.d_b() && hi < big.radius());
    }

    /// A surface chunk's worth of directions around some land (used by the batch check).
    fn land_patch(m: &EarthModel) -> (Vec<DVec3>, Vec<f64>) {
        let d = sphere_dirs(4000)
            .into_iter()
            .find(|d| {
                let c = m.column(*d);
                c.mountains > 0.5 && c.amp > 0.0
            })
            .expect("a mountain");
        patch(d, m.s.tile, 12, m.sea - 10.0 * m.s.l_d, m.s.l_d, 30)
    }
}
