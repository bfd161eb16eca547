//! Chunk batches (`POST /api/v1/chunk-batch`): one record a chunk with the bytes its own request
//! gets, errors per chunk, whole-batch errors for a malformed request, and a batch abandoned by
//! its client drops the jobs nobody else waits for.

use crate::common::{app, get, jobs, send, small_config, stats, stats_until};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use pmc_geometry::{ChunkKey, Layout};
use pmc_planet::{Planet, PresetKind};
use pmc_server::batch_api::{BATCH_CONTENT_TYPE, MAX_BATCH, MAX_BATCH_BODY};
use pmc_server::ServerConfig;
use serde_json::{json, Value};

/// A batch request with `body` as its JSON (`query` after the path, e.g. `?preset=moon`).
fn batch_request(query: &str, body: &str) -> Request<Body> {
    Request::post(format!("/api/v1/chunk-batch{query}"))
        .header("content-type", "application/json")
        .body(Body::from(body.to_owned()))
        .unwrap()
}

/// The records of a batch answer, by index: (status, payload). Checks the header and that every
/// chunk has exactly one record.
fn records(body: &[u8], count: usize) -> Vec<(u16, Vec<u8>)> {
    assert_eq!(&body[..4], b"PMCB", "magic");
    assert_eq!(u16::from_le_bytes([body[4], body[5]]), 1, "version");
    assert_eq!(
        u32::from_le_bytes(body[6..10].try_into().unwrap()) as usize,
        count,
        "count"
    );
    let mut out: Vec<Option<(u16, Vec<u8>)>> = vec![None; count];
    let mut at = 10;
    while at < body.len() {
        let len = u32::from_le_bytes(body[at..at + 4].try_into().unwrap()) as usize;
        let index = u16::from_le_bytes([body[at + 4], body[at + 5]]) as usize;
        let status = u16::from_le_bytes([body[at + 6], body[at + 7]]);
        let payload = body[at + 8..at + 4 + len].to_vec();
        assert!(out[index].is_none(), "two records for chunk {index}");
        out[index] = Some((status, payload));
        at += 4 + len;
    }
    assert_eq!(at, body.len(), "the last record is whole");
    out.into_iter()
        .enumerate()
        .map(|(i, r)| r.unwrap_or_else(|| panic!("no record for chunk {i}")))
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_batch_answers_each_chunk_with_the_bytes_of_its_own_request() {
    let a = app(small_config());
    let planet = Planet::new(PresetKind::Earthlike, 3, crate::common::small_layout());
    let layout = planet.layout();
    // chunks of both levels, with and without seams, the same chunk twice, then bad ones
    let mut good: Vec<(ChunkKey, u8)> = layout.chunks(0).into_iter().take(6).map(|k| (k, 0)).collect();
    let coarse = layout.chunks(1)[0];
    good.push((coarse, 0));
    let sided = layout
        .chunks(0)
        .into_iter()
        .find(|k| !layout.seam_sides(k).is_empty())
        .expect("a chunk with sides toward a coarser neighbour");
    good.push((sided, 63));
    good.push((good[0].0, 0));
    let mut items: Vec<Value> = good
        .iter()
        .enumerate()
        .map(|(n, (k, s))| json!({ "key": k.to_string(), "seams": s, "priority": n as f64 }))
        .collect();
    items.push(json!({ "key": "top/9/0/0/0" }));
    items.push(json!({ "key": "nowhere/0/0/0/0" }));
    items.push(json!({ "key": "top/0/0/0" }));
    items.push(json!({ "key": good[0].0.to_string(), "seams": 64 }));
    let body = json!({ "chunks": items }).to_string();
    let r = send(&a, batch_request("", &body)).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.header("content-type"), Some(BATCH_CONTENT_TYPE));
    assert_eq!(
        r.header("content-encoding"),
        None,
        "records leave as they are ready, uncompressed"
    );
    let got = records(&r.body, items.len());
    for (n, (key, seams)) in good.iter().enumerate() {
        let alone = get(&a, &format!("/api/v1/chunk/{key}?seams={seams}")).await;
        assert_eq!(alone.status, StatusCode::OK);
        assert_eq!(got[n].0, 200, "{key}");
        assert_eq!(
            got[n].1,
            alone.body.to_vec(),
            "{key} with seams {seams}: the bytes of its own request"
        );
    }
    let message = |n: usize| String::from_utf8(got[n].1.clone()).unwrap();
    let bad = good.len();
    assert_eq!(got[bad].0, 404, "{}", message(bad));
    assert!(
        message(bad).contains("above the layout's max level"),
        "{}",
        message(bad)
    );
    assert_eq!(got[bad + 1].0, 400, "{}", message(bad + 1));
    assert_eq!(got[bad + 2].0, 400, "{}", message(bad + 2));
    assert!(message(bad + 2).contains("face/level/i/j/k"), "{}", message(bad + 2));
    assert_eq!(got[bad + 3].0, 400, "{}", message(bad + 3));
    assert!(message(bad + 3).contains("0 to 63"), "{}", message(bad + 3));
    // the other planets the query names are served as by the single requests
    let moon = json!({ "chunks": [{ "key": good[0].0.to_string() }] }).to_string();
    let r = send(&a, batch_request("?preset=moon&seed=5", &moon)).await;
    let alone = get(&a, &format!("/api/v1/chunk/{}?preset=moon&seed=5", good[0].0)).await;
    assert_eq!(records(&r.body, 1)[0].1, alone.body.to_vec());
}

