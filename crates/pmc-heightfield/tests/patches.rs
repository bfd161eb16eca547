//! Single patches: the same lattice point gives the same vertex at every level, a stitched side
//! takes the coarser neighbour's edge and normals (also across a face edge and at a cube corner),
//! and misuse is refused with a clear message.
use crate::common::{closure, used, FbmHeights};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{EdgeKey, Face};
use pmc_heightfield::{
    generate_patch, select, vertex_canonical_lattice, vertex_position, Corner, HeightfieldPlanet, PatchError, PatchKey,
    Side, Stitch, View, MAX_LEVEL,
};
use pmc_mesh::ChunkMesh;
use std::collections::HashMap;

const RADIUS: f64 = 6.371e6;

fn heights() -> FbmHeights {
    FbmHeights::new(42, 700.0, 8, 3000.0)
}

fn mesh(key: PatchKey, stitch: Stitch) -> ChunkMesh {
    let mut m = ChunkMesh::default();
    generate_patch(&heights(), RADIUS, key, stitch, &mut m).unwrap();
    m
}

fn world(m: &ChunkMesh, v: usize) -> DVec3 {
    m.world_position(v)
}

#[test]
fn children_repeat_their_parent_bit_for_bit() {
    let h = heights();
    for (face, level, i, j) in [
        (Face::East, 9, 300, 17),
        (Face::Top, 0, 0, 0),
        (Face::North, 20, 1 << 19, 77),
    ] {
        let parent = PatchKey::new(face, level, i, j).unwrap();
        let pm = mesh(parent, Stitch::NONE);
        for (c, child) in parent.children().unwrap().into_iter().enumerate() {
            let cm = mesh(child, Stitch::NONE);
            let (oa, ob) = (32 * (c as u32 % 2), 32 * (c as u32 / 2));
            let mut shared = 0;
            for b in (0..=64u32).step_by(2) {
                for a in (0..=64u32).step_by(2) {
                    let cv = (b * 65 + a) as usize;
                    let pv = ((ob + b / 2) * 65 + oa + a / 2) as usize;
                    // The same point, the same identity, height and position bits.
                    assert_eq!(cm.edge_keys[cv], pm.edge_keys[pv]);
                    assert_eq!(cm.heights[cv].to_bits(), pm.heights[pv].to_bits());
                    let lc = child.vertex_lattice(i64::from(a), i64::from(b)).unwrap();
                    let lp = parent
                        .vertex_lattice(i64::from(oa + a / 2), i64::from(ob + b / 2))
                        .unwrap();
                    assert_eq!(lc, lp * 2);
                    let pc = vertex_position(&h, RADIUS, lc, child.resolution());
                    let pp = vertex_position(&h, RADIUS, lp, parent.resolution());
                    assert_eq!(pc.to_array().map(f64::to_bits), pp.to_array().map(f64::to_bits));
                    // Each mesh stores exactly that position, relative to its own origin.
                    let (dc, dp) = (pc - cm.origin, pp - pm.origin);
                    assert_eq!(cm.positions[cv], [dc.x as f32, dc.y as f32, dc.z as f32]);
                    assert_eq!(pm.positions[pv], [dp.x as f32, dp.y as f32, dp.z as f32]);
                    assert!((world(&cm, cv) - world(&pm, pv)).length() < 1e-6 * RADIUS);
                    shared += 1;
                }
            }
            assert_eq!(shared, 33 * 33);
        }
    }
}

/// A coarse patch and the two halves of its neighbour one level finer, stitched on the side that
/// faces it: the seam is closed and every shared vertex has the coarse patch's normal, bit for bit.
fn check_level_seam(coarse: PatchKey, side: Side) {
    let fine_parent = coarse.neighbour(side);
    let cm = mesh(coarse, Stitch::NONE);
    let mut meshes = vec![cm.clone()];
    let mut stitched_sides = 0;
    for child in fine_parent.children().unwrap() {
        // The child's sides that face the coarse patch.
        let mut stitch = Stitch::NONE;
        for s in Side::ALL {
            if child.neighbour(s).parent() == Some(coarse) {
                stitch = stitch.with_side(s);
                stitched_sides += 1;
            }
        }
        meshes.push(mesh(child, stitch));
    }
    assert_eq!(stitched_sides, 2, "{coarse} {side:?}");
    let mut normal_of: HashMap<EdgeKey, [f32; 3]> = HashMap::new();
    for (v, u) in used(&cm).into_iter().enumerate() {
        if u {
            normal_of.insert(cm.edge_keys[v], cm.normals[v]);
        }
    }
    let mut matched = 0;
    for m in &meshes[1..] {
        for (v, u) in used(m).into_iter().enumerate() {
            if let Some(n) = normal_of.get(&m.edge_keys[v]).filter(|_| u) {
                // Bit for bit, so in particular within 1e-6.
                assert_eq!(m.normals[v], *n, "{coarse} {side:?}");
                matched += 1;
            }
        }
    }
    assert_eq!(matched, 2 * 33, "{coarse} {side:?}");
    // The seam itself has no boundary edge: the boundary is the outline of the coarse patch and
    // of its neighbour's four children, less the seam (the coarse side's 64 edges all matched).
    let c = closure(&meshes);
    assert_eq!(c.non_manifold, 0, "{c:?}");
    assert_eq!(c.boundary, 3 * 64 + 3 * 128, "{c:?}");
}

