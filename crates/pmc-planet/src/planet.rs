//! The planet instance and its chunk pipeline.

use crate::cache::{BaseCache, BaseCacheStats};
use crate::heightfield::HeightfieldMode;
use crate::terrain::{build_terrain, TerrainError};
use pmc_density::presets::EdgeVertices;
use pmc_density::presets::{self, PresetKind, Terrain};
use pmc_density::terrain::TerrainSpec;
use pmc_density::{Density, ShellColumns};
use pmc_edit::{affected_chunks, paint_at, BrushKind, BrushOp, EditSnapshot, EditedDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, ChunkSide, EdgeKey, Layout, SideMask, VertexEdge};
use pmc_mesh::shell::close_sample;
use pmc_mesh::{close_shell, coarse_voxels, voxel_gradient, ChunkMesh, CubeBox, Mesher, Transition};
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A planet: its layout, terrain and edits.
///
/// Edits (an [`EditSnapshot`] of brush operations, see [`Planet::set_edits`]) apply on top of the
/// terrain: shaping brushes through an [`EditedDensity`], paint brushes when vertices are shaded.
/// [`Planet::terrain`] keeps the unedited terrain; [`Planet::density`] is what chunks mesh.
///
/// Clones are cheap (the terrain, edits and any base density cache are shared).
#[derive(Clone)]
pub struct Planet {
    layout: Layout,
    terrain: Terrain,
    edits: EditSnapshot,
    density: Arc<dyn Density>,
    /// The same as `density` when the edits shape the terrain, typed so that the edits can be
    /// applied over a cached base batch.
    edited: Option<Arc<EditedDensity<Arc<dyn Density>>>>,
    /// Base density batches by chunk, shared by all clones (see [`Planet::with_base_cache`]).
    base_cache: Option<Arc<BaseCache>>,
    /// Height-field meshing instead of marching cubes (see [`Planet::heightfield`]).
    heightfield: Option<Arc<HeightfieldMode>>,
}

impl std::fmt::Debug for Planet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Planet")
            .field("layout", &self.layout)
            .field("terrain", &self.terrain)
            .field("edits", &self.edits.len())
            .field("base_cache", &self.base_cache_stats())
            .finish()
    }
}

/// Per-thread scratch buffers for [`Planet::chunk_mesh_into`].
#[derive(Debug, Default)]
pub struct ChunkScratch {
    mesher: Mesher,
    densities: Vec<f32>,
    /// What the density batch kept per column, for the shader.
    columns: ShellColumns,
    /// The grid of the last chunk meshed, with its layout (a scratch may serve several planets).
    grid: Option<(Layout, ChunkGrid)>,
    /// Per vertex of a mesh remeshed around an edit, the previous mesh's vertex it was copied
    /// from (`u32::MAX`: marched anew).
    copied: Vec<u32>,
    /// Vertex index of each edge key of a previous mesh, for [`Planet::remesh_reusing`].
    previous: EdgeIndex,
}

/// The grid of a marching-cubes mesh (whose vertices' grid edges are in
/// [`ChunkMesh::vertex_edges`]) and what the density batch kept, for [`Planet::shade`].
struct GridEdges<'a> {
    grid: &'a ChunkGrid,
    columns: &'a ShellColumns,
}

/// Vertex index by edge key.
type EdgeIndex = HashMap<EdgeKey, u32, BuildHasherDefault<KeyHasher>>;

thread_local! {
    /// The scratch of [`Planet::remesh`] and [`Planet::remesh_reusing`] on this thread: the
    /// mesher's buffers are about 2.5 MB at `n_t = 32`, and allocating (and faulting in) them
    /// anew for every edit cost as much as meshing a chunk.
    static REMESH_SCRATCH: RefCell<ChunkScratch> = RefCell::new(ChunkScratch::default());
}

/// Runs `f` with this thread's remesh scratch (a fresh one if it is in use further up the stack,
/// as when a `previous` callback remeshes).
fn with_remesh_scratch<R>(f: impl FnOnce(&mut ChunkScratch) -> R) -> R {
    REMESH_SCRATCH.with(|s| match s.try_borrow_mut() {
        Ok(mut s) => f(&mut s),
        Err(_) => f(&mut ChunkScratch::default()),
    })
}

/// A fast hasher for the edge keys of a mesh (two `u128` voxel keys). Not resistant to chosen
/// keys, which is fine: the keys come from the mesher, not from outside.
#[derive(Clone, Copy, Debug, Default)]
struct KeyHasher(u64);

impl KeyHasher {
    #[inline]
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(26) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.add(u64::from(*b));
        }
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }

    #[inline]
    fn write_u128(&mut self, x: u128) {
        self.add(x as u64);
        self.add((x >> 64) as u64);
    }

    /// The state through a 64-bit finaliser (MurmurHash3's), so that the low bits the table
    /// indexes by and the high bits it tags by both depend on every input bit.
    #[inline]
    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

/// A chunk's mesh before an edit, whose shading can be reused where the edit changed nothing.
#[derive(Clone, Copy)]
struct Reuse<'a> {
    previous: &'a ChunkMesh,
    op: &'a BrushOp,
}

/// A [`Reuse`] as [`Planet::shade`] takes it: with the scratch map of the previous mesh's
/// vertices by edge key and, for a mesh remeshed around the edit, the previous vertex each vertex
/// was copied from.
struct Reused<'a, 'b> {
    reuse: Reuse<'a>,
    index: &'b mut EdgeIndex,
    copied: Option<&'b [u32]>,
}

