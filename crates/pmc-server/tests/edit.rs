//! Editing through the API (`docs/specs/http-api-v1.md`, "Editing: worlds"): the world file,
//! the edit endpoints, their validation and limits, chunk invalidation and the server push.

use crate::common::{get, send, small_config, small_layout, stats, Reply};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use axum::Router;
use futures_util::StreamExt;
use pmc_edit::{affected_chunks_lod, BrushKind, BrushOp};
use pmc_formats::chunk_encoding::encode_chunk;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Layout};
use pmc_planet::{Planet, PresetKind};
use pmc_server::{router, AppState, EditLimits, ServerConfig};
use pmc_world::World;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A fresh directory for one test.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-server-edit-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn world_config(path: &Path) -> ServerConfig {
    ServerConfig {
        world: Some(path.to_path_buf()),
        ..small_config()
    }
}

fn world_app(path: &Path) -> (AppState, Router) {
    let state = AppState::new(world_config(path)).unwrap();
    (state.clone(), router(state))
}

async fn post(app: &Router, uri: &str, body: Value) -> Reply {
    let req = Request::post(uri)
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    send(app, req).await
}

async fn post_empty(app: &Router, uri: &str) -> Reply {
    send(app, Request::post(uri).body(Body::empty()).unwrap()).await
}