#[test]
fn stitched_sides_take_the_coarser_edge_and_normals() {
    // Inside a face, across a face edge (several face pairs and orientations), at a cube corner.
    check_level_seam(PatchKey::new(Face::South, 4, 5, 9).unwrap(), Side::MaxU);
    for face in Face::ALL {
        let n = 7;
        check_level_seam(PatchKey::new(face, 3, 0, 3).unwrap(), Side::MinU);
        check_level_seam(PatchKey::new(face, 3, n, 4).unwrap(), Side::MaxU);
        check_level_seam(PatchKey::new(face, 3, 2, 0).unwrap(), Side::MinV);
        check_level_seam(PatchKey::new(face, 3, 5, n).unwrap(), Side::MaxV);
        check_level_seam(PatchKey::new(face, 3, 0, 0).unwrap(), Side::MinV);
        check_level_seam(PatchKey::new(face, 3, n, n).unwrap(), Side::MaxU);
    }
}

#[test]
fn cube_corner_normals_agree_at_both_spacings() {
    // The three level-2 patches at the corner (+X, +Y, +Z) share one vertex; with and without a
    // coarser neighbour flagged at that corner, all three agree on its normal.
    let corner = vertex_canonical_lattice(PatchKey::new(Face::East, 0, 0, 0).unwrap(), 64, 64).unwrap();
    for flagged in [false, true] {
        let mut normals = Vec::new();
        for face in Face::ALL {
            for key in [(0, 0), (3, 0), (0, 3), (3, 3)].map(|(i, j)| PatchKey::new(face, 2, i, j).unwrap()) {
                for c in Corner::ALL {
                    let (a, b) = c.vertex();
                    if vertex_canonical_lattice(key, a, b) == Some(corner) {
                        let stitch = if flagged {
                            Stitch::NONE.with_corner(c)
                        } else {
                            Stitch::NONE
                        };
                        let m = mesh(key, stitch);
                        normals.push(m.normals[(b * 65 + a) as usize]);
                    }
                }
            }
        }
        assert_eq!(normals.len(), 3);
        assert!(normals.iter().all(|n| *n == normals[0]), "{normals:?}");
        let d = DVec3::from(normals[0].map(f64::from));
        assert!(d.dot(corner.as_dvec3().normalize()) > 0.9, "points outward: {d:?}");
    }
}

#[test]
fn misuse_is_refused_with_a_clear_message() {
    let mut out = ChunkMesh::default();
    let h = heights();
    let deep = PatchKey {
        face: Face::Top,
        level: MAX_LEVEL + 1,
        i: 0,
        j: 0,
    };
    let e = generate_patch(&h, RADIUS, deep, Stitch::NONE, &mut out).unwrap_err();
    assert_eq!(
        e,
        PatchError::LevelTooDeep {
            level: 25,
            max: MAX_LEVEL
        }
    );
    assert_eq!(e.to_string(), "patch level 25 is deeper than the maximum level 24");
    let bad = PatchKey {
        face: Face::West,
        level: 2,
        i: 1,
        j: 4,
    };
    let e = generate_patch(&h, RADIUS, bad, Stitch::NONE, &mut out).unwrap_err();
    assert_eq!(
        e.to_string(),
        "patch index (1, 4) is out of range for level 2 (a face side has 4 patches)"
    );
    let ok = PatchKey::root(Face::West);
    let e = generate_patch(&h, f64::NAN, ok, Stitch::NONE, &mut out).unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
    assert!(HeightfieldPlanet::new(RADIUS, 10.0, -10.0, 5).is_err());
    assert!(HeightfieldPlanet::new(RADIUS, 0.0, 1.0, MAX_LEVEL + 1)
        .unwrap_err()
        .to_string()
        .contains("deeper"));
    let planet = HeightfieldPlanet::new(RADIUS, 0.0, 1.0, 5).unwrap();
    assert!(planet.clone().with_level_errors(vec![1.0; 3]).is_err());
    assert!(planet
        .clone()
        .with_level_errors(vec![1.0, 1.0, 1.0, -1.0, 1.0, 1.0])
        .is_err());
    let view = View::perspective(DVec3::new(0.0, 0.0, 2.0 * RADIUS), 1.0, 600.0, 0.0);
    assert!(select(&view, &planet)
        .unwrap_err()
        .to_string()
        .contains("max_pixel_error"));
    // The deepest level works, and its positions are fine at Earth radius.
    let n = 1u32 << MAX_LEVEL;
    let deepest = PatchKey::new(Face::South, MAX_LEVEL, n / 2, n / 2).unwrap();
    let m = mesh(deepest, Stitch::NONE);
    let spacing = (world(&m, 1) - world(&m, 0)).length();
    assert!(spacing > 0.003 && spacing < 0.03, "{spacing}");
}

