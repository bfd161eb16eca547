//! The camera: where it is, where it looks and how wide it sees.

use pmc_geometry::glam::DVec3;

use crate::RenderError;

/// Vertical field of view of [`Camera::orbit`], degrees.
pub const DEFAULT_FOV_DEG: f64 = 40.0;

/// A perspective camera placed by latitude, longitude and distance from the planet centre.
///
/// The world frame is the planet's (see [`pmc_geometry::LatLon`]): Y is the polar axis, longitude
/// 0 is +Z and longitude +90 degrees is +X. The camera sits at `LatLon(lat, lon).to_unit() *
/// distance` and looks at [`Camera::look_at`] (the planet centre when `None`). With a `look_at`
/// target the image's "up" is the local vertical at the camera projected onto the image plane, so
/// ground-level views keep the horizon level; otherwise it is +Y projected onto the image plane; when the camera looks straight along the polar axis it is
/// the horizontal direction of `lon` (pointing away from the camera's side of the pole), which is
/// the limit of the ordinary rule as `lat` goes to +-90 degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Latitude of the camera position, degrees, positive north.
    pub lat: f64,
    /// Longitude of the camera position, degrees, positive east.
    pub lon: f64,
    /// Distance of the camera from the planet centre, metres (at least 0).
    pub distance: f64,
    /// Vertical field of view, degrees, in (0, 180).
    pub fov_deg: f64,
    /// World point the camera looks at; `None` looks at the planet centre.
    pub look_at: Option<DVec3>,
}

impl Camera {
    /// A camera at `distance` metres from the planet centre above (`lat`, `lon`) degrees, looking at
    /// the centre with a [`DEFAULT_FOV_DEG`] vertical field of view.
    pub fn orbit(lat: f64, lon: f64, distance: f64) -> Camera {
        Camera {
            lat,
            lon,
            distance,
            fov_deg: DEFAULT_FOV_DEG,
            look_at: None,
        }
    }

    /// A camera above (`lat`, `lon`) looking at the centre, far enough away that a sphere of
    /// `radius` metres spans about 85% of the image height.
    pub fn framing(lat: f64, lon: f64, radius: f64) -> Camera {
        let half = (0.5 * DEFAULT_FOV_DEG).to_radians();
        let angular_radius = (0.85 * half.tan()).atan();
        Camera::orbit(lat, lon, radius / angular_radius.sin())
    }

    /// This camera with another vertical field of view (degrees).
    pub fn with_fov(self, fov_deg: f64) -> Camera {
        Camera { fov_deg, ..self }
    }

    /// This camera looking at `target` (world metres) instead of the planet centre.
    pub fn with_look_at(self, target: DVec3) -> Camera {
        Camera {
            look_at: Some(target),
            ..self
        }
    }

    /// The camera position in world metres.
    pub fn eye(&self) -> DVec3 {
        unit(self.lat, self.lon) * self.distance
    }

    /// The point looked at in world metres.
    pub fn target(&self) -> DVec3 {
        self.look_at.unwrap_or(DVec3::ZERO)
    }

