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
}

impl Mesher {
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
        assert_eq!(densities.len(), grid.sample_count(), "densities must cover the padded chunk grid");
        out.clear();
        out.key = Some(grid.key);
        out.origin = grid.origin;
        let p = grid.padded;
        let n = grid.tiles;
        let total = p * p * p;
        if self.edge_cache.len() < total * 3 {
            self.edge_cache = vec![0; total * 3];
            self.grad_stamp = vec![0; total];
            self.grad = vec![DVec3::ZERO; total];
            self.generation = 0;
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.edge_cache.fill(0);
            self.grad_stamp.fill(0);
            self.generation = 1;
        }

        if !has_sign_change(grid, densities) {
            return;
        }

        let tables = &*TABLES;
        let corner_index: [usize; 8] = std::array::from_fn(|c| {
            let o = corner_offset(c as u8);
            (o[2] * p + o[1]) * p + o[0]
        });
        let mut ctx = Ctx { grid, densities, mesher: self, out };
        for c in 1..=n {
            for b in 1..=n {
                let row = grid.index(0, b, c);
                for a in 1..=n {
                    let base = row + a;
                    let mut case = 0u8;
                    for (k, off) in corner_index.iter().enumerate() {
                        if is_solid(densities[base + off]) {
                            case |= 1 << k;
                        }
                    }
                    if case == 0 || case == 255 {
                        continue;
                    }
                    for tri in tables.case(case) {
                        let v = tri.map(|e| ctx.vertex(a, b, c, e));
                        ctx.out.indices.extend_from_slice(&v);
                    }
                }
            }
        }
    }
}

/// Whether the chunk's own (unpadded) samples hold both solid and air.
fn has_sign_change(grid: &ChunkGrid, d: &[f32]) -> bool {
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

struct Ctx<'a> {
    grid: &'a ChunkGrid,
    densities: &'a [f32],
    mesher: &'a mut Mesher,
    out: &'a mut ChunkMesh,
}

impl Ctx<'_> {
    /// The vertex on cube edge `e` of the cube whose lowest corner is padded voxel `(a, b, c)`.
    #[inline]
    fn vertex(&mut self, a: usize, b: usize, c: usize, e: u8) -> u32 {
        let (lo, _) = EDGE_CORNERS[e as usize];
        let o = corner_offset(lo);
        let (va, vb, vc) = (a + o[0], b + o[1], c + o[2]);
        let axis = EDGE_AXIS[e as usize] as usize;
        let vi = self.grid.index(va, vb, vc);
        let slot = vi * 3 + axis;
        let gen = self.mesher.generation;
        let cached = self.mesher.edge_cache[slot];
        if (cached >> 32) as u32 == gen {
            return cached as u32;
        }
        let (wa, wb, wc) = match axis {
            0 => (va + 1, vb, vc),
            1 => (va, vb + 1, vc),
            _ => (va, vb, vc + 1),
        };
        let idx = self.make_vertex((va, vb, vc), (wa, wb, wc), axis);
        self.mesher.edge_cache[slot] = (u64::from(gen) << 32) | u64::from(idx);
        idx
    }

    /// Creates the vertex on the grid edge between two adjacent padded voxels.
    fn make_vertex(&mut self, v: (usize, usize, usize), w: (usize, usize, usize), axis: usize) -> u32 {
        let g = self.grid;
        let p = g.padded;
        // Canonical order: along depth the lower layer first; across the surface the column with
        // the smaller lattice point first. Every chunk holding this edge orders it the same way.
        let first_is_v = axis == 2 || g.lattice[v.1 * p + v.0].to_array() < g.lattice[w.1 * p + w.0].to_array();
        let (f, s) = if first_is_v { (v, w) } else { (w, v) };
        let df = f64::from(self.densities[g.index(f.0, f.1, f.2)]);
        let ds = f64::from(self.densities[g.index(s.0, s.1, s.2)]);
        // One endpoint is solid (> 0), the other not, so df - ds is never 0; t lies in [0, 1].
        let t = (df / (df - ds)).clamp(0.0, 1.0);
        let pf = g.position(f.0, f.1, f.2);
        let ps = g.position(s.0, s.1, s.2);
        let pos = pf + (ps - pf) * t;
        let gf = self.gradient(f);
        let gs = self.gradient(s);
        let grad = gf + (gs - gf) * t;
        let normal = (-grad).try_normalize().unwrap_or_else(|| pos.normalize_or(DVec3::Y));
        let rel = pos - g.origin;
        let out = &mut *self.out;
        let idx = out.positions.len() as u32;
        out.positions.push(rel.as_vec3().to_array());
        out.normals.push(normal.as_vec3().normalize_or(pmc_geometry::glam::Vec3::Y).to_array());
        out.edge_keys.push(EdgeKey::new(g.voxel_key(v.0, v.1, v.2), g.voxel_key(w.0, w.1, w.2)));
        idx
    }

    /// The density gradient at a padded voxel by central differences over its six axis
    /// neighbours, solved in world space through the grid's (non-orthogonal) local frame.
    fn gradient(&mut self, v: (usize, usize, usize)) -> DVec3 {
        let g = self.grid;
        let vi = g.index(v.0, v.1, v.2);
        if self.mesher.grad_stamp[vi] == self.mesher.generation {
            return self.mesher.grad[vi];
        }
        let (a, b, c) = v;
        let d = |x: usize, y: usize, z: usize| f64::from(self.densities[g.index(x, y, z)]);
        let pos = |x: usize, y: usize, z: usize| g.position(x, y, z);
        let eu = pos(a + 1, b, c) - pos(a - 1, b, c);
        let ev = pos(a, b + 1, c) - pos(a, b - 1, c);
        let ek = pos(a, b, c + 1) - pos(a, b, c - 1);
        let du = d(a + 1, b, c) - d(a - 1, b, c);
        let dv = d(a, b + 1, c) - d(a, b - 1, c);
        let dk = d(a, b, c + 1) - d(a, b, c - 1);
        let cvk = ev.cross(ek);
        let det = eu.dot(cvk);
        let grad = if det.abs() > 0.0 { (cvk * du + ek.cross(eu) * dv + eu.cross(ev) * dk) / det } else { DVec3::ZERO };
        self.mesher.grad_stamp[vi] = self.mesher.generation;
        self.mesher.grad[vi] = grad;
        grad
    }
}
