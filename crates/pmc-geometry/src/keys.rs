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

impl ChunkKey {
    /// The level-`level + 1` chunk holding this one (its parent in the face's octree).
    pub fn parent(&self) -> ChunkKey {
        ChunkKey {
            face: self.face,
            level: self.level + 1,
            i: self.i / 2,
            j: self.j / 2,
            k: self.k / 2,
        }
    }

    /// The eight level-`level - 1` chunks this one covers (children in the face's octree), in
    /// key order; `None` at level 0. Children past the shell's depth are included: check them
    /// with [`Layout::contains_chunk`](crate::Layout::contains_chunk).
    pub fn children(&self) -> Option<[ChunkKey; 8]> {
        let level = self.level.checked_sub(1)?;
        Some(std::array::from_fn(|n| ChunkKey {
            face: self.face,
            level,
            i: 2 * self.i + (n as u32 >> 2 & 1),
            j: 2 * self.j + (n as u32 >> 1 & 1),
            k: 2 * self.k + (n as u32 & 1),
        }))
    }
}

/// One of the six sides of a chunk, named in its face's local axes: `u`, `v` and depth (inner
/// towards the planet's centre, outer away from it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ChunkSide {
    /// The side at the smallest `u` index (`i0`).
    UMin,
    /// The side at the largest `u` index.
    UMax,
    /// The side at the smallest `v` index.
    VMin,
    /// The side at the largest `v` index.
    VMax,
    /// The innermost layer (smallest depth index).
    Inner,
    /// The outermost layer.
    Outer,
}

impl ChunkSide {
    /// The six sides, in bit order of [`SideMask`].
    pub const ALL: [ChunkSide; 6] = [
        ChunkSide::UMin,
        ChunkSide::UMax,
        ChunkSide::VMin,
        ChunkSide::VMax,
        ChunkSide::Inner,
        ChunkSide::Outer,
    ];

    /// The side's bit in a [`SideMask`].
    pub fn bit(self) -> u8 {
        1 << (self as u8)
    }

    /// The local axis the side is perpendicular to: 0 for `u`, 1 for `v`, 2 for depth.
    pub fn axis(self) -> usize {
        (self as usize) / 2
    }

    /// Whether the side is at the largest index of its axis.
    pub fn is_max(self) -> bool {
        (self as u8) % 2 == 1
    }
}

/// A set of [`ChunkSide`]s, one bit each (bit `n` is `ChunkSide::ALL[n]`).
///
/// Level-of-detail meshing uses it for the sides of a chunk across which the selected
/// neighbour is one level coarser: the chunk then closes the seam there (see
/// `pmc_mesh::Mesher::mesh_with_transitions`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SideMask(pub u8);

impl SideMask {
    /// No side.
    pub const NONE: SideMask = SideMask(0);
    /// Every side.
    pub const ALL: SideMask = SideMask(0x3f);

    /// Whether `side` is in the set.
    pub fn contains(self, side: ChunkSide) -> bool {
        self.0 & side.bit() != 0
    }

    /// The set with `side` added.
    pub fn with(self, side: ChunkSide) -> SideMask {
        SideMask(self.0 | side.bit())
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 & 0x3f == 0
    }

    /// The sides in the set, in bit order.
    pub fn sides(self) -> impl Iterator<Item = ChunkSide> {
        ChunkSide::ALL.into_iter().filter(move |s| self.contains(*s))
    }
}

/// The text form of a chunk key, the one every program and file uses (the HTTP API's chunk
/// paths, edit events, GLB node names): `face/level/i/j/k`, for example `top/0/3/4/1`.
impl std::fmt::Display for ChunkKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}/{}/{}/{}", self.face, self.level, self.i, self.j, self.k)
    }
}

/// Why a text was refused as a chunk key (`face/level/i/j/k`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ChunkKeyParseError {
    /// Not five `/`-separated parts. Write `face/level/i/j/k`, for example `top/0/3/4/1`.
    #[error("expected face/level/i/j/k (for example top/0/3/4/1), got {0} parts")]
    Parts(usize),
    /// The first part is not a face name. Use top, bottom, north, south, east or west.
    #[error("{0}")]
    Face(String),
    /// A numeric part is not a non-negative decimal integer in range (level below 256, indices
    /// below 2^32).
    #[error("chunk {what} must be a non-negative integer, got {text:?}")]
    Index {
        /// `level`, `i`, `j` or `k`.
        what: &'static str,
        /// The part as written.
        text: String,
    },
}

impl std::str::FromStr for ChunkKey {
    type Err = ChunkKeyParseError;

    /// Parses `face/level/i/j/k` (the face name in any case). Whether the key is a chunk of a
    /// given layout is not checked: see [`Layout::contains_chunk`](crate::Layout::contains_chunk).
    fn from_str(s: &str) -> Result<ChunkKey, ChunkKeyParseError> {
        let parts: Vec<&str> = s.split('/').collect();
        let [face, level, i, j, k] = parts[..] else {
            return Err(ChunkKeyParseError::Parts(parts.len()));
        };
        let face: Face = face.parse().map_err(ChunkKeyParseError::Face)?;
        let index = |what: &'static str, text: &str| {
            text.parse::<u32>().map_err(|_| ChunkKeyParseError::Index {
                what,
                text: text.to_string(),
            })
        };
        let level = u8::try_from(index("level", level)?).map_err(|_| ChunkKeyParseError::Index {
            what: "level",
            text: level.to_string(),
        })?;
        Ok(ChunkKey {
            face,
            level,
            i: index("i", i)?,
            j: index("j", j)?,
            k: index("k", k)?,
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_keys_round_trip_through_text() {
        let key = ChunkKey {
            face: Face::Top,
            level: 0,
            i: 3,
            j: 4,
            k: 1,
        };
        assert_eq!(key.to_string(), "top/0/3/4/1");
        for face in Face::ALL {
            let key = ChunkKey {
                face,
                level: 255,
                i: u32::MAX,
                j: 0,
                k: 7,
            };
            assert_eq!(key.to_string().parse::<ChunkKey>(), Ok(key));
        }
        assert_eq!("West/2/0/1/0".parse::<ChunkKey>().unwrap().face, Face::West);
    }

    #[test]
    fn bad_chunk_keys_are_refused_with_the_reason() {
        let err = |s: &str| s.parse::<ChunkKey>().unwrap_err();
        assert_eq!(err("top/0/3/4"), ChunkKeyParseError::Parts(4));
        assert_eq!(err(""), ChunkKeyParseError::Parts(1));
        assert_eq!(err("top/0/3/4/1/"), ChunkKeyParseError::Parts(6));
        assert!(matches!(err("up/0/0/0/0"), ChunkKeyParseError::Face(m) if m.contains("unknown face 'up'")));
        let index = |what: &'static str, text: &str| ChunkKeyParseError::Index {
            what,
            text: text.into(),
        };
        assert_eq!(err("top/L0/3/4/1"), index("level", "L0"));
        assert_eq!(err("top/256/0/0/0"), index("level", "256"));
        assert_eq!(err("top/0/-1/0/0"), index("i", "-1"));
        assert_eq!(err("top/0/0/4294967296/0"), index("j", "4294967296"));
        assert_eq!(err("top/0/0/0/x"), index("k", "x"));
        assert_eq!(err("top/0/3_4_1"), ChunkKeyParseError::Parts(3));
    }
}
