//! Where a planet's tiles go in Earth-centred, Earth-fixed metres (the frame of 3D Tiles).
//!
//! A planet's own frame is Y-up: Y the polar axis, longitude 0 on +Z, +90° on +X. ECEF is Z-up:
//! Z to the north pole, X to longitude 0, Y to +90°. The rotation between them is the cyclic
//! permutation `(x, y, z) -> (z, x, y)`.
//!
//! Two frames:
//!
//! - [`TileFrame::Sphere`]: the planet as it is, rotated into ECEF. Heights are above the planet's
//!   own datum sphere. Lengths, angles and bounds are unchanged.
//! - [`TileFrame::Wgs84`]: the planet laid on the WGS84 ellipsoid, so that it lines up with a
//!   globe's imagery and terrain (CesiumJS). A point at geocentric latitude `φ`, longitude `λ`
//!   and radius `r` goes to the ECEF point of geodetic latitude `φ`, longitude `λ` and ellipsoid
//!   height `h = r - datum`: on a sphere both latitudes are the same, and every place keeps its
//!   latitude, longitude and height above sea level. With `u` the unit vector of the point in
//!   ECEF axes and `N = a / sqrt(1 - e² u_z²)` the prime vertical radius:
//!   `W(p) = ((N + h) u_x, (N + h) u_y, (N (1 - e²) + h) u_z)`.
//!   In the local (up, north, east) frame, which the map keeps (the ellipsoid's normal at geodetic
//!   latitude `φ` is `u` itself), its Jacobian is `diag(1, (M + h) / r, (N + h) / r)` with `M`
//!   the meridional radius. So it stretches lengths by at most
//!   `L = max(1, (a²/b + h) / r)` over radii `r >= r_min` (`N, M <= a²/b`, and
//!   `(a²/b - datum + r) / r` falls as `r` grows): a ball of radius `ρ` around `c` lands in the
//!   ball of radius `L ρ` around `W(c)` (the mean value inequality, the ball not holding the
//!   centre). Points move by at most [`TileFrame::max_displacement`] from their place on the
//!   sphere (35.6 km for the Earth's mean radius).

use pmc_geometry::glam::DVec3;

/// WGS84 semi-major axis, metres.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// WGS84 first eccentricity squared, `f (2 - f)`.
fn e2() -> f64 {
    WGS84_F * (2.0 - WGS84_F)
}

/// WGS84 semi-minor axis, metres.
fn wgs84_b() -> f64 {
    WGS84_A * (1.0 - WGS84_F)
}

/// Where a planet's tiles are placed in ECEF metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TileFrame {
    /// The planet as it is, rotated into ECEF axes.
    Sphere,
    /// The planet laid on the WGS84 ellipsoid: latitude, longitude and the height above `datum`
    /// (the planet's sea-level radius, metres) become geodetic latitude, longitude and
    /// ellipsoid height.
    Wgs84 {
        /// The planet's datum radius, metres.
        datum: f64,
    },
}

/// A planet point in ECEF axes (no change of shape).
#[inline]
pub fn to_ecef_axes(p: DVec3) -> DVec3 {
    DVec3::new(p.z, p.x, p.y)
}

