//! Properties of the selection: a partition of the shell, 2:1 balance across sides, edges and
//! corners (face edges and cube corners included), no checkerboard around an edge, seam masks,
//! culling soundness, budget and determinism.

use crate::common::{
    assert_balanced, assert_coarser_masks, assert_no_checkerboard, assert_partition, leaves_covering, small_layouts,
    voxel_owners,
};
use pmc_geometry::glam::{DVec3, DVec4};
use pmc_geometry::{sphere_to_face_uv, ChunkKey, Layout};
use pmc_lod::bounds::{chunk_sphere, BoundingSphere};
use pmc_lod::{frustum_planes, sphere_below_horizon, sphere_in_frustum, LodParams, Selection, Selector, View};
use proptest::prelude::*;

/// An error table that doubles per level, `scale` metres at level 1.
fn doubling(layout: &Layout, scale: f64) -> Vec<f64> {
    (0..=layout.max_level())
        .map(|l| {
            if l == 0 {
                0.0
            } else {
                scale * f64::from(1u32 << (l - 1))
            }
        })
        .collect()
}

fn view(eye: DVec3) -> View {
    View {
        eye,
        frustum: None,
        viewport_height_px: 1080.0,
        fov_y: 1.0,
    }
}

/// The level-0 chunk holding point `p` (inside the shell).
fn level0_chunk_at(layout: &Layout, p: DVec3) -> ChunkKey {
    let (face, u, v) = sphere_to_face_uv(p).unwrap();
    let n = layout.n_c();
    let cell = |t: f64| (((t + 1.0) * 0.5 * f64::from(n)) as u32).min(n - 1);
    let k = ((p.length() - layout.d_b()) / (layout.l_d() * f64::from(layout.n_t()))) as u32;
    ChunkKey::new(face, cell(u), cell(v), k.min(layout.d_c() - 1))
}

fn check_structure(layout: &Layout, selection: &Selection) -> usize {
    assert_partition(layout, selection);
    let owners = voxel_owners(layout, selection);
    assert_balanced(selection, &owners);
    assert_coarser_masks(layout, selection);
    let sorted = selection.chunks.windows(2).all(|w| w[0].key < w[1].key);
    assert!(sorted, "leaves in key order");
    assert_no_checkerboard(layout, selection, &owners)
}

fn unit(d: [f64; 3]) -> DVec3 {
    let v = DVec3::from_array(d);
    if v.length() < 1e-3 {
        DVec3::Y
    } else {
        v.normalize()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random eyes inside the planet, near its surface and far outside, with and without a
    /// frustum: the leaves partition the shell, are balanced across every kind of contact, have
    /// no checkerboard, and their seam masks match a brute-force lookup.
    #[test]
    fn selections_are_balanced_partitions(
        which in 0usize..2,
        dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        look in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        height in prop_oneof![0.0f64..1.0, 0.9f64..1.2, 1.2f64..20.0],
        scale in 0.05f64..4.0,
        pixels in 0.5f64..8.0,
        finest in 0u8..2,
        with_frustum in any::<bool>(),
    ) {
        let layout = small_layouts()[which];
        let eye = unit(dir) * height * layout.radius();
        let frustum = with_frustum.then(|| frustum_planes(eye, unit(look), DVec3::Y, 1.0, 1.5, 0.1, 1e5));
        let selector = Selector::new(layout, doubling(&layout, scale), 0.95 * layout.d_b()).unwrap();
        let params = LodParams { max_pixel_error: pixels, finest_level: finest, max_chunks: usize::MAX };
        let selection = selector.select(&View { frustum, ..view(eye) }, &params).unwrap();
        prop_assert!(!selection.truncated);
        check_structure(&layout, &selection);
        prop_assert!(selection.chunks.iter().all(|s| s.key.level >= finest));
    }
}

/// Eyes chosen to make deep refinement next to face edges and cube corners, where the balance
/// and the checkerboard rule must see across faces.
#[test]
fn refinement_at_face_edges_and_cube_corners_stays_balanced() {
    let mut examined = 0;
    let mut coarser_sides = 0;
    for layout in small_layouts() {
        let selector = Selector::new(layout, doubling(&layout, 1.0), 0.0).unwrap();
        let r = layout.radius() - 0.5;
        for dir in [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 0.2),
            DVec3::new(0.3, 1.0, 0.0),
        ] {
            for pixels in [1.0, 4.0, 30.0] {
                let params = LodParams {
                    max_pixel_error: pixels,
                    ..LodParams::default()
                };
                let s = selector.select(&view(dir.normalize() * r), &params).unwrap();
                examined += check_structure(&layout, &s);
                coarser_sides += s.chunks.iter().filter(|c| !c.coarser.is_empty()).count();
            }
        }
    }
    assert!(examined > 0, "no line with four leaves around it was examined");
    assert!(coarser_sides > 0, "no level transitions were produced");
}

