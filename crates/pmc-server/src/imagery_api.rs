//! The imagery draped on the default planet: its description in `/api/v1/planet` and the image
//! itself, `GET /api/v1/imagery` (`docs/specs/http-api-v1.md`).

use crate::request::{ApiError, Params};
use crate::AppState;
use axum::body::Bytes;
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use pmc_imagery::Imagery;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::Arc;

/// The path of the image.
pub const IMAGERY_PATH: &str = "/api/v1/imagery";

/// The imagery a server serves, with the PNG encodings of the levels asked for so far (at most
/// one per halving of the image, so a few).
pub struct ServedImagery {
    imagery: Arc<Imagery>,
    /// PNG files by level size `(width, height)`.
    encoded: tokio::sync::Mutex<HashMap<(u32, u32), Bytes>>,
}

impl std::fmt::Debug for ServedImagery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServedImagery")
            .field("imagery", &self.imagery)
            .finish_non_exhaustive()
    }
}

impl ServedImagery {
    /// Serves `imagery`.
    pub fn new(imagery: Imagery) -> ServedImagery {
        ServedImagery {
            imagery: Arc::new(imagery),
            encoded: tokio::sync::Mutex::new(HashMap::new()),
        }
    }

    /// The imagery.
    pub fn imagery(&self) -> &Imagery {
        &self.imagery
    }

    /// The `imagery` field of `/api/v1/planet`.
    pub fn describe(&self) -> Value {
        let i = &self.imagery;
        let e = i.extent();
        json!({
            "url": IMAGERY_PATH,
            "extent": e.to_array(),
            "width": i.width(),
            "height": i.height(),
            "digest": i.digest(),
            "wraps": e.wraps(),
            "color_space": "srgb",
        })
    }

    /// The PNG of the level of size `size` (encoded off the async runtime once, then kept).
    async fn png(&self, size: (u32, u32), max: u32) -> Result<Bytes, ApiError> {
        let mut encoded = self.encoded.lock().await;
        if let Some(b) = encoded.get(&size) {
            return Ok(b.clone());
        }
        let imagery = Arc::clone(&self.imagery);
        let bytes = tokio::task::spawn_blocking(move || {
            if (imagery.width(), imagery.height()) == size {
                imagery.to_png()
            } else {
                imagery.downsampled(max).to_png()
            }
        })
        .await
        .map_err(|e| ApiError::internal(format!("encoding the imagery failed: {e}")))?
        .map_err(|e| ApiError::internal(e.to_string()))?;
        let bytes = Bytes::from(bytes);
        encoded.insert(size, bytes.clone());
        Ok(bytes)
    }
}

/// The `imagery` field of `/api/v1/planet` for a planet: the server's imagery for its default
/// planet, `null` for any other planet or without imagery.
pub(crate) fn planet_field(state: &AppState, is_default_planet: bool) -> Value {
    match state.imagery() {
        Some(i) if is_default_planet => i.describe(),
        _ => Value::Null,
    }
}

/// The `max` parameter of a picture or a grid (`GET /api/v1/imagery`, `/relief`): the most
/// `units` a side of the `what` may have, `u32::MAX` when absent; a 400 saying what it must be
/// otherwise.
pub(crate) fn max_side(params: &Params, units: &str, what: &str) -> Result<u32, ApiError> {
    match params.get("max") {
        None => Ok(u32::MAX),
        Some(s) => match s.trim().parse::<u32>() {
            Ok(n) if n >= 1 => Ok(n),
            _ => Err(ApiError::bad_request(format!(
                "max must be an integer from 1 to {}, the most {units} a side of the {what} may have, got '{s}'",
                u32::MAX
            ))),
        },
    }
}

/// A `304 Not Modified` with its `ETag` and `Cache-Control: no-cache`.
pub(crate) fn not_modified(etag: HeaderValue) -> Response {
    let mut r = StatusCode::NOT_MODIFIED.into_response();
    r.headers_mut().insert(header::ETAG, etag);
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    r
}

/// Whether an `If-None-Match` header value names `etag` (or is `*`).
pub(crate) fn matches_etag(headers: &HeaderMap, etag: &str) -> bool {
    headers
        .get_all(header::IF_NONE_MATCH)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .map(|t| t.trim().trim_start_matches("W/"))
        .any(|t| t == etag || t == "*")
}

/// `GET /api/v1/imagery?max=N`: the image as PNG (8-bit RGB, sRGB, row 0 the northern edge),
/// whole or its largest halving whose sides are at most `max` pixels; `ETag` the content digest
/// (with the level's size for a smaller level), `304` when `If-None-Match` names it.
pub async fn imagery(
    State(state): State<AppState>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let Some(served) = state.imagery() else {
        return Err(ApiError::not_found(
            "this server has no imagery: start it with --imagery FILE.pmcimg (made by `pmc imagery import`)",
        ));
    };
    let params = Params::parse(q);
    let img = served.imagery();
    let max = max_side(&params, "pixels", "image")?;
    let size = img.level_size(max);
    let etag = if size == (img.width(), img.height()) {
        format!("\"{}\"", img.digest())
    } else {
        format!("\"{}-{}x{}\"", img.digest(), size.0, size.1)
    };
    let etag_value =
        HeaderValue::from_str(&etag).map_err(|_| ApiError::internal("the imagery digest is not a valid ETag"))?;
    let cache = HeaderValue::from_static("no-cache");
    if matches_etag(&headers, &etag) {
        return Ok(not_modified(etag_value));
    }
    let png = served.png(size, max).await?;
    let mut r = png.into_response();
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static("image/png"));
    h.insert(header::ETAG, etag_value);
    h.insert(header::CACHE_CONTROL, cache);
    Ok(r)
}
