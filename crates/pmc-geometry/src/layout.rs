//! The planet layout of seed 000 Sec. 4.3: parameters `n_c`, `n_t`, `d_b`, `l_d`, `d_c`, and the
//! counts and radius of Eq. (2)-(4).

use crate::cube_sphere::cube_to_sphere;
use crate::face::Face;
use crate::keys::{ChunkKey, ChunkSide, SideMask, VoxelKey};
use glam::{DVec3, IVec3};

/// Largest number of tiles along a face edge or the depth axis (keeps lattice keys in 32 bits).
pub const MAX_AXIS_TILES: u64 = 1 << 24;
/// Largest number of tiles per chunk axis (`n_t`): bounds the memory of one chunk.
pub const MAX_CHUNK_TILES: u32 = 128;

/// Indices that name no chunk of a layout ([`Layout::chunk_key`]); the message says which.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct NotAChunk(pub String);

/// Why a set of layout parameters was refused. Each variant says which parameter to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// `n_c` must be at least 1: a face needs at least one chunk per side.
    #[error("n_c (chunks per face side) must be at least 1, got {0}")]
    ChunksPerSide(u32),
    /// `n_t` must be in `1..=128`.
    #[error("n_t (tiles per chunk side) must be between 1 and {MAX_CHUNK_TILES}, got {0}")]
    TilesPerChunk(u32),
    /// `d_c` must be at least 1.
    #[error("d_c (chunks along the depth axis) must be at least 1, got {0}")]
    DepthChunks(u32),
    /// `l_d` must be a finite length above zero, in metres.
    #[error("l_d (tile length along depth) must be a finite number of metres above 0, got {0}")]
    TileDepth(f64),
    /// `d_b` must be finite and at least `l_d`, so the padding layer below the base stays
    /// outside the centre.
    #[error("d_b (base depth, the radius of the innermost layer) must be a finite number of metres, at least l_d = {l_d}; got {d_b}")]
    BaseDepth {
        /// The refused base depth.
        d_b: f64,
        /// The tile depth it was compared with.
        l_d: f64,
    },
    /// `n_c * n_t` or `n_t * d_c` is above 2^24 tiles.
    #[error(
        "the layout has {0} tiles along one axis, more than the supported {MAX_AXIS_TILES}; lower n_c, n_t or d_c"
    )]
    TooLarge(u64),
}

/// A validated planet layout (seed 000 Sec. 4.3).
///
/// A face holds `n_c x n_c` chunks at its base, `d_c` chunks deep; a chunk holds `n_t^3` tiles
/// (morphed cubes, Fig. 9). Voxels are the tile corners: face grid indices `i, j` in `0..=N` with
/// `N = n_c n_t`, depth index `k` in `0..=D` with `D = n_t d_c`. Layer `k` lies at radius
/// `d_b + k l_d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    n_c: u32,
    n_t: u32,
    d_b: f64,
    l_d: f64,
    d_c: u32,
}

/// The default layout: `n_c = 8`, `n_t = 32`, `d_b = 1744 m`, `l_d = 4 m`, `d_c = 2`, radius 2000 m.
impl Default for Layout {
    fn default() -> Self {
        Layout::new(8, 32, 1744.0, 4.0, 2).expect("default layout is valid")
    }
}

impl Layout {
    /// Validates and builds a layout from the paper's parameters.
    pub fn new(n_c: u32, n_t: u32, d_b: f64, l_d: f64, d_c: u32) -> Result<Layout, LayoutError> {
        if n_c == 0 {
            return Err(LayoutError::ChunksPerSide(n_c));
        }
        if n_t == 0 || n_t > MAX_CHUNK_TILES {
            return Err(LayoutError::TilesPerChunk(n_t));
        }
        if d_c == 0 {
            return Err(LayoutError::DepthChunks(d_c));
        }
        if !(l_d.is_finite() && l_d > 0.0) {
            return Err(LayoutError::TileDepth(l_d));
        }
        if !(d_b.is_finite() && d_b >= l_d) {
            return Err(LayoutError::BaseDepth { d_b, l_d });
        }
        let face = u64::from(n_c) * u64::from(n_t);
        let depth = u64::from(d_c) * u64::from(n_t);
        if face > MAX_AXIS_TILES || depth > MAX_AXIS_TILES {
            return Err(LayoutError::TooLarge(face.max(depth)));
        }
        Ok(Layout {
            n_c,
            n_t,
            d_b,
            l_d,
            d_c,
        })
    }

