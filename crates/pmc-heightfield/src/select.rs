//! Which patches to draw: six quadtrees split by screen-space error, horizon culling, a depth
//! cap and 2:1 balance, with the stitching flags of every selected patch.

use crate::lattice::{canonical_lattice, resolution, MAX_LEVEL};
use crate::patch::{Corner, PatchError, PatchKey, Side, Stitch};
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{face_uv_to_sphere, Face};
use std::collections::HashSet;

/// How far the map from face coordinates `(u, v)` in `[-1, 1]` to the unit sphere can stretch a
/// length: its Jacobian's largest singular value is 1 (at the middle of the face edges), plus a
/// margin. A test checks it.
pub const LIPSCHITZ: f64 = 1.02;

/// The planet the selection works on: datum radius, height bounds, the geometric error of each
/// level and the depth cap.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightfieldPlanet {
    radius: f64,
    min_height: f64,
    max_height: f64,
    max_level: u8,
    level_errors: Vec<f64>,
}

impl HeightfieldPlanet {
    /// A planet of datum `radius` (metres) whose heights lie in `[min_height, max_height]`, with
    /// patches down to `max_level` (at most [`MAX_LEVEL`]) and the default per-level errors
    /// [`HeightfieldPlanet::default_level_error`].
    pub fn new(radius: f64, min_height: f64, max_height: f64, max_level: u8) -> Result<Self, PatchError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(PatchError::InvalidParameter("radius must be finite and positive"));
        }
        if !(min_height.is_finite() && max_height.is_finite() && min_height <= max_height) {
            return Err(PatchError::InvalidParameter(
                "height bounds must be finite with min_height <= max_height",
            ));
        }
        if radius + min_height <= 0.0 {
            return Err(PatchError::InvalidParameter("radius + min_height must be positive"));
        }
        if max_level > MAX_LEVEL {
            return Err(PatchError::LevelTooDeep {
                level: max_level,
                max: MAX_LEVEL,
            });
        }
        let mut p = HeightfieldPlanet {
            radius,
            min_height,
            max_height,
            max_level,
            level_errors: Vec::new(),
        };
        p.level_errors = (0..=max_level).map(|l| p.default_level_error(l)).collect();
        Ok(p)
    }

    /// Replaces the per-level geometric errors (metres, index = level, `max_level + 1` finite
    /// non-negative values), e.g. measured ones.
    pub fn with_level_errors(mut self, errors: Vec<f64>) -> Result<Self, PatchError> {
        if errors.len() != usize::from(self.max_level) + 1 {
            return Err(PatchError::InvalidParameter("one level error per level 0..=max_level"));
        }
        if errors.iter().any(|e| !(e.is_finite() && *e >= 0.0)) {
            return Err(PatchError::InvalidParameter(
                "level errors must be finite and non-negative",
            ));
        }
        self.level_errors = errors;
        Ok(self)
    }

    /// Datum radius, metres.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Lowest height above the datum, metres.
    pub fn min_height(&self) -> f64 {
        self.min_height
    }

    /// Highest height above the datum, metres.
    pub fn max_height(&self) -> f64 {
        self.max_height
    }

    /// The deepest level the selection may use.
    pub fn max_level(&self) -> u8 {
        self.max_level
    }

    /// The geometric error (metres) of patches of `level` (levels past `max_level` get the last).
    pub fn level_error(&self, level: u8) -> f64 {
        self.level_errors[usize::from(level.min(self.max_level))]
    }

    /// The default error of `level`, a heuristic: with `l` the largest segment length of the level
    /// (`π/2 · (radius + max_height) / (64 · 2^level)`), the height change over one segment at a
    /// slope of at most 1, capped by the height range, plus the sagitta `l² / 8r` of the sphere.
    pub fn default_level_error(&self, level: u8) -> f64 {
        let r = self.radius + self.max_height;
        let l = std::f64::consts::FRAC_PI_2 * r / resolution(level) as f64;
        l.min(self.max_height - self.min_height) + l * l / (8.0 * r)
    }

    /// A sphere that holds every vertex of patch `key` (any stitching) and so, by convexity, every
    /// triangle.
    ///
    /// Every vertex is `d r` with `d` the image of a point of the patch's square of face
    /// coordinates and `r` within `radius + [min_height, max_height]`. The square's points lie
    /// within half its diagonal of its centre and the map to the sphere stretches lengths by at
    /// most [`LIPSCHITZ`], so `d` lies in the cap of angle `θ = LIPSCHITZ · √2 · half side` about
    /// the centre's direction `a`. For a centre `h a`, the squared distance to `d r` is
    /// `(r - h)² + 4 r h sin²(φ/2)`, largest at `φ = θ` and at `r` at either bound; the best of a
    /// few `h` is taken and padded for rounding.
    pub fn bounding_sphere(&self, key: PatchKey) -> BoundingSphere {
        let n = f64::from(1u32 << key.level.min(31));
        let half = 1.0 / n;
        let u = -1.0 + (2.0 * f64::from(key.i) + 1.0) * half;
        let v = -1.0 + (2.0 * f64::from(key.j) + 1.0) * half;
        let axis = face_uv_to_sphere(key.face, u, v);
        let theta = LIPSCHITZ * std::f64::consts::SQRT_2 * half;
        let (r0, r1) = (self.radius + self.min_height, self.radius + self.max_height);
        let (c, s) = (theta.cos(), (0.5 * theta).sin());
        let d2 = |r: f64, h: f64| (r - h) * (r - h) + 4.0 * r * h * s * s;
        let (h, best) = [r0 * c, r1 * c, 0.5 * (r0 + r1) * c, 0.5 * (r0 + r1), r1]
            .into_iter()
            .map(|h| (h, d2(r0, h).max(d2(r1, h))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("candidates");
        BoundingSphere {
            center: axis * h,
            radius: best.sqrt() * (1.0 + 1e-9) + 1e-9 * r1,
        }
    }

    /// The radius of a ball that the surface mesh never enters (so it hides what lies behind it):
    /// `(radius + min_height) cos(0.07)`, since a triangle's vertices lie at or above
    /// `radius + min_height` and within 0.07 rad of each other (at most two segments of level 0,
    /// `4/64` in face coordinates, stretched by [`LIPSCHITZ`]).
    pub fn occluder_radius(&self) -> f64 {
        (self.radius + self.min_height) * 0.07f64.cos()
    }
}

/// A sphere, world coordinates (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
}

