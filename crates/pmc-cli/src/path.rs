//! `pmc path`: the walking path between two places on a planet (or a world's edited planet), over
//! its navigation grid, as JSON or GeoJSON (docs/specs/path-v1.md).
//!
//! Planets of up to [`pmc_nav::EAGER_COLUMNS`] columns get the whole-planet grid (components known, the
//! walk from the hierarchical search, within [`pmc_nav::HIERARCHICAL_WEIGHT`] of the shortest, with
//! its smoothed form); larger ones, the Earth at true scale among them, get the lazy grid, built
//! tile by tile around the search within its bounds (`--max-expanded`, `--max-tiles`, `--weight`).

use crate::edit::parse_place;
use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use clap::{Args, ValueEnum};
use pmc_geometry::{LatLon, Place};
use pmc_nav::{
    lazy_path_geojson, lazy_path_json, path_geojson, path_json, query, query_exact, wants_lazy_grid, Agent, End,
    LazyGrid, LazyOptions, NavGrid, PathAnswer, SearchOptions,
};
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
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "seed", "radius", "n_c", "n_t", "d_b", "l_d", "d_c"])]
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

    /// Use the lazy grid, built tile by tile around the search, whatever the planet's size (it is
    /// used anyway above 4 million columns).
    #[arg(long)]
    lazy: bool,

    /// Whole-planet grid: the exact shortest walk (A* over the whole grid) instead of the
    /// hierarchical search's (within 1.5 times the shortest, far faster across long distances).
    #[arg(long)]
    exact: bool,

    /// Lazy grid: most nodes the search expands before it answers "no path found within the
    /// search bound".
    #[arg(long = "max-expanded", default_value_t = SearchOptions::default().max_expanded, value_name = "N")]
    max_expanded: usize,

    /// Lazy grid: most tiles (4 x 4 columns) the search builds before it answers "no path found
    /// within the search bound".
    #[arg(long = "max-tiles", default_value_t = SearchOptions::default().max_tiles_built, value_name = "N")]
    max_tiles: usize,

    /// Lazy grid: heuristic weight, at least 1; the path is at most this many times the
    /// shortest (1: a shortest path, which on rough ground may need far more of the bounds).
    #[arg(long, default_value_t = SearchOptions::default().weight, value_name = "W", allow_negative_numbers = true)]
    weight: f64,

    /// Worker threads for building the whole-planet grid; 0 uses every core (the lazy grid
    /// builds on one).
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing on standard error.
    #[arg(short, long)]
    quiet: bool,
}

/// One end: direction, and the radius of the floor when an altitude is given.
fn end(at: Place, datum: f64) -> End {
    let dir = LatLon {
        lat: at.lat(),
        lon: at.lon(),
    }
    .to_unit();
    End {
        dir,
        radius: at.alt().map(|a| datum + a),
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
    let search = SearchOptions {
        max_expanded: args.max_expanded,
        max_tiles_built: args.max_tiles,
        weight: args.weight,
    };
    search.validate().map_err(|e| CliError::Edit(e.to_string()))?;
    let datum = planet.datum_radius();
    let (a, b) = (end(from, datum), end(to, datum));
    let start = Instant::now();
    let lazy = args.lazy || wants_lazy_grid(planet.layout());
    let doc = if lazy {
        let mut grid = LazyGrid::new(planet.density().clone(), planet.layout(), agent, LazyOptions::default())
            .map_err(|e| CliError::Edit(e.to_string()))?;
        let found = grid.query(a, b, SNAP_RINGS, &search);
        if !args.quiet {
            eprintln!(
                "lazy navigation grid: {} tiles built ({} nodes), {} nodes expanded, in {:.0} ms",
                found.stats.tiles_built,
                grid.cached_nodes(),
                found.stats.expanded,
                start.elapsed().as_secs_f64() * 1e3
            );
            report(&found.answer);
        }
        match args.format {
            PathFormat::Json => lazy_path_json(&grid, &found, &search, a, b, datum),
            PathFormat::Geojson => lazy_path_geojson(&grid, &found, &search, a, b, datum),
        }
    } else {
        let pool = crate::work::thread_pool(args.threads)?;
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
        let answer = if args.exact {
            query_exact(&grid, a, b, SNAP_RINGS)
        } else {
            query(&grid, a, b, SNAP_RINGS)
        };
        if !args.quiet {
            report(&answer);
        }
        match args.format {
            PathFormat::Json => path_json(&grid, &answer, a, b, datum),
            PathFormat::Geojson => path_geojson(&grid, &answer, a, b, datum),
        }
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

/// One line on standard error: the path's length, or why there is none.
fn report<N>(answer: &PathAnswer<N>) {
    match answer {
        PathAnswer::Found(p) => eprintln!("path: {:.1} m in {} steps", p.length, p.nodes.len().saturating_sub(1)),
        other => eprintln!("{}", other.reason().unwrap_or_default()),
    }
}
