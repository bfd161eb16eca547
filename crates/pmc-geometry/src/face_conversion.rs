//! Seed 000 Algorithm 1: converting positions and directions between the local coordinates of two
//! adjacent faces.
//!
//! Face coordinates here run from 0 to `size` along each face axis (the face's origin is its corner
//! at `u = v = -1`). A position past a face's border is read as lying on the neighbouring face,
//! with the neighbour unfolded about the shared edge: a point `d` units past the edge of the
//! current face is `d` units inside the target face. Each axis converts on its own, by the steps of
//! Algorithm 1:
//!
//! 1. pick the target axis: the target face's axis of the same name, unless it is orthogonal to the
//!    current axis after unfolding, in which case the other one (`OrthogonalAxis`);
//! 2. if the two axes point in opposite directions, multiply by -1 (`IsOppositeDirection`);
//! 3. add the difference of the two origins measured along the axes (`OriginDifference`), a whole
//!    number of face sizes.
//!
//! The table of steps is derived from the face frames in [`crate::face`], not typed in, and the
//! tests check it geometrically on all 24 directed pairs of adjacent faces.

use crate::face::{Face, FaceAxis};

/// How one axis of the current face maps to the target face: `p_t = mul * p_c + offset * size`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisMap {
    /// The target face's axis.
    pub target: FaceAxis,
    /// +1 when the axes point the same way after unfolding, -1 when opposite.
    pub mul: i8,
    /// Difference of the origins, in face sizes.
    pub offset: i8,
}

impl AxisMap {
    #[inline]
    fn apply(&self, p: f64, size: f64) -> f64 {
        f64::from(self.mul) * p + f64::from(self.offset) * size
    }
}

/// The conversion from one face's coordinates to an adjacent face's (Algorithm 1 for both axes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceTransition {
    /// The current face.
    pub from: Face,
    /// The target face.
    pub to: Face,
    /// Where the current face's `u` axis goes.
    pub u: AxisMap,
    /// Where the current face's `v` axis goes.
    pub v: AxisMap,
}

impl FaceTransition {
    /// The transition from `from` to `to`, or `None` when the faces are not adjacent.
    pub fn new(from: Face, to: Face) -> Option<FaceTransition> {
        if !from.is_adjacent(to) {
            return None;
        }
        let fc = from.frame();
        let ft = to.frame();
        // The current face axis that crosses the shared edge, and its sign toward the edge.
        let (cross, sigma) = if ft.n == fc.u {
            (FaceAxis::U, 1)
        } else if ft.n == -fc.u {
            (FaceAxis::U, -1)
        } else if ft.n == fc.v {
            (FaceAxis::V, 1)
        } else {
            (FaceAxis::V, -1)
        };
        let along = cross.orthogonal();
        let along_vec = fc.axis(along);
        // In [-1, 1] units, a folded point is `n_t + y * along + (2 - sigma x) * n_c`, where x is
        // the crossing coordinate and y the along-edge one. Project it on each target axis.
        let map_axis = |src: FaceAxis| -> AxisMap {
            for tgt in [FaceAxis::U, FaceAxis::V] {
                let t = ft.axis(tgt);
                if src == along {
                    let m = along_vec.dot(t);
                    if m != 0 {
                        // u_t = m y  =>  p_t = m p + (1 - m)/2 size
                        return AxisMap {
                            target: tgt,
                            mul: m as i8,
                            offset: ((1 - m) / 2) as i8,
                        };
                    }
                } else {
                    let tau = fc.n.dot(t);
                    if tau != 0 {
                        // u_t = 2 tau - tau sigma x  =>  p_t = m p + (2 tau - m + 1)/2 size
                        let m = -tau * sigma;
                        return AxisMap {
                            target: tgt,
                            mul: m as i8,
                            offset: ((2 * tau - m + 1) / 2) as i8,
                        };
                    }
                }
            }
            unreachable!("adjacent faces always share an axis direction")
        };
        Some(FaceTransition {
            from,
            to,
            u: map_axis(FaceAxis::U),
            v: map_axis(FaceAxis::V),
        })
    }

    /// The axis map for the current face's `axis`.
    pub fn axis_map(&self, axis: FaceAxis) -> AxisMap {
        match axis {
            FaceAxis::U => self.u,
            FaceAxis::V => self.v,
        }
    }

