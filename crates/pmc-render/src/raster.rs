//! The rasteriser: project, bin, rasterise a visibility buffer band by band, shade, filter.
//!
//! 1. Every vertex is moved into camera space in `f64` (`origin + position - eye`) and projected
//!    to supersampled screen coordinates (kept in `f64`, so triangles reaching far off screen stay
//!    exact).
//! 2. Each triangle with all three vertices in front of the near plane, front-facing on screen
//!    and covering at least one sample is put in the bins of the horizontal bands it touches.
//! 3. Bands are independent (one rayon task each): the band's triangles are rasterised with edge
//!    functions into a depth buffer (`1/z`, interpolated linearly in screen space) and a buffer of
//!    triangle ids; then every sample is shaded: the ray through the sample is intersected with
//!    the winning triangle in `f64` (perspective-correct barycentrics and the exact distance),
//!    colour and normal are interpolated, lit, covered by the sea and the atmosphere, and the
//!    2x2 samples of each pixel are averaged in linear light and written as sRGB.

use pmc_geometry::glam::DVec3;
use pmc_geometry::math::{smoothstep, srgb_to_linear};
use pmc_mesh::ChunkMesh;
use rayon::prelude::*;

use crate::camera::Frame;
use crate::coverage::Coverage;
use crate::{Camera, Image, RenderError, RenderOptions, MAX_DIMENSION};

/// Samples per pixel along each axis.
const SS: usize = 2;
/// Output rows per band (one rayon task).
const BAND_ROWS: usize = 8;
/// Id of "no triangle" in the visibility buffer.
const NONE: u64 = u64::MAX;
/// Share of the light that reaches faces turned away from the sun.
const AMBIENT: f64 = 0.25;
/// Linear albedo of meshes without a colour per vertex.
const DEFAULT_ALBEDO: [f64; 3] = [0.5, 0.5, 0.5];
/// Linear colour of deep sea water.
const SEA_COLOUR: [f64; 3] = [0.004, 0.025, 0.10];
/// Absorption length per channel relative to the sea's: red goes first, so shallows look
/// turquoise.
const SEA_ABSORB_SCALE: [f64; 3] = [0.45, 0.8, 1.3];
/// Blinn-Phong exponent and strength of the sun's glint on the sea.
const SPEC_POWER: i32 = 512;
const SPEC_STRENGTH: f64 = 0.5;
/// Atmosphere thickness as a fraction of the planet radius, its strongest opacity and its colour.
const ATM_THICKNESS: f64 = 0.02;
const ATM_STRENGTH: f64 = 0.55;
const ATM_COLOUR: [f64; 3] = [0.30, 0.52, 1.0];

