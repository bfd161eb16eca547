//! What the server serves and how much it may hold.

use crate::ServerError;
use pmc_geometry::Layout;
use pmc_planet::{PresetKind, TerrainSpec};
use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

/// Limits on edits sent to the server (`POST /api/v1/edits`, undo and redo).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditLimits {
    /// Smallest brush radius accepted, metres (default 0.5).
    pub min_brush_radius: f64,
    /// Largest brush radius accepted, metres (default 64; at most
    /// [`pmc_edit::MAX_BRUSH_RADIUS`]).
    pub max_brush_radius: f64,
    /// Edits (undo and redo included) per second one client address may send, on average
    /// (default 20).
    pub rate_per_second: f64,
    /// Edits one client address may send at once before the rate applies (default 40).
    pub burst: u32,
}

impl Default for EditLimits {
    fn default() -> Self {
        EditLimits {
            min_brush_radius: 0.5,
            max_brush_radius: 64.0,
            rate_per_second: 20.0,
            burst: 40,
        }
    }
}

/// The server's settings. [`ServerConfig::default`] serves the default planet (earthlike, seed 7,
/// the default layout) on `127.0.0.1:8080`.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerConfig {
    /// Address to listen on.
    pub host: IpAddr,
    /// Port to listen on; 0 picks a free one (see [`Server::local_addr`](crate::Server::local_addr)).
    pub port: u16,
    /// The terrain of the planet served when a request names none: a preset and a seed, or an
    /// elevation model.
    pub terrain: TerrainSpec,
    /// The layout of every planet served (fixed for the server's life).
    pub layout: Layout,
    /// Most bytes of encoded chunks kept in the cache (default 512 MiB). With a world, a quarter
    /// as much again holds the world planet's meshes, for reusing their shading after an edit.
    pub cache_bytes: u64,
    /// Most planets (terrains) kept at once, with their cached chunks (default 4).
    pub max_planets: usize,
    /// Most chunk jobs waiting for a worker; a request that would add one more is answered 503
    /// (default 256).
    pub queue_limit: usize,
    /// Worker threads that generate chunks; 0 uses every core.
    pub threads: usize,
    /// The world file to serve and edit (created when missing, with `terrain` and `layout`).
    /// With a world, its planet is the server's default planet: an existing world's terrain and
    /// layout replace those above. `None`: no editing.
    pub world: Option<PathBuf>,
    /// Limits on edits (with a world).
    pub edit_limits: EditLimits,
    /// Chunks whose base terrain samples the edited planet keeps to remesh edits fast (with a
    /// world; about 171 KB each at `n_t` 32).
    pub base_cache_chunks: usize,
    /// How the default planet is meshed: marching cubes (caves, overhangs, editing) or, for an
    /// elevation model, a height field of 65 x 65 patches (seed 003).
    pub mesher: Mesher,
    /// A `.pmcimg` imagery file draped on the default planet (`pmc_imagery`), served at
    /// `/api/v1/imagery` and described in `/api/v1/planet`; read and checked at start. `None`:
    /// no imagery.
    pub imagery: Option<PathBuf>,
    /// Where the 3D Tiles of `/tiles/` are placed (`docs/specs/tiles-v1.md`).
    pub tiles_frame: pmc_tiles::FrameChoice,
    /// CesiumJS's built files (npm's `cesium/Build/Cesium`), served at `/cesium/Cesium/` under
    /// the example page at `/cesium/`. `None`: no CesiumJS page.
    pub cesium_js: Option<PathBuf>,
}

/// How a server meshes its planet.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mesher {
    /// Marching cubes in spherical space, with levels of detail (every terrain; editable).
    #[default]
    Volumetric,
    /// The height-field quadtree of 65 x 65 patches (elevation models only; not editable). The
    /// planet's layout becomes its patch layout (`pmc_planet::heightfield`).
    Heightfield,
}

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            host: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 8080,
            terrain: TerrainSpec::preset(PresetKind::Earthlike, 7),
            layout: Layout::default(),
            cache_bytes: 512 << 20,
            max_planets: 4,
            queue_limit: 256,
            threads: 0,
            world: None,
            edit_limits: EditLimits::default(),
            base_cache_chunks: 256,
            mesher: Mesher::Volumetric,
            imagery: None,
            tiles_frame: pmc_tiles::FrameChoice::Auto,
            cesium_js: None,
        }
    }
}

impl ServerConfig {
    /// Checks the limits.
    pub fn validate(&self) -> Result<(), ServerError> {
        if self.max_planets == 0 {
            return Err(ServerError::Config("max_planets must be at least 1".into()));
        }
        if self.queue_limit == 0 {
            return Err(ServerError::Config(
                "queue_limit must be at least 1 (jobs waiting for a worker)".into(),
            ));
        }
        if self.mesher == Mesher::Heightfield {
            if !matches!(self.terrain, TerrainSpec::Dem(_)) {
                return Err(ServerError::Config(format!(
                    "--mesher heightfield meshes elevation models only (give --dem FILE), not the preset {}",
                    self.terrain.name()
                )));
            }
            if self.world.is_some() {
                return Err(ServerError::Config(
                    "a height field cannot be edited: serve a world with the volumetric mesher (leave --mesher out)"
                        .into(),
                ));
            }
        }
        if let Some(dir) = &self.cesium_js {
            if !dir.join("Cesium.js").is_file() {
                return Err(ServerError::Config(format!(
                    "--cesium-js {}: no Cesium.js there; give npm's cesium/Build/Cesium folder (run `npm ci` in \
                     examples/cesium, then --cesium-js examples/cesium/node_modules/cesium/Build/Cesium)",
                    dir.display()
                )));
            }
        }
        let e = &self.edit_limits;
        if !(e.min_brush_radius > 0.0 && e.min_brush_radius <= e.max_brush_radius) {
            return Err(ServerError::Config(format!(
                "the smallest brush radius must be above 0 and at most the largest, got {} and {}",
                e.min_brush_radius, e.max_brush_radius
            )));
        }
        if e.max_brush_radius > pmc_edit::MAX_BRUSH_RADIUS {
            return Err(ServerError::Config(format!(
                "the largest brush radius must be at most {} m, got {}",
                pmc_edit::MAX_BRUSH_RADIUS,
                e.max_brush_radius
            )));
        }
        if !(e.rate_per_second > 0.0 && e.rate_per_second.is_finite()) || e.burst == 0 {
            return Err(ServerError::Config(format!(
                "the edit rate must be a finite number above 0 per second and the burst at least 1, got {} and {}",
                e.rate_per_second, e.burst
            )));
        }
        Ok(())
    }
}
