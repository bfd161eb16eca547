//! Chunk keys and canonical voxel and edge keys.
//!
//! A voxel on a face edge belongs to two faces, a voxel at a cube corner to three, and a voxel on a
//! chunk border to up to eight chunks (seed 000 Sec. 4.4). Each voxel has one canonical key: the
//! integer point of the cube-surface lattice it projects from, plus its depth index. Positions and
//! densities are computed from that key only, so paired voxels are bit-identical by construction.

use crate::face::Face;
use glam::IVec3;

/// A chunk: face, level of detail, and its indices along `u`, `v` and depth.
///
/// A level-`L` chunk covers `2^L` times the tiles of a level-0 chunk per axis with the same number
/// of samples (stride `2^L`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ChunkKey {
    /// The face the chunk lies on.
    pub face: Face,
    /// Level of detail: 0 is the finest.
    pub level: u8,
    /// Chunk index along the face's `u` axis.
    pub i: u32,
    /// Chunk index along the face's `v` axis.
    pub j: u32,
    /// Chunk index along the depth axis (0 is the innermost).
    pub k: u32,
}

impl ChunkKey {
    /// A level-0 chunk key.
    pub fn new(face: Face, i: u32, j: u32, k: u32) -> ChunkKey {
        ChunkKey {
            face,
            level: 0,
            i,
            j,
            k,
        }
    }

    /// The sample stride of this chunk's level, in level-0 grid steps.
    pub fn stride(&self) -> i64 {
        1i64 << self.level
    }
}

impl std::fmt::Display for ChunkKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/L{}/{}_{}_{}", self.face, self.level, self.i, self.j, self.k)
    }
}

/// The canonical identity of a voxel: its cube-surface lattice point and depth index.
///
/// The lattice point of face `f`, grid indices `(i, j)` on a face with `N` tiles per side is
/// `N n + (2i - N) u + (2j - N) v` (frame of `f`): every component lies in `[-N, N]`, and voxels
/// shared by two or three faces get the same point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VoxelKey {
    /// Lattice point on the cube surface, in half grid steps.
    pub lattice: [i32; 3],
    /// Depth index (layer), 0 at the base depth.
    pub k: i32,
}

impl VoxelKey {
    /// Builds a key from a lattice point and a depth index.
    pub fn new(lattice: IVec3, k: i32) -> VoxelKey {
        VoxelKey {
            lattice: lattice.to_array(),
            k,
        }
    }

    /// Packs the key into 128 bits (lattice components must lie within +-2^30, as every
    /// [`Layout`](crate::Layout) guarantees).
    pub fn pack(&self) -> u128 {
        let c = |x: i32| u128::from((x as i64 + (1 << 30)) as u32);
        (c(self.lattice[0]) << 96) | (c(self.lattice[1]) << 64) | (c(self.lattice[2]) << 32) | c(self.k)
    }
}

/// The canonical identity of a grid edge (and so of a mesh vertex): its two voxels, smaller first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EdgeKey(pub u128, pub u128);

impl EdgeKey {
    /// The key of the edge between two voxels, in either order.
    pub fn new(a: VoxelKey, b: VoxelKey) -> EdgeKey {
        let (pa, pb) = (a.pack(), b.pack());
        if pa <= pb {
            EdgeKey(pa, pb)
        } else {
            EdgeKey(pb, pa)
        }
    }
}