    /// Algorithm 1: converts the 1D position `p` on the current face's `axis` to the target face.
    pub fn convert_axis(&self, axis: FaceAxis, p: f64, size: f64) -> (FaceAxis, f64) {
        let m = self.axis_map(axis);
        (m.target, m.apply(p, size))
    }

    /// Converts a position `(s, t)` in the current face's coordinates (0..size per axis) to the
    /// target face's.
    pub fn convert_point(&self, s: f64, t: f64, size: f64) -> (f64, f64) {
        let mut out = [0.0; 2];
        for (axis, p) in [(FaceAxis::U, s), (FaceAxis::V, t)] {
            let (a, q) = self.convert_axis(axis, p, size);
            out[a as usize] = q;
        }
        (out[0], out[1])
    }

    /// Converts integer grid indices (0..=size per axis) exactly.
    pub fn convert_index(&self, i: i64, j: i64, size: i64) -> (i64, i64) {
        let mut out = [0i64; 2];
        for (axis, p) in [(FaceAxis::U, i), (FaceAxis::V, j)] {
            let m = self.axis_map(axis);
            out[m.target as usize] = i64::from(m.mul) * p + i64::from(m.offset) * size;
        }
        (out[0], out[1])
    }

    /// Converts a direction (a difference of positions) in the current face's coordinates.
    pub fn convert_direction(&self, ds: f64, dt: f64) -> (f64, f64) {
        let mut out = [0.0; 2];
        for (axis, d) in [(FaceAxis::U, ds), (FaceAxis::V, dt)] {
            let m = self.axis_map(axis);
            out[m.target as usize] = f64::from(m.mul) * d;
        }
        (out[0], out[1])
    }

    /// The transition back from the target face to the current one.
    pub fn inverse(&self) -> FaceTransition {
        FaceTransition::new(self.to, self.from).expect("adjacency is symmetric")
    }
}

/// Algorithm 1 as a free function: converts the position `p` on `axis` of face `from` to the
/// adjacent face `to`. Returns `None` when the faces are not adjacent.
pub fn convert_axis(from: Face, to: Face, axis: FaceAxis, p: f64, size: f64) -> Option<(FaceAxis, f64)> {
    FaceTransition::new(from, to).map(|t| t.convert_axis(axis, p, size))
}

impl FaceAxis {
    fn index(self) -> usize {
        self as usize
    }
}

