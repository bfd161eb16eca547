//! World files (`docs/specs/world-sqlite-v2.md`: SQLite), opened as `pmc serve --world` does.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::world_file(data));
