//! Landmark fixtures cut from NOAA ETOPO5 (public domain) by the `crop_etopo` example; see
//! `tests/fixtures/landmarks/README.md` for their origin and the commands that made them.
//!
//! Each fixture is decoded twice: independently, with the `netcdf3` crate's `FileReader` alone
//! ([`Raw::read`]), and with [`EquirectDem::read_netcdf`]; the two must agree sample for sample.
//! The landmark heights (Everest's massif, the Challenger Deep, the Dead Sea, a coastline) are
//! then pinned from the independent decoding with [`extreme_cell`].

use pmc_dem::EquirectDem;
use std::path::PathBuf;

/// The fill value the fixtures are written with (`_FillValue` and `missing_value` of `ROSE`).
const FILL: f32 = -1e34;

/// Path of the landmark fixture `name` (for example `"everest.cdf"`).
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/landmarks")
        .join(name)
}

/// A landmark fixture decoded with `netcdf3::FileReader` only, without any of `pmc-dem`'s code:
/// the grid in the file's own order.
pub struct Raw {
    /// `ETOPO05_X`, degrees east, in file order.
    pub lon: Vec<f64>,
    /// `ETOPO05_Y`, degrees north, in file order.
    pub lat: Vec<f64>,
    /// `ROSE(ETOPO05_Y, ETOPO05_X)` in metres, row-major with the latitude outer, as stored;
    /// samples equal to the variable's `_FillValue` or `missing_value` are `NaN`.
    pub rose: Vec<f32>,
}

impl Raw {
    /// Decodes the fixture `name`, checking the layout `crop_etopo` writes: CDF-1, `ROSE` over
    /// (`ETOPO05_Y`, `ETOPO05_X`), float32 in `METERS` with -1e34 as fill and missing value.
    pub fn read(name: &str) -> Raw {
        let mut r = netcdf3::FileReader::open(fixture(name)).unwrap();
        assert_eq!(r.version(), netcdf3::Version::Classic, "{name}");
        let ds = r.data_set();
        assert_eq!(
            ds.get_var("ROSE").unwrap().dim_names(),
            ["ETOPO05_Y", "ETOPO05_X"],
            "{name}"
        );
        assert_eq!(ds.get_var_attr_as_string("ROSE", "units").as_deref(), Some("METERS"));
        assert_eq!(
            ds.get_var_attr_as_string("ETOPO05_X", "units").as_deref(),
            Some("degrees_east")
        );
        assert_eq!(
            ds.get_var_attr_as_string("ETOPO05_Y", "units").as_deref(),
            Some("degrees_north")
        );
        let source = ds.get_global_attr_as_string("source").unwrap();
        assert!(
            source.contains("NOAA ETOPO5") && source.contains("public domain"),
            "{source}"
        );
        let fills: Vec<f32> = ["_FillValue", "missing_value"]
            .iter()
            .map(|a| ds.get_var_attr_f32("ROSE", a).unwrap()[0])
            .collect();
        assert_eq!(fills, [FILL, FILL], "{name}");
        let lon = r.read_var_f64("ETOPO05_X").unwrap();
        let lat = r.read_var_f64("ETOPO05_Y").unwrap();
        let rose: Vec<f32> = r
            .read_var_f32("ROSE")
            .unwrap()
            .into_iter()
            .map(|v| if fills.contains(&v) { f32::NAN } else { v })
            .collect();
        assert_eq!(rose.len(), lon.len() * lat.len(), "{name}");
        Raw { lon, lat, rose }
    }

    /// The samples as `(lat, lon, height)`, in file order (north-west first, row by row).
    pub fn cells(&self) -> impl Iterator<Item = (f64, f64, f32)> + '_ {
        self.lat
            .iter()
            .flat_map(|&lat| self.lon.iter().map(move |&lon| (lat, lon)))
            .zip(&self.rose)
            .map(|((lat, lon), &v)| (lat, lon, v))
    }

    /// The height at the sample whose coordinates are within a millionth of a degree of `(lat,
    /// lon)`; `None` if there is no such sample. Panics if the sample is a fill value.
    pub fn at(&self, lat: f64, lon: f64) -> Option<f32> {
        let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
        let v = self.cells().find(|&(la, lo, _)| near(la, lat) && near(lo, lon))?.2;
        assert!(!v.is_nan(), "fill value at {lat} {lon}");
        Some(v)
    }
}

/// The extreme valid sample of `raw` among those for which `keep(lat, lon)` holds: the highest
/// when `highest`, else the lowest, as `(lat, lon, height)` with the coordinates of the file's
/// coordinate variables. Fill values (`NaN` in [`Raw`]) never count. Of equal heights the first
/// in file order (north-west first, row by row) wins. `None` if no valid sample is kept.
///
/// It works on the independent decoding ([`Raw::read`]), so a test that uses it checks
/// `pmc-dem` against values that `pmc-dem` did not produce.
pub fn extreme_cell(raw: &Raw, highest: bool, keep: impl Fn(f64, f64) -> bool) -> Option<(f64, f64, f32)> {
    raw.cells().filter(|&(lat, lon, v)| !v.is_nan() && keep(lat, lon)).fold(
        None,
        |best: Option<(f64, f64, f32)>, cell| match best {
            Some(b) if (highest && cell.2 <= b.2) || (!highest && cell.2 >= b.2) => Some(b),
            _ => Some(cell),
        },
    )
}

