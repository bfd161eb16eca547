//! The density trait and its combinators.
//!
//! # Sign convention
//!
//! Density is a signed value in (roughly) metres: **positive is solid, zero or negative is air**,
//! and the surface is the zero level. Every source, the mesher and the editing layer use this one
//! convention.

use pmc_geometry::glam::DVec3;

/// A scalar field over world space (metres, planet-centred). Positive is solid.
///
/// Implementations must be deterministic (the same point gives the same bits on every call and
/// thread) and thread-safe.
pub trait Density: Send + Sync {
    /// The density at world point `p`.
    fn density(&self, p: DVec3) -> f64;

    /// Whole-chunk batch call: the density at `dirs[d] * radii[r]` for every pair, written to
    /// `out[r * dirs.len() + d]`.
    ///
    /// Sources override this to share work along a column (a height field is evaluated once per
    /// direction, not once per voxel). The result must agree with [`Density::density`] up to the
    /// rounding of the direction (a point call has to normalise `p`, which may differ from the
    /// batch's unit direction in the last bit). Chunks always sample through this call with
    /// canonical directions, so voxels shared by several chunks get identical values.
    /// Must be deterministic: the same inputs give the same bits.
    ///
    /// # Panics
    /// If `out.len() != dirs.len() * radii.len()`.
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        for (r, row) in radii.iter().zip(out.chunks_exact_mut(dirs.len())) {
            for (d, o) in dirs.iter().zip(row) {
                *o = self.density(*d * *r) as f32;
            }
        }
    }

    /// Radii between which the surface can lie: below the first everything is solid, above the
    /// second everything is air. `None` when the source cannot tell. Used to skip chunks that
    /// hold no surface without sampling them.
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        None
    }
}

impl<T: Density + ?Sized> Density for Box<T> {
    fn density(&self, p: DVec3) -> f64 {
        (**self).density(p)
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        (**self).sample_shell(dirs, radii, out)
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        (**self).radial_bounds()
    }
}

impl<T: Density + ?Sized> Density for std::sync::Arc<T> {
    fn density(&self, p: DVec3) -> f64 {
        (**self).density(p)
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        (**self).sample_shell(dirs, radii, out)
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        (**self).radial_bounds()
    }
}

/// A solid ball: `radius - |p|`, an exact signed distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Radius in metres.
    pub radius: f64,
}

impl Density for Sphere {
    fn density(&self, p: DVec3) -> f64 {
        self.radius - p.length()
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        for (r, row) in radii.iter().zip(out.chunks_exact_mut(dirs.len())) {
            for (d, o) in dirs.iter().zip(row) {
                *o = (self.radius - (*d * *r).length()) as f32;
            }
        }
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        Some((self.radius, self.radius))
    }
}

/// Solid where either source is solid (`max`).
#[derive(Clone, Debug)]
pub struct Union<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Union<A, B> {
    fn density(&self, p: DVec3) -> f64 {
        self.0.density(p).max(self.1.density(p))
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        self.0.sample_shell(dirs, radii, out);
        let mut tmp = vec![0.0f32; out.len()];
        self.1.sample_shell(dirs, radii, &mut tmp);
        for (o, t) in out.iter_mut().zip(tmp) {
            *o = o.max(t);
        }
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        let (a, b) = (self.0.radial_bounds()?, self.1.radial_bounds()?);
        Some((a.0.min(b.0), a.1.max(b.1)))
    }
}

/// Solid where the first source is solid and the second is not (`min(a, -b)`): carving.
#[derive(Clone, Debug)]
pub struct Subtract<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Subtract<A, B> {
    fn density(&self, p: DVec3) -> f64 {
        self.0.density(p).min(-self.1.density(p))
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        self.0.sample_shell(dirs, radii, out);
        let mut tmp = vec![0.0f32; out.len()];
        self.1.sample_shell(dirs, radii, &mut tmp);
        for (o, t) in out.iter_mut().zip(tmp) {
            *o = o.min(-t);
        }
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        let (a, b) = (self.0.radial_bounds()?, self.1.radial_bounds()?);
        // Carving can open air down to the carver's lowest extent, never add solid above `a`.
        Some((a.0.min(b.0), a.1))
    }
}

/// A closure as a density source (for tests and quick experiments).
pub struct FnDensity<F>(pub F);

impl<F: Fn(DVec3) -> f64 + Send + Sync> Density for FnDensity<F> {
    fn density(&self, p: DVec3) -> f64 {
        (self.0)(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batch_matches_point_calls() {
        let s = Union(
            Sphere { radius: 10.0 },
            FnDensity(|p: DVec3| 3.0 - (p - DVec3::X * 10.0).length()),
        );
        let dirs = [DVec3::X, DVec3::Y, DVec3::new(0.6, 0.8, 0.0)];
        let radii = [5.0, 9.5, 10.0, 12.0];
        let mut out = vec![0.0; 12];
        s.sample_shell(&dirs, &radii, &mut out);
        for (ri, r) in radii.iter().enumerate() {
            for (di, d) in dirs.iter().enumerate() {
                assert_eq!(out[ri * 3 + di], s.density(*d * *r) as f32);
            }
        }
        assert!(out[3 * 3] > 0.0, "the bump makes (12,0,0) solid");
    }

    #[test]
    fn subtract_carves() {
        let s = Subtract(Sphere { radius: 10.0 }, Sphere { radius: 5.0 });
        assert!(s.density(DVec3::ZERO) < 0.0);
        assert!(s.density(DVec3::X * 7.0) > 0.0);
        assert!(s.density(DVec3::X * 11.0) < 0.0);
        assert_eq!(s.radial_bounds(), Some((5.0, 10.0)));
    }
}