#[test]
fn a_far_camera_selects_only_the_roots() {
    for layout in small_layouts() {
        let selector = Selector::new(layout, doubling(&layout, 2.0), layout.d_b()).unwrap();
        let s = selector
            .select(
                &view(DVec3::new(3.0, 1.0, 2.0).normalize() * 1e7),
                &LodParams::default(),
            )
            .unwrap();
        let roots = layout.chunks(layout.max_level());
        assert_eq!(s.chunks.iter().map(|c| c.key).collect::<Vec<_>>(), roots);
        assert!(s.chunks.iter().all(|c| c.coarser.is_empty()));
        assert!(!s.truncated);
        let h = s.level_histogram();
        assert_eq!(h[usize::from(layout.max_level())], roots.len());
    }
}

#[test]
fn a_camera_on_the_surface_gets_the_finest_level_under_it() {
    for layout in small_layouts() {
        let selector = Selector::new(layout, doubling(&layout, 0.1), layout.d_b()).unwrap();
        for dir in [DVec3::Y, DVec3::new(0.2, -0.4, 0.9), DVec3::new(1.0, 1.0, 1.0)] {
            let surface = dir.normalize() * (layout.d_b() + 0.6 * (layout.radius() - layout.d_b()));
            let s = selector.select(&view(surface), &LodParams::default()).unwrap();
            let under = level0_chunk_at(&layout, surface);
            let leaf = s.covering(&under).unwrap();
            assert_eq!(leaf.key.level, 0, "{under} is under a level {} leaf", leaf.key.level);
            assert!(leaf.drawn);
            // And coarser far away: the antipode's leaf is coarser than the one underfoot.
            let far = s.covering(&level0_chunk_at(&layout, -surface)).unwrap();
            assert!(far.key.level > 0);
            // The finest level cap holds.
            let capped = selector
                .select(
                    &view(surface),
                    &LodParams {
                        finest_level: 1,
                        ..LodParams::default()
                    },
                )
                .unwrap();
            assert_eq!(capped.covering(&under).unwrap().key.level, 1);
        }
    }
}

