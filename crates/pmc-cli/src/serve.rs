//! `pmc serve`: the web viewer and the HTTP API, streaming chunks of a planet generated on demand.

use crate::edit::WorldPlanetArgs;
use crate::error::CliError;
use crate::planet_args::{MesherName, PlanetArgs};
use clap::Args;
use pmc_server::{EditLimits, Server, ServerConfig};
use std::io::{IsTerminal, Write};
use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

/// Options of `pmc serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Address to listen on: an IP address, or "localhost". 127.0.0.1 serves this machine only;
    /// 0.0.0.0 serves every network interface.
    #[arg(long, default_value = "127.0.0.1", value_name = "ADDRESS")]
    host: String,

    /// Port to listen on; 0 picks a free one (the URL line says which).
    #[arg(long, default_value_t = 8080)]
    port: u16,

    /// How the planet is meshed: volumetric (marching cubes: caves, overhangs, editing) or
    /// heightfield (65 x 65 patches of six quadtrees, seed 003: elevation models only, no editing).
    #[arg(long, value_enum, default_value = "volumetric")]
    mesher: MesherName,

    /// Worker threads that generate chunks; 0 uses every core.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Most megabytes (MiB) of encoded chunks kept in memory (with --world, a quarter as much
    /// again for the meshes whose shading an edit reuses).
    #[arg(long = "cache-mb", default_value_t = 512, value_name = "MIB")]
    cache_mb: u64,

    /// Serve and edit this world file (SQLite, format pmc-world v2; see `pmc edit`): the viewer
    /// gets its dig, build, smooth, flatten and paint tools, and every edit is saved durably. A
    /// missing file is created with the planet options; an existing one keeps its own planet
    /// (planet options given must agree with it).
    #[arg(long, value_name = "FILE")]
    world: Option<PathBuf>,

    /// Largest brush radius, metres, that clients may use (with --world).
    #[arg(long = "max-brush-radius", default_value_t = EditLimits::default().max_brush_radius, value_name = "METRES", allow_negative_numbers = true)]
    max_brush_radius: f64,

    /// Edits per second one client address may send on average (with --world).
    #[arg(long = "edit-rate", default_value_t = EditLimits::default().rate_per_second, value_name = "PER_SECOND", allow_negative_numbers = true)]
    edit_rate: f64,

    /// Edits one client address may send at once before --edit-rate applies (with --world).
    #[arg(long = "edit-burst", default_value_t = EditLimits::default().burst, value_name = "N")]
    edit_burst: u32,

    /// Drape this imagery (a .pmcimg file made by `pmc imagery import`) on the planet: the
    /// viewer colours the terrain from it (GET /api/v1/imagery).
    #[arg(long, value_name = "FILE.pmcimg")]
    imagery: Option<PathBuf>,

    /// Where the OGC 3D Tiles at /tiles/tileset.json are placed: auto (WGS84 for a planet of the
    /// Earth's size, else its sphere), wgs84 or sphere.
    #[arg(long = "tiles-frame", value_enum, default_value = "auto")]
    tiles_frame: crate::tiles::FrameArg,

    /// CesiumJS's built files (npm's cesium/Build/Cesium): the CesiumJS example page at /cesium/
    /// then shows the planet's 3D Tiles (./scripts/run.sh installs it in examples/cesium).
    #[arg(long = "cesium-js", value_name = "DIR")]
    cesium_js: Option<PathBuf>,
}

/// Parses `--host`: an IP address or "localhost" (no name lookups).
fn parse_host(s: &str) -> Result<IpAddr, CliError> {
    if s.eq_ignore_ascii_case("localhost") {
        return Ok(IpAddr::V4(Ipv4Addr::LOCALHOST));
    }
    s.trim_start_matches('[')
        .trim_end_matches(']')
        .parse::<IpAddr>()
        .map_err(|_| CliError::Host(s.to_string()))
}

/// Runs `pmc serve` until Ctrl-C or SIGTERM. `given` tells which planet options were typed.
pub fn run(args: &ServeArgs, given: &dyn Fn(&str) -> bool) -> Result<(), CliError> {
    let terrain = args.planet.terrain()?;
    let layout = args.planet.layout_for(&terrain)?;
    let host = parse_host(&args.host)?;
    if let Some(path) = args.world.as_deref().filter(|p| std::fs::symlink_metadata(p).is_ok()) {
        // An existing world keeps its planet: typed options that disagree are a mistake.
        let world = pmc_world::World::open(path)?;
        WorldPlanetArgs::typed(&args.planet, given).check_against(&world)?;
        world.close()?;
    }
    let config = ServerConfig {
        host,
        port: args.port,
        terrain,
        layout,
        mesher: args.mesher.into(),
        cache_bytes: args.cache_mb.saturating_mul(1 << 20),
        threads: args.threads,
        world: args.world.clone(),
        imagery: args.imagery.clone(),
        tiles_frame: args.tiles_frame.into(),
        cesium_js: args.cesium_js.clone(),
        edit_limits: EditLimits {
            max_brush_radius: args.max_brush_radius,
            rate_per_second: args.edit_rate,
            burst: args.edit_burst,
            ..EditLimits::default()
        },
        ..ServerConfig::default()
    };
    init_logging();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .thread_name("pmc-http")
        .build()
        .map_err(|e| CliError::Threads {
            threads: 0,
            reason: e.to_string(),
        })?;
    runtime.block_on(async {
        let server = Server::bind(config).await?;
        let mut out = std::io::stdout().lock();
        // The URL line is what scripts and tests wait for; a closed stdout is no reason to stop.
        let _ = writeln!(out, "PMC viewer: {}", server.url());
        if server.state().config().cesium_js.is_some() {
            let _ = writeln!(out, "CesiumJS (3D Tiles): {}cesium/", server.url());
        }
        let _ = out.flush();
        drop(out);
        server.run(pmc_server::shutdown_signal()).await
    })?;
    Ok(())
}

/// Logs to stderr, filtered by `RUST_LOG` (default: the server's start and stop lines and
/// warnings; `RUST_LOG=pmc_server=debug` adds one line per request).
fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,pmc_server=info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .try_init();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hosts() {
        assert_eq!(parse_host("localhost").unwrap(), IpAddr::V4(Ipv4Addr::LOCALHOST));
        assert_eq!(parse_host("0.0.0.0").unwrap(), IpAddr::V4(Ipv4Addr::UNSPECIFIED));
        assert!(parse_host("[::1]").unwrap().is_loopback());
        assert!(matches!(parse_host("not-an-ip"), Err(CliError::Host(_))));
    }
}
