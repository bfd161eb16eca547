//! The data kept (`.pmcdem` version 2): at every sample of the source grid the height equals the
//! source's value, for bilinear and bicubic interpolation, at any data level, for netCDF, GeoTIFF
//! and PNG inputs; heights stay a pure, scale-invariant function of the place; version 1 files
//! still open.

use crate::common::*;
use pmc_dem::cube::{accuracy, import_cube, CubeDem, DetailNoise, ImportOptions, Interpolation};
use pmc_dem::fuzz::{PNG_EXTENT, SEED_FILES};
use pmc_dem::{DemError, EquirectDem, EquirectSource};
use pmc_geometry::glam::IVec3;
use pmc_geometry::{face_lattice, Face, FaceGrid, LatLon};

const INTERPS: [Interpolation; 2] = [Interpolation::Bilinear, Interpolation::Bicubic];

/// Imports `source` at `level` into the test's directory.
fn import(source: &dyn EquirectSource, test: &str, level: Option<u32>) -> CubeDem {
    let out = dir(test).join("kept.pmcdem");
    let options = ImportOptions {
        level,
        ..ImportOptions::default()
    };
    import_cube(source, &out, &options, &|_, _| {}).unwrap();
    let cube = CubeDem::open(&out).unwrap();
    cube.verify().unwrap();
    cube
}

/// Asserts that `cube`'s heights equal `source`'s value at every valid sample, to `tolerance`
/// metres, for both interpolations with the default detail; returns the samples compared.
fn assert_every_sample_kept(cube: &CubeDem, source: &dyn EquirectSource, tolerance: f64) -> u64 {
    let mut samples = 0;
    for interp in INTERPS {
        let a = accuracy(cube, source, interp, &DetailNoise::default()).unwrap();
        assert!(
            a.max <= tolerance && a.p99 <= a.max && a.rms <= a.max,
            "{}: {a:?}",
            source.name()
        );
        samples = a.samples;
    }
    samples
}

#[test]
fn every_sample_of_the_netcdf_fixture_is_kept_at_every_data_level() {
    let dem = etopo60();
    for level in [3, 6, 9] {
        let cube = import(&dem, &format!("netcdf-{level}"), Some(level));
        assert_eq!((cube.version(), cube.source_size()), (2, Some((360, 180))));
        assert_eq!(assert_every_sample_kept(&cube, &dem, 1e-6), 360 * 180);
    }
}

#[test]
fn every_sample_of_the_geotiff_and_png_fixtures_is_kept() {
    let dir_ = fixture_dir();
    for name in &SEED_FILES[1..4] {
        let dem = EquirectDem::read_geotiff(dir_.join(name)).unwrap();
        let cube = import(&dem, &format!("tif-{name}"), None);
        assert_eq!(assert_every_sample_kept(&cube, &dem, 1e-6), 72 * 36, "{name}");
    }
    let png = EquirectDem::read_png16(dir_.join(SEED_FILES[4]), &PNG_EXTENT).unwrap();
    let cube = import(&png, "png", Some(5));
    assert_eq!(assert_every_sample_kept(&cube, &png, 1e-6), 72 * 36);
}

#[test]
fn every_valid_sample_of_a_regional_grid_with_holes_is_kept() {
    let src = Patch;
    let cube = import(&src, "regional", Some(7));
    let kept = assert_every_sample_kept(&cube, &src, 1e-6);
    assert_eq!(kept, 41 * 31 - 41, "one row of holes");
    // Holes hold a filled value, inside the data's range.
    let filled = f64::from(cube.source_sample(5, 10).unwrap());
    let (lo, hi) = cube.value_range();
    assert!(filled >= lo && filled <= hi, "{filled}");
    // Heights are continuous across the grid's edges into the faces' fill outside them.
    for interp in INTERPS {
        for (lat, lon, dlat, dlon) in [
            (12.3, 5.0, 0.0, 1e-9),
            (17.7, 15.0, 0.0, 1e-9),
            (10.0, 9.1, 1e-9, 0.0),
            (25.0, 6.6, 1e-9, 0.0),
        ] {
            let at = |lat: f64, lon: f64| {
                cube.height(
                    LatLon::new(lat, lon).unwrap().to_unit(),
                    interp,
                    &DetailNoise::default(),
                    1.0,
                )
            };
            let (a, b) = (at(lat - dlat, lon - dlon), at(lat + dlat, lon + dlon));
            assert!((a - b).abs() < 1e-3, "{interp:?} ({lat}, {lon}): {a} and {b}");
        }
        // Far outside, the fill.
        let far = cube.height(
            LatLon::new(-40.0, 100.0).unwrap().to_unit(),
            interp,
            &DetailNoise::default(),
            1.0,
        );
        assert!(far >= lo && far <= hi, "{far}");
    }
}

