//! The six cube faces and their local frames.
//!
//! Each face carries a right-handed local frame: two face axes `u` and `v`, and the outward depth
//! axis `n` (`u x v = n`). All six frames are right-handed, so a triangle wound counter-clockwise in
//! face coordinates `(u, v)` faces outward on every face.
//!
//! World frame: Y is the polar axis (north pole at +Y), longitude 0 lies on +Z and longitude +90 deg
//! (east) on +X. This is glTF's Y-up, right-handed frame.
//!
//! ```text
//!                    +---------+
//!                    |   Top   |  n=+Y  u=-X  v=+Z
//!                    |         |
//!                    |         |
//!          +---------+---------+---------+
//!          |  West   |  South  |  East   |
//!   n=-X   | u=+Z    | n=+Z    | u=+Y    |  n=+X
//!   v=+Y   |         | u=-X    | v=+Z    |
//!          |         | v=-Y    |         |
//!          +---------+---------+---------+
//!                    | Bottom  |  n=-Y  u=-X  v=-Z
//!                    +---------+
//!                    |  North  |  n=-Z  u=-X  v=+Y
//!                    +---------+
//! ```
//!
//! Top, South, Bottom and North form a ring around the X axis whose `u` axes all point along -X:
//! crossing from one to the next along `v` is a plain offset of one face size (the "easy" case of
//! the paper's Fig. 7). East and West cap the ring; crossing onto them swaps and may flip axes (the
//! "problematic" case).

use glam::{DVec3, IVec3};

/// One of the six faces of the cube (and so of the planet), with the names of seed 000 Sec. 4.1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Face {
    /// +Y: holds the north pole.
    Top = 0,
    /// -Y: holds the south pole.
    Bottom = 1,
    /// -Z.
    North = 2,
    /// +Z: holds latitude 0, longitude 0.
    South = 3,
    /// +X: holds latitude 0, longitude +90.
    East = 4,
    /// -X: holds latitude 0, longitude -90.
    West = 5,
}

/// One of the two axes that span a face (the third, depth, is always outward).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FaceAxis {
    /// The first face axis.
    U,
    /// The second face axis.
    V,
}

impl FaceAxis {
    /// The other face axis (the paper's `OrthogonalAxis`).
    pub fn orthogonal(self) -> FaceAxis {
        match self {
            FaceAxis::U => FaceAxis::V,
            FaceAxis::V => FaceAxis::U,
        }
    }
}

/// A face's local frame as integer unit vectors of the world axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceFrame {
    /// First face axis.
    pub u: IVec3,
    /// Second face axis.
    pub v: IVec3,
    /// Outward depth axis (`u x v`).
    pub n: IVec3,
}

impl FaceFrame {
    /// The face axis `axis` as an integer vector.
    pub fn axis(&self, axis: FaceAxis) -> IVec3 {
        match axis {
            FaceAxis::U => self.u,
            FaceAxis::V => self.v,
        }
    }
}

const FRAMES: [FaceFrame; 6] = [
    // Top
    FaceFrame {
        u: IVec3::new(-1, 0, 0),
        v: IVec3::new(0, 0, 1),
        n: IVec3::new(0, 1, 0),
    },
    // Bottom
    FaceFrame {
        u: IVec3::new(-1, 0, 0),
        v: IVec3::new(0, 0, -1),
        n: IVec3::new(0, -1, 0),
    },
    // North
    FaceFrame {
        u: IVec3::new(-1, 0, 0),
        v: IVec3::new(0, 1, 0),
        n: IVec3::new(0, 0, -1),
    },
    // South
    FaceFrame {
        u: IVec3::new(-1, 0, 0),
        v: IVec3::new(0, -1, 0),
        n: IVec3::new(0, 0, 1),
    },
    // East
    FaceFrame {
        u: IVec3::new(0, 1, 0),
        v: IVec3::new(0, 0, 1),
        n: IVec3::new(1, 0, 0),
    },
    // West
    FaceFrame {
        u: IVec3::new(0, 0, 1),
        v: IVec3::new(0, 1, 0),
        n: IVec3::new(-1, 0, 0),
    },
];

impl Face {
    /// All six faces in index order.
    pub const ALL: [Face; 6] = [
        Face::Top,
        Face::Bottom,
        Face::North,
        Face::South,
        Face::East,
        Face::West,
    ];

    /// The face's index, 0..6, in the order of [`Face::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The face with index `i`, if `i < 6`.
    pub fn from_index(i: usize) -> Option<Face> {
        Face::ALL.get(i).copied()
    }

    /// The face's lower-case name (`"top"`, `"bottom"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Face::Top => "top",
            Face::Bottom => "bottom",
            Face::North => "north",
            Face::South => "south",
            Face::East => "east",
            Face::West => "west",
        }
    }

    /// The face's local frame.
    pub fn frame(self) -> FaceFrame {
        FRAMES[self.index()]
    }

    /// The outward normal of the face as a unit vector.
    pub fn normal(self) -> DVec3 {
        self.frame().n.as_dvec3()
    }

    /// The face whose outward normal is the largest component of `p`.
    ///
    /// Ties (points on cube edges and corners) go to the face that comes first in [`Face::ALL`].
    /// Returns `None` for the zero vector and for vectors with a NaN component.
    pub fn containing(p: DVec3) -> Option<Face> {
        let a = p.abs();
        if !(a.x.is_finite() && a.y.is_finite() && a.z.is_finite()) {
            return None;
        }
        let m = a.max_element();
        if m == 0.0 {
            return None;
        }
        Face::ALL.into_iter().find(|f| {
            let n = f.frame().n;
            p.dot(n.as_dvec3()) == m
        })
    }

    /// Whether `self` and `other` share an edge (distinct and not opposite).
    pub fn is_adjacent(self, other: Face) -> bool {
        self.frame().n.dot(other.frame().n) == 0
    }
}

impl std::fmt::Display for Face {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Face {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Face::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown face '{s}' (expected top, bottom, north, south, east or west)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_right_handed_and_orthonormal() {
        for f in Face::ALL {
            let fr = f.frame();
            assert_eq!(fr.u.cross(fr.v), fr.n, "{f}");
            assert_eq!(fr.u.dot(fr.v), 0);
            for a in [fr.u, fr.v, fr.n] {
                assert_eq!(a.abs().element_sum(), 1);
            }
        }
    }

    #[test]
    fn normals_are_distinct_and_cover_the_cube() {
        let mut seen = std::collections::HashSet::new();
        for f in Face::ALL {
            assert!(seen.insert(f.frame().n));
            assert_eq!(Face::containing(f.normal()), Some(f));
        }
    }

    #[test]
    fn adjacency_counts() {
        for f in Face::ALL {
            let n = Face::ALL.iter().filter(|g| f.is_adjacent(**g)).count();
            assert_eq!(n, 4);
        }
    }

    #[test]
    fn containing_rejects_bad_input() {
        assert_eq!(Face::containing(DVec3::ZERO), None);
        assert_eq!(Face::containing(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }

    #[test]
    fn names_round_trip() {
        for f in Face::ALL {
            assert_eq!(f.name().parse::<Face>().unwrap(), f);
        }
        assert!("up".parse::<Face>().is_err());
    }
}
