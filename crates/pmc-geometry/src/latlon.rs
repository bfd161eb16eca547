//! Latitude and longitude on the planet.
//!
//! Y is the polar axis: latitude +90 deg is +Y (on [`Face::Top`](crate::Face::Top)). Longitude 0 is
//! +Z ([`Face::South`](crate::Face::South)) and longitude +90 deg (east) is +X
//! ([`Face::East`](crate::Face::East)):
//! `x = cos(lat) sin(lon)`, `y = sin(lat)`, `z = cos(lat) cos(lon)`.
//!
//! In text a position is `LAT,LON` ([`LatLon`]'s `FromStr`) and a place is `LAT,LON[,ALT]`
//! ([`Place`]'s): comma-separated decimal numbers, spaces around them allowed.
//!
//! ```
//! use pmc_geometry::{LatLon, Place};
//! let ll: LatLon = "10, 190".parse().unwrap();
//! assert_eq!((ll.lat, ll.lon), (10.0, -170.0));
//! let p: Place = "-10,20,-3.5".parse().unwrap();
//! assert_eq!((p.lat(), p.lon(), p.alt()), (-10.0, 20.0, Some(-3.5)));
//! assert!("91,0".parse::<Place>().is_err());
//! ```

use glam::DVec3;
use std::str::FromStr;

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

/// A finite longitude wrapped to `(-180, 180]`.
fn wrap_lon(lon: f64) -> f64 {
    let l = lon.rem_euclid(360.0);
    if l > 180.0 {
        l - 360.0
    } else {
        l
    }
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
        Ok(LatLon {
            lat,
            lon: wrap_lon(lon),
        })
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

/// Why a `LAT,LON` or `LAT,LON[,ALT]` text was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlaceParseError {
    /// Not as many comma-separated numbers as the form takes. Give `LAT,LON` (degrees), or
    /// `LAT,LON,ALT` (degrees, metres) where an altitude is taken.
    #[error("expected {expected} numbers, got {got}")]
    Count {
        /// How many the form takes (`2`, or `2 or 3`).
        expected: &'static str,
        /// How many the text holds.
        got: usize,
    },
    /// A part is not a decimal number. Write numbers like `-12.5`, without units.
    #[error("the {what} {text:?} is not a number")]
    NotANumber {
        /// `latitude`, `longitude` or `altitude`.
        what: &'static str,
        /// The part as written.
        text: String,
    },
    /// The latitude or longitude is out of range or not finite (see [`LatLonError`]).
    #[error(transparent)]
    LatLon(#[from] LatLonError),
    /// The altitude is infinite or NaN. Give metres above the datum.
    #[error("the altitude {0} is not a finite number of metres")]
    Altitude(f64),
}

/// A place in text: a checked latitude and longitude in degrees and an optional altitude in
/// metres above the datum, written `LAT,LON` or `LAT,LON,ALT`.
///
/// Made only by parsing, so always checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    lat: f64,
    lon: f64,
    alt: Option<f64>,
}

impl Place {
    /// Latitude in degrees, positive north, in `[-90, 90]`.
    pub fn lat(self) -> f64 {
        self.lat
    }

    /// Longitude in degrees, positive east, finite, as written: not wrapped, so that offsets
    /// added to it keep their bits ([`Place::lat_lon`] gives the wrapped position).
    pub fn lon(self) -> f64 {
        self.lon
    }

    /// Altitude in metres above the datum (finite), when given.
    pub fn alt(self) -> Option<f64> {
        self.alt
    }

    /// The position, its longitude wrapped to `(-180, 180]`.
    pub fn lat_lon(self) -> LatLon {
        LatLon {
            lat: self.lat,
            lon: wrap_lon(self.lon),
        }
    }
}

/// Splits `s` at commas into trimmed numbers, `min..=max` of them, named in `names` order.
fn parse_numbers<const N: usize>(
    s: &str,
    min: usize,
    expected: &'static str,
    names: [&'static str; N],
) -> Result<[Option<f64>; N], PlaceParseError> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if !(min..=N).contains(&parts.len()) {
        return Err(PlaceParseError::Count {
            expected,
            got: parts.len(),
        });
    }
    let mut out = [None; N];
    for ((slot, part), what) in out.iter_mut().zip(&parts).zip(names) {
        let x = part.parse::<f64>().map_err(|_| PlaceParseError::NotANumber {
            what,
            text: (*part).to_string(),
        })?;
        *slot = Some(x);
    }
    Ok(out)
}

