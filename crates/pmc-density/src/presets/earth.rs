//! The earth preset: the Earth at true scale on its own layout (sea level at 6 371 000 m, 1 m
//! voxels), and the same planet shrunk onto any other layout.
//!
//! # Scales
//!
//! Heights below are metres at true scale. On a layout with shell thickness `T` they are scaled
//! by `v = T / 32 768 m` (exactly 1 on the earth layout), and horizontal sizes are angles, so a
//! smaller planet is the same planet shrunk. Metre-scale features (rocks, cliffs, caves) are sized
//! in voxels instead: `l_d` deep (1 m at true scale) and tiles across (about 1.2 m), capped by
//! fractions of `T`. Height-field detail stops at two tiles (finer octaves would only alias). The
//! sea lies in the middle of the shell, `d_b + T/2`.
//!
//! | feature | height | horizontal scale |
//! |---|---|---|
//! | continents, ocean basins | shelf -150 m, ocean floor -2.9 to -5.5 km; lowlands up to +450 m, plateaus up to +1.1 km | continent cells about 5 500 km; about 30% land |
//! | trenches | down to 4.5 km under the ocean floor (about -10 km) | arcs about 300 km wide along a noise zero set |
//! | regional swell | +-320 m at 600 km, gain 0.8 | 600 km to 70 km |
//! | mountain ranges | ridged multifractal, squared, up to 9.5 km | belts about 800 km wide, ridges 150 km down to 25 m |
//! | hills | +-150 m at 35 km, amplitude as wavelength^0.75, times a hilliness of 0.35 to 3 | 35 km down to 2 tiles |
//! | rocks | +-1.2 m at 30 m (height field), and 3D bumps of 1.2 `l_d` | 30 m down to 2 tiles; bumps 4 tiles across, 3 `l_d` deep |
//! | cliffs, overhangs | 3D displacement up to 9 `l_d` on mountain slopes, folding the surface | 20 tiles across, 7 `l_d` deep |
//! | caves | tubes from 56 `l_d` (at most 0.08 T) under the surface up to a roof 4 `l_d` under it, or 3 `l_d` above it where the roof opens (cave mouths); on land, above sea level | tubes about 5 tiles wide and 4 `l_d` tall, about 26 tiles apart |
//!
//! # A signed distance everywhere in the shell
//!
//! The density is `h(dir) - r` (metres) plus the 3D terms (rocks, cliffs, caves), which are
//! exactly zero more than `W` from `h` (`W` under 70 `l_d` below, 18 `l_d` above, per column), so
//! far above and below the surface it is the radial distance to it, and coarse levels of detail,
//! whose layers may be kilometres apart, place the surface by interpolating it.
//!
//! # Cost: the height field is band-limited by the distance to the surface
//!
//! A column first computes its coarse fields once (continents, basins, trenches, plateaus,
//! mountain belts, hilliness, cave regions: 8 to 14 noise lattices). The detail of `h` is a
//! ladder of 35 octaves at true scale (regional swell, ridges, hills, rocks) ordered from the longest
//! wavelength to the shortest; after `k` of them the height `h_k` is known to within a sound
//! bound `B_k` (every octave's amplitude is known from the coarse fields; the squared ridge term
//! is bounded by `B (2 R_k + B)`). A sample at radius `r` stops at the first `k` with
//! `|h_k - r| >= max(8 B_k, B_k + W)` and returns `h_k - r`: the sign is that of the full
//! formula, the value within 1/8 of it, and the 3D terms are certainly zero there. The stopping
//! rule depends on the sample alone (never on the batch), so every chunk that holds a voxel
//! computes the same bits for it. A batch advances each column's ladder only as far as its
//! furthest-reaching radius needs: a chunk kilometres from the surface costs a few coarse
//! octaves per column; a chunk at the surface evaluates the whole ladder once per column and
//! the 3D terms only in the band around the surface. The ladder's noise is evaluated for the
//! next eight entries that count at once ([`crate::noise::gradient3_x8`]): the same bits as one
//! at a time.

