//! Bounding spheres of chunks, and the chunks near a point.
//!
//! # Why the spheres bound every vertex
//!
//! A chunk's vertices lie on grid edges between its own voxels, so they lie in the convex hull of
//! those voxels: points `d r` with `d` a voxel column direction of the chunk and `r` between the
//! radii of its lowest and highest layer. The column directions lie in the image on the sphere of
//! the chunk's rectangle of face coordinates `(u, v)`.
//!
//! - *A cap holds the rectangle's image.* Take the axis `a` = the direction of the rectangle's
//!   centre and `theta` = the largest angle between `a` and the image of the rectangle's border.
//!   The image is a disc on the sphere bounded by the border's image, it does not hold `-a` (it
//!   lies on one face, within the face's hemisphere), and the cap `{d : angle(a, d) <= theta}` is
//!   convex for `theta < 90 deg`; so the whole image lies in the cap. The border is sampled, and
//!   every border point lies within half a sample spacing `s` (in `(u, v)`) of a sample; the map
//!   `(u, v) -> direction` stretches lengths by at most 1 (its Jacobian's largest singular value
//!   is 1, reached at the middle of the face edges; [`LIPSCHITZ`] adds a margin and a test checks
//!   it), so `theta = max sampled angle + LIPSCHITZ s / 2` is sound.
//! - *A sphere holds the cap between two radii.* For a centre `h a` on the axis, the squared
//!   distance to `d r` is `(r - h)^2 + 4 r h sin^2(phi / 2)` (`phi` the angle of `d` from `a`):
//!   largest at `phi = theta`, and convex in `r`, so largest at `r0` or `r1`. The code picks
//!   the best of a few heights `h` and multiplies the radius by [`RADIUS_FACTOR`].
//!
//! # Finding the chunks near a point
//!
//! Each face is searched as a quadtree over its chunk columns: a node's rectangle gets a cap as
//! above, and a node is skipped when the nearest point of its part of the shell (the directions of
//! the cap, the radii of the shell) lies farther from the query than the range plus `2 x` the
//! largest possible chunk sphere (a chunk sphere that reaches within the range holds a voxel of
//! the chunk, which lies in the node's part of the shell, within twice its radius of any of its
//! points). In a column only the chunks whose layers come that near are looked at: the nearest
//! distance is convex in the radius, so those chunks are consecutive, found from the layer nearest
//! the query. So the result is exactly the brute-force list, visiting only chunks near the point:
//! what the range reaches, not the shell's thickness (32.8 km on the Earth) around it.
//!
//! The nearest distance from `p` (radius `rho`, angle `theta` from the cap's axis) to a direction
//! of the cap at radius `r`: the angle between them is at least `gamma = max(0, theta - angle)`,
//! and `|p - d r|^2 = (r - rho)^2 + 4 r rho sin^2(gamma / 2)` is least at `r = rho cos gamma`
//! (clamped to the radii).

use pmc_geometry::glam::DVec3;
use pmc_geometry::{face_uv_to_cube, face_uv_to_sphere, ChunkKey, Face, Layout};
use pmc_planet::Planet;

/// Upper bound (with a 2% margin) of how much `(u, v) -> face_uv_to_sphere(face, u, v)` stretches
/// lengths: arc length on the unit sphere per unit of `(u, v)` distance.
pub const LIPSCHITZ: f64 = 1.02;
/// Every sphere's radius is multiplied by this, for rounding and `f32` vertex storage.
pub const RADIUS_FACTOR: f64 = 1.02;
/// Beyond this cap angle (radians, about 86 degrees) a sphere around the planet centre is used.
const MAX_CAP_ANGLE: f64 = 1.5;
/// Border samples per side of a quadtree node.
const NODE_SAMPLES: u32 = 16;
/// [`chunks_near`] tests at most this many chunks per chunk of its budget.
const TESTED_PER_BUDGET: usize = 8;

/// A sphere, in metres, planet-centred.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
}

