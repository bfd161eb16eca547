//! `pmc generate`: mesh a whole planet and write it as GLB, OBJ or PLY.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use crate::work;
use clap::Args;
use indicatif::ProgressBar;
use pmc_formats::{ExportMeta, Format};
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
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "seed", "n_c", "n_t", "d_b", "l_d", "d_c"])]
    world: Option<PathBuf>,

    /// Worker threads; 0 uses every core. The output does not depend on it.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
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
        None => pmc_planet::Planet::new(args.planet.preset, args.planet.seed, args.planet.layout()?),
    };
    let layout = *planet.layout();
    work::check_whole_planet(&layout)?;
    check_output(&args.output)?;
    let pool = work::thread_pool(args.threads)?;
    let start = Instant::now();
    let total = layout.chunk_count();
    let meshes = work::mesh_planet(&planet, &pool, args.quiet);
    let meshed = start.elapsed();
    let t = planet.terrain();
    let meta = ExportMeta {
        preset: t.kind.name().to_string(),
        seed: t.seed,
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
            "{} preset {} seed {}: {} chunks with surface of {}, {} triangles, {} vertices, meshed in {:.2} s; wrote {} ({:.1} MB) in {:.2} s",
            if stats.meshes > 0 { "planet" } else { "empty planet" },
            t.kind,
            t.seed,
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
