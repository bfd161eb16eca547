//! The 3D Tiles of the served planet (`docs/specs/tiles-v1.md`): the tileset, its subtree files
//! and contents over HTTP, the same bytes as the library's, errors for bad paths, and new URLs
//! after an edit.

use crate::common::{get, jobs, send, small_config, stats_until};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use pmc_server::{router, AppState, ServerConfig};
use serde_json::{json, Value};

/// The URLs of a subtree file's contents and child subtree files (relative to it).
fn uris(node: &Value, out: &mut Vec<String>) {
    if let Some(u) = node["content"]["uri"].as_str() {
        out.push(u.to_string());
    }
    for c in node["children"].as_array().into_iter().flatten() {
        uris(c, out);
    }
}

/// `../../../../../content/...` from `/tiles/rN/subtrees/F/L/X/Y/Z.json` is `/tiles/rN/content/...`.
fn resolve(rev: &str, uri: &str) -> String {
    format!("/tiles/{rev}/{}", uri.trim_start_matches("../../../../../"))
}

#[tokio::test]
async fn the_tileset_its_subtrees_and_contents_are_served() {
    let app = router(AppState::new(small_config()).unwrap());
    let r = get(&app, "/tiles/tileset.json").await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.header("cache-control"), Some("no-cache"));
    assert_eq!(r.header("access-control-allow-origin"), Some("*"));
    let ts = r.json();
    assert_eq!(ts["asset"]["version"], "1.1");
    assert_eq!(ts["extras"]["pmc"]["frame"], "sphere");
    assert_eq!(ts["extras"]["pmc"]["revision"], 0);
    let faces = ts["root"]["children"].as_array().unwrap();
    assert_eq!(faces.len(), 6);
    // Walk every subtree file and fetch every content it names.
    let mut todo: Vec<String> = faces
        .iter()
        .map(|f| format!("/tiles/{}", f["content"]["uri"].as_str().unwrap()))
        .collect();
    let (mut subtrees, mut contents) = (0, 0);
    while let Some(url) = todo.pop() {
        let r = get(&app, &url).await;
        assert_eq!(r.status, StatusCode::OK, "{url}: {}", String::from_utf8_lossy(&r.body));
        assert_eq!(r.header("content-type"), Some("application/json"));
        subtrees += 1;
        let mut found = Vec::new();
        uris(&r.json()["root"], &mut found);
        for u in found {
            let abs = resolve("r0", &u);
            if abs.ends_with(".json") {
                todo.push(abs);
            } else {
                let c = get(&app, &abs).await;
                assert_eq!(c.status, StatusCode::OK, "{abs}");
                assert_eq!(c.header("content-type"), Some("model/gltf-binary"));
                assert_eq!(&c.body[..4], b"glTF");
                contents += 1;
            }
        }
    }
    assert!(
        subtrees >= 6 && contents > 20,
        "{subtrees} subtree files, {contents} contents"
    );
}

#[tokio::test]
async fn bad_tile_paths_get_a_reason() {
    let app = router(AppState::new(small_config()).unwrap());
    for (uri, status) in [
        ("/tiles/r0/subtrees/top/0/0/0/0.subtree", StatusCode::NOT_FOUND),
        ("/tiles/r0/subtrees/top/1/0/0/0.json", StatusCode::NOT_FOUND),
        ("/tiles/r0/subtrees/up/0/0/0/0.json", StatusCode::BAD_REQUEST),
        ("/tiles/x0/subtrees/top/0/0/0/0.json", StatusCode::BAD_REQUEST),
        ("/tiles/r9/subtrees/top/0/0/0/0.json", StatusCode::NOT_FOUND),
        ("/tiles/r0/content/top/9/0/0/0.glb", StatusCode::NOT_FOUND),
        ("/tiles/r0/content/top/0/5/0/0.glb", StatusCode::NOT_FOUND),
        ("/tiles/r0/content/top/0/0/0/-1.glb", StatusCode::BAD_REQUEST),
        ("/tiles/r0/other/top/0/0/0/0.glb", StatusCode::NOT_FOUND),
    ] {
        let r = get(&app, uri).await;
        assert_eq!(r.status, status, "{uri}: {}", String::from_utf8_lossy(&r.body));
        assert!(r.json()["error"].as_str().is_some_and(|e| !e.is_empty()), "{uri}");
    }
}

