//! The marching cubes case tables, all 256 cases, generated from one rule.
//!
//! Rather than typing in the classic tables, we derive them: for every corner configuration, each
//! of the six cube faces is cut by marching squares, always **separating** diagonally opposite
//! solid corners on an ambiguous face. The cut segments chain into closed loops (every cut cube
//! edge lies on exactly two faces), and each loop is fanned into triangles.
//!
//! The rule looks only at a face's own four corners, so two cubes sharing a face always cut it the
//! same way: there is no complementary symmetry (a configuration and its inverse are triangulated
//! independently) and no hole between ambiguous neighbours (seed 001). Tests check the tables
//! against these properties, and the mesher's closedness tests check them in use.
//!
//! Corner `c` of a cube sits at offset `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`. Edges 0-3 run along
//! x, 4-7 along y, 8-11 along z; see [`EDGE_CORNERS`].

use std::sync::LazyLock;

/// The two corners of each of the 12 cube edges, lower corner first.
pub const EDGE_CORNERS: [(u8, u8); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The axis (0 = x, 1 = y, 2 = z) of each cube edge.
pub const EDGE_AXIS: [u8; 12] = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2];

/// Offset of corner `c` within the cube.
pub const fn corner_offset(c: u8) -> [usize; 3] {
    [(c & 1) as usize, ((c >> 1) & 1) as usize, ((c >> 2) & 1) as usize]
}

/// The generated tables.
#[derive(Debug)]
pub struct McTables {
    /// For case `c`, triangles `ranges[c]..ranges[c + 1]` of `triangles`.
    pub ranges: [u16; 257],
    /// Triangles as triples of cube edge indices, counter-clockwise seen from the air side.
    pub triangles: Vec<[u8; 3]>,
    /// For case `c`, the bit mask of cut edges.
    pub edge_masks: [u16; 256],
}

impl McTables {
    /// The triangles of case `c` (bit `i` set when corner `i` is solid).
    #[inline]
    pub fn case(&self, c: u8) -> &[[u8; 3]] {
        &self.triangles[self.ranges[c as usize] as usize..self.ranges[c as usize + 1] as usize]
    }
}

/// The tables, generated on first use.
pub static TABLES: LazyLock<McTables> = LazyLock::new(generate);

/// Cube faces as (axis, side) with their corners counter-clockwise seen from outside.
fn faces() -> [[u8; 4]; 6] {
    let mut out = [[0u8; 4]; 6];
    let mut f = 0;
    for axis in 0..3usize {
        for side in 0..2usize {
            let mut corners: Vec<u8> = (0..8u8).filter(|c| corner_offset(*c)[axis] == side).collect();
            // Tangent axes t1, t2 with t1 x t2 = +axis; flip for the negative side.
            let (mut t1, mut t2) = ((axis + 1) % 3, (axis + 2) % 3);
            if side == 0 {
                std::mem::swap(&mut t1, &mut t2);
            }
            corners.sort_by(|a, b| {
                let ang = |c: u8| {
                    let o = corner_offset(c);
                    (o[t2] as f64 - 0.5).atan2(o[t1] as f64 - 0.5)
                };
                ang(*a).partial_cmp(&ang(*b)).unwrap()
            });
            out[f] = [corners[0], corners[1], corners[2], corners[3]];
            f += 1;
        }
    }
    out
}

fn edge_between(a: u8, b: u8) -> u8 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    EDGE_CORNERS
        .iter()
        .position(|e| *e == (lo, hi))
        .expect("corners share an edge") as u8
}

fn edge_midpoint(e: u8) -> [f64; 3] {
    let (a, b) = EDGE_CORNERS[e as usize];
    let (oa, ob) = (corner_offset(a), corner_offset(b));
    [0, 1, 2].map(|i| (oa[i] + ob[i]) as f64 * 0.5)
}

/// The closed loops of cut edges for `case`, each oriented by the face-walk rule.
fn loops(case: u8, faces: &[[u8; 4]; 6]) -> Vec<Vec<u8>> {
    let solid = |c: u8| case & (1 << c) != 0;
    let mut next = [u8::MAX; 12];
    for f in faces {
        // Walk the face counter-clockwise; pair each entry into solid with the exit that ends
        // the same solid run, so diagonal solid corners are cut off separately.
        let start = match (0..4).find(|&i| !solid(f[i])) {
            Some(s) => s,
            None => continue, // whole face solid: no cut
        };
        let mut enter: Option<u8> = None;
        for step in 0..4 {
            let i = (start + step) % 4;
            let (a, b) = (f[i], f[(i + 1) % 4]);
            if !solid(a) && solid(b) {
                enter = Some(edge_between(a, b));
            } else if solid(a) && !solid(b) {
                let leave = edge_between(a, b);
                let e = enter.take().expect("a solid run is entered before it is left");
                next[leave as usize] = e;
            }
        }
    }
    let mut seen = [false; 12];
    let mut out = Vec::new();
    for s in 0..12u8 {
        if next[s as usize] == u8::MAX || seen[s as usize] {
            continue;
        }
        let mut lp = Vec::new();
        let mut e = s;
        while !seen[e as usize] {
            seen[e as usize] = true;
            lp.push(e);
            e = next[e as usize];
        }
        out.push(lp);
    }
    out
}

fn edges_share_face(a: u8, b: u8, faces: &[[u8; 4]; 6]) -> bool {
    faces.iter().any(|f| {
        let on = |e: u8| {
            let (x, y) = EDGE_CORNERS[e as usize];
            f.contains(&x) && f.contains(&y)
        };
        on(a) && on(b)
    })
}