use super::features::model_key;
use super::features::{lerp, radial, smoothstep, CaveBand, Scales, Spaghetti, Stretch};
use super::layouts::EARTH_RADIUS;
use super::shading::{Look, MaterialMap};
use super::EdgeVertices;
use super::{PresetKind, Terrain};
use crate::noise::{
    derive_seed, gradient3, gradient3_x8, mix64, unit_f64, Fbm, FbmParams, Lanes8, DEFAULT_LACUNARITY, LANES,
};
use crate::{Density, ShellColumns};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`super::Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["seabed", "sand", "grass", "forest", "rock", "snow", "cave"];
const SEABED: u8 = 0;
const SAND: u8 = 1;
const GRASS: u8 = 2;
const FOREST: u8 = 3;
const ROCK: u8 = 4;
const SNOW: u8 = 5;
const CAVE: u8 = 6;

/// The shell thickness of the true-scale layout: heights are metres for it, scaled by
/// `T / TRUE_THICKNESS` on other layouts.
pub(crate) const TRUE_THICKNESS: f64 = 32_768.0;

/// Continents: cells per unit of direction, octaves, and the offset that sets the land fraction.
const CONT_FREQ: f64 = 1.15;
const CONT_OCTAVES: u32 = 7;
const CONT_BIAS: f64 = -0.085;
/// Ocean: shelf depth, mean abyssal depth and its variation between basins (metres).
const SHELF_DEPTH: f64 = 150.0;
const ABYSS_DEPTH: f64 = 4200.0;
const ABYSS_VARIATION: f64 = 1300.0;
const BASIN_FREQ: f64 = 0.9;
/// Trenches: extra depth (metres), cells per unit of direction of their lines and of their gate.
const TRENCH_DEPTH: f64 = 4500.0;
const TRENCH_FREQ: f64 = 1.3;
const TRENCH_GATE_FREQ: f64 = 2.2;
/// Land: rise of the lowlands inland and height of the plateaus (metres).
const LOWLAND_RISE: f64 = 450.0;
const PLATEAU_HEIGHT: f64 = 1100.0;
const PLATEAU_FREQ: f64 = 1.6;
/// Mountain belts: cells per unit of direction, and the highest ridge (metres).
const BELT_FREQ: f64 = 1.5;
const MOUNTAIN_HEIGHT: f64 = 9500.0;
/// Hilliness: cells per unit of direction.
const HILLINESS_FREQ: f64 = 9.0;

/// The detail ladder: wavelengths `LADDER_TOP / 2.03^i` (true-scale metres).
const LADDER_TOP: f64 = 600_000.0;
/// At most this many rungs (the last one is about 2 cm at true scale: never reached).
const LADDER_RUNGS: usize = 24;
/// Room for every octave of every part of the ladder (a test checks the true-scale count).
const MAX_ENTRIES: usize = 40;
/// Regional swell: wavelengths at least this (metres), amplitude of the first octave, gain.
const REGIONAL_MIN: f64 = 50_000.0;
const REGIONAL_AMP: f64 = 320.0;
const REGIONAL_GAIN: f64 = 0.8;
/// Hills: amplitude at `HILLS_REF` metres, spectral exponent (amplitude ~ wavelength^exp).
const HILLS_AMP: f64 = 150.0;
const HILLS_REF: f64 = 35_000.0;
const HILLS_EXP: f64 = 0.75;
/// Ridges: wavelengths from `RIDGE_MAX` down to `RIDGE_MIN` metres, gain.
const RIDGE_MAX: f64 = 170_000.0;
const RIDGE_MIN: f64 = 25.0;
const RIDGE_GAIN: f64 = 0.5;
/// Rocks (height field): wavelengths up to `ROCK_MAX` metres, amplitude there, exponent.
const ROCK_MAX: f64 = 32.0;
const ROCK_AMP: f64 = 1.2;
const ROCK_EXP: f64 = 0.72;
/// Finest height-field detail, in tiles.
const FINEST_TILES: f64 = 2.0;

/// A sample stops refining once its distance from the partial height is this many times the
/// bound on the remaining octaves (so a truncated value is within 1/8 of the full one).
const STOP_FACTOR: f64 = 8.0;

/// 3D rock bumps: amplitude (`l_d`, at most a fraction of `T`), lengths (tiles across, `l_d` deep).
const ROCK3D_AMP: f64 = 1.2;
const ROCK3D_CAP: f64 = 0.005;
const ROCK3D_ACROSS: f64 = 4.0;
const ROCK3D_DEEP: f64 = 3.0;
/// Cliffs: displacement amplitude (`l_d`, at most a fraction of `T`), lengths, gate cells (tiles).
const CLIFF_AMP: f64 = 9.0;
const CLIFF_CAP: f64 = 0.02;
const CLIFF_ACROSS: f64 = 20.0;
const CLIFF_DEEP: f64 = 7.0;
const CLIFF_REGION: f64 = 1500.0;
/// Caves: tube lengths (tiles across, `l_d` deep), threshold, band depth (`l_d`, at most a
/// fraction of `T`), roof (`l_d`) and how far above the surface an open roof goes (`l_d`), the
/// region size (tiles), and how fast the field closes outside its band (density per metre).
const CAVE_ACROSS: f64 = 26.0;
const CAVE_DEEP: f64 = 24.0;
const CAVE_THRESHOLD: f64 = 0.1;
const CAVE_BAND: f64 = 56.0;
const CAVE_BAND_CAP: f64 = 0.08;
const CAVE_ROOF: f64 = 4.0;
const CAVE_MOUTH: f64 = 3.0;
const CAVE_REGION: f64 = 300.0;
const CAVE_SLOPE: f64 = 8.0;

/// The parts of the detail ladder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    Regional = 0,
    Hills = 1,
    Ridge = 2,
    Rocks = 3,
}

/// One octave of the ladder.
#[derive(Clone, Copy, Debug)]
struct Entry {
    part: Part,
    freq: f64,
    offset: DVec3,
    seed: u64,
    /// Amplitude before the column's factor (for ridges: the share of the normalised sum).
    amp: f64,
}

/// A column's coarse fields and its lazily refined height.
#[derive(Clone, Debug)]
pub(crate) struct EarthColumn {
    /// Per-part amplitude factors in metres (Regional, Hills, Ridge = mountain height, Rocks).
    factor: [f64; 4],
    /// 3D rock and cliff amplitudes (metres).
    a_rock: f64,
    a_cliff: f64,
    /// The mountain mask in `[0, 1]` (the shader's rock above the tree line).
    mountains: f64,
    /// Cave gate in `[0, 1]` and roof depth (metres, negative where the roof opens).
    cave_gate: f64,
    roof: f64,
    /// Reach of the 3D terms below and above `h`.
    w_down: f64,
    w_up: f64,
    /// Ladder state: entries done, the linear sum, the ridge sum and weight.
    done: usize,
    linear: f64,
    ridge: f64,
    weight: f64,
    /// After `k` entries: the height, and the radii between which samples go on refining.
    h: [f64; MAX_ENTRIES + 1],
    keep_lo: [f64; MAX_ENTRIES + 1],
    keep_hi: [f64; MAX_ENTRIES + 1],
    /// The bound on the remaining octaves after the `done` entries evaluated.
    rem: f64,
    /// Noise of upcoming entries, evaluated eight at a time: `noise[l]` is entry `noise_of[l]`'s
    /// (`usize::MAX`: none).
    noise: [f64; LANES],
    noise_of: [usize; LANES],
    /// The lane of the next entry asked for (entries are asked for in increasing order).
    noise_next: usize,
}

impl EarthColumn {
    /// The height after the last evaluated entry.
    pub fn height(&self) -> f64 {
        self.h[self.done]
    }

    /// Whether a sample at `r` goes on refining after `k` entries.
    #[inline]
    fn keeps(&self, k: usize, r: f64) -> bool {
        self.keep_lo[k] < r && r < self.keep_hi[k]
    }

    /// Makes `self` the column `src` as far as it is refined: the entries after `src.done` are
    /// not copied (whatever they hold is never read: every read is at an entry up to `done`, and
    /// `advance` writes an entry before reading it). A column is 1.6 kB, most of it entries a
    /// column refined part of the way never fills, and the column cache's copies were a sixth of
    /// a cold teleport's time when they were whole.
    fn copy_refined(&mut self, src: &EarthColumn) {
        let n = src.done + 1;
        self.factor = src.factor;
        self.a_rock = src.a_rock;
        self.a_cliff = src.a_cliff;
        self.mountains = src.mountains;
        self.cave_gate = src.cave_gate;
        self.roof = src.roof;
        self.w_down = src.w_down;
        self.w_up = src.w_up;
        self.done = src.done;
        self.linear = src.linear;
        self.ridge = src.ridge;
        self.weight = src.weight;
        self.h[..n].copy_from_slice(&src.h[..n]);
        self.keep_lo[..n].copy_from_slice(&src.keep_lo[..n]);
        self.keep_hi[..n].copy_from_slice(&src.keep_hi[..n]);
        self.rem = src.rem;
        self.noise = src.noise;
        self.noise_of = src.noise_of;
        self.noise_next = src.noise_next;
    }
}

/// The height-independent fields of a column (see [`EarthModel::surface_fields`]).
struct SurfaceFields {
    mountains: f64,
    on_land: f64,
    a_rock: f64,
    a_cliff: f64,
    cave_gate: f64,
    roof: f64,
}

/// The earth density model.
pub(crate) struct EarthModel {
    s: Scales,
    sea: f64,
    vert: f64,
    continents: Fbm,
    basins: Fbm,
    trenches: Fbm,
    trench_gate_seed: u64,
    plateaus: Fbm,
    belts: Fbm,
    hilliness_seed: u64,
    entries: Vec<Entry>,
    /// `sums[k][p]`: the sum of the amplitudes of part `p` from entry `k` on.
    sums: Vec<[f64; 4]>,
    cliff_seed: u64,
    cliff_freq: f64,
    rock3d: Stretch,
    rock3d_seed: u64,
    rock3d_amp: f64,
    cliff: Stretch,
    cliff_seed3d: u64,
    cliff_amp: f64,
    falloff: f64,
    caves: Spaghetti,
    cave_band: f64,
    region_seed: u64,
    region_freq: f64,
    bounds: (f64, f64),
}

impl EarthModel {
    pub(crate) fn new(seed: u64, layout: &Layout) -> Self {
        let s = Scales::new(layout);
        let t = s.thickness;
        let sea = s.shell(0.5);
        let vert = t / TRUE_THICKNESS;
        let ratio = sea / EARTH_RADIUS;
        let entries = ladder(seed, ratio, s.tile);
        let mut suffix: [Vec<f64>; 4] = Default::default();
        for (p, sums) in suffix.iter_mut().enumerate() {
            *sums = vec![0.0; entries.len() + 1];
            for k in (0..entries.len()).rev() {
                let e = &entries[k];
                sums[k] = sums[k + 1] + if e.part as usize == p { e.amp } else { 0.0 };
            }
        }
        let sums = (0..=entries.len())
            .map(|k| [0, 1, 2, 3].map(|p| suffix[p][k]))
            .collect();
        let l_d = s.l_d;
        let rock3d_amp = (ROCK3D_AMP * l_d).min(ROCK3D_CAP * t);
        let cliff_amp = (CLIFF_AMP * l_d).min(CLIFF_CAP * t);
        let cave_deep = (CAVE_DEEP * l_d).min(0.25 * t);
        let caves = Spaghetti::new(
            (derive_seed(seed, 60), derive_seed(seed, 61)),
            CAVE_ACROSS * s.tile,
            cave_deep,
            sea,
            CAVE_THRESHOLD,
            CAVE_SLOPE,
            t,
        );
        let cave_band = (CAVE_BAND * l_d).min(CAVE_BAND_CAP * t);
        let falloff = l_d;
        // Sound bounds: every term at its extreme (noise within [-1, 1], ridges within [0, 1],
        // masks within [0, 1], the largest column factors), the 3D displacement at its largest.
        let detail = |p: Part, f: f64| f * suffix[p as usize].first().copied().unwrap_or(0.0);
        let hills_max = 1.7 + 1.3;
        let rocks_max = 1.7;
        let common = detail(Part::Regional, 1.0) + detail(Part::Hills, hills_max) + detail(Part::Rocks, rocks_max);
        let deepest = ABYSS_DEPTH + ABYSS_VARIATION + TRENCH_DEPTH;
        let highest = LOWLAND_RISE + PLATEAU_HEIGHT + MOUNTAIN_HEIGHT;
        let a_max = rock3d_amp + cliff_amp;
        let margin = 1e-6 * t;
        let lowest_cave = sea + 2.0 * l_d + caves.floor() / CAVE_SLOPE;
        let bounds = (
            (sea - vert * (deepest + common) - a_max).min(lowest_cave) - margin,
            sea + vert * (highest + common) + a_max + margin,
        );
        EarthModel {
            s,
            sea,
            vert,
            continents: Fbm::new(derive_seed(seed, 40), FbmParams::new(CONT_FREQ, CONT_OCTAVES)),
            basins: Fbm::new(derive_seed(seed, 41), FbmParams::new(BASIN_FREQ, 2)),
            trenches: Fbm::new(derive_seed(seed, 42), FbmParams::new(TRENCH_FREQ, 2)),
            trench_gate_seed: derive_seed(seed, 43),
            plateaus: Fbm::new(derive_seed(seed, 44), FbmParams::new(PLATEAU_FREQ, 2)),
            belts: Fbm::new(derive_seed(seed, 45), FbmParams::new(BELT_FREQ, 2)),
            hilliness_seed: derive_seed(seed, 46),
            entries,
            sums,
            cliff_seed: derive_seed(seed, 47),
            cliff_freq: s.freq(CLIFF_REGION * s.tile),
            rock3d: Stretch::new(ROCK3D_ACROSS * s.tile, (ROCK3D_DEEP * l_d).min(0.25 * t), sea),
            rock3d_seed: derive_seed(seed, 48),
            rock3d_amp,
            cliff: Stretch::new(CLIFF_ACROSS * s.tile, (CLIFF_DEEP * l_d).min(0.25 * t), sea),
            cliff_seed3d: derive_seed(seed, 49),
            cliff_amp,
            falloff,
            caves,
            cave_band,
            region_seed: derive_seed(seed, 62),
            region_freq: s.freq(CAVE_REGION * s.tile),
            bounds,
        }
    }

    /// The sea radius.
    pub(crate) fn sea(&self) -> f64 {
        self.sea
    }

    /// Number of octaves in the detail ladder.
    #[cfg(test)]
    pub(crate) fn ladder_len(&self) -> usize {
        self.entries.len()
    }

    /// The coarse fields of the column along unit direction `dir` (no ladder entry evaluated).
    /// The continental value along unit direction `dir` (its sign tells land from sea).
    #[inline]
    fn continent(&self, dir: DVec3) -> f64 {
        self.continents.sample(dir) + CONT_BIAS
    }

    /// The fields of the column along `dir` (continental value `e`) that do not depend on its
    /// height: the mountain mask and the amplitudes of the 3D terms. The shader needs only these
    /// (and the height in cave regions).
    #[inline]
    fn surface_fields(&self, dir: DVec3, e: f64) -> SurfaceFields {
        // Mountain belts along a noise zero set.
        let land_gate = smoothstep(0.005, 0.05, e);
        let mountains = if land_gate > 0.0 {
            (1.0 - smoothstep(0.015, 0.07, self.belts.sample(dir).abs())) * land_gate
        } else {
            0.0
        };
        let on_land = smoothstep(-0.015, 0.01, e);
        // 3D terms: rock bumps on land, cliffs in parts of the mountains, caves in regions of the
        // land whose roof opens in places.
        let a_rock = self.rock3d_amp * on_land;
        let a_cliff = if mountains > 0.0 {
            self.cliff_amp * mountains * smoothstep(-0.1, 0.3, gradient3(dir * self.cliff_freq, self.cliff_seed))
        } else {
            0.0
        };
        let cave_land = smoothstep(0.0, 0.015, e);
        let (cave_gate, roof) = if cave_land > 0.0 {
            let region = gradient3(dir * self.region_freq, self.region_seed);
            let mouth = smoothstep(0.25, 0.45, region);
            (
                cave_land * smoothstep(-0.15, 0.05, region),
                self.s.l_d * (CAVE_ROOF - (CAVE_ROOF + CAVE_MOUTH) * mouth),
            )
        } else {
            (0.0, 0.0)
        };
        SurfaceFields {
            mountains,
            on_land,
            a_rock,
            a_cliff,
            cave_gate,
            roof,
        }
    }

    pub(crate) fn column(&self, dir: DVec3) -> EarthColumn {
        let mut col = EarthColumn {
            factor: [0.0; 4],
            a_rock: 0.0,
            a_cliff: 0.0,
            mountains: 0.0,
            cave_gate: 0.0,
            roof: 0.0,
            w_down: 0.0,
            w_up: 0.0,
            done: 0,
            linear: 0.0,
            ridge: 0.0,
            weight: 1.0,
            h: [0.0; MAX_ENTRIES + 1],
            keep_lo: [0.0; MAX_ENTRIES + 1],
            keep_hi: [0.0; MAX_ENTRIES + 1],
            rem: 0.0,
            noise: [0.0; LANES],
            noise_of: [usize::MAX; LANES],
            noise_next: LANES,
        };
        self.column_into(dir, &mut col);
        col
    }

    /// Makes `col` the column of `dir` with no entry evaluated, in place: its entries after the
    /// first are left as they were (never read before `advance` writes them, as with
    /// [`EarthColumn::copy_refined`]), so a column reused costs no copy of the whole.
    pub(crate) fn column_into(&self, dir: DVec3, col: &mut EarthColumn) {
        let v = self.vert;
        let e = self.continent(dir);
        // Ocean: a shelf, then the abyssal floor (its depth varying between basins), and trenches
        // along part of a noise zero set. Every noise is skipped where its factor is exactly zero.
        let shelf = smoothstep(0.0, 0.012, -e);
        let deep = smoothstep(0.02, 0.09, -e);
        let mut depth = SHELF_DEPTH * shelf;
        if deep > 0.0 {
            let abyss = ABYSS_DEPTH + ABYSS_VARIATION * (3.0 * self.basins.sample(dir)).clamp(-1.0, 1.0);
            depth += (abyss - SHELF_DEPTH) * deep;
            let gate = smoothstep(0.05, 0.12, -e);
            if gate > 0.0 {
                let gate = gate * smoothstep(0.0, 0.25, gradient3(dir * TRENCH_GATE_FREQ, self.trench_gate_seed));
                if gate > 0.0 {
                    let line = 1.0 - smoothstep(0.0, 0.02, self.trenches.sample(dir).abs());
                    depth += TRENCH_DEPTH * line * gate;
                }
            }
        }
        // Land: lowlands rising inland, plateaus, mountain belts along a noise zero set.
        let mut height = LOWLAND_RISE * smoothstep(0.0, 0.15, e);
        let plateau_gate = smoothstep(0.03, 0.12, e);
        if plateau_gate > 0.0 {
            height += PLATEAU_HEIGHT * plateau_gate * smoothstep(0.1, 0.45, self.plateaus.sample(dir));
        }
        let SurfaceFields {
            mountains,
            on_land,
            a_rock,
            a_cliff,
            cave_gate,
            roof,
        } = self.surface_fields(dir, e);
        let base = self.sea + v * (height - depth);
        // Detail amplitudes: hills rougher where the hilliness noise is high and in mountains,
        // calmer at sea; rocks rougher in the mountains.
        let hilly = lerp(
            0.35,
            1.7,
            smoothstep(-0.3, 0.35, gradient3(dir * HILLINESS_FREQ, self.hilliness_seed)),
        ) + 1.3 * mountains;
        let factor = [
            v * lerp(0.7, 1.0, on_land),
            v * hilly * lerp(0.6, 1.0, on_land),
            v * MOUNTAIN_HEIGHT * mountains,
            v * lerp(0.3, 0.7 + mountains, on_land),
        ];
        let a = a_rock + a_cliff;
        let over = if a > 0.0 { 1.5 * a + self.falloff } else { 0.0 };
        let (cave_down, cave_up) = if cave_gate > 0.0 {
            // Under the band the field rises by CAVE_SLOPE per metre from its floor -tS, so it
            // exceeds the plain distance h - r from (slope D + tS) / (slope - 1) under h; above
            // the band's top (at most -roof above h) likewise, with h - r < 0.
            let ts = -self.caves.floor();
            (
                (CAVE_SLOPE * self.cave_band + ts) / (CAVE_SLOPE - 1.0),
                (CAVE_SLOPE * (-roof).max(0.0) + ts) / (CAVE_SLOPE + 1.0),
            )
        } else {
            (0.0, 0.0)
        };
        let margin = self.s.l_d + 1e-6 * self.s.thickness;
        col.factor = factor;
        col.mountains = mountains;
        col.a_rock = a_rock;
        col.a_cliff = a_cliff;
        col.cave_gate = cave_gate;
        col.roof = roof;
        col.w_down = over.max(cave_down) + margin;
        col.w_up = over.max(cave_up) + margin;
        col.done = 0;
        col.linear = base;
        col.ridge = 0.0;
        col.weight = 1.0;
        col.noise = [0.0; LANES];
        col.noise_of = [usize::MAX; LANES];
        col.noise_next = LANES;
        col.h[0] = base;
        self.set_keep(col, 0, f64::NEG_INFINITY, f64::INFINITY);
    }

    /// Records the remaining bound after `k` entries (`k` is `col.done`) and the radii that keep refining.
    #[inline]
    fn set_keep(&self, col: &mut EarthColumn, k: usize, lo: f64, hi: f64) {
        let f = &col.factor;
        let sums = &self.sums[k];
        let ridge_left = sums[Part::Ridge as usize];
        let rem = f[0] * sums[0] + f[1] * sums[1] + f[3] * sums[3] + f[2] * ridge_left * (2.0 * col.ridge + ridge_left);
        let h = col.h[k];
        col.rem = rem;
        col.keep_lo[k] = lo.max(h - (rem + col.w_down).max(STOP_FACTOR * rem));
        col.keep_hi[k] = hi.min(h + (rem + col.w_up).max(STOP_FACTOR * rem));
    }

    /// Evaluates the next ladder entry of `col`.
    fn advance(&self, col: &mut EarthColumn, dir: DVec3) {
        let k = col.done;
        let e = &self.entries[k];
        let f = col.factor[e.part as usize];
        if f > 0.0 {
            let n = self.ladder_noise(col, dir, k);
            match e.part {
                Part::Ridge => {
                    let s = (1.0 - n.abs()) * (1.0 - n.abs()) * col.weight;
                    col.weight = (2.0 * s).clamp(0.0, 1.0);
                    col.ridge += e.amp * s;
                }
                _ => col.linear += f * e.amp * n,
            }
        }
        col.done = k + 1;
        col.h[k + 1] = col.linear + col.factor[Part::Ridge as usize] * col.ridge * col.ridge;
        let (lo, hi) = (col.keep_lo[k], col.keep_hi[k]);
        self.set_keep(col, k + 1, lo, hi);
    }

    /// The noise of ladder entry `k` of `col` (`gradient3(dir * freq + offset, seed)`, the same
    /// bits), evaluated with the next entries that count for the column (a non-zero factor),
    /// eight at a time, on the first call that needs one of them.
    #[inline]
    fn ladder_noise(&self, col: &mut EarthColumn, dir: DVec3, k: usize) -> f64 {
        // The lanes hold the entries that count in increasing order, and entries are asked for
        // in increasing order: the next lane is the one, unless the lanes are used up.
        let l = col.noise_next;
        if l < LANES && col.noise_of[l] == k {
            col.noise_next = l + 1;
            return col.noise[l];
        }
        let mut q = Lanes8::default();
        let mut l = 0;
        for (j, e) in self.entries.iter().enumerate().skip(k) {
            if l == LANES {
                break;
            }
            if col.factor[e.part as usize] > 0.0 {
                q.set(l, dir * e.freq + e.offset, e.seed);
                col.noise_of[l] = j;
                l += 1;
            }
        }
        col.noise_of[l..].fill(usize::MAX);
        col.noise = gradient3_x8(&q);
        col.noise_next = 1;
        col.noise[0]
    }

    /// Refines `col` until a sample at `r` stops (or the ladder ends).
    fn refine_for(&self, col: &mut EarthColumn, dir: DVec3, r: f64) {
        while col.done < self.entries.len() && col.keeps(col.done, r) {
            self.advance(col, dir);
        }
    }

    /// Refines `col` until its height is known within `tol` metres (or the ladder ends).
    pub(crate) fn refine_to(&self, col: &mut EarthColumn, dir: DVec3, tol: f64) {
        while col.done < self.entries.len() && col.rem > tol {
            self.advance(col, dir);
        }
    }

    /// Whether `h - r > depth` for the column's full height `h` (every entry), refining only
    /// until the sound bound on the remaining octaves settles the comparison.
    pub(crate) fn deeper_than(&self, col: &mut EarthColumn, dir: DVec3, r: f64, depth: f64) -> bool {
        while col.done < self.entries.len() && (col.h[col.done] - r - depth).abs() <= col.rem {
            self.advance(col, dir);
        }
        col.height() - r > depth
    }

    /// The full height of the column (every entry evaluated).
    #[cfg(test)]
    pub(crate) fn full_height(&self, col: &mut EarthColumn, dir: DVec3) -> f64 {
        self.refine_to(col, dir, -1.0);
        col.height()
    }

    /// Refines `col` while some sample of a batch at radii `rs` may still need it. Refining
    /// further than a sample needs never changes its value (its stopping entry depends on the
    /// sample alone), so the column stops as soon as no sample lies inside its (nested,
    /// shrinking) interval: a chunk whose layers are far apart stops long before the ladder's
    /// end. `sorted`: `rs` is in increasing order with none negative; the samples still refining
    /// then form one run of them.
    fn refine_batch(&self, col: &mut EarthColumn, dir: DVec3, rs: &[f64], sorted: bool) {
        if sorted {
            let (mut a, mut b) = (0, rs.len());
            while col.done < self.entries.len() {
                let k = col.done;
                while a < b && rs[a] <= col.keep_lo[k] {
                    a += 1;
                }
                while a < b && rs[b - 1] >= col.keep_hi[k] {
                    b -= 1;
                }
                if a == b {
                    break;
                }
                self.advance(col, dir);
            }
        } else {
            let r_min = rs.iter().copied().fold(f64::INFINITY, f64::min);
            let r_max = rs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            while col.done < self.entries.len() && col.keep_lo[col.done] < r_max && r_min < col.keep_hi[col.done] {
                self.advance(col, dir);
            }
        }
    }

    /// The density at radius `r` of a column refined at least as far as `r` needs.
    #[inline]
    fn value(&self, col: &EarthColumn, dir: DVec3, r: f64) -> f64 {
        // The first k at which the sample stops; `keeps` is monotone in k (nested intervals).
        if !col.keeps(0, r) {
            // Far from the surface: the coarse fields decide (the common case away from it).
            return col.h[0] - r;
        }
        let n = col.done;
        if col.keeps(n, r) {
            debug_assert_eq!(n, self.entries.len());
            return self.near_surface(col, dir, col.h[n], r);
        }
        let (mut lo, mut hi) = (1usize, n);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if col.keeps(mid, r) {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        col.h[lo] - r
    }

    /// [`EarthModel::value`] at every radius of `rs` (in increasing order), handed to `put`
    /// with its index, in time proportional to the samples and the ladder, not to the samples
    /// times the ladder's logarithm: a sample stops at the first entry `k` whose interval does
    /// not hold it, the first with `keep_lo[k] >= r` or with `keep_hi[k] <= r`; the intervals are
    /// nested, so the first of these moves only up and the second only down as `r` grows.
    #[inline]
    fn values_sorted(&self, col: &EarthColumn, dir: DVec3, rs: &[f64], mut put: impl FnMut(usize, f64)) {
        let n = col.done;
        // below: the first k with keep_lo[k] >= r (n + 1: none); above: the first k with
        // keep_hi[k] <= r.
        let mut below = 0;
        let mut above = n + 1;
        for (i, r) in rs.iter().enumerate() {
            let r = *r;
            while below <= n && col.keep_lo[below] < r {
                below += 1;
            }
            while above > 0 && col.keep_hi[above - 1] <= r {
                above -= 1;
            }
            let stop = below.min(above);
            let v = if stop <= n {
                col.h[stop] - r
            } else {
                debug_assert_eq!(n, self.entries.len());
                self.near_surface(col, dir, col.h[n], r)
            };
            put(i, v);
        }
    }

    /// The sign every sample of `col` from radius `lo` up to radius `hi` takes, when the samples
    /// at the two ends settle it (`col` refined as far as both need): `Some(false)` (air) when
    /// the sample at `lo` stops above the surface, `Some(true)` (solid) when the one at `hi`
    /// stops below it, else `None`.
    ///
    /// Why the ends settle the samples between them: a sample at `r` stops at the first entry
    /// `k` whose interval `(keep_lo[k], keep_hi[k])` does not hold it, and there `r` lies beyond
    /// the entry's own bound, `r >= h_k + max(8 B_k, B_k + W_up)` above the surface (value
    /// `h_k - r < 0`) or `r <= h_k - max(8 B_k, B_k + W_down)` below it (value `> 0`): the first
    /// entry whose interval drops `r` is one whose own bound does, as the interval before held
    /// it. The intervals are nested, so a sample above one that stopped above the surface at
    /// `k` lies outside interval `k` on the same side and stops there or earlier, above the
    /// surface again (its value below zero); below the surface alike.
    fn column_sign(&self, col: &EarthColumn, lo: f64, hi: f64) -> Option<bool> {
        let stop = |r: f64| (0..=col.done).find(|&k| !col.keeps(k, r));
        if let Some(k) = stop(lo) {
            if col.h[k] - lo < 0.0 {
                return Some(false);
            }
        }
        match stop(hi) {
            Some(k) if col.h[k] - hi > 0.0 => Some(true),
            _ => None,
        }
    }

    /// The full formula near the surface: the height field displaced by rocks and cliffs, carved
    /// by caves.
    #[inline]
    fn near_surface(&self, col: &EarthColumn, dir: DVec3, h: f64, r: f64) -> f64 {
        let base = h - r;
        let a = col.a_rock + col.a_cliff;
        let mut d0 = base;
        if a > 0.0 {
            let reach = 1.5 * a + self.falloff;
            let z = base.abs();
            if z < reach {
                let w = 1.0 - smoothstep(a, reach, z);
                let mut n = col.a_rock * gradient3(self.rock3d.at(dir, r), self.rock3d_seed);
                if col.a_cliff > 0.0 {
                    n += col.a_cliff * gradient3(self.cliff.at(dir, r), self.cliff_seed3d);
                }
                d0 = base + w * n;
            }
        }
        if col.cave_gate > 0.0 {
            let bottom = (self.sea + 2.0 * self.s.l_d).max(h - self.cave_band);
            let band: CaveBand = self.caves.band(bottom, h - col.roof, col.cave_gate);
            d0 = self.caves.carve(d0, &band, dir, r);
        }
        d0
    }

    /// The density at `dir * r` with no shortcut: every ladder entry, the full 3D formula (for
    /// tests; the radius is taken as `|dir * r|` like the batch does).
    #[cfg(test)]
    pub(crate) fn reference(&self, dir: DVec3, r: f64) -> f64 {
        let r = (dir * r).length();
        let mut col = self.column(dir);
        let h = self.full_height(&mut col, dir);
        self.near_surface(&col, dir, h, r)
    }

    /// Sound radial bounds on the surface.
    pub(crate) fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

/// Builds the detail ladder for a planet `ratio` times the Earth's size with tiles `tile` metres
/// wide: octaves of every part at the ladder's wavelengths, down to `FINEST_TILES` tiles.
fn ladder(seed: u64, ratio: f64, tile: f64) -> Vec<Entry> {
    let mut out = Vec::new();
    let mut ridge_total = 0.0;
    for i in 0..LADDER_RUNGS {
        let lambda = LADDER_TOP / DEFAULT_LACUNARITY.powi(i as i32);
        if lambda * ratio < FINEST_TILES * tile || out.len() + 4 > MAX_ENTRIES {
            break;
        }
        let mut push = |part: Part, amp: f64| {
            let s = derive_seed(derive_seed(seed, 50 + part as u64), i as u64);
            out.push(Entry {
                part,
                freq: EARTH_RADIUS / lambda,
                offset: DVec3::new(
                    unit_f64(mix64(s ^ 1)) * 1024.0,
                    unit_f64(mix64(s ^ 2)) * 1024.0,
                    unit_f64(mix64(s ^ 3)) * 1024.0,
                ),
                seed: s,
                amp,
            });
        };
        if lambda >= REGIONAL_MIN {
            push(Part::Regional, REGIONAL_AMP * REGIONAL_GAIN.powi(i as i32));
        } else {
            push(Part::Hills, HILLS_AMP * (lambda / HILLS_REF).powf(HILLS_EXP));
        }
        if (RIDGE_MIN..=RIDGE_MAX).contains(&lambda) {
            let a = RIDGE_GAIN.powf((RIDGE_MAX / lambda).ln() / DEFAULT_LACUNARITY.ln());
            ridge_total += a;
            push(Part::Ridge, a);
        }
        if lambda <= ROCK_MAX {
            push(Part::Rocks, ROCK_AMP * (lambda / ROCK_MAX).powf(ROCK_EXP));
        }
    }
    // Ridges sum to at most 1 (every signal is at most 1).
    if ridge_total > 0.0 {
        for e in out.iter_mut().filter(|e| e.part == Part::Ridge) {
            e.amp /= ridge_total;
        }
    }
    out
}

/// The earth density: the model behind the [`Density`] trait, with the band-limited batch.
pub(crate) struct EarthDensity(pub Arc<EarthModel>, ColumnCache);

impl EarthDensity {
    /// The density of `model`, with an empty column cache.
    pub(crate) fn new(model: Arc<EarthModel>) -> Self {
        EarthDensity(model, ColumnCache::default())
    }

    /// Makes `col` the column of `dir` as far as the cache has it (else a fresh one; `fresh`:
    /// `col` already is), refines it as far as samples at `rs` need
    /// ([`EarthModel::refine_batch`]) and keeps it in the cache when it went further.
    fn refine_cached(&self, col: &mut EarthColumn, fresh: bool, dir: DVec3, rs: &[f64], sorted: bool) {
        let m = &*self.0;
        let done = if self.1.get_into(dir, col) {
            Some(col.done)
        } else {
            if !fresh {
                m.column_into(dir, col);
            }
            None
        };
        m.refine_batch(col, dir, rs, sorted);
        if done.is_none_or(|d| d < col.done) {
            self.1.put(dir, col);
        }
    }

    /// The batch of [`Density::sample_shell`], leaving in `kept` (when given; cleared first)
    /// every column it used, refined as far as the layers needed, in the order of `dirs`.
    fn batch(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], mut kept: Option<&mut Vec<EarthColumn>>) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        let m = &*self.0;
        let n = dirs.len();
        // The point call sees `|dir * r|`; the batch takes the same radius so both follow the
        // same path (they differ only by the rounding of the direction).
        let mut rs = vec![0.0; radii.len()];
        // Layer radii come in increasing order from every chunk grid; `|dir * r|` keeps that
        // order (each rounded operation is monotone), so the samples still refining form one
        // run of them.
        let sorted = radii.windows(2).all(|w| w[0] <= w[1]) && radii.first().is_none_or(|r| *r >= 0.0);
        // `kept` holds the columns of an earlier batch: each is overwritten in place (a kept
        // column is copied only as far as it is refined), new ones pushed.
        if let Some(k) = kept.as_deref_mut() {
            k.truncate(n);
        }
        let mut scratch: Option<EarthColumn> = None;
        for (d, dir) in dirs.iter().enumerate() {
            for (x, r) in rs.iter_mut().zip(radii) {
                *x = (*dir * *r).length();
            }
            // (`fresh`: the slot was just made, as the column of `dir`)
            let (col, fresh) = match kept.as_deref_mut() {
                Some(k) if d < k.len() => (&mut k[d], false),
                Some(k) => {
                    k.push(m.column(*dir));
                    (k.last_mut().expect("just pushed"), true)
                }
                None => match scratch {
                    Some(ref mut c) => (c, false),
                    None => (scratch.insert(m.column(*dir)), true),
                },
            };
            self.refine_cached(col, fresh, *dir, &rs, sorted);
            if sorted {
                m.values_sorted(col, *dir, &rs, |k, v| out[k * n + d] = v as f32);
            } else {
                for (k, r) in rs.iter().enumerate() {
                    out[k * n + d] = m.value(col, *dir, *r) as f32;
                }
            }
        }
    }
}

impl EarthDensity {
    /// [`Density::uniform_sign`]: each column (from the cache, as the batch takes it, and kept
    /// there) refined only as far as its lowest and highest sample need, and asked for the sign
    /// of its samples ([`EarthModel::column_sign`]); the first column that does not settle it,
    /// or settles the other sign, ends the call. A surface chunk is told apart after a column or
    /// a few; a chunk with no surface costs its columns (which the chunks above and below it
    /// share through the cache) and not its samples. Radii out of order or negative give
    /// `None`, as the batch's sorted walk needs them in order.
    fn one_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        let (first, last) = (*radii.first()?, *radii.last()?);
        if !(first >= 0.0 && radii.windows(2).all(|w| w[0] <= w[1])) {
            return None;
        }
        let m = &*self.0;
        let mut sign = None;
        let mut scratch: Option<EarthColumn> = None;
        for dir in dirs {
            // the radii the batch's samples take (`|dir * r|`, in the same order)
            let (lo, hi) = ((*dir * first).length(), (*dir * last).length());
            // A kept column refined as far as both ends need is read where it is: most columns
            // of a chunk with no surface were refined by a chunk above or below it.
            let kept = self.1.read(*dir, |c| {
                let refined = c.done == m.entries.len() || !(c.keeps(c.done, lo) || c.keeps(c.done, hi));
                refined.then(|| m.column_sign(c, lo, hi))
            });
            let s = match kept.flatten() {
                Some(s) => s?,
                None => self.refined_sign(m, &mut scratch, *dir, lo, hi)?,
            };
            if *sign.get_or_insert(s) != s {
                return None;
            }
        }
        sign
    }

    /// The sign of the samples of the column of `dir` from `lo` up to `hi`
    /// ([`EarthModel::column_sign`]), the column taken from the cache as far as it is kept (or
    /// made in `scratch`), refined as far as both ends need, and kept again.
    fn refined_sign(
        &self,
        m: &EarthModel,
        scratch: &mut Option<EarthColumn>,
        dir: DVec3,
        lo: f64,
        hi: f64,
    ) -> Option<bool> {
        let (col, fresh) = match scratch {
            Some(c) => (c, false),
            None => (scratch.insert(m.column(dir)), true),
        };
        self.refine_cached(col, fresh, dir, &[lo, hi], true);
        m.column_sign(col, lo, hi)
    }
}

/// Columns kept for the next batches that sample the same directions, by the bits of the
/// direction: the chunks stacked in one column of the shell (3.3 on average in a view near the
/// ground in the mountains) and the borders that neighbouring chunks share sample the same
/// directions, and a column (its coarse fields, then its octave ladder as far as the layers
/// need) is most of a batch's time.
///
/// A column's state depends only on its direction and on how far its ladder was refined, and a
/// sample's value does not change when the ladder is refined further than it needs (the batch's
/// contract, tested by `a_batch_stops_refining_early_with_the_same_bits_as_points` and
/// `kept_columns_give_the_same_bits`), so a kept column gives every sample the bits a fresh one
/// gives. Columns are copied in and out as far as they are refined (`EarthColumn::copy_refined`:
/// no allocation, and no copy of the entries a column never filled) under one of
/// [`ColumnCache::SHARDS`] locks picked by the direction; in each shard two generations bound
/// the memory: when the newer holds [`ColumnCache::GENERATION`] columns it becomes the older, and
/// the older is emptied and filled again in place as the newer.
pub(crate) struct ColumnCache {
    shards: Vec<Shard>,
    /// Columns per generation of a shard ([`ColumnCache::GENERATION`]; fewer in tests).
    generation: usize,
}

/// A shard's lock, alone on its cache lines: the two workers of a 2-core machine mesh
/// neighbouring chunks, which share directions and shards, and shards packed side by side made
/// the lock's cache line bounce between the cores even for different shards.
#[repr(align(128))]
#[derive(Default)]
struct Shard(std::sync::Mutex<[Generation; 2]>);

/// A generation of a shard of the [`ColumnCache`]: the columns, and their slots by direction.
/// A generation dropped is emptied and reused as the newest (its slots overwritten in place).
#[derive(Default)]
struct Generation {
    slots: std::collections::HashMap<[u64; 3], u32, DirHash>,
    columns: Vec<EarthColumn>,
}

impl Default for ColumnCache {
    fn default() -> Self {
        Self::with_generation(Self::GENERATION)
    }
}

/// Hashes a direction's bits (the keys are directions of chunk grids, not chosen by anyone).
#[derive(Default, Clone, Copy)]
pub(crate) struct DirHash;

/// The state of [`DirHash`].
#[derive(Default)]
pub(crate) struct DirHasher(u64);

impl std::hash::BuildHasher for DirHash {
    type Hasher = DirHasher;
    fn build_hasher(&self) -> DirHasher {
        DirHasher(0)
    }
}

impl std::hash::Hasher for DirHasher {
    fn finish(&self) -> u64 {
        mix64(self.0)
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..b.len()].copy_from_slice(b);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(29) ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

impl ColumnCache {
    /// Locks the directions are spread over.
    const SHARDS: usize = 64;
    /// Columns per generation of a shard (about 1.6 kB each: at most ~52 MB in all).
    const GENERATION: usize = 256;

    /// An empty cache of `generation` columns per generation of a shard.
    fn with_generation(generation: usize) -> Self {
        ColumnCache {
            shards: (0..Self::SHARDS).map(|_| Default::default()).collect(),
            generation: generation.max(1),
        }
    }

    fn key(dir: DVec3) -> ([u64; 3], usize) {
        let k = [dir.x.to_bits(), dir.y.to_bits(), dir.z.to_bits()];
        let h = mix64(k[0] ^ k[1].rotate_left(21) ^ k[2].rotate_left(42));
        (k, (h >> 58) as usize % Self::SHARDS)
    }

    fn shard(&self, i: usize) -> std::sync::MutexGuard<'_, [Generation; 2]> {
        self.shards[i].0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Makes `col` the column kept for `dir` (as far as it is refined), if one is kept.
    fn get_into(&self, dir: DVec3, col: &mut EarthColumn) -> bool {
        let (k, i) = Self::key(dir);
        let shard = self.shard(i);
        for g in shard.iter() {
            if let Some(&slot) = g.slots.get(&k) {
                col.copy_refined(&g.columns[slot as usize]);
                return true;
            }
        }
        false
    }

    /// `f` of the column kept for `dir`, read in place under its shard's lock (no copy), if one
    /// is kept.
    fn read<R>(&self, dir: DVec3, f: impl FnOnce(&EarthColumn) -> R) -> Option<R> {
        let (k, i) = Self::key(dir);
        let shard = self.shard(i);
        let slot = shard
            .iter()
            .find_map(|g| g.slots.get(&k).map(|&s| &g.columns[s as usize]))?;
        Some(f(slot))
    }

    /// Keeps a copy of `col`, the column of `dir`, unless one refined as far is kept already.
    fn put(&self, dir: DVec3, col: &EarthColumn) {
        let (k, i) = Self::key(dir);
        let mut shard = self.shard(i);
        if let Some(&slot) = shard[0].slots.get(&k) {
            let kept = &mut shard[0].columns[slot as usize];
            if kept.done < col.done {
                kept.copy_refined(col);
            }
            return;
        }
        if let Some(&slot) = shard[1].slots.get(&k) {
            if shard[1].columns[slot as usize].done >= col.done {
                return;
            }
        }
        if shard[0].slots.len() >= self.generation {
            // the newer generation becomes the older; the older is emptied to be the newer
            shard.swap(0, 1);
            shard[0].slots.clear();
        }
        let g = &mut shard[0];
        let slot = g.slots.len();
        if slot < g.columns.len() {
            g.columns[slot].copy_refined(col);
        } else {
            g.columns.push(col.clone());
        }
        g.slots.insert(k, slot as u32);
    }
}

impl Density for EarthDensity {
    /// The columns' heights refined until the octaves left amount to at most half a percent of
    /// `detail` (at least a metre): a height for features of about `detail` metres.
    fn ground_radii(&self, dirs: &[DVec3], detail: f64, out: &mut [f64]) -> bool {
        assert_eq!(out.len(), dirs.len(), "output buffer has the wrong size");
        let m = &*self.0;
        let tol = (0.005 * detail).max(1.0);
        for (o, dir) in out.iter_mut().zip(dirs) {
            let mut col = m.column(*dir);
            m.refine_to(&mut col, *dir, tol);
            *o = col.height();
        }
        true
    }

    fn density(&self, p: DVec3) -> f64 {
        let m = &*self.0;
        let (r, dir) = radial(p);
        let mut col = m.column(dir);
        m.refine_for(&mut col, dir, r);
        m.value(&col, dir, r)
    }

    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        self.batch(dirs, radii, out, None);
    }

    /// The batch, keeping its columns (`Vec<EarthColumn>`, one per direction, each refined
    /// as far as the batch's layers needed) for the shader ([`EarthMaterials`]).
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        let owner = model_key(&self.0);
        columns.keep_reusing(owner, dirs, |kept: &mut Vec<EarthColumn>| {
            self.batch(dirs, radii, out, Some(kept))
        });
    }

    fn uniform_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        self.one_sign(dirs, radii)
    }

    fn radial_bounds(&self) -> Option<(f64, f64)> {
        Some(self.0.bounds())
    }
}

/// The earth's colours.
const LOOK: Look = Look {
    names: MATERIALS,
    colors: &[
        [[118, 108, 86], [92, 88, 76]],     // seabed
        [[222, 204, 150], [206, 178, 120]], // sand
        [[96, 140, 60], [128, 160, 72]],    // grass
        [[36, 80, 38], [56, 98, 46]],       // forest
        [[116, 108, 100], [148, 140, 128]], // rock
        [[244, 246, 252], [216, 224, 238]], // snow
        [[62, 56, 52], [90, 80, 72]],       // cave
    ],
    mix_salt: 70,
    mix_tiles: 3.0,
    blend_colors: [[0.36, 0.48, 0.24], [0.58, 0.50, 0.36]],
};

/// The earth's materials: the seabed under water, beaches, deserts in the dry subtropics, grass
/// and forest below a tree line, rock above it and on steep slopes, snow above a snow line that
/// drops from about 5 km at the equator to sea level near the poles, cave rock under the
/// surface.
pub(crate) struct EarthMaterials {
    model: Arc<EarthModel>,
    jitter_seed: u64,
    forest_seed: u64,
    dry_seed: u64,
}

/// Snow line at the equator (true-scale metres); it falls with the square of the sine of the
/// latitude.
const SNOW_LINE: f64 = 5200.0;
/// Tree line as a fraction of the snow line.
const TREE_LINE: f64 = 0.72;
/// Random shift of the snow and tree lines (true-scale metres).
const LINE_JITTER: f64 = 250.0;

impl EarthMaterials {
    fn new(model: Arc<EarthModel>, seed: u64) -> Self {
        EarthMaterials {
            model,
            jitter_seed: derive_seed(seed, 71),
            forest_seed: derive_seed(seed, 72),
            dry_seed: derive_seed(seed, 73),
        }
    }
}

/// What the earth's materials read of a column: the mountain mask, the 3D terms' amplitudes and
/// the cave gate (from [`EarthModel::surface_fields`] at a point, from the columns of a vertex's
/// edge in a chunk).
#[derive(Clone, Copy)]
struct ColumnFields {
    mountains: f64,
    a_rock: f64,
    a_cliff: f64,
    cave_gate: f64,
}

impl ColumnFields {
    fn of(col: &EarthColumn) -> Self {
        ColumnFields {
            mountains: col.mountains,
            a_rock: col.a_rock,
            a_cliff: col.a_cliff,
            cave_gate: col.cave_gate,
        }
    }

    fn lerp(&self, o: &Self, t: f64) -> Self {
        ColumnFields {
            mountains: lerp(self.mountains, o.mountains, t),
            a_rock: lerp(self.a_rock, o.a_rock, t),
            a_cliff: lerp(self.a_cliff, o.a_cliff, t),
            cave_gate: lerp(self.cave_gate, o.cave_gate, t),
        }
    }
}

impl EarthModel {
    /// Whether `lerp(h_a, h_b, t) - r > depth` for the full heights of columns `a` and `b`
    /// (along `dir_a`, `dir_b`; `b` may be `a` itself with `t = 0`), refining copies of them only
    /// until the sound bounds on their remaining octaves settle the comparison: the same answer
    /// whatever they were refined to before.
    fn lerp_deeper_than(&self, a: (&EarthColumn, DVec3), b: (&EarthColumn, DVec3), t: f64, r: f64, depth: f64) -> bool {
        let len = self.entries.len();
        let (mut ca, mut cb) = (std::borrow::Cow::Borrowed(a.0), std::borrow::Cow::Borrowed(b.0));
        loop {
            let (ka, kb) = (ca.done, cb.done);
            let h = lerp(ca.h[ka], cb.h[kb], t);
            let rem = lerp(ca.rem, cb.rem, t);
            // Refine the column whose bound weighs most (of those that can go on and count).
            let wa = if ka < len && t < 1.0 { (1.0 - t) * ca.rem } else { -1.0 };
            let wb = if kb < len && t > 0.0 { t * cb.rem } else { -1.0 };
            if (h - r - depth).abs() > rem || (wa < 0.0 && wb < 0.0) {
                return h - r > depth;
            }
            if wa >= wb {
                self.advance(ca.to_mut(), a.1);
            } else {
                self.advance(cb.to_mut(), b.1);
            }
        }
    }
}

impl EarthMaterials {
    /// The material at `p` (normal `normal`) with the column fields `f` there; `deeper` tells
    /// whether `p` lies more than the given depth under the height field (asked only where caves
    /// can be).
    fn material_with(&self, p: DVec3, normal: DVec3, f: &ColumnFields, deeper: impl FnOnce(f64) -> bool) -> u8 {
        let m = &*self.model;
        let (l_d, tile, v) = (m.s.l_d, m.s.tile, m.vert);
        let (r, dir) = radial(p);
        // Cave rock: well under the height field. Rock bumps and cliffs move the surface by at
        // most `a_rock + a_cliff`, less than the threshold, so only carved caves get there:
        // columns without caves need no height at all.
        let cave_depth = (1.5 * l_d).max(f.a_rock + f.a_cliff + l_d);
        if f.cave_gate > 0.0 && deeper(cave_depth) {
            return CAVE;
        }
        // Heights above the sea: in layout metres for the shore, in true-scale metres for the
        // climate lines.
        let z = r - m.sea;
        if z < -1.5 * l_d {
            return SEABED;
        }
        let up = normal.dot(dir);
        let zt = z / v + LINE_JITTER * gradient3(p / (8.0 * tile), self.jitter_seed);
        let lat2 = dir.y * dir.y;
        let snow = SNOW_LINE * (1.0 - lat2).powf(1.5);
        if zt > snow && up > 0.5 {
            return SNOW;
        }
        if up < 0.68 {
            return ROCK;
        }
        if z < 4.0 * v + 0.25 * l_d {
            return SAND;
        }
        // Deserts: dry where a noise is high, mostly in the subtropics (sine of latitude near 0.4).
        let subtropics = 1.0 - smoothstep(0.0, 0.25, (dir.y.abs() - 0.42).abs());
        let dry = gradient3(dir * 3.0, self.dry_seed) + 0.35 * subtropics;
        if dry > 0.35 && zt < 0.6 * snow {
            return SAND;
        }
        if zt > TREE_LINE * snow {
            return if f.mountains > 0.3 { ROCK } else { GRASS };
        }
        if lat2 > 0.78 {
            return GRASS;
        }
        if gradient3(dir * m.s.freq(40.0 * tile) + DVec3::splat(0.5), self.forest_seed) + 0.2 * (0.2 - dry) > 0.0 {
            FOREST
        } else {
            GRASS
        }
    }
}

impl MaterialMap for EarthMaterials {
    fn material(&self, p: DVec3, normal: DVec3) -> u8 {
        let m = &*self.model;
        let (r, dir) = radial(p);
        let s = m.surface_fields(dir, m.continent(dir));
        let f = ColumnFields {
            mountains: s.mountains,
            a_rock: s.a_rock,
            a_cliff: s.a_cliff,
            cave_gate: s.cave_gate,
        };
        self.material_with(p, normal, &f, |depth| m.deeper_than(&mut m.column(dir), dir, r, depth))
    }

    /// A chunk's vertices take the column fields and heights of their edge's ends (interpolated
    /// along lateral edges), from the columns the density batch kept: a vertex costs a few noise
    /// values instead of a column of its own, whose cave test alone ran most of the ladder.
    fn edge_materials(&self, v: &EdgeVertices<'_>, out: &mut Vec<u8>) {
        let m = &*self.model;
        let kept = v.columns.get::<EarthColumn>(model_key(&self.model), v.dirs);
        // Without kept columns, each direction an edge ends at is computed once.
        let mut computed: Vec<Option<EarthColumn>> = Vec::new();
        if kept.is_none() {
            computed.resize(v.dirs.len(), None);
            for e in v.edges {
                for d in [e.a as usize, e.b as usize] {
                    if computed[d].is_none() {
                        computed[d] = Some(m.column(v.dirs[d]));
                    }
                }
            }
        }
        let col = |d: u32| -> Option<&EarthColumn> {
            match kept {
                Some(k) => k.get(d as usize),
                None => computed.get(d as usize)?.as_ref(),
            }
        };
        out.clear();
        out.extend(v.points.iter().zip(v.normals).zip(v.edges).map(|((p, normal), e)| {
            let (Some(ca), Some(cb)) = (col(e.a), col(e.b)) else {
                // (not reached: `check` bounds the edges, and every end was computed)
                return self.material(*p, *normal);
            };
            let (a, b) = ((ca, v.dirs[e.a as usize]), (cb, v.dirs[e.b as usize]));
            let t = if e.a == e.b { 0.0 } else { e.t };
            let f = ColumnFields::of(ca).lerp(&ColumnFields::of(cb), t);
            let r = p.length();
            self.material_with(*p, *normal, &f, |depth| m.lerp_deeper_than(a, b, t, r, depth))
        }));
    }
}

/// Builds the earth terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    let model = Arc::new(EarthModel::new(seed, layout));
    let (sea, tile) = (model.sea(), model.s.tile);
    let density = Arc::new(EarthDensity::new(model.clone()));
    let spec = crate::terrain::TerrainSpec::preset(PresetKind::Earth, seed);
    LOOK.terrain(spec, density, Some(sea), EarthMaterials::new(model, seed), tile)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::testing::*;

    fn earth(seed: u64) -> (Layout, Arc<EarthModel>, EarthDensity) {
        let layout = PresetKind::Earth.default_layout(None).unwrap();
        let m = Arc::new(EarthModel::new(seed, &layout));
        (layout, m.clone(), EarthDensity::new(m))
    }

    /// The column along `dir` with every ladder entry evaluated, and its height.
    fn full(m: &EarthModel, dir: DVec3) -> (EarthColumn, f64) {
        let mut c = m.column(dir);
        let h = m.full_height(&mut c, dir);
        (c, h)
    }

    #[test]
    fn true_scale() {
        let (layout, m, _) = earth(1);
        assert_eq!(m.sea(), EARTH_RADIUS);
        assert_eq!(m.vert, 1.0);
        assert!(
            m.ladder_len() >= 30 && m.ladder_len() <= MAX_ENTRIES,
            "{}",
            m.ladder_len()
        );
        // The finest octave is a few metres (two tiles of about 1.2 m), the coarsest 600 km.
        let finest = m.entries.iter().map(|e| EARTH_RADIUS / e.freq).fold(f64::MAX, f64::min);
        assert!((2.0..6.0).contains(&finest), "finest wavelength {finest} m");
        let (lo, hi) = m.bounds();
        assert!(
            lo > layout.d_b() && hi < layout.radius(),
            "bounds {lo} {hi} leave the shell"
        );
        assert!(m.sea - lo > 10_000.0 && hi - m.sea > 10_000.0);
    }

    #[test]
    fn density_is_finite_everywhere() {
        // About two million samples: the shell at 16 m spacing, and far inside and outside it
        // (coarse levels of detail sample layers thousands of kilometres apart).
        let (layout, _, d) = earth(2);
        let dirs = sphere_dirs(3000);
        let mut radii: Vec<f64> = (0..=2048).step_by(4).map(|k| layout.layer_radius(16 * k)).collect();
        radii.extend([0.0, 1.0, 1e3, 1e5, 1e6, 5e6, 6.2e6, 6.5e6, 7e6, 1e7, 2e7, 1e8]);
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        d.sample_shell(&dirs, &radii, &mut out);
        assert!(out.len() > 1_500_000);
        assert!(out.iter().all(|v| v.is_finite()), "a sample is not finite");
        for p in [DVec3::ZERO, DVec3::X * 1e-300, DVec3::new(1e9, -1e9, 3.0)] {
            assert!(d.density(p).is_finite(), "{p}");
        }
    }

    #[test]
    fn about_a_third_is_land() {
        for seed in [1, 2, 3] {
            let (_, m, _) = earth(seed);
            let dirs = sphere_dirs(4000);
            let land = dirs.iter().filter(|d| full(&m, **d).1 > m.sea).count() as f64 / dirs.len() as f64;
            assert!((0.2..0.4).contains(&land), "seed {seed}: land fraction {land}");
        }
    }

    #[test]
    fn relief_from_trenches_to_high_mountains() {
        let (_, m, _) = earth(1);
        let heights: Vec<f64> = sphere_dirs(4000).iter().map(|d| full(&m, *d).1 - m.sea).collect();
        let lowest = heights.iter().cloned().fold(f64::MAX, f64::min);
        let highest = heights.iter().cloned().fold(f64::MIN, f64::max);
        assert!(lowest < -6000.0, "deepest sample {lowest} m");
        assert!(highest > 4000.0, "highest sample {highest} m");
        assert!(lowest > -11_500.0 && highest < 9_500.0, "{lowest} .. {highest}");
        // The ocean floor lies around -4 km, the land mostly low with hills.
        let mut sea: Vec<f64> = heights.iter().cloned().filter(|h| *h < 0.0).collect();
        sea.sort_by(f64::total_cmp);
        let median_sea = sea[sea.len() / 2];
        assert!(
            (-5000.0..-3000.0).contains(&median_sea),
            "median sea floor {median_sea}"
        );
        let mut land: Vec<f64> = heights.iter().cloned().filter(|h| *h > 0.0).collect();
        land.sort_by(f64::total_cmp);
        let median_land = land[land.len() / 2];
        assert!((100.0..1500.0).contains(&median_land), "median land {median_land}");
    }

    #[test]
    fn neighbouring_metres_differ_a_little() {
        // Detail down to metres: columns 1.2 m apart have distinct, close surfaces; columns 30 m
        // apart differ more (hills and rocks), and nothing quantises at 6.4e6 m.
        let (_, m, _) = earth(3);
        let (mut small, mut large, mut n) = (0.0, 0.0, 0.0);
        for d in sphere_dirs(400) {
            let (_, h) = full(&m, d);
            if h < m.sea {
                continue;
            }
            let u = d.any_orthonormal_vector();
            let (_, h1) = full(&m, (d + u * (1.2 / m.sea)).normalize());
            let (_, h30) = full(&m, (d + u * (30.0 / m.sea)).normalize());
            assert_ne!(h, h1);
            small += (h - h1).abs();
            large += (h - h30).abs();
            n += 1.0;
        }
        let (small, large) = (small / n, large / n);
        assert!(small < 3.0 && small > 0.01, "mean step over 1.2 m: {small}");
        assert!(large > 3.0 * small, "30 m: {large}, 1.2 m: {small}");
    }

    /// The first solid sample of the column going down from above its 3D reach in 1 m steps, and
    /// the first air under it within `depth` metres (radii).
    fn pocket(m: &EarthModel, d: &EarthDensity, dir: DVec3, depth: f64) -> Option<(f64, Option<f64>)> {
        let (c, h) = full(m, dir);
        let top = (h + c.w_up).ceil();
        let n = (c.w_up + c.w_down + depth).ceil() as usize + 2;
        let radii: Vec<f64> = (0..n).map(|i| top - i as f64).collect();
        let mut out = vec![0.0f32; n];
        d.sample_shell(&[dir], &radii, &mut out);
        let first = out.iter().position(|v| *v > 0.0)?;
        let surface = radii[first];
        let air = (first..n)
            .take_while(|i| radii[*i] >= surface - depth)
            .find(|i| out[*i] <= 0.0)
            .map(|i| radii[i]);
        Some((surface, air))
    }

    #[test]
    fn caves_under_the_land_within_reach() {
        let (_, m, d) = earth(1);
        let (mut land, mut with_air) = (0, 0);
        for dir in sphere_dirs(20_000) {
            let Some((surface, air)) = pocket(&m, &d, dir, 50.0) else {
                continue;
            };
            if surface <= m.sea {
                continue;
            }
            land += 1;
            if let Some(r) = air {
                assert!(r > m.sea, "a dry cave under the sea at {}", r - m.sea);
                with_air += 1;
            }
            if land == 2000 {
                break;
            }
        }
        assert_eq!(land, 2000);
        let frac = f64::from(with_air) / f64::from(land);
        assert!(
            frac >= 0.05,
            "land columns with air within 50 m under the surface: {frac}"
        );
        assert!(frac < 0.6, "too hollow: {frac}");
    }

    #[test]
    fn caves_and_overhangs_stay_near_the_surface() {
        // Nothing hollow deeper than the 3D reach under the surface, nothing solid above it.
        let (_, m, d) = earth(4);
        for dir in sphere_dirs(1500) {
            let (c, h) = full(&m, dir);
            assert!(c.w_down <= 72.0 && c.w_up <= 18.0, "reach {} {}", c.w_down, c.w_up);
            for z in [c.w_down + 0.01, 100.0, 1000.0] {
                assert!(d.density(dir * (h - z)) > 0.0, "air {z} m under the surface");
                assert!(
                    d.density(dir * (h + z.max(c.w_up + 0.01))) <= 0.0,
                    "solid above the surface"
                );
            }
        }
    }

    #[test]
    fn overhangs_fold_the_surface_in_the_mountains() {
        let (_, m, d) = earth(1);
        let mut folded = 0;
        for dir in sphere_dirs(40_000) {
            let (c, h) = full(&m, dir);
            if c.a_cliff < 4.0 {
                continue;
            }
            // Look within the displacement only, above any cave band.
            if sign_changes(&d, dir, h - 1.5 * c.a_cliff - 1.0, h + c.w_up, 0.25) > 1 {
                folded += 1;
            }
        }
        assert!(folded > 5, "folded columns: {folded}");
    }

    #[test]
    fn behaves_like_a_signed_distance() {
        // Away from the 3D band the density is the radial distance to the surface within 1/8
        // (exactly h - r when every octave was needed), with its sign; in the band it differs
        // from h - r by less than the band.
        let (_, m, d) = earth(5);
        let zs = [
            -10_000.0, -3000.0, -1000.0, -300.0, -100.0, -30.0, -10.0, -3.0, -1.0, -0.3, 0.4, 1.5, 4.0, 12.0, 40.0,
            90.0, 200.0, 1000.0, 4000.0, 10_000.0,
        ];
        for dir in sphere_dirs(600) {
            let (c, h) = full(&m, dir);
            let band = c.w_down.max(c.w_up);
            for z in zs {
                let v = d.density(dir * (h - z));
                let outside = z > c.w_down || -z > c.w_up;
                if outside {
                    assert_eq!(v > 0.0, z > 0.0, "sign at {z} m");
                    assert!((v - z).abs() <= z.abs() / STOP_FACTOR + 1e-6, "{v} at {z} m");
                } else {
                    assert!((v - z).abs() <= band, "{v} at {z} m in a band of {band}");
                }
            }
        }
    }

    #[test]
    fn shortcuts_agree_with_the_full_formula() {
        // In the band around the surface the value is the full formula bit for bit; elsewhere
        // it is within 1/8 of it, with the same sign.
        let (_, m, d) = earth(6);
        let mut exact = 0;
        for dir in sphere_dirs(300) {
            let (c, h) = full(&m, dir);
            let radii: Vec<f64> = (-80..=40)
                .map(|i| h + 0.73 * f64::from(i))
                .chain([h - 5e3, h + 5e3])
                .collect();
            let mut out = vec![0.0f32; radii.len()];
            d.sample_shell(&[dir], &radii, &mut out);
            for (r, v) in radii.iter().zip(&out) {
                let full = m.reference(dir, *r);
                if h - r < c.w_down && r - h < c.w_up {
                    assert_eq!(v.to_bits(), (full as f32).to_bits(), "at {} m", h - r);
                    exact += 1;
                } else {
                    assert_eq!(*v > 0.0, full > 0.0);
                    assert!((f64::from(*v) - full).abs() <= full.abs() / STOP_FACTOR + 1e-3);
                }
            }
        }
        assert!(exact > 5000, "{exact}");
    }

    #[test]
    fn a_voxel_has_one_value_whatever_batch_holds_it() {
        // Chunks share border layers and columns: the band-limiting must not depend on the
        // batch. Two overlapping radius sets at several scales give the same bits where they meet.
        let (_, m, d) = earth(7);
        let dirs: Vec<DVec3> = sphere_dirs(200)
            .into_iter()
            .flat_map(|c| {
                let u = c.any_orthonormal_vector();
                [c, (c + u * (1.0 / m.sea)).normalize()]
            })
            .collect();
        for dir in &dirs {
            let (_, h) = full(&m, *dir);
            for step in [1.0, 16.0, 1024.0, 65_536.0] {
                let r0 = (h / step).floor() * step;
                let a: Vec<f64> = (-34..=0).map(|i| r0 + step * f64::from(i)).collect();
                let b: Vec<f64> = (0..=34).map(|i| r0 + step * f64::from(i)).collect();
                let (mut va, mut vb) = (vec![0.0f32; 35], vec![0.0f32; 35]);
                d.sample_shell(&[*dir], &a, &mut va);
                d.sample_shell(&[*dir], &b, &mut vb);
                assert_eq!(va[34].to_bits(), vb[0].to_bits(), "step {step}");
                let mut one = [0.0f32];
                d.sample_shell(&[*dir], &[r0], &mut one);
                assert_eq!(one[0].to_bits(), vb[0].to_bits());
            }
        }
    }

    #[test]
    fn batch_matches_points_and_is_deterministic() {
        let (_, m, d) = earth(7);
        let centre = sphere_dirs(4000)
            .into_iter()
            .find(|dir| {
                let (c, h) = full(&m, *dir);
                c.cave_gate > 0.5 && h > m.sea + 100.0
            })
            .expect("land with caves");
        let (_, h) = full(&m, centre);
        let patch = patch(centre, 1.2, 12, h - 40.0, 1.0, 50);
        check_batch_matches_points(&d, &patch, 1e-3);
        // And far from the surface, at coarse strides.
        let coarse = super::super::testing::patch(centre, 5000.0, 6, h - 8000.0, 1000.0, 17);
        check_batch_matches_points(&d, &coarse, 1e-3);
    }

    #[test]
    fn a_batch_stops_refining_early_with_the_same_bits_as_points() {
        // Columns stop refining once no sample of the batch needs more: a batch of layers far
        // apart stops early, and every sample keeps the point call's bits, in increasing or any
        // other order of radii.
        let (_, m, d) = earth(7);
        for (n, dir) in sphere_dirs(60).into_iter().enumerate() {
            let (_, h) = full(&m, dir);
            for step in [1.0, 8.0, 128.0, 4096.0] {
                let r0 = (h / step).floor() * step - 17.0 * step + 0.37 * (n as f64);
                let mut radii: Vec<f64> = (0..35).map(|i| r0 + step * f64::from(i)).collect();
                for pass in 0..2 {
                    let mut out = vec![0.0f32; radii.len()];
                    d.sample_shell(&[dir], &radii, &mut out);
                    for (r, v) in radii.iter().zip(&out) {
                        let point = d.density(dir * *r) as f32;
                        assert_eq!(
                            v.to_bits(),
                            point.to_bits(),
                            "step {step}, pass {pass}, r - h = {}",
                            r - h
                        );
                    }
                    radii.reverse();
                }
            }
        }
    }

    #[test]
    fn surface_within_bounds_at_true_scale() {
        // Sparser than the shared check (the shell is 32 768 voxels deep).
        let (layout, _, d) = earth(3);
        let (lo, hi) = d.radial_bounds().unwrap();
        let radii: Vec<f64> = (0..=1024).map(|k| layout.layer_radius(32 * k)).collect();
        let dirs = sphere_dirs(1000);
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        d.sample_shell(&dirs, &radii, &mut out);
        for (k, r) in radii.iter().enumerate() {
            for v in &out[k * dirs.len()..(k + 1) * dirs.len()] {
                if *r < lo {
                    assert!(*v > 0.0, "air below the lower bound at {r}");
                }
                if *r > hi {
                    assert!(*v <= 0.0, "solid above the upper bound at {r}");
                }
            }
        }
    }

    #[test]
    fn works_on_small_layouts() {
        for layout in [
            Layout::default(),
            Layout::new(2, 8, 200.0, 2.0, 1).unwrap(),
            PresetKind::Earth.default_layout(Some(20_000.0)).unwrap(),
        ] {
            let t = build(3, &layout);
            check_surface_within_bounds(&t, &layout);
            let other = build(4, &layout);
            check_seeds_differ(&*t.density, &*other.density, &layout);
            assert_eq!(
                t.sea_radius,
                Some(layout.d_b() + 0.5 * layout.l_d() * layout.depth_tiles() as f64)
            );
        }
    }

    #[test]
    fn same_planet_at_every_scale() {
        // Shrunk onto the default layout, the continents are where they are at true scale.
        let (_, big, _) = earth(5);
        let small = EarthModel::new(5, &Layout::default());
        let dirs = sphere_dirs(2000);
        let agree = dirs
            .iter()
            .filter(|d| (full(&big, **d).1 > big.sea) == (full(&small, **d).1 > small.sea))
            .count();
        assert!(agree * 100 > dirs.len() * 90, "{agree} of {}", dirs.len());
    }

    #[test]
    fn golden_values() {
        // A fixed seed gives fixed bits. Direction 24 is a coastal lowland (30 m) with caves, so
        // its radii 10 to 31 m above the sea cross the 3D band; the others are far from it.
        let (_, _, d) = earth(7);
        let all = sphere_dirs(40);
        let dirs = [all[24], all[3], all[11], all[0]];
        let radii = [-3000.0, 10.0, 25.0, 29.0, 31.0, 80.0, 4e5].map(|z| EARTH_RADIUS + z);
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        d.sample_shell(&dirs, &radii, &mut out);
        let bits: Vec<u32> = out.iter().map(|v| v.to_bits()).collect();
        assert_eq!(bits, GOLDEN, "values now: {out:?}");
        for (i, dir) in dirs.iter().enumerate() {
            assert_eq!((d.density(*dir * radii[6]) as f32).to_bits(), GOLDEN[6 * 4 + i]);
        }
    }

    const GOLDEN: [u32; 28] = [
        1161558163, 1162496898, 1163982681, 3291377753, 1100993642, 1132375983, 1141563578, 3311600104, 1084182953,
        1131392943, 1141317818, 3311661544, 1063810274, 1131130799, 1141252282, 3311677928, 3213362494, 1130999727,
        1141219514, 3311686120, 3259692377, 1127700414, 1139982708, 3311886824, 3368242866, 3368234533, 3368230208,
        3368363998,
    ];

    #[test]
    fn cave_rock_is_decided_by_the_full_height() {
        // The shader refines a column only until the comparison with the cave depth is settled:
        // the answer is that of the full ladder, and columns without caves are never cave rock.
        let (_, m, _) = earth(7);
        let materials = EarthMaterials::new(m.clone(), 7);
        let (mut caves, mut plain) = (0, 0);
        for dir in sphere_dirs(3000) {
            let (c, h) = full(&m, dir);
            if h < m.sea + 20.0 {
                continue;
            }
            let depth = (1.5 * m.s.l_d).max(c.a_rock + c.a_cliff + m.s.l_d);
            for dz in [-60.0, -20.0, -8.0, -3.0, -depth - 0.01, -depth + 0.01, -1.0, 0.0, 2.0] {
                let r = h + dz;
                let cave = materials.material(dir * r, dir) == CAVE;
                assert_eq!(
                    cave,
                    c.cave_gate > 0.0 && h - r > depth,
                    "dz {dz}, gate {}",
                    c.cave_gate
                );
                if cave {
                    caves += 1;
                } else {
                    plain += 1;
                }
            }
        }
        assert!(caves > 100 && plain > 100, "{caves} cave, {plain} other");
    }

    #[test]
    fn the_one_way_walk_finds_the_entry_the_search_finds() {
        // `values_sorted` (two pointers over nested intervals) against `value` (a binary search
        // per sample), bit for bit, on columns refined to every depth and radii across the surface.
        let (_, m, _) = earth(7);
        let mut checked = 0;
        for (i, dir) in sphere_dirs(300).into_iter().enumerate() {
            let (_, h) = full(&m, dir);
            let spacing = [0.5, 1.0, 8.0, 200.0][i % 4];
            let rs: Vec<f64> = (0..40).map(|k| h - 20.0 * spacing + f64::from(k) * spacing).collect();
            let mut col = m.column(dir);
            m.refine_batch(&mut col, dir, &rs, true);
            let mut got = vec![0.0; rs.len()];
            m.values_sorted(&col, dir, &rs, |k, v| got[k] = v);
            for (k, r) in rs.iter().enumerate() {
                assert_eq!(got[k].to_bits(), m.value(&col, dir, *r).to_bits(), "dir {i}, layer {k}");
                checked += 1;
            }
        }
        assert_eq!(checked, 300 * 40);
    }

    #[test]
    fn a_batch_of_one_sign_is_told_by_the_ends_of_its_columns() {
        // Patches of land (hills, mountains with cliffs, cave regions) and sea, with layers from
        // far below the surface to far above it, at spacings of one voxel to a coarse level's:
        // wherever `uniform_sign` says a sign, the batch gives every sample that sign, cold or
        // warm; batches across the surface are never told one sign; and most batches of one
        // sign outside the 3D terms' reach are told.
        let (layout, m, warm) = earth(7);
        let dirs_all = sphere_dirs(400);
        let mut picks: Vec<DVec3> = Vec::new();
        let mut want = |pred: &dyn Fn(&EarthColumn, f64) -> bool, n: usize| {
            picks.extend(
                dirs_all
                    .iter()
                    .copied()
                    .filter(|d| {
                        let (c, h) = full(&m, *d);
                        pred(&c, h)
                    })
                    .take(n),
            )
        };
        want(&|c, _| c.mountains > 0.3 && c.a_cliff > 0.0, 2);
        want(&|c, _| c.cave_gate > 0.5, 2);
        want(&|_, h| h < m.sea - 2000.0, 1);
        want(&|c, h| h > m.sea && c.mountains == 0.0, 1);
        assert_eq!(picks.len(), 6, "patches of every kind");
        let l_d = layout.l_d();
        let (mut told, mut one_sign, mut far) = (0, 0, 0);
        for base in picks {
            let h = full(&m, base).1;
            let step = 3.0 * l_d / m.sea;
            let (u, w) = base.any_orthonormal_pair();
            let dirs: Vec<DVec3> = (0..64)
                .map(|i| (base + u * (step * f64::from(i % 8)) + w * (step * f64::from(i / 8))).normalize())
                .collect();
            for spacing in [1.0f64, 2.0, 16.0] {
                for from in (-160..=60).step_by(4) {
                    let radii: Vec<f64> = (0..35)
                        .map(|k| h + f64::from(from) * l_d * spacing.min(4.0) + f64::from(k) * spacing * l_d)
                        .collect();
                    let mut out = vec![0.0f32; dirs.len() * radii.len()];
                    EarthDensity::new(m.clone()).sample_shell(&dirs, &radii, &mut out);
                    let solid = out.iter().filter(|v| **v > 0.0).count();
                    let sign = (solid == 0 || solid == out.len()).then_some(solid > 0);
                    let cold = EarthDensity::new(m.clone()).uniform_sign(&dirs, &radii);
                    let hot = warm.uniform_sign(&dirs, &radii);
                    assert_eq!(cold, hot, "a warm cache tells what a cold one does");
                    if let Some(s) = cold {
                        assert_eq!(
                            sign,
                            Some(s),
                            "told {s} for a batch of {solid} solid samples of {}",
                            out.len()
                        );
                        told += 1;
                    }
                    if sign.is_some() {
                        one_sign += 1;
                        // clear of the 3D terms (caves reach under 70 voxels down, the rest
                        // 18 up) by a margin for the other columns' heights
                        if radii[0] > h + 40.0 * l_d || radii[34] < h - 120.0 * l_d {
                            far += 1;
                            assert!(cold.is_some(), "a batch clear of the surface is told its sign");
                        }
                    }
                }
            }
        }
        assert!(
            far > 100 && told >= far,
            "{told} told of {one_sign} of one sign ({far} clear of the surface)"
        );
        assert!(told < one_sign, "some batches near the surface cannot be told");
    }

    #[test]
    fn kept_columns_give_the_same_bits() {
        // Batches over the same directions at other radii (other chunks of the column, and
        // neighbours sharing border directions) leave columns refined to other depths in the
        // density's cache; a batch reading them gives the bits of a density that never saw them.
        let (layout, m, warm) = earth(7);
        let base = sphere_dirs(300)
            .into_iter()
            .find(|dir| full(&m, *dir).1 > m.sea + 800.0)
            .expect("a land column");
        let h = full(&m, base).1;
        let step = 3.0 * m.s.l_d / m.sea;
        let (u, w) = base.any_orthonormal_pair();
        let dirs: Vec<DVec3> = (0..100)
            .map(|i| (base + u * (step * f64::from(i % 10)) + w * (step * f64::from(i / 10))).normalize())
            .collect();
        let layers = |from: f64, spacing: f64| (0..35).map(|k| from + f64::from(k) * spacing).collect::<Vec<f64>>();
        let l_d = layout.l_d();
        // chunks above, across and below the surface, at two levels, some twice
        let batches = [
            layers(h + 20.0 * l_d, l_d),
            layers(h - 15.0 * l_d, l_d),
            layers(h - 60.0 * l_d, 2.0 * l_d),
            layers(h - 50.0 * l_d, l_d),
            layers(h - 15.0 * l_d, l_d),
            layers(h - 200.0 * l_d, 16.0 * l_d),
        ];
        let mut warm_out = vec![0.0f32; dirs.len() * 35];
        for (b, radii) in batches.iter().enumerate() {
            // the cold density is a new one each time: it keeps nothing from the others
            let cold = EarthDensity::new(m.clone());
            let mut cold_out = vec![0.0f32; dirs.len() * 35];
            cold.sample_shell(&dirs, radii, &mut cold_out);
            warm.sample_shell(&dirs, radii, &mut warm_out);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&warm_out), bits(&cold_out), "batch {b}");
            let mut kept = ShellColumns::default();
            let mut kept_out = vec![0.0f32; dirs.len() * 35];
            warm.sample_shell_keeping(&dirs, radii, &mut kept_out, &mut kept);
            assert_eq!(bits(&kept_out), bits(&cold_out), "batch {b}, keeping");
        }
        // A cache of three columns a shard recycles its slots all the time (a slot then holds
        // the entries of deeper columns past the `done` of the one copied in), and one keeper
        // reused over batches of other directions holds other columns in every slot: the same
        // bits again.
        let small = EarthDensity(m.clone(), ColumnCache::with_generation(3));
        let mut kept = ShellColumns::default();
        for round in 0..3 {
            for (b, radii) in batches.iter().enumerate() {
                let mut these = dirs.clone();
                if (b + round) % 2 == 1 {
                    these.reverse();
                }
                these.truncate(100 - 10 * ((b + round) % 4));
                let mut cold_out = vec![0.0f32; these.len() * 35];
                EarthDensity::new(m.clone()).sample_shell(&these, radii, &mut cold_out);
                let mut out = vec![0.0f32; these.len() * 35];
                small.sample_shell_keeping(&these, radii, &mut out, &mut kept);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&out), bits(&cold_out), "round {round}, batch {b}, a small cache");
            }
        }
        // and a point call agrees with the warm batch as with a cold one
        for (k, r) in batches[1].iter().enumerate() {
            let p = dirs[3] * *r;
            assert_eq!(warm.density(p), EarthDensity::new(m.clone()).density(p), "layer {k}");
        }
    }

    #[test]
    fn edge_vertices_are_cave_rock_by_the_full_heights_of_their_ends() {
        // A chunk's vertex is cave rock when it lies deeper than the cave depth under the height
        // interpolated between its edge's ends, whatever those columns were refined to by the
        // batch (refined copies settle the comparison): the answer of the full ladders.
        let (_, m, _) = earth(7);
        let dirs = sphere_dirs(2000);
        let (mut caves, mut plain) = (0, 0);
        for (i, pair) in dirs.windows(2).enumerate() {
            let (da, db) = (pair[0], pair[1]);
            let ((fa, ha), (fb, hb)) = (full(&m, da), full(&m, db));
            if ha.min(hb) < m.sea + 20.0 {
                continue;
            }
            // Columns refined to different depths, as batches leave them.
            let mut ca = m.column(da);
            for _ in 0..(i % 9) * 3 {
                m.advance(&mut ca, da);
            }
            let cb = m.column(db);
            for t in [0.0, 0.25, 0.5, 1.0] {
                let h = lerp(ha, hb, t);
                let depth = 3.0 + 10.0 * t;
                for dz in [-40.0, -depth - 0.01, -depth + 0.01, -1.0, 0.0, 3.0] {
                    let r = h + dz;
                    let deeper = m.lerp_deeper_than((&ca, da), (&cb, db), t, r, depth);
                    assert_eq!(deeper, h - r > depth, "t {t}, dz {dz}");
                    // The same with the full columns given.
                    assert_eq!(deeper, m.lerp_deeper_than((&fa, da), (&fb, db), t, r, depth));
                    if deeper {
                        caves += 1;
                    } else {
                        plain += 1;
                    }
                }
            }
        }
        assert!(caves > 100 && plain > 100, "{caves} deeper, {plain} not");
    }

    #[test]
    fn edge_vertices_shade_alike_with_and_without_the_batch_columns() {
        // The shader reads the columns the chunk's batch kept (refined as far as its layers
        // needed); computed afresh they give the same shades, and a radial edge's vertex takes
        // its column's fields and the cave test of its full height.
        use crate::presets::EdgeVertices;
        use crate::ShellColumns;
        use pmc_geometry::VertexEdge;
        let (layout, m, d) = earth(7);
        let ter = build(7, &layout);
        let base = sphere_dirs(400)
            .into_iter()
            .find(|dir| full(&m, *dir).1 > m.sea + 500.0 && m.column(*dir).cave_gate > 0.0)
            .expect("a land column with caves");
        let step = 2.0 * m.s.l_d / m.sea;
        let (u, w) = base.any_orthonormal_pair();
        let dirs: Vec<DVec3> = (0..64)
            .map(|i| (base + u * (step * f64::from(i % 8)) + w * (step * f64::from(i / 8))).normalize())
            .collect();
        let heights: Vec<f64> = dirs.iter().map(|dir| full(&m, *dir).1).collect();
        let edges: Vec<VertexEdge> = (0..64u32)
            .flat_map(|i| {
                [
                    VertexEdge { a: i, b: i, t: 0.0 },
                    VertexEdge {
                        a: i,
                        b: (i + 1) % 64,
                        t: f64::from(i % 5) / 4.0,
                    },
                ]
            })
            .collect();
        let points: Vec<DVec3> = edges
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let (a, b) = (dirs[e.a as usize], dirs[e.b as usize]);
                let h = lerp(heights[e.a as usize], heights[e.b as usize], e.t);
                let dz = [0.0, -2.0 * m.s.l_d, -30.0 * m.s.l_d, 0.5][k % 4];
                (a + (b - a) * e.t).normalize() * (h + dz)
            })
            .collect();
        let normals: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
        // The layers of a chunk around the surface.
        let h0 = heights[0];
        let radii: Vec<f64> = (0..35).map(|k| h0 - 20.0 + f64::from(k) * m.s.l_d).collect();
        let mut kept = ShellColumns::default();
        let mut out = vec![0.0f32; dirs.len() * radii.len()];
        d.sample_shell_keeping(&dirs, &radii, &mut out, &mut kept);
        assert!(!kept.is_empty(), "the earth batch keeps its columns");
        let mut plain = vec![0.0f32; out.len()];
        d.sample_shell(&dirs, &radii, &mut plain);
        assert_eq!(
            out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            plain.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "keeping the columns changes no sample"
        );
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
        let caves = from_batch.iter().filter(|s| s.material == CAVE).count();
        assert!(caves > 0 && caves < from_batch.len(), "{caves} cave vertices");
        // Radial edges: cave rock exactly where the point is deeper than the cave depth under its
        // column's full height.
        for (k, (e, s)) in edges.iter().zip(&from_batch).enumerate() {
            if e.a != e.b {
                continue;
            }
            let c = m.column(dirs[e.a as usize]);
            let depth = (1.5 * m.s.l_d).max(c.a_rock + c.a_cliff + m.s.l_d);
            let r = points[k].length();
            let deep = c.cave_gate > 0.0 && heights[e.a as usize] - r > depth;
            assert_eq!(s.material == CAVE, deep, "vertex {k}");
        }
    }

    #[test]
    fn shader_tells_the_seabed_the_beach_and_the_peaks_apart() {
        let (_, m, _) = earth(1);
        let t = build(1, &PresetKind::Earth.default_layout(None).unwrap());
        let mat = |p: DVec3, n: DVec3| MATERIALS[usize::from(t.shader.shade(p, n).material)];
        let (mut beach, mut seabed, mut peak) = (None, None, None::<(f64, DVec3)>);
        for dir in sphere_dirs(40_000) {
            let (_, h) = full(&m, dir);
            let z = h - m.sea;
            if z > 0.3 && z < 2.0 && beach.is_none() {
                beach = Some(dir * h);
            }
            if z < -3000.0 && seabed.is_none() {
                seabed = Some(dir * h);
            }
            if dir.y.abs() < 0.5 && peak.is_none_or(|(best, _)| z > best) {
                peak = Some((z, dir * h));
            }
        }
        let beach = beach.expect("a beach");
        assert_eq!(mat(beach, beach.normalize()), "sand");
        let seabed = seabed.expect("deep sea");
        assert_eq!(mat(seabed, seabed.normalize()), "seabed");
        let (z, peak) = peak.unwrap();
        assert!(z > 5500.0, "highest tropical peak {z}");
        assert_eq!(mat(peak, peak.normalize()), "snow");
        // A cliff is rock, deep underground is cave rock.
        let side = peak.normalize().any_orthonormal_vector();
        assert_eq!(mat(peak, side), "rock");
        assert_eq!(mat(peak * (1.0 - 40.0 / peak.length()), peak.normalize()), "cave");
        // Grass and forest both occur on the lowlands.
        let mut seen = std::collections::HashSet::new();
        for dir in sphere_dirs(6000) {
            let (_, h) = full(&m, dir);
            if h > m.sea + 50.0 {
                seen.insert(mat(dir * h, dir));
            }
        }
        for name in ["grass", "forest", "rock", "sand", "snow"] {
            assert!(seen.contains(name), "no {name} on the land: {seen:?}");
        }
    }
}
