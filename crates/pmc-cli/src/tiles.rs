//! `pmc tiles bake`: a planet as a static OGC 3D Tiles 1.1 tileset (`docs/specs/tiles-v1.md`).

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use crate::work;
use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pmc_tiles::bake::BakeStats;
use pmc_tiles::{FrameChoice, Region, TileOptions};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Options of `pmc tiles`.
#[derive(Args, Debug)]
pub struct TilesArgs {
    #[command(subcommand)]
    command: TilesCommand,
}

#[derive(Subcommand, Debug)]
enum TilesCommand {
    /// Bake a planet into a folder of 3D Tiles 1.1 (tileset.json, subtrees, glTF contents) that
    /// any web server can host and CesiumJS loads. Resumable: run it again after an interrupt.
    Bake(BakeArgs),
}

/// Where the tiles go in Earth-centred, Earth-fixed metres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FrameArg {
    /// WGS84 for a planet of the Earth's size (within 1% of 6 371 km), else the sphere.
    Auto,
    /// Latitude, longitude and height above sea level laid on the WGS84 ellipsoid: lines up
    /// with a globe's imagery and terrain.
    Wgs84,
    /// The planet's own sphere, rotated into ECEF axes.
    Sphere,
}

/// Options of `pmc tiles bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Bake the planet of this world file, with its edits (see `pmc edit`). The planet options
    /// then come from the world and cannot be given.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "seed", "radius", "n_c", "n_t", "d_b", "l_d", "d_c", "dem"])]
    world: Option<PathBuf>,

    /// The folder to bake into: created if missing; a bake of the same tileset found there is
    /// resumed; any other content is refused.
    #[arg(short = 'o', long = "output", default_value = "tiles", value_name = "DIR")]
    output: PathBuf,

    /// The deepest tile level (0 is a cube face's root; the earth preset has levels 0 to 18,
    /// level L holding chunks of level of detail 18 - L). Default: every level.
    #[arg(long, value_name = "L")]
    max_level: Option<u8>,

    /// Tiles above this level are kept in the tree without content.
    #[arg(long, value_name = "L", default_value_t = 0)]
    min_level: u8,

    /// Only the tiles near a place: within RADIUS_M metres of LAT,LON (degrees) at sea level.
    #[arg(long, value_name = "LAT,LON,RADIUS_M", allow_hyphen_values = true)]
    region: Option<String>,

    /// Where the tiles are placed.
    #[arg(long, value_enum, default_value = "auto")]
    frame: FrameArg,

    /// Worker threads; 0 uses every core. The output does not depend on it.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

impl From<FrameArg> for FrameChoice {
    fn from(arg: FrameArg) -> FrameChoice {
        match arg {
            FrameArg::Auto => FrameChoice::Auto,
            FrameArg::Wgs84 => FrameChoice::Wgs84,
            FrameArg::Sphere => FrameChoice::Sphere,
        }
    }
}

fn parse_region(s: &str) -> Result<Region, CliError> {
    let (lat, lon, radius) = crate::generate::parse_region(s)?;
    Ok(Region { lat, lon, radius })
}

/// Runs `pmc tiles`.
pub fn run(args: &TilesArgs) -> Result<(), CliError> {
    match &args.command {
        TilesCommand::Bake(b) => bake(b),
    }
}

fn bake(args: &BakeArgs) -> Result<(), CliError> {
    let (planet, edits) = match &args.world {
        Some(path) => {
            let world = pmc_world::World::open(path)?;
            let n = world.active_edits()?.len();
            (crate::edit::planet_of(&world)?, Some(n))
        }
        None => (args.planet.planet()?, None),
    };
    let region = args.region.as_deref().map(parse_region).transpose()?;
    let pool = work::thread_pool(args.threads)?;
    let extras = pmc_tiles::planet_extras(&planet, edits);
    let planet = Arc::new(planet);
    let quiet = args.quiet;
    let start = Instant::now();
    let say = |s: &str| {
        if !quiet {
            eprintln!("{s}");
        }
    };
    say("measuring the geometric error of each level of detail");
    let options = TileOptions {
        max_level: args.max_level,
        min_level: args.min_level,
        region,
    };
    let tiles = pool.install(|| pmc_tiles::bake::tile_set(planet, FrameChoice::from(args.frame), options))?;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr())
    };
    bar.set_style(ProgressStyle::with_template("{spinner} baking {msg} ({elapsed})").expect("valid template"));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let progress = |s: &BakeStats| {
        bar.set_message(format!(
            "{} subtrees, {} tiles, {:.1} MB{}",
            s.subtrees + s.resumed,
            s.tiles(),
            s.bytes() as f64 / 1e6,
            if s.resumed > 0 {
                format!(" ({} subtrees already baked)", s.resumed)
            } else {
                String::new()
            }
        ));
    };
    let stats = pool.install(|| pmc_tiles::bake::bake(&tiles, &args.output, extras, &progress))?;
    bar.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    if !quiet {
        outln!(
            "baked {} tiles ({:.1} MB, {} subtrees{}) into {} in {secs:.1} s, {:.0} tiles/s; frame {}",
            stats.tiles(),
            stats.bytes() as f64 / 1e6,
            stats.subtrees,
            if stats.resumed > 0 {
                format!(", {} resumed", stats.resumed)
            } else {
                String::new()
            },
            args.output.display(),
            stats.tiles() as f64 / secs.max(1e-9),
            tiles.frame().name(),
        );
        for (level, l) in stats.levels.iter().enumerate().filter(|(_, l)| l.tiles > 0) {
            outln!(
                "  level {level:>2}: {:>8} tiles {:>10.2} MB ({:.1} KB a tile)",
                l.tiles,
                l.bytes as f64 / 1e6,
                l.bytes as f64 / 1e3 / l.tiles as f64
            );
        }
        outln!(
            "host the folder with any web server and load {} (CesiumJS: Cesium3DTileset.fromUrl)",
            args.output.join("tileset.json").display()
        );
    }
    Ok(())
}
