//! `pmc`: planetary marching cubes from the command line.
#![forbid(unsafe_code)]

/// `println!` for what a command prints on standard output: a reader that went away
/// (`pmc dem info earth.pmcdem | head -3`) ends the program quietly with the status a shell
/// gives a command stopped by SIGPIPE (141), as Unix tools do, and any other write error (a full
/// disk) is reported on standard error with status 1, instead of a panic.
macro_rules! outln {
    () => {
        $crate::stdout_line(format_args!(""))
    };
    ($($t:tt)*) => {
        $crate::stdout_line(format_args!($($t)*))
    };
}

mod dem;
mod edit;
mod error;
mod flight;
mod generate;
mod imagery;
mod info;
mod path;
mod planet_args;
mod render;
mod serve;
mod tiles;
mod work;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

/// Planetary marching cubes: closed planets with caves and overhangs, meshed on a cube-sphere.
#[derive(Parser, Debug)]
#[command(name = "pmc", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Mesh a whole planet and write it to a file (.glb, .obj or .ply).
    Generate(generate::GenerateArgs),
    /// Print the layout (chunk and voxel counts, radius: seed 000 Eq. 2-4) and the terrain.
    Info(info::InfoArgs),
    /// Render a picture of a planet to a PNG file.
    Render(render::RenderArgs),
    /// Serve the web viewer and the HTTP API: chunks are generated on demand and streamed.
    Serve(serve::ServeArgs),
    /// Dig and build: apply a brush to a planet kept in a world file, undo, redo, list edits.
    Edit(edit::EditArgs),
    /// Find a walking path between two places over the navigation grid (JSON or GeoJSON).
    Path(path::PathArgs),
    /// Measure a viewer's flight through an in-process server: a cold teleport to 2 m above
    /// the ground, then a descent from orbit (time to converge, triangles, memory per stop).
    BenchFlight(flight::FlightArgs),
    /// Real planets: import elevation models (netCDF, GeoTIFF, 16-bit PNG) onto the cube faces,
    /// describe the files, probe the surface at a place.
    Dem(dem::DemArgs),
    /// Imagery draped on a planet: import a colour image (JPEG, PNG, GeoTIFF) into a .pmcimg
    /// file for `pmc serve --imagery`, describe the file, look up its colour at a place.
    Imagery(imagery::ImageryArgs),
    /// OGC 3D Tiles 1.1: bake a planet into a static tileset for CesiumJS and other 3D Tiles
    /// clients (`pmc serve` also answers them live under /tiles/).
    Tiles(tiles::TilesArgs),
}

/// Writes one line to standard output (see `outln!`).
pub(crate) fn stdout_line(line: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if let Err(e) = writeln!(std::io::stdout().lock(), "{line}") {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(141);
        }
        eprintln!("error: writing to standard output: {e}");
        std::process::exit(1);
    }
}

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    let result = match &cli.command {
        Command::Generate(a) => generate::run(a),
        Command::Info(a) => info::run(a),
        Command::Render(a) => render::run(a),
        Command::Serve(a) => {
            // Which planet options were typed matters when a world file already holds a planet.
            let given = |id: &str| {
                matches
                    .subcommand_matches("serve")
                    .and_then(|m| m.value_source(id))
                    .is_some_and(|s| s == clap::parser::ValueSource::CommandLine)
            };
            serve::run(a, &given)
        }
        Command::Edit(a) => edit::run(a),
        Command::Path(a) => path::run(a),
        Command::BenchFlight(a) => flight::run(a),
        Command::Dem(a) => dem::run(a),
        Command::Imagery(a) => imagery::run(a),
        Command::Tiles(a) => tiles::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
