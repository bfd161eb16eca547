//! The density trait and its combinators.
//!
//! # Sign convention
//!
//! Density is a signed value in (roughly) metres: **positive is solid, zero or negative is air**,
//! and the surface is the zero level. Every source, the mesher and the editing layer use this one
//! convention.

use pmc_geometry::glam::DVec3;
use std::any::Any;

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
    /// Must be deterministic: the same inputs give the same bits. A sample's value must not
    /// depend on the batch's other directions and radii: a batch over part of a chunk's samples
    /// gives them the bits the whole chunk's batch gives them (remeshing around an edit samples
    /// only a box of the chunk).
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

    /// [`sample_shell`](Self::sample_shell) (the same bits into `out`) that also leaves in
    /// `columns` what the batch computed once per direction, for the terrain's shader to read
    /// instead of computing it again ([`crate::presets::Shader::shade_edges`]). The default
    /// leaves `columns` empty; column models keep their columns.
    ///
    /// # Panics
    /// If `out.len() != dirs.len() * radii.len()`.
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        columns.clear();
        self.sample_shell(dirs, radii, out);
    }

    /// Whether every sample of the batch `dirs` × `radii` has one sign, told without computing
    /// them all where the source can: `Some(true)` when [`Density::sample_shell`] gives every
    /// sample a value above zero (solid), `Some(false)` when it gives every one zero or below
    /// (air), `None` when they may differ or the source cannot tell (the default). Never `Some`
    /// for a batch whose samples differ in sign. A chunk whose batch has one sign holds no
    /// surface, so it need not be sampled and meshed: a column model decides each column from
    /// its lowest and highest sample, refining its height only as far as these two need, and
    /// stops at the first column that does not settle it.
    fn uniform_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        let _ = (dirs, radii);
        None
    }

    /// Radii between which the surface can lie: below the first everything is solid, above the
    /// second everything is air. `None` when the source cannot tell. Used to skip chunks that
    /// hold no surface without sampling them.
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        None
    }

    /// The radius of the ground along each unit direction of `dirs`, into `out` (as long as
    /// `dirs`), as the terrain's height model gives it before its 3D features (overhangs, caves,
    /// rocks) move the surface, band-limited to features of about `detail` metres: the height a
    /// viewer colours the ground by from afar, the same whatever level of detail is drawn.
    /// Returns `false`, leaving `out` as it is, when the density has no height model.
    fn ground_radii(&self, dirs: &[DVec3], detail: f64, out: &mut [f64]) -> bool {
        let _ = (dirs, detail, out);
        false
    }
}

/// What a density batch computed once per direction (a column model's columns), kept with the
/// directions it belongs to and the model that computed it ([`Density::sample_shell_keeping`]).
///
/// A reader gets the values back only for the same model (its `owner` key: the address of the
/// model the density and the shader share), exactly the same directions and the same type
/// ([`ShellColumns::get`]); anything else finds nothing and computes the columns itself. So
/// keeping columns saves work and never changes a result.
#[derive(Default)]
pub struct ShellColumns {
    owner: usize,
    dirs: Vec<DVec3>,
    values: Option<Box<dyn Any + Send + Sync>>,
}

impl std::fmt::Debug for ShellColumns {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShellColumns")
            .field("dirs", &self.dirs.len())
            .field("kept", &self.values.is_some())
            .finish()
    }
}

impl ShellColumns {
    /// Forgets the kept values ([`get`](Self::get) finds nothing until the next
    /// [`keep`](Self::keep), which reuses their allocation).
    pub fn clear(&mut self) {
        self.dirs.clear();
    }

    /// Whether nothing is kept.
    pub fn is_empty(&self) -> bool {
        self.dirs.is_empty()
    }

