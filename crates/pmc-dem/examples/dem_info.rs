//! Prints what `pmc-dem` reads from a netCDF classic elevation file: its grid, axes, wrap and
//! height statistics, and a few sampled heights.
//!
//! ```text
//! cargo run --release -p pmc-dem --example dem_info -- FILE.cdf [VARIABLE]
//! ```

use pmc_dem::EquirectDem;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: dem_info FILE.cdf [VARIABLE]");
        return ExitCode::from(2);
    };
    let variable = args.next();
    let start = std::time::Instant::now();
    let dem = match EquirectDem::read_netcdf(&path, variable.as_deref()) {
        Ok(dem) => dem,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let read_s = start.elapsed().as_secs_f64();
    let (w, h) = (dem.width(), dem.height());
    println!(
        "{} variable {}: {w} x {h} samples, read in {read_s:.3} s",
        dem.source(),
        dem.variable()
    );
    println!(
        "longitudes {} .. {} step {} ({}wraps)",
        dem.lon(0),
        dem.lon(w - 1),
        dem.lon_step(),
        if dem.wraps_in_longitude() { "" } else { "no " }
    );
    println!(
        "latitudes  {} .. {} step {} (row 0 south)",
        dem.lat(0),
        dem.lat(h - 1),
        dem.lat_step()
    );
    let s = dem.stats();
    let at = |(c, r): (usize, usize)| format!("col {c} row {r}, lat {:.4} lon {:.4}", dem.lat(r), dem.lon(c));
    println!("min {} m at {}", s.min, at(s.min_at));
    println!("max {} m at {}", s.max, at(s.max_at));
    println!("{} valid, {} missing", s.valid, s.missing);
    for (name, lat, lon) in [
        ("Everest", 27.988, 86.925),
        ("Challenger Deep", 11.35, 142.2),
        ("antimeridian, equator", 0.0, 180.0),
        ("same, as -180", 0.0, -180.0),
        ("North Pole", 90.0, 0.0),
    ] {
        println!("{name:>22} ({lat}, {lon}): {:?}", dem.sample_bilinear(lat, lon));
    }
    ExitCode::SUCCESS
}