    /// `n_c`: chunks along each side of a face.
    pub fn n_c(&self) -> u32 {
        self.n_c
    }
    /// `n_t`: tiles along each side of a chunk.
    pub fn n_t(&self) -> u32 {
        self.n_t
    }
    /// `d_b`: base depth, the radius of voxel layer 0, in metres.
    pub fn d_b(&self) -> f64 {
        self.d_b
    }
    /// `l_d`: length of a depth edge, in metres.
    pub fn l_d(&self) -> f64 {
        self.l_d
    }
    /// `d_c`: chunks along the depth axis.
    pub fn d_c(&self) -> u32 {
        self.d_c
    }

    /// `N = n_c n_t`: tiles along a face side.
    pub fn face_tiles(&self) -> i64 {
        i64::from(self.n_c) * i64::from(self.n_t)
    }

    /// `D = n_t d_c`: tiles along the depth axis.
    pub fn depth_tiles(&self) -> i64 {
        i64::from(self.n_t) * i64::from(self.d_c)
    }

    /// Eq. (2): the number of chunks, `6 n_c^2 d_c`.
    pub fn chunk_count(&self) -> u64 {
        6u64.saturating_mul(u64::from(self.n_c).pow(2))
            .saturating_mul(u64::from(self.d_c))
    }

    /// Eq. (3): the number of voxels counted per face, `6 (n_t n_c + 1)^2 (n_t d_c + 1)`. Voxels
    /// on face edges count once per face; see [`Layout::unique_voxel_count`]. Saturates at
    /// `u64::MAX` on layouts whose count does not fit (the largest Earth-sized ones).
    pub fn voxel_count(&self) -> u64 {
        let n = self.face_tiles() as u64;
        let d = self.depth_tiles() as u64;
        // Saturates instead of overflowing on the largest layouts (about 1.6e22 voxels).
        6u64.saturating_mul((n + 1).saturating_pow(2)).saturating_mul(d + 1)
    }

    /// The number of distinct voxels once face-edge and corner voxels are paired:
    /// `(6 N^2 + 2) (D + 1)`.
    pub fn unique_voxel_count(&self) -> u64 {
        let n = self.face_tiles() as u64;
        let d = self.depth_tiles() as u64;
        6u64.saturating_mul(n.saturating_mul(n))
            .saturating_add(2)
            .saturating_mul(d + 1)
    }

    /// Eq. (4): the planet radius `d_b + l_d n_t d_c` (the outermost voxel layer), in metres.
    pub fn radius(&self) -> f64 {
        self.layer_radius(self.depth_tiles())
    }

    /// The radius of voxel layer `k` (which may lie outside `0..=D` for padding).
    #[inline]
    pub fn layer_radius(&self, k: i64) -> f64 {
        self.d_b + self.l_d * k as f64
    }

    /// The coarsest level of detail: the largest `L` with `2^L` dividing `n_c`, or 0 when `n_t`
    /// is odd (a level-`L + 1` voxel must be a level-`L` voxel, which needs chunk origins on even
    /// level-`L` indices).
    ///
    /// A level-`L` chunk covers `2^L` level-0 chunks along every axis with the same `n_t^3` tiles
    /// (stride `2^L`): an octree per face that also covers depth. Along the face the chunks tile
    /// it exactly; along depth there are `ceil(d_c / 2^L)` of them, so the outermost may reach
    /// past the shell's top layer `D`, where the shell contract makes every voxel air.
    pub fn max_level(&self) -> u8 {
        if self.n_t % 2 == 1 {
            return 0;
        }
        self.n_c.trailing_zeros() as u8
    }

