//! Heightfield quadtree meshing of whole planets on a cube-sphere (seed 003, Fisher et al.):
//! six quadtrees of 65 × 65-vertex patches, heights from any [`LatticeHeights`] source, seams
//! stitched between levels, normals that agree across patches, levels and face edges, and a
//! screen-space-error selection with 2:1 balance.
//!
//! # Lattice points
//!
//! A face of resolution `m` (segments per side, a power of two) has grid points `(I, J)`,
//! `0 <= I, J <= m`, at the canonical lattice point `m n + (2I - m) u + (2J - m) v` of the face's
//! frame (the same point from every face that holds it), with direction
//! `cube_to_sphere(lattice / m)`. Patch `(face, level, i, j)` has `m = 64 · 2^level` and vertex
//! `(a, b)` at `(64 i + a, 64 j + b)`. A vertex's position `direction · (radius + height)` is a
//! function of its lattice point alone, computed in `f64`, so shared vertices are the same bits in
//! every patch, level and face. Meshes store positions as `f32` relative to the patch's centre
//! vertex, and identify each vertex by its lattice point at the finest resolution in `edge_keys`.
//!
//! # Stitching
//!
//! Where a patch meets a coarser one (one level up; [`select`] balances the trees so that this is
//! the only case), its side skips every odd vertex: each 2 × 2 block on that side fans its centre to
//! the even vertices, so the side's polyline is exactly the coarser patch's. Corner blocks work the
//! same way for two stitched sides.
//!
//! ```text
//!   coarse patch (level L)              fine patch (level L+1), side MinU stitched
//!
//!   o-----------o                       o-----o-----o-----o----
//!   |           |                       |\    |    /|\    |
//!   |           |                       |  \  |  /  |  \  |
//!   |           |            shared     |    \|/    |    \|
//!   |           o  even  ==  vertex  == o-----o-----o-----o----
//!   |           |                       |    /|\    |    /|
//!   |           |           (odd vertex |  /  |  \  |  /  |
//!   |           |            skipped)   |/    |    \|/    |
//!   o-----------o                       o-----o-----o-----o----
//! ```
//!
//! The odd vertex in the middle of each fine side segment is absent from every triangle: the fan
//! of the 2 × 2 block joins the two even vertices directly.
//!
//! # Normals
//!
//! Each patch samples one extra row of heights around itself (past a face edge by unfolding, as
//! Algorithm 1 does) and takes central differences of positions, so a vertex gets the same normal
//! in every same-level patch that holds it, across face edges too. A vertex that a coarser patch
//! also holds (the even vertices of a stitched side, and corners flagged in [`Stitch`]) uses the
//! coarser spacing, so it gets the coarser patch's normal. A cube corner (three faces) takes its
//! normal from its three neighbours along the cube edges. The four corners of the 67 × 67 sample
//! grid are never needed (a four-neighbour stencil), which is why there is no rule for points past
//! a cube corner.
//!
//! # Example
//!
//! ```
//! use pmc_heightfield::{generate_patches, select, HeightfieldPlanet, Ripples, View};
//! use pmc_geometry::glam::DVec3;
//! use pmc_mesh::WeldedMesh;
//!
//! let heights = Ripples { amplitude: 2_000.0, frequency: 7.0 };
//! let planet = HeightfieldPlanet::new(100_000.0, -2_000.0, 2_000.0, 6).unwrap();
//! let mut view = View::perspective(DVec3::new(0.0, 0.0, 130_000.0), 1.0, 720.0, 4.0);
//! view.horizon_cull = false;
//! let patches = select(&view, &planet).unwrap();
//! let meshes = generate_patches(&heights, planet.radius(), &patches).unwrap();
//! // The union of the patches is one closed surface.
//! let report = WeldedMesh::weld(&meshes).report();
//! assert!(report.is_closed_manifold());
//! assert_eq!(report.euler_characteristic(), 2);
//! ```
//!
//! Generation is a pure function of its inputs; run [`generate_patch`] or [`generate_patches`] on
//! any thread (seed 003 Sec. 4.4 generates off the main thread and swaps meshes in when ready).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod heights;
mod lattice;
mod mesh;
mod patch;
mod select;

pub use heights::{ConstantHeight, LatticeHeights, Ripples};
pub use lattice::{
    canonical_lattice, face_lattice, lattice_direction, resolution, CANONICAL_RESOLUTION, MAX_LEVEL, PATCH_SEGMENTS,
    PATCH_SIDE,
};
pub use mesh::{
    generate_patch, patch_height_range, patch_indices, vertex_canonical_lattice, vertex_position, PATCH_COLOR,
};
pub use patch::{Corner, PatchError, PatchKey, Side, Stitch};
pub use select::{
    check_selection, patch_corners, select, BoundingSphere, HeightfieldPlanet, SelectedPatch, View, LIPSCHITZ,
};

use pmc_mesh::ChunkMesh;
use rayon::prelude::*;

/// Generates the meshes of `patches` in parallel (rayon's global pool), in the order given.
///
/// Each mesh is [`generate_patch`]`(heights, radius, p.key, p.stitch)`; the result does not depend
/// on the number of threads. The first refused patch is the error.
pub fn generate_patches<H: LatticeHeights + ?Sized>(
    heights: &H,
    radius: f64,
    patches: &[SelectedPatch],
) -> Result<Vec<ChunkMesh>, PatchError> {
    patches
        .par_iter()
        .map(|p| {
            let mut mesh = ChunkMesh::default();
            generate_patch(heights, radius, p.key, p.stitch, &mut mesh)?;
            Ok(mesh)
        })
        .collect()
}
