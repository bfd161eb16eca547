//! Coordinate axes: checking that they are regular, and normalising them to increasing order.

/// Relative tolerance of even spacing: a value may depart from the straight line through the
/// first and last values by this fraction of a step (plus the rounding of its storage type).
pub(crate) const EVEN_TOLERANCE: f64 = 1e-6;

/// A grid whose columns span 360 degrees within this fraction of a step wraps in longitude.
///
/// Real files round their step: ETOPO20's is 0.3333333 degrees (1080 of them fall 36e-6 degrees
/// short of a turn) and ETOPO5's longitudes end at 359.92 instead of 359.9167 (4% of a step).
pub(crate) const WRAP_TOLERANCE: f64 = 0.1;

/// Why an axis is unusable.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum AxisProblem {
    /// Fewer than two values.
    TooShort(usize),
    /// A value that is not a finite number.
    NotFinite { index: usize, value: f64 },
    /// Value `index` repeats the one before it or reverses the direction.
    NotMonotonic { index: usize },
    /// Value `index` is off the line of even steps.
    Uneven { index: usize, expected: f64, found: f64 },
    /// Longitudes spanning more than a turn.
    SpansMoreThanATurn { span: f64 },
    /// A latitude outside [-90, 90].
    LatitudeOutOfRange { value: f64 },
}

/// An evenly spaced axis in increasing order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Regular {
    /// The smallest value.
    pub first: f64,
    /// The step between values, > 0.
    pub step: f64,
    /// Whether the file stores the values in decreasing order.
    pub reversed: bool,
    /// Tolerance used for comparisons on this axis, in its units.
    pub tolerance: f64,
}

/// Checks that `values` are finite, strictly monotonic and evenly spaced. `storage_epsilon` is the
/// relative precision of the type the values were stored in (`f32::EPSILON` for floats), `slack`
/// an absolute allowance (half the scale factor of packed integers).
pub(crate) fn regular(values: &[f64], storage_epsilon: f64, slack: f64) -> Result<Regular, AxisProblem> {
    let n = values.len();
    if n < 2 {
        return Err(AxisProblem::TooShort(n));
    }
    if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(AxisProblem::NotFinite { index, value });
    }
    let increasing = values[1] > values[0];
    for i in 1..n {
        let ok = if increasing {
            values[i] > values[i - 1]
        } else {
            values[i] < values[i - 1]
        };
        if !ok {
            return Err(AxisProblem::NotMonotonic { index: i });
        }
    }
    let (a, b) = (values[0], values[n - 1]);
    let step = (b - a) / (n - 1) as f64;
    let magnitude = a.abs().max(b.abs());
    let tolerance = EVEN_TOLERANCE * step.abs() + 4.0 * storage_epsilon * magnitude + slack;
    for (i, &v) in values.iter().enumerate() {
        // Interpolate from both ends so that rounding is symmetric.
        let t = i as f64 / (n - 1) as f64;
        let expected = a + (b - a) * t;
        if (v - expected).abs() > tolerance {
            return Err(AxisProblem::Uneven {
                index: i,
                expected,
                found: v,
            });
        }
    }
    Ok(if increasing {
        Regular {
            first: a,
            step,
            reversed: false,
            tolerance,
        }
    } else {
        Regular {
            first: b,
            step: -step,
            reversed: true,
            tolerance,
        }
    })
}

/// A longitude axis, normalised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Longitudes {
    /// The first longitude kept, in [-180, 180).
    pub first: f64,
    /// The step, > 0; exactly 360 / `width` when the grid wraps.
    pub step: f64,
    /// Number of columns kept.
    pub width: usize,
    /// Whether the columns span 360 degrees.
    pub wraps: bool,
    /// Whether the file stores longitudes in decreasing order.
    pub reversed: bool,
}

/// Normalises a regular axis of `n` longitudes: detects a grid that wraps around the globe (and
/// snaps its step to 360 / width), drops a last column that repeats the first one turn later,
/// and moves the first longitude into [-180, 180).
pub(crate) fn longitudes(axis: Regular, n: usize) -> Result<Longitudes, AxisProblem> {
    let step = axis.step;
    let near_turn = |columns: usize| (columns as f64 * step - 360.0).abs() <= WRAP_TOLERANCE * step;
    let (width, wraps) = if near_turn(n) {
        (n, true)
    } else if n >= 3 && near_turn(n - 1) {
        (n - 1, true)
    } else if (n - 1) as f64 * step > 360.0 + axis.tolerance {
        return Err(AxisProblem::SpansMoreThanATurn {
            span: (n - 1) as f64 * step,
        });
    } else {
        (n, false)
    };
    Ok(Longitudes {
        first: if (-180.0..180.0).contains(&axis.first) {
            axis.first
        } else {
            (axis.first + 180.0).rem_euclid(360.0) - 180.0
        },
        step: if wraps { 360.0 / width as f64 } else { step },
        width,
        wraps,
        reversed: axis.reversed,
    })
}

