//! The HTTP API's query strings, chunk paths and edit bodies, through the server's router.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::http_request(data));
