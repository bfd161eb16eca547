//! `pmc info`: the layout's counts and radius (seed 000 Eq. (2)-(4)) and the terrain.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use clap::Args;

/// Options of `pmc info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    planet: PlanetArgs,

    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `pmc info`.
pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let planet = args.planet.planet()?;
    let l = planet.layout();
    let t = planet.terrain();
    let face_arc = std::f64::consts::FRAC_PI_2 * l.radius();
    let tile = face_arc / l.face_tiles() as f64;
    let bounds = t.density.radial_bounds();
    // Counting chunks one by one is only worth it for planets that can be meshed whole.
    let candidate = (l.chunk_count() <= crate::work::MAX_WHOLE_PLANET_CHUNKS)
        .then(|| l.chunks(0).iter().filter(|k| planet.may_hold_surface(k)).count());
    if args.json {
        let v = serde_json::json!({
            "preset": t.kind.name(),
            "seed": t.seed,
            "layout": { "n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c() },
            "chunks": l.chunk_count(),
            "voxels": l.voxel_count(),
            "unique_voxels": l.unique_voxel_count(),
            "radius": l.radius(),
            "face_tiles": l.face_tiles(),
            "depth_tiles": l.depth_tiles(),
            "mean_tile_width": tile,
            "sea_radius": t.sea_radius,
            "surface_bounds": bounds.map(|(a, b)| [a, b]),
            "chunks_that_may_hold_surface": candidate,
            "materials": t.materials,
        });
        println!("{}", serde_json::to_string_pretty(&v).expect("JSON of plain values"));
        return Ok(());
    }
    println!(
        "planet       preset {} ({}), seed {}",
        t.kind,
        t.kind.description(),
        t.seed
    );
    println!(
        "layout       n_c = {}, n_t = {}, d_b = {} m, l_d = {} m, d_c = {}",
        l.n_c(),
        l.n_t(),
        l.d_b(),
        l.l_d(),
        l.d_c()
    );
    println!("chunks       {} (Eq. 2: 6 n_c^2 d_c)", l.chunk_count());
    println!(
        "voxels       {} (Eq. 3: 6 (n_t n_c + 1)^2 (n_t d_c + 1)), {} once paired",
        l.voxel_count(),
        l.unique_voxel_count()
    );
    println!("radius       {} m (Eq. 4: d_b + l_d n_t d_c)", l.radius());
    println!(
        "grid         {} tiles per face side, {} deep; tiles about {:.2} m wide at the surface, {} m deep",
        l.face_tiles(),
        l.depth_tiles(),
        tile,
        l.l_d()
    );
    match t.sea_radius {
        Some(s) => println!("sea          radius {s:.2} m ({:.2} m above the base)", s - l.d_b()),
        None => println!("sea          none"),
    }
    if let Some((a, b)) = bounds {
        match candidate {
            Some(c) => println!(
                "surface      between radius {a:.2} and {b:.2} m; {c} of {} chunks may hold it",
                l.chunk_count()
            ),
            None => println!("surface      between radius {a:.2} and {b:.2} m"),
        }
    }
    println!("materials    {}", t.materials.join(", "));
    Ok(())
}