/// Checks that a regular axis of `n` latitudes lies within [-90, 90] (to its tolerance).
pub(crate) fn latitudes(axis: Regular, n: usize) -> Result<Regular, AxisProblem> {
    let last = axis.first + (n - 1) as f64 * axis.step;
    for value in [axis.first, last] {
        if value.abs() > 90.0 + axis.tolerance {
            return Err(AxisProblem::LatitudeOutOfRange { value });
        }
    }
    Ok(axis)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lin(first: f64, step: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| first + step * i as f64).collect()
    }

    #[test]
    fn regular_axes_in_either_order() {
        let up = regular(&lin(-89.5, 1.0, 180), f64::EPSILON, 0.0).unwrap();
        assert_eq!((up.first, up.step, up.reversed), (-89.5, 1.0, false));
        let down = regular(&lin(89.5, -1.0, 180), f64::EPSILON, 0.0).unwrap();
        assert_eq!((down.first, down.step, down.reversed), (-89.5, 1.0, true));
    }

    #[test]
    fn float32_rounding_is_tolerated_but_not_a_real_defect() {
        let values: Vec<f64> = (0..1081).map(|i| f64::from((20.0 + i as f64 / 3.0) as f32)).collect();
        assert!(regular(&values, f64::from(f32::EPSILON), 0.0).is_ok());
        let mut bad = values.clone();
        bad[500] += 0.01;
        assert!(matches!(
            regular(&bad, f64::from(f32::EPSILON), 0.0),
            Err(AxisProblem::Uneven { index: 500, .. })
        ));
    }

    #[test]
    fn defects_are_located() {
        assert_eq!(regular(&[1.0], 0.0, 0.0), Err(AxisProblem::TooShort(1)));
        assert_eq!(
            regular(&[1.0, 2.0, 2.0, 3.0], 0.0, 0.0),
            Err(AxisProblem::NotMonotonic { index: 2 })
        );
        assert_eq!(
            regular(&[1.0, 2.0, 1.5], 0.0, 0.0),
            Err(AxisProblem::NotMonotonic { index: 2 })
        );
        assert!(matches!(
            regular(&[1.0, f64::NAN], 0.0, 0.0),
            Err(AxisProblem::NotFinite { index: 1, .. })
        ));
        assert!(matches!(
            regular(&[0.0, 1.0, 3.0, 4.0, 5.0, 6.0], 0.0, 0.0),
            Err(AxisProblem::Uneven { index: 1, .. })
        ));
    }

    #[test]
    fn longitudes_wrap_drop_the_repeated_column_and_normalise() {
        let l = longitudes(regular(&lin(20.5, 1.0, 360), 0.0, 0.0).unwrap(), 360).unwrap();
        assert_eq!((l.first, l.step, l.width, l.wraps), (20.5, 1.0, 360, true));
        let l = longitudes(regular(&lin(20.1666667, 0.3333333, 1081), 0.0, 0.0).unwrap(), 1081).unwrap();
        assert_eq!((l.width, l.wraps), (1080, true));
        assert_eq!(l.step, 360.0 / 1080.0);
        let l = longitudes(regular(&lin(190.0, 1.0, 20), 0.0, 0.0).unwrap(), 20).unwrap();
        assert_eq!((l.first, l.width, l.wraps), (-170.0, 20, false));
        assert!(matches!(
            longitudes(regular(&lin(0.0, 1.0, 400), 0.0, 0.0).unwrap(), 400),
            Err(AxisProblem::SpansMoreThanATurn { .. })
        ));
    }

    #[test]
    fn latitudes_beyond_the_poles_are_refused() {
        assert!(latitudes(regular(&lin(-90.0, 0.5, 361), 0.0, 0.0).unwrap(), 361).is_ok());
        assert!(matches!(
            latitudes(regular(&lin(-90.0, 1.0, 182), 0.0, 0.0).unwrap(), 182),
            Err(AxisProblem::LatitudeOutOfRange { value }) if value == 91.0
        ));
    }
}