/// A server of the small planet with a world (editing on) in a new folder, and the folder.
fn world_app(tag: &str) -> (axum::Router, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("{tag}{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let config = ServerConfig {
        world: Some(dir.join("w.pmcw")),
        ..small_config()
    };
    (router(AppState::new(config).unwrap()), dir)
}

#[tokio::test]
async fn an_edit_gives_the_tileset_new_urls() {
    let (app, dir) = world_app("pmc-server-tiles-");
    let before = get(&app, "/tiles/tileset.json").await.json();
    assert_eq!(before["extras"]["pmc"]["revision"], 0);
    assert!(before["root"]["children"][0]["content"]["uri"]
        .as_str()
        .unwrap()
        .starts_with("r0/"));
    let planet = get(&app, "/api/v1/planet").await.json();
    let top = planet["radius"].as_f64().unwrap();
    let edit = json!({"brush": "remove", "x": 0.0, "y": top * 0.97, "z": 0.0, "radius": 8.0});
    let req = Request::post("/api/v1/edits")
        .header("content-type", "application/json")
        .body(Body::from(edit.to_string()))
        .unwrap();
    let r = send(&app, req).await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let after = get(&app, "/tiles/tileset.json").await.json();
    assert_eq!(after["extras"]["pmc"]["revision"], 1);
    assert_eq!(after["extras"]["pmc"]["edits"], 1);
    assert!(after["root"]["children"][0]["content"]["uri"]
        .as_str()
        .unwrap()
        .starts_with("r1/"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test]
async fn a_frame_named_in_the_path_places_the_tiles_in_it() {
    let app = router(AppState::new(small_config()).unwrap());
    let mut first_content = Vec::new();
    for frame in ["sphere", "wgs84"] {
        let r = get(&app, &format!("/tiles/{frame}/tileset.json")).await;
        assert_eq!(
            r.status,
            StatusCode::OK,
            "{frame}: {}",
            String::from_utf8_lossy(&r.body)
        );
        let ts = r.json();
        assert_eq!(ts["extras"]["pmc"]["frame"], frame);
        // The face's subtree file and one of its contents, under the frame's prefix.
        let face = ts["root"]["children"][0]["content"]["uri"]
            .as_str()
            .unwrap()
            .to_string();
        let sub = get(&app, &format!("/tiles/{frame}/{face}")).await;
        assert_eq!(sub.status, StatusCode::OK, "{frame}/{face}");
        let mut found = Vec::new();
        uris(&sub.json()["root"], &mut found);
        let glb = found.iter().find(|u| u.ends_with(".glb")).expect("a content");
        let c = get(
            &app,
            &format!("/tiles/{frame}/{}", resolve("r0", glb).trim_start_matches("/tiles/")),
        )
        .await;
        assert_eq!(c.status, StatusCode::OK, "{frame} {glb}");
        first_content.push(c.body.to_vec());
    }
    // The same tile, placed in two frames: two different files.
    assert_ne!(first_content[0], first_content[1]);
    // The unframed URLs are the server's frame (the sphere, for this small planet).
    let served = get(&app, "/tiles/tileset.json").await.json();
    assert_eq!(served["extras"]["pmc"]["frame"], "sphere");
    for uri in ["/tiles/mars/tileset.json", "/tiles/mars/r0/subtrees/top/0/0/0/0.json"] {
        let r = get(&app, uri).await;
        assert_eq!(r.status, StatusCode::NOT_FOUND, "{uri}");
        assert!(
            r.json()["error"].as_str().unwrap().contains("`wgs84` or `sphere`"),
            "{uri}"
        );
    }
}

/// Every content of the served tileset at its current revision: (path after `rN/`, bytes), and
/// the number of subtree files walked.
async fn all_contents(app: &axum::Router) -> (Vec<(String, Vec<u8>)>, usize) {
    let ts = get(app, "/tiles/tileset.json").await.json();
    let rev = format!("r{}", ts["extras"]["pmc"]["revision"]);
    let mut todo: Vec<String> = ts["root"]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| format!("/tiles/{}", f["content"]["uri"].as_str().unwrap()))
        .collect();
    let (mut out, mut subtrees) = (Vec::new(), 0);
    while let Some(url) = todo.pop() {
        let r = get(app, &url).await;
        assert_eq!(r.status, StatusCode::OK, "{url}");
        subtrees += 1;
        let mut found = Vec::new();
        uris(&r.json()["root"], &mut found);
        for u in found {
            let abs = resolve(&rev, &u);
            if abs.ends_with(".json") {
                todo.push(abs);
            } else {
                let c = get(app, &abs).await;
                assert_eq!(c.status, StatusCode::OK, "{abs}");
                let path = abs.split_once(&format!("{rev}/")).unwrap().1.to_string();
                out.push((path, c.body.to_vec()));
            }
        }
    }
    out.sort();
    (out, subtrees)
}

#[tokio::test]
async fn after_an_edit_only_the_tiles_it_touched_are_made_again() {
    let (app, dir) = world_app("pmc-server-tiles-reuse-");
    let (before, _) = all_contents(&app).await;
    let planet = get(&app, "/api/v1/planet").await.json();
    // a pit at the north pole, through whatever the ground's height is there
    let (base, top) = (
        planet["base_radius"].as_f64().unwrap(),
        planet["radius"].as_f64().unwrap(),
    );
    let mut touched = std::collections::HashSet::new();
    for k in 2..=3 {
        let y = base + (top - base) * f64::from(k) / 5.0;
        let edit = json!({"brush": "remove", "x": 0.0, "y": y, "z": 0.0, "radius": 30.0});
        let req = Request::post("/api/v1/edits")
            .header("content-type", "application/json")
            .body(Body::from(edit.to_string()))
            .unwrap();
        let r = send(&app, req).await;
        assert_eq!(r.status, StatusCode::OK);
        for c in r.json()["chunks"].as_array().unwrap() {
            touched.insert(c.as_str().unwrap().to_string());
        }
    }
    let done = |s: &Value| s["jobs"]["done"].as_u64().unwrap();
    let jobs_before = done(&stats_until(&app, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await);
    let (after, subtrees) = all_contents(&app).await;
    // (a job is counted done just after it answers)
    let s = stats_until(&app, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await;
    let made = done(&s) - jobs_before - subtrees as u64;
    // The tree is the same (the pits are inside the tiles), each tile's content is its chunk's.
    assert!(before.iter().map(|c| &c.0).eq(after.iter().map(|c| &c.0)));
    let chunk = |glb: &[u8]| {
        let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let doc: Value = serde_json::from_slice(&glb[20..20 + jlen]).unwrap();
        doc["asset"]["extras"]["pmc"]["chunk"].as_str().unwrap().to_string()
    };
    let (mut hit, mut changed) = (0, 0);
    for ((_, b), (path, a)) in before.iter().zip(&after) {
        if touched.contains(&chunk(a)) {
            hit += 1;
            changed += usize::from(a != b);
        } else {
            assert_eq!(a, b, "{path}: a tile the edits did not touch changed");
        }
    }
    // The pits are there, and exactly the tiles they touched were made again.
    assert!(changed >= 1, "no content changed after the edits");
    assert_eq!(
        made as usize,
        hit,
        "{made} contents made again, {hit} touched of {}",
        after.len()
    );
    assert!(hit < after.len(), "every tile touched: the test shows nothing");
    let _ = std::fs::remove_dir_all(&dir);
}
