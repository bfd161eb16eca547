//! `pmc render`: a picture of a planet (PNG), from orbit or close to the ground.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use crate::work;
use clap::Args;
use pmc_geometry::LatLon;
use pmc_render::{Camera, RenderOptions};
use std::path::PathBuf;

/// Options of `pmc render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Output PNG file.
    #[arg(short = 'o', long = "output", default_value = "planet.png", value_name = "PATH")]
    output: PathBuf,

    /// Latitude of the camera, degrees.
    #[arg(long, default_value_t = 25.0, allow_negative_numbers = true)]
    lat: f64,

    /// Longitude of the camera, degrees.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    lon: f64,

    /// Camera distance from the planet centre in metres; by default the planet fills the frame.
    #[arg(long, value_name = "METRES")]
    distance: Option<f64>,

    /// Point the camera at this place on the surface, "LAT,LON" in degrees (default: the planet
    /// centre). With --distance close to the radius this gives a view along the ground.
    #[arg(long, value_name = "LAT,LON", value_parser = parse_lat_lon, allow_hyphen_values = true)]
    look_at: Option<LatLon>,

    /// Image width in pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,

    /// Image height in pixels.
    #[arg(long, default_value_t = 800)]
    height: u32,

    /// Worker threads; 0 uses every core.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

fn parse_lat_lon(s: &str) -> Result<LatLon, String> {
    s.parse::<LatLon>().map_err(|e| format!("{e}; give LAT,LON in degrees"))
}

/// Runs `pmc render`.
pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    let planet = args.planet.planet()?;
    let ext_ok = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !ext_ok {
        return Err(CliError::Output {
            path: args.output.clone(),
            reason: "pictures are written as PNG: use a .png name".into(),
        });
    }
    work::check_whole_planet(planet.layout())?;
    work::check_writable(&args.output)?;
    let pool = work::thread_pool(args.threads)?;
    let meshes = work::mesh_planet(&planet, &pool, args.quiet);
    let radius = planet.layout().radius();
    let mut camera = match args.distance {
        Some(d) => Camera::orbit(args.lat, args.lon, d),
        None => Camera::framing(args.lat, args.lon, radius),
    };
    if let Some(t) = args.look_at {
        camera = camera.with_look_at(t.to_unit() * planet.datum_radius());
    }
    let opts = RenderOptions {
        width: args.width,
        height: args.height,
        sea_radius: planet.terrain().sea_radius,
        atmosphere: planet.terrain().sea_radius.is_some(),
        ..Default::default()
    };
    let image = pool.install(|| pmc_render::render(&meshes, &camera, &opts))?;
    image.write_png(&args.output)?;
    if !args.quiet {
        eprintln!("wrote {} ({}x{})", args.output.display(), args.width, args.height);
    }
    Ok(())
}