    /// The checked orthonormal frame of the camera.
    pub(crate) fn frame(&self) -> Result<Frame, RenderError> {
        let bad = |what: &str, v: f64| RenderError::Camera(format!("{what} is {v}, not a finite number"));
        if !self.lat.is_finite() {
            return Err(bad("latitude", self.lat));
        }
        if !self.lon.is_finite() {
            return Err(bad("longitude", self.lon));
        }
        if !self.distance.is_finite() {
            return Err(bad("distance", self.distance));
        }
        if self.distance < 0.0 {
            return Err(RenderError::Camera(format!("distance {} is negative", self.distance)));
        }
        if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(RenderError::Camera(format!(
                "field of view {} is not in (0, 180) degrees",
                self.fov_deg
            )));
        }
        let target = self.target();
        if !target.is_finite() {
            return Err(RenderError::Camera(format!("look_at {target} is not finite")));
        }
        let eye = self.eye();
        let to_target = target - eye;
        let reach = to_target.length();
        if !(reach > 0.0 && reach.is_finite()) {
            return Err(RenderError::Camera(format!(
                "camera at {eye} looks at its own position"
            )));
        }
        let forward = to_target / reach;
        // Looking at a place on the planet, "up" is the local vertical at the camera (the
        // horizon stays level); looking at the centre, it is the polar axis.
        let reference = match self.look_at {
            Some(_) if eye.length() > 0.0 => eye.normalize(),
            _ => DVec3::Y,
        };
        let mut up = reference - forward * forward.dot(reference);
        if up.length() < 1e-9 {
            up = DVec3::Y - forward * forward.y;
        }
        if up.length() < 1e-9 {
            // Straight along the polar axis: the horizontal direction of the longitude, pointing
            // away from the camera's side (the limit of the projection of +Y).
            let (so, co) = self.lon.to_radians().sin_cos();
            let horizontal = DVec3::new(so, 0.0, co);
            up = if forward.y < 0.0 { -horizontal } else { horizontal };
            up -= forward * forward.dot(up);
        }
        let up = up.normalize();
        let right = forward.cross(up);
        let tan_half = (0.5 * self.fov_deg).to_radians().tan();
        Ok(Frame {
            eye,
            forward,
            right,
            up,
            tan_half,
            near: 1e-5 * reach,
        })
    }
}

/// The unit direction of (`lat`, `lon`) degrees, as [`pmc_geometry::LatLon::to_unit`] without the
/// range check.
fn unit(lat: f64, lon: f64) -> DVec3 {
    let (sl, cl) = lat.to_radians().sin_cos();
    let (so, co) = lon.to_radians().sin_cos();
    DVec3::new(cl * so, sl, cl * co)
}

/// An orthonormal camera frame: `right = forward x up`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub eye: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    /// `tan(fov / 2)`.
    pub tan_half: f64,
    /// Camera-space depth below which a vertex is behind the near plane.
    pub near: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equator_frame_is_north_up_east_right() {
        let f = Camera::orbit(0.0, 0.0, 10.0).frame().unwrap();
        assert!((f.eye - DVec3::new(0.0, 0.0, 10.0)).length() < 1e-12);
        assert!((f.forward + DVec3::Z).length() < 1e-12);
        assert!((f.up - DVec3::Y).length() < 1e-12);
        assert!((f.right - DVec3::X).length() < 1e-12);
    }

    #[test]
    fn pole_up_is_the_limit_of_nearby_views() {
        for lon in [0.0, 37.0, -120.0] {
            for (pole, near) in [(90.0, 89.999), (-90.0, -89.999)] {
                let a = Camera::orbit(pole, lon, 5.0).frame().unwrap();
                let b = Camera::orbit(near, lon, 5.0).frame().unwrap();
                assert!(
                    (a.up - b.up).length() < 1e-3,
                    "lon {lon} pole {pole}: {} vs {}",
                    a.up,
                    b.up
                );
                assert!((a.right - b.right).length() < 1e-3);
                assert!(a.up.dot(a.forward).abs() < 1e-12 && (a.up.length() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn framing_fits_the_sphere() {
        let c = Camera::framing(10.0, 20.0, 1000.0);
        let half = (0.5 * c.fov_deg).to_radians();
        let ang = (1000.0 / c.distance).asin();
        assert!((ang.tan() / half.tan() - 0.85).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_cameras() {
        assert!(Camera::orbit(f64::NAN, 0.0, 1.0).frame().is_err());
        assert!(Camera::orbit(0.0, f64::INFINITY, 1.0).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, f64::NAN).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, -1.0).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, 0.0).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, 1.0).with_fov(0.0).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, 1.0).with_fov(180.0).frame().is_err());
        assert!(Camera::orbit(0.0, 0.0, 1.0)
            .with_look_at(DVec3::new(0.0, f64::NAN, 0.0))
            .frame()
            .is_err());
        assert!(Camera::orbit(0.0, 0.0, 1.0).with_look_at(DVec3::Z).frame().is_err());
        // Inside the planet, or at its centre looking elsewhere, is fine.
        assert!(Camera::orbit(0.0, 0.0, 0.0).with_look_at(DVec3::X).frame().is_ok());
    }
}