/// Renders `meshes` (all in the same planet-centred world frame) as seen by `camera`.
///
/// Triangles are drawn front faces only (counter-clockwise seen from outside, as
/// [`ChunkMesh`] winds them); a triangle with any vertex behind the camera's near plane is
/// dropped. Each sample's colour is the vertex colour (linear RGBA, alpha ignored; mid grey when
/// the mesh has no colours) times `0.25 + 0.75 max(0, n . sun)`, with `n` the interpolated vertex
/// normal (the face normal when the mesh has none). With [`RenderOptions::sea_radius`] a sea sphere
/// is drawn over the terrain, more opaque the longer the ray runs through water (absorption length
/// 15% of the deepest [`ChunkMesh::water_depths`], within 0.05% to 2% of the sea radius, or 0.4%
/// of it without depths; red fades first, so shallows look turquoise), with a glint of the sun. A
/// thin atmosphere (2% of the sea radius or of the mean vertex radius, whichever is larger) hazes
/// the lit side and glows around the lit limb, only above directions that hold some mesh. The
/// planet centre is the world origin. Pixels are the average of 2x2
/// samples, written as sRGB with alpha 255; pixels where nothing was drawn are exactly
/// [`RenderOptions::background`].
///
/// Errors: image size outside 1..=[`MAX_DIMENSION`], a camera value that is not finite (or a
/// camera on its own target), a zero or non-finite sun direction, a non-positive or non-finite sea
/// radius, or a mesh whose indices are not a triangle list over its vertices.
pub fn render(meshes: &[ChunkMesh], camera: &Camera, opts: &RenderOptions) -> Result<Image, RenderError> {
    if opts.width == 0 || opts.height == 0 || opts.width > MAX_DIMENSION || opts.height > MAX_DIMENSION {
        return Err(RenderError::Size {
            width: opts.width,
            height: opts.height,
        });
    }
    let frame = camera.frame()?;
    let sun = opts.sun_dir;
    if !sun.is_finite() || sun.length() == 0.0 {
        return Err(RenderError::Options(format!(
            "sun direction {sun} is not a finite non-zero vector"
        )));
    }
    let sun = sun.normalize();
    if let Some(r) = opts.sea_radius {
        if !(r.is_finite() && r > 0.0) {
            return Err(RenderError::Options(format!(
                "sea radius {r} is not a positive finite number"
            )));
        }
    }
    for (i, m) in meshes.iter().enumerate() {
        check_mesh(i, m)?;
    }

    let (w, h) = (opts.width as usize, opts.height as usize);
    let (sw, sh) = (w * SS, h * SS);
    let view = View {
        frame,
        focal: 0.5 * sh as f64 / frame.tan_half,
        cx: 0.5 * sw as f64,
        cy: 0.5 * sh as f64,
        sw,
        sh,
    };

    let projected: Vec<Projected> = meshes.par_iter().map(|m| project(m, &view)).collect();

    // Bin the visible triangles by band.
    let band_samples = BAND_ROWS * SS;
    let bands = h.div_ceil(BAND_ROWS);
    let covers: Vec<Vec<[u32; 3]>> = meshes
        .par_iter()
        .zip(&projected)
        .map(|(m, p)| {
            (0..m.triangle_count())
                .into_par_iter()
                .filter_map(|t| {
                    let (lo, hi) = sample_rows(m, p, t, &view)?;
                    Some([t as u32, (lo / band_samples) as u32, (hi / band_samples) as u32])
                })
                .collect()
        })
        .collect();
    let mut bins: Vec<Vec<(u32, u32)>> = vec![Vec::new(); bands];
    for (mi, list) in covers.iter().enumerate() {
        for &[t, lo, hi] in list {
            for bin in &mut bins[lo as usize..=hi as usize] {
                bin.push((mi as u32, t));
            }
        }
    }
    drop(covers);

    let shader = Shader::new(meshes, &projected, &view, sun, opts);
    let mut rgba = vec![0u8; w * h * 4];
    rgba.par_chunks_mut(BAND_ROWS * w * 4)
        .zip(bins.par_iter())
        .enumerate()
        .for_each_init(
            || (Vec::new(), Vec::new()),
            |(depth, ids): &mut (Vec<f64>, Vec<u64>), (band, (out, bin))| {
                let rows = out.len() / (4 * w);
                let y0 = band * band_samples;
                let rows_ss = rows * SS;
                depth.clear();
                depth.resize(rows_ss * sw, 0.0);
                ids.clear();
                ids.resize(rows_ss * sw, NONE);
                for &(mi, t) in bin {
                    rasterise(
                        &meshes[mi as usize],
                        &projected[mi as usize],
                        mi,
                        t,
                        &view,
                        y0,
                        rows_ss,
                        depth,
                        ids,
                    );
                }
                shader.resolve(out, w, y0, ids);
            },
        );
    Ok(Image {
        width: opts.width,
        height: opts.height,
        rgba,
    })
}

/// Index buffer checks: a whole number of triangles, every index names a vertex.
fn check_mesh(i: usize, m: &ChunkMesh) -> Result<(), RenderError> {
    let bad = |reason: String| Err(RenderError::Mesh { mesh: i, reason });
    if !m.indices.len().is_multiple_of(3) {
        return bad(format!(
            "{} indices is not a whole number of triangles",
            m.indices.len()
        ));
    }
    if m.indices.len() / 3 > u32::MAX as usize {
        return bad(format!(
            "{} triangles is more than one mesh can hold",
            m.indices.len() / 3
        ));
    }
    let n = m.positions.len();
    if let Some(&bad_index) = m.indices.iter().find(|&&k| k as usize >= n) {
        return bad(format!("index {bad_index} is out of range for {n} vertices"));
    }
    if !m.origin.is_finite() {
        return bad(format!("origin {} is not finite", m.origin));
    }
    Ok(())
}

