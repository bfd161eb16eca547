//! Where an image lies on the globe: the outer edges of its pixels.

use std::fmt;

/// The longitudes and latitudes an equirectangular image covers, in degrees: the **outer edges**
/// of its pixels (not their centres). Column 0's western edge is `west`, the last column's
/// eastern edge is `east`; row 0's northern edge is `north` (images run from the north down),
/// the last row's southern edge is `south`.
///
/// An extent is valid when every bound is finite, `west < east <= west + 360` and
/// `-90 <= south < north <= 90`. [`Extent::new`] normalises `west` into [-180, 180) by whole
/// turns (moving `east` with it, so `east` may exceed 180 for an image across the antimeridian)
/// and snaps a span within a billionth of a turn of 360 degrees to exactly 360 (a global image).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    west: f64,
    south: f64,
    east: f64,
    north: f64,
}

impl Extent {
    /// The whole globe: -180 to 180 degrees of longitude, -90 to 90 of latitude.
    pub const GLOBAL: Extent = Extent {
        west: -180.0,
        south: -90.0,
        east: 180.0,
        north: 90.0,
    };

    /// An extent from its bounds in degrees, normalised as described on [`Extent`]; `Err` says
    /// which rule the bounds break.
    pub fn new(west: f64, south: f64, east: f64, north: f64) -> Result<Extent, String> {
        let named = [("west", west), ("south", south), ("east", east), ("north", north)];
        if let Some((name, v)) = named.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("{name} is {v:?}, not a finite number"));
        }
        if west >= east {
            return Err(format!("west ({west}) is not less than east ({east})"));
        }
        let mut span = east - west;
        if span > 360.0 * (1.0 + 1e-9) {
            return Err(format!("west to east spans {span} degrees, more than 360"));
        }
        if south >= north {
            return Err(format!("south ({south}) is not less than north ({north})"));
        }
        if south < -90.0 || north > 90.0 {
            return Err(format!("the latitudes {south} to {north} leave [-90, 90]"));
        }
        if (span - 360.0).abs() <= 360.0 * 1e-9 {
            span = 360.0;
        }
        let turns = ((west + 180.0) / 360.0).floor();
        let mut w = west - 360.0 * turns;
        if w >= 180.0 {
            // Rounding of a west just below a multiple of 360 turns.
            w -= 360.0;
        }
        Ok(Extent {
            west: w,
            south,
            east: w + span,
            north,
        })
    }

    /// Western edge, degrees east, in [-180, 180).
    pub fn west(&self) -> f64 {
        self.west
    }

    /// Southern edge, degrees north.
    pub fn south(&self) -> f64 {
        self.south
    }

    /// Eastern edge, degrees east: greater than [`west`](Self::west), at most 360 degrees east
    /// of it (so up to 540).
    pub fn east(&self) -> f64 {
        self.east
    }

    /// Northern edge, degrees north.
    pub fn north(&self) -> f64 {
        self.north
    }

    /// Degrees of longitude covered, in (0, 360].
    pub fn lon_span(&self) -> f64 {
        self.east - self.west
    }

    /// Degrees of latitude covered, in (0, 180].
    pub fn lat_span(&self) -> f64 {
        self.north - self.south
    }

    /// Whether the image goes all the way round (360 degrees of longitude), so that sampling
    /// wraps from its last column to its first.
    pub fn wraps(&self) -> bool {
        self.lon_span() == 360.0
    }

    /// The bounds as `[west, east, south, north]`: the order of the `.pmcimg` header, of the
    /// `.pmcdem` header's source extent and of the HTTP API's `imagery.extent` (the text form,
    /// [`Display`](std::fmt::Display), is `WEST,SOUTH,EAST,NORTH` as on the command line).
    pub fn to_array(&self) -> [f64; 4] {
        [self.west, self.east, self.south, self.north]
    }

    /// Degrees east of [`west`](Self::west) of longitude `lon` (any longitude, wrapped by whole
    /// turns), in [0, 360).
    pub fn offset_east(&self, lon: f64) -> f64 {
        let d = (lon - self.west).rem_euclid(360.0);
        // rem_euclid may round up to exactly 360 for tiny negative differences.
        if d >= 360.0 {
            0.0
        } else {
            d
        }
    }
}

