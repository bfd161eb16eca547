//! A short run of the readers' mutation fuzzer (`src/fuzz.rs`), so that CI keeps it honest, and
//! the regression inputs of the panics it found.

use pmc_dem::fuzz;
use std::path::Path;

fn fixtures() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

#[test]
fn a_short_fuzz_run_finds_no_panic_in_any_reader() {
    let targets = fuzz::targets(&fixtures()).unwrap();
    assert_eq!(targets.len(), 9);
    let reports = fuzz::run(&targets, 800, 0x5EED, None);
    let panics: Vec<_> = reports
        .iter()
        .filter(|r| !r.panics.is_empty())
        .map(|r| (r.name, r.panics.clone()))
        .collect();
    assert!(panics.is_empty(), "{panics:?}");
    assert_eq!(reports.iter().map(|r| r.executions).sum::<u64>(), 9 * 800);
}

#[test]
fn inputs_are_rebuilt_from_the_seed_and_iteration() {
    let targets = fuzz::targets(&fixtures()).unwrap();
    let a = fuzz::input(&targets[2], 7, 2, 123);
    assert_eq!(a, fuzz::input(&targets[2], 7, 2, 123));
    assert_ne!(a, targets[2].seed);
    let mut rng = fuzz::Rng::new(1);
    assert!((0..1000).all(|_| rng.below(10) < 10));
}
