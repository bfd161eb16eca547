//! What one chunk's density batch costs on the earth preset at true scale.
//!
//! Run with `cargo run --release -p pmc-density --example earth_chunk_cost`. For chunks of
//! several levels of detail at the surface (over land and over the sea), and at level 0 one and
//! ten kilometres above and below it, prints the mean time of one `sample_shell` call over the
//! chunk's padded `(n_t + 3)^3` sample grid, with two references measured in the same run: one
//! call of the gradient noise, and a surface chunk of the earthlike preset on its 2000 m layout.

use pmc_density::noise::gradient3;
use pmc_density::presets::{build, PresetKind};
use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Face, Layout};
use std::time::Instant;

/// The radius of the outermost surface along `dir`: the first sign change from the top of the
/// bounds, stepping `step` metres, refined by bisection.
fn surface(d: &dyn Density, dir: DVec3, lo: f64, hi: f64, step: f64) -> f64 {
    let mut r = hi;
    while r > lo && d.density(dir * r) <= 0.0 {
        r -= step;
    }
    let (mut a, mut b) = (r, r + step);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if d.density(dir * m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    a
}

/// The chunk of `level` over face grid point `(i, j)` of `face` whose depth range holds radius `r`.
fn chunk_at(layout: &Layout, face: Face, i: i64, j: i64, level: u8, r: f64) -> ChunkKey {
    let span = layout.chunk_span(level);
    let k = ((r - layout.d_b()) / layout.l_d()).floor() as i64 / span;
    ChunkKey {
        face,
        level,
        i: (i / span) as u32,
        j: (j / span) as u32,
        k: k.clamp(0, i64::from(layout.depth_chunks(level)) - 1) as u32,
    }
}

fn time_chunks(name: &str, d: &dyn Density, layout: &Layout, keys: &[ChunkKey]) {
    let grids: Vec<ChunkGrid> = keys.iter().map(|k| ChunkGrid::new(layout, *k)).collect();
    let mut out = vec![0.0f32; grids[0].sample_count()];
    // Warm up once, then time every chunk a few times.
    for g in &grids {
        d.sample_shell(&g.dirs, &g.radii, &mut out);
    }
    let reps = 3;
    let start = Instant::now();
    let mut solid = 0usize;
    for _ in 0..reps {
        for g in &grids {
            d.sample_shell(&g.dirs, &g.radii, &mut out);
            solid += out.iter().filter(|v| **v > 0.0).count();
        }
    }
    let per = start.elapsed().as_secs_f64() / (reps * grids.len()) as f64;
    let frac = solid as f64 / (reps * grids.len() * out.len()) as f64;
    println!(
        "{name:<34} {:>4} chunks, {:>6} samples each: {:>7.3} ms per chunk ({:.0} ns per sample), {:.0}% solid",
        grids.len(),
        out.len(),
        per * 1e3,
        per * 1e9 / out.len() as f64,
        frac * 100.0
    );
}

fn main() {
    let layout = PresetKind::Earth.default_layout(None).expect("the earth layout");
    let terrain = build(PresetKind::Earth, 7, &layout);
    let d = &*terrain.density;
    let sea = terrain.sea_radius.expect("the earth has a sea");
    let (lo, hi) = d.radial_bounds().expect("bounds");
    let n = layout.face_tiles();
    // Pseudo-random places on every face, split into land and sea by their surface.
    let (mut land, mut sea_places) = (Vec::new(), Vec::new());
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    while land.len() < 40 || sea_places.len() < 40 {
        let face = Face::ALL[(next() % 6) as usize];
        let (i, j) = ((next() % n as u64) as i64, (next() % n as u64) as i64);
        let dir = layout.lattice_direction(layout.lattice(face, i, j).expect("on the face"));
        let h = surface(d, dir, lo, hi, 25.0);
        if h > sea && land.len() < 40 {
            land.push((face, i, j, h));
        } else if h <= sea && sea_places.len() < 40 {
            sea_places.push((face, i, j, h));
        }
    }
    // Calibration: the cost of one noise lattice evaluation on this machine now.
    let start = Instant::now();
    let mut acc = 0.0;
    for i in 0..2_000_000 {
        let x = f64::from(i) * 0.37;
        acc += gradient3(DVec3::new(x, 0.7 * x + 6.4e6, 3.3 - x), 5);
    }
    println!(
        "one gradient3 call: {:.1} ns (checksum {acc:.3})",
        start.elapsed().as_secs_f64() * 1e9 / 2e6
    );
    let small = Layout::default();
    let earthlike = build(PresetKind::Earthlike, 7, &small);
    let (elo, ehi) = earthlike.density.radial_bounds().expect("bounds");
    let ns = small.face_tiles() as u64;
    let keys: Vec<ChunkKey> = (0..40)
        .map(|_| {
            let face = Face::ALL[(next() % 6) as usize];
            let (i, j) = ((next() % ns) as i64, (next() % ns) as i64);
            let dir = small.lattice_direction(small.lattice(face, i, j).expect("on the face"));
            let h = surface(&*earthlike.density, dir, elo, ehi, 0.5);
            chunk_at(&small, face, i, j, 0, h)
        })
        .collect();
    time_chunks(
        "earthlike (2000 m), level 0, surface",
        &*earthlike.density,
        &small,
        &keys,
    );
    println!("earth preset, seed 7, layout n_c = 2^18, n_t = 32, l_d = 1 m, d_c = 1024");
    for level in [0u8, 4, 8, 12, 18] {
        for (what, places) in [("land", &land), ("sea floor", &sea_places)] {
            let keys: Vec<ChunkKey> = places
                .iter()
                .map(|(f, i, j, h)| chunk_at(&layout, *f, *i, *j, level, *h))
                .collect();
            time_chunks(&format!("level {level:>2}, surface, {what}"), d, &layout, &keys);
        }
    }
    for (what, dz) in [
        ("1 km above", 1000.0),
        ("10 km above", 10_000.0),
        ("1 km below", -1000.0),
        ("10 km below", -10_000.0),
    ] {
        let keys: Vec<ChunkKey> = land
            .iter()
            .map(|(f, i, j, h)| chunk_at(&layout, *f, *i, *j, 0, (h + dz).clamp(layout.d_b(), layout.radius())))
            .collect();
        time_chunks(&format!("level  0, {what} the land"), d, &layout, &keys);
    }
}
