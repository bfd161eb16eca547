//! 16-bit PNG elevation grids.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::dem_png(data));
