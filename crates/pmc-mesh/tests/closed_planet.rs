//! The union of all chunk meshes of a planet is a closed, consistently oriented 2-manifold:
//! every edge is shared by exactly two triangles, across chunk borders, face edges and cube
//! corners, with vertices identified by their canonical grid edge (no welding tolerance).

use pmc_density::{Density, FnDensity, Sphere};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, EdgeKey, Layout};
use pmc_mesh::{close_shell, ChunkMesh, Mesher, WeldedMesh};
use proptest::prelude::*;
use std::collections::HashMap;

fn mesh_planet(layout: &Layout, density: &dyn Density) -> Vec<ChunkMesh> {
    let mut mesher = Mesher::new();
    let mut out = Vec::new();
    for key in layout.chunks(0) {
        let grid = ChunkGrid::new(layout, key);
        let radii = &grid.radii;
        let mut d = vec![0.0f32; grid.sample_count()];
        density.sample_shell(&grid.dirs, radii, &mut d);
        close_shell(&grid, layout.depth_tiles(), &mut d);
        let mut m = ChunkMesh::default();
        mesher.mesh(&grid, &d, &mut m);
        out.push(m);
    }
    out
}

fn check_closed(w: &WeldedMesh) -> i64 {
    let r = w.report();
    assert!(r.is_closed_manifold(), "not a closed manifold: {r:?}");
    r.euler_characteristic()
}

#[test]
fn sphere_is_closed_with_euler_2_and_the_right_volume() {
    let layout = Layout::new(4, 16, 60.0, 1.0, 2).unwrap();
    let r = 60.0 + 16.37;
    let meshes = mesh_planet(&layout, &Sphere { radius: r });
    let w = WeldedMesh::weld(&meshes);
    assert_eq!(check_closed(&w), 2);
    let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let v = w.volume();
    assert!((v - exact).abs() / exact < 0.005, "volume {v} vs {exact}");
    // Every vertex lies on the sphere: radial edges cut it exactly.
    for p in &w.positions {
        assert!(
            (p.length() - r).abs() < 1e-3,
            "vertex off the sphere by {}",
            p.length() - r
        );
    }
}

#[test]
fn normals_agree_across_chunk_and_face_borders() {
    let layout = Layout::new(2, 8, 40.0, 1.0, 2).unwrap();
    let f = FnDensity(|p: DVec3| 48.3 - p.length() + 2.0 * (p.x * 0.21).sin() * (p.z * 0.17).cos());
    let meshes = mesh_planet(&layout, &f);
    let mut seen: HashMap<EdgeKey, ([u32; 3], [f32; 3])> = HashMap::new();
    let mut shared = 0;
    for m in &meshes {
        for i in 0..m.vertex_count() {
            let wp = m.world_position(i);
            let n = m.normals[i];
            let bits = [wp.x as f32, wp.y as f32, wp.z as f32].map(f32::to_bits);
            if let Some((pb, pn)) = seen.insert(m.edge_keys[i], (bits, n)) {
                shared += 1;
                let dp: Vec<f32> = (0..3)
                    .map(|k| (f32::from_bits(pb[k]) - f32::from_bits(bits[k])).abs())
                    .collect();
                assert!(dp.iter().all(|d| *d < 1e-3), "shared vertex moved: {dp:?}");
                let dot = pn[0] * n[0] + pn[1] * n[1] + pn[2] * n[2];
                assert!(dot > 0.99, "shared vertex normals disagree: {pn:?} vs {n:?}");
            }
        }
    }
    assert!(shared > 100, "the test surface crosses chunk borders");
}

