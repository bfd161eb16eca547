//! A planet meshed as a height field (seed 003 Sec. 4-6): six quadtrees of 65 x 65 patches
//! (`pmc_heightfield`), served through the same chunk interface as the marching cubes.
//!
//! # Patches as chunks
//!
//! A heightfield planet has a *patch layout*: `n_t = 64` (a patch's 64 segments), `n_c = 2^P`
//! (`P` the deepest patch level, about 1 m between vertices), one chunk along depth whose shell
//! `[d_b, radius]` holds every height. Chunk `(face, L, i, j, 0)` is patch `(face, P - L, i, j)`:
//! chunk level 0 is the finest patch level, and a chunk's parent is its patch's parent, so the
//! chunk level-of-detail selection (its provable bounding spheres from the shell, its 2:1
//! balance across sides, face edges and cube corners) chooses a restricted quadtree of patches,
//! and a chunk side that faces a coarser chunk is the patch side to stitch. Everything that
//! streams chunks (the server, the viewer) streams patches unchanged.
//!
//! The terrain (density, shader, sea) is the elevation model's volumetric terrain on its own
//! layout: patches are shaded by its shader, and walking, flights and probes use its density.
//! Edits do not apply to patches (a height field has no caves to dig): worlds use the
//! volumetric planet.

use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{ChunkKey, ChunkSide, Face, Layout, LayoutError, SideMask};
use pmc_heightfield::{generate_patch, lattice_direction, LatticeHeights, PatchKey, Side, Stitch, PATCH_SEGMENTS};
use pmc_mesh::ChunkMesh;
use std::sync::Arc;

/// Metres between the vertices of the finest patches, about.
pub const FINEST_SPACING: f64 = 1.0;

/// The deepest patch level allowed (the layout's axis limit: `64 * 2^18 = 2^24` tiles a face).
const MAX_PATCH_LEVEL: u32 = 18;

/// The height-field meshing of a planet: its heights, datum and patch levels.
pub struct HeightfieldMode {
    heights: Arc<dyn LatticeHeights>,
    datum: f64,
    max_patch_level: u8,
    errors: Vec<f64>,
}

impl std::fmt::Debug for HeightfieldMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeightfieldMode")
            .field("datum", &self.datum)
            .field("max_patch_level", &self.max_patch_level)
            .finish_non_exhaustive()
    }
}

impl HeightfieldMode {
    /// Patches of `heights` (metres above `datum`, within `bounds`) down to about
    /// [`FINEST_SPACING`] between vertices; returns the mode and its patch layout.
    pub fn new(
        heights: Arc<dyn LatticeHeights>,
        datum: f64,
        bounds: (f64, f64),
    ) -> Result<(HeightfieldMode, Layout), LayoutError> {
        let arc = std::f64::consts::FRAC_PI_2 * datum;
        let levels = (arc / (f64::from(PATCH_SEGMENTS) * FINEST_SPACING)).log2().round();
        let p = (levels.max(0.0) as u32).min(MAX_PATCH_LEVEL);
        // A shell with a little room around the heights.
        let (lo, hi) = bounds;
        let margin = 1e-3 * (hi - lo).max(1.0);
        let d_b = datum + lo - margin;
        let l_d = (hi - lo + 2.0 * margin) / f64::from(PATCH_SEGMENTS);
        let layout = Layout::new(1 << p, PATCH_SEGMENTS, d_b, l_d, 1)?;
        let mut mode = HeightfieldMode {
            heights,
            datum,
            max_patch_level: p as u8,
            errors: Vec::new(),
        };
        mode.errors = mode.measure_errors(256, 0x5eed);
        Ok((mode, layout))
    }

    /// The radius heights are measured from.
    pub fn datum(&self) -> f64 {
        self.datum
    }

    /// The deepest patch level (chunk level 0).
    pub fn max_patch_level(&self) -> u8 {
        self.max_patch_level
    }

    /// The patch a chunk key of the patch layout stands for (depth index 0 only).
    pub fn patch_of(&self, key: &ChunkKey) -> Option<PatchKey> {
        if key.k != 0 || key.level > self.max_patch_level {
            return None;
        }
        PatchKey::new(key.face, self.max_patch_level - key.level, key.i, key.j).ok()
    }

