//! Remeshing only the cubes an edit can change: the other cubes' triangles and vertices are
//! copied from the mesh before the edit, in the order the mesher would have made them, so the
//! result is the same bytes as meshing the whole chunk again.

use crate::chunk_mesh::ChunkMesh;
use crate::mesher::{corner_flat_offsets, cube_case, finish_normals, Ctx, Mesher};
use crate::tables::{EDGE_AXIS, EDGE_CORNERS, TABLES};
use pmc_geometry::ChunkGrid;

/// A box of a chunk's cubes, by the padded indices `(a, b, c)` of their lowest corners,
/// inclusive at both ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CubeBox {
    /// The lowest cube of the box.
    pub lo: [usize; 3],
    /// The highest cube of the box.
    pub hi: [usize; 3],
}

impl CubeBox {
    /// The chunk's cubes (`1..=tiles` on each axis) whose triangles or vertices can change when
    /// the padded samples in the box `lo..=hi` change: those with a corner within one sample of
    /// the box, since a vertex's normal reads the samples next to its edge's ends. `None` when
    /// no cube of the chunk is among them.
    pub fn around_samples(lo: [usize; 3], hi: [usize; 3], tiles: usize) -> Option<CubeBox> {
        let mut b = CubeBox { lo: [0; 3], hi: [0; 3] };
        for k in 0..3 {
            b.lo[k] = lo[k].saturating_sub(2).max(1);
            b.hi[k] = (hi[k] + 1).min(tiles);
            if b.lo[k] > b.hi[k] {
                return None;
            }
        }
        Some(b)
    }

    /// Whether cube `v` is in the box.
    pub fn contains(&self, v: [usize; 3]) -> bool {
        (0..3).all(|k| self.lo[k] <= v[k] && v[k] <= self.hi[k])
    }

    /// The padded samples that meshing these cubes reads, as a box `(lo, hi)`, inclusive: the
    /// cubes' corners and their neighbours (for the normals).
    pub fn samples(&self) -> ([usize; 3], [usize; 3]) {
        (self.lo.map(|x| x - 1), self.hi.map(|x| x + 2))
    }
}

impl Mesher {
    /// Meshes `grid` into `out` as [`Mesher::mesh`] meshes all of `densities`, but marches only
    /// the cubes of `region` and copies the other cubes' triangles and vertices from `previous`:
    /// the mesh of the same grid (without transition patches) from samples that differ from
    /// `densities` only in a box `region` was made around ([`CubeBox::around_samples`]; `None`
    /// when no sample differs). `densities` needs to hold only the samples
    /// [`CubeBox::samples`] names; the others are never read. The result is byte-identical to
    /// meshing all the samples: the cubes come in the mesher's order and each cube's vertices
    /// are numbered as the mesher numbers them, and a copied vertex keeps its bits.
    ///
    /// `copied_from` receives, for every vertex of `out`, the index in `previous` of the vertex
    /// it was copied from, or `u32::MAX` for a vertex of a cube marched anew.
    ///
    /// Returns false, with `out` and `copied_from` cleared, when `previous` cannot be reused: it
    /// is not this grid's marching-cubes mesh with its per-vertex edges and cube runs, or it has
    /// transition patches.
    ///
    /// # Panics
    /// If `densities.len() != grid.sample_count()`.
    pub fn remesh_cubes(
        &mut self,
        grid: &ChunkGrid,
        densities: &[f32],
        previous: &ChunkMesh,
        region: Option<CubeBox>,
        out: &mut ChunkMesh,
        copied_from: &mut Vec<u32>,
    ) -> bool {
        assert_eq!(
            densities.len(),
            grid.sample_count(),
            "densities must cover the padded chunk grid"
        );
        copied_from.clear();
        let Some(edges) = copyable(grid, previous) else {
            out.clear();
            return false;
        };
        self.start(grid, out);
        let p = grid.padded;
        let coords = |flat: usize| [flat % p, (flat / p) % p, flat / (p * p)];
        let corner_flat = corner_flat_offsets(p);
        // The region's cut cubes (neither all solid nor all air), in the mesher's order.
        let mut fresh: Vec<(usize, u8)> = Vec::new();
        if let Some(r) = region {
            for c in r.lo[2]..=r.hi[2] {
                for b in r.lo[1]..=r.hi[1] {
                    for a in r.lo[0]..=r.hi[0] {
                        let base = grid.index(a, b, c);
                        let case = cube_case(densities, base, &corner_flat);
                        if case != 0 && case != 255 {
                            fresh.push((base, case));
                        }
                    }
                }
            }
        }
        let tables = &*TABLES;
        let mut ctx = Ctx {
            grid,
            densities,
            mesher: self,
            out,
        };
        let n_prev = previous.vertex_count();
        // Previous vertex -> new vertex (and, in `copied_from`, new -> previous).
        let mut map = vec![u32::MAX; n_prev];
        let mut cube_verts: Vec<(u8, u32)> = Vec::with_capacity(12);
        let runs = &previous.cube_runs;
        let (mut pi, mut fi, mut start) = (0, 0, 0usize);
        loop {
            let take_previous = match (runs.get(pi), fresh.get(fi)) {
                (None, None) => break,
                (Some(r), Some(f)) => (r[0] as usize) < f.0,
                (Some(_), None) => true,
                (None, Some(_)) => false,
            };
            if !take_previous {
                let (flat, case) = fresh[fi];
                fi += 1;
                let [a, b, c] = coords(flat);
                ctx.emit_cube(tables, case, a, b, c);
                continue;
            }
            let [flat, end] = runs[pi].map(|x| x as usize);
            pi += 1;
            let tris = &previous.indices[start * 3..end * 3];
            start = end;
            let cube = coords(flat);
            if region.is_some_and(|r| r.contains(cube)) {
                // Marched again above.
                continue;
            }
            // The cube's vertices not made yet, in the order of their cube edges, as
            // `emit_cube` makes them.
            cube_verts.clear();
            for &j in tris {
                if map[j as usize] == u32::MAX && !cube_verts.iter().any(|v| v.1 == j) {
                    cube_verts.push((0, j));
                }
            }
            if cube_verts.len() > 1 {
                for v in cube_verts.iter_mut() {
                    v.0 = cube_edge(edges[v.1 as usize], flat, &corner_flat);
                }
                cube_verts.sort_unstable();
            }
            for &(_, j) in &cube_verts {
                map[j as usize] = ctx.copy_vertex(previous, j as usize, edges[j as usize], copied_from);
            }
            ctx.out.indices.extend(tris.iter().map(|&j| map[j as usize]));
            let end = (ctx.out.indices.len() / 3) as u32;
            ctx.out.cube_runs.push([flat as u32, end]);
        }
        finish_normals(out);
        // Copied normals are final already (normalising them again could move a bit).
        copied_from.resize(out.vertex_count(), u32::MAX);
        for (new, &old) in copied_from.iter().enumerate().filter(|(_, j)| **j != u32::MAX) {
            out.normals[new] = previous.normals[old as usize];
        }
        true
    }
}

