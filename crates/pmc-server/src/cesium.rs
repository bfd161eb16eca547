//! The CesiumJS example page (`examples/cesium/index.html`, embedded) at `/cesium/`, and
//! CesiumJS's own built files at `/cesium/Cesium/...` from the folder given by
//! [`ServerConfig::cesium_js`](crate::ServerConfig::cesium_js) (npm's
//! `cesium/Build/Cesium`): the page shows the served planet's 3D Tiles in CesiumJS.

use crate::AppState;
use axum::extract::{Path, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Redirect, Response};

/// The example page.
const PAGE: &str = include_str!("../../../examples/cesium/index.html");

/// `GET /cesium`: to `/cesium/`, where the page's relative URLs work.
pub async fn redirect() -> Redirect {
    Redirect::permanent("/cesium/")
}

/// `GET /cesium/`: the example page.
pub async fn page(State(state): State<AppState>) -> Response {
    if state.config().cesium_js.is_none() {
        return (
            StatusCode::NOT_FOUND,
            "the CesiumJS page needs CesiumJS: run pmc serve with --cesium-js DIR (npm's cesium/Build/Cesium, \
             e.g. examples/cesium/node_modules/cesium/Build/Cesium after `npm ci` in examples/cesium)\n",
        )
            .into_response();
    }
    let mut r = PAGE.into_response();
    let h = r.headers_mut();
    h.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("text/html; charset=utf-8"),
    );
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    r
}

/// The content type of a CesiumJS file, by its extension.
fn mime(path: &str) -> &'static str {
    match path.rsplit('.').next().unwrap_or("") {
        "js" | "mjs" => "text/javascript",
        "css" => "text/css",
        "json" => "application/json",
        "wasm" => "application/wasm",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "gif" => "image/gif",
        "svg" => "image/svg+xml",
        "html" => "text/html; charset=utf-8",
        "xml" => "application/xml",
        "glb" => "model/gltf-binary",
        "ktx2" => "image/ktx2",
        "woff" => "font/woff",
        "woff2" => "font/woff2",
        "ttf" => "font/ttf",
        _ => "application/octet-stream",
    }
}

/// `GET /cesium/Cesium/{*path}`: a file of CesiumJS's build folder (no path outside it).
pub async fn file(State(state): State<AppState>, Path(path): Path<String>) -> Response {
    let Some(dir) = state.config().cesium_js.clone() else {
        return (
            StatusCode::NOT_FOUND,
            "no CesiumJS here: run pmc serve with --cesium-js DIR\n",
        )
            .into_response();
    };
    let safe = path
        .split('/')
        .all(|part| !part.is_empty() && part != "." && part != ".." && !part.contains('\\'));
    if !safe {
        return (StatusCode::NOT_FOUND, format!("not found: /cesium/Cesium/{path}\n")).into_response();
    }
    let full = dir.join(&path);
    match tokio::task::spawn_blocking(move || std::fs::read(full))
        .await
        .unwrap_or_else(|e| Err(std::io::Error::other(e)))
    {
        Ok(bytes) => {
            let mut r = bytes.into_response();
            let h = r.headers_mut();
            h.insert(header::CONTENT_TYPE, HeaderValue::from_static(mime(&path)));
            h.insert(header::CACHE_CONTROL, HeaderValue::from_static("public, max-age=3600"));
            r
        }
        Err(_) => (StatusCode::NOT_FOUND, format!("not found: /cesium/Cesium/{path}\n")).into_response(),
    }
}
