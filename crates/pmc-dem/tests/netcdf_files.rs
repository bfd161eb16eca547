//! Files that are not clean ETOPO grids: foreign or damaged files, and netCDF files written here
//! with the `netcdf3` crate to exercise each layout and each refusal. Every refusal is checked
//! for its variant and for naming the file.

use netcdf3::{DataSet, DataVector, FileWriter, Version};
use pmc_dem::{DemError, EquirectDem, EquirectSource, NetcdfSource, MAX_CELLS, MAX_HEADER_BYTES};
use std::path::{Path, PathBuf};

const FILL: f32 = -1e34;

fn fixture_bytes() -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf")).unwrap()
}

/// A fresh, empty directory for one test.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-dem-test-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Reads `path`, expecting a refusal whose message names the file.
fn refusal(path: &Path, variable: Option<&str>) -> DemError {
    let e = EquirectDem::read_netcdf(path, variable).unwrap_err();
    let shown = path.display().to_string();
    assert!(e.to_string().contains(&shown), "message does not name {shown}: {e}");
    assert_eq!(e.file(), shown);
    e
}

/// Reads `bytes` under `name`, expecting a refusal whose message names it.
fn refusal_of_bytes(name: &str, bytes: Vec<u8>, variable: Option<&str>) -> DemError {
    let e = EquirectDem::from_netcdf_bytes(name, bytes, variable).unwrap_err();
    assert!(e.to_string().contains(name), "message does not name {name}: {e}");
    e
}

/// Checks that every row read through `src`, one band of three rows at a time, is bit for bit
/// the grid `dem`, with the same axes.
fn same_rows(dem: &EquirectDem, src: &NetcdfSource) {
    assert_eq!((src.width(), src.height()), (dem.width(), dem.height()));
    assert_eq!((src.lon_first(), src.lon_step()), (dem.lon_first(), dem.lon_step()));
    assert_eq!((src.lat_first(), src.lat_step()), (dem.lat_first(), dem.lat_step()));
    assert_eq!(src.wraps_in_longitude(), dem.wraps_in_longitude());
    assert_eq!(src.variable(), dem.variable());
    let w = dem.width();
    let mut row0 = 0;
    while row0 < dem.height() {
        let rows = 3.min(dem.height() - row0);
        let mut band = vec![0.0f32; rows * w];
        src.read_rows(row0, rows, &mut band).unwrap();
        let want = &dem.heights()[row0 * w..(row0 + rows) * w];
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&band), bits(want), "rows {row0}..{}", row0 + rows);
        row0 += rows;
    }
}

/// Reads `path` whole, and checks that [`NetcdfSource`] reads the same rows.
fn read_both(path: impl AsRef<Path>, variable: Option<&str>) -> EquirectDem {
    let dem = EquirectDem::read_netcdf(path.as_ref(), variable).unwrap();
    same_rows(&dem, &NetcdfSource::open(path.as_ref(), variable).unwrap());
    dem
}

/// Reads `bytes` whole, and checks that [`NetcdfSource`] reads the same rows.
fn both_from_bytes(name: &str, bytes: Vec<u8>, variable: Option<&str>) -> EquirectDem {
    let dem = EquirectDem::from_netcdf_bytes(name, bytes.clone(), variable).unwrap();
    same_rows(&dem, &NetcdfSource::from_bytes(name, bytes, variable).unwrap());
    dem
}

/// A netCDF data set to write, with its data.
struct Nc {
    ds: DataSet,
    data: Vec<(String, DataVector)>,
}

impl Nc {
    fn new() -> Nc {
        Nc {
            ds: DataSet::new(),
            data: Vec::new(),
        }
    }

    fn dim(mut self, name: &str, size: usize) -> Nc {
        self.ds.add_fixed_dim(name, size).unwrap();
        self
    }

    fn var(mut self, name: &str, dims: &[&str], data: DataVector) -> Nc {
        self.ds.add_var(name, dims, data.data_type()).unwrap();
        self.data.push((name.to_owned(), data));
        self
    }

    fn text(mut self, var: &str, attr: &str, value: &str) -> Nc {
        self.ds.add_var_attr_string(var, attr, value).unwrap();
        self
    }

    fn f32_attr(mut self, var: &str, attr: &str, value: f32) -> Nc {
        self.ds.add_var_attr_f32(var, attr, vec![value]).unwrap();
        self
    }