    /// Chunks per face side at `level`.
    pub fn chunks_per_side(&self, level: u8) -> u32 {
        self.n_c >> level
    }

    /// Chunks along depth at `level`: `ceil(d_c / 2^level)`.
    pub fn depth_chunks(&self, level: u8) -> u32 {
        let step = 1u64 << level;
        (u64::from(self.d_c).div_ceil(step)) as u32
    }

    /// Level-0 grid steps along each axis of a level-`level` chunk: `n_t 2^level`.
    pub fn chunk_span(&self, level: u8) -> i64 {
        i64::from(self.n_t) << level
    }

    /// Whether `key` names a chunk of this layout.
    pub fn contains_chunk(&self, key: &ChunkKey) -> bool {
        key.level <= self.max_level()
            && key.i < self.chunks_per_side(key.level)
            && key.j < self.chunks_per_side(key.level)
            && key.k < self.depth_chunks(key.level)
    }

    /// The chunk `face/level/i/j/k` of this layout, from indices given from outside (a request,
    /// a script): [`NotAChunk`] saying which index is out of range otherwise.
    pub fn chunk_key(&self, face: Face, level: u64, i: u64, j: u64, k: u64) -> Result<ChunkKey, NotAChunk> {
        let shown = format!("{}/{level}/{i}/{j}/{k}", face.name());
        let max_level = self.max_level();
        if level > u64::from(max_level) {
            return Err(NotAChunk(format!(
                "chunk {shown} is not part of this planet: level {level} is above the layout's max level {max_level}"
            )));
        }
        let level = level as u8;
        let (n, d) = (self.chunks_per_side(level), self.depth_chunks(level));
        let key = match (u32::try_from(i), u32::try_from(j), u32::try_from(k)) {
            (Ok(i), Ok(j), Ok(k)) if i < n && j < n && k < d => ChunkKey { face, level, i, j, k },
            _ => {
                return Err(NotAChunk(format!(
                "chunk {shown} is not part of this planet: at level {level}, i and j must be below {n} and k below {d}"
            )))
            }
        };
        if !self.contains_chunk(&key) {
            return Err(NotAChunk(format!("chunk {shown} is not part of this planet")));
        }
        Ok(key)
    }

    /// The chunk of `level` one step beyond `side` of `key`, or `None` past the shell's inner or
    /// outer boundary (or when `key` is not a chunk of this layout, or `level` too coarse).
    ///
    /// Across a face edge this is the chunk of the neighbouring face whose footprint continues
    /// `key`'s, found by unfolding the face as Algorithm 1 does. When `level` is coarser than
    /// `key`'s, the answer is the coarser chunk holding that region; when finer, the finer chunk
    /// at the middle of that region (one of several).
    pub fn neighbour(&self, key: &ChunkKey, side: ChunkSide, level: u8) -> Option<ChunkKey> {
        if !self.contains_chunk(key) || level > self.max_level() {
            return None;
        }
        let span = self.chunk_span(key.level);
        let (i0, j0, k0) = (
            i64::from(key.i) * span,
            i64::from(key.j) * span,
            i64::from(key.k) * span,
        );
        // The middle of the neighbouring same-level chunk, in face grid indices (doubled, so
        // that an odd span stays exact).
        let (mut ci, mut cj, mut ck) = (2 * i0 + span, 2 * j0 + span, 2 * k0 + span);
        match side {
            ChunkSide::UMin => ci -= 2 * span,
            ChunkSide::UMax => ci += 2 * span,
            ChunkSide::VMin => cj -= 2 * span,
            ChunkSide::VMax => cj += 2 * span,
            ChunkSide::Inner => ck -= 2 * span,
            ChunkSide::Outer => ck += 2 * span,
        }
        if ck < 0 {
            return None;
        }
        let k_index = ck / 2;
        let target_span = self.chunk_span(level);
        let k = k_index / target_span;
        if k >= i64::from(self.depth_chunks(level)) {
            return None;
        }
        let (face, fi, fj) = self.face_index_doubled(key.face, ci, cj)?;
        let per_side = i64::from(self.chunks_per_side(level));
        let i = (fi / (2 * target_span)).min(per_side - 1);
        let j = (fj / (2 * target_span)).min(per_side - 1);
        Some(ChunkKey {
            face,
            level,
            i: i as u32,
            j: j as u32,
            k: k as u32,
        })
    }

