//! Reading the ETOPO60 fixture (NOAA's one-degree global relief, netCDF classic), checked against
//! the file's raw contents read directly with the `netcdf3` crate, and bilinear sampling on it.

use pmc_dem::EquirectDem;
use std::path::PathBuf;

fn fixture() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf")
}

fn dem() -> EquirectDem {
    EquirectDem::read_netcdf(fixture(), None).unwrap()
}

/// The fixture's raw contents: longitudes, latitudes and heights (row-major, latitude outer).
struct Raw {
    lon: Vec<f64>,
    lat: Vec<f64>,
    rose: Vec<f32>,
}

fn raw() -> Raw {
    let mut r = netcdf3::FileReader::open(fixture()).unwrap();
    let ds = r.data_set();
    assert_eq!(ds.get_var("ROSE").unwrap().dim_names(), ["ETOPO60Y", "ETOPO60X"]);
    Raw {
        lon: r.read_var_f64("ETOPO60X").unwrap(),
        lat: r.read_var_f64("ETOPO60Y").unwrap(),
        rose: r.read_var_f32("ROSE").unwrap(),
    }
}

#[test]
fn grid_and_axes_are_those_of_the_file() {
    let raw = raw();
    let dem = dem();
    assert_eq!((dem.width(), dem.height()), (360, 180));
    assert_eq!((dem.source(), dem.variable()), ("etopo60.cdf", "ROSE"));
    // The file's cell centres: longitudes 20.5 .. 379.5, latitudes -89.5 .. 89.5.
    assert_eq!((raw.lon[0], raw.lon[359]), (20.5, 379.5));
    assert_eq!((raw.lat[0], raw.lat[179]), (-89.5, 89.5));
    assert_eq!((dem.lon_first(), dem.lon_step()), (20.5, 1.0));
    assert_eq!((dem.lat_first(), dem.lat_step()), (-89.5, 1.0));
    assert!(dem.wraps_in_longitude());
    for (col, &lon) in raw.lon.iter().enumerate() {
        assert_eq!(dem.lon(col), lon);
    }
    for (row, &lat) in raw.lat.iter().enumerate() {
        assert_eq!(dem.lat(row), lat);
    }
    // Latitudes increase in the file, so rows are stored as in the file.
    for row in 0..180 {
        for col in 0..360 {
            assert_eq!(dem.value(col, row), Some(raw.rose[row * 360 + col]));
        }
    }
    assert_eq!(dem.heights(), &raw.rose[..]);
    assert_eq!(dem.value(360, 0), None);
    assert_eq!(dem.value(0, 180), None);
}

#[test]
fn reading_a_path_or_bytes_gives_the_same_grid() {
    let bytes = std::fs::read(fixture()).unwrap();
    let from_bytes = EquirectDem::from_netcdf_bytes("etopo60.cdf", bytes, Some("ROSE")).unwrap();
    let from_path = dem();
    assert_eq!(format!("{from_bytes:?}"), format!("{from_path:?}"));
    assert_eq!(from_bytes.heights(), from_path.heights());
}

#[test]
fn extremes_match_a_scan_of_the_raw_array_and_lie_where_the_earth_has_them() {
    let raw = raw();
    let (mut min_i, mut max_i) = (0, 0);
    for (i, &v) in raw.rose.iter().enumerate() {
        if v < raw.rose[min_i] {
            min_i = i;
        }
        if v > raw.rose[max_i] {
            max_i = i;
        }
    }
    let place = |i: usize| (raw.lat[i / 360], raw.lon[i % 360]);

    let stats = dem().stats();
    let dem = dem();
    assert_eq!((stats.min, stats.max), (raw.rose[min_i], raw.rose[max_i]));
    assert_eq!((stats.valid, stats.missing), (64_800, 0));
    let at = |(col, row): (usize, usize)| (dem.lat(row), dem.lon(col));
    assert_eq!(at(stats.min_at), place(min_i));
    assert_eq!(at(stats.max_at), place(max_i));

    // The highest cell is in the Himalaya (25-40 N, 75-100 E)...
    let (lat, lon) = place(max_i);
    assert!(
        (25.0..=40.0).contains(&lat) && (75.0..=100.0).contains(&lon),
        "max at {lat}, {lon}"
    );
    assert!(stats.max > 5000.0);
    // ... and the deepest in the trenches of the western Pacific (Kuril to Kermadec).
    let (lat, lon) = place(min_i);
    assert!(
        (-40.0..=60.0).contains(&lat) && (120.0..=190.0).contains(&lon.rem_euclid(360.0)),
        "min at {lat}, {lon}"
    );
    assert!(stats.min < -7000.0);
}