/// Screen mapping of the supersampled image.
struct View {
    frame: Frame,
    /// Focal length in samples.
    focal: f64,
    cx: f64,
    cy: f64,
    sw: usize,
    sh: usize,
}

impl View {
    /// The unit world direction of the ray through supersampled screen point (`px`, `py`).
    fn ray(&self, px: f64, py: f64) -> DVec3 {
        let f = &self.frame;
        (f.forward + f.right * ((px - self.cx) / self.focal) - f.up * ((py - self.cy) / self.focal)).normalize()
    }
}

/// One mesh in screen space, plus its extent.
struct Projected {
    /// Supersampled screen `x`, `y` and camera depth `z` of each vertex; `z` is NaN behind the
    /// near plane or for a non-finite position.
    verts: Vec<[f64; 3]>,
    /// Sum of the distances of the (finite) vertices from the planet centre, and their count.
    radius_sum: f64,
    radius_count: usize,
    /// Largest water depth of a vertex (0 without the attribute).
    max_water: f64,
}

fn project(m: &ChunkMesh, view: &View) -> Projected {
    let f = &view.frame;
    let (mut radius_sum, mut radius_count) = (0.0, 0);
    let verts = (0..m.positions.len())
        .map(|i| {
            let p = m.world_position(i);
            if p.is_finite() {
                radius_sum += p.length();
                radius_count += 1;
            }
            let rel = p - f.eye;
            let z = rel.dot(f.forward);
            if z >= f.near && z.is_finite() {
                let x = view.cx + view.focal * rel.dot(f.right) / z;
                let y = view.cy - view.focal * rel.dot(f.up) / z;
                [x, y, z]
            } else {
                [0.0, 0.0, f64::NAN]
            }
        })
        .collect();
    let max_water = m
        .water_depths
        .iter()
        .fold(0.0f64, |a, &d| if d.is_finite() { a.max(f64::from(d)) } else { a });
    Projected {
        verts,
        radius_sum,
        radius_count,
        max_water,
    }
}

/// The three projected vertices of triangle `t`.
fn corners(m: &ChunkMesh, p: &Projected, t: usize) -> [[f64; 3]; 3] {
    let i = &m.indices[3 * t..3 * t + 3];
    [p.verts[i[0] as usize], p.verts[i[1] as usize], p.verts[i[2] as usize]]
}

/// Twice the signed screen area (y down): negative for triangles counter-clockwise seen from the
/// camera, that is front faces.
fn signed_area(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// First and last sample index in `0..n` whose centre (`i + 0.5`) lies in `[lo, hi]`.
fn sample_span(lo: f64, hi: f64, n: usize) -> Option<(usize, usize)> {
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(n as f64 - 1.0);
    (first <= last).then_some((first as usize, last as usize))
}

/// The sample rows a visible triangle may cover, or `None` when it is culled (behind the near
/// plane, back-facing or degenerate, or between samples / off screen).
fn sample_rows(m: &ChunkMesh, p: &Projected, t: usize, view: &View) -> Option<(usize, usize)> {
    let [a, b, c] = corners(m, p, t);
    if a[2].is_nan() || b[2].is_nan() || c[2].is_nan() {
        return None;
    }
    let area = signed_area(&a, &b, &c);
    if area.is_nan() || area >= 0.0 {
        return None;
    }
    sample_span(a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]), view.sw)?;
    sample_span(a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]), view.sh)
}

