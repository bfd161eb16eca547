//! Real planets from elevation models, meshed: the surface the finest level of detail draws lies
//! on the model at its data points, and at landmarks of NOAA ETOPO5 (fixtures cut by pmc-dem's
//! `crop_etopo` example; the expected values are decoded here with the `netcdf3` crate alone).
//! The error of each coarser level at the landmarks is printed (`--nocapture`) for the docs.

use pmc_dem::{import_cube, CubeDem, EquirectSource, HeightField, ImportOptions, NetcdfSource};
use pmc_geometry::glam::DVec3;
use pmc_geometry::LatLon;
use pmc_lod::probe::meshed_surface_radius;
use pmc_planet::{default_layout, DemSpec, Interpolation, Planet, TerrainSpec};
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn dem_fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pmc-dem/tests/fixtures")
        .join(path)
}

fn scratch(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-lod-dem-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Imports `source` (netCDF) into `dir` at `level`, missing samples (outside a regional grid)
/// set to `fill`, and returns the file and its terrain.
fn import(
    source: &Path,
    dir: &Path,
    level: Option<u32>,
    fill: Option<f32>,
    interpolation: Interpolation,
) -> (PathBuf, TerrainSpec) {
    let src = NetcdfSource::open(source, None).unwrap();
    let out = dir.join("planet.pmcdem");
    let options = ImportOptions {
        level,
        fill_value: fill,
        ..ImportOptions::default()
    };
    let report = import_cube(&src as &dyn EquirectSource, &out, &options, &|_, _| {}).unwrap();
    let spec = TerrainSpec::Dem(DemSpec {
        path: out.to_str().unwrap().to_string(),
        digest: report.digest,
        interpolation,
        seed: 7,
    });
    (out, spec)
}

/// Whether the planet is solid just under `radius` along `dir` (no cave mouth opens there).
fn solid_below(planet: &Planet, dir: DVec3, radius: f64) -> bool {
    (1..=3).all(|k| planet.density().density(dir * (radius - 0.75 * f64::from(k))) > 0.0)
}

#[test]
fn the_finest_mesh_passes_within_a_metre_of_every_data_point_tried() {
    let dir = scratch("data-points");
    let (path, spec) = import(&dem_fixture("etopo60.cdf"), &dir, Some(7), None, Interpolation::Bicubic);
    let layout = default_layout(&spec).unwrap();
    let planet = Planet::from_terrain(&spec, layout).unwrap();
    let dem = CubeDem::open(&path).unwrap();
    let sea = planet.datum_radius();
    assert_eq!(
        sea,
        dem.radius(),
        "the Earth's layout puts the sea at the body's radius"
    );
    // Source samples spread over the globe (the file keeps the grid: heights equal its values
    // there), the polar rows and the antimeridian included.
    let grid = pmc_dem::EquirectDem::read_netcdf(dem_fixture("etopo60.cdf"), None).unwrap();
    let (w, h) = (grid.width(), grid.height());
    let (mut tried, mut mouths) = (0, 0);
    for s in 0..60usize {
        let (c, r) = ((s * 37 + 11) % w, (s * 53 + 5) % h);
        let r = if s == 0 {
            0
        } else if s == 1 {
            h - 1
        } else {
            r
        };
        let value = f64::from(grid.value(c, r).unwrap());
        let d = LatLon::new(grid.lat(r), grid.lon(c)).unwrap().to_unit();
        if !solid_below(&planet, d, sea + value) {
            mouths += 1;
            continue;
        }
        tried += 1;
        let meshed = meshed_surface_radius(&planet, d, 0).expect("the finest level meets the ray") - sea;
        assert!(
            (meshed - value).abs() <= 1.0,
            "source sample ({c}, {r}): the mesh is at {meshed:.3} m, the data point at {value} m"
        );
    }
    assert!(mouths * 10 <= tried, "{mouths} cave mouths among {tried} data points");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An ETOPO5 landmark fixture decoded with `netcdf3::FileReader` alone: `(lat, lon, height)`
/// of every cell (the fill value -1e34 left out).
fn raw_cells(name: &str) -> Vec<(f64, f64, f32)> {
    let mut r = netcdf3::FileReader::open(dem_fixture("landmarks").join(name)).unwrap();
    let lon = r.read_var_f64("ETOPO05_X").unwrap();
    let lat = r.read_var_f64("ETOPO05_Y").unwrap();
    let rose = r.read_var_f32("ROSE").unwrap();
    assert_eq!(rose.len(), lon.len() * lat.len());
    let mut out = Vec::new();
    for (y, la) in lat.iter().enumerate() {
        for (x, lo) in lon.iter().enumerate() {
            let v = rose[y * lon.len() + x];
            if v != -1e34 {
                out.push((*la, *lo, v));
            }
        }
    }
    out
}

/// The first cell (file order) with the largest (`highest`) or smallest value among those
/// `keep` accepts.
fn extreme(cells: &[(f64, f64, f32)], highest: bool, keep: impl Fn(f64, f64) -> bool) -> (f64, f64, f32) {
    let better = |a: f32, b: f32| if highest { a > b } else { a < b };
    cells
        .iter()
        .copied()
        .filter(|(la, lo, _)| keep(*la, *lo))
        .reduce(|best, c| if better(c.2, best.2) { c } else { best })
        .unwrap()
}

/// The local relief around a cell: the highest minus the lowest of it and its eight neighbours.
fn local_relief(cells: &[(f64, f64, f32)], lat: f64, lon: f64) -> f64 {
    let step = 5.0 / 60.0;
    let (lo, hi) = cells
        .iter()
        .filter(|(la, lo, _)| (la - lat).abs() < 1.5 * step && (lo - lon).abs() < 1.5 * step)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
            (a.min(f64::from(c.2)), b.max(f64::from(c.2)))
        });
    hi - lo
}