#[test]
fn sampling_is_exact_at_every_sample_point() {
    let dem = dem();
    for row in 0..dem.height() {
        for col in 0..dem.width() {
            let want = Some(f64::from(dem.value(col, row).unwrap()));
            let (lat, lon) = (dem.lat(row), dem.lon(col));
            assert_eq!(dem.sample_bilinear(lat, lon), want, "({col}, {row})");
            // The same place with its longitude in [-180, 180).
            let lon = (lon + 180.0).rem_euclid(360.0) - 180.0;
            assert_eq!(dem.sample_bilinear(lat, lon), want, "({col}, {row}) at {lon}");
        }
    }
}

#[test]
fn sampling_between_samples_is_bilinear() {
    let dem = dem();
    let v = |c: usize, r: usize| f64::from(dem.value(c % 360, r).unwrap());
    for (col, row) in [(0, 0), (66, 118), (159, 90), (359, 100), (200, 178)] {
        // Halfway between four samples: their mean.
        let got = dem.sample_bilinear(dem.lat(row) + 0.5, dem.lon(col) + 0.5).unwrap();
        let mean = (v(col, row) + v(col + 1, row) + v(col, row + 1) + v(col + 1, row + 1)) / 4.0;
        assert!((got - mean).abs() < 1e-9, "({col}, {row}): {got} vs {mean}");
        // A quarter of the way east along a row.
        let got = dem.sample_bilinear(dem.lat(row), dem.lon(col) + 0.25).unwrap();
        let want = 0.75 * v(col, row) + 0.25 * v(col + 1, row);
        assert!((got - want).abs() < 1e-9, "({col}, {row}): {got} vs {want}");
    }
}

#[test]
fn sampling_is_continuous_across_the_antimeridian_and_periodic() {
    let dem = dem();
    let eps = 1e-9;
    for i in 0..=36 {
        let lat = -90.0 + 5.0 * f64::from(i);
        let west = dem.sample_bilinear(lat, 180.0 - eps).unwrap();
        let east = dem.sample_bilinear(lat, -180.0 + eps).unwrap();
        assert!((west - east).abs() < 1e-3, "lat {lat}: {west} vs {east}");
        for lon in [-179.99, -170.0, -0.3, 0.0, 19.9, 20.5, 20.7, 179.2, 359.9] {
            let a = dem.sample_bilinear(lat, lon).unwrap();
            for turns in [-2.0, -1.0, 1.0, 3.0] {
                let b = dem.sample_bilinear(lat, lon + 360.0 * turns).unwrap();
                assert!(
                    (a - b).abs() <= 1e-9 * a.abs().max(1.0),
                    "lat {lat} lon {lon}: {a} vs {b}"
                );
            }
        }
    }
    // The seam of the file's own columns (379.5 then 20.5, one degree apart) is interpolated too.
    let seam = dem.sample_bilinear(0.5, 20.0).unwrap();
    let (a, b) = (
        f64::from(dem.value(359, 90).unwrap()),
        f64::from(dem.value(0, 90).unwrap()),
    );
    assert!((seam - (a + b) / 2.0).abs() < 1e-9);
}

#[test]
fn latitudes_beyond_the_first_and_last_rows_are_clamped() {
    let dem = dem();
    for lon in [-120.0, 0.0, 45.25, 170.0] {
        let north = dem.sample_bilinear(89.5, lon);
        let south = dem.sample_bilinear(-89.5, lon);
        assert!(north.is_some() && south.is_some());
        for lat in [89.75, 90.0, 95.0, 1e9] {
            assert_eq!(dem.sample_bilinear(lat, lon), north);
            assert_eq!(dem.sample_bilinear(-lat, lon), south);
        }
    }
}

#[test]
fn non_finite_inputs_give_none() {
    let dem = dem();
    for (lat, lon) in [
        (f64::NAN, 0.0),
        (0.0, f64::NAN),
        (f64::INFINITY, 0.0),
        (0.0, f64::NEG_INFINITY),
    ] {
        assert_eq!(dem.sample_bilinear(lat, lon), None);
    }
}