    fn f64_attr(mut self, var: &str, attr: &str, value: f64) -> Nc {
        self.ds.add_var_attr_f64(var, attr, vec![value]).unwrap();
        self
    }

    fn i16_attr(mut self, var: &str, attr: &str, value: i16) -> Nc {
        self.ds.add_var_attr_i16(var, attr, vec![value]).unwrap();
        self
    }

    /// Writes the file `name` in a fresh directory for `test`; returns its path.
    fn write_as(&self, test: &str, name: &str, version: Version) -> PathBuf {
        let path = dir(test).join(name);
        let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
        let mut w = FileWriter::open_seek_write(name, Box::new(file)).unwrap();
        w.set_def(&self.ds, version, 0).unwrap();
        for (name, data) in &self.data {
            match data {
                DataVector::I8(v) => w.write_var_i8(name, v),
                DataVector::U8(v) => w.write_var_u8(name, v),
                DataVector::I16(v) => w.write_var_i16(name, v),
                DataVector::I32(v) => w.write_var_i32(name, v),
                DataVector::F32(v) => w.write_var_f32(name, v),
                DataVector::F64(v) => w.write_var_f64(name, v),
            }
            .unwrap();
        }
        w.close().unwrap();
        path
    }

    fn write(&self, test: &str) -> PathBuf {
        self.write_as(test, "grid.nc", Version::Classic)
    }
}

fn steps(first: f64, step: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| first + step * i as f64).collect()
}

/// A grid `z(lat, lon)` in the usual CF layout, with `_FillValue` -1e34.
fn grid(lon: Vec<f64>, lat: Vec<f64>, z: Vec<f32>) -> Nc {
    Nc::new()
        .dim("lon", lon.len())
        .dim("lat", lat.len())
        .var("lon", &["lon"], DataVector::F64(lon))
        .text("lon", "units", "degrees_east")
        .var("lat", &["lat"], DataVector::F64(lat))
        .text("lat", "units", "degrees_north")
        .var("z", &["lat", "lon"], DataVector::F32(z))
        .f32_attr("z", "_FillValue", FILL)
}

/// Heights `100 * row + col` for a file of `width` x `height`.
fn ramp(width: usize, height: usize) -> Vec<f32> {
    (0..height)
        .flat_map(|r| (0..width).map(move |c| (100 * r + c) as f32))
        .collect()
}

// ------------------------------------------------------------------------------------------------
// Files that are not netCDF, or not whole

#[test]
fn a_missing_file_or_a_directory_is_an_io_error() {
    let d = dir("missing");
    assert!(matches!(refusal(&d.join("nowhere.cdf"), None), DemError::Io { .. }));
    assert!(matches!(refusal(&d, None), DemError::Io { .. }));
}

#[test]
fn an_empty_file_is_not_netcdf() {
    let p = dir("empty").join("empty.cdf");
    std::fs::write(&p, b"").unwrap();
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::NotNetcdf { detail, .. } if detail.contains("empty")),
        "{e}"
    );
    assert!(matches!(
        refusal_of_bytes("empty.cdf", Vec::new(), None),
        DemError::NotNetcdf { .. }
    ));
}

#[test]
fn random_bytes_text_and_images_are_not_netcdf() {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let random: Vec<u8> = (0..4096)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u8
        })
        .collect();
    let png = [b"\x89PNG\r\n\x1a\n".as_slice(), &[0, 0, 0, 13], b"IHDR", &[0; 17]].concat();
    let d = dir("foreign");
    for (name, bytes) in [
        ("random.bin", random),
        ("notes.txt", b"ETOPO60 heights, see README\n".to_vec()),
        ("image.png", png),
        ("hdf5.nc", b"\x89HDF\r\n\x1a\n\0\0\0\0\0\0\0\0".to_vec()),
        ("cdf5.nc", b"CDF\x05\0\0\0\0\0\0\0\0".to_vec()),
    ] {
        let p = d.join(name);
        std::fs::write(&p, &bytes).unwrap();
        let e = refusal(&p, None);
        assert!(matches!(e, DemError::NotNetcdf { .. }), "{name}: {e}");
        assert!(matches!(
            refusal_of_bytes(name, bytes, None),
            DemError::NotNetcdf { .. }
        ));
    }
}