/// A hash-based value field: rough, with many ambiguous cube configurations.
fn rough_field(seed: u64, scale: f64, base: f64) -> impl Fn(DVec3) -> f64 + Send + Sync {
    move |p: DVec3| {
        let q = (p * scale).floor();
        let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
        for c in [q.x, q.y, q.z] {
            h ^= (c as i64 as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 31)).wrapping_mul(0x94D0_49BB_1331_11EB);
        }
        let noise = (h >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        base - p.length() + noise * 8.0
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn random_fields_mesh_to_closed_manifolds(seed in any::<u64>(), n_c in 1u32..3, n_t in 2u32..7, d_c in 1u32..3, scale in 0.3f64..1.5) {
        let layout = Layout::new(n_c, n_t, 20.0, 1.0, d_c).unwrap();
        let mid = 20.0 + f64::from(n_t * d_c) * 0.5;
        let f = FnDensity(rough_field(seed, scale, mid));
        let meshes = mesh_planet(&layout, &f);
        let w = WeldedMesh::weld(&meshes);
        prop_assert!(!w.triangles.is_empty());
        check_closed(&w);
    }
}

/// Degenerate iso values: samples exactly on the surface (density 0) count as air, so vertices may
/// land exactly on voxels and triangles may have zero area, yet the surface stays a closed
/// manifold and no vertex is lost or duplicated.
#[test]
fn exact_zero_samples_keep_the_surface_closed() {
    let layout = Layout::new(2, 8, 40.0, 1.0, 2).unwrap();
    // Integer-valued density: every voxel whose layer radius rounds to 48 sits exactly on it.
    let f = FnDensity(|p: DVec3| (48.0 - p.length() + 1.5 * (p.x * 0.3).sin()).round());
    let mut zeros = 0;
    for key in layout.chunks(0) {
        let grid = ChunkGrid::new(&layout, key);
        let mut d = vec![0.0f32; grid.sample_count()];
        f.sample_shell(&grid.dirs, &grid.radii, &mut d);
        zeros += d.iter().filter(|v| **v == 0.0).count();
    }
    assert!(zeros > 1000, "the field has exact zeros: {zeros}");
    let meshes = mesh_planet(&layout, &f);
    let w = WeldedMesh::weld(&meshes);
    check_closed(&w);
    for m in &meshes {
        assert!(
            m.normals.iter().all(|n| n.iter().all(|c| c.is_finite())),
            "finite normals"
        );
        assert!(m.positions.iter().all(|p| p.iter().all(|c| c.is_finite())));
    }
}

#[test]
fn nan_samples_become_air_and_the_surface_stays_closed() {
    let layout = Layout::new(1, 8, 40.0, 1.0, 2).unwrap();
    let f = FnDensity(|p: DVec3| {
        if (p.x * 0.7).sin() > 0.9 {
            f64::NAN
        } else {
            48.3 - p.length()
        }
    });
    let w = WeldedMesh::weld(&mesh_planet(&layout, &f));
    check_closed(&w);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]
    /// Every vertex knows its grid edge (`ChunkMesh::vertex_edges`): two adjacent samples, one
    /// solid and one not, with the vertex on the segment between them; and a vertex shared by
    /// neighbouring chunks (the same edge key) finds the same two directions, in the same order,
    /// at the same place between them, so what a shader reads from the ends agrees across seams.
    #[test]
    fn vertices_know_their_grid_edge_the_same_way_in_every_chunk(seed in any::<u64>(), n_t in 2u32..6, scale in 0.3f64..1.5) {
        let layout = Layout::new(2, n_t, 20.0, 1.0, 2).unwrap();
        let mid = 20.0 + f64::from(n_t * 2) * 0.5;
        let f = FnDensity(rough_field(seed, scale, mid));
        let mut mesher = Mesher::new();
        let mut seen: HashMap<EdgeKey, ([u64; 3], [u64; 3], f64)> = HashMap::new();
        let mut shared = 0;
        for key in layout.chunks(0) {
            let grid = ChunkGrid::new(&layout, key);
            let mut d = vec![0.0f32; grid.sample_count()];
            f.sample_shell(&grid.dirs, &grid.radii, &mut d);
            close_shell(&grid, layout.depth_tiles(), &mut d);
            let mut m = ChunkMesh::default();
            mesher.mesh(&grid, &d, &mut m);
            let edges = &m.vertex_edges;
            prop_assert_eq!(edges.len(), m.vertex_count());
            let p = grid.padded;
            let coords = |x: u32| {
                let x = x as usize;
                [x % p, (x / p) % p, x / (p * p)]
            };
            for (i, e) in edges.iter().enumerate() {
                let (f_, s) = (coords(e[0]), coords(e[1]));
                let steps: usize = (0..3).map(|k| f_[k].abs_diff(s[k])).sum();
                prop_assert_eq!(steps, 1, "adjacent samples");
                let solid = |x: u32| pmc_mesh::is_solid(d[x as usize]);
                prop_assert!(solid(e[0]) != solid(e[1]), "the surface crosses the edge");
                let w = m.world_position(i);
                let ve = grid.vertex_edge(*e, w);
                let pf = grid.position(f_[0], f_[1], f_[2]);
                let ps = grid.position(s[0], s[1], s[2]);
                let on = pf + (ps - pf) * if ve.a == ve.b { (w - pf).length() / (ps - pf).length() } else { ve.t };
                prop_assert!((on - w).length() < 1e-4, "vertex {i} off its edge by {}", (on - w).length());
                let bits = |v: DVec3| v.to_array().map(f64::to_bits);
                let found = (bits(grid.dirs[ve.a as usize]), bits(grid.dirs[ve.b as usize]), ve.t);
                if let Some(before) = seen.insert(m.edge_keys[i], found) {
                    shared += 1;
                    prop_assert_eq!(before.0, found.0);
                    prop_assert_eq!(before.1, found.1);
                    prop_assert!((before.2 - found.2).abs() < 1e-6, "t {} against {}", before.2, found.2);
                }
            }
        }
        prop_assert!(shared > 0, "some vertices lie on chunk borders");
    }
}
