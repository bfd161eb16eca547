//! Mutation fuzzing of every reader over the fixture files (see `pmc_dem::fuzz`).
//!
//! `cargo run --release -p pmc-dem --example fuzz_readers -- --iterations N --seed S [--out DIR]`
//!
//! Parses N damaged copies of each target's seed file; prints, per target, the executions, the
//! time and the panics. Each panicking input is named by its seed and iteration and written to
//! DIR (default `target/fuzz-readers`). Exits with status 1 if any reader panicked.

use pmc_dem::fuzz;
use std::path::{Path, PathBuf};

fn main() {
    let mut iterations: u64 = 10_000;
    let mut seed: u64 = 1;
    let mut out = PathBuf::from("target/fuzz-readers");
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| usage(&format!("{arg} needs a value")));
        match arg.as_str() {
            "--iterations" => iterations = value().parse().unwrap_or_else(|_| usage("--iterations N")),
            "--seed" => seed = value().parse().unwrap_or_else(|_| usage("--seed S")),
            "--out" => out = PathBuf::from(value()),
            _ => usage(&format!("unknown argument {arg:?}")),
        }
    }
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let targets = fuzz::targets(&fixtures).unwrap_or_else(|e| {
        eprintln!("cannot read the seed files in {}: {e}", fixtures.display());
        std::process::exit(2);
    });
    // Panics are reported by the fuzzer; keep their messages short.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("  panic: {info}");
    }));
    println!(
        "{:<16} {:>12} {:>10} {:>12} {:>7}",
        "reader", "executions", "seconds", "execs/s", "panics"
    );
    let mut total = (0u64, 0.0f64, 0usize, 0u64);
    for report in fuzz::run(&targets, iterations, seed, Some(&out)) {
        let secs = report.elapsed.as_secs_f64();
        println!(
            "{:<16} {:>12} {:>10} {:>10.1} {:>12.0} {:>7}",
            report.name,
            report.executions,
            report.accepted,
            secs,
            report.executions as f64 / secs.max(1e-9),
            report.panics.len()
        );
        total.0 += report.executions;
        total.1 += secs;
        total.2 += report.panics.len();
        total.3 += report.accepted;
    }
    println!(
        "{:<16} {:>12} {:>10} {:>10.1} {:>12.0} {:>7}",
        "total",
        total.0,
        total.3,
        total.1,
        total.0 as f64 / total.1.max(1e-9),
        total.2
    );
    if total.2 > 0 {
        std::process::exit(1);
    }
}

fn usage(problem: &str) -> ! {
    eprintln!("{problem}\nusage: fuzz_readers [--iterations N] [--seed S] [--out DIR]");
    std::process::exit(2);
}
