//! The height source behind the mesher.

use crate::lattice::lattice_direction;
use pmc_geometry::glam::IVec3;
use pmc_geometry::FaceGrid;

/// Heights of the planet's surface at canonical lattice points.
///
/// `height(lattice, m)` is the surface height in metres above the datum radius at the lattice point
/// `lattice` of resolution `m`: `m` is a power of two (segments per face side), every component of
/// `lattice` lies in `[-m, m]` and one of them is `±m` (the point lies on the cube's surface), and
/// the point's direction is `cube_to_sphere(lattice / m)` (see [`crate::lattice_direction`]).
///
/// # Contract
///
/// - **Pure:** the result is a function of the point alone (no state, no dependence on the order
///   of calls or on the thread).
/// - **Scale-invariant:** the same point given at resolution `2m` as `2 lattice` returns the same
///   bits. Computing from the exact cube point `lattice / m` (or the direction) guarantees it,
///   since the division by a power of two is exact.
/// - **Finite**, and within the planet's declared height bounds (the selection's bounding spheres
///   rely on them).
///
/// The mesher relies on both properties: every patch, level and face that reaches a point asks
/// for it, and shared vertices come out bit-identical only because the answers are.
pub trait LatticeHeights: Send + Sync {
    /// Height in metres above the datum radius at `lattice` of resolution `m`.
    fn height(&self, lattice: IVec3, m: i32) -> f64;

    /// Heights of many points of one resolution into `out` (same length as `points`). The default
    /// calls [`LatticeHeights::height`] per point; a source may batch, with the same bits.
    fn heights(&self, points: &[IVec3], m: i32, out: &mut [f64]) {
        assert_eq!(points.len(), out.len(), "one output per point");
        for (p, h) in points.iter().zip(out.iter_mut()) {
            *h = self.height(*p, m);
        }
    }

    /// [`LatticeHeights::heights`] of the entries of a face grid: `points[b * side + a]` is
    /// `face_lattice(grid.face, i, j, m)` for the entry's indices `(i, j)` wherever that point
    /// exists (any valid point elsewhere). A source may use the grid's rows and columns; the
    /// default ignores them. The same bits as `heights` either way.
    fn heights_on_grid(&self, grid: &FaceGrid, points: &[IVec3], m: i32, out: &mut [f64]) {
        debug_assert_eq!(grid.len(), points.len(), "one point per grid entry");
        self.heights(points, m, out)
    }
}

impl<T: LatticeHeights + ?Sized> LatticeHeights for &T {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        (**self).height(lattice, m)
    }

    fn heights(&self, points: &[IVec3], m: i32, out: &mut [f64]) {
        (**self).heights(points, m, out)
    }

    fn heights_on_grid(&self, grid: &FaceGrid, points: &[IVec3], m: i32, out: &mut [f64]) {
        (**self).heights_on_grid(grid, points, m, out)
    }
}

/// The same height everywhere: a sphere of radius `datum + height`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConstantHeight(pub f64);

impl LatticeHeights for ConstantHeight {
    fn height(&self, _lattice: IVec3, _m: i32) -> f64 {
        self.0
    }
}

/// A smooth analytic height field of the direction `d`:
/// `amplitude * sin(f d.x + 0.3) * sin(f d.y + 1.1) * cos(f d.z - 0.7)` with `f = frequency`, in
/// `[-amplitude, amplitude]`. Scale-invariant because it reads only the direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ripples {
    /// Largest height magnitude, metres.
    pub amplitude: f64,
    /// Angular frequency (radians per unit of direction component).
    pub frequency: f64,
}

impl LatticeHeights for Ripples {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        let d = lattice_direction(lattice, i64::from(m)) * self.frequency;
        self.amplitude * (d.x + 0.3).sin() * (d.y + 1.1).sin() * (d.z - 0.7).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ripples_are_scale_invariant() {
        let r = Ripples {
            amplitude: 300.0,
            frequency: 9.0,
        };
        let p = IVec3::new(64, -13, 7);
        let h = r.height(p, 64);
        for k in 1..20 {
            assert_eq!(r.height(p * (1 << k), 64 << k).to_bits(), h.to_bits());
        }
        let mut out = [0.0; 2];
        r.heights(&[p, p], 64, &mut out);
        assert_eq!(out, [h, h]);
        fn through<H: LatticeHeights>(h: H, p: IVec3) -> f64 {
            h.height(p, 64)
        }
        let by_ref: &Ripples = &r;
        assert_eq!(through(by_ref, p), h);
    }
}