impl TileFrame {
    /// The frame's name in the tileset (`"wgs84"` or `"sphere"`).
    pub fn name(&self) -> &'static str {
        match self {
            TileFrame::Sphere => "sphere",
            TileFrame::Wgs84 { .. } => "wgs84",
        }
    }

    /// The ECEF position of planet point `p` (metres, planet frame).
    pub fn to_ecef(&self, p: DVec3) -> DVec3 {
        let e = to_ecef_axes(p);
        match *self {
            TileFrame::Sphere => e,
            TileFrame::Wgs84 { datum } => {
                let r = e.length();
                if r == 0.0 {
                    return e;
                }
                let u = e / r;
                let h = r - datum;
                let n = WGS84_A / (1.0 - e2() * u.z * u.z).sqrt();
                DVec3::new((n + h) * u.x, (n + h) * u.y, (n * (1.0 - e2()) + h) * u.z)
            }
        }
    }

    /// The ECEF direction of a surface normal `n` at planet point `p` (unit length): the normal
    /// transformed by the inverse transpose of the map's Jacobian.
    pub fn normal_to_ecef(&self, p: DVec3, n: DVec3) -> DVec3 {
        let e = to_ecef_axes(p);
        let ne = to_ecef_axes(n);
        match *self {
            TileFrame::Sphere => ne,
            TileFrame::Wgs84 { datum } => {
                let r = e.length();
                if r == 0.0 {
                    return ne;
                }
                let u = e / r;
                let h = r - datum;
                let w = 1.0 - e2() * u.z * u.z;
                let big_n = WGS84_A / w.sqrt();
                let big_m = WGS84_A * (1.0 - e2()) / (w * w.sqrt());
                let (s_north, s_east) = ((big_m + h) / r, (big_n + h) / r);
                // The local frame: up, east, north (any tangent pair at the poles, where the two
                // stretches are equal).
                let east = DVec3::new(-u.y, u.x, 0.0);
                let east = if east.length_squared() > 1e-24 {
                    east.normalize()
                } else {
                    DVec3::X
                };
                let north = u.cross(east);
                let t = u * ne.dot(u) + east * (ne.dot(east) / s_east) + north * (ne.dot(north) / s_north);
                t.normalize_or(ne)
            }
        }
    }

    /// The largest factor by which the map stretches a length among points at radius
    /// `r_min` or more (planet frame). 1 for the sphere frame.
    pub fn stretch(&self, r_min: f64) -> f64 {
        match *self {
            TileFrame::Sphere => 1.0,
            TileFrame::Wgs84 { datum } => {
                let big = WGS84_A * WGS84_A / wgs84_b();
                if r_min <= 0.0 {
                    return f64::INFINITY;
                }
                // (a²/b + h) / r with h = r - datum; rounded up a hair for the arithmetic.
                ((big - datum + r_min) / r_min).max(1.0) * (1.0 + 1e-12)
            }
        }
    }

    /// A ball that holds the image of the ball of radius `radius` around `center` (planet
    /// frame): its centre's image, with the radius stretched by [`TileFrame::stretch`].
    pub fn ball(&self, center: DVec3, radius: f64) -> (DVec3, f64) {
        let c = self.to_ecef(center);
        match *self {
            TileFrame::Sphere => (c, radius),
            TileFrame::Wgs84 { .. } => {
                let r_min = center.length() - radius;
                if r_min <= 0.0 {
                    // A ball holding the planet's centre: everything within the farthest image.
                    let far = center.length() + radius;
                    return (DVec3::ZERO, far + self.max_displacement() + 1e-9 * far);
                }
                (c, radius * self.stretch(r_min))
            }
        }
    }

    /// How far any point moves from its place in the sphere frame, at most (metres).
    pub fn max_displacement(&self) -> f64 {
        match *self {
            TileFrame::Sphere => 0.0,
            TileFrame::Wgs84 { datum } => {
                // W(p) - p = ((N - datum) u_x, (N - datum) u_y, (N (1 - e²) - datum) u_z), with
                // N between a and a²/b: each part is at most the larger of its ends.
                let big = WGS84_A * WGS84_A / wgs84_b();
                let planar = (WGS84_A - datum).abs().max((big - datum).abs());
                let polar = (WGS84_A * (1.0 - e2()) - datum)
                    .abs()
                    .max((big * (1.0 - e2()) - datum).abs());
                planar.max(polar) * (1.0 + 1e-9) + 1e-3
            }
        }
    }

    /// The default frame for a planet of datum radius `datum`: WGS84 for a planet of the Earth's
    /// size (within 1% of its mean radius, 6 371 km), else the sphere.
    pub fn default_for(datum: f64) -> TileFrame {
        if (datum / 6_371_000.0 - 1.0).abs() < 0.01 {
            TileFrame::Wgs84 { datum }
        } else {
            TileFrame::Sphere
        }
    }
}
