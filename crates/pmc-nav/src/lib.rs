//! Navigation on planetary marching cubes (seed 000 Sec. 4.5): a navigation grid of surface
//! voxels, with the overhang and cave checks of Fig. 11, connected components (Fig. 10), and A*
//! paths with a great-circle and lattice heuristic; over the whole planet, or built lazily tile
//! by tile around a query for planets of any size.
//!
//! - [`Columns`]: every voxel column of the planet and its neighbours across chunk borders, face
//!   edges and cube corners.
//! - [`NavGrid`]: surface voxels (every floor of a column, so cave floors too), the steps an
//!   [`Agent`] can take between them, and components; rebuilt per tile after an edit. Up to
//!   [`MAX_COLUMNS`] columns.
//! - [`find_path`]: the shortest walk between two nodes, or [`NoPath`] (an answer, not an error):
//!   the exact reference.
//! - [`find_path_hierarchical`]: the same answer on whether a walk exists, the walk found through
//!   an abstract graph of the tiles' local components and a weighted A* in the corridor it picks
//!   (within [`HIERARCHICAL_WEIGHT`] of the shortest there; tens of times faster across a face).
//! - [`smooth_path`]: a walk pulled into straight legs along great circles, each leg checked
//!   column by column against the grid's own steps ([`SmoothPath`]).
//! - Rebuilds after an edit read either the density or whole-chunk batches
//!   ([`NavGrid::rebuild_for_from`] with a `pmc_density::ChunkSamples`, which a planet with a base
//!   cache answers without sampling its terrain again).
//! - [`LazyGrid`]: the same nodes and steps, built on first use in small tiles kept in a cache
//!   bounded in bytes, sampling only a band of layers around each column's top on deep shells
//!   (the Earth at 1 m voxels); searched within [`SearchOptions`] bounds, answering "no path
//!   found within the search bound" apart from "no path exists" ([`NoPath`]).
//!
//! ```
//! use pmc_density::Sphere;
//! use pmc_geometry::{glam::DVec3, Layout};
//! use pmc_nav::{find_path, find_path_hierarchical, smooth_path, Agent, NavGrid, HIERARCHICAL_WEIGHT};
//! let layout = Layout::new(2, 8, 100.0, 2.0, 1).unwrap();
//! let grid = NavGrid::build(&Sphere { radius: 110.0 }, &layout, Agent::default()).unwrap();
//! let a = grid.node_near(DVec3::Y, None, 0).unwrap();
//! let b = grid.node_near(DVec3::X, None, 0).unwrap();
//! let path = find_path(&grid, a, b).unwrap();
//! // A quarter of a great circle at radius about 110 m.
//! assert!((path.length - 110.0 * std::f64::consts::FRAC_PI_2).abs() < 10.0);
//! let fast = find_path_hierarchical(&grid, a, b).unwrap();
//! assert!(fast.length <= HIERARCHICAL_WEIGHT * path.length);
//! // Pulled straight: one leg along the great circle.
//! let smooth = smooth_path(&grid, &fast);
//! assert_eq!(smooth.corners, vec![a, b]);
//! assert!((smooth.length - 110.0 * std::f64::consts::FRAC_PI_2).abs() < 10.0);
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod agent;
mod columns;
mod grid;
mod hierarchical;
mod lazy;
mod report;
mod rules;
mod search;
mod smooth;

pub use agent::{Agent, AgentError};
pub use columns::{ColumnPlace, Columns, NeighbourPlaces, Neighbours};
pub use grid::{NavError, NavGrid, Node, NodeId, Step, TileKey, MAX_COLUMNS};
pub use hierarchical::{find_path_hierarchical, HIERARCHICAL_WEIGHT};
pub use lazy::{CacheStats, LazyAnswer, LazyGrid, LazyOptions, NodeKey};
pub use report::{
    lazy_path_geojson, lazy_path_json, path_geojson, path_json, query, query_exact, waypoint, End, PathAnswer,
    PATH_FORMAT, PATH_VERSION,
};
pub use search::{find_path, NoPath, Path, SearchOptions, SearchStats};
pub use smooth::{smooth_path, SmoothPath};

/// Layouts with more column slots than this (`6 (N + 1)^2`; `n_c n_t` above about 800) are
/// navigated with the [`LazyGrid`]: a whole-planet [`NavGrid`] of them would take too long to
/// build for a query (and beyond [`MAX_COLUMNS`], too much memory).
pub const EAGER_COLUMNS: usize = 4_000_000;

/// Whether paths on `layout` should be searched on the [`LazyGrid`] (see [`EAGER_COLUMNS`]).
pub fn wants_lazy_grid(layout: &pmc_geometry::Layout) -> bool {
    Columns::new(layout).index_count() > EAGER_COLUMNS
}
