//! `pmc`: planetary marching cubes from the command line.
#![forbid(unsafe_code)]

mod edit;
mod error;
mod generate;
mod info;
mod planet_args;
mod render;
mod serve;
mod work;

use clap::{Parser, Subcommand};
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Generate(a) => generate::run(a),
        Command::Info(a) => info::run(a),
        Command::Render(a) => render::run(a),
        Command::Serve(a) => serve::run(a),
        Command::Edit(a) => edit::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
