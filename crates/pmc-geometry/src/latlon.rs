//! Latitude and longitude on the planet.
//!
//! Y is the polar axis: latitude +90 deg is +Y (on [`Face::Top`](crate::Face::Top)). Longitude 0 is
//! +Z ([`Face::South`](crate::Face::South)) and longitude +90 deg (east) is +X
//! ([`Face::East`](crate::Face::East)):
//! `x = cos(lat) sin(lon)`, `y = sin(lat)`, `z = cos(lat) cos(lon)`.

use glam::DVec3;

/// A geographic position in degrees. Latitude in `[-90, 90]`, longitude in `(-180, 180]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatLon {
    /// Latitude in degrees, positive north.
    pub lat: f64,
    /// Longitude in degrees, positive east.
    pub lon: f64,
}

/// Why a latitude/longitude pair was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LatLonError {
    /// Latitude outside [-90, 90] or not a number. Give degrees, positive north.
    #[error("latitude {0} is not in [-90, 90] degrees")]
    Latitude(f64),
    /// Longitude not finite. Any finite value is accepted and wrapped.
    #[error("longitude {0} is not a finite number of degrees")]
    Longitude(f64),
}

impl LatLon {
    /// A checked position: latitude must be in `[-90, 90]`, longitude finite (wrapped to
    /// `(-180, 180]`).
    pub fn new(lat: f64, lon: f64) -> Result<LatLon, LatLonError> {
        if !(-90.0..=90.0).contains(&lat) {
            return Err(LatLonError::Latitude(lat));
        }
        if !lon.is_finite() {
            return Err(LatLonError::Longitude(lon));
        }
        let mut l = lon.rem_euclid(360.0);
        if l > 180.0 {
            l -= 360.0;
        }
        Ok(LatLon { lat, lon: l })
    }

    /// The unit direction from the planet centre.
    pub fn to_unit(self) -> DVec3 {
        let (sl, cl) = self.lat.to_radians().sin_cos();
        let (so, co) = self.lon.to_radians().sin_cos();
        DVec3::new(cl * so, sl, cl * co)
    }

    /// The latitude and longitude of the direction of `p`; `None` for the origin or non-finite
    /// input. At the poles the longitude is 0.
    pub fn from_point(p: DVec3) -> Option<LatLon> {
        if !p.is_finite() || p == DVec3::ZERO {
            return None;
        }
        let h = p.x.hypot(p.z);
        let lat = p.y.atan2(h).to_degrees();
        let lon = if h == 0.0 { 0.0 } else { p.x.atan2(p.z).to_degrees() };
        Some(LatLon {
            lat,
            lon: if lon == -180.0 { 180.0 } else { lon },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn axes() {
        let d = |lat, lon| LatLon::new(lat, lon).unwrap().to_unit();
        assert!((d(90.0, 0.0) - DVec3::Y).length() < 1e-15);
        assert!((d(0.0, 0.0) - DVec3::Z).length() < 1e-15);
        assert!((d(0.0, 90.0) - DVec3::X).length() < 1e-15);
    }

    #[test]
    fn rejects_bad_input() {
        assert!(LatLon::new(91.0, 0.0).is_err());
        assert!(LatLon::new(f64::NAN, 0.0).is_err());
        assert!(LatLon::new(0.0, f64::INFINITY).is_err());
        assert_eq!(LatLon::new(0.0, 190.0).unwrap().lon, -170.0);
        assert!(LatLon::from_point(DVec3::ZERO).is_none());
        assert!(LatLon::from_point(DVec3::new(f64::NAN, 0.0, 0.0)).is_none());
    }

    proptest! {
        #[test]
        fn round_trip(lat in -89.9f64..89.9, lon in -179.9f64..180.0, r in 1.0f64..1e7) {
            let ll = LatLon::new(lat, lon).unwrap();
            let back = LatLon::from_point(ll.to_unit() * r).unwrap();
            prop_assert!((back.lat - lat).abs() < 1e-9 && (back.lon - lon).abs() < 1e-9);
        }
    }
}