    /// The values `owner` kept for `dirs` as a slice of `T` (one per direction), if these are
    /// exactly the directions they were computed for (bit for bit) and they are of type `T`.
    pub fn get<T: 'static>(&self, owner: usize, dirs: &[DVec3]) -> Option<&[T]> {
        let values = self.values.as_ref()?.downcast_ref::<Vec<T>>()?;
        let same = owner == self.owner
            && self.dirs.len() == dirs.len()
            && self
                .dirs
                .iter()
                .zip(dirs)
                .all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits));
        (same && values.len() == dirs.len()).then_some(values.as_slice())
    }

    /// Keeps values of type `T` for `dirs`, computed by the model `owner` names (a key unique
    /// among the models alive, such as the address of the model shared by a terrain's density
    /// and shader): `fill` writes them into an empty vector (reusing the previous allocation
    /// when its type matches) and must push one per direction.
    pub fn keep<T: Send + Sync + 'static>(&mut self, owner: usize, dirs: &[DVec3], fill: impl FnOnce(&mut Vec<T>)) {
        self.keep_reusing(owner, dirs, |values: &mut Vec<T>| {
            values.clear();
            fill(values)
        });
    }

    /// As [`ShellColumns::keep`], but `fill` gets the vector with the values kept before, when
    /// their type matches (to overwrite in place: large values then cost no copy of a whole
    /// value), and must leave exactly one value per direction in it (values of any other count
    /// are never read).
    pub fn keep_reusing<T: Send + Sync + 'static>(
        &mut self,
        owner: usize,
        dirs: &[DVec3],
        fill: impl FnOnce(&mut Vec<T>),
    ) {
        let mut values: Box<Vec<T>> = match self.values.take().map(|v| v.downcast::<Vec<T>>()) {
            Some(Ok(v)) => v,
            _ => Box::default(),
        };
        fill(&mut values);
        self.owner = owner;
        self.dirs.clear();
        self.dirs.extend_from_slice(dirs);
        self.values = Some(values);
    }
}

impl<T: Density + ?Sized> Density for Box<T> {
    fn density(&self, p: DVec3) -> f64 {
        (**self).density(p)
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        (**self).sample_shell(dirs, radii, out)
    }
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        (**self).sample_shell_keeping(dirs, radii, out, columns)
    }
    fn uniform_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        (**self).uniform_sign(dirs, radii)
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        (**self).radial_bounds()
    }
    fn ground_radii(&self, dirs: &[DVec3], detail: f64, out: &mut [f64]) -> bool {
        (**self).ground_radii(dirs, detail, out)
    }
}

impl<T: Density + ?Sized> Density for std::sync::Arc<T> {
    fn density(&self, p: DVec3) -> f64 {
        (**self).density(p)
    }
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        (**self).sample_shell(dirs, radii, out)
    }
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        (**self).sample_shell_keeping(dirs, radii, out, columns)
    }
    fn uniform_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        (**self).uniform_sign(dirs, radii)
    }
    fn radial_bounds(&self) -> Option<(f64, f64)> {
        (**self).radial_bounds()
    }
    fn ground_radii(&self, dirs: &[DVec3], detail: f64, out: &mut [f64]) -> bool {
        (**self).ground_radii(dirs, detail, out)
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
    fn kept_columns_come_back_only_for_the_same_model_directions_and_type() {
        let dirs = [DVec3::X, DVec3::Y];
        let mut kept = ShellColumns::default();
        assert!(kept.is_empty() && kept.get::<f64>(7, &dirs).is_none());
        kept.keep(7, &dirs, |v: &mut Vec<f64>| v.extend([1.0, 2.0]));
        assert_eq!(kept.get::<f64>(7, &dirs), Some(&[1.0, 2.0][..]));
        assert!(kept.get::<f64>(8, &dirs).is_none(), "another model");
        assert!(kept.get::<f32>(7, &dirs).is_none(), "another type");
        assert!(kept.get::<f64>(7, &[DVec3::X]).is_none(), "fewer directions");
        assert!(kept.get::<f64>(7, &[DVec3::X, DVec3::Z]).is_none(), "other directions");
        let nudged = DVec3::new(f64::from_bits(1.0f64.to_bits() - 1), 0.0, 0.0);
        assert!(kept.get::<f64>(7, &[nudged, DVec3::Y]).is_none(), "one bit off");
        // A default batch keeps nothing; a keeper of the wrong count is never read.
        Sphere { radius: 1.0 }.sample_shell_keeping(&dirs, &[1.0], &mut [0.0; 2], &mut kept);
        assert!(kept.is_empty() && kept.get::<f64>(7, &dirs).is_none());
        kept.keep(7, &dirs, |v: &mut Vec<f64>| v.push(1.0));
        assert!(kept.get::<f64>(7, &dirs).is_none(), "one value for two directions");
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
