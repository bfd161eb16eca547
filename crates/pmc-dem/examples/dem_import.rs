//! Reprojects an equirectangular netCDF elevation grid onto the six cube faces and writes a
//! `.pmcdem` file, then reopens it, verifies every tile and prints timings, the file's size and
//! its storage table (seed 003 Fig. 13), and the cost of sampling heights.
//!
//! ```text
//! cargo run --release -p pmc-dem --example dem_import -- IN.cdf OUT.pmcdem [LEVEL] [BUDGET_MIB]
//! ```

use pmc_dem::cube::{import_cube, CubeDem, DetailNoise, ImportOptions, Interpolation};
use pmc_dem::EquirectDem;
use pmc_geometry::LatLon;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: dem_import IN.cdf OUT.pmcdem [LEVEL] [BUDGET_MIB]");
        return ExitCode::from(2);
    }
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    let t = Instant::now();
    let dem = EquirectDem::read_netcdf(&args[0], None)?;
    println!(
        "read {}: {} x {} samples in {:.2} s",
        dem.source(),
        dem.width(),
        dem.height(),
        t.elapsed().as_secs_f64()
    );
    let mut options = ImportOptions::default();
    if let Some(level) = args.get(2) {
        options.level = Some(level.parse()?);
    }
    if let Some(mib) = args.get(3) {
        options.memory_budget = mib.parse::<usize>()? << 20;
    }
    let t = Instant::now();
    let report = import_cube(&dem, args[1].as_ref(), &options, &|done, total| {
        if done == total {
            eprintln!("{done}/{total} tiles");
        }
    })?;
    let import_s = t.elapsed().as_secs_f64();
    println!(
        "imported level {} ({} samples a side) as {:?} in {import_s:.2} s on {} threads: {} tiles ({} constant), {} samples, {} filled, {} bytes ({:.1} MB), {} band(s) of {} rows",
        report.level,
        (1u64 << report.level) + 1,
        report.format,
        rayon::current_num_threads(),
        report.tiles,
        report.constant_tiles,
        report.samples,
        report.filled,
        report.bytes,
        report.bytes as f64 / 1e6,
        report.bands,
        report.band_rows
    );
    println!("digest {}", report.digest);
    let t = Instant::now();
    let cube = CubeDem::open(&args[1])?;
    let open_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    cube.verify()?;
    println!(
        "opened in {open_s:.4} s, verified in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    let (lo, hi) = cube.height_bounds();
    println!(
        "height bounds {lo:.0} .. {hi:.0} m, data spacing {:.0} m at a face centre",
        cube.data_spacing()
    );
    println!("log2  samples/side  16-bit bytes    stored bytes  m/sample centre  m/sample equator");
    for row in cube.storage_table() {
        println!(
            "{:>4}  {:>12}  {:>13}  {:>14}  {:>15.2}  {:>16.2}",
            row.log2,
            row.samples_per_side,
            row.bytes_16bit,
            row.bytes_stored.map_or("noise".to_owned(), |b| b.to_string()),
            row.metres_at_centre,
            row.metres_at_equator
        );
    }
    let detail = DetailNoise::default();
    let count = 1_000_000;
    for interp in [Interpolation::Bilinear, Interpolation::Bicubic] {
        let t = Instant::now();
        let mut sum = 0.0;
        for k in 0..count {
            let lat = -89.0 + 178.0 * (f64::from(k) * 0.618_033_988_7).fract();
            let lon = -180.0 + 360.0 * (f64::from(k) * 0.754_877_666_2).fract();
            sum += cube.height(LatLon::new(lat, lon)?.to_unit(), interp, &detail, 1.0);
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / f64::from(count);
        println!(
            "height({interp:?}, detail to 1 m): {ns:.0} ns a call, one thread (mean {:.1} m)",
            sum / f64::from(count)
        );
    }
    Ok(())
}
