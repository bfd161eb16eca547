//! Spherical space for planetary marching cubes (seed 000 Sec. 4.1-4.4).
//!
//! - [`cube_to_sphere`] and [`sphere_to_cube`]: Eq. (1) and its exact inverse.
//! - [`Face`]: the six faces with their local frames (two face axes and the outward depth axis).
//! - [`FaceTransition`]: Algorithm 1, positions and directions between adjacent faces.
//! - [`LatLon`], [`Place`]: geographic coordinates, and their text forms `LAT,LON[,ALT]`.
//! - [`Layout`]: the parameters `n_c, n_t, d_b, l_d, d_c` and Eq. (2)-(4).
//! - [`ChunkKey`] (text form `face/level/i/j/k`), [`VoxelKey`], [`EdgeKey`]: chunk identity and
//!   canonical voxel identity.
//! - [`ChunkGrid`]: where one chunk samples, with the overlap and padding contract.
//! - [`math`]: `lerp`, `smoothstep` and `srgb_to_linear`, one definition each for every crate.
//!
//! World positions are `f64`, planet-centred, in metres.
//!
//! ```
//! use pmc_geometry::{Layout, Face, sphere_to_face_uv, face_uv_to_sphere};
//! let layout = Layout::new(8, 32, 1744.0, 4.0, 2).unwrap();
//! assert_eq!(layout.radius(), 2000.0);
//! let p = face_uv_to_sphere(Face::East, 0.25, -0.5) * layout.radius();
//! let (face, u, v) = sphere_to_face_uv(p).unwrap();
//! assert_eq!(face, Face::East);
//! assert!((u - 0.25).abs() < 1e-12 && (v + 0.5).abs() < 1e-12);
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod chunk_grid;
mod cube_sphere;
mod face;
mod face_conversion;
mod keys;
mod latlon;
mod layout;
pub mod math;

pub use chunk_grid::{ChunkGrid, VertexEdge};
pub use cube_sphere::{
    cube_sphere_factor, cube_to_sphere, face_uv_to_cube, face_uv_to_sphere, sphere_to_cube, sphere_to_face_uv,
};
pub use face::{Face, FaceAxis, FaceFrame};
pub use face_conversion::{convert_axis, AxisMap, FaceTransition};
pub use glam;
pub use keys::{ChunkKey, ChunkKeyParseError, ChunkSide, EdgeKey, SideMask, VoxelKey};
pub use latlon::{LatLon, LatLonError, Place, PlaceParseError};
pub use layout::{face_lattice, FaceGrid, Layout, LayoutError, NotAChunk, MAX_AXIS_TILES, MAX_CHUNK_TILES};
