//! netCDF classic elevation grids, read whole and as a source of rows.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| pmc_fuzz::dem_netcdf(data));