/// Rasterises triangle `t` of mesh `mi` into the band of `rows` sample rows starting at `y0`.
#[allow(clippy::too_many_arguments)]
fn rasterise(
    m: &ChunkMesh,
    p: &Projected,
    mi: u32,
    t: u32,
    view: &View,
    y0: usize,
    rows: usize,
    depth: &mut [f64],
    ids: &mut [u64],
) {
    let [a, b, c] = corners(m, p, t as usize);
    let area = -signed_area(&a, &b, &c);
    let Some((x_lo, x_hi)) = sample_span(a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]), view.sw) else {
        return;
    };
    let Some((y_lo, y_hi)) = sample_span(a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]), view.sh) else {
        return;
    };
    let (y_lo, y_hi) = (y_lo.max(y0), y_hi.min(y0 + rows - 1));
    if y_lo > y_hi || area.is_nan() || area <= 0.0 {
        return;
    }
    // Edge function of edge u -> v, positive inside a front face: w(p) = (v - u) x (p - u) negated
    // for y-down screens. Vertex weights: edge b->c for a, c->a for b, a->b for c.
    // Kept relative to `u` for precision far off screen.
    let edge = |u: &[f64; 3], v: &[f64; 3]| {
        let dx = v[1] - u[1]; // d w / d px
        let dy = -(v[0] - u[0]); // d w / d py
        (dx, dy, u[0], u[1])
    };
    let e = [edge(&b, &c), edge(&c, &a), edge(&a, &b)];
    let inv = 1.0 / area;
    let iz = [inv / a[2], inv / b[2], inv / c[2]];
    let id = (u64::from(mi) << 32) | u64::from(t);
    let px0 = x_lo as f64 + 0.5;
    for y in y_lo..=y_hi {
        let py = y as f64 + 0.5;
        let mut w = [0.0; 3];
        for k in 0..3 {
            w[k] = e[k].0 * (px0 - e[k].2) + e[k].1 * (py - e[k].3);
        }
        let row = (y - y0) * view.sw;
        for x in x_lo..=x_hi {
            if w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0 {
                let z = w[0] * iz[0] + w[1] * iz[1] + w[2] * iz[2];
                let k = row + x;
                if z > depth[k] {
                    depth[k] = z;
                    ids[k] = id;
                }
            }
            w[0] += e[0].0;
            w[1] += e[1].0;
            w[2] += e[2].0;
        }
    }
}

/// The sea sphere and how quickly it hides what is under it.
struct Sea {
    radius: f64,
    /// Absorption length per channel, metres of water along the ray.
    absorb: [f64; 3],
}

/// A thin glowing shell above the planet.
struct Atmosphere {
    outer: f64,
    /// Rays that hit nothing and pass closer to the centre than this look through a gap in the
    /// meshes (a partial planet): no glow for them.
    hole: f64,
    /// Directions that hold terrain: rays that hit nothing glow only above them.
    coverage: Coverage,
    /// Optical length scale, metres.
    scale: f64,
}

/// Everything per-sample shading needs.
struct Shader<'a> {
    meshes: &'a [ChunkMesh],
    view: &'a View,
    sun: DVec3,
    sea: Option<Sea>,
    atmosphere: Option<Atmosphere>,
    background: [f64; 3],
    background_srgb: [u8; 3],
}

impl<'a> Shader<'a> {
    fn new(meshes: &'a [ChunkMesh], projected: &[Projected], view: &'a View, sun: DVec3, opts: &RenderOptions) -> Self {
        let count: usize = projected.iter().map(|p| p.radius_count).sum();
        let mean_radius = projected.iter().map(|p| p.radius_sum).sum::<f64>() / count.max(1) as f64;
        let max_water = projected.iter().fold(0.0f64, |a, p| a.max(p.max_water));
        let sea = opts.sea_radius.map(|radius| {
            // Scale the absorption to the seas at hand: a fraction of the deepest water, kept
            // within sane bounds of the planet size.
            let base = if max_water > 0.0 {
                (0.15 * max_water).clamp(5e-4 * radius, 2e-2 * radius)
            } else {
                4e-3 * radius
            };
            Sea {
                radius,
                absorb: SEA_ABSORB_SCALE.map(|k| k * base),
            }
        });
        // The atmosphere stands on the sea, or on the mean terrain radius when that is higher.
        let surface = mean_radius.max(opts.sea_radius.unwrap_or(0.0));
        let atmosphere = (opts.atmosphere && surface > 0.0 && count > 0).then(|| Atmosphere {
            outer: surface * (1.0 + ATM_THICKNESS),
            hole: 0.9 * mean_radius,
            scale: 4.0 * ATM_THICKNESS * surface,
            coverage: meshes
                .par_iter()
                .fold(Coverage::new, Coverage::add)
                .reduce(Coverage::new, Coverage::merge),
        });
        Shader {
            meshes,
            view,
            sun,
            sea,
            atmosphere,
            background: opts.background.map(srgb_to_linear),
            background_srgb: opts.background,
        }
    }

