//! The sample grid of one chunk: voxel directions, layer radii and canonical keys, with one voxel
//! of padding on every side.
//!
//! # Overlap and padding contract
//!
//! A chunk of `n = n_t` tiles per axis owns the `(n + 1)^3` voxels at its tile corners; it shares
//! its border voxels with its neighbours (seed 000 Sec. 4.4: chunks overlap by their border
//! voxels). Around them lies one layer of padding, used only for density gradients (normals): the
//! grid is `(n + 3)^3` samples, local index `a` in `0..n + 3` standing for face grid index
//! `i0 + (a - 1) stride`. Padding past a face edge is the neighbouring face's voxel (unfolded as in
//! Algorithm 1). Past a cube corner, where neither face has a voxel, the padding column is marked
//! invalid and never read by the mesher.

use crate::face::Face;
use crate::keys::{ChunkKey, VoxelKey};
use crate::layout::Layout;
use glam::{DVec3, IVec3};

/// The sampling geometry of one chunk (see the module docs for the padding contract).
#[derive(Clone, Debug)]
pub struct ChunkGrid {
    /// The chunk.
    pub key: ChunkKey,
    /// Tiles per axis (`n_t`).
    pub tiles: usize,
    /// Samples per padded axis, `tiles + 3`.
    pub padded: usize,
    /// Level-0 grid steps between samples.
    pub stride: i64,
    /// Face grid index of local voxel 0 along `u` and `v`.
    pub i0: i64,
    /// Face grid index of local voxel 0 along `v`.
    pub j0: i64,
    /// Depth index of local voxel 0.
    pub k0: i64,
    /// Unit direction of each padded column, index `b * padded + a`.
    pub dirs: Vec<DVec3>,
    /// Canonical lattice point of each padded column.
    pub lattice: Vec<IVec3>,
    /// Whether each padded column exists (false only past cube corners).
    pub valid: Vec<bool>,
    /// Radius of each padded layer, index `c`.
    pub radii: Vec<f64>,
    /// The chunk's origin in world space: mesh vertices are stored relative to it.
    pub origin: DVec3,
}

/// Where a mesh vertex lies on an edge between two of a chunk's samples, by column: what a
/// shader reads the chunk's per-column values from ([`ChunkGrid::vertex_edge`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexEdge {
    /// The column of the first end (an index into [`ChunkGrid::dirs`]).
    pub a: u32,
    /// The column of the second end (`a` along the depth axis).
    pub b: u32,
    /// Where the vertex lies, from 0 at the first end to 1 at the second (0 along the depth
    /// axis, where both ends are one column).
    pub t: f64,
}

impl ChunkGrid {
    /// Builds the grid of `key`. Panics if the key is not a chunk of `layout` (a programming
    /// error: keys from outside must be checked with [`Layout::contains_chunk`]).
    pub fn new(layout: &Layout, key: ChunkKey) -> ChunkGrid {
        assert!(layout.contains_chunk(&key), "chunk {key} is not part of the layout");
        let tiles = layout.n_t() as usize;
        let padded = tiles + 3;
        let stride = key.stride();
        let span = tiles as i64 * stride;
        let (i0, j0, k0) = (
            i64::from(key.i) * span,
            i64::from(key.j) * span,
            i64::from(key.k) * span,
        );
        let mut dirs = Vec::with_capacity(padded * padded);
        let mut lattice = Vec::with_capacity(padded * padded);
        let mut valid = Vec::with_capacity(padded * padded);
        let mut fallback = None;
        for b in 0..padded {
            for a in 0..padded {
                let i = i0 + (a as i64 - 1) * stride;
                let j = j0 + (b as i64 - 1) * stride;
                match layout.lattice(key.face, i, j) {
                    Some(l) => {
                        lattice.push(l);
                        dirs.push(layout.lattice_direction(l));
                        valid.push(true);
                        fallback.get_or_insert(l);
                    }
                    None => {
                        // Past a cube corner: no voxel. Keep a harmless direction (the clamped
                        // corner) so batch density calls stay finite; the mesher never reads it.
                        let n = layout.face_tiles();
                        let l = layout
                            .lattice(key.face, i.clamp(0, n), j.clamp(0, n))
                            .expect("clamped index is on the face");
                        lattice.push(l);
                        dirs.push(layout.lattice_direction(l));
                        valid.push(false);
                    }
                }
            }
        }
        let radii = (0..padded)
            .map(|c| layout.layer_radius(k0 + (c as i64 - 1) * stride))
            .collect::<Vec<_>>();
        let mid = padded / 2;
        let origin = dirs[mid * padded + mid] * radii[mid];
        ChunkGrid {
            key,
            tiles,
            padded,
            stride,
            i0,
            j0,
            k0,
            dirs,
            lattice,
            valid,
            radii,
            origin,
        }
    }