/// Fans a loop from the apex whose diagonals stay off the cube faces when possible, so that no
/// mesh edge lies in a cube face except the face cuts themselves.
fn triangulate(lp: &[u8], faces: &[[u8; 4]; 6], flip: bool, out: &mut Vec<[u8; 3]>) {
    let m = lp.len();
    let bad = |apex: usize| {
        (2..m - 1)
            .filter(|&k| edges_share_face(lp[apex], lp[(apex + k) % m], faces))
            .count()
    };
    let apex = (0..m).min_by_key(|&a| bad(a)).unwrap_or(0);
    for k in 1..m - 1 {
        let (a, b, c) = (lp[apex], lp[(apex + k) % m], lp[(apex + k + 1) % m]);
        out.push(if flip { [a, c, b] } else { [a, b, c] });
    }
}

fn newell_normal(lp: &[u8]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for i in 0..lp.len() {
        let p = edge_midpoint(lp[i]);
        let q = edge_midpoint(lp[(i + 1) % lp.len()]);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    n
}

fn generate() -> McTables {
    let faces = faces();
    // Decide the winding once, from the single-corner case: corner 0 solid, so the outward
    // (air-side) normal points along +x+y+z.
    let n = newell_normal(&loops(1, &faces)[0]);
    let flip = n[0] + n[1] + n[2] < 0.0;
    let mut ranges = [0u16; 257];
    let mut triangles = Vec::new();
    let mut edge_masks = [0u16; 256];
    for case in 0..=255u8 {
        for lp in loops(case, &faces) {
            for e in &lp {
                edge_masks[case as usize] |= 1 << e;
            }
            triangulate(&lp, &faces, flip, &mut triangles);
        }
        ranges[case as usize + 1] = triangles.len() as u16;
    }
    McTables {
        ranges,
        triangles,
        edge_masks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cut_edges(case: u8) -> u16 {
        let mut m = 0;
        for (e, (a, b)) in EDGE_CORNERS.iter().enumerate() {
            if ((case >> a) & 1) != ((case >> b) & 1) {
                m |= 1 << e;
            }
        }
        m
    }

    #[test]
    fn every_cut_edge_is_used_and_no_other() {
        let t = &*TABLES;
        for c in 0..=255u8 {
            let mut used = 0u16;
            for tri in t.case(c) {
                for e in tri {
                    used |= 1 << e;
                }
            }
            assert_eq!(used, cut_edges(c), "case {c}");
            assert_eq!(t.edge_masks[c as usize], cut_edges(c));
        }
        assert!(t.case(0).is_empty() && t.case(255).is_empty());
    }

    /// Inside one cube, every triangle edge that lies on a cube face is a face cut used once,
    /// and every other triangle edge is used twice with opposite directions (the loop interior).
    #[test]
    fn each_case_is_a_surface_with_boundary_on_the_cube_faces() {
        let t = &*TABLES;
        let faces = faces();
        for c in 0..=255u8 {
            let mut count: std::collections::HashMap<(u8, u8), i32> = Default::default();
            for tri in t.case(c) {
                for k in 0..3 {
                    *count.entry((tri[k], tri[(k + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &count {
                let back = count.get(&(b, a)).copied().unwrap_or(0);
                assert_eq!(n, 1, "case {c}: directed edge {a}->{b} used {n} times");
                if back == 0 {
                    assert!(
                        edges_share_face(a, b, &faces),
                        "case {c}: open edge {a}-{b} off the faces"
                    );
                }
            }
        }
    }

    /// Triangles face the air: the area-weighted normal of each case points from the solid
    /// corners toward the air corners whenever that direction is defined.
    #[test]
    fn triangles_face_the_air() {
        let t = &*TABLES;
        for c in 1..=254u8 {
            let mut s = [0.0; 3];
            let mut a = [0.0; 3];
            for k in 0..8u8 {
                let o = corner_offset(k);
                let tgt = if c & (1 << k) != 0 { &mut s } else { &mut a };
                for i in 0..3 {
                    tgt[i] += o[i] as f64;
                }
            }
            let ns = c.count_ones() as f64;
            let na = 8.0 - ns;
            let dir: Vec<f64> = (0..3).map(|i| a[i] / na - s[i] / ns).collect();
            let mut n = [0.0; 3];
            for tri in t.case(c) {
                let [p, q, r] = tri.map(edge_midpoint);
                let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
                n[0] += u[1] * v[2] - u[2] * v[1];
                n[1] += u[2] * v[0] - u[0] * v[2];
                n[2] += u[0] * v[1] - u[1] * v[0];
            }
            let d: f64 = (0..3).map(|i| n[i] * dir[i]).sum();
            let len: f64 = dir.iter().map(|x| x * x).sum::<f64>().sqrt();
            if len > 1e-9 {
                assert!(d > 0.0, "case {c} faces the solid");
            }
        }
    }

    /// A configuration and its complement cut ambiguous faces differently (no complementary
    /// symmetry): the single-corner cases and their inverses differ only in winding, but the
    /// diagonal face case does not reduce to its inverse.
    #[test]
    fn no_complementary_symmetry_on_ambiguous_faces() {
        let t = &*TABLES;
        // Corners 0 and 3 solid: diagonal on the z = 0 face; separated, so two triangles.
        let c: u8 = 0b0000_1001;
        assert_eq!(t.case(c).len(), 2);
        // The inverse connects the six solid corners into one region: a single loop of 6 cuts.
        assert_eq!(t.case(!c).len(), 4);
    }

    #[test]
    fn tables_fit_the_classic_bound() {
        let t = &*TABLES;
        let max = (0..=255u8).map(|c| t.case(c).len()).max().unwrap();
        assert!(max <= 5, "at most five triangles per cube, got {max}");
    }
}