impl BoundingSphere {
    /// Distance from `p` to the sphere (0 inside).
    pub fn distance(&self, p: DVec3) -> f64 {
        ((p - self.center).length() - self.radius).max(0.0)
    }
}

/// The viewer: where the camera is and how errors become pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Camera position, world coordinates (metres, planet-centred).
    pub camera: DVec3,
    /// Pixels per unit of error at unit distance: `screen_height / (2 tan(fov_y / 2))` for a
    /// perspective camera. A patch of error `e` at distance `d` shows `e · error_scale / d` pixels.
    pub error_scale: f64,
    /// Split a patch while its projected error exceeds this many pixels.
    pub max_pixel_error: f64,
    /// Do not refine patches hidden behind the planet (they are still selected, with
    /// `visible: false`, so the selection stays closed).
    pub horizon_cull: bool,
}

impl View {
    /// A perspective view: vertical field of view `fov_y` (radians) over `screen_height` pixels,
    /// horizon culling on.
    pub fn perspective(camera: DVec3, fov_y: f64, screen_height: f64, max_pixel_error: f64) -> View {
        View {
            camera,
            error_scale: screen_height / (2.0 * (0.5 * fov_y).tan()),
            max_pixel_error,
            horizon_cull: true,
        }
    }

    fn validate(&self) -> Result<(), PatchError> {
        if !self.camera.is_finite() {
            return Err(PatchError::InvalidParameter("camera must be finite"));
        }
        if !(self.error_scale.is_finite() && self.error_scale > 0.0) {
            return Err(PatchError::InvalidParameter("error_scale must be finite and positive"));
        }
        if !(self.max_pixel_error.is_finite() && self.max_pixel_error > 0.0) {
            return Err(PatchError::InvalidParameter(
                "max_pixel_error must be finite and positive",
            ));
        }
        Ok(())
    }

