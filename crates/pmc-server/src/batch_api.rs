//! `POST /api/v1/chunk-batch`: many chunks in one request, each answered as soon as it is ready
//! (`docs/specs/http-api-v1.md`, "Chunk batches").
//!
//! A browser opens at most six connections to one server, so a viewer that asks for each chunk
//! with a request of its own has at most six chunks in flight, and each waits for a round trip
//! through the browser's network stack and the server's queue: on two cores about 25 ms, whatever
//! the generation costs. A batch puts tens of chunks in flight on one connection. The answer is
//! a stream: a header, then one record a chunk in the order the chunks are ready, so the first
//! chunks are drawn while the last are generated. Each chunk goes through the same queue, cache,
//! de-duplication and priorities as `GET /api/v1/chunk`; a client that hangs up withdraws every
//! chunk of the batch not yet answered.

use crate::api::{chunk_error, chunk_key};
use crate::generator::ChunkId;
use crate::request::{read_body, require_json, ApiError, Params};
use crate::AppState;
use axum::body::{Body, Bytes};
use axum::extract::{RawQuery, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::Response;
use futures_util::stream::{self, FuturesUnordered, StreamExt};
use pmc_geometry::SideMask;
use serde::Deserialize;

/// Most chunks one batch may ask for.
pub const MAX_BATCH: usize = 256;
/// Largest body of a batch request, bytes (256 chunks take about 20 kB).
pub const MAX_BATCH_BODY: usize = 64 * 1024;
/// The media type of the answer.
pub const BATCH_CONTENT_TYPE: &str = "application/x-pmc-chunk-batch";
/// The answer's first four bytes.
pub const BATCH_MAGIC: &[u8; 4] = b"PMCB";
/// The version of the answer's layout.
pub const BATCH_VERSION: u16 = 1;

/// The body of a batch request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BatchRequest {
    chunks: Vec<BatchItem>,
}

/// One chunk of a batch request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BatchItem {
    /// `face/level/i/j/k`, as in the path of `GET /api/v1/chunk`.
    key: String,
    /// The seams mask (0 to 63), as the `seams` query parameter of `GET /api/v1/chunk`.
    #[serde(default)]
    seams: u64,
    /// The job's priority (finite), as the `priority` query parameter.
    #[serde(default)]
    priority: f64,
}

/// The answer's header: magic, version, the number of records that follow.
fn header_bytes(count: usize) -> Bytes {
    let mut b = Vec::with_capacity(10);
    b.extend_from_slice(BATCH_MAGIC);
    b.extend_from_slice(&BATCH_VERSION.to_le_bytes());
    b.extend_from_slice(&(count as u32).to_le_bytes());
    Bytes::from(b)
}

/// One record: its length (after this field), the chunk's index in the request, a status and
/// the payload (the chunk's encoding for 200, else the UTF-8 message of the error).
fn record(index: usize, status: StatusCode, payload: &[u8]) -> Bytes {
    let mut b = Vec::with_capacity(8 + payload.len());
    b.extend_from_slice(&((4 + payload.len()) as u32).to_le_bytes());
    b.extend_from_slice(&(index as u16).to_le_bytes());
    b.extend_from_slice(&status.as_u16().to_le_bytes());
    b.extend_from_slice(payload);
    Bytes::from(b)
}

/// The record of a chunk that could not be answered.
fn error_record(index: usize, e: &ApiError) -> Bytes {
    record(index, e.status, e.message.as_bytes())
}

/// `POST /api/v1/chunk-batch` (planet query parameters as `GET /api/v1/chunk`), body
/// `{"chunks": [{"key": "top/0/3/4/1", "seams": 0, "priority": 0}, ...]}`.
pub async fn chunk_batch(
    State(state): State<AppState>,
    RawQuery(q): RawQuery,
    req: Request,
) -> Result<Response, ApiError> {
    let params = Params::parse(q);
    let planet = params.planet(&state)?;
    require_json(&req, "a chunk batch")?;
    let body = read_body(req, MAX_BATCH_BODY, "the chunk batch's body").await?;
    let parsed: BatchRequest = serde_json::from_slice(&body).map_err(|e| {
        ApiError::bad_request(format!(
            "malformed chunk batch: {e}; send {{\"chunks\": [{{\"key\": \"top/0/3/4/1\", \"seams\": 0, \"priority\": 0}}, \
             ...]}} (see docs/specs/http-api-v1.md)"
        ))
    })?;
    let n = parsed.chunks.len();
    if n == 0 || n > MAX_BATCH {
        return Err(ApiError::bad_request(format!(
            "a chunk batch asks for 1 to {MAX_BATCH} chunks, this one for {n}"
        )));
    }
    let layout = state.config().layout;
    let jobs: FuturesUnordered<_> = parsed
        .chunks
        .into_iter()
        .enumerate()
        .map(|(index, item)| {
            let state = state.clone();
            let planet = planet.clone();
            async move {
                let id = item_id(&layout, &item).map(|(key, seams)| ChunkId { planet, key, seams });
                match id {
                    Err(e) => error_record(index, &e),
                    Ok(id) => match state.chunk(id, item.priority + 0.0).await {
                        Ok(bytes) => record(index, StatusCode::OK, &bytes),
                        Err(e) => error_record(index, &chunk_error(e)),
                    },
                }
            }
        })
        .collect();
    // Dropping the body (the client hung up) drops the chunks' futures: each withdraws from its
    // job, and a queued job nobody waits for leaves the queue.
    let records = stream::once(async move { header_bytes(n) }).chain(jobs);
    let mut r = Response::new(Body::from_stream(records.map(Ok::<_, std::convert::Infallible>)));
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(BATCH_CONTENT_TYPE));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(r)
}

/// The key and seams of one chunk of a batch, checked as `GET /api/v1/chunk` checks them.
fn item_id(layout: &pmc_geometry::Layout, item: &BatchItem) -> Result<(pmc_geometry::ChunkKey, SideMask), ApiError> {
    let parts: Vec<&str> = item.key.split('/').collect();
    let [face, level, i, j, k] = parts[..] else {
        return Err(ApiError::bad_request(format!(
            "chunk key must be face/level/i/j/k, got '{}'",
            item.key
        )));
    };
    let key = chunk_key(layout, face, level, i, j, k)?;
    if item.seams >= 64 {
        return Err(ApiError::bad_request(format!(
            "seams must be a side mask from 0 to 63 (bits: u min, u max, v min, v max, inner, outer), got {}",
            item.seams
        )));
    }
    if !item.priority.is_finite() {
        return Err(ApiError::bad_request("priority must be a finite number"));
    }
    Ok((key, SideMask(item.seams as u8 & layout.seam_sides(&key).0)))
}
