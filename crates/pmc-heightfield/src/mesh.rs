//! Patch meshes: positions, normals with a one-sample border, stitched index buffers.

use crate::heights::LatticeHeights;
use crate::lattice::{canonical_lattice, face_lattice, lattice_direction, PATCH_SEGMENTS, PATCH_SIDE};
use crate::patch::{Corner, PatchError, PatchKey, Side, Stitch};
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{cube_sphere_factor, EdgeKey, FaceGrid, VoxelKey};
use pmc_mesh::ChunkMesh;
use std::cell::RefCell;
use std::sync::OnceLock;

/// Side of the sample grid: the patch's 65 vertices plus one border sample on each side.
const GRID: usize = PATCH_SIDE as usize + 2;
const SIDE: usize = PATCH_SIDE as usize;
const SEG: i64 = PATCH_SEGMENTS as i64;

/// The colour every patch vertex gets (shading belongs to the caller).
pub const PATCH_COLOR: [u8; 4] = [255, 255, 255, 255];

/// The world position (metres, planet-centred, `f64`) of lattice point `lattice` of resolution
/// `m`: `lattice_direction(lattice, m) * (radius + height)`.
///
/// Every patch computes its vertices with exactly this expression, so a point has the same bits
/// in every patch, level and face that holds it (given the [`LatticeHeights`] contract).
#[inline]
pub fn vertex_position<H: LatticeHeights + ?Sized>(heights: &H, radius: f64, lattice: IVec3, m: i64) -> DVec3 {
    lattice_direction(lattice, m) * (radius + heights.height(lattice, m as i32))
}

/// Cross product written out, so its bits are fixed: `cross(b, -a) == cross(a, b)` bit for bit,
/// which makes normals independent of how a face's frame labels the neighbours.
#[inline]
fn cross(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)
}

#[inline]
fn unit_f32(n: DVec3) -> [f32; 3] {
    let n = n * (1.0 / n.length());
    [n.x as f32, n.y as f32, n.z as f32]
}

/// The index buffer of a patch for each combination of stitched sides (16), built once.
///
/// Vertex `(a, b)` has index `b * 65 + a`. The patch is cut into 32 × 32 blocks of 2 × 2 quads; each
/// block is a fan of 8 triangles around its centre vertex, and a block side on a stitched patch
/// side drops its middle vertex (one triangle instead of two), so a stitched side's edges run
/// between even vertices only. Triangles wind counter-clockwise in `(u, v)`, that is, seen from
/// outside the planet.
pub fn patch_indices(sides: u8) -> &'static [u32] {
    static TABLES: OnceLock<Vec<Vec<u32>>> = OnceLock::new();
    &TABLES.get_or_init(|| (0..16u8).map(build_indices).collect())[usize::from(sides & 15)]
}

fn build_indices(sides: u8) -> Vec<u32> {
    let stitched = |s: Side| Stitch::NONE.with_side(s).side_bits() & sides != 0;
    let last = SEG as u32 / 2 - 1;
    let idx = |a: u32, b: u32| b * PATCH_SIDE + a;
    let mut out = Vec::with_capacity((PATCH_SEGMENTS * PATCH_SEGMENTS * 6) as usize);
    for q in 0..=last {
        for p in 0..=last {
            let (a, b) = (2 * p, 2 * q);
            // The block's border, counter-clockwise, with the middle vertices that stitching drops.
            let ring: [(u32, u32, bool); 8] = [
                (a, b, false),
                (a + 1, b, q == 0 && stitched(Side::MinV)),
                (a + 2, b, false),
                (a + 2, b + 1, p == last && stitched(Side::MaxU)),
                (a + 2, b + 2, false),
                (a + 1, b + 2, q == last && stitched(Side::MaxV)),
                (a, b + 2, false),
                (a, b + 1, p == 0 && stitched(Side::MinU)),
            ];
            let kept: Vec<u32> = ring.iter().filter(|r| !r.2).map(|r| idx(r.0, r.1)).collect();
            let centre = idx(a + 1, b + 1);
            for k in 0..kept.len() {
                out.extend_from_slice(&[centre, kept[k], kept[(k + 1) % kept.len()]]);
            }
        }
    }
    out
}

/// Samples of one patch: positions on the 67 × 67 grid (vertices and the one-sample border; the
/// four grid corners are never read and stay unset).
struct Samples<'a, H: ?Sized> {
    heights: &'a H,
    key: PatchKey,
    radius: f64,
    m: i64,
    pos: &'a [DVec3],
    lattice: &'a [IVec3],
}

