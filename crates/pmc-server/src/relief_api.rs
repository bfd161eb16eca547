//! The relief of an elevation-model planet: its description in `/api/v1/planet` and the grid
//! itself, `GET /api/v1/relief` (`docs/specs/http-api-v1.md`).
//!
//! The viewer chooses the terrain's materials (snow line, shelf, sea) from this grid, sampled per
//! pixel by latitude and longitude, wherever a pixel spans a good part of a data cell: the same
//! heights whatever level of detail a chunk was meshed at, so a chunk border between two levels
//! does not move the snow line (the chunks' own interpolated heights differ by hundreds of metres
//! between levels from orbit).

use crate::request::{ApiError, Params};
use crate::AppState;
use axum::body::Bytes;
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use pmc_dem::{CubeDem, DemError};
use pmc_planet::TerrainSpec;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::Arc;

/// The path of the grid.
pub const RELIEF_PATH: &str = "/api/v1/relief";

/// Bytes of decoded `.pmcdem` tiles the relief's reader keeps (it reads each tile once per
/// stride asked for).
const READ_CACHE_BYTES: usize = 16 << 20;

/// The source grid of the default planet's elevation model, with the encodings of the strides
/// asked for so far (at most one per halving, so a few).
pub struct ServedRelief {
    dem: Arc<CubeDem>,
    axes: pmc_dem::SourceAxes,
    /// Little-endian `f32` bodies by stride.
    encoded: tokio::sync::Mutex<HashMap<u32, Bytes>>,
}

impl std::fmt::Debug for ServedRelief {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServedRelief")
            .field("dem", &self.dem.path())
            .field("axes", &self.axes)
            .finish_non_exhaustive()
    }
}

impl ServedRelief {
    /// The relief of `terrain`: its elevation model's source grid when the terrain is one and
    /// its file keeps the grid (version 2); `None` for presets and version 1 files.
    pub fn of(terrain: &TerrainSpec) -> Result<Option<ServedRelief>, DemError> {
        let TerrainSpec::Dem(spec) = terrain else {
            return Ok(None);
        };
        let dem = CubeDem::open_with_cache(&spec.path, READ_CACHE_BYTES)?;
        Ok(dem.source_axes().map(|axes| ServedRelief {
            dem: Arc::new(dem),
            axes,
            encoded: tokio::sync::Mutex::new(HashMap::new()),
        }))
    }

    /// The content digest of the elevation model.
    pub fn digest(&self) -> &str {
        self.dem.digest()
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
            "scale": sea_radius / self.dem.radius(),
            "digest": self.dem.digest(),
            "encoding": "f32le",
        })
    }

    /// The body of stride `stride` (read off the async runtime once, then kept).
    async fn body(&self, stride: u32) -> Result<Bytes, ApiError> {
        let mut encoded = self.encoded.lock().await;
        if let Some(b) = encoded.get(&stride) {
            return Ok(b.clone());
        }
        let dem = Arc::clone(&self.dem);
        let bytes = tokio::task::spawn_blocking(move || {
            dem.source_decimated(stride).map(|(_, _, values)| {
                let mut out = Vec::with_capacity(4 * values.len());
                for v in values {
                    out.extend_from_slice(&v.to_le_bytes());
                }
                out
            })
        })
        .await
        .map_err(|e| ApiError::internal(format!("reading the relief failed: {e}")))?
        .map_err(|e| ApiError::internal(e.to_string()))?;
        let bytes = Bytes::from(bytes);
        encoded.insert(stride, bytes.clone());
        Ok(bytes)
    }
}

/// The `relief` field of `/api/v1/planet` for a planet of `terrain` with its sea at
/// `sea_radius`: the served relief when the planet is of the same elevation model (any seed of
/// its detail noise), `null` otherwise.
pub(crate) fn planet_field(state: &AppState, terrain: &TerrainSpec, sea_radius: Option<f64>) -> Value {
    match (state.relief(), terrain, sea_radius) {
        (Some(r), TerrainSpec::Dem(d), Some(sea)) if d.digest == r.digest() => r.describe(sea),
        _ => Value::Null,
    }
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
            "this server has no relief: it is served for a planet of an elevation model (--dem FILE.pmcdem) whose \
             file keeps its source grid (version 2; re-import a version 1 file with `pmc dem import`)",
        ));
    };
    let params = Params::parse(q);
    let max = match params.get("max") {
        None => u32::MAX,
        Some(s) => match s.trim().parse::<u32>() {
            Ok(n) if n >= 1 => n,
            _ => {
                return Err(ApiError::bad_request(format!(
                    "max must be an integer from 1 to {}, the most samples a side of the grid may have, got '{s}'",
                    u32::MAX
                )))
            }
        },
    };
    let stride = served.stride_for(max);
    let etag = format!("\"{}-s{stride}\"", served.digest());
    let etag_value =
        HeaderValue::from_str(&etag).map_err(|_| ApiError::internal("the relief digest is not a valid ETag"))?;
    let cache = HeaderValue::from_static("no-cache");
    if crate::imagery_api::matches_etag(&headers, &etag) {
        let mut r = StatusCode::NOT_MODIFIED.into_response();
        r.headers_mut().insert(header::ETAG, etag_value);
        r.headers_mut().insert(header::CACHE_CONTROL, cache);
        return Ok(r);
    }
    let body = served.body(stride).await?;
    let (w, h) = (served.axes.width.div_ceil(stride), served.axes.height.div_ceil(stride));
    let mut r = body.into_response();
    let hd = r.headers_mut();
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