#[test]
fn a_truncated_fixture_is_refused_as_truncated() {
    let bytes = fixture_bytes();
    let len = bytes.len();
    let header = 568; // where the data begin
    let d = dir("truncated");
    for cut in [
        2,
        4,
        10,
        100,
        header - 1,
        header,
        header + 1000,
        len / 2,
        len - 4,
        len - 1,
    ] {
        let p = d.join(format!("etopo60-{cut}.cdf"));
        std::fs::write(&p, &bytes[..cut]).unwrap();
        match refusal(&p, None) {
            DemError::Truncated { expected, actual, .. } => {
                assert_eq!(actual, cut as u64);
                assert!(
                    expected > actual && expected <= len as u64,
                    "cut {cut}: expected {expected}"
                );
            }
            e => panic!("cut at {cut}: {e}"),
        }
        let name = format!("cut-{cut}");
        let e = refusal_of_bytes(&name, bytes[..cut].to_vec(), None);
        assert!(matches!(e, DemError::Truncated { .. }), "{e}");
    }
}

#[test]
fn damaged_header_counts_and_offsets_are_refused_without_reserving_memory() {
    let bytes = fixture_bytes();
    // Bytes 12..16 count the dimensions.
    for count in [0x7FFF_FFFFu32, 0x00FF_FFFF] {
        let mut b = bytes.clone();
        b[12..16].copy_from_slice(&count.to_be_bytes());
        assert!(matches!(refusal_of_bytes("dims", b, None), DemError::Truncated { .. }));
    }
    let mut b = bytes.clone();
    b[12..16].copy_from_slice(&[0xFF; 4]);
    assert!(matches!(
        refusal_of_bytes("negative", b, None),
        DemError::Corrupt { .. }
    ));
    // The last four bytes of the header are ROSE's data offset.
    let mut b = bytes.clone();
    b[564..568].copy_from_slice(&(-8i32).to_be_bytes());
    assert!(matches!(refusal_of_bytes("offset", b, None), DemError::Corrupt { .. }));
    let mut b = bytes.clone();
    b[564..568].copy_from_slice(&100_000_000i32.to_be_bytes());
    assert!(matches!(refusal_of_bytes("far", b, None), DemError::Truncated { .. }));
}

// ------------------------------------------------------------------------------------------------
// Choosing the variable and its axes

#[test]
fn a_file_without_a_grid_lists_its_variables() {
    let p = Nc::new()
        .dim("lon", 3)
        .var("lon", &["lon"], DataVector::F64(vec![0.0, 1.0, 2.0]))
        .var("depth", &["lon"], DataVector::F32(vec![1.0, 2.0, 3.0]))
        .write("no-grid");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::NoGridVariable { variables, .. } if variables.len() == 2),
        "{e}"
    );
    assert!(e.to_string().contains("depth(lon) float"), "{e}");
}

#[test]
fn a_named_variable_must_exist_and_be_a_grid() {
    let p = grid(steps(0.0, 1.0, 4), steps(0.0, 1.0, 3), ramp(4, 3)).write("named");
    let e = refusal(&p, Some("elevation"));
    assert!(
        matches!(&e, DemError::VariableNotFound { name, .. } if name == "elevation"),
        "{e}"
    );
    assert!(e.to_string().contains("z(lat, lon) float"), "{e}");
    assert!(matches!(refusal(&p, Some("lat")), DemError::UnsuitableVariable { .. }));
    assert_eq!(read_both(&p, Some("z")).width(), 4);
}

#[test]
fn several_candidate_grids_must_be_named() {
    let p = grid(steps(0.0, 1.0, 4), steps(0.0, 1.0, 3), ramp(4, 3))
        .var("slope", &["lat", "lon"], DataVector::F32(vec![0.5; 12]))
        .write("ambiguous");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::AmbiguousVariable { candidates, .. } if candidates.len() == 2),
        "{e}"
    );
    let slope = read_both(&p, Some("slope"));
    assert_eq!(slope.value(3, 2), Some(0.5));
}

#[test]
fn a_dimension_without_coordinates_is_a_missing_axis() {
    let p = Nc::new()
        .dim("lon", 4)
        .dim("lat", 3)
        .var("lon", &["lon"], DataVector::F64(steps(0.0, 1.0, 4)))
        .var("z", &["lat", "lon"], DataVector::F32(ramp(4, 3)))
        .write("no-axis");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::MissingAxis { dimension, .. } if dimension == "lat"),
        "{e}"
    );
}