/// A landmark: its fixture, what it is, whether it is the highest (or lowest) cell among those
/// the filter keeps, and the value the file holds there.
type Landmark<'a> = (&'a str, &'a str, bool, &'a dyn Fn(f64, f64) -> bool, f32);

#[test]
fn landmarks_of_etopo5_are_where_the_data_puts_them() {
    // (fixture, landmark, highest or lowest, the cells considered, the value the file holds)
    let everest = |_: f64, _: f64| true;
    let dead_sea = |_: f64, lon: f64| lon > 35.2;
    let landmarks: [Landmark; 3] = [
        (
            "everest.cdf",
            "the highest cell of the Himalaya window",
            true,
            &everest,
            7010.0,
        ),
        (
            "challenger.cdf",
            "the deepest cell near the Challenger Deep",
            false,
            &everest,
            -10376.0,
        ),
        (
            "dead_sea.cdf",
            "the lowest cell of the Dead Sea",
            false,
            &dead_sea,
            -637.0,
        ),
    ];
    let mut places: Vec<(String, &str, f64, f64, f32, f64)> = Vec::new();
    for (file, what, highest, keep, expected) in landmarks {
        let cells = raw_cells(file);
        let (lat, lon, value) = extreme(&cells, highest, keep);
        assert_eq!(value, expected, "{file}: {what}");
        places.push((file.to_string(), what, lat, lon, value, local_relief(&cells, lat, lon)));
    }
    // A coast: a land cell east of Tarifa and the sea cell next to it.
    let coast = raw_cells("coast.cdf");
    let at = |lat: f64, lon: f64| {
        *coast
            .iter()
            .find(|c| (c.0 - lat).abs() < 1e-3 && (c.1 - lon).abs() < 1e-3)
            .unwrap()
    };
    for (lat, lon, expected, what) in [
        (36.0833, -5.6667, 137.0, "a land cell on the Strait of Gibraltar"),
        (36.0833, -5.5833, -135.0, "the sea cell east of it"),
    ] {
        let c = at(lat, lon);
        assert_eq!(c.2, expected, "coast.cdf: {what}");
        places.push(("coast.cdf".into(), what, c.0, c.1, c.2, local_relief(&coast, c.0, c.1)));
    }
    for (file, what, lat, lon, value, relief) in places {
        let dir = scratch(&file.replace('.', "-"));
        // A regional import: the rest of the planet is sea floor at 0 m (constant tiles).
        let (path, spec) = import(
            &dem_fixture("landmarks").join(&file),
            &dir,
            None,
            Some(0.0),
            Interpolation::Bicubic,
        );
        let layout = default_layout(&spec).unwrap();
        let planet = Planet::from_terrain(&spec, layout).unwrap();
        let TerrainSpec::Dem(d) = &spec else { unreachable!() };
        let dem = Arc::new(CubeDem::open(&path).unwrap());
        let (heights, vertical) = pmc_dem::dem_heights(dem.clone(), d, &layout);
        assert_eq!(vertical, 1.0);
        let ray = LatLon::new(lat, lon).unwrap().to_unit();
        let interpolated = heights.height(ray);
        // The file keeps the source grid: the height at a data cell is its value.
        assert!(
            (interpolated - f64::from(value)).abs() <= 1e-3,
            "{file}, {what}: interpolated {interpolated:.3} m, the file holds {value} m (relief {relief} m)"
        );
        let sea = planet.datum_radius();
        let mut line = format!("{file} {what} ({lat:.4}, {lon:.4}): data {value} m, interpolated {interpolated:.2} m");
        for level in 0..=layout.max_level() {
            let meshed = meshed_surface_radius(&planet, ray, level).map(|r| r - sea);
            if level == 0 {
                let meshed = meshed.expect("the finest level meets the ray");
                if solid_below(&planet, ray, sea + interpolated) {
                    assert!(
                        (meshed - interpolated).abs() <= 1.0,
                        "{file}, {what}: the finest mesh is at {meshed:.3} m, the surface at {interpolated:.3} m"
                    );
                }
            }
            match meshed {
                Some(m) => line += &format!(", level {level}: {:+.2}", m - interpolated),
                None => line += &format!(", level {level}: -"),
            }
        }
        println!("{line}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
