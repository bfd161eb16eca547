//! A server meshing an elevation model as a height field (`--mesher heightfield`): the planet
//! description gives the patch layout and its errors, chunks are stitched patches, and what a
//! height field cannot do (presets, editing, other planets) is refused with a clear message.

use crate::common::{app, get};
use axum::http::StatusCode;
use pmc_dem::{import_cube, EquirectDem, ImportOptions};
use pmc_formats::chunk_encoding::decode_chunk;
use pmc_geometry::{ChunkKey, Face, SideMask};
use pmc_planet::{DemSpec, Interpolation, Planet, PresetKind, TerrainSpec};
use pmc_server::{AppState, Mesher, ServerConfig};
use std::path::Path;

fn dem_terrain(test: &str) -> TerrainSpec {
    let dir = std::env::temp_dir().join(format!("pmc-server-heightfield-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../pmc-dem/tests/fixtures/etopo60.cdf");
    let dem = EquirectDem::read_netcdf(&src, None).unwrap();
    let out = dir.join("earth.pmcdem");
    let options = ImportOptions {
        level: Some(6),
        ..ImportOptions::default()
    };
    let report = import_cube(&dem, &out, &options, &|_, _| {}).unwrap();
    TerrainSpec::Dem(DemSpec {
        path: out.to_str().unwrap().into(),
        digest: report.digest,
        interpolation: Interpolation::Bicubic,
        seed: 7,
    })
}

fn config(terrain: TerrainSpec) -> ServerConfig {
    ServerConfig {
        port: 0,
        terrain,
        mesher: Mesher::Heightfield,
        threads: 2,
        ..ServerConfig::default()
    }
}

#[tokio::test]
async fn patches_are_served_as_chunks_of_the_patch_layout() {
    let terrain = dem_terrain("serve");
    let a = app(config(terrain.clone()));
    let p = get(&a, "/api/v1/planet").await.json();
    assert_eq!(p["layout"]["n_t"], 64, "{p}");
    assert_eq!(p["layout"]["d_c"], 1);
    assert_eq!(p["terrain"]["kind"], "dem");
    let errors = p["lod"]["errors"].as_array().unwrap();
    assert_eq!(errors.len(), p["max_level"].as_u64().unwrap() as usize + 1);
    assert!(errors.windows(2).all(|w| w[0].as_f64() <= w[1].as_f64()), "{errors:?}");
    // A coarse patch with two sides stitched: the server's bytes are the planet's patch.
    let planet = Planet::heightfield(&terrain).unwrap();
    let level = planet.layout().max_level() - 2;
    let key = ChunkKey {
        face: Face::Top,
        level,
        i: 1,
        j: 2,
        k: 0,
    };
    let r = get(&a, &format!("/api/v1/chunk/{key}?seams=5")).await;
    assert_eq!(r.status, StatusCode::OK);
    let d = decode_chunk(&r.body).unwrap();
    let mesh = planet.chunk_mesh_lod(key, SideMask(5));
    assert_eq!(d.positions, mesh.positions);
    assert_eq!(d.vertex_count(), 65 * 65);
    assert!(d.triangle_count() > 0 && d.triangle_count() < 2 * 64 * 64);
    // Another planet: this server meshes one elevation model only.
    let r = get(&a, "/api/v1/planet?preset=moon").await;
    assert!(r.status.is_client_error() || r.status.is_server_error());
    assert!(
        String::from_utf8_lossy(&r.body).contains("height field"),
        "{:?}",
        r.body
    );
}

#[test]
fn what_a_height_field_cannot_do_is_refused() {
    let e = AppState::new(config(TerrainSpec::preset(PresetKind::Earthlike, 3))).unwrap_err();
    assert!(e.to_string().contains("elevation models only"), "{e}");
    let terrain = dem_terrain("refused");
    let world = std::env::temp_dir().join(format!("pmc-server-heightfield-{}.pmcw", std::process::id()));
    let e = AppState::new(ServerConfig {
        world: Some(world.clone()),
        ..config(terrain)
    })
    .unwrap_err();
    assert!(e.to_string().contains("cannot be edited"), "{e}");
    assert!(!world.exists());
}