#[test]
fn axes_are_told_apart_by_units_then_attributes_then_names_then_order() {
    // Transposed storage z(lon, lat), identified by units.
    let (lon, lat) = (steps(10.0, 2.0, 4), steps(-5.0, 5.0, 3));
    let z_lon_lat: Vec<f32> = (0..4).flat_map(|c| (0..3).map(move |r| (100 * r + c) as f32)).collect();
    let p = Nc::new()
        .dim("a", 4)
        .dim("b", 3)
        .var("a", &["a"], DataVector::F64(lon.clone()))
        .text("a", "units", "degree_E")
        .var("b", &["b"], DataVector::F64(lat.clone()))
        .text("b", "units", "degrees_north")
        .var("z", &["a", "b"], DataVector::F32(z_lon_lat.clone()))
        .write("transposed");
    let dem = read_both(&p, None);
    assert_eq!((dem.width(), dem.height(), dem.lon(1), dem.lat(1)), (4, 3, 12.0, 0.0));
    assert_eq!(dem.heights(), &ramp(4, 3)[..]);

    // By the CF `axis` attribute.
    let p = Nc::new()
        .dim("a", 4)
        .dim("b", 3)
        .var("a", &["a"], DataVector::F64(lon.clone()))
        .text("a", "axis", "X")
        .var("b", &["b"], DataVector::F64(lat.clone()))
        .var("z", &["a", "b"], DataVector::F32(z_lon_lat))
        .write("axis-attribute");
    assert_eq!(read_both(&p, None).heights(), &ramp(4, 3)[..]);

    // By name, with coordinate variables named otherwise than their dimensions.
    let p = Nc::new()
        .dim("i", 3)
        .dim("j", 4)
        .var("latitude", &["i"], DataVector::F64(lat.clone()))
        .var("longitude", &["j"], DataVector::F64(lon.clone()))
        .var("z", &["i", "j"], DataVector::F32(ramp(4, 3)))
        .write("names");
    let dem = read_both(&p, None);
    assert_eq!((dem.lon(3), dem.lat(2)), (16.0, 5.0));

    // Nothing to go by: the last dimension is the longitude.
    let p = Nc::new()
        .dim("p", 3)
        .dim("q", 4)
        .var("p", &["p"], DataVector::F64(lat))
        .var("q", &["q"], DataVector::F64(lon))
        .var("z", &["p", "q"], DataVector::F32(ramp(4, 3)))
        .write("order");
    let dem = read_both(&p, None);
    assert_eq!((dem.width(), dem.lon(3), dem.lat(2)), (4, 16.0, 5.0));
}

// ------------------------------------------------------------------------------------------------
// Axes

#[test]
fn a_non_monotonic_or_uneven_axis_is_refused() {
    let mut lon = steps(0.0, 1.0, 5);
    lon.swap(2, 3);
    let p = grid(lon, steps(0.0, 1.0, 3), ramp(5, 3)).write("non-monotonic");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::AxisNotMonotonic { axis, index: 3, .. } if axis == "longitude (lon)"),
        "{e}"
    );

    let lat = vec![0.0, 1.0, 2.5, 3.0];
    let p = grid(steps(0.0, 1.0, 5), lat, ramp(5, 4)).write("uneven");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::AxisUneven { axis, index: 2, .. } if axis == "latitude (lat)"),
        "{e}"
    );

    // A millionth of a step is tolerated; a ten-thousandth is not.
    let mut lat = steps(0.0, 1.0, 4);
    lat[1] += 5e-7;
    assert!(EquirectDem::read_netcdf(
        grid(steps(0.0, 1.0, 5), lat.clone(), ramp(5, 4)).write("tolerated"),
        None
    )
    .is_ok());
    lat[1] += 1e-4;
    let e = refusal(&grid(steps(0.0, 1.0, 5), lat, ramp(5, 4)).write("intolerable"), None);
    assert!(matches!(e, DemError::AxisUneven { .. }));
}