impl<H: LatticeHeights + ?Sized> Samples<'_, H> {
    #[inline]
    fn g(a: i64, b: i64) -> usize {
        (b + 1) as usize * GRID + (a + 1) as usize
    }

    /// Position of vertex-grid point `(a, b)`: from the grid when it lies on it, else computed.
    fn at(&self, a: i64, b: i64) -> DVec3 {
        let on_grid = |x: i64| (-1..=SEG + 1).contains(&x);
        let corner = !(0..=SEG).contains(&a) && !(0..=SEG).contains(&b);
        if on_grid(a) && on_grid(b) && !corner {
            self.pos[Self::g(a, b)]
        } else {
            let p = self
                .key
                .vertex_lattice(a, b)
                .expect("normal stencils never reach past a cube corner");
            vertex_position(self.heights, self.radius, p, self.m)
        }
    }

    /// The normal at vertex `(a, b)` from central differences at spacing `s` (1 or 2 vertex steps),
    /// or from the three edge neighbours when the vertex is a cube corner.
    fn normal(&self, a: i64, b: i64, s: i64) -> DVec3 {
        let (fi, fj) = (SEG * i64::from(self.key.i) + a, SEG * i64::from(self.key.j) + b);
        if (fi == 0 || fi == self.m) && (fj == 0 || fj == self.m) {
            return self.corner_normal(self.lattice[Self::g(a, b)], s);
        }
        let du = self.at(a + s, b) - self.at(a - s, b);
        let dv = self.at(a, b + s) - self.at(a, b - s);
        cross(du, dv)
    }

    /// At a cube corner three faces meet and each face's stencil would see different points, so
    /// the normal comes from the three points one step (`s` vertex steps) along the three cube
    /// edges, taken in axis order (x, y, z) and turned outward: the same bits from every face.
    fn corner_normal(&self, c: IVec3, s: i64) -> DVec3 {
        let step = (2 * s) as i32;
        let along = |k: usize| {
            let mut p = c;
            p[k] -= c[k].signum() * step;
            vertex_position(self.heights, self.radius, p, self.m)
        };
        let (px, py, pz) = (along(0), along(1), along(2));
        let n = cross(py - px, pz - px);
        if n.dot(c.as_dvec3()) < 0.0 {
            -n
        } else {
            n
        }
    }
}

/// Generates the mesh of patch `key` into `out` (cleared first, capacity kept).
///
/// - 65 × 65 vertices in a fixed layout (vertex `(a, b)` at index `b * 65 + a`), position
///   [`vertex_position`] of lattice point [`PatchKey::vertex_lattice`]`(a, b)`, stored as `f32`
///   relative to `out.origin` (the patch's centre vertex, `f64`). On a stitched side the odd
///   vertices stay in the buffers but no triangle uses them.
/// - Normals: central differences of positions over the four neighbours at one vertex step,
///   reaching one sample past the patch (across face edges by unfolding), so co-located vertices
///   of same-level patches get equal normals. A vertex that a coarser patch also holds (even
///   vertices of a stitched side, flagged corners) uses two steps, the coarser patch's spacing,
///   and so gets the coarser patch's normal. A cube corner's normal comes from its three edge
///   neighbours, the same from all three faces.
/// - Indices: [`patch_indices`] for the stitched sides.
/// - `edge_keys`: both halves are the vertex's [`canonical_lattice`] (as a [`VoxelKey`] with
///   `k = 0`), so `pmc_mesh::WeldedMesh` welds co-located vertices of any patches.
/// - `heights`: metres above the datum radius; `water_depths` 0, `colors` [`PATCH_COLOR`],
///   `materials` 0; `key` is `None` (a patch is no marching-cubes chunk).
///
/// Refuses keys that [`PatchKey::validate`] refuses and a non-finite or non-positive `radius`.
pub fn generate_patch<H: LatticeHeights + ?Sized>(
    heights: &H,
    radius: f64,
    key: PatchKey,
    stitch: Stitch,
    out: &mut ChunkMesh,
) -> Result<(), PatchError> {
    key.validate()?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(PatchError::InvalidParameter("radius must be finite and positive"));
    }
    let m = key.resolution();
    SCRATCH.with(|scratch| {
        let mut scratch = scratch.borrow_mut();
        let Scratch { lattice, hs, pos } = &mut *scratch;
        grid_heights(heights, key, lattice, hs);
        fill_positions(key, lattice, hs, radius, m, pos);
        let samples = Samples {
            heights,
            key,
            radius,
            m,
            pos,
            lattice,
        };
        write_mesh(&samples, hs, stitch, out);
    });
    Ok(())
}