impl BoundingSphere {
    /// Distance from `p` to the sphere (0 inside it).
    pub fn distance(&self, p: DVec3) -> f64 {
        ((p - self.center).length() - self.radius).max(0.0)
    }
}

/// A cap on the unit sphere: the directions within `angle` of `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cap {
    axis: DVec3,
    angle: f64,
}

/// The angle between two unit vectors, accurate for small angles.
pub(crate) fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The cap holding the image of the face rectangle `[u0, u1] x [v0, v1]`, from `samples + 1`
/// samples per side of its border.
///
/// The angle is the largest of `atan2(|a x p|, a . p)` over the samples `p` (normalised). That
/// is evaluated only where it can be the largest: for the samples whose tangent
/// `|a x p| / a . p`, estimated on a direction computed with a few products where
/// `face_uv_to_sphere` divides, comes within [`RATIO_MARGIN`] (relative) or [`TANGENT_SLACK`]
/// (absolute) of the largest. A sample further below has a smaller angle by far more than the
/// rounding of `atan2`, of the normalisation and of the estimate (a few units in the last place
/// of numbers near 1), so the result has the same bits as the largest `atan2` over every sample.
/// Samples at 90 degrees or more from the axis, or anything not finite, fall back to evaluating
/// every sample.
fn rect_cap(face: Face, u0: f64, u1: f64, v0: f64, v1: f64, samples: u32) -> Cap {
    let axis = face_uv_to_sphere(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1)).normalize();
    let m = f64::from(samples);
    // Each sample, its squared sine and squared cosine (of the estimate, not normalised).
    let mut found = Vec::with_capacity(4 * (samples as usize + 1));
    let (mut best_sin2, mut best_cos2) = (0.0f64, 1.0f64);
    let mut ahead = true;
    for s in 0..=samples {
        let t = f64::from(s) / m;
        let (u, v) = (u0 + (u1 - u0) * t, v0 + (v1 - v0) * t);
        for (su, sv) in [(u, v0), (u, v1), (u0, v), (u1, v)] {
            let p = direction_estimate(face, su, sv);
            let (sin2, cos) = (axis.cross(p).length_squared(), axis.dot(p));
            let cos2 = cos * cos;
            if cos > 0.0 && sin2.is_finite() && sin2 <= MAX_RATIO * MAX_RATIO * cos2 {
                if sin2 * best_cos2 > best_sin2 * cos2 {
                    (best_sin2, best_cos2) = (sin2, cos2);
                }
            } else {
                ahead = false;
            }
            found.push((su, sv, sin2, cos2));
        }
    }
    let low = ((best_sin2 / best_cos2).sqrt() * (1.0 - RATIO_MARGIN) - TANGENT_SLACK).max(0.0);
    let threshold = low * low;
    let mut angle: f64 = 0.0;
    for (su, sv, sin2, cos2) in found {
        if !ahead || sin2 >= threshold * cos2 {
            angle = angle.max(angle_between(axis, face_uv_to_sphere(face, su, sv).normalize()));
        }
    }
    let spacing = (u1 - u0).max(v1 - v0) / m;
    Cap {
        axis,
        angle: angle + LIPSCHITZ * 0.5 * spacing,
    }
}

/// [`face_uv_to_sphere`] with products by `1 / 3` where it divides by 3: within a few units in
/// the last place of it.
fn direction_estimate(face: Face, u: f64, v: f64) -> DVec3 {
    const THIRD: f64 = 1.0 / 3.0;
    let c = face_uv_to_cube(face, u, v);
    let (x2, y2, z2) = (c.x * c.x, c.y * c.y, c.z * c.z);
    DVec3::new(
        c.x * (1.0 - y2 * 0.5 - z2 * 0.5 + y2 * z2 * THIRD).sqrt(),
        c.y * (1.0 - z2 * 0.5 - x2 * 0.5 + z2 * x2 * THIRD).sqrt(),
        c.z * (1.0 - x2 * 0.5 - y2 * 0.5 + x2 * y2 * THIRD).sqrt(),
    )
}