#[test]
fn unusable_axes_are_refused() {
    let p = grid(vec![0.0, f64::NAN, 2.0], steps(0.0, 1.0, 2), ramp(3, 2)).write("nan-axis");
    assert!(matches!(refusal(&p, None), DemError::AxisInvalid { .. }));
    let p = grid(vec![5.0], steps(0.0, 1.0, 2), ramp(1, 2)).write("single-column");
    assert!(matches!(refusal(&p, None), DemError::AxisInvalid { .. }));
    let p = grid(steps(0.0, 1.0, 400), steps(0.0, 1.0, 2), ramp(400, 2)).write("overlap");
    let e = refusal(&p, None);
    assert!(
        matches!(&e, DemError::AxisInvalid { detail, .. } if detail.contains("360")),
        "{e}"
    );
}

#[test]
fn latitudes_outside_the_globe_are_refused() {
    let p = grid(steps(0.0, 1.0, 3), steps(-91.0, 1.0, 3), ramp(3, 3)).write("south-of-pole");
    assert!(matches!(refusal(&p, None), DemError::LatitudeOutOfRange { value, .. } if value == -91.0));
    let p = grid(steps(0.0, 1.0, 3), steps(0.0, 50.0, 3), ramp(3, 3)).write("north-of-pole");
    assert!(matches!(refusal(&p, None), DemError::LatitudeOutOfRange { value, .. } if value == 100.0));
}

#[test]
fn descending_latitudes_are_stored_south_first() {
    let lat = steps(45.0, -45.0, 3); // 45, 0, -45
    let p = grid(steps(0.0, 90.0, 4), lat, ramp(4, 3)).write("descending");
    let dem = read_both(&p, None);
    assert_eq!((dem.lat_first(), dem.lat_step()), (-45.0, 45.0));
    // The file's last row (at -45) is row 0.
    for col in 0..4 {
        assert_eq!(dem.value(col, 0), Some((200 + col) as f32));
        assert_eq!(dem.value(col, 2), Some(col as f32));
    }
    assert_eq!(dem.sample_bilinear(45.0, 90.0), Some(1.0));
    assert_eq!(dem.sample_bilinear(-22.5, 0.0), Some(150.0));
}

#[test]
fn descending_longitudes_are_stored_west_first() {
    let p = grid(steps(270.0, -90.0, 4), steps(0.0, 1.0, 2), ramp(4, 2)).write("descending-lon");
    let dem = read_both(&p, None);
    assert_eq!(
        (dem.lon_first(), dem.lon_step(), dem.wraps_in_longitude()),
        (0.0, 90.0, true)
    );
    assert_eq!(dem.value(0, 1), Some(103.0));
    assert_eq!(dem.sample_bilinear(1.0, 270.0), Some(100.0));
}

#[test]
fn a_last_column_repeating_the_first_is_dropped() {
    // Columns at 20, 110, 200, 290 and 380 (the first again), as in ETOPO20.
    let z: Vec<f32> = (0..3)
        .flat_map(|r| (0..5).map(move |c| (100 * r + c % 4) as f32))
        .collect();
    let p = grid(steps(20.0, 90.0, 5), steps(-45.0, 45.0, 3), z).write("repeated");
    let dem = read_both(&p, None);
    assert_eq!((dem.width(), dem.lon_first(), dem.lon_step()), (4, 20.0, 90.0));
    assert!(dem.wraps_in_longitude());
    assert_eq!(dem.heights(), &ramp(4, 3)[..]);
    // Between the last column and the first, across the seam.
    assert_eq!(dem.sample_bilinear(0.0, 335.0), Some(101.5));
}

#[test]
fn regional_grids_do_not_wrap_and_longitudes_are_normalised() {
    let p = grid(steps(190.0, 10.0, 4), steps(0.0, 10.0, 2), ramp(4, 2)).write("regional");
    let dem = read_both(&p, None);
    assert_eq!((dem.lon_first(), dem.wraps_in_longitude()), (-170.0, false));
    assert_eq!(dem.sample_bilinear(0.0, 195.0), Some(0.5));
    assert_eq!(dem.sample_bilinear(0.0, -165.0), Some(0.5));
    assert_eq!(dem.sample_bilinear(0.0, 225.0), None);
    assert_eq!(dem.sample_bilinear(0.0, 185.0), None);
}

// ------------------------------------------------------------------------------------------------
// Values

#[test]
fn a_grid_of_fill_values_or_nan_has_no_valid_data() {
    let p = grid(steps(0.0, 1.0, 3), steps(0.0, 1.0, 2), vec![FILL; 6]).write("all-fill");
    assert!(matches!(refusal(&p, None), DemError::NoValidData { .. }));
    let p = grid(steps(0.0, 1.0, 3), steps(0.0, 1.0, 2), vec![f32::NAN; 6]).write("all-nan");
    assert!(matches!(refusal(&p, None), DemError::NoValidData { .. }));
}

