//! Marching cubes in spherical space (seed 000 with the 256-case mesher of seed 001).
//!
//! [`Mesher::mesh`] turns the padded density samples of one chunk ([`pmc_geometry::ChunkGrid`])
//! into a [`ChunkMesh`]: indexed vertices shared inside the chunk, one vertex per cut grid edge,
//! positions interpolated in `f64` world space from the edge's two voxels taken in canonical
//! order (so the same edge gives the same bits in every chunk that holds it), normals from the
//! density gradient.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod caps;
mod chunk_mesh;
mod mesher;
mod region;
pub mod shell;
pub mod tables;
pub mod topology;
pub mod transition;

pub use chunk_mesh::ChunkMesh;
pub use mesher::{has_sign_change, is_solid, voxel_gradient, Mesher};
pub use region::CubeBox;
pub use shell::close_shell;
pub use topology::{ManifoldReport, WeldedMesh};
pub use transition::{coarse_voxels, Transition};