/// [`rect_cap`] evaluates `atan2` only for samples whose tangent is within this relative margin
/// of the largest, or within [`TANGENT_SLACK`] of it.
const RATIO_MARGIN: f64 = 1e-9;
/// The absolute margin of [`rect_cap`]'s tangents: a thousand times the rounding of a sine
/// computed from unit vectors, for caps so small that the relative margin is not enough.
const TANGENT_SLACK: f64 = 1e-12;
/// Tangents above this (angles within 0.06 degrees of 90) make [`rect_cap`] evaluate every
/// sample: there `atan2` flattens and the margins would no longer dwarf its rounding.
const MAX_RATIO: f64 = 1e3;

/// Squared distance from `h a` to a point at radius `r` and angle `angle` from `a`, given
/// `half_sin = sin(angle / 2)`.
fn dist2(r: f64, h: f64, half_sin: f64) -> f64 {
    (r - h) * (r - h) + 4.0 * r * h * half_sin * half_sin
}

/// A sphere holding every point `d r` with `d` in `cap` and `r` in `[r0, r1]` (`0 < r0 <= r1`).
pub(crate) fn cap_sphere(cap: Cap, r0: f64, r1: f64) -> BoundingSphere {
    let pad = |radius: f64| radius * RADIUS_FACTOR + 1e-9 * r1;
    if cap.angle >= MAX_CAP_ANGLE {
        return BoundingSphere {
            center: DVec3::ZERO,
            radius: pad(r1),
        };
    }
    let (c, s) = (cap.angle.cos(), (0.5 * cap.angle).sin());
    let (h, d2) = [r0 * c, r1 * c, 0.5 * (r0 + r1) / c, r1]
        .into_iter()
        .map(|h| h.clamp(0.0, r1))
        .map(|h| (h, dist2(r0, h, s).max(dist2(r1, h, s))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((r1, 0.0));
    BoundingSphere {
        center: cap.axis * h,
        radius: pad(d2.sqrt()),
    }
}

/// Face coordinate (`-1..=1`) of face grid index `t` of `n` tiles per side.
fn uv(t: i64, n: i64) -> f64 {
    2.0 * t as f64 / n as f64 - 1.0
}

/// Level-0 tiles along one axis of a chunk of `level`.
fn span(layout: &Layout, level: u8) -> i64 {
    i64::from(layout.n_t()) << level
}

/// The cap of the column of chunks `(face, level, i, j, *)`.
pub(crate) fn column_cap(layout: &Layout, face: Face, level: u8, i: u32, j: u32) -> Cap {
    let (n, s) = (layout.face_tiles(), span(layout, level));
    let (ti, tj) = (i64::from(i) * s, i64::from(j) * s);
    rect_cap(face, uv(ti, n), uv(ti + s, n), uv(tj, n), uv(tj + s, n), layout.n_t())
}

/// The radii of the lowest and highest voxel layer of chunks `k` of `level`.
pub(crate) fn layer_range(layout: &Layout, level: u8, k: u32) -> (f64, f64) {
    let s = span(layout, level);
    let (lo, hi) = (i64::from(k) * s, (i64::from(k + 1) * s).min(vertex_top(layout, level)));
    (layout.layer_radius(lo), layout.layer_radius(hi.max(lo)))
}

/// The highest layer a level-`level` vertex can reach: a vertex lies on an edge with a solid
/// end, solid voxels lie below the shell's top layer `D` (the shell contract makes every layer
/// from `D` up air), so no vertex lies above the first layer of the level's stride at or past
/// `D`. This keeps the spheres of coarse chunks that overhang the shell tight.
fn vertex_top(layout: &Layout, level: u8) -> i64 {
    let stride = 1i64 << level;
    let d = layout.depth_tiles();
    (d + stride - 1) / stride * stride
}

/// A sphere that holds every vertex chunk `key` can have. `key` must be a chunk of `layout`.
pub fn chunk_sphere(layout: &Layout, key: &ChunkKey) -> BoundingSphere {
    let cap = column_cap(layout, key.face, key.level, key.i, key.j);
    let (r0, r1) = layer_range(layout, key.level, key.k);
    cap_sphere(cap, r0, r1)
}

/// An upper bound of [`chunk_sphere`]'s radius over every chunk of `level`.
fn max_chunk_radius(layout: &Layout, level: u8) -> f64 {
    let (n, s) = (layout.face_tiles() as f64, span(layout, level) as f64);
    // The largest angle a column cap can get: half diagonal plus the sampling margin (one voxel
    // column stride), both stretched by at most LIPSCHITZ.
    let angle = LIPSCHITZ * (std::f64::consts::SQRT_2 * s / n + (1u64 << level) as f64 / n);
    // The outermost layer any chunk of the level reaches: past the shell's top for coarse levels
    // whose depth chunks overhang it.
    let r = layout.radius().max(layout.layer_radius(vertex_top(layout, level)));
    if angle >= MAX_CAP_ANGLE {
        return 2.0 * r;
    }
    // The sphere centred at h = r1 has radius^2 <= w^2 + 4 r^2 sin^2(angle / 2).
    // The radial extent of the vertices: a chunk's layers, cut at the highest layer a vertex
    // can reach (see `vertex_top`).
    let w = s.min(vertex_top(layout, level) as f64) * layout.l_d();
    let sin = (0.5 * angle).sin();
    (w * w + 4.0 * r * r * sin * sin).sqrt() * RADIUS_FACTOR + 1e-9 * r
}

/// A chunk near the query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChunkHit {
    /// The chunk.
    pub key: ChunkKey,
    /// Its bounding sphere.
    pub sphere: BoundingSphere,
    /// Distance from the query point to the sphere (0 inside).
    pub distance: f64,
}

/// The query was too broad: more chunks in range than the budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooManyChunks {
    /// The budget that was exceeded.
    pub budget: usize,
}