    /// Whether `s` is certainly hidden behind the ball of radius `rho` about the origin: inside the
    /// cone from the camera tangent to the ball, and beyond the plane of the tangent circle.
    fn hidden(&self, s: &BoundingSphere, rho: f64) -> bool {
        let e = self.camera.length();
        if e <= rho {
            return false;
        }
        let axis = -self.camera / e;
        let to = s.center - self.camera;
        let dist = to.length();
        if dist <= s.radius {
            return false;
        }
        let beta = (rho / e).asin();
        let angle = (to.dot(axis) / dist).clamp(-1.0, 1.0).acos();
        let within_cone = angle + (s.radius / dist).asin() <= beta * (1.0 - 1e-9);
        let beyond_plane = s.center.dot(-axis) + s.radius <= rho * rho / e * (1.0 - 1e-9);
        within_cone && beyond_plane
    }
}

/// One selected patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SelectedPatch {
    /// Which patch.
    pub key: PatchKey,
    /// Where it meets coarser patches (pass to [`crate::generate_patch`]).
    pub stitch: Stitch,
    /// `false` when the patch is certainly hidden behind the planet (horizon culling); such
    /// patches are still part of the closed surface.
    pub visible: bool,
}

/// Selects the patches to draw for `view`: the leaves of six quadtrees, which together cover the
/// sphere exactly once, sorted by key.
///
/// A patch splits while its level is below `planet.max_level()` and its projected error
/// `level_error · error_scale / distance(camera, bounding sphere)` exceeds `max_pixel_error`
/// (always when the camera is inside the sphere), unless horizon culling is on and the sphere is
/// hidden behind the planet. Then patches are split until every two patches that touch (beyond a
/// side, diagonally, across face edges and at cube corners) differ by at most one level, so
/// stitching only ever bridges one level; last, every patch gets its [`Stitch`] flags.
pub fn select(view: &View, planet: &HeightfieldPlanet) -> Result<Vec<SelectedPatch>, PatchError> {
    view.validate()?;
    let rho = planet.occluder_radius();
    let mut leaves = HashSet::new();
    let mut stack: Vec<PatchKey> = Face::ALL.into_iter().map(PatchKey::root).collect();
    while let Some(key) = stack.pop() {
        let sphere = planet.bounding_sphere(key);
        let split = key.level < planet.max_level()
            && !(view.horizon_cull && view.hidden(&sphere, rho))
            && planet.level_error(key.level) * view.error_scale > view.max_pixel_error * sphere.distance(view.camera);
        match key.children() {
            Some(children) if split => stack.extend(children),
            _ => {
                leaves.insert(key);
            }
        }
    }
    balance(&mut leaves);
    let mut out: Vec<SelectedPatch> = leaves
        .iter()
        .map(|&key| SelectedPatch {
            key,
            stitch: stitch_of(&leaves, key),
            visible: !(view.horizon_cull && view.hidden(&planet.bounding_sphere(key), rho)),
        })
        .collect();
    out.sort();
    Ok(out)
}

/// The leaf that covers `cell` when it is `cell` itself or coarser (`None` when `cell` is split).
fn covering_leaf(leaves: &HashSet<PatchKey>, cell: PatchKey) -> Option<PatchKey> {
    (0..=cell.level)
        .rev()
        .filter_map(|l| cell.ancestor(l))
        .find(|a| leaves.contains(a))
}

/// The cells of a patch's level that touch it: four beyond its sides, up to four diagonal.
fn touching_cells(key: PatchKey) -> impl Iterator<Item = PatchKey> {
    const STEPS: [(i32, i32); 8] = [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)];
    STEPS.into_iter().filter_map(move |(di, dj)| key.offset(di, dj))
}

/// Splits leaves until every two touching leaves differ by at most one level.
pub(crate) fn balance(leaves: &mut HashSet<PatchKey>) {
    let mut queue: Vec<PatchKey> = leaves.iter().copied().filter(|k| k.level >= 2).collect();
    while let Some(key) = queue.pop() {
        if !leaves.contains(&key) {
            continue;
        }
        for cell in touching_cells(key) {
            // Split the covering leaf while it is two or more levels coarser.
            while let Some(leaf) = covering_leaf(leaves, cell) {
                if leaf.level + 1 >= key.level {
                    break;
                }
                leaves.remove(&leaf);
                let children = leaf.children().expect("a coarser leaf has children");
                leaves.extend(children);
                queue.extend(children);
            }
        }
    }
}

