//! Which directions from the planet centre hold any mesh, on a coarse cube map.
//!
//! The atmosphere glows around the limb only where there is terrain below it, so a picture of a
//! few chunks does not get a ring around a planet that is not there.

use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;

/// Cells along each side of a cube face.
const N: usize = 32;
/// Rough angular size of one cell, radians.
const CELL_ANGLE: f64 = std::f64::consts::FRAC_PI_2 / N as f64;
/// Most samples along a triangle edge when marking large triangles.
const MAX_STEPS: usize = 64;

/// A set of cube-map cells of directions.
#[derive(Clone)]
pub(crate) struct Coverage {
    cells: Vec<bool>,
}

impl Coverage {
    pub(crate) fn new() -> Coverage {
        Coverage {
            cells: vec![false; 6 * N * N],
        }
    }

    /// Marks the directions of every vertex of `m`, and of points spread over its triangles that
    /// are larger than a cell.
    pub(crate) fn add(mut self, m: &ChunkMesh) -> Coverage {
        for i in 0..m.positions.len() {
            self.mark(m.world_position(i));
        }
        for tri in m.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| m.world_position(tri[k] as usize));
            let r = a.length().min(b.length()).min(c.length());
            let edge = (b - a).length().max((c - b).length()).max((a - c).length());
            let angle = edge / r;
            if !(angle.is_finite()) || angle <= 0.5 * CELL_ANGLE {
                continue;
            }
            let n = ((2.0 * angle / CELL_ANGLE).ceil() as usize).clamp(1, MAX_STEPS);
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    self.mark(a + (b - a) * u + (c - a) * v);
                }
            }
        }
        self
    }

    /// Both sets together.
    pub(crate) fn merge(mut self, other: Coverage) -> Coverage {
        for (a, b) in self.cells.iter_mut().zip(other.cells) {
            *a |= b;
        }
        self
    }

    fn mark(&mut self, p: DVec3) {
        if let Some((face, u, v)) = cell(p) {
            self.cells[(face * N + v) * N + u] = true;
        }
    }

    /// Whether direction `d` lies in, or next to, a marked cell (on the same cube face).
    pub(crate) fn contains(&self, d: DVec3) -> bool {
        let Some((face, u, v)) = cell(d) else { return false };
        let range = |x: usize| x.saturating_sub(1)..=(x + 1).min(N - 1);
        range(v).any(|vv| range(u).any(|uu| self.cells[(face * N + vv) * N + uu]))
    }
}

/// The cube face (0..6) and cell of direction `p`, or `None` for zero or non-finite `p`.
fn cell(p: DVec3) -> Option<(usize, usize, usize)> {
    if !p.is_finite() {
        return None;
    }
    let a = p.abs();
    let (face, major, s, t) = if a.x >= a.y && a.x >= a.z {
        (usize::from(p.x < 0.0), a.x, p.y, p.z)
    } else if a.y >= a.z {
        (2 + usize::from(p.y < 0.0), a.y, p.x, p.z)
    } else {
        (4 + usize::from(p.z < 0.0), a.z, p.x, p.y)
    };
    if major <= 0.0 {
        return None;
    }
    let index = |x: f64| (((x / major + 1.0) * 0.5 * N as f64) as usize).min(N - 1);
    Some((face, index(s), index(t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_vertices_and_large_triangles() {
        let mut m = ChunkMesh {
            origin: DVec3::new(0.0, 0.0, 10.0),
            ..ChunkMesh::default()
        };
        // A big triangle in front of +Z spanning about 60 degrees.
        m.positions = vec![[-5.0, -5.0, 0.0], [5.0, -5.0, 0.0], [0.0, 5.0, 0.0]];
        m.indices = vec![0, 1, 2];
        let c = Coverage::new().add(&m);
        assert!(c.contains(DVec3::Z));
        assert!(c.contains(DVec3::new(0.0, -0.3, 1.0)));
        assert!(!c.contains(-DVec3::Z));
        assert!(!c.contains(DVec3::X));
        assert!(!c.contains(DVec3::ZERO));
        let both = c.merge(Coverage::new().add(&ChunkMesh {
            origin: DVec3::new(-10.0, 0.0, 0.0),
            ..m
        }));
        assert!(both.contains(-DVec3::X) && both.contains(DVec3::Z));
    }
}
