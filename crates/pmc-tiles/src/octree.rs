//! The octree of each cube face: tile coordinates, chunk keys, Morton order.
//!
//! A face's chunks already form an octree that also covers depth (`ChunkKey::level`: a level-`L`
//! chunk covers `2^L` level-0 chunks along `u`, `v` and depth). Tiles count levels the other
//! way, from the root: tile level `ℓ` holds the chunks of level
//! `L = top + v - ℓ`, with `x = i`, `y = j`, `z = k` (depth outward), where `top` is the
//! layout's coarsest level and `v` the number of *virtual* levels above it. A layout whose
//! coarsest level has more than one chunk per face side or along depth (`m` of them) needs
//! `v = ceil(log2 m)` levels of tiles with no chunk and no content, so that one root holds the
//! face; for the `earth` preset `v = 0` and the root is the face's single level-18 chunk.

use pmc_geometry::{ChunkKey, Face, Layout};

/// Levels per subtree file: a subtree holds `1 + 8 + 64` tiles and up to 512 child subtrees.
pub const SUBTREE_LEVELS: u8 = 3;

/// A tile of a face's tile octree.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileCoord {
    /// The face whose octree holds the tile.
    pub face: Face,
    /// Implicit level: 0 is the face's root.
    pub level: u8,
    /// Along the face's `u` axis.
    pub x: u32,
    /// Along the face's `v` axis.
    pub y: u32,
    /// Along depth, outward.
    pub z: u32,
}

impl TileCoord {
    /// The face's root tile.
    pub fn root(face: Face) -> TileCoord {
        TileCoord {
            face,
            level: 0,
            x: 0,
            y: 0,
            z: 0,
        }
    }

    /// The tile holding this one (`None` for a root).
    pub fn parent(&self) -> Option<TileCoord> {
        Some(TileCoord {
            level: self.level.checked_sub(1)?,
            x: self.x / 2,
            y: self.y / 2,
            z: self.z / 2,
            face: self.face,
        })
    }

    /// The tile `d` levels below this one at offsets `(dx, dy, dz)` (each below `2^d`).
    pub fn descendant(&self, d: u8, dx: u32, dy: u32, dz: u32) -> TileCoord {
        TileCoord {
            face: self.face,
            level: self.level + d,
            x: (self.x << d) + dx,
            y: (self.y << d) + dy,
            z: (self.z << d) + dz,
        }
    }

    /// The root of the subtree file holding this tile.
    pub fn subtree_root(&self) -> TileCoord {
        let d = self.level % SUBTREE_LEVELS;
        TileCoord {
            face: self.face,
            level: self.level - d,
            x: self.x >> d,
            y: self.y >> d,
            z: self.z >> d,
        }
    }

    /// The tile's path below a face folder: `level/x/y/z`.
    pub fn path(&self) -> String {
        format!("{}/{}/{}/{}", self.level, self.x, self.y, self.z)
    }
}

/// Interleaves the low bits of `x`, `y`, `z` (x lowest): the octree Morton index.
pub fn morton3(x: u32, y: u32, z: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = u64::from(v) & 0x1f_ffff;
        v = (v | v << 32) & 0x001f_0000_0000_ffff;
        v = (v | v << 16) & 0x001f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        v = (v | v << 2) & 0x1249_2492_4924_9249;
        v
    }
    spread(x) | spread(y) << 1 | spread(z) << 2
}

/// The inverse of [`morton3`].
pub fn demorton3(m: u64) -> (u32, u32, u32) {
    fn compact(mut v: u64) -> u32 {
        v &= 0x1249_2492_4924_9249;
        v = (v | v >> 2) & 0x10c3_0c30_c30c_30c3;
        v = (v | v >> 4) & 0x100f_00f0_0f00_f00f;
        v = (v | v >> 8) & 0x001f_0000_ff00_00ff;
        v = (v | v >> 16) & 0x001f_0000_0000_ffff;
        v = (v | v >> 32) & 0x1f_ffff;
        v as u32
    }
    (compact(m), compact(m >> 1), compact(m >> 2))
}

/// Tiles in the first `levels` levels of an octree: `(8^levels - 1) / 7`.
pub fn octree_tiles(levels: u8) -> u64 {
    ((1u64 << (3 * u32::from(levels))) - 1) / 7
}

/// How a layout's chunks sit in the faces' tile octrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tiling {
    layout: Layout,
    top: u8,
    virtual_levels: u8,
}

impl Tiling {
    /// The tiling of `layout`.
    pub fn new(layout: Layout) -> Tiling {
        let top = layout.max_level();
        let m = layout.chunks_per_side(top).max(layout.depth_chunks(top));
        let virtual_levels = (32 - (m - 1).leading_zeros()) as u8;
        Tiling {
            layout,
            top,
            virtual_levels,
        }
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Levels of tiles with no chunk above the coarsest chunks.
    pub fn virtual_levels(&self) -> u8 {
        self.virtual_levels
    }

    /// Implicit levels in all: the virtual ones and one per level of detail.
    pub fn levels(&self) -> u8 {
        self.virtual_levels + self.top + 1
    }

    /// The level of detail of tile level `level` (`None` for a virtual level).
    pub fn chunk_level(&self, level: u8) -> Option<u8> {
        let l = (self.top + self.virtual_levels).checked_sub(level)?;
        (level >= self.virtual_levels).then_some(l)
    }

    /// The tile level of level of detail `lod`.
    pub fn tile_level(&self, lod: u8) -> u8 {
        self.top + self.virtual_levels - lod
    }

    /// Whether the tile exists: a chunk of the layout, or a virtual tile over some.
    pub fn exists(&self, t: &TileCoord) -> bool {
        if t.level >= self.levels() {
            return false;
        }
        match self.chunk_level(t.level) {
            Some(l) => {
                t.x < self.layout.chunks_per_side(l)
                    && t.y < self.layout.chunks_per_side(l)
                    && t.z < self.layout.depth_chunks(l)
            }
            None => {
                let shift = u32::from(self.virtual_levels - t.level);
                let side = self.layout.chunks_per_side(self.top).div_ceil(1 << shift);
                let depth = self.layout.depth_chunks(self.top).div_ceil(1 << shift);
                t.x < side && t.y < side && t.z < depth
            }
        }
    }

    /// The chunk of a tile (`None` for a virtual tile or one past the grid).
    pub fn key(&self, t: &TileCoord) -> Option<ChunkKey> {
        if !self.exists(t) {
            return None;
        }
        let level = self.chunk_level(t.level)?;
        Some(ChunkKey {
            face: t.face,
            level,
            i: t.x,
            j: t.y,
            k: t.z,
        })
    }

    /// The tile of a chunk.
    pub fn tile(&self, key: &ChunkKey) -> TileCoord {
        TileCoord {
            face: key.face,
            level: self.tile_level(key.level),
            x: key.i,
            y: key.j,
            z: key.k,
        }
    }
}
