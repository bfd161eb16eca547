//! `pmc info`: the layout's counts and radius (seed 000 Eq. (2)-(4)), its levels of detail and
//! the terrain.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use clap::Args;
use pmc_geometry::{Face, Layout};

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
    let levels: Vec<Level> = (0..=l.max_level()).map(|level| Level::of(l, level)).collect();
    if args.json {
        let v = serde_json::json!({
            "preset": t.spec.preset_kind().map(|k| k.name()),
            "terrain": t.spec.to_string(),
            "seed": t.spec.seed(),
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
            "max_level": l.max_level(),
            "levels": levels.iter().map(|v| serde_json::json!({
                "level": v.level,
                "chunks_per_side": v.per_side,
                "depth_chunks": v.depth,
                "voxel_across_min": v.across.0,
                "voxel_across_max": v.across.1,
                "voxel_radial": v.radial,
                "chunk_across": v.chunk_across,
                "chunk_deep": v.chunk_deep,
            })).collect::<Vec<_>>(),
        });
        outln!("{}", serde_json::to_string_pretty(&v).expect("JSON of plain values"));
        return Ok(());
    }
    outln!(
        "planet       {} ({}), seed {}",
        t.spec.name(),
        t.spec
            .preset_kind()
            .map_or("an elevation model, detail noise and caves", |k| k.description()),
        t.spec.seed()
    );
    outln!(
        "layout       n_c = {}, n_t = {}, d_b = {} m, l_d = {} m, d_c = {}",
        l.n_c(),
        l.n_t(),
        l.d_b(),
        l.l_d(),
        l.d_c()
    );
    outln!("chunks       {} (Eq. 2: 6 n_c^2 d_c)", l.chunk_count());
    outln!(
        "voxels       {} (Eq. 3: 6 (n_t n_c + 1)^2 (n_t d_c + 1)), {} once paired",
        l.voxel_count(),
        l.unique_voxel_count()
    );
    outln!("radius       {} m (Eq. 4: d_b + l_d n_t d_c)", l.radius());
    outln!(
        "grid         {} tiles per face side, {} deep; tiles about {:.2} m wide at the surface, {} m deep",
        l.face_tiles(),
        l.depth_tiles(),
        tile,
        l.l_d()
    );
    match t.sea_radius {
        Some(s) => outln!("sea          radius {s:.2} m ({:.2} m above the base)", s - l.d_b()),
        None => outln!("sea          none"),
    }
    if let Some((a, b)) = bounds {
        match candidate {
            Some(c) => outln!(
                "surface      between radius {a:.2} and {b:.2} m; {c} of {} chunks may hold it",
                l.chunk_count()
            ),
            None => outln!("surface      between radius {a:.2} and {b:.2} m"),
        }
    }
    outln!("materials    {}", t.materials.join(", "));
    outln!(
        "levels       {} levels of detail, 0 to {}; voxel widths across the face (min-max) at radius {} m",
        levels.len(),
        l.max_level(),
        l.radius()
    );
    outln!("  level  chunks/side  depth chunks  voxel across (min-max)  voxel radial  chunk (across x deep)");
    for v in &levels {
        outln!(
            "  {:>5}  {:>11}  {:>12}  {:>22}  {:>12}  {:>21}",
            v.level,
            v.per_side,
            v.depth,
            format!("{} - {}", length(v.across.0), length(v.across.1)),
            length(v.radial),
            format!("{} x {}", length(v.chunk_across), length(v.chunk_deep)),
        );
    }
    Ok(())
}

/// One level of detail of a layout.
struct Level {
    level: u8,
    /// Chunks per face side.
    per_side: u32,
    /// Chunks along depth.
    depth: u32,
    /// Smallest and largest voxel edge across the face at the layout radius (metres), from the
    /// edges at a grid of 65 x 65 places on a face (every face is the same).
    across: (f64, f64),
    /// Voxel depth, `l_d 2^level` metres.
    radial: f64,
    /// A chunk's mean width across the face and its depth (metres).
    chunk_across: f64,
    chunk_deep: f64,
}

impl Level {
    fn of(l: &Layout, level: u8) -> Level {
        let stride = 1i64 << level;
        let n = l.face_tiles();
        let radius = l.radius();
        // Places on the level's grid: the face's edges, its middle and a regular grid between.
        let samples = 64.min(n / stride);
        let place = |t: i64| (t * (n / stride) / samples) * stride;
        let dir = |i: i64, j: i64| l.lattice(Face::ALL[0], i, j).map(|p| l.lattice_direction(p));
        let (mut lo, mut hi) = (f64::MAX, 0.0f64);
        for a in 0..=samples {
            for b in 0..=samples {
                let (i, j) = (place(a).min(n - stride), place(b));
                if let (Some(p), Some(q)) = (dir(i, j), dir(i + stride, j)) {
                    let w = (q - p).length() * radius;
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
            }
        }
        let span = l.chunk_span(level) as f64;
        Level {
            level,
            per_side: l.chunks_per_side(level),
            depth: l.depth_chunks(level),
            across: (lo, hi),
            radial: l.l_d() * stride as f64,
            chunk_across: span * std::f64::consts::FRAC_PI_2 * radius / n as f64,
            chunk_deep: span * l.l_d(),
        }
    }
}

/// A length in metres for people: three significant figures, in km from 10 km.
fn length(m: f64) -> String {
    if m >= 10_000.0 {
        format!("{} km", sig3(m / 1000.0))
    } else {
        format!("{} m", sig3(m))
    }
}

fn sig3(x: f64) -> String {
    let decimals = if x >= 100.0 {
        0
    } else if x >= 10.0 {
        1
    } else {
        2
    };
    format!("{x:.decimals$}")
}
