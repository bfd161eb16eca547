//! The union of the selected patches is one closed surface with matching normals, for random
//! views of several planets.
use crate::common;

use common::{closure, normal_spread, sources, used};
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{Face, VoxelKey};
use pmc_heightfield::{
    check_selection, generate_patches, select, vertex_position, HeightfieldPlanet, LatticeHeights, SelectedPatch,
    Stitch, View, CANONICAL_RESOLUTION,
};
use pmc_mesh::{ChunkMesh, WeldedMesh};
use proptest::prelude::*;
use std::collections::HashMap;

/// Every stored vertex is `vertex_position` of its lattice point (recovered from its key at the
/// finest resolution), minus the origin, rounded to f32: a function of the point alone.
fn check_positions(heights: &dyn LatticeHeights, radius: f64, meshes: &[ChunkMesh]) {
    let mut cache: HashMap<u128, DVec3> = HashMap::new();
    for m in meshes {
        for (v, key) in m.edge_keys.iter().enumerate() {
            assert_eq!(key.0, key.1);
            let p = *cache.entry(key.0).or_insert_with(|| {
                let c = |s: u32| (((key.0 >> s) as u32) as i64 - (1 << 30)) as i32;
                let lattice = IVec3::new(c(96), c(64), c(32));
                assert_eq!(VoxelKey::new(lattice, 0).pack(), key.0);
                vertex_position(heights, radius, lattice, CANONICAL_RESOLUTION)
            });
            let d = p - m.origin;
            assert_eq!(m.positions[v], [d.x as f32, d.y as f32, d.z as f32]);
        }
    }
}

struct Outcome {
    patches: Vec<SelectedPatch>,
    meshes: Vec<ChunkMesh>,
}

fn run(view: &View, planet: &HeightfieldPlanet, heights: &dyn LatticeHeights) -> Outcome {
    let patches = select(view, planet).unwrap();
    check_selection(&patches).unwrap();
    let meshes = generate_patches(heights, planet.radius(), &patches).unwrap();
    let report = closure(&meshes);
    assert!(report.is_closed_manifold(), "{report:?} with {} patches", patches.len());
    assert_eq!(report.euler(), 2, "{report:?}");
    let (spread, shared) = normal_spread(&meshes);
    assert!(spread <= 1e-6, "co-located normals differ by {spread}");
    assert!(shared > 0);
    check_positions(heights, planet.radius(), &meshes);
    Outcome { patches, meshes }
}

fn camera(dir: (f64, f64, f64), altitude: f64, radius: f64) -> DVec3 {
    let d = DVec3::new(dir.0, dir.1, dir.2);
    let d = if d.length() < 1e-3 { DVec3::Y } else { d.normalize() };
    d * (radius * (1.0 + altitude))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_views_give_closed_surfaces(
        dir in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        altitude in prop_oneof![1e-4..1e-2f64, 1e-2..3.0f64],
        source in 0usize..3,
        radius in prop_oneof![Just(1.0f64), Just(6.371e6f64)],
        max_level in 2u8..6,
        pixels in 1.0..8.0f64,
        cull in any::<bool>(),
    ) {
        let s = &sources()[source];
        let planet = HeightfieldPlanet::new(radius, s.min * radius, s.max * radius, max_level).unwrap();
        let heights = Scaled { inner: s.heights.as_ref(), scale: radius };
        let mut view = View::perspective(camera(dir, altitude, radius), 1.0, 600.0, pixels);
        view.horizon_cull = cull;
        let out = run(&view, &planet, &heights);
        prop_assert_eq!(out.meshes.len(), out.patches.len());
    }
}

/// A unit-radius source scaled to a planet of `scale` metres (heights scale with the radius).
struct Scaled<'a> {
    inner: &'a dyn LatticeHeights,
    scale: f64,
}

impl LatticeHeights for Scaled<'_> {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        self.inner.height(lattice, m) * self.scale
    }
}

