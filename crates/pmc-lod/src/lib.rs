//! Level of detail for planetary marching cubes: which chunks of the chunk octree to draw for a
//! view.
//!
//! Each face's chunks form an octree over the face and the depth axis
//! ([`Layout::max_level`](pmc_geometry::Layout::max_level)): a level-`L` chunk covers `2^L`
//! level-0 chunks per axis with the same `n_t^3` tiles. A selection is a set of leaves of these
//! six octrees that covers every level-0 chunk exactly once.
//!
//! - [`bounds`]: a bounding sphere per chunk that provably holds every vertex the chunk can have,
//!   and the chunks near a point (a quadtree search over those spheres).
//! - [`Selector::select`]: the rule below.
//! - [`measure_level_errors`]: the geometric error `errors[L]` of each level, measured on a
//!   planet.
//! - [`sphere_in_frustum`], [`sphere_below_horizon`], [`occluder_radius`]: culling.
//! - [`adjacent`]: the 26 chunks around a chunk, across face edges and cube corners.
//! - [`ChunkRadii`], [`Selector::with_radii`], [`planet_radii`]: radial bounds tighter than a
//!   chunk's layers where a source knows them (a height-field planet's patches, bounded by their
//!   own heights instead of the whole relief).
//!
//! # The selection rule
//!
//! Inputs: the layout, each chunk's bounding sphere ([`bounds::chunk_sphere`], or between the
//! tighter radii of a [`ChunkRadii`] source), the error table
//! `errors[L]` in metres, the radius `R` of a ball that is solid at every level (the occluder), a
//! [`View`] (eye `E`, optional frustum, viewport height `h` in pixels, vertical field of view
//! `fov`) and [`LodParams`] (pixel error bound `tau`, finest level `L_min`, budget `max_chunks`).
//!
//! 1. **Refinement.** Start from the roots, every chunk of the coarsest level (`6` faces
//!    `x n_c / 2^Lmax` squared `x ceil(d_c / 2^Lmax)`). A chunk of level `L > L_min` is replaced
//!    by its children that exist ([`Layout::contains_chunk`](pmc_geometry::Layout::contains_chunk);
//!    the octree's depth may end between two children) while its screen-space error exceeds the
//!    bound:
//!
//!    ```text
//!    rho = errors[L] * h / (2 tan(fov / 2) * d)  >  tau
//!    ```
//!
//!    where `d` is the distance from the eye to the nearest point of the chunk's bounding sphere
//!    (0 inside it, where any level with a positive error refines down to `L_min`). The code
//!    compares `errors[L] h > tau 2 tan(fov / 2) d` so that `d = 0` needs no division; a level
//!    with error 0 is never refined. Chunks are refined nearest first (a heap ordered by `d`, ties
//!    by key), which fixes the order of the splits.
//! 2. **Balance.** Then any leaf is split while
//!    - a leaf touching it (across a side, an edge or a corner: the 26-neighbourhood, across
//!      face edges and at the eight cube corners too) is more than one level finer, or
//!    - one of its edges is a *checkerboard*: around a line of the edge, the four leaves alternate
//!      coarse, fine, coarse, fine (the leaf and the one diagonally across the line are both
//!      coarser than the two beside it). The seam closure between levels would be non-manifold
//!      there, so the coarse leaves are split.
//!
//!    Splitting only refines and never goes below `L_min`, so this reaches a fixpoint. It is
//!    computed in rounds (test every candidate against the tree as it stands, then split all that
//!    must), so the result does not depend on any iteration order.
//! 3. **Budget.** When the balanced leaves number more than `max_chunks`, refinement is cut:
//!    the splits of step 1, nearest first, are applied only up to the longest prefix whose
//!    balanced tree fits (found by bisection over the prefix length; refinement itself also stops
//!    at the first split that would pass the budget), so the farthest chunks are the ones left
//!    coarser. [`Selection::truncated`] says so. The roots are always selected.
//! 4. **Culling.** Every leaf is returned, each with `drawn = false` when its sphere lies outside
//!    the frustum ([`sphere_in_frustum`]) or entirely below the horizon of the occluder ball as
//!    seen from the eye ([`sphere_below_horizon`]). Culled leaves still count in step 2, so the
//!    levels around them do not change when the camera turns.
//! 5. **Seams.** Each leaf's [`Selected::coarser`] holds the sides across which the leaf region is
//!    exactly one level coarser (after balancing never more); the side is named in the leaf's own
//!    face, across a face edge too. Leaves come in key order.
//!
//! # Cost
//!
//! The rule is computed in time proportional to the chunks near the refinement, not to the
//! layout: a chunk column's bounding cap (border samples, `atan2` only where it can be the
//! largest) is computed once and shared by the chunks of the column, and the selector keeps it
//! for its next selections; the tree is
//! an arena in which the chunks around a leaf are found from those around its parent; the first
//! balance round tests only the leaves beside split chunks of their level (the others cannot
//! need splitting), and each later round only what the splits before it can have changed; a
//! balance that passes the budget stops there when only its size is needed. The result is the
//! same, chunk for chunk, as computing the rule the plain way (a test compares them). The
//! `lod_select` bench of `pmc-bench` times views of the earth at true scale (19 levels, a
//! thousand chunks of depth) and of the default planet.
//!
//! ```
//! use pmc_geometry::{glam::DVec3, Layout};
//! use pmc_lod::{LodParams, Selector, View};
//! let layout = Layout::default();
//! let selector = Selector::new(layout, vec![0.0, 0.5, 1.0, 2.0], 1800.0).unwrap();
//! let view = View { eye: DVec3::Y * 2010.0, frustum: None, viewport_height_px: 1080.0, fov_y: 1.0 };
//! let selection = selector.select(&view, &LodParams::default()).unwrap();
//! // Level 0 near the eye, the coarsest level on the far side.
//! let histogram = selection.level_histogram();
//! assert!(histogram[0] > 0 && histogram[3] > 0, "{histogram:?}");
//! // What lies below the horizon is selected but not drawn.
//! assert!(selection.drawn().count() < selection.chunks.len());
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod adjacency;
pub mod bounds;
mod cull;
mod errors;
pub mod probe;
mod radii;
#[cfg(test)]
mod reference;
mod region;
mod select;
mod tree;

pub use adjacency::{adjacent, OFFSETS};
pub use cull::{frustum_planes, occluder_radius, sphere_below_horizon, sphere_in_frustum};
pub use errors::{measure_level_errors, CELLS_PER_CHUNK, MIN_GRADIENT};
pub use radii::{planet_radii, ChunkRadii, PatchRadii, MAX_KEPT_RADII, WIDE_PATCH};
pub use region::{level_for_error, region_chunks, RegionError, REGION_BUDGET};
pub use select::{LodError, LodParams, Selected, Selection, Selector, View, DEFAULT_MAX_CHUNKS, MAX_KEPT_CAPS};