/// Whether `a` and `b` are the same longitude, up to a millionth of a degree, modulo 360.
fn same_lon(a: f64, b: f64) -> bool {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d) < 1e-6
}

/// Asserts that the cell `got` is `want`: the same height, and coordinates within a billionth
/// of a degree (the fixtures' coordinates are sums of 1/12-degree steps).
fn assert_cell(got: Option<(f64, f64, f32)>, want: (f64, f64, f32)) {
    let got = got.expect("no valid cell");
    assert!(
        (got.0 - want.0).abs() < 1e-9 && (got.1 - want.1).abs() < 1e-9 && got.2 == want.2,
        "{got:?} is not {want:?}"
    );
}

/// Reads `name` both ways and checks that they agree on the axes and, bit for bit, on every
/// height (`NaN` for fill). Returns the independent decoding.
fn both_agree(name: &str, size: (usize, usize)) -> Raw {
    let raw = Raw::read(name);
    let dem = EquirectDem::read_netcdf(fixture(name), None).unwrap();
    assert_eq!((dem.width(), dem.height()), size, "{name}");
    assert_eq!((raw.lon.len(), raw.lat.len()), size, "{name}");
    assert_eq!(dem.variable(), "ROSE");
    let (w, h) = size;
    // crop_etopo writes longitudes west to east and latitudes north to south.
    assert!(
        raw.lon.windows(2).all(|p| p[0] < p[1]),
        "{name}: longitudes not increasing"
    );
    assert!(
        raw.lat.windows(2).all(|p| p[0] > p[1]),
        "{name}: latitudes not decreasing"
    );
    for (i, &lat) in raw.lat.iter().enumerate() {
        let row = h - 1 - i;
        assert!(
            (dem.lat(row) - lat).abs() < 1e-9,
            "{name} row {row}: {} vs {lat}",
            dem.lat(row)
        );
        for (col, &lon) in raw.lon.iter().enumerate() {
            if i == 0 {
                assert!(
                    same_lon(dem.lon(col), lon),
                    "{name} col {col}: {} vs {lon}",
                    dem.lon(col)
                );
            }
            let want = raw.rose[i * w + col];
            let got = dem.heights()[row * w + col];
            assert_eq!(
                dem.value(col, row),
                (!want.is_nan()).then_some(want),
                "{name} ({col}, {row})"
            );
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "{name} ({col}, {row}): {got} vs {want}"
            );
        }
    }
    raw
}

#[test]
fn everest_highest_cell() {
    let raw = both_agree("everest.cdf", (37, 37));
    let top = extreme_cell(&raw, true, |_, _| true);
    assert!(top.is_some_and(|c| (6500.0..8000.0).contains(&c.2)), "{top:?}");
    // ETOPO5 smooths the Himalaya: its highest 5-minute cell here, 7010 m, lies west of Everest
    // (by the Langtang and Shishapangma ranges); the cell nearest the summit (27.988 N,
    // 86.925 E) holds 6096 m.
    assert_cell(top, (28.5, 85.0 + 7.0 / 12.0, 7010.0));
    assert_eq!(raw.at(28.0, 86.0 + 11.0 / 12.0), Some(6096.0));
}

#[test]
fn challenger_deepest_cell() {
    let raw = both_agree("challenger.cdf", (37, 37));
    let deep = extreme_cell(&raw, false, |_, _| true);
    assert!(deep.is_some_and(|c| (-11_000.0..-9_500.0).contains(&c.2)), "{deep:?}");
    assert_cell(deep, (11.0 + 1.0 / 3.0, 142.0 + 1.0 / 3.0, -10376.0));
}

#[test]
fn dead_sea_lowest_land_cell() {
    let raw = both_agree("dead_sea.cdf", (25, 25));
    // The window's western edge reaches the Mediterranean's sea floor (-998 m at 32.5 N,
    // 34.5 E); the Jordan rift, the Dead Sea in it, lies east of 35.2 E, away from the sea.
    let low = extreme_cell(&raw, false, |_, lon| lon > 35.2);
    assert!(low.is_some_and(|c| c.2 < 0.0), "{low:?}");
    // -637 m at several cells of the Dead Sea; this is the first from the north-west.
    assert_cell(low, (31.75, 35.0 + 5.0 / 12.0, -637.0));
    let sea = extreme_cell(&raw, false, |_, _| true);
    assert_cell(sea, (32.5, 34.5, -998.0));
}

#[test]
fn coast_has_a_sea_cell_next_to_land() {
    let raw = both_agree("coast.cdf", (37, 25));
    // The Spanish shore of the Strait of Gibraltar, east of Tarifa: land, then sea one cell
    // (5 minutes) east.
    let lat = 36.0 + 1.0 / 12.0;
    let land = raw.at(lat, -5.0 - 8.0 / 12.0).unwrap();
    let sea = raw.at(lat, -5.0 - 7.0 / 12.0).unwrap();
    assert!(land > 0.0 && sea < 0.0, "{land} {sea}");
    assert_eq!((land, sea), (137.0, -135.0));
    // The window reaches both the Atlantic's and the Mediterranean's floor and the Rif.
    assert_cell(
        extreme_cell(&raw, false, |_, _| true),
        (35.0 + 8.0 / 12.0, -4.25, -1490.0),
    );
    assert_cell(
        extreme_cell(&raw, true, |_, _| true),
        (35.0 + 2.0 / 12.0, -5.25, 1523.0),
    );
}
