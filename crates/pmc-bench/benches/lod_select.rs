//! Level-of-detail selection (`pmc_lod::Selector::select`) on the views of `pmc bench-flight`:
//! 60 degree field of view, 1920 x 1080, 2 px, the default budget of 4096 chunks.
//!
//! - `earth/2m`: the earth preset at true scale (seed 7 as in `pmc bench-flight --preset earth`,
//!   6 371 km, 19 levels, 1 024 chunks of depth), the eye 2 m above the ground at 27.9 N 86.9 E
//!   looking north 15 degrees below the horizon; the budget cuts this selection, so it balances
//!   a dozen prefixes of the splits.
//! - `earth/orbit`: the same planet from twice its radius, looking at the centre.
//! - `default/2m`: the default planet (earthlike, seed 7, 2 km), the same ground view.
//!
//! The level errors are measured at the start as the server measures them (2 048 cells per
//! level, seed `0x5eed`). Each view is timed twice: on a selector that has selected it before (it
//! keeps the chunk columns' bounding caps, as during a flight), and on a fresh one (`/fresh`).
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use pmc_bench::default_planet;
use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::LatLon;
use pmc_lod::{frustum_planes, measure_level_errors, occluder_radius, LodParams, Selector, View};
use pmc_planet::{Planet, PresetKind};
use std::hint::black_box;

/// The radius of the outermost surface above `dir`: stepping down from the top of the density's
/// radial bounds, then bisecting the first crossing; the datum radius when there is none.
fn ground(planet: &Planet, dir: DVec3) -> f64 {
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

/// The view from `height` metres above the ground at 27.9 N 86.9 E: looking north 15 degrees
/// below the horizon, or at the centre from above a tenth of the radius.
fn view(planet: &Planet, height: f64) -> View {
    let dir = LatLon::new(27.9, 86.9).expect("a place").to_unit();
    let eye = dir * (ground(planet, dir) + height);
    let radius = planet.layout().radius();
    let north = (DVec3::Y - dir * dir.y).normalize_or(DVec3::X);
    let forward = if height > 0.1 * radius {
        -eye
    } else {
        north * 15f64.to_radians().cos() - dir * 15f64.to_radians().sin()
    };
    let fov = 60f64.to_radians();
    let near = (0.5 * height).clamp(0.05, 1.0e5);
    View {
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
    }
}

fn lod_select(c: &mut Criterion) {
    let earth = Planet::new(
        PresetKind::Earth,
        7,
        PresetKind::Earth.default_layout(None).expect("a layout"),
    );
    let earth_selector = Selector::new(
        *earth.layout(),
        measure_level_errors(&earth, 2048, 0x5eed),
        occluder_radius(&earth),
    )
    .expect("a selector");
    let default = default_planet();
    let default_selector = Selector::new(
        *default.layout(),
        measure_level_errors(&default, 2048, 0x5eed),
        occluder_radius(&default),
    )
    .expect("a selector");
    let params = LodParams::default();
    let mut g = c.benchmark_group("lod_select");
    for (name, selector, view) in [
        ("earth/2m", &earth_selector, view(&earth, 2.0)),
        (
            "earth/orbit",
            &earth_selector,
            view(&earth, 2.0 * earth.layout().radius()),
        ),
        ("default/2m", &default_selector, view(&default, 2.0)),
    ] {
        let s = selector.select(&view, &params).expect("a valid view");
        eprintln!(
            "{name}: {} chunks, {} drawn{}",
            s.chunks.len(),
            s.drawn().count(),
            if s.truncated { ", budget reached" } else { "" }
        );
        g.bench_function(name, |b| b.iter(|| black_box(selector.select(&view, &params))));
        // A fresh selector (a clone keeps no caps): every column cap computed anew.
        g.bench_function(format!("{name}/fresh"), |b| {
            b.iter_batched(
                || selector.clone(),
                |s| black_box(s.select(&view, &params)),
                BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, lod_select);
criterion_main!(benches);
