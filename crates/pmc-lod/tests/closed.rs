//! The seam contract under real selections: for random views on several presets, the chunks a
//! selection picks, each meshed with its `coarser` sides closed, weld by edge key into one closed
//! 2-manifold, and every vertex shared by two chunks carries the same normal in both.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{EdgeKey, Layout};
use pmc_lod::{measure_level_errors, occluder_radius, LodParams, Selector, View};
use pmc_mesh::{ChunkMesh, WeldedMesh};
use pmc_planet::{Planet, PresetKind};
use proptest::prelude::*;
use std::collections::HashMap;

fn planets() -> Vec<Planet> {
    let layout = Layout::new(8, 8, 200.0, 2.0, 4).unwrap();
    [
        (PresetKind::Earthlike, 7),
        (PresetKind::Moon, 3),
        (PresetKind::Mars, 5),
        (PresetKind::Sphere, 0),
    ]
    .into_iter()
    .map(|(p, s)| Planet::new(p, s, layout))
    .collect()
}

/// Meshes every selected chunk (drawn or culled: closedness is a property of the whole set).
fn mesh_selection(planet: &Planet, eye: DVec3, max_pixel_error: f64) -> (Vec<ChunkMesh>, Vec<usize>) {
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
    let histogram = selection.level_histogram();
    let meshes = selection
        .chunks
        .iter()
        .map(|s| planet.chunk_mesh_lod(s.key, s.coarser))
        .filter(|m| !m.is_empty())
        .collect();
    (meshes, histogram)
}

fn check(planet: &Planet, eye: DVec3, max_pixel_error: f64) -> Result<Vec<usize>, TestCaseError> {
    let (meshes, histogram) = mesh_selection(planet, eye, max_pixel_error);
    let report = WeldedMesh::weld(&meshes).report();
    let what = format!("{:?} eye {eye:?} levels {histogram:?}", planet.terrain().spec);
    prop_assert!(report.is_closed_manifold(), "{what}: {report:?}");
    let mut normals: HashMap<EdgeKey, [f32; 3]> = HashMap::new();
    for m in &meshes {
        for (k, n) in m.edge_keys.iter().zip(&m.normals) {
            if let Some(prev) = normals.insert(*k, *n) {
                let dot: f32 = (0..3).map(|i| prev[i] * n[i]).sum();
                prop_assert!(dot > 1.0 - 1e-6, "{what}: normals differ at a shared vertex");
            }
        }
    }
    Ok(histogram)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random eyes from the ground to far away, on four presets.
    #[test]
    fn selections_are_closed(preset in 0usize..4, x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0,
                             altitude in 0.0f64..1.5, pixels in 0.5f64..4.0) {
        let planet = &planets()[preset];
        let dir = DVec3::new(x, y, z).normalize_or(DVec3::Y);
        let eye = dir * (planet.datum_radius() * (1.0 + altitude * altitude));
        check(planet, eye, pixels)?;
    }
}

/// Views from the ground up mix levels, and still close: every preset shows two levels or more
/// in some view, and some view shows three or more.
#[test]
fn views_from_the_ground_up_mix_levels_and_close() {
    let mut overall = 0;
    for planet in planets() {
        let mut most = 0;
        for altitude in [4.0, 60.0, 250.0, 1000.0, 4000.0] {
            for pixels in [2.0, 8.0] {
                let eye = DVec3::new(0.3, 0.9, 0.2).normalize() * (planet.datum_radius() + altitude);
                let histogram = check(&planet, eye, pixels).unwrap();
                most = most.max(histogram.iter().filter(|n| **n > 0).count());
            }
        }
        assert!(most >= 2, "{:?}: at most {most} levels", planet.terrain().spec);
        overall = overall.max(most);
    }
    assert!(overall >= 3, "no view mixed three levels");
}
