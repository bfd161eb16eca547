//! The relief of the server's planet: its description in `/api/v1/planet` and the grid itself,
//! `GET /api/v1/relief` (`docs/specs/http-api-v1.md`).
//!
//! The viewer chooses the terrain's materials (snow line, shelf, sea) from this grid, sampled per
//! pixel by latitude and longitude, wherever a pixel spans a good part of a grid cell: the same
//! heights whatever level of detail a chunk was meshed at, so a chunk border between two levels
//! does not move the snow line (the chunks' own interpolated heights differ by hundreds of metres
//! between levels from orbit). An elevation model's grid is its source grid; a preset's is its
//! height model's ground ([`pmc_density::Density::ground_radii`]) on a grid of
//! [`GROUND_COLUMNS`] x [`GROUND_ROWS`] cell centres, computed when first asked for.

use crate::request::{ApiError, Params};
use crate::AppState;
use axum::body::Bytes;
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use pmc_dem::{CubeDem, DemError};
use pmc_density::Density;
use pmc_geometry::LatLon;
use pmc_planet::TerrainSpec;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::Arc;

/// The path of the grid.
pub const RELIEF_PATH: &str = "/api/v1/relief";

/// Bytes of decoded `.pmcdem` tiles the relief's reader keeps (it reads each tile once per
/// stride asked for).
const READ_CACHE_BYTES: usize = 16 << 20;

/// Columns of a preset's ground grid (cell centres every 360 / 1024 degrees of longitude).
pub const GROUND_COLUMNS: u32 = 1024;
/// Rows of a preset's ground grid (cell centres every 180 / 512 degrees of latitude).
pub const GROUND_ROWS: u32 = 512;

/// Where the grid comes from.
enum Source {
    /// An elevation model's source grid.
    Dem(Arc<CubeDem>),
    /// The default planet's ground, computed on first use (values, row by row from the south).
    Ground(tokio::sync::Mutex<Option<Arc<Vec<f32>>>>),
}

/// The relief of the default planet, with the encodings of the strides asked for so far (at
/// most one per halving, so a few).
pub struct ServedRelief {
    source: Source,
    axes: pmc_dem::SourceAxes,
    /// Content digest (of the elevation model, or of the preset's terrain and the grid).
    digest: String,
    /// Data metres to the planet's metres above its datum, given the datum's radius (`None`: 1).
    dem_radius: Option<f64>,
    /// Little-endian `f32` bodies by stride, plain and gzip-compressed.
    encoded: tokio::sync::Mutex<HashMap<u32, Encoded>>,
}

/// A body as sent: plain, and compressed once (gzip on the fly took 4.5 s for ETOPO5's 37 MB,
/// on every request).
#[derive(Clone)]
struct Encoded {
    plain: Bytes,
    gzip: Bytes,
}

impl std::fmt::Debug for ServedRelief {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServedRelief")
            .field("axes", &self.axes)
            .field("digest", &self.digest)
            .finish_non_exhaustive()
    }
}

/// The axes of a preset's ground grid: cell centres, wrapping in longitude.
fn ground_axes() -> pmc_dem::SourceAxes {
    let lon_step = 360.0 / f64::from(GROUND_COLUMNS);
    let lat_step = 180.0 / f64::from(GROUND_ROWS);
    pmc_dem::SourceAxes {
        width: GROUND_COLUMNS,
        height: GROUND_ROWS,
        lon_first: -180.0 + 0.5 * lon_step,
        lon_step,
        lat_first: -90.0 + 0.5 * lat_step,
        lat_step,
        wraps: true,
    }
}

/// The ground of `planet` on `axes` (metres above its datum, row by row from the south), or
/// `None` when its terrain has no height model. Rows in parallel.
pub fn ground_grid(planet: &pmc_planet::Planet, axes: &pmc_dem::SourceAxes) -> Option<Vec<f32>> {
    use rayon::prelude::*;
    let density = &planet.terrain().density;
    let datum = planet.datum_radius();
    let detail = axes.lat_step.to_radians() * datum;
    let (w, h) = (axes.width as usize, axes.height as usize);
    let mut out = vec![0f32; w * h];
    let ok = out.par_chunks_mut(w).enumerate().all(|(r, row)| {
        let lat = axes.lat_first + r as f64 * axes.lat_step;
        let dirs: Vec<_> = (0..w)
            .map(|c| {
                let lon = axes.lon_first + c as f64 * axes.lon_step;
                LatLon::new(lat, lon)
                    .map(LatLon::to_unit)
                    .unwrap_or(pmc_geometry::glam::DVec3::Y)
            })
            .collect();
        let mut radii = vec![0.0; w];
        if !density.ground_radii(&dirs, detail, &mut radii) {
            return false;
        }
        for (o, r) in row.iter_mut().zip(&radii) {
            *o = (r - datum) as f32;
        }
        true
    });
    ok.then_some(out)
}

