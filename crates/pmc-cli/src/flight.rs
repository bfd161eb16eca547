//! `pmc bench-flight`: a viewer's flight through an in-process server, measured (see
//! `pmc_server::flight`): a cold teleport to the ground, then a descent from orbit.

use crate::error::CliError;
use crate::planet_args::{MesherName, PlanetArgs};
use clap::Args;
use pmc_server::flight::{descent, fly, FlightCamera, StopReport};
use pmc_server::{AppState, ServerConfig};
use serde_json::json;

/// Options of `pmc bench-flight`.
#[derive(Args, Debug)]
pub struct FlightArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Where to fly down: LAT,LON in degrees.
    #[arg(
        long,
        default_value = "27.9,86.9",
        value_name = "LAT,LON",
        allow_hyphen_values = true
    )]
    at: String,

    /// Worker threads generating chunks; 0 uses every core.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// How the planet is meshed: volumetric (marching cubes: caves, overhangs, editing) or
    /// heightfield (65 x 65 patches of six quadtrees, seed 003: elevation models only, no editing).
    #[arg(long, value_enum, default_value = "volumetric")]
    mesher: MesherName,

    /// Largest screen-space error, pixels.
    #[arg(long, default_value_t = 2.0, value_name = "PX")]
    pixels: f64,

    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// Parses `LAT,LON`.
fn parse_at(s: &str) -> Result<(f64, f64), CliError> {
    let place = crate::edit::parse_place("--at", s)?;
    Ok((place.lat(), place.lon()))
}

/// Runs `pmc bench-flight`.
pub fn run(args: &FlightArgs) -> Result<(), CliError> {
    let (lat, lon) = parse_at(&args.at)?;
    if !(args.pixels.is_finite() && args.pixels > 0.0) {
        return Err(CliError::Edit(format!("--pixels must be above 0, got {}", args.pixels)));
    }
    let terrain = args.planet.terrain()?;
    let layout = args.planet.layout_for(&terrain)?;
    let name = terrain.name();
    let config = ServerConfig {
        terrain,
        layout,
        mesher: args.mesher.into(),
        threads: args.threads,
        ..ServerConfig::default()
    };
    let camera = FlightCamera {
        max_pixel_error: args.pixels,
        ..FlightCamera::default()
    };
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| CliError::Threads {
            threads: 0,
            reason: e.to_string(),
        })?;
    let radius = layout.radius();
    let heights = |list: &[(&str, f64)]| list.iter().map(|(n, h)| (n.to_string(), *h)).collect::<Vec<_>>();
    let flights = [
        ("cold teleport", heights(&[("2 m", 2.0)])),
        (
            "descent",
            heights(&[
                ("orbit", 2.0 * radius),
                ("10 km", 10_000.0f64.min(0.5 * radius)),
                ("100 m", 100.0),
                ("2 m", 2.0),
            ]),
        ),
    ];
    let mut all: Vec<(&str, Vec<StopReport>)> = Vec::new();
    for (name, heights) in &flights {
        // A fresh server for each flight: the first stop starts cold.
        let reports = runtime.block_on(async {
            let state = AppState::new(config.clone()).map_err(CliError::Serve)?;
            let planet = state.default_planet().await.map_err(CliError::Edit)?;
            let stops = descent(&planet, lat, lon, heights).map_err(CliError::Edit)?;
            // The level errors are measured once per planet, before the camera arrives.
            let _ = state.lod_errors_of_default().await;
            fly(&state, &stops, &camera)
                .await
                .map_err(|e| CliError::Edit(e.to_string()))
        })?;
        all.push((name, reports));
    }
    if args.json {
        let v: Vec<_> = all
            .iter()
            .map(
                |(name, reports)| json!({"flight": name, "stops": reports.iter().map(report_json).collect::<Vec<_>>()}),
            )
            .collect();
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        outln!(
            "{} seed {} (radius {:.0} m) at {lat}, {lon}; {} px, 1920x1080, 60 deg",
            name,
            args.planet.seed,
            radius,
            args.pixels
        );
        for (name, reports) in &all {
            outln!("\n{name}:");
            outln!(
                "{:>8} {:>12} {:>10} {:>8} {:>7} {:>11} {:>10} {:>8} {:>6}  levels drawn",
                "stop",
                "height m",
                "converged",
                "select",
                "chunks",
                "triangles",
                "vs L0",
                "RSS MB",
                "cores"
            );
            for r in reports {
                outln!(
                    "{:>8} {:>12.1} {:>9.3}s {:>6.1}ms {:>7} {:>11} {:>9.1e}x {:>8} {:>6}  {}",
                    r.name,
                    r.height,
                    r.converged.as_secs_f64(),
                    r.selection.as_secs_f64() * 1e3,
                    r.drawn_per_level.iter().sum::<usize>(),
                    r.triangles,
                    r.level0_triangles / (r.triangles.max(1) as f64),
                    r.peak_rss
                        .map_or("-".into(), |b| format!("{:.0}", b as f64 / 1048576.0)),
                    r.cores_busy.map_or("-".into(), |c| format!("{c:.2}")),
                    histogram(r)
                );
            }
        }
    }
    Ok(())
}

/// `L0 12 · L1 40 · ...` for the levels with drawn chunks, with chunks generated per second.
fn histogram(r: &StopReport) -> String {
    r.drawn_per_level
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(l, n)| match r.chunks_per_second[l] {
            Some(c) => format!("L{l} {n} ({c:.0}/s)"),
            None => format!("L{l} {n}"),
        })
        .collect::<Vec<_>>()
        .join(" · ")
}

fn report_json(r: &StopReport) -> serde_json::Value {
    json!({
        "name": r.name,
        "height_m": r.height,
        "converged_s": r.converged.as_secs_f64(),
        "selection_s": r.selection.as_secs_f64(),
        "selected": r.selected,
        "drawn_per_level": r.drawn_per_level,
        "triangles": r.triangles,
        "level0_triangles_estimate": r.level0_triangles,
        "chunks_per_second": r.chunks_per_second,
        "truncated": r.truncated,
        "retries": r.retries,
        "peak_rss_bytes": r.peak_rss,
        "cores_busy": r.cores_busy,
    })
}
