//! Helpers for the server tests: small planets and one-shot requests against the router.
#![allow(dead_code)]

use axum::body::{Body, Bytes};
use axum::http::{HeaderMap, Request, StatusCode};
use axum::Router;
use pmc_geometry::Layout;
use pmc_planet::PresetKind;
use pmc_server::{router, AppState, ServerConfig};
use serde_json::Value;
use tower::ServiceExt;

/// A small planet: 2 x 2 chunks per face side, 8 tiles per chunk, 2 chunks deep (48 chunks,
/// max level 1).
pub fn small_layout() -> Layout {
    Layout::new(2, 8, 100.0, 2.0, 2).unwrap()
}

/// A config for `small_layout`, earthlike seed 3, two workers.
pub fn small_config() -> ServerConfig {
    ServerConfig {
        port: 0,
        terrain: pmc_planet::TerrainSpec::preset(PresetKind::Earthlike, 3),
        layout: small_layout(),
        threads: 2,
        ..ServerConfig::default()
    }
}

/// The router of a fresh state.
pub fn app(config: ServerConfig) -> Router {
    router(AppState::new(config).unwrap())
}

/// A response, read whole.
pub struct Reply {
    pub status: StatusCode,
    pub headers: HeaderMap,
    pub body: Bytes,
}

impl Reply {
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }

    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers.get(name).and_then(|v| v.to_str().ok())
    }
}

/// Sends `req` to `app` and reads the whole answer.
pub async fn send(app: &Router, req: Request<Body>) -> Reply {
    let res = app.clone().oneshot(req).await.unwrap();
    let status = res.status();
    let headers = res.headers().clone();
    let body = axum::body::to_bytes(res.into_body(), usize::MAX).await.unwrap();
    Reply { status, headers, body }
}

/// `GET uri`.
pub async fn get(app: &Router, uri: &str) -> Reply {
    send(app, Request::get(uri).body(Body::empty()).unwrap()).await
}

/// `GET /api/v1/stats` as JSON.
pub async fn stats(app: &Router) -> Value {
    let r = get(app, "/api/v1/stats").await;
    assert_eq!(r.status, StatusCode::OK);
    r.json()
}

/// Polls `/api/v1/stats` until `done` holds (a bounded number of times, yielding between polls);
/// returns the stats that satisfied it.
pub async fn stats_until(a: &Router, what: &str, done: impl Fn(&Value) -> bool) -> Value {
    let mut last = Value::Null;
    for _ in 0..20_000 {
        last = stats(a).await;
        if done(&last) {
            return last;
        }
        tokio::time::sleep(std::time::Duration::from_millis(1)).await;
    }
    panic!("stats never showed {what}: {last}");
}

/// `jobs.FIELD` of a stats answer.
pub fn jobs(s: &Value, field: &str) -> u64 {
    s["jobs"][field]
        .as_u64()
        .unwrap_or_else(|| panic!("no jobs.{field} in {s}"))
}