/// The small planet's top point and a point on its surface along +Y, found by bisection.
fn surface_top(planet: &Planet) -> DVec3 {
    let d = planet.density();
    let (mut lo, mut hi) = (planet.layout().d_b(), planet.layout().radius());
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if d.density(DVec3::Y * mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    DVec3::Y * lo
}

fn encoded(planet: &Planet, key: ChunkKey) -> Vec<u8> {
    let mut out = Vec::new();
    encode_chunk(&planet.chunk_mesh(key), &mut out).unwrap();
    out
}

/// A chunk's encoded level-of-detail mesh with every seam side closed.
fn encoded_seams(planet: &Planet, key: ChunkKey) -> Vec<u8> {
    let mut out = Vec::new();
    let seams = planet.layout().seam_sides(&key);
    encode_chunk(&planet.chunk_mesh_lod(key, seams), &mut out).unwrap();
    out
}

fn chunk_uri(key: &ChunkKey) -> String {
    format!("/api/v1/chunk/{key}")
}

fn unedited() -> Planet {
    Planet::new(PresetKind::Earthlike, 3, small_layout())
}

fn remove_at(center: DVec3, radius: f64) -> BrushOp {
    BrushOp::new(BrushKind::Remove, center, radius, 1.0).unwrap()
}

fn body_of(op: &BrushOp) -> Value {
    json!({"brush": op.kind.name(), "x": op.center.x, "y": op.center.y, "z": op.center.z, "radius": op.radius,
           "strength": op.strength})
}

#[tokio::test]
async fn a_missing_world_is_created_and_an_existing_one_keeps_its_planet() {
    let d = dir("create");
    let path = d.join("w.pmcw");
    let (_, a) = world_app(&path);
    assert!(path.exists(), "the world file was created");
    let v = get(&a, "/api/v1/planet").await.json();
    let e = &v["edit"];
    assert_eq!(e["enabled"], true, "{e}");
    assert_eq!(e["world"], "w.pmcw");
    assert_eq!(
        (e["revision"].as_u64(), e["active"].as_u64(), e["redo"].as_u64()),
        (Some(0), Some(0), Some(0))
    );
    assert_eq!(e["max_brush_radius"], 64.0);
    assert_eq!(e["brushes"], json!(["add", "remove", "smooth", "flatten", "paint"]));
    drop(a);
    // Reopened with other planet settings: the world's planet wins.
    let other = ServerConfig {
        terrain: pmc_planet::TerrainSpec::preset(PresetKind::Moon, 99),
        layout: Layout::new(4, 8, 100.0, 2.0, 2).unwrap(),
        ..world_config(&path)
    };
    let state = AppState::new(other).unwrap();
    assert_eq!(
        state.config().terrain,
        pmc_planet::TerrainSpec::preset(PresetKind::Earthlike, 3)
    );
    assert_eq!(state.config().layout, small_layout());
    let v = get(&router(state), "/api/v1/planet").await.json();
    assert_eq!(
        (v["preset"].as_str(), v["seed"].as_str()),
        (Some("earthlike"), Some("3"))
    );
    // Another planet is served unedited and says why it cannot be edited.
    let (_, a) = world_app(&path);
    let v = get(&a, "/api/v1/planet?preset=moon").await.json();
    assert_eq!(v["edit"]["enabled"], false);
    assert!(v["edit"]["reason"]
        .as_str()
        .unwrap()
        .contains("only the world's planet"));
}

#[tokio::test]
async fn a_foreign_file_is_refused_untouched() {
    let d = dir("foreign");
    let path = d.join("notes.txt");
    std::fs::write(&path, "not a world\n").unwrap();
    let err = AppState::new(world_config(&path)).unwrap_err();
    assert!(err.to_string().contains("not a PMC world"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"not a world\n");
}

#[tokio::test]
async fn edits_change_exactly_the_listed_chunks_and_undo_redo_restore_them() {
    let d = dir("apply");
    let path = d.join("w.pmcw");
    let (_, a) = world_app(&path);
    let base = unedited();
    let op = remove_at(surface_top(&base), 6.0);
    let keys = affected_chunks_lod(base.layout(), &op);
    assert!(!keys.is_empty());
    // Every chunk fetched (and cached) before the edit, and every coarser chunk with all its
    // seams closed.
    let all = base.layout().chunks(0);
    let coarse: Vec<ChunkKey> = (1..=base.layout().max_level())
        .flat_map(|l| base.layout().chunks(l))
        .collect();
    for k in &all {
        let r = get(&a, &chunk_uri(k)).await;
        assert_eq!(r.status, StatusCode::OK);
        assert_eq!(r.body.as_ref(), encoded(&base, *k).as_slice());
    }
    for k in &coarse {
        let r = get(&a, &format!("{}?seams=63", chunk_uri(k))).await;
        assert_eq!(r.body.as_ref(), encoded_seams(&base, *k).as_slice(), "{k}");
    }
    let r = post(&a, "/api/v1/edits", body_of(&op)).await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let v = r.json();
    assert_eq!(
        (v["id"].as_u64(), v["revision"].as_u64(), v["active"].as_u64()),
        (Some(1), Some(1), Some(1))
    );
    let listed: Vec<String> = keys.iter().map(ToString::to_string).collect();
    assert_eq!(v["chunks"], json!(listed));

    // After the answer, every chunk is the edited planet's: the listed ones changed, the cache
    // kept none of their old meshes.
    let edited = base.clone().with_edits(vec![op].into());
    let mut changed = 0;
    for k in &all {
        let got = get(&a, &chunk_uri(k)).await.body;
        assert_eq!(got.as_ref(), encoded(&edited, *k).as_slice(), "chunk {k}");
        if got.as_ref() != encoded(&base, *k).as_slice() {
            changed += 1;
            assert!(keys.contains(k), "chunk {k} changed but was not listed");
        }
    }
    assert!(changed > 0, "the edit changed some chunk");
    let mut changed_coarse = 0;
    for k in &coarse {
        let got = get(&a, &format!("{}?seams=63", chunk_uri(k))).await.body;
        assert_eq!(got.as_ref(), encoded_seams(&edited, *k).as_slice(), "chunk {k}");
        if got.as_ref() != encoded_seams(&base, *k).as_slice() {
            changed_coarse += 1;
            assert!(keys.contains(k), "chunk {k} changed but was not listed");
        }
    }
    assert!(changed_coarse > 0, "the edit changed some coarser chunk");
    // The listed chunks were meshed again from their meshes before the edit (the shading of the
    // vertices the edit did not reach copied), with the bytes of a fresh mesh checked above.
    let reused = |s: Value| s["jobs"]["reused_shading"].as_u64().unwrap();
    let after_edit = reused(stats(&a).await);
    assert!(
        after_edit >= changed as u64,
        "{after_edit} chunks reused their shading, {changed} changed"
    );

    // The edit is in the file, durably.
    let w = World::open(&path).unwrap();
    assert_eq!(w.active_edits().unwrap(), vec![op]);
    drop(w);

    let v = post_empty(&a, "/api/v1/edits/undo").await.json();
    assert_eq!(
        (v["id"].as_u64(), v["active"].as_u64(), v["redo"].as_u64()),
        (Some(1), Some(0), Some(1))
    );
    assert_eq!(v["chunks"], json!(listed));
    for k in &keys {
        assert_eq!(
            get(&a, &chunk_uri(k)).await.body.as_ref(),
            encoded(&base, *k).as_slice()
        );
    }
    let after_undo = reused(stats(&a).await);
    assert!(after_undo > after_edit, "undoing reuses the edited meshes' shading too");
    let v = post_empty(&a, "/api/v1/edits/undo").await.json();
    assert_eq!(
        (v["id"].clone(), v["chunks"].clone()),
        (Value::Null, json!([])),
        "nothing left to undo"
    );
    let v = post_empty(&a, "/api/v1/edits/redo").await.json();
    assert_eq!((v["id"].as_u64(), v["revision"].as_u64()), (Some(1), Some(3)));
    for k in &keys {
        assert_eq!(
            get(&a, &chunk_uri(k)).await.body.as_ref(),
            encoded(&edited, *k).as_slice()
        );
    }
    assert!(reused(stats(&a).await) > after_undo, "and redoing");
    let list = get(&a, "/api/v1/edits").await.json();
    assert_eq!(list["active"], 1);
    assert_eq!(list["edits"][0]["brush"], "remove");
    assert_eq!(list["edits"][0]["center"], json!(op.center.to_array()));
    assert_eq!(list["edits"][0]["active"], true);
}

#[tokio::test]
async fn paint_takes_a_material_by_name_or_index() {
    let d = dir("paint");
    let (_, a) = world_app(&d.join("w.pmcw"));
    let top = surface_top(&unedited());
    let r = post(
        &a,
        "/api/v1/edits",
        json!({"brush": "paint", "x": top.x, "y": top.y, "z": top.z, "radius": 5, "material": "Rock"}),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let r = post(
        &a,
        "/api/v1/edits",
        json!({"brush": "paint", "x": top.x, "y": top.y, "z": top.z, "radius": 5, "material": 1}),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK);
    let list = get(&a, "/api/v1/edits").await.json();
    assert_eq!(list["edits"][0]["material"], 3);
    assert_eq!(list["edits"][1]["material"], 1);
}

#[tokio::test]
async fn bad_edits_get_a_clear_4xx_and_change_nothing() {
    let d = dir("bad");
    let path = d.join("w.pmcw");
    let (_, a) = world_app(&path);
    let top = surface_top(&unedited());
    let ok = |extra: Value| {
        let mut v = json!({"brush": "remove", "x": top.x, "y": top.y, "z": top.z, "radius": 4});
        for (k, x) in extra.as_object().unwrap() {
            if x.is_null() {
                v.as_object_mut().unwrap().remove(k);
            } else {
                v[k] = x.clone();
            }
        }
        v.to_string()
    };
    let cases: Vec<(String, u16, &str)> = vec![
        ("{".into(), 400, "malformed edit"),
        ("[]".into(), 400, "malformed edit"),
        ("null".into(), 400, "malformed edit"),
        (ok(json!({"brush": "explode"})), 400, "unknown brush 'explode'"),
        (ok(json!({"brush": null})), 400, "missing field `brush`"),
        (ok(json!({"x": null})), 400, "missing field `x`"),
        (ok(json!({"x": "12"})), 400, "malformed edit"),
        (ok(json!({"colour": "red"})), 400, "unknown field `colour`"),
        (ok(json!({"radius": 0.1})), 400, "radius must be from 0.5 to 64"),
        (ok(json!({"radius": 65})), 400, "radius must be from 0.5 to 64"),
        (ok(json!({"radius": -3})), 400, "radius"),
        (ok(json!({"strength": 0})), 400, "strength"),
        (ok(json!({"strength": 1.5})), 400, "strength"),
        (ok(json!({"material": "rock"})), 400, "paint brush only"),
        (ok(json!({"brush": "paint"})), 400, "paint needs a material"),
        (
            ok(json!({"brush": "paint", "material": "lava"})),
            400,
            "unknown material",
        ),
        (ok(json!({"brush": "paint", "material": 99})), 400, "unknown material"),
        (ok(json!({"brush": "paint", "material": -1})), 400, "malformed edit"),
        (ok(json!({"y": 1e6})), 400, "cannot touch the planet's shell"),
        (
            ok(json!({"x": 0, "y": 0, "z": 0})),
            400,
            "cannot touch the planet's shell",
        ),
        (
            r#"{"brush":"remove","x":1e999,"y":0,"z":0,"radius":4}"#.into(),
            400,
            "malformed edit",
        ),
        (
            r#"{"brush":"remove","x":NaN,"y":0,"z":0,"radius":4}"#.into(),
            400,
            "malformed edit",
        ),
    ];
    for (body, status, needle) in &cases {
        let req = Request::post("/api/v1/edits")
            .header("content-type", "application/json")
            .body(Body::from(body.clone()))
            .unwrap();
        let r = send(&a, req).await;
        assert_eq!(
            r.status.as_u16(),
            *status,
            "{body}: {}",
            String::from_utf8_lossy(&r.body)
        );
        let msg = r.json()["error"].as_str().unwrap().to_string();
        assert!(msg.contains(needle), "{body}: '{needle}' not in '{msg}'");
    }
    // The body must be JSON, small, and sent to a method the endpoint takes.
    let r = send(
        &a,
        Request::post("/api/v1/edits").body(Body::from(ok(json!({})))).unwrap(),
    )
    .await;
    assert_eq!(r.status, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    let r = send(
        &a,
        Request::post("/api/v1/edits")
            .header("content-type", "text/plain")
            .body(Body::from(ok(json!({}))))
            .unwrap(),
    )
    .await;
    assert_eq!(r.status, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    let huge = format!(r#"{{"brush":"remove","pad":"{}"}}"#, "x".repeat(20_000));
    let r = send(
        &a,
        Request::post("/api/v1/edits")
            .header("content-type", "application/json")
            .body(Body::from(huge))
            .unwrap(),
    )
    .await;
    assert_eq!(r.status, StatusCode::PAYLOAD_TOO_LARGE);
    assert!(r.json()["error"].as_str().unwrap().contains("16384"));
    let r = get(&a, "/api/v1/edits/undo").await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
    assert!(r.json()["error"].as_str().unwrap().contains("POST only"));
    let r = send(&a, Request::delete("/api/v1/edits").body(Body::empty()).unwrap()).await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
    // Another planet may not be edited.
    let r = post(
        &a,
        "/api/v1/edits?preset=moon",
        serde_json::from_str(&ok(json!({}))).unwrap(),
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    let r = post_empty(&a, "/api/v1/edits/undo?seed=4").await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    // Nothing reached the world.
    let w = World::open(&path).unwrap();
    assert_eq!(w.edit_count().unwrap(), 0);
    assert_eq!(get(&a, "/api/v1/planet").await.json()["edit"]["revision"], 0);
}

#[tokio::test]
async fn without_a_world_editing_is_forbidden() {
    let a = router(AppState::new(small_config()).unwrap());
    let v = get(&a, "/api/v1/planet").await.json();
    assert_eq!(v["edit"]["enabled"], false);
    assert!(v["edit"]["reason"].as_str().unwrap().contains("--world"));
    let top = surface_top(&unedited());
    for r in [
        post(&a, "/api/v1/edits", body_of(&remove_at(top, 4.0))).await,
        post_empty(&a, "/api/v1/edits/undo").await,
        post_empty(&a, "/api/v1/edits/redo").await,
        get(&a, "/api/v1/edits").await,
        get(&a, "/api/v1/events").await,
    ] {
        assert_eq!(r.status, StatusCode::FORBIDDEN);
        assert!(r.json()["error"].as_str().unwrap().contains("pmc serve --world FILE"));
    }
}

#[tokio::test]
async fn the_rate_limit_answers_429_with_retry_after() {
    let d = dir("rate");
    let config = ServerConfig {
        edit_limits: EditLimits {
            rate_per_second: 0.01,
            burst: 3,
            ..EditLimits::default()
        },
        ..world_config(&d.join("w.pmcw"))
    };
    let a = router(AppState::new(config).unwrap());
    let op = remove_at(surface_top(&unedited()), 2.0);
    for _ in 0..2 {
        assert_eq!(post(&a, "/api/v1/edits", body_of(&op)).await.status, StatusCode::OK);
    }
    assert_eq!(post_empty(&a, "/api/v1/edits/undo").await.status, StatusCode::OK);
    let r = post(&a, "/api/v1/edits", body_of(&op)).await;
    assert_eq!(r.status, StatusCode::TOO_MANY_REQUESTS);
    let wait: u64 = r.header("retry-after").unwrap().parse().unwrap();
    assert!((1..=100).contains(&wait), "{wait}");
    assert!(r.json()["error"].as_str().unwrap().contains("too many edits"));
    assert_eq!(
        post_empty(&a, "/api/v1/edits/redo").await.status,
        StatusCode::TOO_MANY_REQUESTS
    );
    // Reading is not limited.
    assert_eq!(get(&a, "/api/v1/edits").await.json()["active"], 1);
}

/// Reads server-sent events from a streaming body.
struct Events {
    stream: axum::body::BodyDataStream,
    buf: String,
}

impl Events {
    async fn open(app: &Router) -> Events {
        use tower::ServiceExt;
        let res = app
            .clone()
            .oneshot(Request::get("/api/v1/events").body(Body::empty()).unwrap())
            .await
            .unwrap();
        assert_eq!(res.status(), StatusCode::OK);
        assert_eq!(
            res.headers().get("content-type").and_then(|v| v.to_str().ok()),
            Some("text/event-stream")
        );
        Events {
            stream: res.into_body().into_data_stream(),
            buf: String::new(),
        }
    }

    /// The next event's name and data.
    async fn next(&mut self) -> (String, Value) {
        loop {
            if let Some(end) = self.buf.find("\n\n") {
                let block: String = self.buf.drain(..end + 2).collect();
                let mut name = String::new();
                let mut data = String::new();
                for line in block.lines() {
                    if let Some(v) = line.strip_prefix("event: ") {
                        name = v.to_string();
                    } else if let Some(v) = line.strip_prefix("data: ") {
                        data.push_str(v);
                    }
                }
                if name.is_empty() {
                    continue; // a keep-alive comment
                }
                return (name, serde_json::from_str(&data).unwrap());
            }
            let chunk = tokio::time::timeout(Duration::from_secs(20), self.stream.next())
                .await
                .expect("an event within 20 s")
                .expect("the stream stays open")
                .unwrap();
            self.buf.push_str(&String::from_utf8_lossy(&chunk));
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn subscribers_are_told_of_every_edit_in_order() {
    let d = dir("events");
    let path = d.join("w.pmcw");
    let (state, a) = world_app(&path);
    let mut watcher = Events::open(&a).await;
    let mut other = Events::open(&a).await;
    assert_eq!(watcher.next().await, ("hello".into(), json!({"revision": 0})));
    assert_eq!(other.next().await.0, "hello");
    let op = remove_at(surface_top(&unedited()), 5.0);
    let answer = post(&a, "/api/v1/edits", body_of(&op)).await.json();
    post_empty(&a, "/api/v1/edits/undo").await;
    post_empty(&a, "/api/v1/edits/redo").await;
    for w in [&mut watcher, &mut other] {
        let (name, e) = w.next().await;
        assert_eq!(name, "edit");
        assert_eq!(
            (e["revision"].as_u64(), e["action"].as_str(), e["id"].as_u64()),
            (Some(1), Some("apply"), Some(1))
        );
        assert_eq!(e["chunks"], answer["chunks"]);
        assert_eq!(w.next().await.1["action"], "undo");
        let (_, e) = w.next().await;
        assert_eq!((e["action"].as_str(), e["revision"].as_u64()), (Some("redo"), Some(3)));
    }

    // Another program edits the world file: one step is passed on as an edit, with its chunks.
    let op2 = remove_at(surface_top(&unedited()) + DVec3::X * 10.0, 3.0);
    let mut w = World::open(&path).unwrap();
    w.append(&op2).unwrap();
    assert!(state.sync_world().await.unwrap());
    let (name, e) = watcher.next().await;
    assert_eq!(
        (name.as_str(), e["action"].as_str(), e["revision"].as_u64()),
        ("edit", Some("apply"), Some(4))
    );
    let listed: Vec<String> = affected_chunks_lod(&small_layout(), &op2)
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(e["chunks"], json!(listed));
    assert!(!state.sync_world().await.unwrap(), "nothing new");
    // Several steps at once: everything is reloaded.
    w.undo().unwrap();
    w.undo().unwrap();
    assert!(state.sync_world().await.unwrap());
    let (name, e) = watcher.next().await;
    assert_eq!((name.as_str(), e["revision"].as_u64()), ("resync", Some(5)));
    let edited = unedited();
    for k in small_layout().chunks(0) {
        assert_eq!(
            get(&a, &chunk_uri(&k)).await.body.as_ref(),
            encoded(&edited, k).as_slice(),
            "chunk {k}"
        );
    }
    assert_eq!(get(&a, "/api/v1/edits").await.json()["redo"], 2);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn chunks_fetched_while_editing_end_up_matching_the_final_planet() {
    let d = dir("race");
    let (_, a) = world_app(&d.join("w.pmcw"));
    let base = unedited();
    let top = surface_top(&base);
    let all = base.layout().chunks(0);
    // Readers fetch chunks over and over while edits land.
    let mut readers = Vec::new();
    for r in 0..4 {
        let (a, all) = (a.clone(), all.clone());
        readers.push(tokio::spawn(async move {
            for n in 0..60 {
                let k = all[(n * 7 + r * 13) % all.len()];
                let res = get(&a, &chunk_uri(&k)).await;
                assert_eq!(res.status, StatusCode::OK);
            }
        }));
    }
    let mut ops = Vec::new();
    for i in 0..12 {
        let kind = if i % 3 == 2 { BrushKind::Add } else { BrushKind::Remove };
        let c = top + DVec3::new(f64::from(i) * 1.5 - 9.0, -2.0, f64::from(i % 4) * 2.0);
        let op = BrushOp::new(kind, c, 4.0, 1.0).unwrap();
        let r = post(&a, "/api/v1/edits", body_of(&op)).await;
        assert_eq!(r.status, StatusCode::OK);
        ops.push(op);
    }
    for r in readers {
        r.await.unwrap();
    }
    let edited = base.with_edits(ops.into());
    for k in &all {
        assert_eq!(
            get(&a, &chunk_uri(k)).await.body.as_ref(),
            encoded(&edited, *k).as_slice(),
            "chunk {k}"
        );
    }
}
