//! Checking that a set of chunk meshes forms a closed surface.
//!
//! Vertices are identified by their canonical [`EdgeKey`], never by position, so the check needs
//! no tolerance: two chunks agree on a vertex exactly when they hold the same grid edge.

use crate::ChunkMesh;
use pmc_geometry::glam::DVec3;
use pmc_geometry::EdgeKey;
use std::collections::HashMap;

/// Chunk meshes joined into one indexed mesh by canonical vertex identity, in f64 world space.
#[derive(Clone, Debug, Default)]
pub struct WeldedMesh {
    /// World positions (metres, planet-centred), one per distinct edge key.
    pub positions: Vec<DVec3>,
    /// Triangles into `positions`, winding kept.
    pub triangles: Vec<[u32; 3]>,
}

/// Edge statistics of a welded mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ManifoldReport {
    /// Vertices used.
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Triangles.
    pub triangles: usize,
    /// Edges with a single triangle (holes).
    pub boundary_edges: usize,
    /// Edges with more than two triangles, or two with the same direction (flipped or folded).
    pub bad_edges: usize,
    /// Triangles with a repeated vertex.
    pub collapsed_triangles: usize,
}

impl ManifoldReport {
    /// Whether every edge is shared by exactly two consistently oriented triangles.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.bad_edges == 0 && self.collapsed_triangles == 0
    }

    /// Euler characteristic `V - E + F` (2 for a sphere).
    pub fn euler_characteristic(&self) -> i64 {
        self.vertices as i64 - self.edges as i64 + self.triangles as i64
    }
}

impl WeldedMesh {
    /// Welds chunk meshes by their edge keys (meshes without keys are not welded).
    pub fn weld(meshes: &[ChunkMesh]) -> WeldedMesh {
        let mut ids: HashMap<EdgeKey, u32> = HashMap::new();
        let mut out = WeldedMesh::default();
        for m in meshes {
            let local: Vec<u32> = (0..m.vertex_count())
                .map(|i| {
                    let mut push = || {
                        out.positions.push(m.world_position(i));
                        (out.positions.len() - 1) as u32
                    };
                    match m.edge_keys.get(i) {
                        Some(k) => *ids.entry(*k).or_insert_with(push),
                        None => push(),
                    }
                })
                .collect();
            out.triangles.extend(
                m.indices
                    .chunks_exact(3)
                    .map(|t| [0, 1, 2].map(|k| local[t[k] as usize])),
            );
        }
        out
    }

    /// Counts boundary and non-manifold edges.
    pub fn report(&self) -> ManifoldReport {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 3);
        let mut collapsed = 0;
        let mut used = vec![false; self.positions.len()];
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                collapsed += 1;
            }
            for k in 0..3 {
                used[t[k] as usize] = true;
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        let (mut edges, mut boundary, mut bad) = (0, 0, 0);
        for (&(a, b), &n) in &directed {
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if a < b || back == 0 {
                edges += 1;
            }
            if n > 1 || back > 1 {
                bad += 1;
            } else if back == 0 {
                boundary += 1;
            }
        }
        ManifoldReport {
            vertices: used.iter().filter(|u| **u).count(),
            edges,
            triangles: self.triangles.len(),
            boundary_edges: boundary,
            bad_edges: bad,
            collapsed_triangles: collapsed,
        }
    }

    /// Enclosed volume (divergence theorem; positive when triangles face outward), cubic metres.
    /// Computed about the mean vertex so it stays accurate far from the origin.
    pub fn volume(&self) -> f64 {
        if self.positions.is_empty() {
            return 0.0;
        }
        let c = self.positions.iter().copied().sum::<DVec3>() / self.positions.len() as f64;
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, d] = t.map(|i| self.positions[i as usize] - c);
                a.dot(b.cross(d)) / 6.0
            })
            .sum()
    }
}