    /// The sides of `key` across which a coarser chunk can lie in a level-of-detail selection:
    /// those whose same-level neighbour exists and is not a sibling (a chunk of the same parent),
    /// none at the coarsest level. A side mask means the same outside these sides as without
    /// them, so masks are normalised by `mask & seam_sides(key)` (at most 8 variants a chunk).
    pub fn seam_sides(&self, key: &ChunkKey) -> SideMask {
        if key.level >= self.max_level() {
            return SideMask::NONE;
        }
        ChunkSide::ALL
            .into_iter()
            .filter(|side| {
                self.neighbour(key, *side, key.level)
                    .is_some_and(|n| n.parent() != key.parent())
            })
            .fold(SideMask::NONE, SideMask::with)
    }

    /// A point given in doubled face grid indices of `face` (possibly past one of its edges),
    /// as doubled face grid indices on the face that holds it. `None` past a cube corner.
    fn face_index_doubled(&self, face: Face, ci: i64, cj: i64) -> Option<(Face, i64, i64)> {
        let n2 = 2 * self.face_tiles();
        let out_i = !(0..=n2).contains(&ci);
        let out_j = !(0..=n2).contains(&cj);
        if !out_i && !out_j {
            return Some((face, ci, cj));
        }
        if out_i && out_j {
            return None;
        }
        // Unfold as `lattice` does, with doubled indices: the lattice point in quarter steps.
        let p = face_lattice(face, ci, cj, n2)?.as_i64vec3();
        let other = Face::ALL.into_iter().find(|f| f.frame().n.as_i64vec3().dot(p) == n2)?;
        let ofr = other.frame();
        Some((
            other,
            (ofr.u.as_i64vec3().dot(p) + n2) / 2,
            (ofr.v.as_i64vec3().dot(p) + n2) / 2,
        ))
    }

    /// All chunks of `level`, in key order (face, then i, j, k).
    pub fn chunks(&self, level: u8) -> Vec<ChunkKey> {
        let n = self.chunks_per_side(level);
        let d = self.depth_chunks(level);
        let mut out = Vec::with_capacity((6 * n * n * d) as usize);
        for face in Face::ALL {
            for i in 0..n {
                for j in 0..n {
                    for k in 0..d {
                        out.push(ChunkKey { face, level, i, j, k });
                    }
                }
            }
        }
        out
    }

    /// The canonical lattice point of face grid indices `(i, j)`.
    ///
    /// Indices in `0..=N` lie on `face`. An index up to `N` past one side (the other in range)
    /// lies on the neighbouring face, unfolded about the shared edge as in Algorithm 1: this is how
    /// chunk padding reaches across face edges. Returns `None` when both indices are out of range
    /// (there is no such point next to a cube corner) or when one is too far out.
    pub fn lattice(&self, face: Face, i: i64, j: i64) -> Option<IVec3> {
        face_lattice(face, i, j, self.face_tiles())
    }

    /// The canonical key of voxel `(i, j, k)` of `face` (see [`Layout::lattice`] for the range).
    pub fn voxel_key(&self, face: Face, i: i64, j: i64, k: i64) -> Option<VoxelKey> {
        Some(VoxelKey::new(self.lattice(face, i, j)?, k as i32))
    }

    /// The unit direction of a lattice point.
    #[inline]
    pub fn lattice_direction(&self, lattice: IVec3) -> DVec3 {
        let n = self.face_tiles() as f64;
        cube_to_sphere(lattice.as_dvec3() / n)
    }

