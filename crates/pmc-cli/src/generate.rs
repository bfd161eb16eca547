//! `pmc generate`: mesh a whole planet and write it as GLB, OBJ or PLY.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use crate::work;
use clap::Args;
use indicatif::ProgressBar;
use pmc_formats::{ExportMeta, Format};
use pmc_geometry::LatLon;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `pmc generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Output file. The format follows the extension: .glb (glTF 2.0 binary, one node per chunk,
    /// chunk-relative positions), .obj or .ply (one welded mesh in planet-centred metres).
    #[arg(short = 'o', long = "output", default_value = "planet.glb", value_name = "PATH")]
    output: PathBuf,

    /// Export the planet of this world file, with its edits (see `pmc edit`). The planet options
    /// then come from the world and cannot be given.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "seed", "radius", "n_c", "n_t", "d_b", "l_d", "d_c"])]
    world: Option<PathBuf>,

    /// Export only a region: the chunks of one level of detail within RADIUS_M metres of the
    /// ground at LAT,LON (degrees; the first surface going down from the sky). For planets too large to mesh whole (Earth). The
    /// level is --level, or the coarsest whose measured error is within --max-error, or 0.
    #[arg(long, value_name = "LAT,LON,RADIUS_M", allow_hyphen_values = true)]
    region: Option<String>,

    /// With --region: the level of detail (0 finest; `pmc info` lists the levels).
    #[arg(long, value_name = "L", requires = "region", conflicts_with = "max_error")]
    level: Option<u8>,

    /// With --region: the coarsest level whose measured geometric error is at most M metres.
    #[arg(long, value_name = "M", requires = "region", allow_negative_numbers = true)]
    max_error: Option<f64>,

    /// Worker threads; 0 uses every core. The output does not depend on it.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

/// Parses `--region LAT,LON,RADIUS_M` (of `pmc generate` and `pmc tiles bake`).
pub(crate) fn parse_region(s: &str) -> Result<(f64, f64, f64), CliError> {
    let err = |why: String| CliError::Region(format!("{s}: {why}; give LAT,LON,RADIUS_M (degrees, degrees, metres)"));
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(err(format!("expected 3 numbers, got {}", parts.len())));
    }
    let num = |name: &str, t: &str| {
        t.parse::<f64>()
            .map_err(|_| err(format!("the {name} {t:?} is not a number")))
    };
    let (lat, lon, radius) = (
        num("latitude", parts[0])?,
        num("longitude", parts[1])?,
        num("radius", parts[2])?,
    );
    LatLon::new(lat, lon).map_err(|e| err(e.to_string()))?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(err(format!("the radius {radius} is not a number of metres above 0")));
    }
    Ok((lat, lon, radius))
}

/// Checks, before any work, that `path` can be written in a known format.
fn check_output(path: &Path) -> Result<(), CliError> {
    Format::from_path(path).map_err(|e| CliError::Output {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    work::check_writable(path)
}

/// Runs `pmc generate`.
pub fn run(args: &GenerateArgs) -> Result<(), CliError> {
    let planet = match &args.world {
        Some(path) => crate::edit::planet_of(&pmc_world::World::open(path)?)?,
        None => args.planet.planet()?,
    };
    let layout = *planet.layout();
    let region = match &args.region {
        Some(r) => Some(parse_region(r)?),
        None => {
            work::check_whole_planet(&layout)?;
            None
        }
    };
    check_output(&args.output)?;
    let pool = work::thread_pool(args.threads)?;
    let start = Instant::now();
    let (total, meshes) = match region {
        Some((lat, lon, radius)) => {
            let level = match (args.level, args.max_error) {
                (Some(l), _) => l,
                (None, Some(e)) if e.is_finite() && e >= 0.0 => {
                    pmc_lod::level_for_error(&pmc_lod::measure_level_errors(&planet, 2048, 0x5eed), e)
                }
                (None, Some(e)) => {
                    return Err(CliError::Region(format!(
                        "--max-error must be a finite number of metres, at least 0, got {e}"
                    )))
                }
                (None, None) => 0,
            };
            let dir = LatLon::new(lat, lon)
                .map_err(|e| CliError::Region(e.to_string()))?
                .to_unit();
            // Centred on the ground there, so the region holds the surface around the place.
            let centre = dir * planet.surface_radius(dir);
            let keys = pmc_lod::region_chunks(&planet, centre, radius, level, pmc_lod::REGION_BUDGET)
                .map_err(|e| CliError::Region(e.to_string()))?;
            if !args.quiet {
                eprintln!(
                    "region of {radius} m around {lat}, {lon}: {} chunks of level {level} ({} m tiles along depth)",
                    keys.len(),
                    layout.l_d() * f64::from(1u32 << level)
                );
            }
            (keys.len() as u64, work::mesh_chunks(&planet, &keys, &pool, args.quiet))
        }
        None => (layout.chunk_count(), work::mesh_planet(&planet, &pool, args.quiet)),
    };
    let meshed = start.elapsed();
    let t = planet.terrain();
    let meta = ExportMeta {
        preset: t.spec.preset_kind().map_or("dem", |k| k.name()).to_string(),
        seed: t.spec.seed(),
        n_c: layout.n_c(),
        n_t: layout.n_t(),
        d_b: layout.d_b(),
        l_d: layout.l_d(),
        d_c: layout.d_c(),
        radius: layout.radius(),
        sea_radius: t.sea_radius,
        materials: t.materials.iter().map(|s| s.to_string()).collect(),
        generator: format!("pmc {}", env!("CARGO_PKG_VERSION")),
    };
    let spinner = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    spinner.set_message(format!("writing {}", args.output.display()));
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let stats = pmc_formats::export(&args.output, &meshes, &meta)?;
    spinner.finish_and_clear();
    if !args.quiet {
        eprintln!(
            "{} {} seed {}: {} chunks with surface of {}, {} triangles, {} vertices, meshed in {:.2} s; wrote {} ({:.1} MB) in {:.2} s",
            if stats.meshes > 0 { "planet" } else { "empty planet" },
            t.spec.name(),
            t.spec.seed(),
            meshes.len(),
            total,
            stats.triangles,
            stats.vertices,
            meshed.as_secs_f64(),
            args.output.display(),
            stats.bytes as f64 / 1e6,
            start.elapsed().as_secs_f64() - meshed.as_secs_f64(),
        );
    }
    Ok(())
}