    /// Shades the output rows of one band from its visibility buffer (`ids`, rows from sample
    /// row `y0`).
    fn resolve(&self, out: &mut [u8], w: usize, y0: usize, ids: &[u64]) {
        let sw = self.view.sw;
        for (oy, row) in out.chunks_exact_mut(4 * w).enumerate() {
            for (ox, px) in row.chunks_exact_mut(4).enumerate() {
                let mut sum = [0.0; 3];
                let mut all_background = true;
                for sy in 0..SS {
                    for sx in 0..SS {
                        let (x, y) = (ox * SS + sx, oy * SS + sy);
                        let (c, is_bg) = self.sample(x as f64 + 0.5, (y0 + y) as f64 + 0.5, ids[y * sw + x]);
                        all_background &= is_bg;
                        for k in 0..3 {
                            sum[k] += c[k];
                        }
                    }
                }
                let rgb = if all_background {
                    self.background_srgb
                } else {
                    sum.map(|s| linear_to_srgb(s / (SS * SS) as f64))
                };
                px.copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
            }
        }
    }

    /// Linear colour of the sample at supersampled screen point (`px`, `py`) whose visible
    /// triangle is `id`, and whether it is plain background.
    fn sample(&self, px: f64, py: f64, id: u64) -> ([f64; 3], bool) {
        let d = self.view.ray(px, py);
        let eye = self.view.frame.eye;
        let (mut colour, mut t_hit) = match self.terrain(id, d) {
            Some((c, t)) => (c, t),
            None => (self.background, f64::INFINITY),
        };
        let mut is_bg = t_hit.is_infinite();

        // Sea.
        let mut t_surface = t_hit;
        if let Some(sea) = &self.sea {
            if let Some((t0, t1)) = sphere_hits(eye, d, sea.radius) {
                let t_in = t0.max(0.0);
                if t1 > 0.0 && t_in < t_hit {
                    let path = t1.min(t_hit) - t_in;
                    let (lit, spec) = if t0 > 0.0 {
                        let n = (eye + d * t0) / sea.radius;
                        let ndl = n.dot(self.sun);
                        let spec = if ndl > 0.0 {
                            let half = (self.sun - d).normalize();
                            SPEC_STRENGTH * n.dot(half).max(0.0).powi(SPEC_POWER)
                        } else {
                            0.0
                        };
                        (AMBIENT + (1.0 - AMBIENT) * ndl.max(0.0), spec)
                    } else {
                        (AMBIENT, 0.0) // camera under water
                    };
                    for k in 0..3 {
                        let a = 1.0 - (-path / sea.absorb[k]).exp();
                        colour[k] = colour[k] * (1.0 - a) + SEA_COLOUR[k] * lit * a + spec * a;
                    }
                    t_surface = t_in;
                    t_hit = t_hit.min(t1);
                    is_bg = false;
                }
            }
        }

        // Atmosphere: glow along the part of the ray inside the shell, lit by the sun.
        if let Some(atm) = &self.atmosphere {
            if let Some((t0, t1)) = sphere_hits(eye, d, atm.outer) {
                let t_start = t0.max(0.0);
                let t_end = t1.min(t_surface);
                let mid = (eye + d * (0.5 * (t_start + t_end))).normalize_or_zero();
                let through_gap = t_hit.is_infinite()
                    && ((eye - d * eye.dot(d)).length_squared() < atm.hole * atm.hole || !atm.coverage.contains(mid));
                if t_end > t_start && !through_gap {
                    let depth = 1.0 - (-(t_end - t_start) / atm.scale).exp();
                    let light = smoothstep(-0.15, 0.35, mid.dot(self.sun));
                    let a = ATM_STRENGTH * depth * depth * light;
                    if a > 1e-5 {
                        for k in 0..3 {
                            colour[k] += (ATM_COLOUR[k] - colour[k]) * a;
                        }
                        is_bg = false;
                    }
                }
            }
        }
        (colour, is_bg)
    }

