//! The marching cubes mesher over one chunk's spherical grid.

use crate::chunk_mesh::ChunkMesh;
use crate::tables::{corner_offset, EDGE_AXIS, EDGE_CORNERS, TABLES};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, EdgeKey};

/// Whether a density sample is solid: strictly positive. Zero and NaN are air.
#[inline]
pub fn is_solid(d: f32) -> bool {
    d > 0.0
}

/// Reusable scratch state for meshing chunks. Keep one per thread.
///
/// Vertex and gradient caches are stamped with a generation number instead of being cleared, so
/// meshing an empty or sparse chunk costs little more than reading its samples.
#[derive(Debug, Default)]
pub struct Mesher {
    generation: u32,
    /// Per padded voxel and axis: `(generation << 32) | vertex index`.
    edge_cache: Vec<u64>,
    /// Per padded voxel: generation of the cached gradient.
    grad_stamp: Vec<u32>,
    grad: Vec<DVec3>,
    /// Solidity bits per voxel row (fast path).
    rows: Vec<u128>,
    /// Per padded column: generation of the cached reciprocal frame.
    col_stamp: Vec<u32>,
    col_basis: Vec<[DVec3; 3]>,
    /// Per padded layer: `1 / r` and `1 / (r[c + 1] - r[c - 1])`.
    inv_radii: Vec<[f64; 2]>,
}

impl Mesher {
    /// Readies the caches for meshing `grid` into `out` (cleared, keyed to the grid): a new
    /// generation of the vertex and gradient stamps, and the layers' reciprocal radii.
    pub(crate) fn start(&mut self, grid: &ChunkGrid, out: &mut ChunkMesh) {
        out.clear();
        out.key = Some(grid.key);
        out.origin = grid.origin;
        let p = grid.padded;
        let total = p * p * p;
        if self.edge_cache.len() < total * 3 {
            self.edge_cache = vec![0; total * 3];
            self.grad_stamp = vec![0; total];
            self.grad = vec![DVec3::ZERO; total];
            self.col_stamp = vec![0; p * p];
            self.col_basis = vec![[DVec3::ZERO; 3]; p * p];
            self.generation = 0;
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.edge_cache.fill(0);
            self.grad_stamp.fill(0);
            self.col_stamp.fill(0);
            self.generation = 1;
        }

        self.inv_radii.clear();
        self.inv_radii.extend((0..p).map(|c| {
            let dr = grid.radii[(c + 1).min(p - 1)] - grid.radii[c.saturating_sub(1)];
            [1.0 / grid.radii[c], 1.0 / dr]
        }));
    }

    /// The vertex made on edge slot `slot` (padded voxel `* 3 +` axis) of the mesh being made,
    /// if any.
    #[inline(always)]
    pub(crate) fn cached_vertex(&self, slot: usize) -> Option<u32> {
        let cached = self.edge_cache[slot];
        ((cached >> 32) as u32 == self.generation).then_some(cached as u32)
    }

    /// Records vertex `idx` as the one on edge slot `slot` of the mesh being made.
    #[inline(always)]
    pub(crate) fn cache_vertex(&mut self, slot: usize, idx: u32) {
        self.edge_cache[slot] = (u64::from(self.generation) << 32) | u64::from(idx);
    }

    /// A mesher with empty caches (they grow to the first chunk's size).
    pub fn new() -> Mesher {
        Mesher::default()
    }

    /// Meshes one chunk into `out` (cleared first; buffers keep their capacity).
    ///
    /// `densities` are the padded samples of `grid` in [`ChunkGrid::index`] order. Only the
    /// chunk's own `n_t^3` tiles are meshed; the padding feeds the gradients. Attribute buffers
    /// (heights, colours, ...) are left empty for the caller to fill.
    ///
    /// # Panics
    /// If `densities.len() != grid.sample_count()`.
    pub fn mesh(&mut self, grid: &ChunkGrid, densities: &[f32], out: &mut ChunkMesh) {
        self.mesh_with_transitions(grid, densities, &[], out);
    }

