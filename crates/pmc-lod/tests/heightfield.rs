//! A real planet meshed as a height field, through the chunk selection the server and the viewer
//! use: for random views, the selected patches (each stitched on the sides facing a coarser one)
//! weld by lattice key into one closed 2-manifold, and co-located vertices carry the same normals
//! (to 1e-3: see `check`). Bounded by their own heights (`planet_radii`), patches near the ground
//! are few, every vertex lies within its patch's radii, and the selection is a subset of the
//! one bounded by the shell.

use pmc_dem::{import_cube, EquirectSource, ImportOptions, NetcdfSource};
use pmc_geometry::glam::DVec3;
use pmc_geometry::ChunkKey;
use pmc_geometry::EdgeKey;
use pmc_lod::{measure_level_errors, occluder_radius, planet_radii, LodParams, Selection, Selector, View};
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

/// The selection for `eye`, its patches bounded by their own heights (`tight`) or by the shell.
fn select(eye: DVec3, max_pixel_error: f64, tight: bool, max_chunks: usize) -> Selection {
    // Made once: the level errors are measured, and the patch radii are kept between selections.
    static SELECTORS: OnceLock<[Selector; 2]> = OnceLock::new();
    let [loose, tight_selector] = SELECTORS.get_or_init(|| {
        let planet = planet();
        let errors = measure_level_errors(planet, 256, 1);
        let loose = Selector::new(*planet.layout(), errors, occluder_radius(planet)).unwrap();
        let tight = loose
            .clone()
            .with_radii(planet_radii(planet).expect("a height-field planet has patch radii"));
        [loose, tight]
    });
    let selector = if tight { tight_selector } else { loose };
    let view = View {
        eye,
        frustum: None,
        viewport_height_px: 1080.0,
        fov_y: 1.0,
    };
    let params = LodParams {
        max_pixel_error,
        max_chunks,
        ..LodParams::default()
    };
    selector.select(&view, &params).unwrap()
}

fn check(eye: DVec3, max_pixel_error: f64, tight: bool) -> Result<usize, TestCaseError> {
    let planet = planet();
    let selection = select(eye, max_pixel_error, tight, pmc_lod::DEFAULT_MAX_CHUNKS);
    // Smaller spheres are farther from the eye: never a split the shell's spheres do not make
    // (compared where the shell's selection is small enough to make whole).
    let loose = tight
        .then(|| select(eye, max_pixel_error, false, 4_000))
        .filter(|l| !l.truncated);
    if let Some(loose) = loose {
        let keys: std::collections::HashSet<ChunkKey> = selection.chunks.iter().map(|s| s.key).collect();
        prop_assert!(
            // Every leaf of the loose selection is a tight leaf or lies inside one.
            loose.chunks.iter().all(|s| {
                let mut k = s.key;
                loop {
                    if keys.contains(&k) {
                        break true;
                    }
                    if k.level >= planet.layout().max_level() {
                        break false;
                    }
                    k = k.parent();
                }
            }),
            "the tight selection splits a chunk the loose one does not"
        );
    }
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
        for tight in [false, true] {
            let n = check(eye, px, tight).unwrap();
            assert!(n >= 6, "{n} patches");
        }
    }
}

/// Bounded by the shell, every patch whose column of the shell holds the eye looks as near as can
/// be, and near the ground all of them are refined to the finest level; bounded by their own
/// heights, only the patches near the eye are (the near-ground view of `pmc bench-flight
/// --mesher heightfield`: 3 877 patches before, 185 after). Regression test of that view.
#[test]
fn near_the_ground_only_patches_near_the_eye_are_finest() {
    let planet = planet();
    let himalaya = DVec3::new(0.07, 0.47, 0.88).normalize();
    let mode = planet.heightfield_mode().unwrap();
    let ground = pmc_lod::probe::meshed_surface_radius(planet, himalaya, 0).expect("the ground under the eye");
    let eye = himalaya * (ground.max(mode.datum()) + 2.0);
    let tight = select(eye, 2.0, true, pmc_lod::DEFAULT_MAX_CHUNKS);
    // (the shell's selection stopped at a budget: more than the budget's worth otherwise)
    let loose = select(eye, 2.0, false, 4_000);
    let (t, l) = (tight.level_histogram()[0], loose.level_histogram()[0]);
    assert!(t > 0, "the patch under the eye is the finest");
    assert!(
        4 * t < l,
        "{t} finest patches bounded by their heights, {l} by the shell"
    );
    eprintln!(
        "near the ground: {} patches ({t} finest) bounded by their heights, {} ({l}) by the shell",
        tight.chunks.len(),
        loose.chunks.len()
    );
    // And they still close (at 8 px: fewer patches to weld).
    check(eye, 8.0, true).unwrap();
}

/// Every vertex of a patch's mesh, stitched or not, lies within the radii `planet_radii` gives.
#[test]
fn every_vertex_lies_within_its_patch_radii() {
    let planet = planet();
    let radii = planet_radii(planet).unwrap();
    let layout = planet.layout();
    let mut keys = Vec::new();
    let mut seed = 0x1234_5678_u64;
    let mut next = move |n: u32| {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((seed >> 33) % u64::from(n)) as u32
    };
    for level in 0..=layout.max_level() {
        let n = layout.n_c() >> level;
        for face in pmc_geometry::Face::ALL {
            keys.push(ChunkKey {
                face,
                level,
                i: next(n),
                j: next(n),
                k: 0,
            });
        }
    }
    let mut out = vec![None; keys.len()];
    radii.radii(&keys, &mut out);
    let mut bounded = 0;
    for (key, r) in keys.iter().zip(out) {
        // Patches over `WIDE_PATCH` shell thicknesses wide keep their layers; the five finest
        // chunk levels (patches of 76 m to 1.2 km) are far narrower than that.
        let Some((lo, hi)) = r else {
            assert!(key.level > 4, "{key:?}: no radii");
            continue;
        };
        bounded += 1;
        assert!(lo <= hi);
        for sides in [0u8, 9, 15] {
            let mesh = planet.chunk_mesh_lod(*key, pmc_geometry::SideMask(sides));
            assert!(!mesh.is_empty());
            for (p, low) in mesh.positions.iter().zip(&mesh.positions_low) {
                let v = mesh.origin
                    + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
                    + DVec3::new(f64::from(low[0]), f64::from(low[1]), f64::from(low[2]));
                let d = v.length();
                assert!(
                    d >= lo - 1e-9 * hi && d <= hi + 1e-9 * hi,
                    "{key:?}: a vertex at radius {d}, outside [{lo}, {hi}]"
                );
            }
        }
    }
    assert!(bounded >= 5 * 6, "{bounded} patches had radii");
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
        check(d.normalize() * (r + 10f64.powf(alt)), 12.0, false)?;
    }

    // Bounded by their heights, views down to 10 m are few enough patches to mesh.
    #[test]
    fn tightly_bounded_patches_of_random_views_are_closed(x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0, alt in 1.0f64..6.5) {
        let d = DVec3::new(x, y, z);
        prop_assume!(d.length() > 0.1);
        let planet = planet();
        let mode = planet.heightfield_mode().unwrap();
        let dir = d.normalize();
        let ground = pmc_lod::probe::meshed_surface_radius(planet, dir, 0).unwrap_or(mode.datum());
        check(dir * (ground.max(mode.datum()) + 10f64.powf(alt)), 8.0, true)?;
    }
}