    /// The world position (metres, planet-centred) of a voxel, from its canonical key only.
    pub fn voxel_position(&self, key: VoxelKey) -> DVec3 {
        self.lattice_direction(IVec3::from_array(key.lattice)) * self.layer_radius(i64::from(key.k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::face_conversion::FaceTransition;
    use proptest::prelude::*;

    #[test]
    fn chunk_keys_from_outside_are_checked() {
        let l = Layout::new(4, 16, 100.0, 2.0, 3).unwrap();
        let k = l.chunk_key(Face::ALL[2], 1, 1, 0, 1).unwrap();
        assert_eq!((k.level, k.i, k.j, k.k), (1, 1, 0, 1));
        assert!(l.contains_chunk(&k));
        for (level, i, j, kk, needle) in [
            (3, 0, 0, 0, "above the layout's max level 2"),
            (0, 4, 0, 0, "i and j must be below 4 and k below 3"),
            (1, 0, 0, 2, "i and j must be below 2 and k below 2"),
            (0, 0, u64::MAX, 0, "is not part of this planet"),
        ] {
            let e = l.chunk_key(Face::ALL[0], level, i, j, kk).unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("is not part of this planet"), "{e}");
        }
    }

    #[test]
    fn formulas_match_the_paper() {
        let l = Layout::new(4, 16, 100.0, 2.0, 3).unwrap();
        assert_eq!(l.chunk_count(), 6 * 16 * 3);
        assert_eq!(l.voxel_count(), 6 * 65 * 65 * 49);
        assert_eq!(l.radius(), 100.0 + 2.0 * 48.0);
        assert_eq!(l.chunks(0).len() as u64, l.chunk_count());
        let d = Layout::default();
        assert_eq!(d.radius(), 2000.0);
    }

    #[test]
    fn unique_voxels_are_counted_by_distinct_lattice_points() {
        let l = Layout::new(2, 3, 10.0, 1.0, 1).unwrap();
        let n = l.face_tiles();
        let mut set = std::collections::HashSet::new();
        for f in Face::ALL {
            for i in 0..=n {
                for j in 0..=n {
                    set.insert(l.lattice(f, i, j).unwrap());
                }
            }
        }
        assert_eq!(set.len() as u64 * (l.depth_tiles() as u64 + 1), l.unique_voxel_count());
    }

    #[test]
    fn rejects_invalid_parameters() {
        assert_eq!(Layout::new(0, 8, 10.0, 1.0, 1), Err(LayoutError::ChunksPerSide(0)));
        assert_eq!(Layout::new(1, 0, 10.0, 1.0, 1), Err(LayoutError::TilesPerChunk(0)));
        assert_eq!(Layout::new(1, 8, 10.0, 1.0, 0), Err(LayoutError::DepthChunks(0)));
        assert!(matches!(
            Layout::new(1, 8, 10.0, f64::NAN, 1),
            Err(LayoutError::TileDepth(_))
        ));
        assert!(matches!(
            Layout::new(1, 8, 10.0, -1.0, 1),
            Err(LayoutError::TileDepth(_))
        ));
        assert!(matches!(
            Layout::new(1, 8, f64::NAN, 1.0, 1),
            Err(LayoutError::BaseDepth { .. })
        ));
        assert!(matches!(
            Layout::new(1, 8, -5.0, 1.0, 1),
            Err(LayoutError::BaseDepth { .. })
        ));
        assert!(matches!(
            Layout::new(1 << 20, 128, 10.0, 1.0, 1),
            Err(LayoutError::TooLarge(_))
        ));
    }

    /// Face-edge and corner voxels get one key whichever face names them.
    #[test]
    fn paired_voxels_share_one_key() {
        let l = Layout::new(3, 4, 50.0, 1.0, 1).unwrap();
        let n = l.face_tiles();
        let mut owners: std::collections::HashMap<IVec3, Vec<Face>> = Default::default();
        for f in Face::ALL {
            for i in 0..=n {
                for j in 0..=n {
                    owners.entry(l.lattice(f, i, j).unwrap()).or_default().push(f);
                }
            }
        }
        let corners = owners.values().filter(|v| v.len() == 3).count();
        let edges = owners.values().filter(|v| v.len() == 2).count();
        assert_eq!(corners, 8);
        assert_eq!(edges as i64, 12 * (n - 1));
        assert!(owners.values().all(|v| v.len() <= 3));
    }

    /// Padding past a face edge is the neighbour's voxel found by Algorithm 1.
    #[test]
    fn padding_fold_agrees_with_algorithm_1() {
        let l = Layout::new(2, 4, 50.0, 1.0, 1).unwrap();
        let n = l.face_tiles();
        for a in Face::ALL {
            for b in Face::ALL {
                let Some(tr) = FaceTransition::new(a, b) else { continue };
                for e in 1..=3 {
                    for t in 0..=n {
                        for (i, j) in [(n + e, t), (-e, t), (t, n + e), (t, -e)] {
                            let (i2, j2) = tr.convert_index(i, j, n);
                            if (0..=n).contains(&i2) && (0..=n).contains(&j2) {
                                assert_eq!(l.lattice(a, i, j), l.lattice(b, i2, j2), "{a}->{b} ({i},{j})");
                            }
                        }
                    }
                }
            }
        }
    }

    proptest! {
        #[test]
        fn voxel_positions_lie_on_their_layer(fi in 0usize..6, i in 0i64..=24, j in 0i64..=24, k in 0i64..=8) {
            let l = Layout::new(3, 8, 100.0, 2.5, 1).unwrap();
            let key = l.voxel_key(Face::ALL[fi], i, j, k).unwrap();
            let p = l.voxel_position(key);
            prop_assert!((p.length() - l.layer_radius(k)).abs() < 1e-9);
        }
    }
}

#[cfg(test)]
mod level_tests {
    use super::*;

    #[test]
    fn levels_cover_depth_past_the_shell() {
        let l = Layout::new(8, 32, 1744.0, 4.0, 2).unwrap();
        assert_eq!(l.max_level(), 3);
        assert_eq!((l.chunks_per_side(3), l.depth_chunks(3)), (1, 1));
        assert_eq!(l.depth_chunks(1), 1);
        assert_eq!(l.depth_chunks(0), 2);
        let odd = Layout::new(8, 5, 100.0, 1.0, 2).unwrap();
        assert_eq!(odd.max_level(), 0);
        let twelve = Layout::new(12, 8, 100.0, 1.0, 3).unwrap();
        assert_eq!(twelve.max_level(), 2);
        assert_eq!(twelve.depth_chunks(2), 1);
    }

    #[test]
    fn seam_sides_are_the_sides_away_from_siblings() {
        let l = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
        let key = ChunkKey {
            face: Face::Top,
            level: 0,
            i: 1,
            j: 2,
            k: 2,
        };
        let s = l.seam_sides(&key);
        assert!(s.contains(ChunkSide::UMax) && s.contains(ChunkSide::VMin) && s.contains(ChunkSide::Inner));
        assert!(!s.contains(ChunkSide::UMin) && !s.contains(ChunkSide::VMax) && !s.contains(ChunkSide::Outer));
        // The outermost chunk has no neighbour beyond its outer side.
        let outer = ChunkKey { k: 3, ..key };
        assert!(!l.seam_sides(&outer).contains(ChunkSide::Outer));
        let top = ChunkKey {
            face: Face::Top,
            level: 2,
            i: 0,
            j: 0,
            k: 0,
        };
        assert_eq!(l.seam_sides(&top), SideMask::NONE);
    }

    #[test]
    fn counts_of_the_largest_layouts_saturate_instead_of_overflowing() {
        let l = Layout::new(1 << 19, 32, 6.0e6, 1.0, 1 << 19).unwrap();
        assert_eq!(l.voxel_count(), u64::MAX);
        assert_eq!(l.unique_voxel_count(), u64::MAX);
        assert!(l.chunk_count() > 0);
    }

    #[test]
    fn parent_and_children_round_trip() {
        let key = ChunkKey {
            face: Face::East,
            level: 2,
            i: 3,
            j: 1,
            k: 0,
        };
        for c in key.children().unwrap() {
            assert_eq!(c.parent(), key);
        }
        assert!(ChunkKey::new(Face::Top, 0, 0, 0).children().is_none());
    }

    /// Neighbours are symmetric: the neighbour's neighbour across some side is the chunk again,
    /// on every face edge and next to every cube corner.
    #[test]
    fn neighbours_are_mutual_across_face_edges() {
        let l = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
        for level in 0..=l.max_level() {
            for key in l.chunks(level) {
                for side in ChunkSide::ALL {
                    let Some(n) = l.neighbour(&key, side, level) else {
                        assert!(matches!(side, ChunkSide::Inner | ChunkSide::Outer), "{key} {side:?}");
                        continue;
                    };
                    assert_ne!(n, key);
                    let back = ChunkSide::ALL
                        .into_iter()
                        .filter(|s| l.neighbour(&n, *s, level) == Some(key))
                        .count();
                    assert_eq!(back, 1, "{key} {side:?} -> {n}");
                    if n.face != key.face {
                        assert!(key.face.is_adjacent(n.face));
                    }
                }
                if level < l.max_level() {
                    let up = l.neighbour(&key, ChunkSide::UMax, level + 1).unwrap();
                    let same = l.neighbour(&key, ChunkSide::UMax, level).unwrap();
                    assert_eq!(up, same.parent());
                }
            }
        }
    }
}

/// A square block of face grid indices: entry `(a, b)` (`a, b` in `0..side`) is index
/// `(i0 + a, j0 + b)` of `face`, stored at `b * side + a`. Batched samplers take one with its
/// points ([`face_lattice`] of each entry) to use the structure: a row shares its `j`, a column
/// its `i`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceGrid {
    /// The face.
    pub face: Face,
    /// Face index along `u` of entry `(0, 0)` (may lie past the face's edge).
    pub i0: i64,
    /// Face index along `v` of entry `(0, 0)`.
    pub j0: i64,
    /// Entries per side.
    pub side: usize,
}

impl FaceGrid {
    /// Number of entries, `side^2`.
    pub fn len(&self) -> usize {
        self.side * self.side
    }