/// The chunks of `level` whose bounding spheres come within `range` of `point` and that may hold
/// surface, nearest first (ties by key), with their total count; at most `limit` are returned.
/// Fails when more than `budget` chunks lie in range. The work is in proportion to the chunks in
/// range (and those within twice a chunk's size of it), not to the planet's or the shell's size.
pub fn chunks_near(
    planet: &Planet,
    level: u8,
    point: DVec3,
    range: f64,
    limit: usize,
    budget: usize,
) -> Result<(Vec<ChunkHit>, usize), TooManyChunks> {
    let layout = planet.layout();
    let mut search = Search {
        planet,
        layout,
        level,
        point,
        range,
        margin: 2.0 * max_chunk_radius(layout, level),
        budget,
        tested: 0,
        hits: Vec::new(),
    };
    let n = layout.chunks_per_side(level);
    for face in Face::ALL {
        search.node(face, 0, n, 0, n)?;
    }
    let mut hits = search.hits;
    hits.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.key.cmp(&b.key)));
    let total = hits.len();
    hits.truncate(limit);
    Ok((hits, total))
}

struct Search<'a> {
    planet: &'a Planet,
    layout: &'a Layout,
    level: u8,
    point: DVec3,
    range: f64,
    margin: f64,
    budget: usize,
    tested: usize,
    hits: Vec<ChunkHit>,
}

