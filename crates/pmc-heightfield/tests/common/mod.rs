//! Height sources and mesh checks shared by the integration tests.
#![allow(dead_code)]

use pmc_density::noise::{Fbm, FbmParams};
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::EdgeKey;
use pmc_heightfield::{lattice_direction, ConstantHeight, LatticeHeights, Ripples};
use pmc_mesh::ChunkMesh;

/// Fractal noise of the direction: `amplitude * fbm(direction)`, scale-invariant.
pub struct FbmHeights {
    pub fbm: Fbm,
    pub amplitude: f64,
}

impl FbmHeights {
    pub fn new(seed: u64, frequency: f64, octaves: u32, amplitude: f64) -> Self {
        FbmHeights {
            fbm: Fbm::new(seed, FbmParams::new(frequency, octaves)),
            amplitude,
        }
    }
}

impl LatticeHeights for FbmHeights {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        self.amplitude * self.fbm.sample(lattice_direction(lattice, i64::from(m)))
    }
}

/// A planet's height source and its bounds.
pub struct Source {
    pub name: &'static str,
    pub heights: Box<dyn LatticeHeights>,
    pub min: f64,
    pub max: f64,
}

pub fn sources() -> Vec<Source> {
    vec![
        Source {
            name: "sphere",
            heights: Box::new(ConstantHeight(0.0)),
            min: 0.0,
            max: 0.0,
        },
        Source {
            name: "ripples",
            heights: Box::new(Ripples {
                amplitude: 0.02,
                frequency: 11.0,
            }),
            min: -0.02,
            max: 0.02,
        },
        Source {
            name: "fbm",
            heights: Box::new(FbmHeights::new(7, 2.0, 8, 0.03)),
            min: -0.03,
            max: 0.03,
        },
    ]
}

/// The vertices that some triangle uses.
pub fn used(mesh: &ChunkMesh) -> Vec<bool> {
    let mut u = vec![false; mesh.vertex_count()];
    for &i in &mesh.indices {
        u[i as usize] = true;
    }
    u
}

/// Largest normal deviation among co-located used vertices, and how many keys are shared.
/// (Sorted by key, the copies of a vertex in mesh order: a sort, not a hash map, for the
/// millions of vertices of a view.)
pub fn normal_spread(meshes: &[ChunkMesh]) -> (f64, usize) {
    let mut copies: Vec<(EdgeKey, [f32; 3])> = Vec::new();
    for m in meshes {
        for (v, u) in used(m).into_iter().enumerate() {
            if u {
                copies.push((m.edge_keys[v], m.normals[v]));
            }
        }
    }
    copies.sort_by_key(|c| c.0);
    let mut worst: f64 = 0.0;
    let mut shared = 0;
    for ns in copies.chunk_by(|a, b| a.0 == b.0).filter(|n| n.len() > 1) {
        shared += 1;
        let a = DVec3::from(ns[0].1.map(f64::from));
        for n in &ns[1..] {
            worst = worst.max((DVec3::from(n.1.map(f64::from)) - a).length());
        }
    }
    (worst, shared)
}

/// Edge statistics of the meshes welded by vertex key.
#[derive(Debug, Default)]
pub struct Closure {
    pub vertices: usize,
    pub edges: usize,
    pub triangles: usize,
    /// Undirected edges used by one triangle only.
    pub boundary: usize,
    /// Undirected edges used by more than two triangles, or by two in the same direction.
    pub non_manifold: usize,
    /// Triangles with a repeated welded vertex.
    pub degenerate: usize,
}

impl Closure {
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary == 0 && self.non_manifold == 0 && self.degenerate == 0
    }

    pub fn euler(&self) -> i64 {
        self.vertices as i64 - self.edges as i64 + self.triangles as i64
    }
}

/// Welds the meshes by `edge_keys` (the lattice identity) and counts every undirected edge's
/// triangles: a closed 2-manifold has each edge in exactly two, in opposite directions.
pub fn closure(meshes: &[ChunkMesh]) -> Closure {
    // the welded vertices: every distinct key, sorted (its index is its id)
    let mut keys: Vec<u128> = meshes.iter().flat_map(|m| m.edge_keys.iter().map(|k| k.0)).collect();
    keys.sort_unstable();
    keys.dedup();
    let mut edges: Vec<(u64, bool)> = Vec::new();
    let mut c = Closure::default();
    for m in meshes {
        let local: Vec<u32> = m
            .edge_keys
            .iter()
            .map(|k| keys.binary_search(&k.0).expect("every key was collected") as u32)
            .collect();
        for t in m.indices.chunks_exact(3) {
            let v = [local[t[0] as usize], local[t[1] as usize], local[t[2] as usize]];
            c.triangles += 1;
            if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                c.degenerate += 1;
            }
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                edges.push(((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), a < b));
            }
        }
    }
    edges.sort_unstable();
    let mut used = vec![false; keys.len()];
    for e in &edges {
        used[(e.0 >> 32) as usize] = true;
        used[e.0 as u32 as usize] = true;
    }
    c.vertices = used.iter().filter(|u| **u).count();
    for group in edges.chunk_by(|a, b| a.0 == b.0) {
        c.edges += 1;
        match group {
            [_] => c.boundary += 1,
            [a, b] if a.1 != b.1 => {}
            _ => c.non_manifold += 1,
        }
    }
    c
}