/// A regional grid, 5..15 E by 10..25 N at 0.25 and 0.5 degrees, with row 10 missing.
struct Patch;
impl EquirectSource for Patch {
    fn name(&self) -> &str {
        "patch"
    }
    fn width(&self) -> usize {
        41
    }
    fn height(&self) -> usize {
        31
    }
    fn lon_first(&self) -> f64 {
        5.0
    }
    fn lon_step(&self) -> f64 {
        0.25
    }
    fn lat_first(&self) -> f64 {
        10.0
    }
    fn lat_step(&self) -> f64 {
        0.5
    }
    fn wraps_in_longitude(&self) -> bool {
        false
    }
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError> {
        assert_eq!(out.len(), rows * 41);
        for (k, v) in out.iter_mut().enumerate() {
            let (c, r) = (k % 41, row0 + k / 41);
            *v = if r == 10 {
                f32::NAN
            } else {
                (1000.0 * ((c * 7 + r * 13) % 17) as f64 - 8000.0 + 0.5 * c as f64) as f32
            };
        }
        Ok(())
    }
}

/// Lattice points of several resolutions over every face, edges and corners included.
fn lattice_points(m: i32) -> Vec<IVec3> {
    let mut points = Vec::new();
    for face in Face::ALL {
        for k in 0..97i64 {
            let i = (k * 7919 + face.index() as i64 * 31) % (i64::from(m) + 1);
            let j = (k * 104_729 + 17) % (i64::from(m) + 1);
            for (a, b) in [(i, j), (0, j), (i, i64::from(m)), (0, 0)] {
                points.push(face_lattice(face, a, b, i64::from(m)).unwrap());
            }
        }
    }
    points
}

#[test]
fn heights_are_the_same_bits_at_every_lattice_resolution_and_in_batches() {
    let dem = etopo60();
    let cube = import(&dem, "scale-invariance", Some(6));
    let detail = DetailNoise::default();
    for interp in INTERPS {
        for m in [8, 64, 256, 1 << 12, 1 << 20] {
            let points = lattice_points(m);
            let mut batch = vec![0.0; points.len()];
            cube.heights_at_lattice(&points, m, interp, &detail, &mut batch);
            for (p, b) in points.iter().zip(&batch) {
                let h = cube.height_at_lattice(*p, m, interp, &detail);
                assert!(h.is_finite(), "{p} at {m}");
                assert_eq!(h.to_bits(), b.to_bits(), "{p} at {m}: one at a time and in a batch");
                for k in [1, 2, 5] {
                    let finer = cube.height_at_lattice(*p * (1 << k), m << k, interp, &detail);
                    assert_eq!(h.to_bits(), finer.to_bits(), "{p} at {m} and {}", m << k);
                }
                let dir = pmc_geometry::cube_to_sphere(p.as_dvec3() / f64::from(m));
                let along = cube.height(dir, interp, &detail, 0.0);
                assert!((along - h).abs() < 1e-6, "{p} at {m}: {along} vs {h}");
            }
        }
        // Face grids (a patch's vertices) give the bits of one point at a time.
        let m = 1 << 14;
        for face in Face::ALL {
            for (i0, j0) in [(-1i64, -1i64), (5000, 7000), (i64::from(m) - 66, 40)] {
                let grid = FaceGrid { face, i0, j0, side: 67 };
                let points: Vec<IVec3> = (0..grid.len())
                    .map(|e| {
                        let (i, j) = grid.indices(e % 67, e / 67);
                        face_lattice(face, i, j, i64::from(m)).unwrap_or(IVec3::new(m, m, m))
                    })
                    .collect();
                let mut on_grid = vec![0.0; points.len()];
                cube.heights_on_grid(&grid, &points, m, interp, &detail, &mut on_grid);
                for (p, h) in points.iter().zip(&on_grid) {
                    let one = cube.height_at_lattice(*p, m, interp, &detail);
                    assert_eq!(h.to_bits(), one.to_bits(), "{grid:?} {p}");
                }
            }
        }
    }
}

