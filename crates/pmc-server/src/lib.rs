//! The PMC HTTP server: streams a planet's chunk meshes to the web viewer.
//!
//! It implements `docs/specs/http-api-v1.md` (endpoints) and `docs/specs/chunk-mesh-v1.md` (the
//! binary chunk encoding, written by [`pmc_formats::chunk_encoding`]), and serves the viewer's
//! built files, embedded in the binary.
//!
//! - Chunks are generated on demand on a worker pool (never on the async runtime), cached as
//!   encoded bytes in a cache bounded by [`ServerConfig::cache_bytes`], and concurrent requests
//!   for one chunk share one generation. More than [`ServerConfig::queue_limit`] waiting jobs
//!   make new chunk requests answer 503 with `Retry-After: 1`.
//! - `POST /chunk-batch` asks for up to 256 chunks at once and streams each as it is ready
//!   ([`batch_api`]): a browser's six connections no longer cap the chunks in flight.
//! - Requests may name any preset and seed; up to
//!   [`ServerConfig::max_planets`] planets are kept (those asked for again before those asked
//!   for once), each with its cached chunks.
//! - `/chunks` finds the chunks near a point with a quadtree per face over provable bounding
//!   spheres (see [`pmc_lod::bounds`]), so it stays fast on planets of any size.
//! - `/tiles/` answers OGC 3D Tiles 1.1 of the planet for CesiumJS and other clients
//!   ([`tiles_api`], `docs/specs/tiles-v1.md`), built subtree by subtree on demand and cached.
//! - Every malformed request gets a 4xx with a JSON `{"error": ...}`; no request can panic the
//!   server.
//!
//! ```no_run
//! # async fn run() -> Result<(), pmc_server::ServerError> {
//! use pmc_server::{serve, shutdown_signal, ServerConfig};
//! serve(ServerConfig { port: 8080, ..Default::default() }, shutdown_signal()).await
//! # }
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod api;
pub mod assets;
pub mod batch_api;
pub mod cesium;
mod chunk_cache;
mod config;
pub mod edit_api;
mod editing;
mod error;
pub mod flight;
mod generator;
pub mod imagery_api;
pub mod nav_api;
mod planets;
mod rate;
pub mod relief_api;
mod request;
mod server;
mod state;
pub mod tiles_api;

pub use config::{EditLimits, Mesher, ServerConfig};
pub use error::ServerError;
pub use server::{router, serve, shutdown_signal, Server};
pub use state::{AppState, Stats};