    /// Meshes one chunk as [`Mesher::mesh`] does, and closes the seam on every side in
    /// `transitions`, across which the neighbour is one level coarser, with transition patches
    /// (see [`crate::transition`]). With no transitions the result is [`Mesher::mesh`]'s.
    ///
    /// # Panics
    /// If `densities.len() != grid.sample_count()`.
    pub fn mesh_with_transitions(
        &mut self,
        grid: &ChunkGrid,
        densities: &[f32],
        transitions: &[crate::transition::Transition],
        out: &mut ChunkMesh,
    ) {
        self.march(grid, densities, out, |ctx| ctx.emit_transitions(transitions));
    }

    /// Meshes one chunk as [`Mesher::mesh`] does and adds its caps: the solid part of each of its
    /// six sides, so the mesh bounds a closed solid on its own and no neighbour of any level
    /// beside it can open a crack into it (see [`crate::caps`]). Cap vertices on the chunk's
    /// edges are voxels (their key is the voxel's key twice); the others are the mesh's own.
    ///
    /// # Panics
    /// If `densities.len() != grid.sample_count()`.
    pub fn mesh_closed(&mut self, grid: &ChunkGrid, densities: &[f32], out: &mut ChunkMesh) {
        self.march(grid, densities, out, |ctx| {
            // A chunk with no surface has no cap either: it is all solid or all air.
            if !ctx.out.indices.is_empty() {
                ctx.emit_caps();
            }
        });
    }