/// A vertex's grid edge as the mesher's edge cache keys it: the lower sample and the axis.
#[derive(Clone, Copy, Debug)]
struct Edge {
    lower: usize,
    axis: usize,
}

/// The grid edges of `previous`'s vertices, if it is this grid's marching-cubes mesh with its
/// records whole: per-vertex edges between neighbouring samples, cube runs in order covering
/// every triangle (so no transition patches), indices within the vertices.
fn copyable(grid: &ChunkGrid, previous: &ChunkMesh) -> Option<Vec<Edge>> {
    let n = previous.vertex_count();
    let p = grid.padded;
    let same_grid = previous.key == Some(grid.key)
        && previous.origin.to_array().map(f64::to_bits) == grid.origin.to_array().map(f64::to_bits);
    let whole = previous.normals.len() == n && previous.edge_keys.len() == n && previous.vertex_edges.len() == n;
    if !same_grid || !whole || !previous.indices.len().is_multiple_of(3) {
        return None;
    }
    let mut last = (None, 0);
    for r in &previous.cube_runs {
        let (flat, end) = (r[0] as usize, r[1] as usize);
        if last.0.is_some_and(|f| flat <= f) || end < last.1 || flat >= grid.sample_count() {
            return None;
        }
        last = (Some(flat), end);
    }
    if last.1 != previous.triangle_count() || previous.indices.iter().any(|&j| j as usize >= n) {
        return None;
    }
    previous
        .vertex_edges
        .iter()
        .map(|e| {
            let (lower, upper) = (e[0].min(e[1]) as usize, e[0].max(e[1]) as usize);
            let axis = [1, p, p * p].iter().position(|&step| upper - lower == step)?;
            (upper < grid.sample_count()).then_some(Edge { lower, axis })
        })
        .collect()
}

/// The number (0..12) of `edge` among the edges of the cube whose lowest corner is the sample
/// `cube` (flat index), the corners' flat offsets in `corner_flat`; 12 for an edge not the
/// cube's.
fn cube_edge(edge: Edge, cube: usize, corner_flat: &[usize; 8]) -> u8 {
    let offset = edge.lower.wrapping_sub(cube);
    let Some(corner) = corner_flat.iter().position(|&f| f == offset) else {
        return 12;
    };
    (0..12u8)
        .find(|&e| usize::from(EDGE_AXIS[e as usize]) == edge.axis && usize::from(EDGE_CORNERS[e as usize].0) == corner)
        .unwrap_or(12)
}

impl Ctx<'_> {
    /// Copies vertex `j` of `previous` (on `edge`) into the mesh, or finds it there already (a
    /// marched cube made it): its new index, recorded in `copied_from` when it is a copy.
    fn copy_vertex(&mut self, previous: &ChunkMesh, j: usize, edge: Edge, copied_from: &mut Vec<u32>) -> u32 {
        let slot = edge.lower * 3 + edge.axis;
        if let Some(idx) = self.mesher.cached_vertex(slot) {
            return idx;
        }
        let out = &mut *self.out;
        let idx = out.positions.len() as u32;
        out.positions.push(previous.positions[j]);
        out.positions_low
            .push(previous.positions_low.get(j).copied().unwrap_or([0.0; 3]));
        out.normals.push(previous.normals[j]);
        out.edge_keys.push(previous.edge_keys[j]);
        out.vertex_edges.push(previous.vertex_edges[j]);
        self.mesher.cache_vertex(slot, idx);
        // Vertices marched anew in between stay `u32::MAX`.
        copied_from.resize(idx as usize, u32::MAX);
        copied_from.push(j as u32);
        idx
    }
}