    /// The radii (metres from the planet's centre) between which every vertex of the mesh of
    /// chunk `key` lies, whatever its stitching: the datum plus the least and the greatest height
    /// of its patch's vertices ([`pmc_heightfield::patch_height_range`], the mesher's bits).
    /// `None` when the key is no patch of this planet. Costs about a patch's heights.
    pub fn patch_radii(&self, key: &ChunkKey) -> Option<(f64, f64)> {
        let patch = self.patch_of(key)?;
        let (lo, hi) = pmc_heightfield::patch_height_range(&*self.heights, patch).ok()?;
        Some((self.datum + lo, self.datum + hi))
    }

    /// The geometric error of each chunk level (index 0 the finest patches, 0 by convention as
    /// for the marching cubes): the 99th percentile, over `samples` random cells of the level, of
    /// the distance from the true surface to the drawn one at the middles of the cells' edges and
    /// at their centres, made non-decreasing.
    pub fn level_errors(&self) -> &[f64] {
        &self.errors
    }

    fn measure_errors(&self, samples: usize, seed: u64) -> Vec<f64> {
        let mut rng = seed;
        let mut next = move || {
            rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = rng;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let p = self.max_patch_level;
        let mut errors = vec![0.0; usize::from(p) + 1];
        let point = |lattice: IVec3, m: i64| {
            lattice_direction(lattice, m) * (self.datum + self.heights.height(lattice, m as i32))
        };
        for level in 1..=p {
            // patch level p - level: cells of resolution m; midpoints at 2m
            let m = i64::from(PATCH_SEGMENTS) << (p - level);
            let mut d = Vec::with_capacity(samples * 3);
            for _ in 0..samples {
                let face = Face::ALL[(next() % 6) as usize];
                let (i, j) = ((next() % m as u64) as i64, (next() % m as u64) as i64);
                let at = |a: i64, b: i64, r: i64| pmc_heightfield::face_lattice(face, a, b, r);
                let (Some(c00), Some(c10), Some(c01), Some(c11)) =
                    (at(i, j, m), at(i + 1, j, m), at(i, j + 1, m), at(i + 1, j + 1, m))
                else {
                    continue;
                };
                let (p00, p10, p01, p11) = (point(c00, m), point(c10, m), point(c01, m), point(c11, m));
                for (mid, drawn) in [
                    (at(2 * i + 1, 2 * j, 2 * m), 0.5 * (p00 + p10)),
                    (at(2 * i, 2 * j + 1, 2 * m), 0.5 * (p00 + p01)),
                    (at(2 * i + 1, 2 * j + 1, 2 * m), 0.25 * (p00 + p10 + p01 + p11)),
                ] {
                    if let Some(mid) = mid {
                        d.push((point(mid, 2 * m) - drawn).length());
                    }
                }
            }
            d.sort_by(f64::total_cmp);
            let e = d.get((d.len() * 99) / 100).or(d.last()).copied().unwrap_or(0.0);
            errors[usize::from(level)] = e.max(errors[usize::from(level) - 1]);
        }
        errors
    }

    /// Meshes the patch of chunk `key` with the sides in `coarser` stitched to the coarser level,
    /// into `out` (cleared first; its key is set to `key`). Returns false (and an empty mesh)
    /// when the key is no patch of this planet.
    pub fn mesh(&self, key: ChunkKey, coarser: SideMask, out: &mut ChunkMesh) -> bool {
        out.clear();
        let Some(patch) = self.patch_of(&key) else {
            out.key = Some(key);
            return false;
        };
        let mut stitch = Stitch::NONE;
        for (side, s) in [
            (ChunkSide::UMin, Side::MinU),
            (ChunkSide::UMax, Side::MaxU),
            (ChunkSide::VMin, Side::MinV),
            (ChunkSide::VMax, Side::MaxV),
        ] {
            if coarser.contains(side) {
                stitch = stitch.with_side(s);
            }
        }
        let ok = generate_patch(&*self.heights, self.datum, patch, stitch, out).is_ok();
        out.key = Some(key);
        // The shader fills these again.
        out.heights.clear();
        out.water_depths.clear();
        out.colors.clear();
        out.materials.clear();
        ok
    }

    /// The surface's direction-to-point map, for tests: the point of lattice `p` at `m`.
    pub fn vertex(&self, p: IVec3, m: i64) -> DVec3 {
        lattice_direction(p, m) * (self.datum + self.heights.height(p, m as i32))
    }
}
