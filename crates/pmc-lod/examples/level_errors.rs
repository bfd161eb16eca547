//! Measures the per-level geometric errors of a preset on its default layout and prints the
//! table with the time it took.
//!
//! ```text
//! cargo run --release -p pmc-lod --example level_errors -- [preset] [samples per level] [seed]
//! ```
//!
//! Defaults: `earth`, 2048 samples per level (what the server asks for), seed `0x5eed`.

use pmc_lod::measure_level_errors;
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
    let samples = args
        .next()
        .map_or(2048, |s| s.parse().expect("samples per level: a number"));
    let seed = args.next().map_or(0x5eed, |s| s.parse().expect("seed: a number"));
    let layout = preset
        .default_layout(None)
        .expect("the preset's default layout is valid");
    let planet = Planet::new(preset, 1, layout);
    let start = Instant::now();
    let errors = measure_level_errors(&planet, samples, seed);
    let elapsed = start.elapsed();
    println!(
        "{name}: radius {} m, {samples} samples per level, seed {seed}",
        layout.radius()
    );
    for (level, e) in errors.iter().enumerate() {
        println!("level {level:2}: {e:12.3} m");
    }
    println!("measured in {:.3} s", elapsed.as_secs_f64());
}