/// The least and greatest height (metres above the datum) of the 65 × 65 vertices of patch
/// `key`: the heights [`generate_patch`] gives them, bit for bit. Every vertex of the patch's
/// mesh, whatever its stitching, is one of them (a stitched side drops vertices, it adds none),
/// so the mesh lies between the radii `datum + low` and `datum + high` (a triangle lies in the
/// convex hull of its corners). Selections bound a patch by these instead of the whole relief.
///
/// Refuses keys that [`PatchKey::validate`] refuses.
pub fn patch_height_range<H: LatticeHeights + ?Sized>(heights: &H, key: PatchKey) -> Result<(f64, f64), PatchError> {
    key.validate()?;
    Ok(SCRATCH.with(|scratch| {
        let mut scratch = scratch.borrow_mut();
        let Scratch { lattice, hs, .. } = &mut *scratch;
        grid_heights(heights, key, lattice, hs);
        hs.chunks_exact(GRID)
            .skip(1)
            .take(SIDE)
            .flat_map(|row| &row[1..=SIDE])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }))
}

/// The lattice points of patch `key`'s 67 × 67 sample grid (its vertices and the one-sample
/// border) into `lattice`, and their heights into `hs`.
fn grid_heights<H: LatticeHeights + ?Sized>(heights: &H, key: PatchKey, lattice: &mut Vec<IVec3>, hs: &mut Vec<f64>) {
    fill_lattice(key, lattice);
    hs.resize(lattice.len(), 0.0);
    let grid = FaceGrid {
        face: key.face,
        i0: SEG * i64::from(key.i) - 1,
        j0: SEG * i64::from(key.j) - 1,
        side: GRID,
    };
    heights.heights_on_grid(&grid, lattice, key.resolution() as i32, hs);
}

/// The positions of the sample grid, `lattice_direction(p, m) * (radius + h)` with the same bits:
/// on the patch's face, the cube-to-sphere factor of the component along the face's `u` axis
/// depends on the row alone and the one along `v` on the column alone, so they are computed once
/// per row and column (the points past the face's edges take the whole map).
fn fill_positions(key: PatchKey, lattice: &[IVec3], hs: &[f64], radius: f64, m: i64, pos: &mut Vec<DVec3>) {
    let fr = key.face.frame();
    let axis = |v: IVec3| {
        if v.x != 0 {
            0
        } else if v.y != 0 {
            1
        } else {
            2
        }
    };
    let (ku, kv) = (axis(fr.u), axis(fr.v));
    let inv = 1.0 / m as f64;
    let (fi, fj) = (SEG * i64::from(key.i) - 1, SEG * i64::from(key.j) - 1);
    let on_face = |x: i64| (0..=m).contains(&x);
    // Component `k`'s factor from the squares `sq` (see `cube_sphere_factor`).
    let factor = |k: usize, sq: [f64; 3]| cube_sphere_factor(sq[(k + 1) % 3], sq[(k + 2) % 3]);
    let mut columns: [Option<f64>; GRID] = [None; GRID];
    pos.clear();
    for (b, (row_points, row_heights)) in lattice.chunks_exact(GRID).zip(hs.chunks_exact(GRID)).enumerate() {
        let mut row: Option<f64> = None;
        for (a, (p, h)) in row_points.iter().zip(row_heights).enumerate() {
            let (i, j) = (fi + a as i64, fj + b as i64);
            let dir = if on_face(i) && on_face(j) {
                let c = p.as_dvec3() * inv;
                let sq = [c.x * c.x, c.y * c.y, c.z * c.z];
                let mut f = [0.0; 3];
                for (k, fk) in f.iter_mut().enumerate() {
                    *fk = if k == ku {
                        *row.get_or_insert_with(|| factor(k, sq))
                    } else if k == kv {
                        *columns[a].get_or_insert_with(|| factor(k, sq))
                    } else {
                        factor(k, sq)
                    };
                }
                DVec3::new(c.x * f[0], c.y * f[1], c.z * f[2])
            } else {
                lattice_direction(*p, m)
            };
            pos.push(dir * (radius + h));
        }
    }
}

