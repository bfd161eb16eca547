//! `pmc path`: the walking path between two places on a planet (or a world's edited planet), over
//! its navigation grid, as JSON or GeoJSON (docs/specs/path-v1.md).

use crate::edit::{parse_place, At};
use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use clap::{Args, ValueEnum};
use pmc_geometry::LatLon;
use pmc_nav::{path_geojson, path_json, query, Agent, End, NavGrid, PathAnswer};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Columns searched around each end for walkable ground.
pub const SNAP_RINGS: usize = 8;

/// Output formats of `pmc path`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PathFormat {
    /// The pmc-path JSON document.
    Json,
    /// A GeoJSON FeatureCollection: the path as a LineString of [lon, lat, alt].
    Geojson,
}

/// Options of `pmc path`.
#[derive(Args, Debug)]
pub struct PathArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Find the path on this world file's planet, with its edits (see `pmc edit`). The planet
    /// options then come from the world and cannot be given.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "seed", "n_c", "n_t", "d_b", "l_d", "d_c"])]
    world: Option<PathBuf>,

    /// Start: latitude and longitude in degrees and, optionally, the altitude in metres above the
    /// datum to pick a floor (a cave floor below the ground); without it the highest floor.
    /// Write negative values as --from=-10,20.
    #[arg(long, value_name = "LAT,LON[,ALT]", allow_hyphen_values = true)]
    from: String,

    /// Goal, like --from.
    #[arg(long, value_name = "LAT,LON[,ALT]", allow_hyphen_values = true)]
    to: String,

    /// Output format.
    #[arg(long, value_enum, default_value_t = PathFormat::Json)]
    format: PathFormat,

    /// Write to this file instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "PATH")]
    output: Option<PathBuf>,

    /// Head room the agent needs, metres.
    #[arg(long, default_value_t = Agent::default().clearance, value_name = "METRES", allow_negative_numbers = true)]
    clearance: f64,

    /// Largest rise between neighbouring columns, metres.
    #[arg(long = "step-up", default_value_t = Agent::default().step_up, value_name = "METRES", allow_negative_numbers = true)]
    step_up: f64,

    /// Largest drop between neighbouring columns, metres.
    #[arg(long = "step-down", default_value_t = Agent::default().step_down, value_name = "METRES", allow_negative_numbers = true)]
    step_down: f64,

    /// Steepest slope walked, degrees.
    #[arg(long = "max-slope", default_value_t = Agent::default().max_slope, value_name = "DEGREES", allow_negative_numbers = true)]
    max_slope: f64,

    /// Worker threads for building the grid; 0 uses every core.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing on standard error.
    #[arg(short, long)]
    quiet: bool,
}

/// One end: direction, and the radius of the floor when an altitude is given.
fn end(at: At, datum: f64) -> End {
    let dir = LatLon {
        lat: at.lat,
        lon: at.lon,
    }
    .to_unit();
    End {
        dir,
        radius: at.alt.map(|a| datum + a),
    }
}

/// Runs `pmc path`.
pub fn run(args: &PathArgs) -> Result<(), CliError> {
    let from = parse_place("--from", &args.from)?;
    let to = parse_place("--to", &args.to)?;
    let agent = Agent {
        clearance: args.clearance,
        step_up: args.step_up,
        step_down: args.step_down,
        max_slope: args.max_slope,
    };
    agent.validate().map_err(|e| CliError::Edit(e.to_string()))?;
    if let Some(out) = &args.output {
        crate::work::check_writable(out)?;
    }
    let planet = match &args.world {
        Some(path) => crate::edit::planet_of(&pmc_world::World::open(path)?)?,
        None => args.planet.planet()?,
    };
    let pool = crate::work::thread_pool(args.threads)?;
    let start = Instant::now();
    let grid = pool
        .install(|| NavGrid::build(planet.density().as_ref(), planet.layout(), agent))
        .map_err(|e| CliError::Edit(e.to_string()))?;
    if !args.quiet {
        eprintln!(
            "navigation grid: {} nodes in {} components, built in {:.0} ms",
            grid.node_count(),
            grid.component_sizes().len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    let datum = planet.datum_radius();
    let (a, b) = (end(from, datum), end(to, datum));
    let answer = query(&grid, a, b, SNAP_RINGS);
    if !args.quiet {
        match &answer {
            PathAnswer::Found(p) => eprintln!("path: {:.1} m in {} steps", p.length, p.nodes.len() - 1),
            other => eprintln!("{}", other.reason().unwrap_or_default()),
        }
    }
    let doc = match args.format {
        PathFormat::Json => path_json(&grid, &answer, a, b, datum),
        PathFormat::Geojson => path_geojson(&grid, &answer, a, b, datum),
    };
    let text = format!("{doc:#}\n");
    match &args.output {
        Some(out) => std::fs::write(out, text).map_err(|e| CliError::Output {
            path: out.clone(),
            reason: e.to_string(),
        })?,
        None => {
            let mut o = std::io::stdout().lock();
            // A closed stdout (a pipe into `head`) is not an error of the command.
            let _ = o.write_all(text.as_bytes());
        }
    }
    Ok(())
}