#[test]
fn fill_values_and_nan_mixed_in_are_missing_samples() {
    let mut z = ramp(4, 3);
    z[1] = f32::NAN;
    z[6] = FILL;
    z[11] = f32::INFINITY;
    let p = grid(steps(0.0, 90.0, 4), steps(-45.0, 45.0, 3), z)
        .f32_attr("z", "missing_value", -999.0)
        .write("mixed");
    let dem = read_both(&p, None);
    assert_eq!((dem.value(1, 0), dem.value(2, 1), dem.value(3, 2)), (None, None, None));
    assert_eq!(dem.value(0, 0), Some(0.0));
    let stats = dem.stats();
    assert_eq!(
        (stats.missing, stats.valid, stats.max, stats.max_at),
        (3, 9, 202.0, (2, 2))
    );
    // Sampling needs every sample it weighs.
    assert_eq!(dem.sample_bilinear(-45.0, 45.0), None);
    assert_eq!(dem.sample_bilinear(-45.0, 0.0), Some(0.0));
    assert_eq!(dem.sample_bilinear(0.0, 45.0), Some(100.5));
}

#[test]
fn packed_integers_are_scaled_and_their_fill_value_is_missing() {
    let raw: Vec<i16> = vec![0, 1, 2, -32767, 10, 11, 12, 13];
    let p = Nc::new()
        .dim("lon", 4)
        .dim("lat", 2)
        .var("lon", &["lon"], DataVector::F32(vec![0.0, 90.0, 180.0, 270.0]))
        .text("lon", "units", "degrees_east")
        .var("lat", &["lat"], DataVector::F32(vec![-10.0, 10.0]))
        .text("lat", "units", "degrees_north")
        .var("h", &["lat", "lon"], DataVector::I16(raw))
        .f64_attr("h", "scale_factor", 0.5)
        .f64_attr("h", "add_offset", -100.0)
        .i16_attr("h", "_FillValue", -32767)
        .write("packed");
    // netcdf3 0.6 pads a 2-byte attribute value with fill bytes where the format (and its own
    // reader) wants zeros: zero them, as other writers do.
    let mut bytes = std::fs::read(&p).unwrap();
    let attr = [b"\0\0\0\x0a_FillValue\0\0\0\0\0\x03\0\0\0\x01\x80\x01".as_slice()].concat();
    let at = bytes.windows(attr.len()).position(|w| w == attr).unwrap() + attr.len();
    bytes[at..at + 2].fill(0);
    let dem = both_from_bytes("packed.nc", bytes, None);
    assert_eq!(dem.heights()[..3], [-100.0, -99.5, -99.0]);
    assert_eq!(dem.value(3, 0), None);
    assert_eq!(dem.value(3, 1), Some(-93.5));
}

#[test]
fn without_fill_attributes_the_netcdf_default_fill_is_missing() {
    let p = Nc::new()
        .dim("lon", 3)
        .dim("lat", 2)
        .var("lon", &["lon"], DataVector::F64(steps(0.0, 1.0, 3)))
        .var("lat", &["lat"], DataVector::F64(steps(0.0, 1.0, 2)))
        .var(
            "z",
            &["lat", "lon"],
            DataVector::F32(vec![1.0, netcdf3::NC_FILL_F32, 3.0, 4.0, 5.0, 6.0]),
        )
        .write("default-fill");
    let dem = read_both(&p, None);
    assert_eq!((dem.value(1, 0), dem.stats().missing), (None, 1));
}

#[test]
fn sixty_four_bit_offset_files_read_like_classic_ones() {
    let nc = grid(steps(0.0, 90.0, 4), steps(-45.0, 45.0, 3), ramp(4, 3));
    let classic = read_both(nc.write_as("cdf1", "a.nc", Version::Classic), None);
    let cdf2 = read_both(nc.write_as("cdf2", "a.nc", Version::Offset64Bit), None);
    assert_eq!(classic.heights(), cdf2.heights());
    assert_eq!(format!("{classic:?}"), format!("{cdf2:?}"));
}