/// Views aimed at a cube corner, a face edge and a face centre put level seams across face edges
/// and at cube corners; check that they are there and that the surface is closed.
#[test]
fn seams_across_face_edges_and_cube_corners() {
    let radius = 1000.0;
    for s in sources() {
        let planet = HeightfieldPlanet::new(radius, s.min * radius, s.max * radius, 5).unwrap();
        let heights = Scaled {
            inner: s.heights.as_ref(),
            scale: radius,
        };
        for dir in [(-1.0, 1.0, -1.0), (1.0, 0.0, 1.0), (0.2, 0.1, -1.0)] {
            let view = View::perspective(camera(dir, 0.01, radius), 1.0, 600.0, 3.0);
            let out = run(&view, &planet, &heights);
            // Level seams that reach a face edge: a stitched side on the face's border.
            let edge_seams = out
                .patches
                .iter()
                .filter(|p| {
                    let n = (1u32 << p.key.level) - 1;
                    (p.key.i == 0 && p.stitch.side(pmc_heightfield::Side::MinU))
                        || (p.key.i == n && p.stitch.side(pmc_heightfield::Side::MaxU))
                        || (p.key.j == 0 && p.stitch.side(pmc_heightfield::Side::MinV))
                        || (p.key.j == n && p.stitch.side(pmc_heightfield::Side::MaxV))
                })
                .count();
            assert!(edge_seams > 0, "{} {dir:?}: no level seam across a face edge", s.name);
            let levels: std::collections::BTreeSet<u8> = out.patches.iter().map(|p| p.key.level).collect();
            assert!(levels.len() >= 3, "{levels:?}");
        }
    }
}

/// Without the stitching flags the same patches leave cracks: the check above is not vacuous.
#[test]
fn unstitched_level_seams_are_open() {
    let planet = HeightfieldPlanet::new(1000.0, -20.0, 20.0, 5).unwrap();
    let heights = common::FbmHeights::new(3, 2.0, 8, 20.0);
    let view = View::perspective(camera((1.0, 1.0, 1.0), 0.01, 1000.0), 1.0, 600.0, 2.0);
    let patches: Vec<SelectedPatch> = select(&view, &planet)
        .unwrap()
        .into_iter()
        .map(|p| SelectedPatch {
            stitch: Stitch::NONE,
            ..p
        })
        .collect();
    let meshes = generate_patches(&heights, 1000.0, &patches).unwrap();
    let report = closure(&meshes);
    assert!(report.boundary > 0, "{report:?}");
    // The same patches stitched are closed, and pmc-mesh's welder agrees.
    let stitched = select(&view, &planet).unwrap();
    let meshes = generate_patches(&heights, 1000.0, &stitched).unwrap();
    let welded = WeldedMesh::weld(&meshes).report();
    assert!(
        welded.is_closed_manifold() && welded.euler_characteristic() == 2,
        "{welded:?}"
    );
}

/// The whole planet at one level (no seams between levels) is closed too, and a cube corner's
/// three patches agree on its normal exactly.
#[test]
fn uniform_levels_are_closed() {
    let heights = common::FbmHeights::new(11, 3.0, 6, 5.0);
    for level in 0..3u8 {
        let n = 1u32 << level;
        let patches: Vec<SelectedPatch> = Face::ALL
            .into_iter()
            .flat_map(|face| (0..n * n).map(move |k| (face, k % n, k / n)))
            .map(|(face, i, j)| SelectedPatch {
                key: pmc_heightfield::PatchKey::new(face, level, i, j).unwrap(),
                stitch: Stitch::NONE,
                visible: true,
            })
            .collect();
        check_selection(&patches).unwrap();
        let meshes = generate_patches(&heights, 500.0, &patches).unwrap();
        let report = closure(&meshes);
        assert!(report.is_closed_manifold() && report.euler() == 2, "{report:?}");
        assert_eq!(normal_spread(&meshes).0, 0.0);
        for m in &meshes {
            assert!(used(m).into_iter().all(|u| u));
        }
    }
}