impl ServedRelief {
    /// The relief of `terrain` (the server's default planet) on `layout`: its elevation model's
    /// source grid when the terrain is one and its file keeps the grid (version 2; `None` for a
    /// version 1 file), else its ground on the preset grid (computed when first asked for; a
    /// terrain without a height model has none then).
    pub fn of(terrain: &TerrainSpec, layout: &pmc_geometry::Layout) -> Result<Option<ServedRelief>, DemError> {
        let TerrainSpec::Dem(spec) = terrain else {
            let axes = ground_axes();
            let key = format!(
                "ground-v1 {} {} {} {} {} {} {} {}x{}",
                terrain.name(),
                terrain.seed(),
                layout.n_c(),
                layout.n_t(),
                layout.d_b(),
                layout.l_d(),
                layout.d_c(),
                axes.width,
                axes.height
            );
            return Ok(Some(ServedRelief {
                source: Source::Ground(tokio::sync::Mutex::new(None)),
                axes,
                digest: format!("{:016x}", fnv1a(key.as_bytes())),
                dem_radius: None,
                encoded: tokio::sync::Mutex::new(HashMap::new()),
            }));
        };
        let dem = CubeDem::open_with_cache(&spec.path, READ_CACHE_BYTES)?;
        Ok(dem.source_axes().map(|axes| ServedRelief {
            digest: dem.digest().to_owned(),
            dem_radius: Some(dem.radius()),
            source: Source::Dem(Arc::new(dem)),
            axes,
            encoded: tokio::sync::Mutex::new(HashMap::new()),
        }))
    }

    /// The content digest: the elevation model's, or a digest of the preset's terrain, layout
    /// and grid.
    pub fn digest(&self) -> &str {
        &self.digest
    }

    /// The stride the grid is served with for `?max=max`: the smallest power of two that brings
    /// both sides to at most `max` samples.
    pub fn stride_for(&self, max: u32) -> u32 {
        let mut s = 1u32;
        while s < (1 << 30) && (self.axes.width.div_ceil(s) > max || self.axes.height.div_ceil(s) > max) {
            s *= 2;
        }
        s
    }

    /// The `relief` field of `/api/v1/planet` for a planet whose sea lies at `sea_radius`
    /// metres: the grid at stride 1 (`?max=` gives every `stride`-th sample, see the spec) and
    /// the vertical scale from the data's metres to the planet's.
    pub fn describe(&self, sea_radius: f64) -> Value {
        let a = &self.axes;
        json!({
            "url": RELIEF_PATH,
            "width": a.width,
            "height": a.height,
            "lon_first": a.lon_first,
            "lon_step": a.lon_step,
            "lat_first": a.lat_first,
            "lat_step": a.lat_step,
            "wraps": a.wraps,
            "scale": self.dem_radius.map_or(1.0, |r| sea_radius / r),
            "digest": self.digest,
            "encoding": "f32le",
        })
    }

    /// The body of stride `stride` (read or computed off the async runtime once, then kept).
    async fn body(&self, state: &AppState, stride: u32) -> Result<Encoded, ApiError> {
        let mut encoded = self.encoded.lock().await;
        if let Some(b) = encoded.get(&stride) {
            return Ok(b.clone());
        }
        let values = match &self.source {
            Source::Dem(dem) => {
                let dem = Arc::clone(dem);
                tokio::task::spawn_blocking(move || dem.source_decimated(stride).map(|(_, _, v)| v))
                    .await
                    .map_err(|e| ApiError::internal(format!("reading the relief failed: {e}")))?
                    .map_err(|e| ApiError::internal(e.to_string()))?
            }
            Source::Ground(cell) => {
                let full = {
                    let mut g = cell.lock().await;
                    match &*g {
                        Some(v) => Arc::clone(v),
                        None => {
                            let planet = state.default_planet().await.map_err(ApiError::internal)?;
                            let axes = self.axes;
                            let v = tokio::task::spawn_blocking(move || ground_grid(&planet, &axes))
                                .await
                                .map_err(|e| ApiError::internal(format!("computing the relief failed: {e}")))?
                                .ok_or_else(|| {
                                    ApiError::not_found(
                                        "this planet's terrain has no height model to take a relief from",
                                    )
                                })?;
                            let v = Arc::new(v);
                            *g = Some(Arc::clone(&v));
                            v
                        }
                    }
                };
                let (w, h) = (self.axes.width.div_ceil(stride), self.axes.height.div_ceil(stride));
                let mut out = Vec::with_capacity((w * h) as usize);
                for r in 0..h {
                    for c in 0..w {
                        out.push(full[(r * stride * self.axes.width + c * stride) as usize]);
                    }
                }
                out
            }
        };
        let encoded_now = tokio::task::spawn_blocking(move || {
            let mut out = Vec::with_capacity(4 * values.len());
            for v in values {
                out.extend_from_slice(&v.to_le_bytes());
            }
            let mut gz = flate2::write::GzEncoder::new(Vec::with_capacity(out.len() / 2), flate2::Compression::fast());
            std::io::Write::write_all(&mut gz, &out)
                .and_then(|()| gz.finish())
                .map(|gzip| Encoded {
                    plain: Bytes::from(out),
                    gzip: Bytes::from(gzip),
                })
        })
        .await
        .map_err(|e| ApiError::internal(format!("encoding the relief failed: {e}")))?
        .map_err(|e| ApiError::internal(format!("compressing the relief failed: {e}")))?;
        encoded.insert(stride, encoded_now.clone());
        Ok(encoded_now)
    }
}

