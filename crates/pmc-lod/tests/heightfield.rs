//! A real planet meshed as a height field, through the chunk selection the server and the viewer
//! use: for random views, the selected patches (each stitched on the sides facing a coarser one)
//! weld by lattice key into one closed 2-manifold, and co-located vertices carry the same normals
//! (to 1e-4: see `check`).

use pmc_dem::{import_cube, EquirectSource, ImportOptions, NetcdfSource};
use pmc_geometry::glam::DVec3;
use pmc_geometry::EdgeKey;
use pmc_lod::{measure_level_errors, occluder_radius, LodParams, Selector, View};
use pmc_mesh::{ChunkMesh, WeldedMesh};
use pmc_planet::{DemSpec, Interpolation, Planet, TerrainSpec};
use proptest::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The one-degree ETOPO60 fixture imported once (level 7) as a height-field planet.
fn planet() -> &'static Planet {
    static PLANET: OnceLock<Planet> = OnceLock::new();
    PLANET.get_or_init(|| {
        let dir: PathBuf = std::env::temp_dir().join(format!("pmc-lod-heightfield-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let src = NetcdfSource::open(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../pmc-dem/tests/fixtures/etopo60.cdf"),
            None,
        )
        .unwrap();
        let out = dir.join("earth.pmcdem");
        let options = ImportOptions {
            level: Some(7),
            ..ImportOptions::default()
        };
        let report = import_cube(&src as &dyn EquirectSource, &out, &options, &|_, _| {}).unwrap();
        let spec = TerrainSpec::Dem(DemSpec {
            path: out.to_str().unwrap().into(),
            digest: report.digest,
            interpolation: Interpolation::Bicubic,
            seed: 3,
        });
        Planet::heightfield(&spec).unwrap()
    })
}

fn check(eye: DVec3, max_pixel_error: f64) -> Result<usize, TestCaseError> {
    let planet = planet();
    let errors = measure_level_errors(planet, 256, 1);
    let selector = Selector::new(*planet.layout(), errors, occluder_radius(planet)).unwrap();
    let view = View {
        eye,
        frustum: None,
        viewport_height_px: 1080.0,
        fov_y: 1.0,
    };
    let params = LodParams {
        max_pixel_error,
        ..LodParams::default()
    };
    let selection = selector.select(&view, &params).unwrap();
    let meshes: Vec<ChunkMesh> = selection
        .chunks
        .iter()
        .map(|s| planet.chunk_mesh_lod(s.key, s.coarser))
        .collect();
    prop_assert!(meshes.iter().all(|m| !m.is_empty()), "an empty patch");
    let report = WeldedMesh::weld(&meshes).report();
    let what = format!("eye {eye:?} levels {:?}", selection.level_histogram());
    prop_assert!(report.is_closed_manifold(), "{what}: {report:?}");
    let mut normals: HashMap<EdgeKey, [f32; 3]> = HashMap::new();
    let mut worst = 1.0f32;
    for m in &meshes {
        for (k, n) in m.edge_keys.iter().zip(&m.normals) {
            if let Some(prev) = normals.insert(*k, *n) {
                worst = worst.min((0..3).map(|i| prev[i] * n[i]).sum());
            }
        }
    }
    // A chunk selection tells a patch which of its sides face a coarser patch, not which corners
    // do (pmc-heightfield's own selection does, and its tests prove equal normals to 1e-6): at a
    // corner whose only coarser neighbour is diagonal the two normals come from different
    // spacings. Near the ground they differ by a few 1e-6; between coarse patches over rough
    // relief by more: 1.17e-4 (0.9 degrees) at the corner of two level-14 patches 5.9 m under
    // one eye (the case kept in heightfield.proptest-regressions), where the old bound of 1e-4
    // failed one run in a few. 1e-3 is 2.6 degrees.
    prop_assert!(
        worst > 1.0 - 1e-3,
        "{what}: normals of a shared vertex differ (dot {worst})"
    );
    Ok(meshes.len())
}

#[test]
fn patches_seen_from_orbit_and_from_a_mountain_close_up_are_closed() {
    let r = planet().heightfield_mode().unwrap().datum();
    // from orbit, and 40 km over the Himalaya
    let himalaya = DVec3::new(0.07, 0.47, 0.88).normalize();
    for (eye, px) in [(DVec3::new(0.3, 0.5, 2.5) * r, 2.0), (himalaya * (r + 40_000.0), 8.0)] {
        let n = check(eye, px).unwrap();
        assert!(n >= 6, "{n} patches");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4, ..ProptestConfig::default() })]

    // From 30 km up (closer, every patch whose shell column the camera is in is refined to the
    // finest level: thousands of patches, too many for a test).
    #[test]
    fn patches_of_random_views_are_closed(x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0, alt in 4.5f64..6.5) {
        let d = DVec3::new(x, y, z);
        prop_assume!(d.length() > 0.1);
        let r = planet().heightfield_mode().unwrap().datum();
        check(d.normalize() * (r + 10f64.powf(alt)), 12.0)?;
    }
}