/// The stitching flags of leaf `key` among balanced `leaves`.
fn stitch_of(leaves: &HashSet<PatchKey>, key: PatchKey) -> Stitch {
    let coarser = |cell: Option<PatchKey>| {
        cell.and_then(|c| covering_leaf(leaves, c))
            .is_some_and(|leaf| leaf.level < key.level)
    };
    let mut s = Stitch::NONE;
    for side in Side::ALL {
        if coarser(Some(key.neighbour(side))) {
            s = s.with_side(side);
        }
    }
    for corner in Corner::ALL {
        if corner.cells().into_iter().any(|(di, dj)| coarser(key.offset(di, dj))) {
            s = s.with_corner(corner);
        }
    }
    s
}

/// Checks a selection: every patch valid, the patches cover each face exactly once, every two
/// touching patches differ by at most one level, and each patch's flags are the ones the
/// selection rule gives. Returns a message naming the first violation.
pub fn check_selection(patches: &[SelectedPatch]) -> Result<(), String> {
    let mut leaves = HashSet::new();
    for p in patches {
        p.key.validate().map_err(|e| e.to_string())?;
        if !leaves.insert(p.key) {
            return Err(format!("patch {} selected twice", p.key));
        }
    }
    // Area: in units of the finest level present, each face must sum to exactly 4^deepest.
    let deepest = patches.iter().map(|p| p.key.level).max().unwrap_or(0);
    let mut area = [0u128; 6];
    for p in patches {
        area[p.key.face.index()] += 1u128 << (2 * u32::from(deepest - p.key.level));
    }
    for face in Face::ALL {
        if area[face.index()] != 1u128 << (2 * u32::from(deepest)) {
            return Err(format!("face {face} is not covered exactly once"));
        }
    }
    // Overlaps: no selected patch has a selected ancestor (with the area this means a tiling).
    for p in patches {
        if let Some(a) = (0..p.key.level)
            .filter_map(|l| p.key.ancestor(l))
            .find(|a| leaves.contains(a))
        {
            return Err(format!("patch {} overlaps its ancestor {a}", p.key));
        }
    }
    for p in patches {
        for cell in touching_cells(p.key) {
            if let Some(leaf) = covering_leaf(&leaves, cell) {
                if leaf.level + 1 < p.key.level {
                    return Err(format!("patch {} touches {leaf}, more than one level coarser", p.key));
                }
            }
        }
        let want = stitch_of(&leaves, p.key);
        if p.stitch != want {
            return Err(format!("patch {} has flags {:?}, expected {:?}", p.key, p.stitch, want));
        }
    }
    Ok(())
}

/// The four corner vertices of a patch as canonical lattice points (for callers building their own
/// adjacency).
pub fn patch_corners(key: PatchKey) -> [IVec3; 4] {
    Corner::ALL.map(|c| canonical_lattice(key.corner_lattice(c), key.resolution()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::face_uv_to_sphere;

    #[test]
    fn lipschitz_bound_holds() {
        // Largest stretch of (u, v) -> sphere over a fine grid, by finite differences.
        let mut worst: f64 = 0.0;
        let h = 1e-6;
        for face in [Face::Top, Face::East] {
            for a in 0..=200 {
                for b in 0..=200 {
                    let (u, v) = (-1.0 + a as f64 / 100.0, -1.0 + b as f64 / 100.0);
                    let (u, v) = (u.clamp(-1.0 + h, 1.0 - h), v.clamp(-1.0 + h, 1.0 - h));
                    let du = (face_uv_to_sphere(face, u + h, v) - face_uv_to_sphere(face, u - h, v)) / (2.0 * h);
                    let dv = (face_uv_to_sphere(face, u, v + h) - face_uv_to_sphere(face, u, v - h)) / (2.0 * h);
                    // Largest singular value of [du dv].
                    let (p, q, r) = (du.dot(du), du.dot(dv), dv.dot(dv));
                    let s = (0.5 * (p + r) + (0.25 * (p - r) * (p - r) + q * q).sqrt()).sqrt();
                    worst = worst.max(s);
                }
            }
        }
        assert!(worst <= LIPSCHITZ, "{worst}");
        assert!(worst > 0.99, "{worst}");
    }
}
