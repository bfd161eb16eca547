//! The chunk mesh decoder (`docs/specs/chunk-mesh-v1.md`): any bytes decode into a consistent
//! chunk or are refused with an error, never a panic.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::chunk_decode(data));
