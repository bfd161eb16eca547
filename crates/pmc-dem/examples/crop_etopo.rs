//! Cuts a latitude/longitude window out of a netCDF classic ETOPO grid and writes it as a small
//! netCDF classic (CDF-1) file with ETOPO5's names, for test fixtures.
//!
//! ```text
//! cargo run --release -p pmc-dem --example crop_etopo -- IN.cdf OUT.cdf \
//!     --lat-min 26.5 --lat-max 29.5 --lon-min 85.5 --lon-max 88.5
//! ```
//!
//! The input is read with [`EquirectDem::read_netcdf`] (its only elevation variable). The window
//! is in degrees and inclusive: a sample is kept when its latitude and longitude (cell centre or
//! node, as the file's coordinate variables give them) lie within `[lat-min, lat-max]` and
//! `[lon-min, lon-max]`, up to a hundredth of a step. Longitudes are taken modulo 360, so a
//! window such as `--lon-min -7 --lon-max -4` can be cut from a grid stored over 0..360; `lon-min`
//! must not exceed `lon-max`, and the window must span less than a turn.
//!
//! The output holds:
//! - dimensions and coordinate variables `ETOPO05_X` (longitudes, float64, `degrees_east`,
//!   increasing west to east, in the window's convention: -7 .. -4 rather than 353 .. 356) and
//!   `ETOPO05_Y` (latitudes, float64, `degrees_north`, **decreasing, north to south**, as rows
//!   are stored in the ETOPO5 distribution);
//! - `ROSE(ETOPO05_Y, ETOPO05_X)`, float32 heights in metres, `units = "METERS"`, with
//!   `missing_value` and `_FillValue` both -1e34 (float32) where the input had no value;
//! - global attributes `source` (NOAA ETOPO5, public domain, and the window) and `history` (the
//!   input file's name).
//!
//! Coordinates are the reader's: `lat(row)` and `lon(col)`, computed from the grid's first value
//! and step, so a cut reads back with the same positions and bit-identical heights.

use netcdf3::{DataSet, FileWriter, Version};
use pmc_dem::EquirectDem;
use std::process::ExitCode;

const FILL: f32 = -1e34;

const USAGE: &str = "usage: crop_etopo IN.cdf OUT.cdf --lat-min DEG --lat-max DEG --lon-min DEG --lon-max DEG";

struct Window {
    lat_min: f64,
    lat_max: f64,
    lon_min: f64,
    lon_max: f64,
}

fn parse_args() -> Result<(String, String, Window), String> {
    let mut args = std::env::args().skip(1);
    let (Some(input), Some(output)) = (args.next(), args.next()) else {
        return Err(USAGE.to_owned());
    };
    let (mut lat_min, mut lat_max, mut lon_min, mut lon_max) = (None, None, None, None);
    while let Some(flag) = args.next() {
        let slot = match flag.as_str() {
            "--lat-min" => &mut lat_min,
            "--lat-max" => &mut lat_max,
            "--lon-min" => &mut lon_min,
            "--lon-max" => &mut lon_max,
            _ => return Err(format!("unknown argument {flag}\n{USAGE}")),
        };
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let value: f64 = value.parse().map_err(|_| format!("{flag}: not a number: {value}"))?;
        if !value.is_finite() {
            return Err(format!("{flag}: not a finite number: {value}"));
        }
        *slot = Some(value);
    }
    let (Some(lat_min), Some(lat_max), Some(lon_min), Some(lon_max)) = (lat_min, lat_max, lon_min, lon_max) else {
        return Err(format!("all four window bounds are needed\n{USAGE}"));
    };
    if lat_min > lat_max || lon_min > lon_max || lon_max - lon_min >= 360.0 {
        return Err("the window needs lat-min <= lat-max and lon-min <= lon-max < lon-min + 360".to_owned());
    }
    Ok((
        input,
        output,
        Window {
            lat_min,
            lat_max,
            lon_min,
            lon_max,
        },
    ))
}

