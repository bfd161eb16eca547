//! The relief of an elevation-model planet: the `relief` field of `/api/v1/planet` and the grid at
//! `/api/v1/relief` (docs/specs/http-api-v1.md), from which the viewer takes the materials' heights
//! the same at every level of detail.

use crate::common;

use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::{app, get, send, small_config};
use pmc_dem::{import_cube, CubeDem, EquirectDem, ImportOptions};
use pmc_density::Density;
use pmc_planet::{DemSpec, Interpolation, TerrainSpec};
use pmc_server::ServerConfig;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pmc-dem/tests/fixtures")
        .join(name)
}

/// ETOPO60 (360 x 180, one degree) imported into a fresh directory, as a terrain.
fn etopo60(test: &str) -> (TerrainSpec, PathBuf) {
    let dir = std::env::temp_dir().join(format!("pmc-server-relief-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dem = EquirectDem::read_netcdf(fixture("etopo60.cdf"), None).unwrap();
    let out = dir.join("earth.pmcdem");
    let options = ImportOptions {
        level: Some(5),
        ..ImportOptions::default()
    };
    let report = import_cube(&dem, &out, &options, &|_, _| {}).unwrap();
    (terrain(&out, report.digest), out)
}

fn terrain(path: &Path, digest: String) -> TerrainSpec {
    TerrainSpec::Dem(DemSpec {
        path: path.to_str().unwrap().into(),
        digest,
        interpolation: Interpolation::Bilinear,
        seed: 7,
    })
}

/// A server of `terrain` on the layout made for its body (`pmc serve --dem`).
fn config(terrain: TerrainSpec) -> ServerConfig {
    let TerrainSpec::Dem(spec) = &terrain else {
        unreachable!()
    };
    ServerConfig {
        layout: pmc_dem::dem_layout(spec).unwrap(),
        terrain,
        ..small_config()
    }
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

#[tokio::test]
async fn the_relief_is_the_elevation_models_source_grid() {
    let (terrain, path) = etopo60("grid");
    let cube = CubeDem::open(&path).unwrap();
    let a = app(config(terrain));
    let p = get(&a, "/api/v1/planet").await.json();
    let sea = p["sea_radius"].as_f64().unwrap();
    let r = &p["relief"];
    assert_eq!(r["url"], "/api/v1/relief", "{r}");
    assert_eq!((r["width"].as_u64(), r["height"].as_u64()), (Some(360), Some(180)));
    assert_eq!(r["wraps"], true);
    assert_eq!(r["encoding"], "f32le");
    assert_eq!(r["digest"], cube.digest());
    let axes = cube.source_axes().unwrap();
    assert_eq!(r["lon_first"].as_f64(), Some(axes.lon_first));
    assert_eq!(r["lat_step"].as_f64(), Some(axes.lat_step));
    assert_eq!(r["scale"].as_f64(), Some(sea / cube.radius()));

    // the whole grid: every sample as stored
    let whole = get(&a, "/api/v1/relief").await;
    assert_eq!(whole.status, StatusCode::OK);
    assert_eq!(whole.header("content-type"), Some("application/octet-stream"));
    assert_eq!(whole.header("x-pmc-grid-size"), Some("360x180"));
    let values = floats(&whole.body);
    assert_eq!(values.len(), 360 * 180);
    for (k, v) in values.iter().enumerate() {
        let want = cube.source_sample((k % 360) as u32, (k / 360) as u32).unwrap();
        assert_eq!(v.to_bits(), want.to_bits(), "sample {k}");
    }
    // every 4th sample for at most 100 a side
    let fourth = get(&a, "/api/v1/relief?max=100").await;
    assert_eq!(fourth.header("x-pmc-grid-size"), Some("90x45"));
    assert_eq!(fourth.header("x-pmc-grid-stride"), Some("4"));
    let v4 = floats(&fourth.body);
    assert_eq!(v4.len(), 90 * 45);
    assert_eq!(v4[90 * 10 + 7].to_bits(), values[360 * 40 + 28].to_bits());

    // compressed once when the client takes gzip
    let req = Request::get("/api/v1/relief")
        .header("accept-encoding", "gzip, br")
        .body(Body::empty())
        .unwrap();
    let zipped = send(&a, req).await;
    assert_eq!(zipped.header("content-encoding"), Some("gzip"));
    let mut unzipped = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&zipped.body[..]), &mut unzipped).unwrap();
    assert_eq!(unzipped, whole.body.to_vec());
    let req = Request::get("/api/v1/relief")
        .header("accept-encoding", "gzip;q=0")
        .body(Body::empty())
        .unwrap();
    assert_eq!(send(&a, req).await.header("content-encoding"), None);
    // the ETag names the digest and the stride: a revalidation is a 304 with no body
    let etag = whole.header("etag").unwrap().to_owned();
    assert_eq!(etag, format!("\"{}-s1\"", cube.digest()));
    assert_ne!(fourth.header("etag").unwrap(), etag);
    let req = Request::get("/api/v1/relief")
        .header("if-none-match", &etag)
        .body(Body::empty())
        .unwrap();
    let again = send(&a, req).await;
    assert_eq!(again.status, StatusCode::NOT_MODIFIED);
    assert!(again.body.is_empty());

    // a bad max is refused, saying what it must be
    for bad in ["0", "-3", "lots", "1.5"] {
        let r = get(&a, &format!("/api/v1/relief?max={bad}")).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "max={bad}");
        assert!(r.json()["error"].as_str().unwrap().contains("max must be"), "max={bad}");
    }
    // another planet asked for by name has none
    let mars = get(&a, "/api/v1/planet?preset=mars").await.json();
    assert!(mars["relief"].is_null(), "{}", mars["relief"]);
}

