//! The planet instance and its chunk pipeline.

use pmc_density::presets::{self, PresetKind, Terrain};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Layout};
use pmc_mesh::{close_shell, ChunkMesh, Mesher};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A planet: its layout and terrain.
#[derive(Clone, Debug)]
pub struct Planet {
    layout: Layout,
    terrain: Terrain,
}

/// Per-thread scratch buffers for [`Planet::chunk_mesh_into`].
#[derive(Debug, Default)]
pub struct ChunkScratch {
    mesher: Mesher,
    densities: Vec<f32>,
}

/// What the samples of a chunk are known to hold before sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Known {
    Solid,
    Air,
    Unknown,
}

impl Planet {
    /// Builds the terrain of `preset` with `seed` on `layout`.
    pub fn new(preset: PresetKind, seed: u64, layout: Layout) -> Planet {
        let terrain = presets::build(preset, seed, &layout);
        Planet { layout, terrain }
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The terrain.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// The radius heights are measured from: the sea surface when the planet has a sea, else the
    /// middle of the shell.
    pub fn datum_radius(&self) -> f64 {
        self.terrain
            .sea_radius
            .unwrap_or_else(|| 0.5 * (self.layout.d_b() + self.layout.radius()))
    }

    /// Whether a chunk may hold surface, judged from the terrain's radial bounds and the shell
    /// boundary contract alone (no sampling).
    pub fn may_hold_surface(&self, key: &ChunkKey) -> bool {
        let span = i64::from(self.layout.n_t()) * key.stride();
        let k0 = i64::from(key.k) * span;
        let classify = |k: i64| -> Known {
            if k <= 0 {
                return Known::Solid;
            }
            if k >= self.layout.depth_tiles() {
                return Known::Air;
            }
            match self.terrain.density.radial_bounds() {
                Some((lo, _)) if self.layout.layer_radius(k) < lo => Known::Solid,
                Some((_, hi)) if self.layout.layer_radius(k) > hi => Known::Air,
                _ => Known::Unknown,
            }
        };
        let (a, b) = (classify(k0), classify(k0 + span));
        // Radii grow with k, so both ends known and equal means the whole chunk is.
        !(a == b && a != Known::Unknown)
    }

    /// Meshes one chunk into `out`, reusing `scratch`. Chunks that hold no surface give an empty
    /// mesh (with key and origin set).
    ///
    /// # Panics
    /// If `key` is not a chunk of the layout (check with [`Layout::contains_chunk`]).
    pub fn chunk_mesh_into(&self, key: ChunkKey, scratch: &mut ChunkScratch, out: &mut ChunkMesh) {
        let grid = ChunkGrid::new(&self.layout, key);
        if !self.may_hold_surface(&key) {
            out.clear();
            out.key = Some(key);
            out.origin = grid.origin;
            return;
        }
        scratch.densities.resize(grid.sample_count(), 0.0);
        self.terrain
            .density
            .sample_shell(&grid.dirs, &grid.radii, &mut scratch.densities);
        close_shell(&grid, self.layout.depth_tiles(), &mut scratch.densities);
        scratch.mesher.mesh(&grid, &scratch.densities, out);
        self.shade(out);
    }

    /// Meshes one chunk (allocating fresh buffers).
    pub fn chunk_mesh(&self, key: ChunkKey) -> ChunkMesh {
        let mut out = ChunkMesh::default();
        self.chunk_mesh_into(key, &mut ChunkScratch::default(), &mut out);
        out
    }

    /// Fills the per-vertex attributes: height above the datum, water depth, colour, material.
    fn shade(&self, m: &mut ChunkMesh) {
        let datum = self.datum_radius();
        let sea = self.terrain.sea_radius;
        let n = m.vertex_count();
        m.heights.reserve(n);
        m.water_depths.reserve(n);
        m.colors.reserve(n);
        m.materials.reserve(n);
        for i in 0..n {
            let p = m.world_position(i);
            let r = p.length();
            let nrm = DVec3::from(m.normals[i].map(f64::from));
            let shade = self.terrain.shader.shade(p, nrm);
            m.heights.push((r - datum) as f32);
            m.water_depths.push(sea.map_or(0.0, |s| (s - r).max(0.0)) as f32);
            m.colors.push(shade.color);
            m.materials.push(shade.material);
        }
    }

    /// Meshes every level-0 chunk on the current rayon pool. Returns the non-empty meshes in
    /// chunk-key order. `progress` is called with the number of chunks done so far (from any
    /// thread, in increasing order per call site but not necessarily globally).
    pub fn generate(&self, progress: impl Fn(usize) + Sync) -> Vec<ChunkMesh> {
        let keys = self.layout.chunks(0);
        let done = AtomicUsize::new(0);
        let mut meshes: Vec<ChunkMesh> = keys
            .par_iter()
            .map_init(ChunkScratch::default, |scratch, key| {
                let mut m = ChunkMesh::default();
                self.chunk_mesh_into(*key, scratch, &mut m);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1);
                m
            })
            .collect();
        meshes.retain(|m| !m.is_empty());
        meshes
    }
}
