//! The compact binary encoding of one chunk mesh (`docs/specs/chunk-mesh-v1.md`), as the server
//! sends it and the viewer reads it.
//!
//! [`encode_chunk`] validates a [`ChunkMesh`] and appends its encoding to a buffer;
//! [`decode_chunk`] is a full, validating reader that answers every malformed input with a
//! [`ChunkDecodeError`] and never panics.
//!
//! Layout: a 56-byte header (magic `PMCM`, version 1, flags, the chunk key, the `f64` origin,
//! vertex and index counts), then the sections positions (`f32 x 3`), with flag bit 1 their
//! low-order parts (`f32 x 3`, see [`ChunkMesh::positions_low`]), normals (`i8 x 3` snorm),
//! colours (`u8 x 4`), heights (`f32`), water depths (`f32`), materials (`u8`) and indices (`u16`,
//! or `u32` when there are more than 65536 vertices), each padded with zeros to a multiple of 4
//! bytes. Everything is little-endian.
//!
//! ```
//! use pmc_formats::chunk_encoding::{decode_chunk, encode_chunk};
//! use pmc_geometry::{ChunkKey, Face};
//! use pmc_mesh::ChunkMesh;
//! let mesh = ChunkMesh {
//!     key: Some(ChunkKey::new(Face::East, 1, 2, 0)),
//!     positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     normals: vec![[0.0, 0.0, 1.0]; 3],
//!     indices: vec![0, 1, 2],
//!     ..Default::default()
//! };
//! let mut bytes = Vec::new();
//! encode_chunk(&mesh, &mut bytes).unwrap();
//! let back = decode_chunk(&bytes).unwrap();
//! assert_eq!(back.key, mesh.key.unwrap());
//! assert_eq!(back.positions, mesh.positions);
//! assert_eq!(back.colors, vec![[255; 4]; 3]); // no attributes: white, material 255
//! ```

use crate::check::check_meshes;
use crate::ExportError;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face};
use pmc_mesh::ChunkMesh;

/// The magic bytes every encoded chunk starts with.
pub const MAGIC: [u8; 4] = *b"PMCM";
/// The encoding version this module writes and reads.
pub const VERSION: u16 = 1;
/// Length of the header in bytes; an empty chunk is exactly this long.
pub const HEADER_LEN: usize = 56;
/// Flag bit 0: indices are `u32` (else `u16`).
pub const FLAG_U32_INDICES: u16 = 1;
/// Flag bit 1: a section of the positions' low-order parts follows the positions.
pub const FLAG_POSITIONS_LOW: u16 = 2;
/// Every flag bit this reader knows.
const KNOWN_FLAGS: u16 = FLAG_U32_INDICES | FLAG_POSITIONS_LOW;
/// The most vertices a chunk with `u16` indices may have.
pub const MAX_U16_VERTICES: usize = 65536;
/// Colour written for every vertex of a mesh without attributes (opaque white).
pub const DEFAULT_COLOR: [u8; 4] = [255; 4];
/// Material id written for every vertex of a mesh without attributes ("none").
pub const DEFAULT_MATERIAL: u8 = 255;

/// A chunk read back by [`decode_chunk`].
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedChunk {
    /// The chunk's key (face, level, `i`, `j`, `k`).
    pub key: ChunkKey,
    /// World position (metres, planet-centred) the positions are relative to.
    pub origin: DVec3,
    /// Vertex positions relative to `origin`, metres.
    pub positions: Vec<[f32; 3]>,
    /// Their low-order parts (flag bit 1; see [`ChunkMesh::positions_low`]), empty without.
    pub positions_low: Vec<[f32; 3]>,
    /// Unit outward normals as stored: snorm bytes, `round(n * 127)`. See
    /// [`DecodedChunk::unit_normals`].
    pub normals: Vec<[i8; 3]>,
    /// Linear RGBA vertex colours.
    pub colors: Vec<[u8; 4]>,
    /// Metres above the datum (sea level, or the middle of the shell without sea).
    pub heights: Vec<f32>,
    /// Metres of sea water above each vertex.
    pub water_depths: Vec<f32>,
    /// Material ids (index into the planet's material list; 255 for none).
    pub materials: Vec<u8>,
    /// Triangle list, three indices per triangle, every one below the vertex count.
    pub indices: Vec<u32>,
    /// Whether the indices were stored as `u32` (flag bit 0).
    pub u32_indices: bool,
}