impl Search<'_> {
    /// Searches the chunk columns `[i0, i1) x [j0, j1)` of `face`.
    fn node(&mut self, face: Face, i0: u32, i1: u32, j0: u32, j1: u32) -> Result<(), TooManyChunks> {
        if i0 >= i1 || j0 >= j1 {
            return Ok(());
        }
        if i1 - i0 == 1 && j1 - j0 == 1 {
            return self.column(face, i0, j0);
        }
        let (n, s) = (self.layout.face_tiles(), span(self.layout, self.level));
        let t = |c: u32| uv(i64::from(c) * s, n);
        let cap = rect_cap(face, t(i0), t(i1), t(j0), t(j1), NODE_SAMPLES);
        if cap_distance(cap, self.layout.d_b(), self.layout.radius(), self.point) > self.reach() {
            return Ok(());
        }
        let (im, jm) = (i0 + (i1 - i0).div_ceil(2), j0 + (j1 - j0).div_ceil(2));
        self.node(face, i0, im, j0, jm)?;
        self.node(face, im, i1, j0, jm)?;
        self.node(face, i0, im, jm, j1)?;
        self.node(face, im, i1, jm, j1)
    }

    /// How near a chunk's voxels must come to the query for its sphere to reach within the range.
    fn reach(&self) -> f64 {
        // (and a little more for the rounding of the nearest distance)
        self.range + self.margin + 1e-9 * self.layout.radius()
    }

    /// Tests the chunks of the column `(face, i, j)` whose layers come within reach of the query
    /// (consecutive: see the module docs), from the chunk of the nearest radius outward.
    fn column(&mut self, face: Face, i: u32, j: u32) -> Result<(), TooManyChunks> {
        let cap = column_cap(self.layout, face, self.level, i, j);
        let depth = self.layout.depth_chunks(self.level);
        let near = |k: u32| {
            let (r0, r1) = layer_range(self.layout, self.level, k);
            cap_distance(cap, r0, r1, self.point)
        };
        // the chunk holding the radius nearest the query: the last whose bottom is at or below it
        let target = nearest_radius(cap, self.point);
        let (mut lo, mut hi) = (0u32, depth);
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if layer_range(self.layout, self.level, mid).0 <= target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let start = lo;
        if near(start) > self.reach() {
            return Ok(());
        }
        let mut first = start;
        while first > 0 && near(first - 1) <= self.reach() {
            first -= 1;
        }
        let mut last = start;
        while last + 1 < depth && near(last + 1) <= self.reach() {
            last += 1;
        }
        for k in first..=last {
            let key = ChunkKey {
                face,
                level: self.level,
                i,
                j,
                k,
            };
            if !self.planet.may_hold_surface(&key) {
                continue;
            }
            // (the chunks tested and not in range lie in the margin around the range: a few per
            // chunk in range, more only for ranges under a chunk's size; a bound all the same)
            self.tested += 1;
            if self.tested > self.budget.saturating_mul(TESTED_PER_BUDGET) {
                return Err(TooManyChunks { budget: self.budget });
            }
            let (r0, r1) = layer_range(self.layout, self.level, k);
            let sphere = cap_sphere(cap, r0, r1);
            let distance = sphere.distance(self.point);
            if distance <= self.range {
                if self.hits.len() >= self.budget {
                    return Err(TooManyChunks { budget: self.budget });
                }
                self.hits.push(ChunkHit { key, sphere, distance });
            }
        }
        Ok(())
    }
}

/// The least angle between direction `p` and a direction of `cap` (0 when `p` lies in it).
fn cap_gap(cap: Cap, p: DVec3) -> f64 {
    let theta = cap.axis.cross(p).length().atan2(cap.axis.dot(p));
    (theta - cap.angle).max(0.0)
}

/// The radius at which the points of `cap`'s directions come nearest `p` (`rho cos gamma`, see
/// the module docs; not clamped to any shell).
fn nearest_radius(cap: Cap, p: DVec3) -> f64 {
    p.length() * cap_gap(cap, p).cos()
}