/// Per-thread sample buffers, so that generating a patch allocates nothing once warm.
#[derive(Default)]
struct Scratch {
    lattice: Vec<IVec3>,
    hs: Vec<f64>,
    pos: Vec<DVec3>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// The lattice points of the 67 × 67 sample grid: the patch incrementally, the border by
/// unfolding. The four grid corners are never read; where there is no lattice point (past a cube
/// corner) they repeat the nearest patch corner, so that every entry is a valid point.
fn fill_lattice(key: PatchKey, lattice: &mut Vec<IVec3>) {
    let fr = key.face.frame();
    let base = key.vertex_lattice(0, 0).expect("patch corner lies on the face");
    let (du, dv) = (fr.u * 2, fr.v * 2);
    lattice.clear();
    for b in -1..=SEG + 1 {
        let border_row = !(0..=SEG).contains(&b);
        for a in -1..=SEG + 1 {
            let border_col = !(0..=SEG).contains(&a);
            let p = if border_row && border_col {
                key.vertex_lattice(a, b).unwrap_or_else(|| {
                    let (ca, cb) = (a.clamp(0, SEG), b.clamp(0, SEG));
                    base + du * ca as i32 + dv * cb as i32
                })
            } else if border_row || border_col {
                key.vertex_lattice(a, b)
                    .expect("border samples lie past one edge at most")
            } else {
                base + du * a as i32 + dv * b as i32
            };
            lattice.push(p);
        }
    }
}

fn write_mesh<H: LatticeHeights + ?Sized>(samples: &Samples<'_, H>, hs: &[f64], stitch: Stitch, out: &mut ChunkMesh) {
    let g = |a: i64, b: i64| (b + 1) as usize * GRID + (a + 1) as usize;
    let pos = samples.pos;
    let m = samples.m;
    out.clear();
    let centre = SEG / 2;
    let origin = pos[g(centre, centre)];
    out.origin = origin;
    let n = SIDE * SIDE;
    out.positions.resize(n, [0.0; 3]);
    out.positions_low.resize(n, [0.0; 3]);
    out.normals.resize(n, [0.0; 3]);
    out.edge_keys.resize(n, EdgeKey(0, 0));
    out.heights.resize(n, 0.0);
    let rows = out
        .positions
        .chunks_exact_mut(SIDE)
        .zip(out.positions_low.chunks_exact_mut(SIDE))
        .zip(out.normals.chunks_exact_mut(SIDE))
        .zip(
            out.edge_keys
                .chunks_exact_mut(SIDE)
                .zip(out.heights.chunks_exact_mut(SIDE)),
        );
    for (b, (((positions, lows), normals), (keys, heights))) in (0..=SEG).zip(rows) {
        let row = g(0, b);
        let (p_row, h_row, l_row) = (
            &pos[row..row + SIDE],
            &hs[row..row + SIDE],
            &samples.lattice[row..row + SIDE],
        );
        for a in 0..SIDE {
            let d = p_row[a] - origin;
            let high = d.as_vec3();
            positions[a] = high.to_array();
            lows[a] = (d - high.as_dvec3()).as_vec3().to_array();
            heights[a] = h_row[a] as f32;
            let c = VoxelKey::new(canonical_lattice(l_row[a], m), 0).pack();
            keys[a] = EdgeKey(c, c);
        }
        let border_row = b == 0 || b == SEG;
        for (a, nrm) in (0..=SEG).zip(normals.iter_mut()) {
            let k = row + a as usize;
            let normal = if border_row || a == 0 || a == SEG {
                samples.normal(a, b, spacing(stitch, a, b))
            } else {
                cross(pos[k + 1] - pos[k - 1], pos[k + GRID] - pos[k - GRID])
            };
            *nrm = unit_f32(normal);
        }
    }
    out.water_depths.resize(n, 0.0);
    out.colors.resize(n, PATCH_COLOR);
    out.materials.resize(n, 0);
    out.indices.extend_from_slice(patch_indices(stitch.side_bits()));
}

/// The stencil spacing of vertex `(a, b)`: 2 where a coarser patch holds the vertex, else 1.
fn spacing(stitch: Stitch, a: i64, b: i64) -> i64 {
    let even_on = |side: Side, on: bool, along: i64| on && along % 2 == 0 && stitch.side(side);
    let corner = Corner::ALL.into_iter().any(|c| {
        let (ca, cb) = c.vertex();
        (i64::from(ca), i64::from(cb)) == (a, b) && stitch.corner(c)
    });
    if corner
        || even_on(Side::MinU, a == 0, b)
        || even_on(Side::MaxU, a == SEG, b)
        || even_on(Side::MinV, b == 0, a)
        || even_on(Side::MaxV, b == SEG, a)
    {
        2
    } else {
        1
    }
}

/// The lattice point of vertex `(a, b)` of `key` at [`crate::CANONICAL_RESOLUTION`]: the identity
/// that `generate_patch` writes into `edge_keys`.
pub fn vertex_canonical_lattice(key: PatchKey, a: u32, b: u32) -> Option<IVec3> {
    let p = face_lattice(
        key.face,
        SEG * i64::from(key.i) + i64::from(a),
        SEG * i64::from(key.j) + i64::from(b),
        key.resolution(),
    )?;
    Some(canonical_lattice(p, key.resolution()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Face;

    /// The row and column factors give the bits of the whole map, on every face, at face edges
    /// and cube corners, at several levels.
    #[test]
    fn grid_positions_are_the_bits_of_the_map() {
        let heights: Vec<f64> = (0..GRID * GRID).map(|k| (k % 97) as f64 * 13.7 - 300.0).collect();
        let mut lattice = Vec::new();
        let mut pos = Vec::new();
        for face in Face::ALL {
            for level in [0u8, 1, 3, 9] {
                let n = 1u32 << level;
                for (i, j) in [(0, 0), (n - 1, 0), (n / 2, n / 3), (n - 1, n - 1), (0, n - 1)] {
                    let key = PatchKey::new(face, level, i, j).unwrap();
                    let m = key.resolution();
                    fill_lattice(key, &mut lattice);
                    fill_positions(key, &lattice, &heights, 6.371e6, m, &mut pos);
                    for ((p, h), got) in lattice.iter().zip(&heights).zip(&pos) {
                        let want = lattice_direction(*p, m) * (6.371e6 + h);
                        assert_eq!(
                            got.to_array().map(f64::to_bits),
                            want.to_array().map(f64::to_bits),
                            "{key} {p}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn index_buffers_cover_the_patch_once() {
        for sides in 0..16u8 {
            let idx = patch_indices(sides);
            let tris = idx.len() / 3;
            let dropped = sides.count_ones() as usize * 32;
            assert_eq!(tris, 64 * 64 * 2 - dropped, "sides {sides:04b}");
            // Twice the signed area in (a, b) sums to the patch's 2 * 64 * 64.
            let ab = |v: u32| ((v % PATCH_SIDE) as i64, (v / PATCH_SIDE) as i64);
            let mut area = 0;
            for t in idx.chunks_exact(3) {
                let (p, q, r) = (ab(t[0]), ab(t[1]), ab(t[2]));
                let a2 = (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0);
                assert!(a2 > 0, "counter-clockwise, non-degenerate");
                area += a2;
            }
            assert_eq!(area, 2 * 64 * 64);
        }
    }

    /// A patch's height range is its mesh's: the least and greatest vertex height, with the
    /// mesher's bits, for every stitching, on every face, at coarse and fine levels.
    #[test]
    fn height_range_is_the_mesh_vertices_range() {
        let ripples = crate::Ripples {
            amplitude: 800.0,
            frequency: 23.0,
        };
        let mut mesh = ChunkMesh::default();
        for face in Face::ALL {
            for (level, i, j) in [(0u8, 0u32, 0u32), (2, 3, 1), (5, 17, 30), (9, 511, 0)] {
                let key = PatchKey::new(face, level, i, j).unwrap();
                let (lo, hi) = patch_height_range(&ripples, key).unwrap();
                assert!(lo < hi, "ripples vary over a patch");
                for sides in [0u8, 5, 15] {
                    let mut stitch = Stitch::NONE;
                    for (bit, side) in [(1, Side::MinU), (2, Side::MaxU), (4, Side::MinV), (8, Side::MaxV)] {
                        if sides & bit != 0 {
                            stitch = stitch.with_side(side);
                        }
                    }
                    generate_patch(&ripples, 6.0e6, key, stitch, &mut mesh).unwrap();
                    let low = mesh.heights.iter().copied().fold(f32::INFINITY, f32::min);
                    let high = mesh.heights.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                    assert_eq!((low, high), (lo as f32, hi as f32), "{key:?} {sides}");
                }
            }
        }
        assert!(patch_height_range(
            &ripples,
            PatchKey {
                face: Face::Top,
                level: 1,
                i: 2,
                j: 0
            }
        )
        .is_err());
    }
}