    /// Whether the grid has no entry.
    pub fn is_empty(&self) -> bool {
        self.side == 0
    }

    /// Face indices of entry `(a, b)`.
    pub fn indices(&self, a: usize, b: usize) -> (i64, i64) {
        (self.i0 + a as i64, self.j0 + b as i64)
    }
}

/// The canonical lattice point of face grid index `(i, j)` at resolution `m` (grid steps per face
/// side): `m n + (2i - m) u + (2j - m) v` in the face's frame, every component in `[-m, m]`.
///
/// Indices in `0..=m` lie on `face`. An index up to `m` past one side (the other in range) lies on
/// the neighbouring face, unfolded about the shared edge as in Algorithm 1 (seed 000): this is how
/// chunk padding, height-field borders and bicubic stencils reach across face edges. Returns
/// `None` when both indices are out of range (there is no such point next to a cube corner) or
/// when one is more than `m` out. [`Layout::lattice`] is this at `m = n_c n_t`.
pub fn face_lattice(face: Face, i: i64, j: i64, m: i64) -> Option<IVec3> {
    let out_i = !(0..=m).contains(&i);
    let out_j = !(0..=m).contains(&j);
    if out_i && out_j {
        return None;
    }
    let fr = face.frame();
    // Components along u and v in half grid steps, and the excess past the face.
    let fold = |x: i64| -> Option<(i64, i64)> {
        if x < -m || x > 2 * m {
            None
        } else if x > m {
            Some((m, x - m))
        } else if x < 0 {
            Some((-m, -x))
        } else {
            Some((2 * x - m, 0))
        }
    };
    let (cu, eu) = fold(i)?;
    let (cv, ev) = fold(j)?;
    let cn = m - 2 * (eu + ev);
    let p = fr.n.as_i64vec3() * cn + fr.u.as_i64vec3() * cu + fr.v.as_i64vec3() * cv;
    Some(p.as_ivec3())
}