/// What the samples of a chunk are known to hold before sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Known {
    Solid,
    Air,
    Unknown,
}

impl Planet {
    /// Builds the terrain of `preset` with `seed` on `layout` (the same as
    /// [`Planet::from_terrain`] with [`TerrainSpec::Preset`], which cannot fail).
    pub fn new(preset: PresetKind, seed: u64, layout: Layout) -> Planet {
        Planet::with_terrain(presets::build(preset, seed, &layout), layout)
    }

    /// Builds the terrain `spec` describes on `layout`: a preset, or an elevation model (opened
    /// and checked against the spec's digest; see [`build_terrain`](crate::build_terrain)).
    /// [`default_layout`](crate::default_layout) gives the layout a terrain is made for.
    pub fn from_terrain(spec: &TerrainSpec, layout: Layout) -> Result<Planet, TerrainError> {
        Ok(Planet::with_terrain(build_terrain(spec, &layout)?, layout))
    }

    /// A planet of `terrain` (built for `layout`) on `layout`, with no edits.
    pub fn with_terrain(terrain: Terrain, layout: Layout) -> Planet {
        let density = terrain.density.clone();
        Planet {
            layout,
            terrain,
            edits: EditSnapshot::default(),
            density,
            edited: None,
            base_cache: None,
            heightfield: None,
        }
    }

    /// The elevation model `spec` as a height-field planet (seed 003): its chunks are the 65 x 65
    /// patches of six quadtrees on a patch layout (see [`crate::heightfield`]), shaded by the
    /// model's volumetric terrain, whose density walking and probes use. Only elevation models
    /// qualify; edits do not change the patches.
    pub fn heightfield(spec: &TerrainSpec) -> Result<Planet, TerrainError> {
        let (terrain, mode, layout) = crate::terrain::heightfield_parts(spec)?;
        let mut planet = Planet::with_terrain(terrain, layout);
        planet.heightfield = Some(Arc::new(mode));
        Ok(planet)
    }

    /// The height-field meshing, for a planet made by [`Planet::heightfield`].
    pub fn heightfield_mode(&self) -> Option<&HeightfieldMode> {
        self.heightfield.as_deref()
    }

    /// The height-field meshing, shared (for what outlives a borrow of the planet).
    pub fn heightfield_shared(&self) -> Option<Arc<HeightfieldMode>> {
        self.heightfield.clone()
    }

    /// This planet with a cache of the terrain's base density batches for up to `max_chunks`
    /// chunks (when full, batches used again are kept over batches used once); `0` turns caching
    /// off (the default).
    ///
    /// Meshing a chunk samples the terrain's density over the chunk's whole padded grid, and on
    /// the presets that noise is most of a chunk's time. The terrain never changes (edits apply on
    /// top of it), so with the cache a chunk meshed once and meshed again after any edit, undo or
    /// redo copies its base batch and pays only for the edits over it
    /// ([`EditedDensity::apply_edits`]): remeshing the chunks around an edit becomes several times
    /// faster. Meshes are byte-identical with and without the cache, cold or warm.
    ///
    /// Memory: `(n_t + 3)³ × 4` bytes per chunk held (the padded grid in `f32`), for instance
    /// 35³ × 4 = 171 KB at `n_t = 32`, so 1024 chunks hold about 176 MB. Every chunk meshed is
    /// stored, [`Planet::generate`] included; for a one-off whole-planet export leave the cache off.
    ///
    /// The cache is shared by every clone made from the planet afterwards (it stays valid across
    /// [`Planet::set_edits`]) and is safe to use from several threads: a lookup or store holds a
    /// lock only to move an [`Arc`], batches are copied and sampled outside it. Calling this again
    /// gives this planet a new, empty cache (earlier clones keep the old one).
    ///
    /// ```
    /// use pmc_geometry::{ChunkKey, Face, Layout};
    /// use pmc_planet::pmc_edit::{BrushKind, BrushOp};
    /// use pmc_planet::{Planet, PresetKind};
    ///
    /// let layout = Layout::new(2, 8, 60.0, 1.0, 2).unwrap();
    /// let plain = Planet::new(PresetKind::Earthlike, 3, layout);
    /// let mut cached = plain.clone().with_base_cache(64);
    /// let key = ChunkKey::new(Face::Top, 0, 0, 1);
    /// let _ = cached.chunk_mesh(key); // cold: samples the terrain and stores its batch
    /// let dig = BrushOp::new(BrushKind::Remove, pmc_geometry::glam::DVec3::Y * 68.0, 6.0, 1.0).unwrap();
    /// cached.set_edits(vec![dig].into());
    /// let warm = cached.chunk_mesh(key); // warm: the stored batch with the edit applied
    /// assert_eq!(warm, plain.with_edits(vec![dig].into()).chunk_mesh(key));
    /// let stats = cached.base_cache_stats().unwrap();
    /// assert_eq!((stats.chunks, stats.hits, stats.misses), (1, 1, 1));
    /// assert_eq!(stats.bytes, 11 * 11 * 11 * 4); // (n_t + 3)^3 f32 samples
    /// ```
    pub fn with_base_cache(mut self, max_chunks: usize) -> Planet {
        self.base_cache = (max_chunks > 0).then(|| Arc::new(BaseCache::new(max_chunks)));
        self
    }

