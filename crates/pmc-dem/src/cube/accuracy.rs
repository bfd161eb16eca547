//! How far a file's heights lie from its source's values, over every sample of the source.

use super::detail::DetailNoise;
use super::reader::CubeDem;
use super::sample::Interpolation;
use super::source_grid::SourceGrid;
use crate::error::DemError;
use crate::source::EquirectSource;
use pmc_geometry::LatLon;
use rayon::prelude::*;

/// The finest detail spacing, in metres, of the heights [`accuracy`] compares: detail octaves
/// down to a metre, as a planet meshed to its finest level has.
pub const ACCURACY_FINEST_SPACING_M: f64 = 1.0;

/// Bytes of source rows [`accuracy`] holds at once (at least one row).
const BAND_BYTES: usize = 64 << 20;

/// The source sample farthest from its height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstSample {
    /// Column of the sample (from the west, in the normalised layout).
    pub column: usize,
    /// Row of the sample (from the south).
    pub row: usize,
    /// Latitude, degrees.
    pub lat: f64,
    /// Longitude, degrees.
    pub lon: f64,
    /// The source's value, metres.
    pub value: f32,
    /// The height there, metres.
    pub height: f64,
}

/// The errors `|height - value|`, in metres, of a file's heights at every valid source sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Accuracy {
    /// The interpolation the heights were taken with.
    pub interpolation: Interpolation,
    /// Valid source samples compared.
    pub samples: u64,
    /// Source samples with no value (not compared).
    pub missing: u64,
    /// The largest error (infinite where a height could not be read).
    pub max: f64,
    /// The 99th percentile of the errors.
    pub p99: f64,
    /// The root mean square of the errors.
    pub rms: f64,
    /// The sample with the largest error (`None` when no sample was compared).
    pub worst: Option<WorstSample>,
}

/// Compares `cube`'s heights ([`CubeDem::height`] with `interp`, `detail` and detail octaves down
/// to [`ACCURACY_FINEST_SPACING_M`]) with `source`'s value at every one of its samples (its
/// latitude and longitude), reading the source in bands of rows and spreading the work over
/// rayon's threads. `source` should be the grid `cube` was imported from.
pub fn accuracy(
    cube: &CubeDem,
    source: &dyn EquirectSource,
    interp: Interpolation,
    detail: &DetailNoise,
) -> Result<Accuracy, DemError> {
    let grid = SourceGrid::new(source);
    let (w, h) = (source.width(), source.height());
    let rows_per_band = (BAND_BYTES / (4 * w.max(1))).clamp(1, h.max(1));
    let mut band = vec![0f32; rows_per_band * w];
    let mut errors: Vec<f32> = Vec::with_capacity(w * h);
    let (mut samples, mut missing, mut squares) = (0u64, 0u64, 0.0f64);
    let mut worst: Option<(f64, WorstSample)> = None;
    let mut r0 = 0;
    while r0 < h {
        let rows = rows_per_band.min(h - r0);
        let buf = &mut band[..rows * w];
        source.read_rows(r0, rows, buf)?;
        let per_row: Vec<RowErrors> = buf
            .par_chunks(w)
            .enumerate()
            .map(|(k, values)| row_errors(cube, &grid, r0 + k, values, interp, detail))
            .collect();
        for row in per_row {
            samples += row.errors.len() as u64;
            missing += row.missing;
            squares += row.squares;
            if let Some((e, s)) = row.worst {
                if worst.is_none_or(|(we, _)| e > we) {
                    worst = Some((e, s));
                }
            }
            errors.extend_from_slice(&row.errors);
        }
        r0 += rows;
    }
    let p99 = if errors.is_empty() {
        0.0
    } else {
        let k = ((errors.len() as f64 * 0.99).ceil() as usize).clamp(1, errors.len()) - 1;
        let (_, at, _) = errors.select_nth_unstable_by(k, f32::total_cmp);
        f64::from(*at)
    };
    Ok(Accuracy {
        interpolation: interp,
        samples,
        missing,
        max: worst.map_or(0.0, |(e, _)| e),
        p99,
        rms: if samples > 0 {
            (squares / samples as f64).sqrt()
        } else {
            0.0
        },
        worst: worst.map(|(_, s)| s),
    })
}

/// The errors of one source row.
struct RowErrors {
    errors: Vec<f32>,
    missing: u64,
    squares: f64,
    worst: Option<(f64, WorstSample)>,
}

fn row_errors(
    cube: &CubeDem,
    grid: &SourceGrid,
    row: usize,
    values: &[f32],
    interp: Interpolation,
    detail: &DetailNoise,
) -> RowErrors {
    let mut out = RowErrors {
        errors: Vec::with_capacity(values.len()),
        missing: 0,
        squares: 0.0,
        worst: None,
    };
    for (column, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            out.missing += 1;
            continue;
        }
        let (lat, lon) = grid.lat_lon(column, row);
        let height = LatLon::new(lat.clamp(-90.0, 90.0), lon).map_or(f64::NAN, |ll| {
            cube.height(ll.to_unit(), interp, detail, ACCURACY_FINEST_SPACING_M)
        });
        let e = (height - f64::from(value)).abs();
        let e = if e.is_nan() { f64::INFINITY } else { e };
        out.errors.push(e as f32);
        out.squares += e * e;
        if out.worst.is_none_or(|(we, _)| e > we) {
            out.worst = Some((
                e,
                WorstSample {
                    column,
                    row,
                    lat,
                    lon,
                    value,
                    height,
                },
            ));
        }
    }
    out
}