/// The `relief` field of `/api/v1/planet` for `planet` (of `terrain`, the server's default
/// planet or not): an elevation model's served source grid when the planet is of the same model
/// (any seed of its detail noise); the preset ground grid for the default planet when its
/// terrain has a height model; `null` otherwise.
pub(crate) fn planet_field(
    state: &AppState,
    terrain: &TerrainSpec,
    planet: &pmc_planet::Planet,
    is_default: bool,
) -> Value {
    let Some(r) = state.relief() else {
        return Value::Null;
    };
    match (terrain, &r.source) {
        (TerrainSpec::Dem(d), Source::Dem(_)) if d.digest == r.digest() => match planet.terrain().sea_radius {
            Some(sea) => r.describe(sea),
            None => Value::Null,
        },
        (_, Source::Ground(_)) if is_default => {
            let mut probe = [0.0];
            if planet
                .terrain()
                .density
                .ground_radii(&[pmc_geometry::glam::DVec3::Y], 1.0, &mut probe)
            {
                r.describe(planet.datum_radius())
            } else {
                Value::Null
            }
        }
        _ => Value::Null,
    }
}

/// 64-bit FNV-1a of `bytes`: a stable digest of a preset grid's key.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// `GET /api/v1/relief?max=N`: every `stride`-th sample of the elevation model's source grid in
/// both directions (stride 1, or the smallest power of two that brings both sides to at most
/// `max`), as little-endian `f32` metres of the data, rows from the south; `ETag` the content
/// digest with the stride, `304` when `If-None-Match` names it.
pub async fn relief(
    State(state): State<AppState>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let Some(served) = state.relief() else {
        return Err(ApiError::not_found(
            "this server has no relief: it is served for a preset's planet and for an elevation model (--dem \
             FILE.pmcdem) whose file keeps its source grid (version 2; re-import a version 1 file with `pmc dem import`)",
        ));
    };
    let params = Params::parse(q);
    let max = crate::imagery_api::max_side(&params, "samples", "grid")?;
    let stride = served.stride_for(max);
    let etag = format!("\"{}-s{stride}\"", served.digest());
    let etag_value =
        HeaderValue::from_str(&etag).map_err(|_| ApiError::internal("the relief digest is not a valid ETag"))?;
    let cache = HeaderValue::from_static("no-cache");
    if crate::imagery_api::matches_etag(&headers, &etag) {
        return Ok(crate::imagery_api::not_modified(etag_value));
    }
    let body = served.body(&state, stride).await?;
    let (w, h) = (served.axes.width.div_ceil(stride), served.axes.height.div_ceil(stride));
    let gzip = headers
        .get_all(header::ACCEPT_ENCODING)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .any(|e| {
            // `gzip`, unless its weight is `q=0`
            let mut parts = e.split(';').map(str::trim);
            parts.next().is_some_and(|t| t.eq_ignore_ascii_case("gzip"))
                && !parts.any(|p| p.strip_prefix("q=").and_then(|q| q.trim().parse::<f32>().ok()) == Some(0.0))
        });
    let mut r = if gzip { body.gzip } else { body.plain }.into_response();
    let hd = r.headers_mut();
    if gzip {
        hd.insert(header::CONTENT_ENCODING, HeaderValue::from_static("gzip"));
    }
    hd.insert(header::VARY, HeaderValue::from_static("accept-encoding"));
    hd.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/octet-stream"),
    );
    hd.insert(header::ETAG, etag_value);
    hd.insert(header::CACHE_CONTROL, cache);
    if let Ok(v) = HeaderValue::from_str(&format!("{w}x{h}")) {
        hd.insert("x-pmc-grid-size", v);
    }
    if let Ok(v) = HeaderValue::from_str(&stride.to_string()) {
        hd.insert("x-pmc-grid-stride", v);
    }
    Ok(r)
}