    /// Marches every cube of the chunk into `out` (cleared first), lets `then` add to the mesh
    /// (seams, caps), and normalises the normals.
    fn march(&mut self, grid: &ChunkGrid, densities: &[f32], out: &mut ChunkMesh, then: impl FnOnce(&mut Ctx<'_>)) {
        assert_eq!(
            densities.len(),
            grid.sample_count(),
            "densities must cover the padded chunk grid"
        );
        self.start(grid, out);
        let tables = &*TABLES;
        let mut ctx = Ctx {
            grid,
            densities,
            mesher: self,
            out,
        };
        if grid.padded <= 128 {
            march_bit_rows(&mut ctx, tables);
        } else {
            march_plain(&mut ctx, tables);
        }
        then(&mut ctx);
        finish_normals(out);
    }
}

/// Normalises the gradient normals in one tight pass (it vectorises, unlike a square root and a
/// division per vertex inside the march). A zero or non-finite gradient falls back to the
/// radial direction.
pub(crate) fn finish_normals(out: &mut ChunkMesh) {
    for n in out.normals.iter_mut() {
        let len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        let inv = 1.0 / len2.sqrt();
        *n = [n[0] * inv, n[1] * inv, n[2] * inv];
    }
    let origin = out.origin;
    for (n, p) in out.normals.iter_mut().zip(&out.positions) {
        if !(n[0].is_finite() && n[1].is_finite() && n[2].is_finite()) {
            let w = origin + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            *n = w.normalize_or(DVec3::Y).as_vec3().to_array();
        }
    }
}

/// The fast path for chunks up to 125 tiles wide: solidity packed into one `u128` per voxel row,
/// so whole runs of empty or full cubes are skipped with a few bit operations.
fn march_bit_rows(ctx: &mut Ctx<'_>, tables: &crate::tables::McTables) {
    let grid = ctx.grid;
    let (p, n) = (grid.padded, grid.tiles);
    let mut rows = std::mem::take(&mut ctx.mesher.rows);
    rows.clear();
    rows.extend(ctx.densities.chunks_exact(p).map(|row| {
        let (lo, hi) = row.split_at(p.min(64));
        let pack = |part: &[f32]| {
            let mut w = 0u64;
            let mut lanes = part.chunks_exact(8);
            for (k, lane) in lanes.by_ref().enumerate() {
                let mut m = 0u64;
                for (i, d) in lane.iter().enumerate() {
                    m |= u64::from(is_solid(*d)) << i;
                }
                w |= m << (8 * k);
            }
            let base = part.len() - lanes.remainder().len();
            for (i, d) in lanes.remainder().iter().enumerate() {
                w |= u64::from(is_solid(*d)) << (base + i);
            }
            w
        };
        u128::from(pack(lo)) | (u128::from(pack(hi)) << 64)
    }));
    // Bits 1..=n+1 are the chunk's own voxels; cubes start at bits 1..=n.
    let voxel_mask: u128 = ((1u128 << (n + 1)) - 1) << 1;
    let cube_mask: u128 = ((1u128 << n) - 1) << 1;
    let (mut any, mut all) = (0u128, voxel_mask);
    for c in 1..=n + 1 {
        for b in 1..=n + 1 {
            let r = rows[c * p + b] & voxel_mask;
            any |= r;
            all &= r;
        }
    }
    if any == 0 || all == voxel_mask {
        ctx.mesher.rows = rows;
        return;
    }
    for c in 1..=n {
        for b in 1..=n {
            let r00 = rows[c * p + b];
            let r10 = rows[c * p + b + 1];
            let r01 = rows[(c + 1) * p + b];
            let r11 = rows[(c + 1) * p + b + 1];
            let or = r00 | r10 | r01 | r11;
            let and = r00 & r10 & r01 & r11;
            let mut live = (or | (or >> 1)) & !(and & (and >> 1)) & cube_mask;
            while live != 0 {
                let a = live.trailing_zeros() as usize;
                live &= live - 1;
                let bits = |r: u128| ((r >> a) & 3) as u8;
                let case = bits(r00) | (bits(r10) << 2) | (bits(r01) << 4) | (bits(r11) << 6);
                ctx.emit_cube(tables, case, a, b, c);
            }
        }
    }
    ctx.mesher.rows = rows;
}

/// The general path: every cube's case from its eight samples.
fn march_plain(ctx: &mut Ctx<'_>, tables: &crate::tables::McTables) {
    let grid = ctx.grid;
    let (p, n) = (grid.padded, grid.tiles);
    if !has_sign_change(grid, ctx.densities) {
        return;
    }
    let corners = corner_flat_offsets(p);
    for c in 1..=n {
        for b in 1..=n {
            let row = grid.index(0, b, c);
            for a in 1..=n {
                let case = cube_case(ctx.densities, row + a, &corners);
                if case == 0 || case == 255 {
                    continue;
                }
                ctx.emit_cube(tables, case, a, b, c);
            }
        }
    }
}

/// The flat offsets of a cube's eight corners from its lowest, in a grid `p` samples wide.
pub(crate) fn corner_flat_offsets(p: usize) -> [usize; 8] {
    std::array::from_fn(|c| {
        let o = corner_offset(c as u8);
        (o[2] * p + o[1]) * p + o[0]
    })
}

/// The case of the cube whose lowest corner is flat sample `base`: bit `k` set when corner `k`
/// is solid.
#[inline]
pub(crate) fn cube_case(densities: &[f32], base: usize, corners: &[usize; 8]) -> u8 {
    (0..8).fold(0u8, |m, k| m | (u8::from(is_solid(densities[base + corners[k]])) << k))
}

/// Whether the chunk's own (unpadded) samples hold both solid and air.
/// Whether the chunk's own voxels (not its padding) of `d`, the padded samples of `grid`, are
/// not all of one side: the mesher makes triangles exactly then.
pub fn has_sign_change(grid: &ChunkGrid, d: &[f32]) -> bool {
    let n = grid.tiles;
    let first = is_solid(d[grid.index(1, 1, 1)]);
    for c in 1..=n + 1 {
        for b in 1..=n + 1 {
            let row = grid.index(1, b, c);
            if d[row..=row + n].iter().any(|v| is_solid(*v) != first) {
                return true;
            }
        }
    }
    false
}

/// The reciprocal basis of the grid's local frame at padded column `col` (not on the padding's
/// outer ring): what turns central differences along `u`, `v` and depth into a world gradient.
fn column_basis(g: &ChunkGrid, col: usize) -> [DVec3; 3] {
    let p = g.padded;
    let n = g.dirs[col];
    let eu = g.dirs[col + 1] - g.dirs[col - 1];
    let ev = g.dirs[col + p] - g.dirs[col - p];
    let cvn = ev.cross(n);
    let det = eu.dot(cvn);
    if det.abs() > 0.0 {
        [cvn / det, n.cross(eu) / det, eu.cross(ev) / det]
    } else {
        [DVec3::ZERO; 3]
    }
}

/// The world gradient from central differences `du`, `dv`, `dk` through a column's reciprocal
/// basis, with `inv_r = 1 / r` and `inv_dr = 1 / (r[c + 1] - r[c - 1])` of the layer.
#[inline]
fn gradient_in_frame(basis: &[DVec3; 3], du: f64, dv: f64, dk: f64, inv_r: f64, inv_dr: f64) -> DVec3 {
    let [ru, rv, rk] = *basis;
    (ru * du + rv * dv) * inv_r + rk * (dk * inv_dr)
}

/// The density gradient at padded voxel `(a, b, c)` of `grid` (not on the padding), exactly as
/// [`Mesher`] computes it for a vertex's normal: central differences over the six axis
/// neighbours, `density(a, b, c)` giving the (shell-closed) sample of any padded voxel.
///
/// Level-of-detail seams use it to give a vertex of a coarser neighbour's grid edge the normal
/// that neighbour gives it, bit for bit, from only the few samples around it.
pub fn voxel_gradient(
    grid: &ChunkGrid,
    (a, b, c): (usize, usize, usize),
    density: impl Fn(usize, usize, usize) -> f32,
) -> DVec3 {
    let p = grid.padded;
    let d = |a: usize, b: usize, c: usize| f64::from(density(a, b, c));
    let du = d(a + 1, b, c) - d(a - 1, b, c);
    let dv = d(a, b + 1, c) - d(a, b - 1, c);
    let dk = d(a, b, c + 1) - d(a, b, c - 1);
    let dr = grid.radii[(c + 1).min(p - 1)] - grid.radii[c.saturating_sub(1)];
    let (inv_r, inv_dr) = (1.0 / grid.radii[c], 1.0 / dr);
    gradient_in_frame(&column_basis(grid, b * p + a), du, dv, dk, inv_r, inv_dr)
}

pub(crate) struct Ctx<'a> {
    pub(crate) grid: &'a ChunkGrid,
    pub(crate) densities: &'a [f32],
    pub(crate) mesher: &'a mut Mesher,
    pub(crate) out: &'a mut ChunkMesh,
}