#[test]
fn the_source_grid_read_with_a_stride_holds_the_stored_samples() {
    // a tile size that the grid's sides do not divide, so the last tiles are partial
    let dem = etopo60();
    let out = dir("decimated").join("kept.pmcdem");
    let options = ImportOptions {
        level: Some(5),
        tile_size: 48,
        ..ImportOptions::default()
    };
    import_cube(&dem, &out, &options, &|_, _| {}).unwrap();
    let cube = CubeDem::open(&out).unwrap();
    let axes = cube.source_axes().unwrap();
    assert_eq!((axes.width, axes.height, axes.wraps), (360, 180, true));
    assert_eq!((axes.lon_step, axes.lat_step), (dem.lon_step(), dem.lat_step()));
    assert_eq!((axes.lon_first, axes.lat_first), (dem.lon_first(), dem.lat_first()));
    for stride in [1, 2, 7, 64, 500] {
        let (w, h, values) = cube.source_decimated(stride).unwrap();
        assert_eq!(
            (w, h),
            (360u32.div_ceil(stride), 180u32.div_ceil(stride)),
            "stride {stride}"
        );
        assert_eq!(values.len(), (w * h) as usize);
        for r in 0..h {
            for c in 0..w {
                let want = cube.source_sample(c * stride, r * stride).unwrap();
                assert_eq!(
                    values[(r * w + c) as usize].to_bits(),
                    want.to_bits(),
                    "stride {stride} ({c}, {r})"
                );
            }
        }
    }
    assert!(matches!(cube.source_decimated(0), Err(DemError::OutOfGrid { .. })));
    let v1 = CubeDem::open(fixture_dir().join(V1_FIXTURE)).unwrap();
    assert!(v1.source_axes().is_none());
    assert!(matches!(v1.source_decimated(1), Err(DemError::OutOfGrid { .. })));
}

/// `etopo60.cdf` imported at level 6 by the version 1 importer (`pmcdem-v1.md`), kept to check
/// that version 1 files still open and give their heights as before.
const V1_FIXTURE: &str = "etopo60_l6_v1.pmcdem";

#[test]
fn version_1_files_still_open() {
    let cube = CubeDem::open(fixture_dir().join(V1_FIXTURE)).unwrap();
    cube.verify().unwrap();
    assert_eq!(
        (cube.version(), cube.keeps_source(), cube.source_size()),
        (1, false, None)
    );
    assert_eq!((cube.data_level(), cube.source_bytes()), (6, 0));
    assert!(matches!(cube.source_sample(0, 0), Err(DemError::OutOfGrid { .. })));
    // Heights as version 1 gives them: exact at the face samples, interpolated between.
    let detail = DetailNoise::default();
    for face in Face::ALL {
        for (i, j) in [(0, 0), (32, 32), (64, 17), (5, 60)] {
            let stored = f64::from(cube.sample(0, face, i, j).unwrap());
            let p = face_lattice(face, i64::from(i), i64::from(j), 64).unwrap();
            for interp in INTERPS {
                assert_eq!(cube.height_at_lattice(p, 64, interp, &detail), stored);
                assert_eq!(cube.height_at_lattice(p * 8, 512, interp, &detail), stored);
            }
        }
    }
    let everest = LatLon::new(28.0, 87.0).unwrap().to_unit();
    assert!(cube.height(everest, Interpolation::Bicubic, &detail, 10.0) > 2000.0);
}