impl Default for Extent {
    fn default() -> Extent {
        Extent::GLOBAL
    }
}

impl fmt::Display for Extent {
    /// `WEST,SOUTH,EAST,NORTH`, the text [`FromStr`](std::str::FromStr) reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.west, self.south, self.east, self.north)
    }
}

impl std::str::FromStr for Extent {
    type Err = String;

    /// Reads `WEST,SOUTH,EAST,NORTH` in degrees (the order of `pmc dem import --extent`).
    fn from_str(s: &str) -> Result<Extent, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 4 {
            return Err(format!(
                "{s:?} is not four numbers WEST,SOUTH,EAST,NORTH (degrees, the outer edges of the pixels)"
            ));
        }
        let mut v = [0.0; 4];
        for (out, p) in v.iter_mut().zip(&parts) {
            *out = p
                .parse::<f64>()
                .map_err(|_| format!("{p:?} in {s:?} is not a number; expected WEST,SOUTH,EAST,NORTH in degrees"))?;
        }
        Extent::new(v[0], v[1], v[2], v[3])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn global_wraps_and_prints_as_parsed() {
        let e: Extent = "-180,-90,180,90".parse().unwrap();
        assert_eq!(e, Extent::GLOBAL);
        assert!(e.wraps());
        assert_eq!(e.to_string(), "-180,-90,180,90");
        assert_eq!(e.to_string().parse::<Extent>().unwrap(), e);
    }

    #[test]
    fn west_is_normalised_by_whole_turns() {
        let e = Extent::new(170.0, -10.0, 200.0, 10.0).unwrap();
        assert_eq!((e.west(), e.east()), (170.0, 200.0));
        let e = Extent::new(190.0, -10.0, 220.0, 10.0).unwrap();
        assert_eq!((e.west(), e.east()), (-170.0, -140.0));
        let e = Extent::new(0.0, -90.0, 360.0, 90.0).unwrap();
        assert_eq!((e.west(), e.east()), (0.0, 360.0));
        assert!(e.wraps());
        let e = Extent::new(-540.0, 0.0, -530.0, 1.0).unwrap();
        assert_eq!(e.west(), -180.0);
    }

    #[test]
    fn a_span_a_rounding_short_of_a_turn_is_a_turn() {
        let step = 1.0 / 3.0;
        let e = Extent::new(-180.0, -90.0, -180.0 + step * 1080.0, 90.0).unwrap();
        assert!(e.wraps());
    }

    #[test]
    fn bad_extents_say_why() {
        for (w, s, e, n, why) in [
            (f64::NAN, 0.0, 1.0, 1.0, "west is NaN"),
            (0.0, 0.0, f64::INFINITY, 1.0, "east is inf"),
            (10.0, 0.0, 10.0, 1.0, "not less than east"),
            (0.0, 0.0, 361.0, 1.0, "more than 360"),
            (0.0, 5.0, 1.0, 5.0, "not less than north"),
            (0.0, -91.0, 1.0, 0.0, "leave [-90, 90]"),
            (0.0, 0.0, 1.0, 90.5, "leave [-90, 90]"),
        ] {
            let err = Extent::new(w, s, e, n).unwrap_err();
            assert!(err.contains(why), "{err}");
        }
        for text in ["1,2,3", "a,b,c,d", "1,2,3,4,5", ""] {
            assert!(text.parse::<Extent>().is_err(), "{text}");
        }
    }

    #[test]
    fn offset_east_wraps_any_longitude() {
        let e = Extent::GLOBAL;
        assert_eq!(e.offset_east(-180.0), 0.0);
        assert_eq!(e.offset_east(180.0), 0.0);
        assert_eq!(e.offset_east(0.0), 180.0);
        assert_eq!(e.offset_east(-190.0), 350.0);
        assert_eq!(e.offset_east(-180.0 - 1e-14), 0.0); // 360 - 1e-14 rounds to 360
    }
}