impl FromStr for LatLon {
    type Err = PlaceParseError;

    /// Parses `LAT,LON` in degrees, checked and wrapped as [`LatLon::new`] does.
    fn from_str(s: &str) -> Result<LatLon, PlaceParseError> {
        let [lat, lon] = parse_numbers(s, 2, "2", ["latitude", "longitude"])?;
        Ok(LatLon::new(lat.unwrap_or_default(), lon.unwrap_or_default())?)
    }
}

impl FromStr for Place {
    type Err = PlaceParseError;

    /// Parses `LAT,LON` or `LAT,LON,ALT` (degrees, metres).
    fn from_str(s: &str) -> Result<Place, PlaceParseError> {
        let [lat, lon, alt] = parse_numbers(s, 2, "2 or 3", ["latitude", "longitude", "altitude"])?;
        let (lat, lon) = (lat.unwrap_or_default(), lon.unwrap_or_default());
        LatLon::new(lat, lon)?;
        if let Some(a) = alt {
            if !a.is_finite() {
                return Err(PlaceParseError::Altitude(a));
            }
        }
        Ok(Place { lat, lon, alt })
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

    #[test]
    fn places_are_parsed() {
        let p: Place = "10,-20.5".parse().unwrap();
        assert_eq!((p.lat(), p.lon(), p.alt()), (10.0, -20.5, None));
        let p: Place = " -10 , 20 , -3.5 ".parse().unwrap();
        assert_eq!((p.lat(), p.lon(), p.alt()), (-10.0, 20.0, Some(-3.5)));
        let p: Place = "0,190".parse().unwrap();
        assert_eq!(p.lon(), 190.0);
        assert_eq!(p.lat_lon().lon, -170.0);
        assert_eq!("90,-180".parse::<LatLon>().unwrap(), LatLon { lat: 90.0, lon: 180.0 });
    }

    #[test]
    fn bad_places_are_refused_with_the_reason() {
        let err = |s: &str| s.parse::<Place>().unwrap_err();
        assert_eq!(err("91,0"), PlaceParseError::LatLon(LatLonError::Latitude(91.0)));
        assert_eq!(err("-90.5,0"), PlaceParseError::LatLon(LatLonError::Latitude(-90.5)));
        assert!(matches!(err("NaN,0"), PlaceParseError::LatLon(LatLonError::Latitude(x)) if x.is_nan()));
        assert!(matches!(err("0,NaN"), PlaceParseError::LatLon(LatLonError::Longitude(x)) if x.is_nan()));
        assert_eq!(
            err("0,inf"),
            PlaceParseError::LatLon(LatLonError::Longitude(f64::INFINITY))
        );
        assert!(matches!(err("0,0,NaN"), PlaceParseError::Altitude(x) if x.is_nan()));
        assert_eq!(err("0,0,-inf"), PlaceParseError::Altitude(f64::NEG_INFINITY));
        assert_eq!(
            err("0"),
            PlaceParseError::Count {
                expected: "2 or 3",
                got: 1
            }
        );
        assert_eq!(
            err("1,2,3,4"),
            PlaceParseError::Count {
                expected: "2 or 3",
                got: 4
            }
        );
        assert_eq!(
            err("zero,0"),
            PlaceParseError::NotANumber {
                what: "latitude",
                text: "zero".into()
            }
        );
        assert_eq!(
            err("0,1,2m"),
            PlaceParseError::NotANumber {
                what: "altitude",
                text: "2m".into()
            }
        );
        assert!(matches!(err(""), PlaceParseError::Count { got: 1, .. }));
        assert!(matches!(
            err("1,"),
            PlaceParseError::NotANumber { what: "longitude", .. }
        ));
        assert_eq!(err("1,2,3,4").to_string(), "expected 2 or 3 numbers, got 4");
        assert_eq!(err("a,1").to_string(), "the latitude \"a\" is not a number");
        assert_eq!(
            "1,2,3".parse::<LatLon>().unwrap_err(),
            PlaceParseError::Count { expected: "2", got: 3 }
        );
        assert!("1,x".parse::<LatLon>().is_err());
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