#[tokio::test]
async fn a_presets_relief_is_its_ground_on_a_grid_of_cell_centres() {
    let a = app(small_config());
    let p = get(&a, "/api/v1/planet").await.json();
    let r = &p["relief"];
    assert_eq!(
        (r["width"].as_u64(), r["height"].as_u64()),
        (Some(1024), Some(512)),
        "{r}"
    );
    assert_eq!(
        (r["lon_first"].as_f64(), r["lon_step"].as_f64()),
        (Some(-180.0 + 180.0 / 1024.0), Some(360.0 / 1024.0))
    );
    assert_eq!(
        (r["lat_first"].as_f64(), r["lat_step"].as_f64()),
        (Some(-90.0 + 90.0 / 512.0), Some(180.0 / 512.0))
    );
    assert_eq!((r["wraps"].as_bool(), r["scale"].as_f64()), (Some(true), Some(1.0)));
    let whole = get(&a, "/api/v1/relief").await;
    assert_eq!(whole.status, StatusCode::OK);
    let values = floats(&whole.body);
    assert_eq!(values.len(), 1024 * 512);
    // the ground of the planet itself: where no overhang or cave moves it, the first surface met
    // going down the column lies within a voxel of it
    let planet = pmc_planet::Planet::new(pmc_planet::PresetKind::Earthlike, 3, common::small_layout());
    let datum = planet.datum_radius();
    let (lo, hi) = planet.terrain().density.radial_bounds().unwrap();
    let mut off = Vec::new();
    for k in (0..values.len()).step_by(997) {
        let (c, row) = (k % 1024, k / 1024);
        let lat = -90.0 + (row as f64 + 0.5) * 180.0 / 512.0;
        let lon = -180.0 + (c as f64 + 0.5) * 360.0 / 1024.0;
        let g = datum + f64::from(values[k]);
        assert!(
            g >= lo - 1e-6 && g <= hi + 1e-6,
            "ground {g} outside the density's bounds {lo}..{hi}"
        );
        let dir = pmc_geometry::LatLon::new(lat, lon).unwrap().to_unit();
        off.push((planet.surface_radius(dir) - g).abs());
    }
    off.sort_by(f64::total_cmp);
    let l_d = common::small_layout().l_d();
    assert!(
        off[off.len() / 2] <= 0.25 * l_d,
        "median {} of {} columns",
        off[off.len() / 2],
        off.len()
    );
    // the same grid again, and a digest that names it
    let again = get(&a, "/api/v1/relief").await;
    assert_eq!(again.body, whole.body);
    assert_eq!(
        whole.header("etag").map(str::to_owned),
        Some(format!("\"{}-s1\"", r["digest"].as_str().unwrap()))
    );
    // another planet asked for by name has none
    let mars = get(&a, "/api/v1/planet?preset=mars").await.json();
    assert!(mars["relief"].is_null(), "{}", mars["relief"]);
}

#[tokio::test]
async fn a_version_1_file_has_no_relief() {
    let v1 = fixture("etopo60_l6_v1.pmcdem");
    let digest = CubeDem::open(&v1).unwrap().digest().to_owned();
    let a = app(config(terrain(&v1, digest)));
    let p = get(&a, "/api/v1/planet").await.json();
    assert_eq!(p["terrain"]["kind"], "dem");
    assert!(p["relief"].is_null(), "{}", p["relief"]);
    let r = get(&a, "/api/v1/relief").await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.json()["error"].as_str().unwrap().contains("version 2"));
}