impl DecodedChunk {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The normals as floats (`max(c / 127, -1)` per component; within 1/127 of the normals that
    /// were encoded).
    pub fn unit_normals(&self) -> Vec<[f32; 3]> {
        self.normals.iter().map(|n| n.map(snorm_to_f32)).collect()
    }

    /// The chunk as a [`ChunkMesh`] (normals decoded; no edge keys, grid edges or cube runs,
    /// which the encoding does not carry).
    pub fn to_chunk_mesh(&self) -> ChunkMesh {
        ChunkMesh {
            key: Some(self.key),
            origin: self.origin,
            positions: self.positions.clone(),
            positions_low: self.positions_low.clone(),
            normals: self.unit_normals(),
            indices: self.indices.clone(),
            edge_keys: Vec::new(),
            heights: self.heights.clone(),
            water_depths: self.water_depths.clone(),
            colors: self.colors.clone(),
            materials: self.materials.clone(),
            vertex_edges: Vec::new(),
            cube_runs: Vec::new(),
        }
    }
}

/// Why bytes are not a valid encoded chunk.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ChunkDecodeError {
    /// Fewer bytes than the 56-byte header.
    #[error("the chunk is {0} bytes long, shorter than its {HEADER_LEN}-byte header")]
    TooShort(usize),
    /// The first four bytes are not `PMCM`.
    #[error("not a PMC chunk: the magic is {0:02x?}, expected \"PMCM\"")]
    BadMagic([u8; 4]),
    /// A version this reader does not know.
    #[error("chunk encoding version {0} is not supported (this reader knows version {VERSION})")]
    UnsupportedVersion(u16),
    /// Flag bits other than bits 0 and 1 are set.
    #[error("unknown flag bits {0:#06x} are set (only bits 0 and 1 are defined)")]
    UnknownFlags(u16),
    /// The reserved header field is not 0.
    #[error("the reserved header field is {0}, expected 0")]
    Reserved(u16),
    /// The face byte is not 0..=5.
    #[error("face index {0} is out of range (0..=5)")]
    BadFace(u8),
    /// The index count is not a multiple of 3.
    #[error("the index count {0} is not a multiple of 3")]
    IndexCount(u32),
    /// The index width flag disagrees with the vertex count (u16 up to 65536 vertices, else u32).
    #[error("{vertices} vertices need {} indices, but the flags say {}", if *vertices as usize > MAX_U16_VERTICES { "u32" } else { "u16" }, if *u32_flag { "u32" } else { "u16" })]
    IndexWidth {
        /// The vertex count of the header.
        vertices: u32,
        /// Whether flag bit 0 is set.
        u32_flag: bool,
    },
    /// The buffer length differs from what the header's counts imply.
    #[error("the chunk is {actual} bytes long, but its header implies {expected}")]
    Length {
        /// The length the counts imply.
        expected: u64,
        /// The length of the buffer.
        actual: usize,
    },
    /// A padding byte is not zero.
    #[error("padding after the {0} section is not zero")]
    Padding(&'static str),
    /// The origin is not finite (NaN or infinite): no vertex of the chunk could be placed.
    #[error("the origin {0} is not finite")]
    Origin(String),
    /// A triangle index is not below the vertex count.
    #[error("index {value} at position {position} is out of range for {vertices} vertices")]
    IndexOutOfRange {
        /// Position in the index list.
        position: usize,
        /// The index.
        value: u32,
        /// The vertex count.
        vertices: u32,
    },
}

/// Rounds `n` up to a multiple of 4.
fn pad4(n: u64) -> u64 {
    n.div_ceil(4) * 4
}

/// The snorm byte of a normal component: `round(c * 127)`, clamped to -127..=127.
fn f32_to_snorm(c: f32) -> i8 {
    (c * 127.0).round().clamp(-127.0, 127.0) as i8
}

/// The float of a snorm byte: `max(c / 127, -1)`.
fn snorm_to_f32(c: i8) -> f32 {
    (f32::from(c) / 127.0).max(-1.0)
}

/// Byte sizes of the sections (unpadded) for `v` vertices and `i` indices of `index_size` bytes,
/// with the positions' low-order parts when `low` (else that section is 0 bytes).
fn section_sizes(v: u64, i: u64, index_size: u64, low: bool) -> [(&'static str, u64); 8] {
    [
        ("positions", 12 * v),
        ("positions low", if low { 12 * v } else { 0 }),
        ("normals", 3 * v),
        ("colors", 4 * v),
        ("heights", 4 * v),
        ("water depths", 4 * v),
        ("materials", v),
        ("indices", index_size * i),
    ]
}

/// The exact encoded length of a chunk with `v` vertices and `i` indices, with the positions'
/// low-order parts when `low`.
pub fn encoded_len(v: u64, i: u64, low: bool) -> u64 {
    let index_size = if v > MAX_U16_VERTICES as u64 { 4 } else { 2 };
    HEADER_LEN as u64
        + section_sizes(v, i, index_size, low)
            .iter()
            .map(|&(_, s)| pad4(s))
            .sum::<u64>()
}

/// Appends zero bytes to `out` until its length (counted from `start`) is a multiple of 4.
fn pad_to_4(out: &mut Vec<u8>, start: usize) {
    while !(out.len() - start).is_multiple_of(4) {
        out.push(0);
    }
}

/// Appends the encoding of `mesh` to `out` (`docs/specs/chunk-mesh-v1.md`).
///
/// The mesh must have a key. It is checked like every export (buffer lengths, index range, finite
/// values); a mesh without attributes gets white colours, height 0, water depth 0 and material
/// 255. A mesh without triangles is written as an empty chunk (`V = I = 0`, header only), since
/// its vertices cannot be seen. On error nothing is appended.
pub fn encode_chunk(mesh: &ChunkMesh, out: &mut Vec<u8>) -> Result<(), ExportError> {
    let invalid = |reason: String| ExportError::InvalidMesh {
        index: 0,
        name: mesh.key.map_or_else(|| "chunk-0".to_string(), |k| k.to_string()),
        reason,
    };
    let Some(key) = mesh.key else {
        return Err(invalid("it has no chunk key, which the chunk encoding needs".into()));
    };
    let o = mesh.origin;
    if !(o.x.is_finite() && o.y.is_finite() && o.z.is_finite()) {
        return Err(invalid(format!("origin {o} is not finite")));
    }
    let checked = check_meshes(std::slice::from_ref(mesh))?;
    let attributes = checked.first().is_some_and(|c| c.attributes);
    let empty = mesh.indices.is_empty();
    let v = if empty { 0 } else { mesh.positions.len() };
    let i = if empty { 0 } else { mesh.indices.len() };
    let (Ok(v32), Ok(i32_)) = (u32::try_from(v), u32::try_from(i)) else {
        return Err(ExportError::TooLarge(format!(
            "a chunk of {v} vertices and {i} indices does not fit the chunk encoding's u32 counts"
        )));
    };
    let wide = v > MAX_U16_VERTICES;
    // (an empty chunk has no positions, so no low parts either)
    let low = v > 0 && mesh.positions_low.len() == v;
    let start = out.len();
    out.reserve(encoded_len(v as u64, i as u64, low) as usize);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    let flags = (if wide { FLAG_U32_INDICES } else { 0 }) | (if low { FLAG_POSITIONS_LOW } else { 0 });
    out.extend_from_slice(&flags.to_le_bytes());
    out.push(key.face.index() as u8);
    out.push(key.level);
    out.extend_from_slice(&0u16.to_le_bytes());
    for x in [key.i, key.j, key.k] {
        out.extend_from_slice(&x.to_le_bytes());
    }
    for x in o.to_array() {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out.extend_from_slice(&v32.to_le_bytes());
    out.extend_from_slice(&i32_.to_le_bytes());
    debug_assert_eq!(out.len() - start, HEADER_LEN);
    if empty {
        return Ok(());
    }
    for p in &mesh.positions {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    if low {
        for p in &mesh.positions_low {
            for c in p {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    for n in &mesh.normals {
        out.extend(n.map(|c| f32_to_snorm(c) as u8));
    }
    pad_to_4(out, start);
    if attributes {
        for c in &mesh.colors {
            out.extend_from_slice(c);
        }
        for h in mesh.heights.iter().chain(&mesh.water_depths) {
            out.extend_from_slice(&h.to_le_bytes());
        }
        out.extend_from_slice(&mesh.materials);
    } else {
        for _ in 0..v {
            out.extend_from_slice(&DEFAULT_COLOR);
        }
        out.resize(out.len() + 8 * v, 0); // heights and water depths: 0.0f32 is all zero bytes
        out.resize(out.len() + v, DEFAULT_MATERIAL);
    }
    pad_to_4(out, start);
    if wide {
        for x in &mesh.indices {
            out.extend_from_slice(&x.to_le_bytes());
        }
    } else {
        for &x in &mesh.indices {
            // In range: the check above proved x < v <= 65536.
            out.extend_from_slice(&(x as u16).to_le_bytes());
        }
    }
    pad_to_4(out, start);
    debug_assert_eq!((out.len() - start) as u64, encoded_len(v as u64, i as u64, low));
    Ok(())
}

/// A cursor over validated bytes: every read is in bounds because [`decode_chunk`] checked the
/// total length first; reads past the end still return zeros rather than panic.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut a = [0u8; N];
        if let Some(s) = self.bytes.get(self.at..self.at + N) {
            a.copy_from_slice(s);
        }
        self.at += N;
        a
    }

    fn slice(&mut self, n: usize) -> &'a [u8] {
        let s = self.bytes.get(self.at..self.at + n).unwrap_or(&[]);
        self.at += n;
        s
    }

    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }

    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }

    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }

    /// Skips the padding after a section that started at `start`, checking it is zero.
    fn padding(&mut self, start: usize, section: &'static str) -> Result<(), ChunkDecodeError> {
        let n = (4 - (self.at - start) % 4) % 4;
        if self.slice(n).iter().any(|&b| b != 0) {
            return Err(ChunkDecodeError::Padding(section));
        }
        Ok(())
    }
}

/// Reads and validates an encoded chunk (`docs/specs/chunk-mesh-v1.md`): magic, version, flags,
/// reserved field, face, index count and width, exact length, zero padding and index range.
///
/// Never panics, whatever the bytes; allocates only after the length has been checked against
/// the header's counts.
pub fn decode_chunk(bytes: &[u8]) -> Result<DecodedChunk, ChunkDecodeError> {
    if bytes.len() < HEADER_LEN {
        return Err(ChunkDecodeError::TooShort(bytes.len()));
    }
    let mut r = Reader { bytes, at: 0 };
    let magic: [u8; 4] = r.take();
    if magic != MAGIC {
        return Err(ChunkDecodeError::BadMagic(magic));
    }
    let version = r.u16();
    if version != VERSION {
        return Err(ChunkDecodeError::UnsupportedVersion(version));
    }
    let flags = r.u16();
    if flags & !KNOWN_FLAGS != 0 {
        return Err(ChunkDecodeError::UnknownFlags(flags & !KNOWN_FLAGS));
    }
    let u32_flag = flags & FLAG_U32_INDICES != 0;
    let low = flags & FLAG_POSITIONS_LOW != 0;
    let [face_byte, level] = r.take();
    let face = Face::from_index(usize::from(face_byte)).ok_or(ChunkDecodeError::BadFace(face_byte))?;
    let reserved = r.u16();
    if reserved != 0 {
        return Err(ChunkDecodeError::Reserved(reserved));
    }
    let (i, j, k) = (r.u32(), r.u32(), r.u32());
    let origin = DVec3::new(r.f64(), r.f64(), r.f64());
    if !origin.is_finite() {
        return Err(ChunkDecodeError::Origin(format!(
            "({}, {}, {})",
            origin.x, origin.y, origin.z
        )));
    }
    let v32 = r.u32();
    let i32_ = r.u32();
    if !i32_.is_multiple_of(3) {
        return Err(ChunkDecodeError::IndexCount(i32_));
    }
    if u32_flag != (v32 as usize > MAX_U16_VERTICES) {
        return Err(ChunkDecodeError::IndexWidth {
            vertices: v32,
            u32_flag,
        });
    }
    let expected = encoded_len(u64::from(v32), u64::from(i32_), low);
    if expected != bytes.len() as u64 {
        return Err(ChunkDecodeError::Length {
            expected,
            actual: bytes.len(),
        });
    }
    // The length matches, so every count below fits in memory the caller already holds.
    let (v, n_idx) = (v32 as usize, i32_ as usize);
    let start = 0;
    let mut vec3s = |n: usize| -> Vec<[f32; 3]> {
        r.slice(12 * n)
            .chunks_exact(12)
            .map(|c| {
                let f = |o: usize| f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
                [f(0), f(4), f(8)]
            })
            .collect()
    };
    let positions = vec3s(v);
    let positions_low = if low { vec3s(v) } else { Vec::new() };
    let normals = r
        .slice(3 * v)
        .chunks_exact(3)
        .map(|c| [c[0] as i8, c[1] as i8, c[2] as i8])
        .collect();
    r.padding(start, "normals")?;
    let colors = r
        .slice(4 * v)
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    let floats = |s: &[u8]| -> Vec<f32> {
        s.chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let heights = floats(r.slice(4 * v));
    let water_depths = floats(r.slice(4 * v));
    let materials = r.slice(v).to_vec();
    r.padding(start, "materials")?;
    let indices: Vec<u32> = if u32_flag {
        r.slice(4 * n_idx)
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    } else {
        r.slice(2 * n_idx)
            .chunks_exact(2)
            .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
            .collect()
    };
    r.padding(start, "indices")?;
    if let Some((position, &value)) = indices.iter().enumerate().find(|&(_, &x)| x >= v32) {
        return Err(ChunkDecodeError::IndexOutOfRange {
            position,
            value,
            vertices: v32,
        });
    }
    Ok(DecodedChunk {
        key: ChunkKey { face, level, i, j, k },
        origin,
        positions,
        positions_low,
        normals,
        colors,
        heights,
        water_depths,
        materials,
        indices,
        u32_indices: u32_flag,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(n: usize) -> ChunkMesh {
        ChunkMesh {
            key: Some(ChunkKey::new(Face::North, 1, 2, 3)),
            origin: DVec3::new(1.0, 2.0, 3.0),
            positions: (0..n).map(|i| [i as f32, 0.5, -0.25]).collect(),
            normals: vec![[0.0, -1.0, 0.0]; n],
            indices: vec![0, 1, 2],
            ..Default::default()
        }
    }

    #[test]
    fn lengths_follow_the_spec() {
        assert_eq!(encoded_len(0, 0, false), 56);
        // 5 vertices, 6 u16 indices: 60 + 16 + 20 + 20 + 20 + 8 + 12.
        assert_eq!(encoded_len(5, 6, false), 56 + 156);
        // the positions' low-order parts: 12 more bytes a vertex
        assert_eq!(encoded_len(5, 6, true), 56 + 156 + 60);
        assert_eq!(encoded_len(65536, 3, false), 56 + 65536 * 28 + 8);
        assert_eq!(
            encoded_len(65537, 3, false),
            56 + 65537 * 24 + pad4(65537 * 3) + pad4(65537) + 12
        );
    }

    #[test]
    fn positions_low_round_trip_under_flag_bit_1() {
        let mut m = tri(5);
        m.positions_low = (0..5).map(|i| [i as f32 * 1e-8, -3e-9, 0.0]).collect();
        let mut b = Vec::new();
        encode_chunk(&m, &mut b).unwrap();
        assert_eq!(b.len() as u64, encoded_len(5, 3, true));
        assert_eq!(u16::from_le_bytes([b[6], b[7]]), FLAG_POSITIONS_LOW);
        let d = decode_chunk(&b).unwrap();
        assert_eq!(d.positions, m.positions);
        assert_eq!(d.positions_low, m.positions_low);
        assert_eq!(d.to_chunk_mesh().positions_low, m.positions_low);
        // a mesh without them: no flag, no section, and none read back
        m.positions_low.clear();
        let mut plain = Vec::new();
        encode_chunk(&m, &mut plain).unwrap();
        assert_eq!(plain.len() + 60, b.len());
        assert_eq!(u16::from_le_bytes([plain[6], plain[7]]), 0);
        assert!(decode_chunk(&plain).unwrap().positions_low.is_empty());
        // the flag without the section's bytes is a length error, not a misread
        let mut lying = plain.clone();
        lying[6] = FLAG_POSITIONS_LOW as u8;
        assert!(matches!(decode_chunk(&lying), Err(ChunkDecodeError::Length { .. })));
        // low parts of the wrong count or not finite are refused by the writer
        m.positions_low = vec![[0.0; 3]; 4];
        assert!(encode_chunk(&m, &mut Vec::new()).is_err());
        m.positions_low = vec![[f32::NAN, 0.0, 0.0]; 5];
        assert!(encode_chunk(&m, &mut Vec::new()).is_err());
    }

    #[test]
    fn u16_indices_up_to_65536_vertices_then_u32() {
        for (n, wide) in [(65536usize, false), (65537, true)] {
            let mut m = tri(n);
            m.indices = vec![0, 1, (n - 1) as u32, (n - 1) as u32, (n - 2) as u32, 7];
            let mut b = Vec::new();
            encode_chunk(&m, &mut b).unwrap();
            assert_eq!(b.len() as u64, encoded_len(n as u64, 6, false));
            assert_eq!(u16::from_le_bytes([b[6], b[7]]) & FLAG_U32_INDICES != 0, wide);
            let d = decode_chunk(&b).unwrap();
            assert_eq!(d.u32_indices, wide);
            assert_eq!(d.indices, m.indices);
            assert_eq!(d.positions, m.positions);
            if wide {
                // The last 4 bytes hold the last u32 index (24 bytes of indices, no padding).
                let mut bad = b.clone();
                let at = bad.len() - 4;
                bad[at..].copy_from_slice(&(n as u32).to_le_bytes());
                assert!(matches!(
                    decode_chunk(&bad),
                    Err(ChunkDecodeError::IndexOutOfRange { position: 5, value, .. }) if value == n as u32
                ));
            }
        }
    }

    #[test]
    fn rejects_bad_headers() {
        let mut b = Vec::new();
        encode_chunk(&tri(3), &mut b).unwrap();
        assert!(decode_chunk(&b).is_ok());
        let with = |at: usize, val: u8| {
            let mut c = b.clone();
            c[at] = val;
            decode_chunk(&c)
        };
        assert!(matches!(with(0, b'X'), Err(ChunkDecodeError::BadMagic(_))));
        assert_eq!(with(4, 2), Err(ChunkDecodeError::UnsupportedVersion(2)));
        assert_eq!(with(6, 4), Err(ChunkDecodeError::UnknownFlags(4)));
        assert!(matches!(with(6, 1), Err(ChunkDecodeError::IndexWidth { .. })));
        assert_eq!(with(8, 6), Err(ChunkDecodeError::BadFace(6)));
        assert_eq!(with(10, 1), Err(ChunkDecodeError::Reserved(1)));
        assert_eq!(with(52, 4), Err(ChunkDecodeError::IndexCount(4)));
        assert!(matches!(with(48, 4), Err(ChunkDecodeError::Length { .. })));
        assert_eq!(decode_chunk(&b[..55]), Err(ChunkDecodeError::TooShort(55)));
        let mut long = b.clone();
        long.extend([0; 4]);
        assert!(matches!(decode_chunk(&long), Err(ChunkDecodeError::Length { .. })));
        // Padding after the 9 normal bytes is at offset 56 + 36 + 9.
        assert_eq!(with(56 + 36 + 9, 1), Err(ChunkDecodeError::Padding("normals")));
        // The last u16 index (offset len - 4 .. len - 2 holds index 2; the final 2 bytes pad).
        assert_eq!(with(b.len() - 1, 1), Err(ChunkDecodeError::Padding("indices")));
        let at = b.len() - 4;
        assert!(matches!(
            with(at, 3),
            Err(ChunkDecodeError::IndexOutOfRange {
                position: 2,
                value: 3,
                vertices: 3
            })
        ));
    }

    #[test]
    fn refuses_meshes_it_cannot_encode() {
        let mut out = vec![9u8];
        let mut m = tri(3);
        m.key = None;
        assert!(encode_chunk(&m, &mut out)
            .unwrap_err()
            .to_string()
            .contains("no chunk key"));
        let mut m = tri(3);
        m.indices[1] = 3;
        assert!(encode_chunk(&m, &mut out)
            .unwrap_err()
            .to_string()
            .contains("out of range"));
        let mut m = tri(3);
        m.origin.x = f64::NAN;
        assert!(encode_chunk(&m, &mut out).unwrap_err().to_string().contains("origin"));
        assert_eq!(out, vec![9u8], "nothing is appended on error");
    }

    #[test]
    fn appends_after_existing_bytes_and_pads_relative_to_the_chunk() {
        let mut out = vec![1u8, 2, 3];
        encode_chunk(&tri(3), &mut out).unwrap();
        assert_eq!(&out[..3], &[1, 2, 3]);
        assert!(decode_chunk(&out[3..]).is_ok());
    }

    #[test]
    fn meshes_without_triangles_are_empty_chunks() {
        let mut m = tri(3);
        m.indices.clear();
        let mut b = Vec::new();
        encode_chunk(&m, &mut b).unwrap();
        assert_eq!(b.len(), HEADER_LEN);
        let d = decode_chunk(&b).unwrap();
        assert_eq!(d.vertex_count(), 0);
        assert_eq!(d.origin, m.origin);
        assert_eq!(d.key, m.key.unwrap());
    }

    #[test]
    fn snorm_rounds_and_clamps() {
        assert_eq!(f32_to_snorm(1.0), 127);
        assert_eq!(f32_to_snorm(-1.0), -127);
        assert_eq!(f32_to_snorm(1.5), 127);
        assert_eq!(f32_to_snorm(0.6), 76);
        assert_eq!(f32_to_snorm(-0.8), -102);
        assert_eq!(snorm_to_f32(-128), -1.0);
        assert_eq!(snorm_to_f32(127), 1.0);
    }
}
