//! The planet instance and its chunk pipeline.

use pmc_density::presets::{self, PresetKind, Terrain};
use pmc_density::Density;
use pmc_edit::{affected_chunks, paint_at, BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, EdgeKey, Layout};
use pmc_mesh::{close_shell, ChunkMesh, Mesher};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A planet: its layout, terrain and edits.
///
/// Edits (an [`EditSnapshot`] of brush operations, see [`Planet::set_edits`]) apply on top of the
/// terrain: shaping brushes through an [`EditedDensity`], paint brushes when vertices are shaded.
/// [`Planet::terrain`] keeps the unedited terrain; [`Planet::density`] is what chunks mesh.
#[derive(Clone)]
pub struct Planet {
    layout: Layout,
    terrain: Terrain,
    edits: EditSnapshot,
    density: Arc<dyn Density>,
}

impl std::fmt::Debug for Planet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Planet")
            .field("layout", &self.layout)
            .field("terrain", &self.terrain)
            .field("edits", &self.edits.len())
            .finish()
    }
}

/// Per-thread scratch buffers for [`Planet::chunk_mesh_into`].
#[derive(Debug, Default)]
pub struct ChunkScratch {
    mesher: Mesher,
    densities: Vec<f32>,
    /// Vertex index of each edge key of a previous mesh, for [`Planet::remesh_reusing`].
    previous: HashMap<EdgeKey, u32>,
}

