//! The windowed netCDF reader gives the whole-grid reader's rows, bit for bit.

use pmc_dem::{DemError, EquirectDem, EquirectSource, NetcdfSource};
use std::path::{Path, PathBuf};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf")
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn every_row_of_etopo60_equals_the_whole_grid_bit_for_bit() {
    let dem = EquirectDem::read_netcdf(fixture(), None).unwrap();
    let src = NetcdfSource::open(fixture(), None).unwrap();
    assert_eq!((src.width(), src.height()), (360, 180));
    assert_eq!(
        (src.lon_first(), src.lon_step(), src.lat_first(), src.lat_step()),
        (20.5, 1.0, -89.5, 1.0)
    );
    assert!(src.wraps_in_longitude());
    assert_eq!((src.name(), src.variable()), ("etopo60.cdf", "ROSE"));
    let w = dem.width();
    // Single rows, then bands of several sizes, then the whole grid at once.
    for band in [1usize, 7, 64, 180] {
        let mut row0 = 0;
        while row0 < dem.height() {
            let rows = band.min(dem.height() - row0);
            let mut out = vec![f32::NAN; rows * w];
            src.read_rows(row0, rows, &mut out).unwrap();
            assert_eq!(
                bits(&out),
                bits(&dem.heights()[row0 * w..(row0 + rows) * w]),
                "rows {row0}+{rows}"
            );
            row0 += rows;
        }
    }
    let from_bytes = NetcdfSource::from_bytes("etopo60.cdf", std::fs::read(fixture()).unwrap(), Some("ROSE")).unwrap();
    let mut out = vec![0.0; 2 * w];
    from_bytes.read_rows(178, 2, &mut out).unwrap();
    assert_eq!(bits(&out), bits(&dem.heights()[178 * w..]));
}

#[test]
fn requests_outside_the_grid_or_with_the_wrong_buffer_are_errors() {
    let src = NetcdfSource::open(fixture(), None).unwrap();
    let mut out = vec![0.0; 2 * 360];
    for (row0, rows) in [(179, 2), (usize::MAX, 2), (0, 1), (0, usize::MAX)] {
        let e = src.read_rows(row0, rows, &mut out).unwrap_err();
        assert!(matches!(e, DemError::OutOfGrid { .. }), "{e}");
        assert!(e.to_string().contains("etopo60.cdf"));
    }
    src.read_rows(180, 0, &mut []).unwrap();
}

#[test]
fn a_file_cut_short_after_opening_is_an_error_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("pmc-dem-source-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("shrinking.cdf");
    std::fs::copy(fixture(), &path).unwrap();
    let src = NetcdfSource::open(&path, None).unwrap();
    let f = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
    f.set_len(10_000).unwrap();
    let mut out = vec![0.0; 360];
    let e = src.read_rows(179, 1, &mut out).unwrap_err();
    assert!(matches!(e, DemError::Io { .. }), "{e}");
    assert_eq!(e.file(), path.display().to_string());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damaged_file_is_refused_at_opening_with_the_whole_grid_readers_error() {
    let mut bytes = std::fs::read(fixture()).unwrap();
    bytes.truncate(bytes.len() - 1);
    let e = NetcdfSource::from_bytes("cut.cdf", bytes, None).unwrap_err();
    assert!(matches!(e, DemError::Truncated { .. }), "{e}");
    let e = NetcdfSource::open(Path::new("/nonexistent/etopo.cdf"), None).unwrap_err();
    assert!(matches!(e, DemError::Io { .. }));
}
