//! The request side shared by every endpoint: decoded query parameters and error answers.

use crate::generator::PlanetId;
use crate::AppState;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use pmc_planet::{PresetKind, TerrainSpec};
use serde_json::json;

/// An error answer: a status and a JSON `{"error": ...}` body.
#[derive(Debug, Clone, PartialEq)]
pub struct ApiError {
    /// The HTTP status.
    pub status: StatusCode,
    /// What is wrong and how to fix it.
    pub message: String,
}

impl ApiError {
    /// A 400 Bad Request.
    pub fn bad_request(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::BAD_REQUEST,
            message: message.into(),
        }
    }

    /// A 404 Not Found.
    pub fn not_found(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::NOT_FOUND,
            message: message.into(),
        }
    }

    /// A 500 Internal Server Error.
    pub fn internal(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::INTERNAL_SERVER_ERROR,
            message: message.into(),
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let mut r = (self.status, Json(json!({ "error": self.message }))).into_response();
        let h = r.headers_mut();
        h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        if self.status == StatusCode::SERVICE_UNAVAILABLE {
            h.insert(header::RETRY_AFTER, HeaderValue::from_static("1"));
        }
        r
    }
}

impl From<ApiError> for Response {
    fn from(e: ApiError) -> Response {
        e.into_response()
    }
}

/// Refuses (415) a request whose body is not declared JSON; `what` names the body in the message
/// ("the edit", "a chunk batch").
pub(crate) fn require_json(req: &axum::extract::Request, what: &str) -> Result<(), ApiError> {
    let json = req
        .headers()
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.split(';').next())
        .is_some_and(|v| v.trim().eq_ignore_ascii_case("application/json"));
    if json {
        Ok(())
    } else {
        Err(ApiError {
            status: StatusCode::UNSUPPORTED_MEDIA_TYPE,
            message: format!("{what} must be a JSON body with Content-Type: application/json"),
        })
    }
}

/// The body of `req`, at most `max` bytes (413 past it, naming `what`).
pub(crate) async fn read_body(
    req: axum::extract::Request,
    max: usize,
    what: &str,
) -> Result<axum::body::Bytes, ApiError> {
    axum::body::to_bytes(req.into_body(), max).await.map_err(|_| ApiError {
        status: StatusCode::PAYLOAD_TOO_LARGE,
        message: format!("{what} is over {max} bytes (or could not be read)"),
    })
}

/// The decoded query parameters (the last of repeated names wins).
pub(crate) struct Params(Vec<(String, String)>);

impl Params {
    /// Decodes a raw query string.
    pub(crate) fn parse(q: Option<String>) -> Params {
        Params(
            q.map(|q| form_urlencoded::parse(q.as_bytes()).into_owned().collect())
                .unwrap_or_default(),
        )
    }

    pub(crate) fn get(&self, name: &str) -> Option<&str> {
        self.0.iter().rev().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// A required finite number.
    pub(crate) fn finite(&self, name: &str) -> Result<f64, ApiError> {
        let raw = self.get(name).ok_or_else(|| {
            ApiError::bad_request(format!(
                "missing query parameter '{name}' (a finite number of metres, planet frame)"
            ))
        })?;
        match raw.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(ApiError::bad_request(format!(
                "query parameter '{name}' must be a finite number, got '{raw}'"
            ))),
        }
    }

    /// A required finite number of metres above 0 (a search range).
    pub(crate) fn range(&self, name: &str) -> Result<f64, ApiError> {
        let range = self.finite(name)?;
        if range <= 0.0 {
            return Err(ApiError::bad_request(format!(
                "{name} must be above 0 metres, got {range}"
            )));
        }
        Ok(range)
    }

    /// The optional `limit`: an integer from 1 to `max`, `default` when absent.
    pub(crate) fn limit(&self, default: usize, max: usize) -> Result<usize, ApiError> {
        match self.get("limit") {
            None => Ok(default),
            Some(s) => match s.trim().parse::<usize>() {
                Ok(n) if (1..=max).contains(&n) => Ok(n),
                _ => Err(ApiError::bad_request(format!(
                    "limit must be an integer from 1 to {max}, got '{s}'"
                ))),
            },
        }
    }

    /// The optional `seams` of a chunk request: the side mask (0 to 63, bit `n` for side
    /// `ChunkSide::ALL[n]`: u min, u max, v min, v max, inner, outer) of the sides across which
    /// the selected neighbour is one level coarser; 0 when absent.
    pub(crate) fn seams(&self) -> Result<u8, ApiError> {
        match self.get("seams") {
            None => Ok(0),
            Some(raw) => match raw.parse::<u8>() {
                Ok(m) if m < 64 => Ok(m),
                _ => Err(ApiError::bad_request(format!(
                    "query parameter 'seams' must be a side mask from 0 to 63 (bits: u min, u max, v min, v max, inner, \
                     outer), got '{raw}'"
                ))),
            },
        }
    }

    /// The optional `priority` of a chunk request: a finite number (queued jobs of higher
    /// priority are generated first), 0 when absent.
    pub(crate) fn priority(&self) -> Result<f64, ApiError> {
        match self.get("priority") {
            None => Ok(0.0),
            Some(raw) => match raw.trim().parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(ApiError::bad_request(format!(
                    "query parameter 'priority' must be a finite number (higher is generated first), got '{raw}'"
                ))),
            },
        }
    }

    /// The planet the request names (or the server's): `preset` switches to a preset, `seed`
    /// changes the seed (of the preset, or of an elevation model's detail and caves).
    pub(crate) fn planet(&self, state: &AppState) -> Result<PlanetId, ApiError> {
        let c = state.config();
        if self.get("preset").is_none() && self.get("seed").is_none() {
            return Ok(std::sync::Arc::new(c.terrain.clone()));
        }
        let seed = match self.get("seed") {
            None => c.terrain.seed(),
            Some(s) => s.trim().parse::<u64>().map_err(|_| {
                ApiError::bad_request(format!(
                    "seed must be a decimal integer from 0 to {}, got '{s}'",
                    u64::MAX
                ))
            })?,
        };
        let terrain = match (self.get("preset"), &c.terrain) {
            (Some(p), _) => TerrainSpec::preset(
                p.parse::<PresetKind>()
                    .map_err(|e| ApiError::bad_request(e.to_string()))?,
                seed,
            ),
            (None, TerrainSpec::Preset { kind, .. }) => TerrainSpec::preset(*kind, seed),
            (None, TerrainSpec::Dem(d)) => TerrainSpec::Dem(pmc_planet::DemSpec { seed, ..d.clone() }),
        };
        Ok(std::sync::Arc::new(terrain))
    }
}
