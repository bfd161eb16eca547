//! `.pmcdem` files (`docs/specs/pmcdem-v2.md`), opened as `pmc dem` and `pmc serve --dem` do.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::pmcdem(data));
