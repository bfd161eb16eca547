//! Mesh export for planetary marching cubes.
//!
//! - [`write_glb`]: binary glTF 2.0, one node per chunk with the chunk origin as an `f64`
//!   translation and chunk-relative `f32` positions, plus the terrain attributes and an optional
//!   sea sphere (`docs/specs/glb-v1.md`).
//! - [`write_obj`] and [`write_ply`]: one welded world-space mesh with `f64` positions; vertices
//!   of different chunks with equal edge keys become one vertex (`docs/specs/obj-v1.md`,
//!   `docs/specs/ply-v1.md`).
//! - [`export`]: picks the format from the file extension ([`Format::from_path`]) and replaces
//!   the file atomically.
//!
//! Frame: metres, planet-centred, Y-up right-handed; +Y is the north pole, +Z latitude 0
//! longitude 0, +X longitude 90 E. Triangles wind counter-clockwise seen from outside.
//!
//! No input makes these functions panic: meshes are checked first (buffer lengths, index range,
//! finite values) and problems come back as [`ExportError`].
//!
//! ```
//! use pmc_formats::{write_ply, ExportMeta};
//! use pmc_mesh::ChunkMesh;
//! let tri = ChunkMesh {
//!     positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     normals: vec![[0.0, 0.0, 1.0]; 3],
//!     indices: vec![0, 1, 2],
//!     ..Default::default()
//! };
//! let meta = ExportMeta { generator: "pmc 0.1.0".into(), ..Default::default() };
//! let mut bytes = Vec::new();
//! write_ply(&[tri], &meta, &mut bytes).unwrap();
//! assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod check;
pub mod chunk_encoding;
mod error;
mod export;
mod format;
mod glb;
mod meta;
mod obj;
mod ply;
mod sea;
mod weld;

pub use error::ExportError;
pub use export::{export, ExportStats};
pub use format::Format;
pub use glb::{write_glb, write_tile_glb};
pub use meta::ExportMeta;
pub use obj::write_obj;
pub use ply::{write_ply, PLY_FACE_BYTES, PLY_VERTEX_BYTES};
pub use weld::{weld_arrays, WeldedArrays};
