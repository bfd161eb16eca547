//! The web viewer's files, embedded in the binary (staged by `build.rs` from `viewer/dist`).

use axum::http::{header, HeaderMap, HeaderValue, Method, StatusCode, Uri};
use axum::response::{IntoResponse, Response};
use rust_embed::RustEmbed;

/// The viewer's built files (`viewer/dist`), or a page saying how to build them.
#[derive(RustEmbed)]
#[folder = "$OUT_DIR/viewer"]
pub struct ViewerAssets;

/// Whether the embedded viewer is the real one (not the placeholder page written when
/// `viewer/dist` was missing at build time).
pub fn viewer_is_built() -> bool {
    env!("PMC_VIEWER_BUILT") == "1"
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Serves `GET /` (as `index.html`) and every other embedded file; 404 for the rest.
pub async fn static_file(method: Method, uri: Uri, headers: HeaderMap) -> Response {
    if method != Method::GET && method != Method::HEAD {
        return (StatusCode::METHOD_NOT_ALLOWED, "only GET is supported\n").into_response();
    }
    let path = uri.path().trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    let Some(file) = ViewerAssets::get(path) else {
        return (StatusCode::NOT_FOUND, format!("not found: /{path}\n")).into_response();
    };
    let etag = format!("\"{}\"", hex(&file.metadata.sha256_hash()[..16]));
    let cache = if path.starts_with("assets/") {
        // Vite puts content hashes in these names: they never change.
        "public, max-age=31536000, immutable"
    } else {
        "no-cache"
    };
    let mut h = HeaderMap::new();
    if let Ok(v) = HeaderValue::from_str(&etag) {
        h.insert(header::ETAG, v);
    }
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static(cache));
    let fresh = headers
        .get(header::IF_NONE_MATCH)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.split(',').any(|t| t.trim() == etag || t.trim() == "*"));
    if fresh {
        return (StatusCode::NOT_MODIFIED, h).into_response();
    }
    if let Ok(v) = HeaderValue::from_str(file.metadata.mimetype()) {
        h.insert(header::CONTENT_TYPE, v);
    }
    (StatusCode::OK, h, file.data.into_owned()).into_response()
}
