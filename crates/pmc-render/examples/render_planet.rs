//! Generates a planet and renders it to a PNG, timing both steps.
//!
//! `cargo run --release -p pmc-render --example render_planet -- [preset] [n_c] [n_t] [out.png] [lat] [lon] [distance]`
//! (defaults: earthlike 8 32 planet.png 25 -30, and a distance that frames the whole planet;
//! a distance in planet radii below about 1.5 looks at the horizon instead of the centre). The
//! layout uses d_b = 1744, l_d = 4, d_c = 2 as the CLI does.

use std::time::Instant;

use pmc_geometry::Layout;
use pmc_planet::{Planet, PresetKind};
use pmc_render::{render, Camera, RenderOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.to_string());
    let preset: PresetKind = arg(0, "earthlike").parse()?;
    let n_c: u32 = arg(1, "8").parse()?;
    let n_t: u32 = arg(2, "32").parse()?;
    let out = arg(3, "planet.png");
    let lat: f64 = arg(4, "25").parse()?;
    let lon: f64 = arg(5, "-30").parse()?;

    let layout = Layout::new(n_c, n_t, 1744.0, 4.0, 2)?;
    let planet = Planet::new(preset, 7, layout);
    let start = Instant::now();
    let meshes = planet.generate(|_| {});
    let triangles: usize = meshes.iter().map(|m| m.triangle_count()).sum();
    println!(
        "generated {} chunks, {triangles} triangles in {:.2?}",
        meshes.len(),
        start.elapsed()
    );

    let opts = RenderOptions {
        sea_radius: planet.terrain().sea_radius,
        ..RenderOptions::default()
    };
    let radius = planet.layout().radius();
    let camera = match args.get(6) {
        None => Camera::framing(lat, lon, radius),
        Some(d) => {
            let d: f64 = d.parse()?;
            let camera = Camera::orbit(lat, lon, d * radius);
            if d < 1.5 {
                // Look at a surface point 10 degrees north of the one below the camera.
                let ahead = pmc_geometry::LatLon::new((lat + 10.0).min(90.0), lon)?.to_unit() * planet.datum_radius();
                camera.with_look_at(ahead).with_fov(60.0)
            } else {
                camera
            }
        }
    };
    let start = Instant::now();
    let image = render(&meshes, &camera, &opts)?;
    println!("rendered {}x{} in {:.2?}", image.width, image.height, start.elapsed());
    image.write_png(&out)?;
    println!("wrote {out}");
    Ok(())
}