    /// The base density cache's counts and size, or `None` when the planet has no cache (see
    /// [`Planet::with_base_cache`]).
    pub fn base_cache_stats(&self) -> Option<BaseCacheStats> {
        self.base_cache.as_ref().map(|c| c.stats())
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
        if edits.iter().any(BrushOp::shapes) {
            let edited = Arc::new(EditedDensity::new(self.terrain.density.clone(), edits.clone()));
            self.density = edited.clone();
            self.edited = Some(edited);
        } else {
            self.density = self.terrain.density.clone();
            self.edited = None;
        }
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

    /// The radius of the first surface (of the edited planet) met going down the ray `dir` (a
    /// unit vector) from the top of the shell: the density is sampled every quarter tile
    /// (`l_d / 4`) from the highest radius the surface can reach (the density's radial bounds,
    /// or the shell's top), and the first sign change is refined by bisection. The shell contract
    /// makes the base solid, so the answer is at least `d_b`.
    pub fn surface_radius(&self, dir: DVec3) -> f64 {
        let l = self.layout();
        let density = self.density();
        let solid = |r: f64| density.density(dir * r) > 0.0;
        let (top, bottom) = match density.radial_bounds() {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() => (hi.min(l.radius()).max(l.d_b()), lo.max(l.d_b())),
            _ => (l.radius(), l.d_b()),
        };
        if solid(top) {
            return top;
        }
        let step = l.l_d() / 4.0;
        let mut above = top;
        let steps = ((top - bottom) / step).ceil() as u64;
        for i in 1..=steps {
            let r = (top - i as f64 * step).max(bottom);
            if solid(r) {
                let (mut lo, mut hi) = (r, above);
                for _ in 0..64 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if solid(mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                return 0.5 * (lo + hi);
            }
            above = r;
        }
        bottom
    }

    /// Whether a chunk may hold surface, judged from the (edited) density's radial bounds and the
    /// shell boundary contract alone (no sampling).
    pub fn may_hold_surface(&self, key: &ChunkKey) -> bool {
        if let Some(h) = &self.heightfield {
            return h.patch_of(key).is_some();
        }
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

    /// Whether chunk `key` holds no surface by the planet's bounds alone, without sampling:
    /// outside the density's radial bounds ([`Planet::may_hold_surface`]), or every sample of
    /// its batch of one sign by [`Density::uniform_sign`] (the shell's closure included). Such a
    /// chunk meshes to nothing at its level. (A finer level samples between its samples and may
    /// find what they miss.)
    pub fn holds_no_surface_by_bound(&self, key: &ChunkKey) -> bool {
        if !self.may_hold_surface(key) {
            return true;
        }
        if self.heightfield.is_some() {
            return false;
        }
        self.uniform_by_bound(&ChunkGrid::new(&self.layout, *key))
    }

    /// Whether chunk `key` meshes to nothing: told by the bounds
    /// ([`Planet::holds_no_surface_by_bound`]), or else by sampling its batch (through the base
    /// cache when there is one, which the chunk's meshing then reuses) and finding every voxel
    /// of one side. Exact, at the cost of sampling the chunks the bounds cannot tell.
    pub fn chunk_is_empty(&self, key: &ChunkKey, scratch: &mut ChunkScratch) -> bool {
        if self.holds_no_surface_by_bound(key) {
            return true;
        }
        if self.heightfield.is_some() {
            return false;
        }
        let grid = self.grid_after(*key, scratch.grid.take());
        scratch.densities.resize(grid.sample_count(), 0.0);
        self.sample(*key, &grid, &mut scratch.densities, None);
        close_shell(&grid, self.layout.depth_tiles(), &mut scratch.densities);
        let empty = !pmc_mesh::has_sign_change(&grid, &scratch.densities);
        scratch.grid = Some((self.layout, grid));
        empty
    }

    /// Whether the chunk of `grid` holds no surface by the density's own bound: every sample of
    /// its batch has one sign ([`Density::uniform_sign`]), and the shell's closure forces none of
    /// its layers to the other (layers at depth index `<= 0` are made solid, `>= depth` air).
    /// Such a chunk's mesh is empty, and it is neither sampled nor meshed.
    fn uniform_by_bound(&self, grid: &ChunkGrid) -> bool {
        let Some(solid) = self.density.uniform_sign(&grid.dirs, &grid.radii) else {
            return false;
        };
        // layer c of the padded grid lies at depth index k0 + (c - 1) stride
        let layers = grid.radii.len() as i64;
        let (bottom, top) = (grid.k0 - grid.stride, grid.k0 + (layers - 2) * grid.stride);
        if solid {
            top < self.layout.depth_tiles()
        } else {
            bottom > 0
        }
    }

    /// An empty mesh of the chunk of `grid` (key and origin set): what the mesher gives a chunk
    /// that holds no surface.
    fn empty_mesh(grid: &ChunkGrid, out: &mut ChunkMesh) {
        out.clear();
        out.key = Some(grid.key);
        out.origin = grid.origin;
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
        if let Some(h) = &self.heightfield {
            h.mesh(key, SideMask::NONE, out);
            self.shade(out, None, None);
            return;
        }
        let grid = self.grid_after(key, scratch.grid.take());
        self.mesh_chunk_in(&grid, scratch, out, reuse);
        scratch.grid = Some((self.layout, grid));
    }

    /// The sample grid of `key`: `last` (the grid of the chunk meshed before, and its layout)
    /// moved to `key`'s depth when it is of this planet's layout and has the same footprint (its
    /// directions copied, not computed again: the chunks an edit touches come in depth pairs,
    /// and a planet's chunks in depth order), else a new one. The same grid either way
    /// ([`ChunkGrid::at_depth`]).
    fn grid_after(&self, key: ChunkKey, last: Option<(Layout, ChunkGrid)>) -> ChunkGrid {
        match last {
            Some((l, g)) if l == self.layout && g.key == key => g,
            Some((l, g)) if l == self.layout && g.key == ChunkKey { k: g.key.k, ..key } => {
                g.at_depth(&self.layout, key.k)
            }
            _ => ChunkGrid::new(&self.layout, key),
        }
    }

    /// [`Planet::mesh_chunk`] on the chunk's grid.
    fn mesh_chunk_in(&self, grid: &ChunkGrid, scratch: &mut ChunkScratch, out: &mut ChunkMesh, reuse: Option<Reuse>) {
        let key = grid.key;
        if !self.may_hold_surface(&key) || self.uniform_by_bound(grid) {
            Self::empty_mesh(grid, out);
            return;
        }
        if let Some(r) = &reuse {
            if self.remesh_around(grid, r, scratch, out) {
                self.shade_grid(out, grid, scratch, reuse, true);
                return;
            }
        }
        scratch.densities.resize(grid.sample_count(), 0.0);
        self.sample(key, grid, &mut scratch.densities, Some(&mut scratch.columns));
        close_shell(grid, self.layout.depth_tiles(), &mut scratch.densities);
        scratch.mesher.mesh(grid, &scratch.densities, out);
        self.shade_grid(out, grid, scratch, reuse, false);
    }

    /// [`Planet::shade`] for a marching-cubes mesh of `grid`, from the columns the density batch
    /// kept in `scratch`, reusing the attributes of `reuse`'s previous mesh (through the copy
    /// map when the mesh was `remeshed` around the edit).
    fn shade_grid(
        &self,
        out: &mut ChunkMesh,
        grid: &ChunkGrid,
        scratch: &mut ChunkScratch,
        reuse: Option<Reuse>,
        remeshed: bool,
    ) {
        let edges = GridEdges {
            grid,
            columns: &scratch.columns,
        };
        let reuse = reuse.map(|r| Reused {
            reuse: r,
            index: &mut scratch.previous,
            copied: remeshed.then_some(&scratch.copied[..]),
        });
        self.shade(out, Some(edges), reuse);
    }

    /// Meshes the chunk of `grid` after the edit `r.op` by marching again only the cubes the
    /// edit can change and copying the others from `r.previous` ([`Mesher::remesh_cubes`]): only
    /// the samples around the brush's reach are sampled. The same bytes as meshing the whole
    /// chunk; false (nothing done) when the previous mesh cannot be reused.
    fn remesh_around(&self, grid: &ChunkGrid, r: &Reuse, scratch: &mut ChunkScratch, out: &mut ChunkMesh) -> bool {
        let p = grid.padded;
        // The box of samples the brush can change (none for paint).
        let mut changed: Option<([usize; 3], [usize; 3])> = None;
        if r.op.shapes() {
            for b in 0..p {
                for a in 0..p {
                    let Some((lo, hi)) = r.op.column_span(grid.dirs[b * p + a]) else {
                        continue;
                    };
                    let (c0, c1) = (
                        grid.radii.partition_point(|x| *x < lo),
                        grid.radii.partition_point(|x| *x <= hi),
                    );
                    if c0 >= c1 {
                        continue;
                    }
                    let (l, h) = changed.get_or_insert(([a, b, c0], [a, b, c1 - 1]));
                    *l = [l[0].min(a), l[1].min(b), l[2].min(c0)];
                    *h = [h[0].max(a), h[1].max(b), h[2].max(c1 - 1)];
                }
            }
        }
        let region = changed.and_then(|(lo, hi)| CubeBox::around_samples(lo, hi, grid.tiles));
        scratch.densities.clear();
        scratch.densities.resize(grid.sample_count(), f32::NAN);
        if let Some(region) = region {
            let (lo, hi) = region.samples();
            let dirs: Vec<DVec3> = (lo[1]..=hi[1])
                .flat_map(|b| (lo[0]..=hi[0]).map(move |a| grid.dirs[b * p + a]))
                .collect();
            let radii = &grid.radii[lo[2]..=hi[2]];
            let mut batch = vec![0.0f32; dirs.len() * radii.len()];
            // Batches give every sample the bits of the whole chunk's batch.
            self.density.sample_shell(&dirs, radii, &mut batch);
            let depth = self.layout.depth_tiles();
            let mut values = batch.into_iter();
            for c in lo[2]..=hi[2] {
                let k = grid.k0 + (c as i64 - 1) * grid.stride;
                for b in lo[1]..=hi[1] {
                    for a in lo[0]..=hi[0] {
                        let d = values.next().expect("one value per sample of the box");
                        scratch.densities[grid.index(a, b, c)] = close_sample(k, depth, d);
                    }
                }
            }
        }
        scratch.columns.clear();
        scratch
            .mesher
            .remesh_cubes(grid, &scratch.densities, r.previous, region, out, &mut scratch.copied)
    }

    /// The (edited) density batch of a chunk into `out`: [`Planet::density`]'s batch, through the
    /// base cache when there is one (same bits either way). With `columns`, a batch sampled here
    /// keeps its columns there for the shader (a batch from the cache keeps none).
    fn sample(&self, key: ChunkKey, grid: &ChunkGrid, out: &mut [f32], columns: Option<&mut ShellColumns>) {
        fn batch(density: &dyn Density, grid: &ChunkGrid, out: &mut [f32], columns: Option<&mut ShellColumns>) {
            match columns {
                Some(c) => density.sample_shell_keeping(&grid.dirs, &grid.radii, out, c),
                None => density.sample_shell(&grid.dirs, &grid.radii, out),
            }
        }
        let Some(cache) = &self.base_cache else {
            batch(&*self.density, grid, out, columns);
            return;
        };
        match cache.get(&key) {
            Some(base) if base.len() == out.len() => {
                if let Some(c) = columns {
                    c.clear();
                }
                out.copy_from_slice(&base)
            }
            _ => {
                batch(&*self.terrain.density, grid, out, columns);
                cache.insert(key, Arc::from(&*out));
            }
        }
        if let Some(edited) = &self.edited {
            edited.apply_edits(&grid.dirs, &grid.radii, out);
        }
    }

    /// Meshes a chunk of any level of detail into `out`, closing the seam on every side in
    /// `coarser` (the sides across which the selected neighbour is one level coarser) with
    /// transition patches ([`pmc_mesh::transition`]). With an empty mask this is
    /// [`Planet::chunk_mesh_into`]. Sides with no coarser chunk beyond them (the shell's inner
    /// and outer boundary, or a chunk already at the coarsest level) or whose neighbour is a sibling
    /// are ignored, as is the mask
    /// when `n_t` is odd (such layouts have only level 0).
    ///
    /// The patches' coarse vertices get the coarse neighbour's normals bit for bit: the density
    /// is sampled at the few coarse voxels around the seam (about `3 (n_t / 2 + 3)^2` samples
    /// per side, not a whole chunk) and differentiated in the neighbour's frame. A fine vertex
    /// of the seam in the place of a coarse one takes its normal, so the place shades alike in
    /// both chunks (see `pmc_mesh::transition` for the lines where the side mask cannot tell).
    ///
    /// # Panics
    /// If `key` is not a chunk of the layout (check with [`Layout::contains_chunk`]).
    pub fn chunk_mesh_lod_into(
        &self,
        key: ChunkKey,
        coarser: SideMask,
        scratch: &mut ChunkScratch,
        out: &mut ChunkMesh,
    ) {
        self.mesh_chunk_lod(key, coarser, scratch, out, None);
    }

    /// [`Planet::chunk_mesh_lod_into`] after one edit, reusing the shading of the vertices `op`
    /// did not touch, as [`Planet::remesh_reusing`] does: `previous` must be the same chunk and
    /// seam variant meshed under the edits this planet had without `op` (before `op` was pushed,
    /// or before it was undone). The result is byte-identical to
    /// [`Planet::chunk_mesh_lod_into`]; a `previous` of another chunk is ignored.
    ///
    /// # Panics
    /// If `key` is not a chunk of the layout (check with [`Layout::contains_chunk`]).
    pub fn chunk_mesh_lod_reusing_into(
        &self,
        key: ChunkKey,
        coarser: SideMask,
        previous: &ChunkMesh,
        op: &BrushOp,
        scratch: &mut ChunkScratch,
        out: &mut ChunkMesh,
    ) {
        let reuse = (previous.key == Some(key)).then_some(Reuse { previous, op });
        self.mesh_chunk_lod(key, coarser, scratch, out, reuse);
    }

    /// The level-of-detail chunk pipeline, shading from `reuse` where it can.
    fn mesh_chunk_lod(
        &self,
        key: ChunkKey,
        coarser: SideMask,
        scratch: &mut ChunkScratch,
        out: &mut ChunkMesh,
        reuse: Option<Reuse>,
    ) {
        if let Some(h) = &self.heightfield {
            h.mesh(key, coarser, out);
            self.shade(out, None, None);
            return;
        }
        // The sides to close, and the coarser neighbour across each.
        let closing: Vec<(ChunkSide, ChunkKey)> = if self.layout.n_t().is_multiple_of(2) {
            coarser
                .sides()
                .filter_map(|side| {
                    let y = self.layout.neighbour(&key, side, key.level.checked_add(1)?)?;
                    // Across a side shared with a sibling the region is the chunk's own parent,
                    // never a coarser leaf: nothing to close.
                    (y != key.parent()).then_some((side, y))
                })
                .collect()
        } else {
            Vec::new()
        };
        if closing.is_empty() && reuse.is_some() {
            // No transition patches: the plain pipeline, which can remesh around the edit.
            return self.mesh_chunk(key, scratch, out, reuse);
        }
        let grid = ChunkGrid::new(&self.layout, key);
        if !self.may_hold_surface(&key) || self.uniform_by_bound(&grid) {
            Self::empty_mesh(&grid, out);
            return;
        }
        scratch.densities.resize(grid.sample_count(), 0.0);
        self.sample(key, &grid, &mut scratch.densities, Some(&mut scratch.columns));
        close_shell(&grid, self.layout.depth_tiles(), &mut scratch.densities);
        let sides: Vec<(ChunkSide, Vec<DVec3>, [[bool; 2]; 2])> = closing
            .iter()
            .map(|&(side, y)| {
                let borders = self.shared_seam_borders(&grid, side, &closing);
                (side, self.coarse_gradients(&grid, side, y), borders)
            })
            .collect();
        let transitions: Vec<Transition> = sides
            .iter()
            .map(|(side, g, borders)| Transition {
                side: *side,
                gradients: g,
                share_borders: *borders,
            })
            .collect();
        scratch
            .mesher
            .mesh_with_transitions(&grid, &scratch.densities, &transitions, out);
        self.shade_grid(out, &grid, scratch, reuse, false);
    }

    /// [`Transition::share_borders`] of the chunk of `grid` on `side` (across which the
    /// neighbour is coarser), `closing` being every side the chunk closes: for each of the
    /// side's four border lines, whether every chunk of this level holding the line faces a
    /// coarser chunk across a side through it (and so gives the fine vertices there the coarse
    /// normals too).
    ///
    /// Four chunks stand around a line (three at a cube corner, two on the shell's boundary).
    /// Besides this chunk, one of its level holding the line but facing no coarser chunk can
    /// only be the one diagonally opposite the coarse neighbour `y`. The line qualifies when this
    /// chunk's neighbour across its other side through the line is its sibling (then the line
    /// runs through the middle of `y`'s side: `y` fills both quadrants across the side, and the
    /// sibling faces it too), when it is a cube corner (three chunks, each beside both others),
    /// when no chunk lies beyond that other side (the shell's boundary), or when that other side
    /// faces a coarser chunk too (then so do the diagonal chunk's two sides, if it is of this
    /// level). Left out: `y`'s own edges along a straight level boundary, where the chunk beside
    /// this one may face `y`'s neighbour or be of its own level and face nothing coarser, which
    /// this chunk's side mask cannot tell apart.
    fn shared_seam_borders(
        &self,
        grid: &ChunkGrid,
        side: ChunkSide,
        closing: &[(ChunkSide, ChunkKey)],
    ) -> [[bool; 2]; 2] {
        let key = grid.key;
        let (p, n) = (grid.padded, grid.tiles);
        let inplane = match side.axis() {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        let at = if side.is_max() { n + 1 } else { 1 };
        let face_tiles = self.layout.face_tiles();
        inplane.map(|axis| {
            [false, true].map(|high| {
                let other = ChunkSide::ALL[2 * axis + usize::from(high)];
                if closing.iter().any(|(s, _)| *s == other) {
                    return true;
                }
                let Some(beside) = self.layout.neighbour(&key, other, key.level) else {
                    return true;
                };
                if beside.parent() == key.parent() {
                    return true;
                }
                // A radial line on a cube corner: its column's lattice point is a cube corner.
                if axis == 2 || side.axis() == 2 {
                    return false;
                }
                let end = if high { n + 1 } else { 1 };
                let col = if side.axis() == 0 { end * p + at } else { at * p + end };
                grid.lattice[col]
                    .abs()
                    .to_array()
                    .iter()
                    .all(|c| i64::from(*c) == face_tiles)
            })
        })
    }

    /// Meshes a chunk of any level with its seams closed toward coarser neighbours (allocating
    /// fresh buffers); see [`Planet::chunk_mesh_lod_into`].
    pub fn chunk_mesh_lod(&self, key: ChunkKey, coarser: SideMask) -> ChunkMesh {
        let mut out = ChunkMesh::default();
        self.chunk_mesh_lod_into(key, coarser, &mut ChunkScratch::default(), &mut out);
        out
    }

    /// The density gradients that coarse chunk `y` computes at the coarse voxels of `side` of
    /// the chunk of `grid`, in [`coarse_voxels`] order: the samples around each voxel in `y`'s
    /// grid, shell-closed, differentiated in `y`'s frame ([`voxel_gradient`]).
    fn coarse_gradients(&self, grid: &ChunkGrid, side: ChunkSide, y: ChunkKey) -> Vec<DVec3> {
        let gy = ChunkGrid::new(&self.layout, y);
        let n = self.layout.face_tiles();
        let fr = y.face.frame();
        let p = gy.padded;
        let last = p as i64 - 2;
        // Each coarse voxel's padded index in y's grid, from its canonical key.
        let local: Vec<Option<(usize, usize, usize)>> = coarse_voxels(grid, side)
            .into_iter()
            .map(|(a, b, c)| {
                let key = grid.voxel_key(a, b, c);
                let l = pmc_geometry::glam::IVec3::from_array(key.lattice).as_i64vec3();
                let i = (fr.u.as_i64vec3().dot(l) + n) / 2;
                let j = (fr.v.as_i64vec3().dot(l) + n) / 2;
                let idx = |x: i64, x0: i64| {
                    let d = x - x0;
                    (d % gy.stride == 0 && (1..=last).contains(&(d / gy.stride + 1)))
                        .then(|| (d / gy.stride + 1) as usize)
                };
                let on_face = fr.n.as_i64vec3().dot(l) == n;
                Some((
                    idx(i, gy.i0).filter(|_| on_face)?,
                    idx(j, gy.j0)?,
                    idx(i64::from(key.k), gy.k0)?,
                ))
            })
            .collect();
        // The columns and layers the gradients read (each voxel's six neighbours).
        let mut col_slot = vec![u32::MAX; p * p];
        let mut layer_slot = vec![u32::MAX; p];
        let (mut cols, mut layers) = (Vec::new(), Vec::new());
        for (a, b, c) in local.iter().flatten().copied() {
            for col in [
                b * p + a,
                b * p + a - 1,
                b * p + a + 1,
                (b - 1) * p + a,
                (b + 1) * p + a,
            ] {
                if col_slot[col] == u32::MAX {
                    col_slot[col] = cols.len() as u32;
                    cols.push(col);
                }
            }
            for l in [c - 1, c, c + 1] {
                if layer_slot[l] == u32::MAX {
                    layer_slot[l] = layers.len() as u32;
                    layers.push(l);
                }
            }
        }
        let dirs: Vec<DVec3> = cols.iter().map(|c| gy.dirs[*c]).collect();
        let radii: Vec<f64> = layers.iter().map(|l| gy.radii[*l]).collect();
        let mut values = vec![0.0f32; dirs.len() * radii.len()];
        // The base values: from y's cached base batch when the planet has one (y is usually a
        // selected chunk meshed already), else sampled; then the edits, as `sample` does.
        let cached = self
            .base_cache
            .as_ref()
            .and_then(|c| c.get(&y))
            .filter(|b| b.len() == gy.sample_count());
        match cached {
            Some(base) => {
                let ndirs = dirs.len();
                for (li, l) in layers.iter().enumerate() {
                    for (ci, col) in cols.iter().enumerate() {
                        values[li * ndirs + ci] = base[l * p * p + col];
                    }
                }
            }
            None => self.terrain.density.sample_shell(&dirs, &radii, &mut values),
        }
        if let Some(edited) = &self.edited {
            edited.apply_edits(&dirs, &radii, &mut values);
        }
        let depth = self.layout.depth_tiles();
        for (r, row) in layers.iter().zip(values.chunks_exact_mut(dirs.len().max(1))) {
            let k = gy.k0 + (*r as i64 - 1) * gy.stride;
            for v in row {
                *v = close_sample(k, depth, *v);
            }
        }
        let ndirs = dirs.len();
        local
            .iter()
            .map(|l| match l {
                Some(v) => voxel_gradient(&gy, *v, |a, b, c| {
                    values[layer_slot[c] as usize * ndirs + col_slot[b * p + a] as usize]
                }),
                // Not a voxel of y: the layout or the neighbour is inconsistent; a radial normal
                // keeps the mesh usable (never reached for keys the selection produces).
                None => DVec3::ZERO,
            })
            .collect()
    }

    /// Meshes one chunk (allocating fresh buffers).
    pub fn chunk_mesh(&self, key: ChunkKey) -> ChunkMesh {
        let mut out = ChunkMesh::default();
        self.chunk_mesh_into(key, &mut ChunkScratch::default(), &mut out);
        out
    }

    /// Meshes one chunk of any level closed on its own: its surface and its caps, the solid part
    /// of each of its six sides ([`pmc_mesh::caps`]), so that it bounds a solid and no
    /// neighbour of any level beside it can open a crack into it. For clients that pick each
    /// chunk's level on their own (3D Tiles). The surface is [`Planet::chunk_mesh_into`]'s, bit
    /// for bit; the caps' triangles follow it. Chunks with no surface give an empty mesh.
    /// A height-field planet's patches have no volume to close: they come as
    /// [`Planet::chunk_mesh_into`] gives them.
    ///
    /// # Panics
    /// If `key` is not a chunk of the layout (check with [`Layout::contains_chunk`]).
    pub fn chunk_mesh_closed_into(&self, key: ChunkKey, scratch: &mut ChunkScratch, out: &mut ChunkMesh) {
        if self.heightfield.is_some() {
            self.mesh_chunk(key, scratch, out, None);
            return;
        }
        let grid = self.grid_after(key, scratch.grid.take());
        if !self.may_hold_surface(&key) || self.uniform_by_bound(&grid) {
            Self::empty_mesh(&grid, out);
        } else {
            scratch.densities.resize(grid.sample_count(), 0.0);
            self.sample(key, &grid, &mut scratch.densities, Some(&mut scratch.columns));
            close_shell(&grid, self.layout.depth_tiles(), &mut scratch.densities);
            scratch.mesher.mesh_closed(&grid, &scratch.densities, out);
            self.shade_grid(out, &grid, scratch, None, false);
        }
        scratch.grid = Some((self.layout, grid));
    }

    /// [`Planet::chunk_mesh_closed_into`] with fresh buffers.
    pub fn chunk_mesh_closed(&self, key: ChunkKey) -> ChunkMesh {
        let mut out = ChunkMesh::default();
        self.chunk_mesh_closed_into(key, &mut ChunkScratch::default(), &mut out);
        out
    }

    /// Meshes the chunks that `op` can change ([`pmc_edit::affected_chunks`]), in key order,
    /// on the calling thread: after pushing or undoing `op` and [`Planet::set_edits`], these are
    /// the meshes to replace (empty ones included, with key and origin set, so a cache can drop
    /// them). Every other chunk's mesh is unchanged by `op`.
    ///
    /// The scratch buffers (about 2.7 MB at `n_t = 32`) are kept per thread between calls. With
    /// a base cache ([`Planet::with_base_cache`]) holding the affected chunks, the terrain is not
    /// sampled again: only the edits are applied.
    pub fn remesh(&self, op: &BrushOp) -> Vec<ChunkMesh> {
        with_remesh_scratch(|scratch| {
            affected_chunks(&self.layout, op)
                .into_iter()
                .map(|key| {
                    let mut m = ChunkMesh::default();
                    self.chunk_mesh_into(key, scratch, &mut m);
                    m
                })
                .collect()
        })
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
        with_remesh_scratch(|scratch| {
            affected_chunks(&self.layout, op)
                .into_iter()
                .map(|key| {
                    let mut m = ChunkMesh::default();
                    let reuse = previous(&key).map(|previous| Reuse { previous, op });
                    self.mesh_chunk(key, scratch, &mut m, reuse);
                    m
                })
                .collect()
        })
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
    /// With `edges` (a marching-cubes mesh) the shader reads the chunk's columns at each vertex's
    /// edge ([`pmc_density::presets::Shader::shade_edges`]); without (a height-field mesh) it
    /// shades the points, which lie on the surface.
    fn shade(&self, m: &mut ChunkMesh, edges: Option<GridEdges>, reuse: Option<Reused>) {
        let datum = self.datum_radius();
        let sea = self.terrain.sea_radius;
        let paints = self.paints_for(m);
        let n = m.vertex_count();
        m.heights.reserve(n);
        m.water_depths.reserve(n);
        m.colors.reserve(n);
        m.materials.reserve(n);
        let reuse = reuse.filter(|u| u.reuse.previous.origin == m.origin && u.reuse.previous.has_attributes());
        let reuse = reuse.map(|u| {
            let (r, index) = (u.reuse, u.index);
            let copied = u.copied.filter(|c| c.len() == n);
            index.clear();
            // A vertex copied from the previous mesh is that vertex; a vertex marched anew can
            // only be one the copies left (an edge holds one vertex).
            let mut taken = vec![false; r.previous.vertex_count()];
            for &j in copied.unwrap_or_default() {
                if let Some(t) = taken.get_mut(j as usize) {
                    *t = true;
                }
            }
            index.reserve(r.previous.edge_keys.len());
            index.extend(
                r.previous
                    .edge_keys
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| !taken[*j])
                    .map(|(j, k)| (*k, j as u32)),
            );
            (r, &*index, copied)
        });
        // Vertices unchanged by the edit take the previous mesh's attributes; the others are
        // shaded in one batch.
        let previous: Vec<Option<usize>> = match &reuse {
            None => Vec::new(),
            Some((r, index, copied)) => (0..n)
                .map(|i| {
                    let same = |j: &u32| {
                        let j = *j as usize;
                        let bits = |v: [f32; 3]| v.map(f32::to_bits);
                        bits(r.previous.positions[j]) == bits(m.positions[i])
                            && bits(r.previous.normals[j]) == bits(m.normals[i])
                    };
                    let outside = (m.world_position(i) - r.op.center).length() >= r.op.reach();
                    let candidate = match copied.map(|c| c[i]) {
                        Some(j) if j != u32::MAX => Some(j),
                        _ => index.get(&m.edge_keys[i]).copied(),
                    };
                    candidate.filter(|j| outside && same(j)).map(|j| j as usize)
                })
                .collect(),
        };
        let reused = |i: usize| previous.get(i).copied().flatten();
        let todo: Vec<usize> = (0..n).filter(|&i| reused(i).is_none()).collect();
        let points: Vec<DVec3> = todo.iter().map(|&i| m.world_position(i)).collect();
        let normals: Vec<DVec3> = todo.iter().map(|&i| DVec3::from(m.normals[i].map(f64::from))).collect();
        let mut shades = Vec::with_capacity(points.len());
        match edges.filter(|_| m.vertex_edges.len() == n) {
            Some(e) => {
                // Where each vertex lies on its edge is taken from its stored position, so a
                // vertex whose position and edge are unchanged gets the same shade (what reusing
                // shades relies on).
                let at: Vec<VertexEdge> = todo
                    .iter()
                    .zip(&points)
                    .map(|(&i, p)| e.grid.vertex_edge(m.vertex_edges[i], *p))
                    .collect();
                let vertices = EdgeVertices {
                    points: &points,
                    normals: &normals,
                    edges: &at,
                    dirs: &e.grid.dirs,
                    columns: e.columns,
                };
                self.terrain.shader.shade_edges(&vertices, &mut shades);
            }
            // A height-field vertex lies on the surface: the shader need not look it up.
            None => self.terrain.shader.shade_many(&points, &normals, true, &mut shades),
        }
        let mut shaded = points.iter().zip(shades);
        for i in 0..n {
            if let (Some(j), Some((r, _, _))) = (reused(i), &reuse) {
                let prev = r.previous;
                m.heights.push(prev.heights[j]);
                m.water_depths.push(prev.water_depths[j]);
                m.colors.push(prev.colors[j]);
                m.materials.push(prev.materials[j]);
                continue;
            }
            let (&p, mut shade) = shaded.next().expect("one shade per vertex to shade");
            let r = p.length();
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

/// A planet's chunk batches are its (edited) density at the chunk's samples: from the base cache
/// when it has one ([`Planet::with_base_cache`]; a batch not held is sampled and kept), with the
/// edits applied on top, the same bits as [`Planet::density`]'s batch. Readers other than the
/// mesher (the navigation grid's rebuild after an edit) pay then only for the edits.
impl pmc_density::ChunkSamples for Planet {
    fn chunk_samples(&self, grid: &ChunkGrid, out: &mut [f32]) {
        self.sample(grid.key, grid, out, None);
    }
}