impl From<FaceAxis> for usize {
    fn from(a: FaceAxis) -> usize {
        a.index()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cube_sphere::face_uv_to_cube;
    use glam::DVec3;

    const S: f64 = 64.0;

    fn cube(face: Face, s: f64, t: f64) -> DVec3 {
        face_uv_to_cube(face, 2.0 * s / S - 1.0, 2.0 * t / S - 1.0)
    }

    fn pairs() -> Vec<(Face, Face)> {
        let mut v = Vec::new();
        for a in Face::ALL {
            for b in Face::ALL {
                if a.is_adjacent(b) {
                    v.push((a, b));
                }
            }
        }
        v
    }

    #[test]
    fn there_are_24_directed_pairs() {
        assert_eq!(pairs().len(), 24);
        for a in Face::ALL {
            assert!(FaceTransition::new(a, a).is_none());
        }
        assert!(FaceTransition::new(Face::Top, Face::Bottom).is_none());
    }

    #[test]
    fn top_to_south_is_a_plain_offset() {
        // Fig. 7 left: Top and South have compatible axes; only the origin differs by one face.
        let t = FaceTransition::new(Face::Top, Face::South).unwrap();
        assert_eq!(
            t.u,
            AxisMap {
                target: FaceAxis::U,
                mul: 1,
                offset: 0
            }
        );
        assert_eq!(
            t.v,
            AxisMap {
                target: FaceAxis::V,
                mul: 1,
                offset: -1
            }
        );
        // Fig. 7 right: crossing onto a cap face swaps the axes.
        let t = FaceTransition::new(Face::Top, Face::West).unwrap();
        assert_eq!((t.u.target, t.v.target), (FaceAxis::V, FaceAxis::U));
    }

    /// Points on the shared edge are the same cube point on both faces; a point `d` past the edge
    /// lands `d` inside the target face; a step across the edge continues as a step away from it.
    #[test]
    fn all_24_pairs_are_geometrically_right() {
        for (a, b) in pairs() {
            let tr = FaceTransition::new(a, b).unwrap();
            // Find the edge on `a`: the side whose cube points lie on face b's plane.
            let nb = b.normal();
            for k in 0..=8 {
                let lam = S * f64::from(k) / 8.0;
                for (s, t, ds, dt) in [
                    (S, lam, 1.0, 0.0),
                    (0.0, lam, -1.0, 0.0),
                    (lam, S, 0.0, 1.0),
                    (lam, 0.0, 0.0, -1.0),
                ] {
                    let c = cube(a, s, t);
                    // Only the side whose whole edge lies on b's plane (its midpoint does).
                    let mid = cube(
                        a,
                        if ds == 0.0 { S / 2.0 } else { s },
                        if dt == 0.0 { S / 2.0 } else { t },
                    );
                    if (mid.dot(nb) - 1.0).abs() > 1e-12 {
                        continue;
                    }
                    let (s2, t2) = tr.convert_point(s, t, S);
                    assert!((cube(b, s2, t2) - c).length() < 1e-12, "{a}->{b} edge point");
                    // d past the edge on a
                    let d = 3.0;
                    let (s3, t3) = tr.convert_point(s + d * ds, t + d * dt, S);
                    let inside = (0.0..=S).contains(&s3) && (0.0..=S).contains(&t3);
                    assert!(inside, "{a}->{b}: the point past the edge lands inside the target");
                    assert_eq!((s3 - s2).abs() + (t3 - t2).abs(), d, "{a}->{b}: distance from the edge");
                    // The folded 3D point: on b's plane, at distance d/S*2 from the edge, below a's plane.
                    let p = cube(b, s3, t3);
                    let expect_na = 1.0 - 2.0 * d / S;
                    assert!((p.dot(a.normal()) - expect_na).abs() < 1e-12, "{a}->{b}: fold depth");
                    // Direction across the edge becomes a direction away from it.
                    let (ds2, dt2) = tr.convert_direction(ds, dt);
                    assert_eq!((s3 - s2, t3 - t2), (d * ds2, d * dt2), "{a}->{b} direction");
                }
            }
        }
    }

    /// Grid positions (and sub-voxel positions on a dyadic grid, as vertices have) round-trip
    /// exactly; arbitrary floats to within an ulp of the face size (see `round_trips_of_any_float`).
    #[test]
    fn round_trips_are_exact_on_all_pairs() {
        for (a, b) in pairs() {
            let tr = FaceTransition::new(a, b).unwrap();
            let back = tr.inverse();
            for s in [-5.0, 0.0, 0.125, 17.25, 31.999_023_437_5, S, S + 7.5] {
                for t in [-2.0, 0.0, 3.3125, S * 0.5, S, S + 1.0] {
                    let (s2, t2) = tr.convert_point(s, t, S);
                    assert_eq!(back.convert_point(s2, t2, S), (s, t), "{a}->{b}->{a}");
                    let (i2, j2) = tr.convert_index(s as i64, t as i64, S as i64);
                    assert_eq!(back.convert_index(i2, j2, S as i64), (s as i64, t as i64));
                    let (d1, d2) = tr.convert_direction(s, t);
                    assert_eq!(back.convert_direction(d1, d2), (s, t));
                }
            }
            for axis in [FaceAxis::U, FaceAxis::V] {
                let (ta, p) = convert_axis(a, b, axis, 12.5, S).unwrap();
                let (ra, q) = convert_axis(b, a, ta, p, S).unwrap();
                assert_eq!((ra, q), (axis, 12.5));
            }
        }
    }

    #[test]
    fn round_trips_of_any_float() {
        for (a, b) in pairs() {
            let tr = FaceTransition::new(a, b).unwrap();
            let back = tr.inverse();
            for s in [-5.1, 0.3, 17.7, 33.3, S + 2.9] {
                for t in [-2.2, 3.3, 40.1, S + 0.7] {
                    let (s2, t2) = tr.convert_point(s, t, S);
                    let (s3, t3) = back.convert_point(s2, t2, S);
                    assert!((s3 - s).abs() <= S * f64::EPSILON && (t3 - t).abs() <= S * f64::EPSILON);
                }
            }
        }
    }

    #[test]
    fn integer_and_float_conversions_agree() {
        for (a, b) in pairs() {
            let tr = FaceTransition::new(a, b).unwrap();
            for i in [-3i64, 0, 5, 64, 66] {
                for j in [-1i64, 0, 33, 64, 65] {
                    let (fi, fj) = tr.convert_point(i as f64, j as f64, S);
                    let (ii, ij) = tr.convert_index(i, j, S as i64);
                    assert_eq!((fi, fj), (ii as f64, ij as f64));
                }
            }
        }
    }
}