#[test]
fn latitudes_along_the_record_dimension_read_like_fixed_ones() {
    let mut nc = Nc::new();
    nc.ds.set_unlimited_dim("lat", 3).unwrap();
    let nc = nc
        .dim("lon", 4)
        .var("lat", &["lat"], DataVector::F64(steps(-45.0, 45.0, 3)))
        .text("lat", "units", "degrees_north")
        .var("lon", &["lon"], DataVector::F64(steps(0.0, 90.0, 4)))
        .text("lon", "units", "degrees_east")
        .var("z", &["lat", "lon"], DataVector::F32(ramp(4, 3)));
    let mut bytes = std::fs::read(nc.write("records")).unwrap();
    let dem = both_from_bytes("records.nc", bytes.clone(), None);
    assert_eq!((dem.lat(2), dem.heights()), (45.0, &ramp(4, 3)[..]));
    // The number of records left to be computed from the file size (a streamed file).
    bytes[4..8].copy_from_slice(&u32::MAX.to_be_bytes());
    let dem = both_from_bytes("streamed.nc", bytes.clone(), None);
    assert_eq!(dem.heights(), &ramp(4, 3)[..]);
    // Records cut short.
    bytes[4..8].copy_from_slice(&3u32.to_be_bytes());
    bytes.truncate(bytes.len() - 8);
    assert!(matches!(
        refusal_of_bytes("cut.nc", bytes, None),
        DemError::Truncated { .. }
    ));
}

// ------------------------------------------------------------------------------------------------
// Sizes

/// The header offset of the size of dimension `name` (stored as length, name padded to 4, size).
fn dim_size_offset(bytes: &[u8], name: &str) -> usize {
    let mut pattern = (name.len() as u32).to_be_bytes().to_vec();
    pattern.extend_from_slice(name.as_bytes());
    pattern.resize(4 + name.len().div_ceil(4) * 4, 0);
    let at = bytes.windows(pattern.len()).position(|w| w == pattern).unwrap();
    at + pattern.len()
}

#[test]
fn a_grid_too_large_is_refused_before_reading() {
    let p = grid(steps(0.0, 90.0, 4), steps(-45.0, 45.0, 3), ramp(4, 3)).write("too-large");
    let mut bytes = std::fs::read(&p).unwrap();
    for (dim, size) in [("lon", 65_536u32), ("lat", 32_769)] {
        let at = dim_size_offset(&bytes, dim);
        bytes[at..at + 4].copy_from_slice(&size.to_be_bytes());
    }
    let e = refusal_of_bytes("huge.nc", bytes.clone(), None);
    assert!(
        matches!(e, DemError::TooLarge { width: 65_536, height: 32_769, limit, .. } if limit == MAX_CELLS),
        "{e}"
    );
    // Just within the limit, the declared data no longer fit in the file.
    let at = dim_size_offset(&bytes, "lat");
    bytes[at..at + 4].copy_from_slice(&32_768u32.to_be_bytes());
    let e = refusal_of_bytes("large.nc", bytes, None);
    assert!(matches!(e, DemError::Truncated { .. }), "{e}");
}

#[test]
fn the_fixture_with_dimensions_larger_than_its_data_is_truncated() {
    let mut bytes = fixture_bytes();
    let at = dim_size_offset(&bytes, "ETOPO60Y");
    bytes[at..at + 4].copy_from_slice(&181u32.to_be_bytes());
    let e = refusal_of_bytes("etopo60.cdf", bytes, None);
    assert!(matches!(e, DemError::Truncated { .. }), "{e}");
}

#[test]
fn a_huge_header_is_refused_before_it_is_decoded() {
    let history = |bytes: usize| {
        let mut nc = grid(steps(0.0, 90.0, 4), steps(-45.0, 45.0, 3), ramp(4, 3));
        nc.ds.add_global_attr_string("history", "x".repeat(bytes)).unwrap();
        nc
    };
    let p = history(MAX_HEADER_BYTES as usize).write("huge-header");
    let e = refusal(&p, None);
    assert!(
        matches!(e, DemError::HeaderTooLarge { size, limit, .. } if limit == MAX_HEADER_BYTES && size > limit),
        "{e}"
    );
    // A long history within the limit is read.
    let p = history(100_000).write("long-history");
    assert_eq!(read_both(&p, None).heights(), &ramp(4, 3)[..]);
    for test in ["huge-header", "long-history"] {
        std::fs::remove_dir_all(dir(test)).unwrap();
    }
}
