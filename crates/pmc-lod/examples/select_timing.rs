//! Times [`Selector::select`] on the views of `pmc bench-flight`: a camera 2 m, 100 m and 10 km
//! above the ground looking north 15 degrees below the horizon, and one in orbit at twice the
//! radius looking at the centre (60 degree field of view, 1920 x 1080, 2 px, the default
//! budget), on the preset with seed 7 and the level errors the server measures (2048 cells per
//! level, seed `0x5eed`), as `pmc bench-flight` does. Prints, per view, the chunks selected and
//! drawn, whether the budget cut the selection, and the fastest and median time of a selection.
//!
//! ```text
//! cargo run --release -p pmc-lod --example select_timing -- [preset] [LAT,LON] [repeats]
//! ```
//!
//! Defaults: `earth`, `27.9,86.9`, 5 repeats. With `PMC_SELECT_VIEWS=FILE` in the environment the
//! views are also written to `FILE` as JSON, as the cases of `tests/data/selection-vectors.json`
//! are written (without the expected selections), for timing other implementations of the rule.

use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::LatLon;
use pmc_lod::{frustum_planes, measure_level_errors, occluder_radius, LodParams, Selector, View};
use pmc_planet::{Planet, PresetKind};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "earth".to_owned());
    let Some(preset) = PresetKind::ALL.into_iter().find(|p| p.name() == name) else {
        let names: Vec<&str> = PresetKind::ALL.iter().map(|p| p.name()).collect();
        eprintln!("unknown preset {name:?}; one of {}", names.join(", "));
        std::process::exit(2);
    };
    let at = args.next().unwrap_or_else(|| "27.9,86.9".to_owned());
    let (lat, lon) = at
        .split_once(',')
        .and_then(|(a, b)| Some((a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?)))
        .expect("LAT,LON in degrees");
    let repeats: usize = args.next().map_or(5, |s| s.parse().expect("repeats: a number"));
    let layout = preset
        .default_layout(None)
        .expect("the preset's default layout is valid");
    let planet = Planet::new(preset, 7, layout);
    let start = Instant::now();
    let errors = measure_level_errors(&planet, 2048, 0x5eed);
    println!(
        "{name}: radius {} m, {} levels, errors measured in {:.2} s",
        layout.radius(),
        errors.len(),
        start.elapsed().as_secs_f64()
    );
    let selector = Selector::new(layout, errors, occluder_radius(&planet)).expect("a valid selector");
    let dir = LatLon::new(lat, lon).expect("a valid place").to_unit();
    let ground = surface_radius(&planet, dir);
    let north = (DVec3::Y - dir * dir.y).normalize_or(DVec3::X);
    let ahead = north * 15f64.to_radians().cos() - dir * 15f64.to_radians().sin();
    let fov = 60f64.to_radians();
    let radius = layout.radius();
    let mut cases = Vec::new();
    for (label, height) in [
        ("orbit", 2.0 * radius),
        ("10 km", 10_000.0f64.min(0.5 * radius)),
        ("100 m", 100.0),
        ("2 m", 2.0),
    ] {
        let eye = dir * (ground + height);
        let (forward, near) = if height > 0.1 * radius {
            (-eye, (0.5 * height).clamp(0.05, 1.0e5))
        } else {
            (ahead, (0.5 * height).clamp(0.05, 1.0e5))
        };
        let view = View {
            eye,
            frustum: Some(frustum_planes(
                eye,
                forward,
                dir,
                fov,
                16.0 / 9.0,
                near,
                eye.length() + 2.0 * radius,
            )),
            viewport_height_px: 1080.0,
            fov_y: fov,
        };
        let params = LodParams::default();
        cases.push(case_json(&format!("{name} {label}"), &selector, &view, &params));
        let mut times = Vec::with_capacity(repeats);
        let mut selection = None;
        for _ in 0..repeats.max(1) {
            let t = Instant::now();
            let s = selector.select(&view, &params).expect("a valid view");
            times.push(t.elapsed().as_secs_f64() * 1e3);
            selection = Some(s);
        }
        times.sort_by(f64::total_cmp);
        let s = selection.expect("at least one selection");
        println!(
            "{label:>6}: {:5} chunks ({} drawn){}, fastest {:9.3} ms, median {:9.3} ms, levels {:?}",
            s.chunks.len(),
            s.drawn().count(),
            if s.truncated { ", truncated" } else { "" },
            times[0],
            times[times.len() / 2],
            s.level_histogram()
        );
    }
    if let Some(path) = std::env::var_os("PMC_SELECT_VIEWS") {
        let text = serde_json::to_string_pretty(&cases).expect("views are JSON");
        std::fs::write(&path, text).expect("the views file can be written");
    }
}

/// A view as a case of the shared selection vectors (without the expected selection).
fn case_json(name: &str, selector: &Selector, view: &View, params: &LodParams) -> serde_json::Value {
    let l = selector.layout();
    serde_json::json!({
        "name": name,
        "layout": { "n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c() },
        "errors": selector.errors(),
        "occluder": selector.occluder(),
        "view": {
            "eye": view.eye.to_array(),
            "frustum": view.frustum.map(|f| f.map(|p| p.to_array())),
            "viewport_height_px": view.viewport_height_px,
            "fov_y": view.fov_y,
        },
        "params": {
            "max_pixel_error": params.max_pixel_error,
            "finest_level": params.finest_level,
            "max_chunks": params.max_chunks,
        },
    })
}

/// The radius of the outermost surface above `dir`: stepping down from the top of the density's
/// radial bounds, then bisecting the first crossing; the datum radius when there is none.
fn surface_radius(planet: &Planet, dir: DVec3) -> f64 {
    let density = planet.density();
    let layout = planet.layout();
    let (top, bottom) = match density.radial_bounds() {
        Some((lo, hi)) => (hi.min(layout.radius()), lo.max(layout.d_b())),
        None => (layout.radius(), layout.d_b()),
    };
    let step = layout.l_d().max((top - bottom) / 4096.0);
    let solid = |r: f64| density.density(dir * r) > 0.0;
    let (mut lo, mut hi) = (top - step, top);
    if solid(hi) {
        return hi;
    }
    while lo >= bottom {
        if solid(lo) {
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if solid(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return lo;
        }
        hi = lo;
        lo -= step;
    }
    planet.datum_radius()
}