/// Where the ETOPO grids are: `shared/data` beside the workspace, or Debian's
/// `ferret-datasets`.
fn etopo(name: &str) -> std::path::PathBuf {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let candidates = [
        root.join("../shared/data").join(name),
        std::path::Path::new("/usr/share/ferret-vis/data").join(name),
    ];
    candidates.iter().find(|p| p.is_file()).cloned().unwrap_or_else(|| {
        panic!("{name} not found (looked at {candidates:?}); install it with `apt-get install ferret-datasets`")
    })
}

/// The whole of ETOPO5 and ETOPO20: every sample kept to a metre, the highest and lowest cells
/// exactly (to float precision), bilinear and bicubic.
#[test]
fn etopo5_and_etopo20_keep_every_sample_and_the_extremes_exactly() {
    for (name, level) in [("etopo20.cdf", None), ("etopo5.cdf", Some(8))] {
        let dem = EquirectDem::read_netcdf(etopo(name), None).unwrap();
        let cube = import(&dem, name, level);
        let (w, h) = (dem.width(), dem.height());
        let kept = assert_every_sample_kept(&cube, &dem, 1.0);
        assert_eq!(kept, (w * h) as u64, "{name}");
        let heights = dem.heights();
        let (mut hi, mut lo) = (0, 0);
        for (k, v) in heights.iter().enumerate() {
            if *v > heights[hi] {
                hi = k;
            }
            if *v < heights[lo] {
                lo = k;
            }
        }
        for k in [hi, lo] {
            let (c, r) = (k % w, k / w);
            let value = heights[k];
            let dir = LatLon::new(dem.lat(r), dem.lon(c)).unwrap().to_unit();
            for interp in INTERPS {
                let got = cube.height(dir, interp, &DetailNoise::default(), 1.0);
                assert!(
                    (got - f64::from(value)).abs() <= f64::from(value.abs() * f32::EPSILON),
                    "{name} ({}, {}): {got} m where the data hold {value} m ({interp:?})",
                    dem.lat(r),
                    dem.lon(c)
                );
            }
        }
    }
}

/// The detail noise (up to twice 400 m on steep data) made islands in the Strait of Gibraltar,
/// whose ETOPO5 cells lie 135 m and more under the sea, and sank land along the coast: the sea a
/// viewer draws where the ground is below the datum did not follow the data's shoreline. The
/// detail now fades toward the datum, so it never moves a height across it.
#[test]
fn the_detail_noise_made_islands_in_the_strait_of_gibraltar() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/landmarks/coast.cdf");
    let source = EquirectDem::read_netcdf(&path, None).unwrap();
    let cube = import(&source, "gibraltar-islands", None);
    let detail = DetailNoise::default();
    let (mut land, mut sea, mut moved) = (0, 0, 0);
    for interp in INTERPS {
        // a 300 x 120 grid of places over the strait and its coasts, with the detail down to 10 m
        for y in 0..120 {
            for x in 0..300 {
                let lat = 35.6 + 1.2 * f64::from(y) / 119.0;
                let lon = -6.5 + 2.5 * f64::from(x) / 299.0;
                let dir = LatLon::new(lat, lon).unwrap().to_unit();
                let data = cube.height(dir, interp, &DetailNoise::OFF, 10.0);
                let h = cube.height(dir, interp, &detail, 10.0);
                assert!(h.is_finite() && data.is_finite(), "({lat}, {lon})");
                if data > 0.0 {
                    land += 1;
                } else {
                    sea += 1;
                }
                if h != data {
                    moved += 1;
                }
                assert!(
                    (data > 0.0) == (h > 0.0),
                    "{interp:?} at ({lat:.4}, {lon:.4}): the data give {data:.1} m, the detail makes it {h:.1} m"
                );
            }
        }
    }
    // the window holds both, and the detail does move the ground there
    assert!(land > 5000 && sea > 5000, "land {land}, sea {sea}");
    assert!(moved > 20_000, "the detail moved {moved} places");
}