/// A chunk's mesh before an edit, whose shading can be reused where the edit changed nothing.
#[derive(Clone, Copy)]
struct Reuse<'a> {
    previous: &'a ChunkMesh,
    op: &'a BrushOp,
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
        let density = terrain.density.clone();
        Planet {
            layout,
            terrain,
            edits: EditSnapshot::default(),
            density,
        }
    }

    /// This planet with `edits` applied (replacing any earlier edits).
    pub fn with_edits(mut self, edits: EditSnapshot) -> Planet {
        self.set_edits(edits);
        self
    }

    /// Replaces the edits: from now on chunks mesh the terrain with `edits` applied in order
    /// (typically [`pmc_edit::EditLog::snapshot`] after a push, undo or redo). Cheap: the snapshot
    /// is shared, nothing is meshed. An empty snapshot gives back the unedited planet exactly.
    pub fn set_edits(&mut self, edits: EditSnapshot) {
        self.density = if edits.iter().any(BrushOp::shapes) {
            Arc::new(EditedDensity::new(self.terrain.density.clone(), edits.clone()))
        } else {
            self.terrain.density.clone()
        };
        self.edits = edits;
    }

    /// The edits applied.
    pub fn edits(&self) -> &EditSnapshot {
        &self.edits
    }

    /// The density chunks mesh: the terrain's with the shaping edits applied.
    pub fn density(&self) -> &Arc<dyn Density> {
        &self.density
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The terrain, unedited (see [`Planet::density`] for the edited density).
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

    /// Whether a chunk may hold surface, judged from the (edited) density's radial bounds and the
    /// shell boundary contract alone (no sampling).
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
            match self.density.radial_bounds() {
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
        self.mesh_chunk(key, scratch, out, None);
    }

    /// The chunk pipeline, shading from `reuse` where it can.
    fn mesh_chunk(&self, key: ChunkKey, scratch: &mut ChunkScratch, out: &mut ChunkMesh, reuse: Option<Reuse>) {
        let grid = ChunkGrid::new(&self.layout, key);
        if !self.may_hold_surface(&key) {
            out.clear();
            out.key = Some(key);
            out.origin = grid.origin;
            return;
        }
        scratch.densities.resize(grid.sample_count(), 0.0);
        self.density
            .sample_shell(&grid.dirs, &grid.radii, &mut scratch.densities);
        close_shell(&grid, self.layout.depth_tiles(), &mut scratch.densities);
        scratch.mesher.mesh(&grid, &scratch.densities, out);
        self.shade(out, reuse.map(|r| (r, &mut scratch.previous)));
    }

    /// Meshes one chunk (allocating fresh buffers).
    pub fn chunk_mesh(&self, key: ChunkKey) -> ChunkMesh {
        let mut out = ChunkMesh::default();
        self.chunk_mesh_into(key, &mut ChunkScratch::default(), &mut out);
        out
    }

    /// Meshes the chunks that `op` can change ([`pmc_edit::affected_chunks`]), in key order,
    /// on the calling thread: after pushing or undoing `op` and [`Planet::set_edits`], these are
    /// the meshes to replace (empty ones included, with key and origin set, so a cache can drop
    /// them). Every other chunk's mesh is unchanged by `op`.
    pub fn remesh(&self, op: &BrushOp) -> Vec<ChunkMesh> {
        let mut scratch = ChunkScratch::default();
        affected_chunks(&self.layout, op)
            .into_iter()
            .map(|key| {
                let mut m = ChunkMesh::default();
                self.chunk_mesh_into(key, &mut scratch, &mut m);
                m
            })
            .collect()
    }

    /// [`Planet::remesh`], reusing the shading of vertices the edit did not touch: `previous(key)`
    /// must give the chunk's mesh under the edits this planet had without `op` (before `op` was
    /// pushed, or before it was undone), or `None`. A vertex is shaded anew unless the previous
    /// mesh has a vertex on the same grid edge with the same position and normal bits, lying
    /// outside the brush's reach; shading is a function of exactly those (and of the paint
    /// brushes holding the vertex, which outside the reach are the same), so the result is
    /// byte-identical to [`Planet::remesh`], only faster (shading is about half of a chunk's time
    /// on the presets).
    pub fn remesh_reusing<'a>(
        &self,
        op: &BrushOp,
        previous: impl Fn(&ChunkKey) -> Option<&'a ChunkMesh>,
    ) -> Vec<ChunkMesh> {
        let mut scratch = ChunkScratch::default();
        affected_chunks(&self.layout, op)
            .into_iter()
            .map(|key| {
                let mut m = ChunkMesh::default();
                let reuse = previous(&key).map(|previous| Reuse { previous, op });
                self.mesh_chunk(key, &mut scratch, &mut m, reuse);
                m
            })
            .collect()
    }

    /// The paint brushes that may hold a vertex of `m` and name one of the terrain's materials.
    fn paints_for(&self, m: &ChunkMesh) -> Vec<BrushOp> {
        let n_materials = self.terrain.materials.len();
        let mut paints = self
            .edits
            .iter()
            .filter(|op| matches!(op.kind, BrushKind::Paint { material } if usize::from(material) < n_materials));
        let Some(first) = paints.next() else {
            return Vec::new();
        };
        let radius = m
            .positions
            .iter()
            .map(|p| DVec3::from(p.map(f64::from)).length())
            .fold(0.0, f64::max)
            * (1.0 + 1e-6)
            + 1e-6;
        std::iter::once(first)
            .chain(paints)
            .filter(|op| op.touches_ball(m.origin, radius))
            .copied()
            .collect()
    }

    /// Fills the per-vertex attributes: height above the datum, water depth, colour, material.
    /// A vertex inside a paint brush takes the painted material, and its colour mixed toward the
    /// material's colour by the brush strength (see [`pmc_density::presets::Shader::shade_material`]).
    /// With `reuse`, vertices unchanged by the edit copy their attributes from the previous mesh
    /// (see [`Planet::remesh_reusing`]), looked up through the scratch map that comes with it.
    fn shade(&self, m: &mut ChunkMesh, reuse: Option<(Reuse, &mut HashMap<EdgeKey, u32>)>) {
        let datum = self.datum_radius();
        let sea = self.terrain.sea_radius;
        let paints = self.paints_for(m);
        let n = m.vertex_count();
        m.heights.reserve(n);
        m.water_depths.reserve(n);
        m.colors.reserve(n);
        m.materials.reserve(n);
        let reuse = reuse.filter(|(r, _)| r.previous.origin == m.origin && r.previous.has_attributes());
        let reuse = reuse.map(|(r, index)| {
            index.clear();
            index.extend(r.previous.edge_keys.iter().enumerate().map(|(j, k)| (*k, j as u32)));
            (r, &*index)
        });
        for i in 0..n {
            let p = m.world_position(i);
            if let Some((r, index)) = &reuse {
                let same = |j: &u32| {
                    let j = *j as usize;
                    let bits = |v: [f32; 3]| v.map(f32::to_bits);
                    bits(r.previous.positions[j]) == bits(m.positions[i])
                        && bits(r.previous.normals[j]) == bits(m.normals[i])
                };
                let outside = (p - r.op.center).length() >= r.op.reach();
                if let Some(j) = index.get(&m.edge_keys[i]).filter(|j| outside && same(j)) {
                    let j = *j as usize;
                    let prev = r.previous;
                    m.heights.push(prev.heights[j]);
                    m.water_depths.push(prev.water_depths[j]);
                    m.colors.push(prev.colors[j]);
                    m.materials.push(prev.materials[j]);
                    continue;
                }
            }
            let r = p.length();
            let nrm = DVec3::from(m.normals[i].map(f64::from));
            let mut shade = self.terrain.shader.shade(p, nrm);
            if let Some((material, strength)) = paint_at(&paints, p) {
                let paint = self.terrain.shader.shade_material(material, p);
                let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * strength).round() as u8;
                shade.color = [0, 1, 2, 3].map(|k| mix(shade.color[k], paint.color[k]));
                shade.material = material;
            }
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