    /// Lit colour and ray distance of the terrain triangle `id` along unit ray `d` from the eye.
    fn terrain(&self, id: u64, d: DVec3) -> Option<([f64; 3], f64)> {
        if id == NONE {
            return None;
        }
        let m = &self.meshes[(id >> 32) as usize];
        let t = (id & 0xffff_ffff) as usize;
        let i = [
            m.indices[3 * t] as usize,
            m.indices[3 * t + 1] as usize,
            m.indices[3 * t + 2] as usize,
        ];
        let eye = self.view.frame.eye;
        let p0 = m.world_position(i[0]) - eye;
        let e1 = m.world_position(i[1]) - eye - p0;
        let e2 = m.world_position(i[2]) - eye - p0;
        // Moller-Trumbore from the eye (the origin here).
        let pvec = d.cross(e2);
        let det = e1.dot(pvec);
        let (mut u, mut v, dist) = if det != 0.0 {
            let inv = 1.0 / det;
            let tvec = -p0;
            let qvec = tvec.cross(e1);
            (tvec.dot(pvec) * inv, d.dot(qvec) * inv, e2.dot(qvec) * inv)
        } else {
            (1.0 / 3.0, 1.0 / 3.0, p0.dot(d))
        };
        // Samples on an edge may land a hair outside.
        u = if u.is_finite() { u.clamp(0.0, 1.0) } else { 1.0 / 3.0 };
        v = if v.is_finite() { v.clamp(0.0, 1.0) } else { 1.0 / 3.0 };
        if u + v > 1.0 {
            let s = u + v;
            u /= s;
            v /= s;
        }
        let bary = [1.0 - u - v, u, v];
        let dist = if dist.is_finite() && dist > 0.0 {
            dist
        } else {
            (p0 + e1 * u + e2 * v).length()
        };

        let albedo = if m.colors.len() == m.positions.len() {
            let mut c = [0.0; 3];
            for (corner, &b) in i.iter().zip(&bary) {
                let vc = m.colors[*corner];
                for k in 0..3 {
                    c[k] += b * f64::from(vc[k]);
                }
            }
            c.map(|x| x / 255.0)
        } else {
            DEFAULT_ALBEDO
        };
        let face = e1.cross(e2).normalize_or_zero();
        let normal = if m.normals.len() == m.positions.len() {
            let mut n = DVec3::ZERO;
            for (corner, &b) in i.iter().zip(&bary) {
                let vn = m.normals[*corner];
                n += DVec3::new(f64::from(vn[0]), f64::from(vn[1]), f64::from(vn[2])) * b;
            }
            let n = n.normalize_or_zero();
            if n == DVec3::ZERO || !n.is_finite() {
                face
            } else {
                n
            }
        } else {
            face
        };
        let light = AMBIENT + (1.0 - AMBIENT) * normal.dot(self.sun).max(0.0);
        Some((albedo.map(|c| c * light), dist))
    }
}

/// Distances along unit ray `d` from `o` where it enters and leaves the centred sphere of radius
/// `r`, or `None` when it misses.
fn sphere_hits(o: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
    let b = o.dot(d);
    // |o|^2 - b^2 is the squared distance of closest approach, computed stably.
    let closest = (o - d * b).length_squared();
    let disc = r * r - closest;
    if disc.is_nan() || disc <= 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-b - s, -b + s))
}

/// Linear light (clamped to [0, 1]) to an sRGB byte.
pub(crate) fn linear_to_srgb(l: f64) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let s = if l <= 0.0031308 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_every_byte() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb(srgb_to_linear(c)), c);
        }
        assert_eq!(linear_to_srgb(2.0), 255);
        assert_eq!(linear_to_srgb(-1.0), 0);
        assert_eq!(linear_to_srgb(f64::NAN), 0);
    }

    #[test]
    fn sample_span_takes_covered_centres() {
        assert_eq!(sample_span(0.0, 1.0, 10), Some((0, 0)));
        assert_eq!(sample_span(0.6, 1.4, 10), None);
        assert_eq!(sample_span(-5.0, 2.5, 10), Some((0, 2)));
        assert_eq!(sample_span(8.0, 50.0, 10), Some((8, 9)));
        assert_eq!(sample_span(10.6, 50.0, 10), None);
    }

    #[test]
    fn sphere_hits_from_outside_and_inside() {
        let (a, b) = sphere_hits(DVec3::new(0.0, 0.0, 10.0), -DVec3::Z, 2.0).unwrap();
        assert!((a - 8.0).abs() < 1e-12 && (b - 12.0).abs() < 1e-12);
        let (a, b) = sphere_hits(DVec3::ZERO, DVec3::X, 2.0).unwrap();
        assert!((a + 2.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
        assert!(sphere_hits(DVec3::new(0.0, 3.0, 10.0), -DVec3::Z, 2.0).is_none());
    }
}