#[test]
fn selections_are_deterministic() {
    let layout = Layout::default();
    let selector = Selector::new(layout, vec![0.0, 1.0, 3.0, 8.0], 1800.0).unwrap();
    let eye = DVec3::new(0.4, 0.8, -0.3).normalize() * 2050.0;
    let frustum = Some(frustum_planes(eye, -eye, DVec3::Z, 1.0, 1.6, 1.0, 1e5));
    let v = View { frustum, ..view(eye) };
    let a = selector.select(&v, &LodParams::default()).unwrap();
    let b = selector.clone().select(&v, &LodParams::default()).unwrap();
    assert_eq!(a, b);
    let budget = LodParams {
        max_chunks: 200,
        ..LodParams::default()
    };
    assert_eq!(
        selector.select(&v, &budget).unwrap(),
        selector.select(&v, &budget).unwrap()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// A budget is never exceeded (beyond the roots); a selection that fits is unchanged by it;
    /// a cut selection is still a balanced partition, finer near the eye than far from it.
    #[test]
    fn the_budget_is_kept(
        which in 0usize..2,
        dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        height in 0.95f64..1.5,
        budget in 0usize..800,
    ) {
        let layout = small_layouts()[which];
        let selector = Selector::new(layout, doubling(&layout, 1.0), 0.0).unwrap();
        let eye = unit(dir) * height * layout.radius();
        let full = selector.select(&view(eye), &LodParams { max_chunks: usize::MAX, ..LodParams::default() }).unwrap();
        let params = LodParams { max_chunks: budget, ..LodParams::default() };
        let cut = selector.select(&view(eye), &params).unwrap();
        let roots = layout.chunks(layout.max_level()).len();
        prop_assert!(cut.chunks.len() <= budget.max(roots));
        if full.chunks.len() <= budget {
            prop_assert_eq!(&cut, &full);
            prop_assert!(!cut.truncated);
        } else {
            prop_assert!(cut.truncated);
            check_structure(&layout, &cut);
            let near = cut.covering(&level0_chunk_at(&layout, eye.normalize() * layout.radius() * 0.999)).unwrap();
            let far = cut.covering(&level0_chunk_at(&layout, -eye.normalize() * layout.radius() * 0.999)).unwrap();
            prop_assert!(near.key.level <= far.key.level);
        }
    }
}

/// Points spread through a sphere: its centre, and points on shells at several radii.
fn sphere_points(s: &BoundingSphere, rng: &mut impl FnMut() -> f64) -> Vec<DVec3> {
    let mut out = vec![s.center];
    for _ in 0..200 {
        let d = DVec3::new(rng() * 2.0 - 1.0, rng() * 2.0 - 1.0, rng() * 2.0 - 1.0);
        if d.length() < 1e-3 {
            continue;
        }
        let t = [1.0, 0.999, 0.9, 0.5][out.len() % 4];
        out.push(s.center + d.normalize() * s.radius * t);
    }
    out
}

fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed.wrapping_mul(2862933555777941757).wrapping_add(3037000493);
    move || {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn inside(planes: &[DVec4; 6], p: DVec3) -> bool {
    planes.iter().all(|q| q.truncate().dot(p) + q.w >= 0.0)
}

/// Whether the segment from `eye` to `p` meets the ball of radius `r` around the origin.
fn segment_meets_ball(eye: DVec3, p: DVec3, r: f64) -> bool {
    let d = p - eye;
    let t = (-eye.dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (eye + d * t).length() <= r
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A sphere with any point inside the frustum is never reported outside it.
    #[test]
    fn frustum_culling_is_sound(
        eye in [-300.0f64..300.0, -300.0f64..300.0, -300.0f64..300.0],
        look in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        fov in 0.2f64..2.5,
        aspect in 0.3f64..3.0,
        center in [-300.0f64..300.0, -300.0f64..300.0, -300.0f64..300.0],
        radius in 0.0f64..150.0,
        seed in any::<u64>(),
    ) {
        let eye = DVec3::from_array(eye);
        let planes = frustum_planes(eye, unit(look), DVec3::new(0.1, 1.0, 0.2), fov, aspect, 0.5, 400.0);
        let s = BoundingSphere { center: DVec3::from_array(center), radius };
        if !sphere_in_frustum(&planes, &s) {
            for p in sphere_points(&s, &mut lcg(seed)) {
                prop_assert!(!inside(&planes, p), "a point of a culled sphere is inside the frustum");
            }
        }
    }

    /// A sphere reported below the horizon has no point that the occluder leaves in sight.
    #[test]
    fn horizon_culling_is_sound(
        eye_dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        eye_height in 1.0001f64..5.0,
        dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        height in 0.2f64..1.3,
        radius in 0.0f64..0.5,
        seed in any::<u64>(),
    ) {
        let r = 100.0;
        let eye = unit(eye_dir) * eye_height * r;
        let s = BoundingSphere { center: unit(dir) * height * r, radius: radius * r };
        if sphere_below_horizon(eye, r, &s) {
            for p in sphere_points(&s, &mut lcg(seed)) {
                prop_assert!(segment_meets_ball(eye, p, r * (1.0 + 1e-12)), "{p} is in sight");
            }
        }
    }
}

/// Horizon culling is not vacuous: low over the surface most of the planet is hidden, and the
/// selection marks exactly the chunks the two tests keep as drawn.
#[test]
fn culling_hides_the_far_side_and_matches_the_tests() {
    let layout = Layout::new(8, 4, 100.0, 1.0, 3).unwrap();
    let occluder = layout.d_b();
    let selector = Selector::new(layout, doubling(&layout, 0.5), occluder).unwrap();
    let eye = DVec3::new(0.3, 0.9, 0.1).normalize() * (layout.radius() + 2.0);
    let frustum = frustum_planes(eye, DVec3::new(1.0, -0.2, 0.0), eye, 1.0, 1.5, 0.1, 1e4);
    let s = selector
        .select(
            &View {
                frustum: Some(frustum),
                ..view(eye)
            },
            &LodParams::default(),
        )
        .unwrap();
    let mut hidden = 0;
    for c in &s.chunks {
        let sphere = chunk_sphere(&layout, &c.key);
        let below = sphere_below_horizon(eye, occluder, &sphere);
        hidden += usize::from(below);
        assert_eq!(c.drawn, sphere_in_frustum(&frustum, &sphere) && !below, "{}", c.key);
    }
    assert!(hidden * 3 > s.chunks.len(), "{hidden} of {} hidden", s.chunks.len());
    assert!(s.drawn().count() > 0);
    // Culled chunks still count for balance: the same eye without a frustum gives the same
    // leaves.
    let all = selector.select(&view(eye), &LodParams::default()).unwrap();
    let keys = |s: &Selection| s.chunks.iter().map(|c| (c.key, c.coarser)).collect::<Vec<_>>();
    assert_eq!(keys(&all), keys(&s));
    // Chunks under the eye are drawn when nothing culls by frustum.
    let under = leaves_covering(
        &all,
        &level0_chunk_at(&layout, eye.normalize() * (layout.radius() - 1.0)),
    );
    assert!(all.chunks[under[0]].drawn);
}