#[test]
fn the_depth_cap_and_far_views() {
    let planet = HeightfieldPlanet::new(RADIUS, -11_000.0, 9_000.0, 12).unwrap();
    // On the ground: the cap is reached near the camera.
    let cam = DVec3::new(0.3, 0.5, 0.8).normalize() * (RADIUS + 9_500.0);
    let near = select(&View::perspective(cam, 1.0, 1080.0, 2.0), &planet).unwrap();
    pmc_heightfield::check_selection(&near).unwrap();
    assert_eq!(near.iter().map(|p| p.key.level).max(), Some(12));
    assert!(near.iter().any(|p| !p.visible), "the far side is culled");
    // Far away: the six roots.
    let far = select(&View::perspective(cam * 1e4, 1.0, 1080.0, 2.0), &planet).unwrap();
    assert_eq!(far.len(), 6);
    assert!(far.iter().all(|p| p.stitch.is_none()));
}

#[test]
fn bounding_spheres_hold_every_vertex_and_culled_patches_are_hidden() {
    let planet = HeightfieldPlanet::new(RADIUS, -3000.0, 3000.0, 10).unwrap();
    let keys = [
        PatchKey::root(Face::Top),
        PatchKey::new(Face::East, 1, 1, 0).unwrap(),
        PatchKey::new(Face::South, 3, 0, 7).unwrap(),
        PatchKey::new(Face::West, 6, 63, 20).unwrap(),
        PatchKey::new(Face::Bottom, 10, 512, 1023).unwrap(),
    ];
    for key in keys {
        let s = planet.bounding_sphere(key);
        let m = mesh(key, Stitch::NONE);
        for v in 0..m.vertex_count() {
            assert!((world(&m, v) - s.center).length() <= s.radius, "{key}");
        }
    }
    // Culled patches: every vertex lies behind the occluder ball seen from the camera.
    let cam = DVec3::new(-0.2, 0.9, 0.4).normalize() * (RADIUS + 400_000.0);
    let view = View::perspective(cam, 1.0, 1080.0, 2.0);
    let patches = select(&view, &planet).unwrap();
    let rho = planet.occluder_radius();
    let hidden: Vec<_> = patches.iter().filter(|p| !p.visible).collect();
    assert!(!hidden.is_empty());
    for p in hidden.iter().step_by(7) {
        let m = mesh(p.key, p.stitch);
        for v in (0..m.vertex_count()).step_by(13) {
            let q = world(&m, v);
            // Closest approach of the segment cam -> q to the centre is inside the ball.
            let d = q - cam;
            let t = (-cam.dot(d) / d.length_squared()).clamp(0.0, 1.0);
            assert!((cam + d * t).length() < rho, "{} vertex {v}", p.key);
        }
    }
}

#[test]
fn parallel_generation_equals_one_by_one() {
    let planet = HeightfieldPlanet::new(RADIUS, -3000.0, 3000.0, 6).unwrap();
    let view = View::perspective(DVec3::new(1.0, 0.2, 0.1).normalize() * (RADIUS * 1.05), 1.0, 720.0, 4.0);
    let patches = select(&view, &planet).unwrap();
    let h = heights();
    let parallel = pmc_heightfield::generate_patches(&h, RADIUS, &patches).unwrap();
    assert_eq!(parallel.len(), patches.len());
    for (p, m) in patches.iter().zip(&parallel).step_by(5) {
        assert_eq!(*m, mesh(p.key, p.stitch));
    }
}
