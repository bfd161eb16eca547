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
        // Every directed edge as (undirected pair, direction), sorted: the directed edges of one
        // undirected edge lie together, and each is counted against its reverse (a sort instead
        // of a hash map: meshes of millions of triangles are checked in tests and exports).
        let mut directed: Vec<(u64, bool)> = Vec::with_capacity(self.triangles.len() * 3);
        let mut collapsed = 0;
        let mut used = vec![false; self.positions.len()];
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                collapsed += 1;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                used[a as usize] = true;
                directed.push(((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), a > b));
            }
        }
        directed.sort_unstable();
        let (mut edges, mut boundary, mut bad) = (0, 0, 0);
        for group in directed.chunk_by(|x, y| x.0 == y.0) {
            let pair = group[0].0;
            // triangles using the edge from its lower vertex to its higher, and the reverse
            let up = group.iter().filter(|e| !e.1).count();
            let down = group.len() - up;
            if (pair >> 32) as u32 == pair as u32 {
                // a collapsed triangle's edge from a vertex to itself: its own reverse
                if up > 1 {
                    bad += 1;
                }
                continue;
            }
            edges += 1;
            // each direction used, against the other
            for (n, back) in [(up, down), (down, up)] {
                if n == 0 {
                    continue;
                }
                if n > 1 || back > 1 {
                    bad += 1;
                } else if back == 0 {
                    boundary += 1;
                }
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The report as first written: a hash map of directed edges, each counted against its
    /// reverse. The sorted count must give the same numbers for any triangle soup.
    fn reference(mesh: &WeldedMesh) -> ManifoldReport {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        let mut collapsed = 0;
        let mut used = vec![false; mesh.positions.len()];
        for t in &mesh.triangles {
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
            triangles: mesh.triangles.len(),
            boundary_edges: boundary,
            bad_edges: bad,
            collapsed_triangles: collapsed,
        }
    }

    /// A closed octahedron: 6 vertices, 12 edges, 8 triangles.
    fn octahedron() -> WeldedMesh {
        let p = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
        let triangles = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        WeldedMesh {
            positions: p.to_vec(),
            triangles,
        }
    }

    #[test]
    fn an_octahedron_is_closed_and_a_missing_or_turned_face_is_found() {
        let mut m = octahedron();
        let r = m.report();
        assert!(r.is_closed_manifold(), "{r:?}");
        assert_eq!(
            (r.vertices, r.edges, r.triangles, r.euler_characteristic()),
            (6, 12, 8, 2)
        );
        m.triangles.pop();
        let r = m.report();
        assert_eq!((r.boundary_edges, r.bad_edges), (3, 0), "{r:?}");
        assert_eq!(r, reference(&m));
        // a face turned over: each of its three edges runs the same way as its neighbour's
        let mut m = octahedron();
        m.triangles[0].swap(1, 2);
        let r = m.report();
        assert_eq!((r.boundary_edges, r.bad_edges), (0, 3), "{r:?}");
        assert_eq!(r, reference(&m));
    }

    proptest! {
        /// Any soup of triangles over a few vertices (repeated, turned over, collapsed): the
        /// sorted count gives the reference's numbers.
        #[test]
        fn the_sorted_count_equals_the_hash_map_count(
            triangles in proptest::collection::vec([0u32..7, 0u32..7, 0u32..7], 0..40),
        ) {
            let mesh = WeldedMesh { positions: vec![DVec3::ZERO; 7], triangles };
            prop_assert_eq!(mesh.report(), reference(&mesh));
        }
    }
}