fn main() -> ExitCode {
    let (input, output, win) = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let dem = match EquirectDem::read_netcdf(&input, None) {
        Ok(dem) => dem,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };

    // Rows inside the window, kept north to south.
    let lat_tol = dem.lat_step() * 0.01;
    let rows: Vec<usize> = (0..dem.height())
        .rev()
        .filter(|&r| (win.lat_min - lat_tol..=win.lat_max + lat_tol).contains(&dem.lat(r)))
        .collect();
    // Columns inside the window, each with its longitude moved into [lon-min, lon-min + 360),
    // sorted west to east.
    let lon_tol = dem.lon_step() * 0.01;
    let mut cols: Vec<(f64, usize)> = (0..dem.width())
        .map(|c| {
            let west = win.lon_min - lon_tol;
            let turns = ((dem.lon(c) - west) / 360.0).floor();
            // On a wrapping grid (step exactly 360 / width) count the columns of the shifted
            // longitude from the first, for the same rounding as `lon`.
            let lon = if dem.wraps_in_longitude() {
                dem.lon_first() + (c as f64 - turns * dem.width() as f64) * dem.lon_step()
            } else {
                dem.lon(c) - turns * 360.0
            };
            (lon, c)
        })
        .filter(|&(lon, _)| lon <= win.lon_max + lon_tol)
        .collect();
    cols.sort_by(|a, b| a.0.total_cmp(&b.0));
    if rows.is_empty() || cols.is_empty() {
        eprintln!("error: no sample of {input} lies in the window");
        return ExitCode::FAILURE;
    }

    let lons: Vec<f64> = cols.iter().map(|&(lon, _)| lon).collect();
    let lats: Vec<f64> = rows.iter().map(|&r| dem.lat(r)).collect();
    let rose: Vec<f32> = rows
        .iter()
        .flat_map(|&r| cols.iter().map(move |&(_, c)| (r, c)))
        .map(|(r, c)| dem.value(c, r).unwrap_or(FILL))
        .collect();

    let source = format!(
        "NOAA ETOPO5 5-minute gridded global relief (public domain), window latitudes {} .. {}, \
         longitudes {} .. {}",
        win.lat_min, win.lat_max, win.lon_min, win.lon_max
    );
    match write(&output, &source, &dem, &lons, &lats, &rose) {
        Ok(()) => {
            println!(
                "{output}: {} x {} samples, latitudes {} .. {} (north to south), longitudes {} .. {}",
                lons.len(),
                lats.len(),
                lats[0],
                lats[lats.len() - 1],
                lons[0],
                lons[lons.len() - 1]
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: writing {output}: {e}");
            ExitCode::FAILURE
        }
    }
}

fn write(
    output: &str,
    source: &str,
    dem: &EquirectDem,
    lons: &[f64],
    lats: &[f64],
    rose: &[f32],
) -> Result<(), String> {
    // netcdf3's errors implement `Debug` only.
    fn e(err: impl std::fmt::Debug) -> String {
        format!("{err:?}")
    }
    let (x, y) = ("ETOPO05_X", "ETOPO05_Y");
    let mut ds = DataSet::new();
    ds.add_fixed_dim(x, lons.len()).map_err(e)?;
    ds.add_fixed_dim(y, lats.len()).map_err(e)?;
    ds.add_var_f64(x, &[x]).map_err(e)?;
    ds.add_var_attr_string(x, "units", "degrees_east").map_err(e)?;
    ds.add_var_f64(y, &[y]).map_err(e)?;
    ds.add_var_attr_string(y, "units", "degrees_north").map_err(e)?;
    ds.add_var_f32("ROSE", &[y, x]).map_err(e)?;
    ds.add_var_attr_string("ROSE", "long_name", "Relief Of the Surface of the Earth")
        .map_err(e)?;
    ds.add_var_attr_string("ROSE", "units", "METERS").map_err(e)?;
    ds.add_var_attr_f32("ROSE", "missing_value", vec![FILL]).map_err(e)?;
    ds.add_var_attr_f32("ROSE", "_FillValue", vec![FILL]).map_err(e)?;
    ds.add_global_attr_string("source", source).map_err(e)?;
    ds.add_global_attr_string(
        "history",
        format!("cut from {} by pmc-dem's crop_etopo example", dem.source()),
    )
    .map_err(e)?;

    let mut w = FileWriter::open(output).map_err(e)?;
    w.set_def(&ds, Version::Classic, 0).map_err(e)?;
    w.write_var_f64(x, lons).map_err(e)?;
    w.write_var_f64(y, lats).map_err(e)?;
    w.write_var_f32("ROSE", rose).map_err(e)?;
    w.close().map_err(e)?;
    Ok(())
}