#[tokio::test]
async fn a_malformed_batch_is_refused_whole_with_a_clear_error() {
    let a = app(small_config());
    let cases: Vec<(Request<Body>, StatusCode, &str)> = vec![
        (
            Request::post("/api/v1/chunk-batch")
                .body(Body::from(r#"{"chunks":[{"key":"top/0/0/0/0"}]}"#))
                .unwrap(),
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "Content-Type: application/json",
        ),
        (
            batch_request("", "{\"chunks\": [}"),
            StatusCode::BAD_REQUEST,
            "malformed chunk batch",
        ),
        (
            batch_request("", "[]"),
            StatusCode::BAD_REQUEST,
            "malformed chunk batch",
        ),
        (
            batch_request("", r#"{"chunks":[{"key":"top/0/0/0/0","colour":1}]}"#),
            StatusCode::BAD_REQUEST,
            "unknown field",
        ),
        (
            batch_request("", r#"{"chunks":[]}"#),
            StatusCode::BAD_REQUEST,
            "1 to 256 chunks",
        ),
        (
            batch_request(
                "",
                &json!({ "chunks": vec![json!({ "key": "top/0/0/0/0" }); MAX_BATCH + 1] }).to_string(),
            ),
            StatusCode::BAD_REQUEST,
            "1 to 256 chunks",
        ),
        (
            batch_request(
                "",
                &format!("{{\"chunks\": [], \"pad\": \"{}\"}}", "x".repeat(MAX_BATCH_BODY)),
            ),
            StatusCode::PAYLOAD_TOO_LARGE,
            "over 65536 bytes",
        ),
        (
            batch_request("?preset=venus", r#"{"chunks":[{"key":"top/0/0/0/0"}]}"#),
            StatusCode::BAD_REQUEST,
            "venus",
        ),
        (
            batch_request("", r#"{"chunks":[{"key":"top/0/0/0/0","priority":1e999}]}"#),
            StatusCode::BAD_REQUEST,
            "malformed chunk batch",
        ),
    ];
    for (req, status, says) in cases {
        let what = format!("{} {}", req.method(), req.uri());
        let r = send(&a, req).await;
        assert_eq!(r.status, status, "{what}: {}", String::from_utf8_lossy(&r.body));
        let e = r.json()["error"].as_str().unwrap_or_default().to_owned();
        assert!(e.contains(says), "{what}: {e}");
    }
    // nothing was queued for them
    let s = stats(&a).await;
    assert_eq!(s["jobs"]["done"], 0, "{s}");
}

/// Chunks of 128^3 tiles on one worker (as `jobs.rs`): jobs queue up behind the running one.
fn slow_config() -> ServerConfig {
    ServerConfig {
        layout: Layout::new(4, 128, 100.0, 0.5, 2).unwrap(),
        threads: 1,
        ..small_config()
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_abandoned_batch_drops_its_queued_jobs() {
    let a = app(slow_config());
    let layout = Layout::new(4, 128, 100.0, 0.5, 2).unwrap();
    let planet = Planet::new(PresetKind::Earthlike, 3, layout);
    let keys: Vec<ChunkKey> = layout
        .chunks(0)
        .into_iter()
        .filter(|k| planet.may_hold_surface(k))
        .take(25)
        .collect();
    get(&a, "/api/v1/planet").await;
    let body =
        json!({ "chunks": keys.iter().map(|k| json!({ "key": k.to_string() })).collect::<Vec<_>>() }).to_string();
    let batch = {
        let a = a.clone();
        tokio::spawn(async move { send(&a, batch_request("", &body)).await })
    };
    // every chunk's job is registered, one running (the one worker), the others queued
    stats_until(&a, "every job registered", |s| {
        jobs(s, "running") == 1 && jobs(s, "queued") + jobs(s, "running") + jobs(s, "done") == keys.len() as u64
    })
    .await;
    batch.abort();
    assert!(matches!(batch.await, Err(e) if e.is_cancelled()));
    let s = stats_until(&a, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await;
    let (done, dropped) = (jobs(&s, "done"), jobs(&s, "dropped"));
    assert!(dropped > 0, "{s}");
    assert_eq!(done + dropped, keys.len() as u64, "{s}");
    assert_eq!(jobs(&s, "waiting"), 0, "{s}");
}
