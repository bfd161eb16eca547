//! Remeshing only the cubes around changed samples gives the bytes of meshing them all.

use pmc_density::{Density, FnDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Face, Layout};
use pmc_mesh::{close_shell, ChunkMesh, CubeBox, Mesher};
use proptest::prelude::*;

/// A bumpy sphere through the middle of the shell.
fn field(seed: u64, mid: f64) -> impl Fn(DVec3) -> f64 + Send + Sync {
    move |p: DVec3| {
        let q = (p * 0.7).floor();
        let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
        for c in [q.x, q.y, q.z] {
            h ^= (c as i64 as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 31)).wrapping_mul(0x94D0_49BB_1331_11EB);
        }
        mid - p.length() + ((h >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 6.0
    }
}

fn samples(layout: &Layout, grid: &ChunkGrid, seed: u64) -> Vec<f32> {
    let mid = 20.0 + f64::from(layout.n_t() * layout.d_c()) * 0.5;
    let mut d = vec![0.0f32; grid.sample_count()];
    FnDensity(field(seed, mid)).sample_shell(&grid.dirs, &grid.radii, &mut d);
    close_shell(grid, layout.depth_tiles(), &mut d);
    d
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn remeshing_the_cubes_around_changed_samples_gives_the_full_meshes_bytes(
        seed in any::<u64>(),
        k in 0u32..2,
        lo in prop::array::uniform3(0usize..9),
        size in prop::array::uniform3(0usize..4),
        solid in any::<bool>(),
        noise in any::<u64>(),
    ) {
        let layout = Layout::new(1, 6, 20.0, 1.0, 2).unwrap();
        let key = ChunkKey { face: Face::Top, level: 0, i: 0, j: 0, k };
        let grid = ChunkGrid::new(&layout, key);
        let p = grid.padded;
        let before = samples(&layout, &grid, seed);
        let mut mesher = Mesher::new();
        let mut previous = ChunkMesh::default();
        mesher.mesh(&grid, &before, &mut previous);
        // Change a box of samples (carve or fill it).
        let hi: [usize; 3] = std::array::from_fn(|a| (lo[a] + size[a]).min(p - 1));
        let lo = lo.map(|x| x.min(p - 1));
        let mut after = before.clone();
        for c in lo[2]..=hi[2] {
            for b in lo[1]..=hi[1] {
                for a in lo[0]..=hi[0] {
                    let d = &mut after[grid.index(a, b, c)];
                    *d = if solid { d.abs() + 0.5 } else { -d.abs() - 0.5 };
                }
            }
        }
        close_shell(&grid, layout.depth_tiles(), &mut after);
        let mut full = ChunkMesh::default();
        mesher.mesh(&grid, &after, &mut full);
        // Only the region's samples are given; the rest is noise the remesher must not read.
        let region = CubeBox::around_samples(lo, hi, grid.tiles);
        let mut partial = vec![f32::NAN; after.len()];
        let mut h = noise;
        for (i, v) in partial.iter_mut().enumerate() {
            h = (h ^ i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            *v = ((h >> 40) as f32 - 8_388_608.0) / 1000.0;
        }
        if let Some(r) = region {
            let (slo, shi) = r.samples();
            for c in slo[2]..=shi[2] {
                for b in slo[1]..=shi[1] {
                    for a in slo[0]..=shi[0] {
                        partial[grid.index(a, b, c)] = after[grid.index(a, b, c)];
                    }
                }
            }
        }
        let (mut out, mut copied) = (ChunkMesh::default(), Vec::new());
        prop_assert!(mesher.remesh_cubes(&grid, &partial, &previous, region, &mut out, &mut copied));
        prop_assert!(out == full, "region {region:?}: {} against {} triangles", out.triangle_count(), full.triangle_count());
        // A copied vertex is its previous vertex, bit for bit.
        prop_assert_eq!(copied.len(), out.vertex_count());
        for (i, &j) in copied.iter().enumerate().filter(|(_, j)| **j != u32::MAX) {
            let j = j as usize;
            prop_assert!(out.positions[i] == previous.positions[j] && out.normals[i] == previous.normals[j]);
            prop_assert!(out.edge_keys[i] == previous.edge_keys[j] && out.vertex_edges[i] == previous.vertex_edges[j]);
        }
    }
}

#[test]
fn nothing_changed_copies_the_mesh_and_a_foreign_mesh_is_refused() {
    let layout = Layout::new(1, 6, 20.0, 1.0, 2).unwrap();
    let key = ChunkKey {
        face: Face::Top,
        level: 0,
        i: 0,
        j: 0,
        k: 1,
    };
    let grid = ChunkGrid::new(&layout, key);
    let d = samples(&layout, &grid, 5);
    let mut mesher = Mesher::new();
    let mut previous = ChunkMesh::default();
    mesher.mesh(&grid, &d, &mut previous);
    assert!(!previous.is_empty() && previous.cube_runs.len() > 10);
    let unread = vec![f32::NAN; d.len()];
    let (mut out, mut copied) = (ChunkMesh::default(), Vec::new());
    assert!(mesher.remesh_cubes(&grid, &unread, &previous, None, &mut out, &mut copied));
    assert_eq!(out, previous);
    assert!(
        copied.iter().enumerate().all(|(i, j)| *j as usize == i),
        "every vertex copied in place"
    );
    // Another chunk's mesh, a mesh without its records, one with a truncated run list.
    let other = ChunkGrid::new(&layout, ChunkKey { k: 0, ..key });
    assert!(!mesher.remesh_cubes(&other, &unread, &previous, None, &mut out, &mut copied));
    assert!(out.is_empty() && out.vertex_count() == 0 && copied.is_empty());
    let mut bare = previous.clone();
    bare.vertex_edges.clear();
    assert!(!mesher.remesh_cubes(&grid, &unread, &bare, None, &mut out, &mut copied));
    let mut cut = previous.clone();
    cut.cube_runs.pop();
    assert!(!mesher.remesh_cubes(&grid, &unread, &cut, None, &mut out, &mut copied));
}