impl Ctx<'_> {
    /// Emits the triangles of one cube: each cut edge's vertex is looked up once.
    #[inline(always)]
    pub(crate) fn emit_cube(&mut self, tables: &crate::tables::McTables, case: u8, a: usize, b: usize, c: usize) {
        let mut verts = [0u32; 12];
        let mut mask = tables.edge_masks[case as usize];
        while mask != 0 {
            let e = mask.trailing_zeros() as u8;
            mask &= mask - 1;
            verts[e as usize] = self.vertex(a, b, c, e);
        }
        for tri in tables.case(case) {
            self.out.indices.extend_from_slice(&tri.map(|e| verts[e as usize]));
        }
        let end = (self.out.indices.len() / 3) as u32;
        self.out.cube_runs.push([self.grid.index(a, b, c) as u32, end]);
    }

    /// The vertex on cube edge `e` of the cube whose lowest corner is padded voxel `(a, b, c)`.
    #[inline(always)]
    fn vertex(&mut self, a: usize, b: usize, c: usize, e: u8) -> u32 {
        let (lo, _) = EDGE_CORNERS[e as usize];
        let o = corner_offset(lo);
        let axis = EDGE_AXIS[e as usize] as usize;
        self.edge_vertex((a + o[0], b + o[1], c + o[2]), axis)
    }

    /// The vertex on the grid edge from padded voxel `v` one step along `axis` (created once).
    #[inline(always)]
    pub(crate) fn edge_vertex(&mut self, v: (usize, usize, usize), axis: usize) -> u32 {
        let (va, vb, vc) = v;
        let vi = self.grid.index(va, vb, vc);
        let slot = vi * 3 + axis;
        if let Some(idx) = self.mesher.cached_vertex(slot) {
            return idx;
        }
        let (wa, wb, wc) = match axis {
            0 => (va + 1, vb, vc),
            1 => (va, vb + 1, vc),
            _ => (va, vb, vc + 1),
        };
        let idx = self.make_vertex((va, vb, vc), (wa, wb, wc), axis);
        self.mesher.cache_vertex(slot, idx);
        idx
    }

    /// Creates the vertex on the grid edge between two adjacent padded voxels.
    fn make_vertex(&mut self, v: (usize, usize, usize), w: (usize, usize, usize), axis: usize) -> u32 {
        let gv = self.gradient(v);
        let gw = self.gradient(w);
        self.push_vertex(v, w, axis, gv, gw)
    }

    /// Pushes the vertex on the grid edge between padded voxels `v` and `w` (adjacent along
    /// `axis` at any multiple of the grid step), with the density gradients at `v` and `w`.
    pub(crate) fn push_vertex(
        &mut self,
        v: (usize, usize, usize),
        w: (usize, usize, usize),
        axis: usize,
        gv: DVec3,
        gw: DVec3,
    ) -> u32 {
        let g = self.grid;
        let p = g.padded;
        // Canonical order: along depth the lower layer first; across the surface the column with
        // the smaller lattice point first. Every chunk holding this edge orders it the same way.
        let first_is_v = axis == 2 || g.lattice[v.1 * p + v.0].to_array() < g.lattice[w.1 * p + w.0].to_array();
        let (f, s, gf, gs) = if first_is_v { (v, w, gv, gw) } else { (w, v, gw, gv) };
        let df = f64::from(self.densities[g.index(f.0, f.1, f.2)]);
        let ds = f64::from(self.densities[g.index(s.0, s.1, s.2)]);
        // One endpoint is solid (> 0), the other not, so df - ds is never 0; t lies in [0, 1].
        let t = (df / (df - ds)).clamp(0.0, 1.0);
        let pf = g.position(f.0, f.1, f.2);
        let ps = g.position(s.0, s.1, s.2);
        let pos = pf + (ps - pf) * t;
        let grad = gf + (gs - gf) * t;
        let key = EdgeKey::new(g.voxel_key(v.0, v.1, v.2), g.voxel_key(w.0, w.1, w.2));
        let flat = |x: (usize, usize, usize)| g.index(x.0, x.1, x.2) as u32;
        self.push_raw(pos, grad, key, [flat(f), flat(s)])
    }

    /// Pushes a vertex at world position `pos` with density gradient `grad` (its normal is
    /// `-grad`, stored unnormalised: `finish_normals` normalises them all in one pass), its key
    /// and its grid edge; returns its index.
    pub(crate) fn push_raw(&mut self, pos: DVec3, grad: DVec3, key: EdgeKey, edge: [u32; 2]) -> u32 {
        let rel = pos - self.grid.origin;
        let out = &mut *self.out;
        let idx = out.positions.len() as u32;
        let high = rel.as_vec3();
        out.positions.push(high.to_array());
        out.positions_low.push((rel - high.as_dvec3()).as_vec3().to_array());
        out.normals.push((-grad).as_vec3().to_array());
        out.edge_keys.push(key);
        out.vertex_edges.push(edge);
        idx
    }

    /// The density gradient at a padded voxel by central differences over its six axis
    /// neighbours, solved in world space through the grid's (non-orthogonal) local frame.
    ///
    /// Voxel positions factor as `dir(a, b) * radius(c)`, so the frame's reciprocal basis depends
    /// on the column only and is cached per column.
    pub(crate) fn gradient(&mut self, v: (usize, usize, usize)) -> DVec3 {
        let g = self.grid;
        let vi = g.index(v.0, v.1, v.2);
        let gen = self.mesher.generation;
        if self.mesher.grad_stamp[vi] == gen {
            return self.mesher.grad[vi];
        }
        let (a, b, c) = v;
        let p = g.padded;
        let col = b * p + a;
        if self.mesher.col_stamp[col] != gen {
            self.mesher.col_basis[col] = column_basis(g, col);
            self.mesher.col_stamp[col] = gen;
        }
        let d = |i: usize| f64::from(self.densities[i]);
        let layer = p * p;
        let du = d(vi + 1) - d(vi - 1);
        let dv = d(vi + p) - d(vi - p);
        let dk = d(vi + layer) - d(vi - layer);
        let [inv_r, inv_dr] = self.mesher.inv_radii[c];
        let grad = gradient_in_frame(&self.mesher.col_basis[col], du, dv, dk, inv_r, inv_dr);
        self.mesher.grad_stamp[vi] = gen;
        self.mesher.grad[vi] = grad;
        grad
    }
}