    /// The grid of the chunk `k` deep under the same footprint (same face, level, `i` and `j`):
    /// the same columns, their directions copied rather than computed again, and that chunk's
    /// layers. The same as [`ChunkGrid::new`] for that chunk, field for field.
    ///
    /// # Panics
    /// If that chunk is not part of `layout`.
    pub fn at_depth(&self, layout: &Layout, k: u32) -> ChunkGrid {
        let key = ChunkKey { k, ..self.key };
        assert!(layout.contains_chunk(&key), "chunk {key} is not part of the layout");
        let k0 = i64::from(k) * self.tiles as i64 * self.stride;
        let radii: Vec<f64> = (0..self.padded)
            .map(|c| layout.layer_radius(k0 + (c as i64 - 1) * self.stride))
            .collect();
        let mid = self.padded / 2;
        ChunkGrid {
            key,
            k0,
            origin: self.dirs[mid * self.padded + mid] * radii[mid],
            radii,
            dirs: self.dirs.clone(),
            lattice: self.lattice.clone(),
            valid: self.valid.clone(),
            ..*self
        }
    }

    /// Number of padded samples, `padded^3`.
    pub fn sample_count(&self) -> usize {
        self.padded * self.padded * self.padded
    }

    /// Flat index of padded sample `(a, b, c)`: `a` fastest, then `b`, then `c` (depth).
    #[inline]
    pub fn index(&self, a: usize, b: usize, c: usize) -> usize {
        (c * self.padded + b) * self.padded + a
    }

    /// The [`VertexEdge`] of a vertex at world point `p` on the edge between padded samples
    /// `samples` (flat [`index`](Self::index)es, first end first): their columns, and where `p`
    /// projects onto the segment between their positions, clamped to `[0, 1]`.
    ///
    /// # Panics
    /// If a sample index is past the grid.
    pub fn vertex_edge(&self, samples: [u32; 2], p: DVec3) -> VertexEdge {
        let layer = self.padded * self.padded;
        let [f, s] = samples.map(|x| x as usize);
        let (a, b) = (f % layer, s % layer);
        let t = if a == b {
            0.0
        } else {
            let pf = self.dirs[a] * self.radii[f / layer];
            let d = self.dirs[b] * self.radii[s / layer] - pf;
            ((p - pf).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        };
        VertexEdge {
            a: a as u32,
            b: b as u32,
            t,
        }
    }

    /// World position of padded sample `(a, b, c)`.
    #[inline]
    pub fn position(&self, a: usize, b: usize, c: usize) -> DVec3 {
        self.dirs[b * self.padded + a] * self.radii[c]
    }

    /// Canonical key of padded sample `(a, b, c)`.
    #[inline]
    pub fn voxel_key(&self, a: usize, b: usize, c: usize) -> VoxelKey {
        VoxelKey::new(
            self.lattice[b * self.padded + a],
            (self.k0 + (c as i64 - 1) * self.stride) as i32,
        )
    }

    /// The face of the chunk.
    pub fn face(&self) -> Face {
        self.key.face
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_at_another_depth_is_the_grid_of_that_chunk() {
        let l = Layout::new(2, 4, 30.0, 1.0, 3).unwrap();
        for key in l.chunks(0).into_iter().chain(l.chunks(1)) {
            let top = ChunkGrid::new(&l, ChunkKey { k: 0, ..key });
            let (a, b) = (top.at_depth(&l, key.k), ChunkGrid::new(&l, key));
            assert_eq!(a.key, b.key);
            assert_eq!(
                (a.tiles, a.padded, a.stride, a.i0, a.j0, a.k0),
                (b.tiles, b.padded, b.stride, b.i0, b.j0, b.k0)
            );
            assert_eq!(
                (a.dirs, a.lattice, a.valid, a.radii),
                (b.dirs, b.lattice, b.valid, b.radii)
            );
            assert_eq!(a.origin, b.origin);
        }
    }

    #[test]
    fn neighbouring_chunks_share_border_voxels_bit_for_bit() {
        let l = Layout::new(2, 4, 30.0, 1.0, 2).unwrap();
        let mut seen: std::collections::HashMap<VoxelKey, DVec3> = Default::default();
        for key in l.chunks(0) {
            let g = ChunkGrid::new(&l, key);
            for c in 1..=g.tiles + 1 {
                for b in 1..=g.tiles + 1 {
                    for a in 1..=g.tiles + 1 {
                        let k = g.voxel_key(a, b, c);
                        let p = g.position(a, b, c);
                        let prev = *seen.entry(k).or_insert(p);
                        assert_eq!(prev.to_array().map(f64::to_bits), p.to_array().map(f64::to_bits));
                    }
                }
            }
        }
        assert_eq!(seen.len() as u64, l.unique_voxel_count());
    }

    #[test]
    fn padding_is_invalid_only_past_cube_corners() {
        let l = Layout::new(1, 4, 30.0, 1.0, 1).unwrap();
        let g = ChunkGrid::new(&l, ChunkKey::new(Face::Top, 0, 0, 0));
        let invalid = g.valid.iter().filter(|v| !**v).count();
        assert_eq!(invalid, 4);
    }

    #[test]
    #[should_panic(expected = "not part of the layout")]
    fn foreign_key_is_refused() {
        let l = Layout::new(1, 4, 30.0, 1.0, 1).unwrap();
        ChunkGrid::new(&l, ChunkKey::new(Face::Top, 1, 0, 0));
    }
}