/// The least distance from `p` to a point `d r` with `d` in `cap` and `r` in `[r0, r1]`.
fn cap_distance(cap: Cap, r0: f64, r1: f64, p: DVec3) -> f64 {
    let rho = p.length();
    let gamma = cap_gap(cap, p);
    let r = (rho * gamma.cos()).clamp(r0, r1.max(r0));
    dist2(r, rho, (0.5 * gamma).sin()).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_planet::PresetKind;
    use proptest::prelude::*;

    /// The largest stretch of the face map, by finite differences on a dense grid.
    #[test]
    fn lipschitz_bound_holds() {
        let n = 300;
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for face in [Face::Top, Face::East, Face::North] {
            for a in 0..=n {
                for b in 0..=n {
                    let u = (-1.0 + 2.0 * a as f64 / n as f64).clamp(-1.0 + h, 1.0 - h);
                    let v = (-1.0 + 2.0 * b as f64 / n as f64).clamp(-1.0 + h, 1.0 - h);
                    let su = (face_uv_to_sphere(face, u + h, v) - face_uv_to_sphere(face, u - h, v)) / (2.0 * h);
                    let sv = (face_uv_to_sphere(face, u, v + h) - face_uv_to_sphere(face, u, v - h)) / (2.0 * h);
                    // Largest singular value of the 3x2 Jacobian [su sv].
                    let (p, q, r) = (su.dot(su), su.dot(sv), sv.dot(sv));
                    let l = 0.5 * (p + r) + (0.25 * (p - r) * (p - r) + q * q).sqrt();
                    worst = worst.max(l.sqrt());
                }
            }
        }
        assert!(worst <= 1.0 + 1e-6, "stretch {worst}");
        assert!(worst > 0.99, "stretch {worst}: the bound should be nearly tight");
        assert!(LIPSCHITZ >= worst * 1.01);
    }

    fn layouts() -> Vec<Layout> {
        vec![
            Layout::new(2, 8, 100.0, 2.0, 2).unwrap(),
            Layout::new(1, 6, 30.0, 3.0, 1).unwrap(),
            Layout::new(4, 4, 60.0, 4.0, 4).unwrap(),
            // Coarse chunks reach past the shell's top (three level-0 chunks deep, four per
            // level-2 chunk).
            Layout::new(4, 4, 60.0, 4.0, 3).unwrap(),
        ]
    }

    #[test]
    fn spheres_hold_every_vertex_and_reachable_voxel_and_are_tight() {
        for layout in layouts() {
            for preset in [PresetKind::Sphere, PresetKind::Earthlike, PresetKind::Moon] {
                let planet = Planet::new(preset, 5, layout);
                for level in 0..=layout.max_level() {
                    for key in layout.chunks(level) {
                        let s = chunk_sphere(&layout, &key);
                        let m = planet.chunk_mesh(key);
                        for v in 0..m.vertex_count() {
                            let d = (m.world_position(v) - s.center).length();
                            assert!(d <= s.radius, "{key}: vertex at {d} outside {}", s.radius);
                        }
                        // The voxels of the chunk a vertex can touch (up to the first layer of
                        // the level at or past the shell's top), and how tight the sphere is
                        // around them.
                        let grid = pmc_geometry::ChunkGrid::new(&layout, key);
                        let top = vertex_top(&layout, level);
                        let mut far: f64 = 0.0;
                        for c in (1..=grid.tiles + 1).filter(|c| grid.k0 + (*c as i64 - 1) * grid.stride <= top) {
                            for b in 1..=grid.tiles + 1 {
                                for a in 1..=grid.tiles + 1 {
                                    far = far.max((grid.position(a, b, c) - s.center).length());
                                }
                            }
                        }
                        assert!(far <= s.radius, "{key}: voxel at {far} outside {}", s.radius);
                        assert!(
                            s.radius <= 1.35 * far,
                            "{key}: radius {} for voxels within {far}",
                            s.radius
                        );
                        assert!(s.radius <= max_chunk_radius(&layout, level), "{key}");
                    }
                }
            }
        }
    }

    #[test]
    fn spheres_stay_tight_at_earth_radius() {
        let layout = Layout::new(1 << 17, 32, 6.37e6, 2.0, 2).unwrap();
        let key = ChunkKey::new(Face::South, 70_000, 3_000, 1);
        let s = chunk_sphere(&layout, &key);
        let grid = pmc_geometry::ChunkGrid::new(&layout, key);
        let mut far: f64 = 0.0;
        for c in [1, grid.tiles + 1] {
            for b in 1..=grid.tiles + 1 {
                for a in 1..=grid.tiles + 1 {
                    far = far.max((grid.position(a, b, c) - s.center).length());
                }
            }
        }
        assert!(far <= s.radius && s.radius <= 1.35 * far, "{} vs {far}", s.radius);
    }

    fn brute_force(planet: &Planet, level: u8, p: DVec3, range: f64) -> Vec<ChunkHit> {
        let layout = planet.layout();
        let mut v: Vec<ChunkHit> = layout
            .chunks(level)
            .into_iter()
            .filter(|k| planet.may_hold_surface(k))
            .map(|key| {
                let sphere = chunk_sphere(layout, &key);
                ChunkHit {
                    key,
                    sphere,
                    distance: sphere.distance(p),
                }
            })
            .filter(|h| h.distance <= range)
            .collect();
        v.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.key.cmp(&b.key)));
        v
    }

    /// `chunks_near` from the point `dist` planet radii along `dir` (the centre for a tiny `dir`)
    /// finds exactly the brute force's chunks, in its order.
    fn same_as_brute_force(
        planet: &Planet,
        dir: [f64; 3],
        dist: f64,
        range: f64,
        level: u8,
    ) -> Result<(), TestCaseError> {
        let layout = planet.layout();
        let level = level.min(layout.max_level());
        let d = DVec3::from_array(dir);
        let p = if d.length() < 1e-6 {
            DVec3::ZERO
        } else {
            d.normalize() * dist * layout.radius()
        };
        let (hits, total) = chunks_near(planet, level, p, range, usize::MAX, usize::MAX).unwrap();
        let expected = brute_force(planet, level, p, range);
        prop_assert_eq!(total, expected.len());
        prop_assert_eq!(hits, expected);
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn quadtree_search_equals_brute_force(
            dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
            dist in 0.0f64..3.0,
            range in 0.1f64..400.0,
            level in 0u8..4,
        ) {
            // Level 3 chunks reach past the shell's top (four level-0 chunks deep, eight per
            // level-3 chunk).
            let layout = Layout::new(8, 4, 100.0, 2.0, 4).unwrap();
            same_as_brute_force(&Planet::new(PresetKind::Earthlike, 3, layout), dir, dist, range, level)?;
        }

        /// A shell many chunks deep (sixteen level-0 chunks) over a small core: the search walks
        /// each column's chunks from the nearest radius, and must still find every one in range,
        /// from inside the core, in the shell and far outside.
        #[test]
        fn deep_shells_search_equals_brute_force(
            dir in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
            dist in 0.0f64..2.5,
            range in 0.1f64..150.0,
            level in 0u8..5,
            preset in 0usize..3,
        ) {
            let layout = Layout::new(8, 4, 60.0, 1.0, 16).unwrap();
            let kind = [PresetKind::Sphere, PresetKind::Earthlike, PresetKind::Moon][preset];
            same_as_brute_force(&Planet::new(kind, 5, layout), dir, dist, range, level)?;
        }
    }

    /// The least distance to a cap's part of a shell is never more than the distance to any of
    /// its points (sampled), and is that distance for a point straight under the query.
    #[test]
    fn cap_distance_is_a_lower_bound() {
        let layout = Layout::new(8, 4, 60.0, 1.0, 16).unwrap();
        let (r0, r1) = (layout.d_b(), layout.radius());
        let mut worst_gap: f64 = f64::INFINITY;
        for face in Face::ALL {
            let cap = rect_cap(face, -0.3, 0.1, 0.2, 0.7, 16);
            for q in [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(10.0, -80.0, 40.0),
                DVec3::new(150.0, 20.0, -30.0),
                cap.axis * 100.0,
                cap.axis * 20.0,
            ] {
                let bound = cap_distance(cap, r0, r1, q);
                for a in 0..=20 {
                    for b in 0..=20 {
                        let (u, v) = (-0.3 + 0.4 * f64::from(a) / 20.0, 0.2 + 0.5 * f64::from(b) / 20.0);
                        let d = face_uv_to_sphere(face, u, v).normalize();
                        for c in 0..=8 {
                            let r = r0 + (r1 - r0) * f64::from(c) / 8.0;
                            let gap = (q - d * r).length() - bound;
                            assert!(gap >= -1e-9, "{face:?} {q}: a point {gap} nearer than the bound");
                            worst_gap = worst_gap.min(gap);
                        }
                    }
                }
            }
            assert_eq!(cap_distance(cap, r0, r1, cap.axis * 100.0), 0.0);
            assert!((cap_distance(cap, r0, r1, cap.axis * 130.0) - (130.0 - r1)).abs() < 1e-9);
        }
        assert!(worst_gap < 1.0, "the bound is loose by {worst_gap} m");
    }

    /// `GET /api/v1/chunks` on `earth` refused a 50 m range at level 0 and a 20 km range at level 4
    /// ("more than 200000 chunks lie near the point"): the search visited every column within the
    /// shell's 32.8 km thickness, and all its chunks. Now what the range reaches is visited: 54 to
    /// 60 chunks within 50 m at level 0, and at level 4 the 170 000 to 180 000 chunks within 20 km
    /// that the terrain's radial bounds (11 km under the sea to 9 km over it) leave in.
    #[test]
    fn the_earth_chunks_near_a_point_at_fine_and_coarse_levels() {
        let layout = PresetKind::Earth.default_layout(None).unwrap();
        let planet = Planet::new(PresetKind::Earth, 7, layout);
        for (lat, lon) in [(39.0, 0.0), (27.99, 86.93), (-10.0, 120.0)] {
            let ground = pmc_geometry::LatLon::new(lat, lon).unwrap().to_unit() * planet.datum_radius();
            for (level, range) in [(0u8, 50.0), (4, 20_000.0)] {
                let (hits, total) = chunks_near(&planet, level, ground, range, 4096, 200_000).unwrap();
                assert!(
                    total > 0 && hits.len() == total.min(4096),
                    "{lat},{lon} L{level}: {total}"
                );
                // a 50 m range at level 0 (32 m chunks): a few columns, a few chunks deep
                assert!(level != 0 || total < 200, "{lat},{lon}: {total} chunks within 50 m");
                assert!(hits.iter().all(|h| h.distance <= range && h.key.level == level));
            }
        }
    }

    #[test]
    fn limit_budget_and_order() {
        let layout = Layout::new(8, 4, 100.0, 2.0, 4).unwrap();
        let planet = Planet::new(PresetKind::Sphere, 1, layout);
        let p = DVec3::new(0.0, layout.radius(), 0.0);
        let (all, total) = chunks_near(&planet, 0, p, 1e9, usize::MAX, usize::MAX).unwrap();
        assert_eq!(total, all.len());
        assert_eq!(
            total,
            layout.chunks(0).iter().filter(|k| planet.may_hold_surface(k)).count()
        );
        assert!(all.windows(2).all(|w| w[0].distance <= w[1].distance));
        assert_eq!(all[0].key.face, Face::Top);
        let (few, total2) = chunks_near(&planet, 0, p, 1e9, 5, usize::MAX).unwrap();
        assert_eq!((few.as_slice(), total2), (&all[..5], total));
        assert_eq!(
            chunks_near(&planet, 0, p, 1e9, 5, 10),
            Err(TooManyChunks { budget: 10 })
        );
    }

    #[test]
    fn huge_layouts_search_only_near_the_point() {
        // 6 * 2^34 chunks: only those near the point are looked at.
        let layout = Layout::new(1 << 17, 32, 6.37e6, 2.0, 2).unwrap();
        let planet = Planet::new(PresetKind::Earthlike, 1, layout);
        let p = pmc_geometry::LatLon::new(10.0, 20.0).unwrap().to_unit() * planet.datum_radius();
        let (hits, total) = chunks_near(&planet, 0, p, 500.0, 4096, 20_000).unwrap();
        assert!(total > 0 && total == hits.len(), "{total}");
        for h in &hits {
            assert!(h.sphere.distance(p) <= 500.0);
        }
        assert!(chunks_near(&planet, 0, p, 1e6, 4096, 20_000).is_err());
    }
}
