//! Synthetic chunk meshes for the tests (and the `write_samples` example).
#![allow(dead_code)]

use pmc_formats::ExportMeta;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, EdgeKey, Face};
use pmc_mesh::ChunkMesh;
use std::collections::HashMap;
use std::path::PathBuf;

/// A closed box `centre + [-h, h]^3 * scale`, each face cut into `2h x 2h` quads, split into three
/// chunk meshes (by the sign of the triangle centroid's x, then y) with origins `centre +
/// offsets[c]`. Vertex keys are the lattice points, so equal keys in different chunks are the
/// same vertex.
///
/// Welded it has `6 (2h+1)^2 - 12 (2h+1) + 8` vertices and `48 h^2` triangles.
pub fn split_box(h: i32, scale: f64, centre: DVec3, offsets: [DVec3; 3], attributes: bool) -> Vec<ChunkMesh> {
    let mut chunks: Vec<ChunkMesh> = (0..3)
        .map(|c| ChunkMesh {
            key: if c == 1 {
                None
            } else {
                Some(ChunkKey::new(Face::ALL[c], c as u32, 2, 1))
            },
            origin: centre + offsets[c],
            ..Default::default()
        })
        .collect();
    let mut maps: Vec<HashMap<[i32; 3], u32>> = vec![HashMap::new(); 3];
    for axis in 0..3 {
        for sign in [-1i32, 1] {
            // u x v = outward normal.
            let (mut ua, mut va) = ((axis + 1) % 3, (axis + 2) % 3);
            if sign < 0 {
                std::mem::swap(&mut ua, &mut va);
            }
            let at = |i: i32, j: i32| {
                let mut p = [0i32; 3];
                p[axis] = sign * h;
                p[ua] = i;
                p[va] = j;
                p
            };
            for i in -h..h {
                for j in -h..h {
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                    for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                        let sx: i32 = tri.iter().map(|p| p[0]).sum();
                        let sy: i32 = tri.iter().map(|p| p[1]).sum();
                        let c = if sx < 0 {
                            0
                        } else if sy < 0 {
                            1
                        } else {
                            2
                        };
                        let m = &mut chunks[c];
                        for p in tri {
                            let idx = *maps[c].entry(p).or_insert_with(|| {
                                let local = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * scale;
                                let rel = (centre - m.origin) + local;
                                m.positions.push([rel.x as f32, rel.y as f32, rel.z as f32]);
                                let n = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64).normalize();
                                m.normals.push(unit([n.x as f32, n.y as f32, n.z as f32]));
                                m.edge_keys.push(key(p));
                                if attributes {
                                    m.heights.push(local.length() as f32 - 10.0);
                                    m.water_depths.push((10.0 - local.length() as f32).max(0.0));
                                    m.colors.push([(c * 100) as u8, 120, 200, 255]);
                                    m.materials.push(c as u8);
                                }
                                (m.positions.len() - 1) as u32
                            });
                            m.indices.push(idx);
                        }
                    }
                }
            }
        }
    }
    chunks
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// The canonical key of a lattice point.
pub fn key(p: [i32; 3]) -> EdgeKey {
    let c = |x: i32| (x + 1000) as u128;
    EdgeKey((c(p[0]) << 64) | (c(p[1]) << 32) | c(p[2]), 0)
}

/// Welded vertex count of [`split_box`].
pub fn box_vertices(h: i32) -> usize {
    let s = (2 * h + 1) as usize;
    6 * s * s - 12 * s + 8
}

/// Triangle count of [`split_box`].
pub fn box_triangles(h: i32) -> usize {
    (48 * h * h) as usize
}

/// Chunk origin offsets from the box centre, exactly representable.
pub const OFFSETS: [DVec3; 3] = [
    DVec3::new(-20.0, 0.5, 0.0),
    DVec3::new(10.25, -20.0, -3.0),
    DVec3::new(20.0, 20.0, 0.125),
];

/// A planet-scale box centre with awkward `f64` values (not representable as `f32`).
pub const FAR: DVec3 = DVec3::new(1_234.567_890_123, 6_371_000.123_456_789, -0.1);

/// Metadata for the tests.
pub fn meta(sea: Option<f64>) -> ExportMeta {
    ExportMeta {
        preset: "test \"box\"\nZürich".into(),
        seed: u64::MAX - 1,
        n_c: 4,
        n_t: 16,
        d_b: 1744.0,
        l_d: 4.0,
        d_c: 2,
        radius: 2000.0,
        sea_radius: sea,
        materials: vec!["rock".into(), "sand".into(), "snow".into()],
        generator: "pmc-formats tests".into(),
    }
}

/// A fresh empty directory under the system temp directory.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-formats-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Unordered edges must each be used by exactly two triangles and directed edges by exactly one
/// (closed, consistently wound 2-manifold). Returns the signed volume (positive when outward),
/// computed relative to the first vertex to avoid cancellation far from the world origin.
pub fn check_closed(positions: &[DVec3], faces: &[[u32; 3]]) -> f64 {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in faces {
        assert!(f[0] != f[1] && f[1] != f[2] && f[0] != f[2], "degenerate face {f:?}");
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(
            n, 1,
            "directed edge {a}->{b} used {n} times (winding inconsistent or non-manifold)"
        );
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} is used by only one face (open mesh)"
        );
    }
    let used: std::collections::HashSet<u32> = faces.iter().flatten().copied().collect();
    assert_eq!(used.len(), positions.len(), "unreferenced vertices");
    let o = positions[0];
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| positions[i as usize] - o);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}
