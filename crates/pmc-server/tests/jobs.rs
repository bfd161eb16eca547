//! Chunk jobs: requests that go away drop the jobs nobody waits for any more, priorities order
//! the queue, and chunks of every level of detail are served and cached apart.

use crate::common::{app, get, jobs, small_config, stats, stats_until, Reply};
use axum::http::StatusCode;
use axum::Router;
use pmc_density::Density;
use pmc_formats::chunk_encoding::{decode_chunk, encode_chunk};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face, Layout};
use pmc_planet::{Planet, PresetKind};
use pmc_server::{Server, ServerConfig};
use serde_json::Value;
use std::io::Write;
use std::net::TcpStream;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::task::JoinHandle;

/// Chunks of 128^3 tiles (the most a chunk may have): each keeps a worker busy long enough that
/// requests sent meanwhile queue up.
fn slow_layout() -> Layout {
    Layout::new(4, 128, 100.0, 0.5, 2).unwrap()
}

/// One worker, so that a job running blocks every other.
fn slow_config() -> ServerConfig {
    ServerConfig {
        layout: slow_layout(),
        threads: 1,
        ..small_config()
    }
}

/// The level-0 chunks of the slow planet that may hold surface, in key order.
fn surface_chunks() -> Vec<ChunkKey> {
    let planet = Planet::new(PresetKind::Earthlike, 3, slow_layout());
    planet
        .layout()
        .chunks(0)
        .into_iter()
        .filter(|k| planet.may_hold_surface(k))
        .collect()
}

fn chunk_uri(key: &ChunkKey) -> String {
    format!("/api/v1/chunk/{key}")
}

/// Requests `uri` on a task of its own.
fn spawn_get(a: &Router, uri: String) -> JoinHandle<Reply> {
    let a = a.clone();
    tokio::spawn(async move { get(&a, &uri).await })
}

/// Whether a task ended by being aborted.
fn cancelled(joined: Result<Reply, tokio::task::JoinError>) -> bool {
    matches!(joined, Err(e) if e.is_cancelled())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn abandoned_requests_drop_their_queued_jobs() {
    let a = app(slow_config());
    let keys = surface_chunks();
    let (blockers, victims) = keys.split_at(3);
    let victims = &victims[..24];
    // The planet first, so that every request goes straight to the generator.
    get(&a, "/api/v1/planet").await;
    let blocking: Vec<_> = blockers.iter().map(|k| spawn_get(&a, chunk_uri(k))).collect();
    stats_until(&a, "a running job", |s| jobs(s, "running") == 1).await;
    let abandoned: Vec<_> = victims.iter().map(|k| spawn_get(&a, chunk_uri(k))).collect();
    let total = (blockers.len() + victims.len()) as u64;
    // Every request has reached the generator (its job is queued, running or done).
    stats_until(&a, "every job registered", |s| {
        jobs(s, "queued") + jobs(s, "running") + jobs(s, "done") == total
    })
    .await;
    for t in &abandoned {
        t.abort();
    }
    for t in abandoned {
        assert!(cancelled(t.await));
    }
    for t in blocking {
        assert_eq!(t.await.unwrap().status, StatusCode::OK);
    }
    let s = stats_until(&a, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await;
    let (done, dropped) = (jobs(&s, "done"), jobs(&s, "dropped"));
    assert!(dropped > 0, "{s}");
    // Each job was either generated or dropped, never both: the dropped ones were not meshed.
    assert_eq!(done + dropped, total, "{s}");
    assert_eq!(s["generated"], done);
    assert_eq!(s["cached_chunks"], done);
    assert_eq!((s["queued"].as_u64(), s["in_flight"].as_u64()), (Some(0), Some(0)));
    assert_eq!(jobs(&s, "waiting"), 0, "{s}");
    // Every victim asked for again is served (generated now when its job was dropped).
    for key in victims {
        let r = get(&a, &chunk_uri(key)).await;
        assert_eq!(r.status, StatusCode::OK);
        assert_eq!(decode_chunk(&r.body).unwrap().key, *key);
    }
    let s = stats(&a).await;
    assert_eq!(jobs(&s, "done"), total, "{s}");
    assert_eq!(s["cached_chunks"], total);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_still_wanted_by_one_request_completes() {
    let a = app(slow_config());
    let keys = surface_chunks();
    let (blocker, wanted) = (keys[0], keys[1]);
    get(&a, "/api/v1/planet").await;
    let blocking = spawn_get(&a, chunk_uri(&blocker));
    stats_until(&a, "a running job", |s| jobs(s, "running") == 1).await;
    let leaving = spawn_get(&a, chunk_uri(&wanted));
    let staying = spawn_get(&a, chunk_uri(&wanted));
    // Both requests wait for the one queued job.
    stats_until(&a, "three waiting requests", |s| jobs(s, "waiting") == 3).await;
    leaving.abort();
    assert!(cancelled(leaving.await));
    let s = stats(&a).await;
    assert_eq!(jobs(&s, "waiting"), 2, "{s}");
    assert_eq!(jobs(&s, "dropped"), 0, "{s}");
    let r = staying.await.unwrap();
    assert_eq!(r.status, StatusCode::OK);
    let mut expected = Vec::new();
    encode_chunk(
        &Planet::new(PresetKind::Earthlike, 3, slow_layout()).chunk_mesh(wanted),
        &mut expected,
    )
    .unwrap();
    assert!(r.body[..] == expected[..], "the chunk's bytes differ");
    assert_eq!(blocking.await.unwrap().status, StatusCode::OK);
    let s = stats_until(&a, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await;
    assert_eq!(
        (jobs(&s, "done"), jobs(&s, "dropped"), s["cached_chunks"].as_u64()),
        (2, 0, Some(2)),
        "{s}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_running_job_finishes_and_is_cached_when_its_request_leaves() {
    let a = app(slow_config());
    let key = surface_chunks()[0];
    get(&a, "/api/v1/planet").await;
    let leaving = spawn_get(&a, chunk_uri(&key));
    stats_until(&a, "a running job", |s| jobs(s, "running") == 1).await;
    leaving.abort();
    assert!(cancelled(leaving.await));
    let s = stats_until(&a, "the job done", |s| jobs(s, "done") == 1).await;
    assert_eq!((jobs(&s, "dropped"), s["cached_chunks"].as_u64()), (0, Some(1)), "{s}");
    // Asking again is answered from the cache.
    assert_eq!(get(&a, &chunk_uri(&key)).await.status, StatusCode::OK);
    assert_eq!(jobs(&stats(&a).await, "done"), 1);
}

/// Sends `GET path` on a new connection and returns the connection, unread.
fn send_get(addr: std::net::SocketAddr, path: &str) -> TcpStream {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    s
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn closed_connections_drop_their_queued_jobs() {
    let server = Server::bind(slow_config()).await.unwrap();
    let addr = server.local_addr();
    let state = server.state().clone();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let run = tokio::spawn(server.run(async {
        let _ = stopped.await;
    }));
    let keys = surface_chunks();
    let (blocker, victims) = (keys[0], &keys[1..13]);
    let blocking = tokio::task::spawn_blocking(move || {
        use std::io::Read;
        let mut s = send_get(addr, &chunk_uri(&blocker));
        let mut head = [0u8; 12];
        s.read_exact(&mut head).unwrap();
        String::from_utf8_lossy(&head).into_owned()
    });
    let poll = |what: &'static str, done: fn(&pmc_server::Stats) -> bool| {
        let state = state.clone();
        async move {
            for _ in 0..20_000 {
                if done(&state.stats()) {
                    return;
                }
                tokio::time::sleep(Duration::from_millis(1)).await;
            }
            panic!("stats never showed {what}: {:?}", state.stats());
        }
    };
    poll("a running job", |s| s.jobs.running == 1).await;
    let paths: Vec<String> = victims.iter().map(chunk_uri).collect();
    let connections = tokio::task::spawn_blocking(move || paths.iter().map(|p| send_get(addr, p)).collect::<Vec<_>>())
        .await
        .unwrap();
    poll("every job registered", |s| {
        s.jobs.queued as u64 + s.jobs.running as u64 + s.jobs.done == 13
    })
    .await;
    // Hang up without reading the answers.
    for c in &connections {
        c.shutdown(std::net::Shutdown::Both).unwrap();
    }
    drop(connections);
    poll("a dropped job", |s| s.jobs.dropped > 0).await;
    assert_eq!(blocking.await.unwrap(), "HTTP/1.1 200");
    poll("no job left", |s| s.jobs.queued + s.jobs.running == 0).await;
    let s = state.stats();
    assert_eq!(s.jobs.done + s.jobs.dropped, 13, "{s:?}");
    assert_eq!(s.cached_chunks as u64, s.jobs.done, "{s:?}");
    stop.send(()).unwrap();
    tokio::time::timeout(Duration::from_secs(10), run)
        .await
        .expect("the server stops")
        .unwrap()
        .unwrap();
}

/// Requests `uri` on a task of its own, which pushes `n` onto `order` when answered.
fn spawn_noting(a: &Router, uri: String, n: usize, order: &Arc<Mutex<Vec<usize>>>) -> JoinHandle<Reply> {
    let (a, order) = (a.clone(), Arc::clone(order));
    tokio::spawn(async move {
        let r = get(&a, &uri).await;
        order.lock().unwrap().push(n);
        r
    })
}

/// Jobs registered with the generator so far: queued, running or done.
fn registered(s: &Value) -> u64 {
    jobs(s, "queued") + jobs(s, "running") + jobs(s, "done")
}

/// Requests `keys` at priority 100 (above every other request of the test) and waits until the
/// one worker runs the first of them, with `before` jobs registered before: requests queued from
/// then on wait until these are all done.
async fn occupy_the_worker(a: &Router, keys: &[ChunkKey], before: u64) -> Vec<JoinHandle<Reply>> {
    let tasks = keys
        .iter()
        .map(|k| spawn_get(a, format!("{}?priority=100", chunk_uri(k))))
        .collect();
    let all = before + keys.len() as u64;
    stats_until(a, "the worker busy", |s| {
        registered(s) == all && jobs(s, "running") == 1
    })
    .await;
    tasks
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn higher_priority_jobs_are_generated_first() {
    let a = app(slow_config());
    let keys = surface_chunks();
    get(&a, "/api/v1/planet").await;
    let blocking = occupy_the_worker(&a, &keys[..3], 0).await;
    // Queued in this order; expected to be generated as: 3 (priority 7.5), 2 then 4 (priority 2,
    // oldest first), 1 (priority 0, the default), 5 (priority -3).
    let order = Arc::new(Mutex::new(Vec::new()));
    let mut tasks = Vec::new();
    for (n, priority) in [
        (1, None),
        (2, Some("2")),
        (3, Some("7.5")),
        (4, Some("2.0")),
        (5, Some("-3")),
    ] {
        let key = &keys[2 + n];
        let uri = match priority {
            None => chunk_uri(key),
            Some(p) => format!("{}?priority={p}", chunk_uri(key)),
        };
        tasks.push(spawn_noting(&a, uri, n, &order));
        // Each request is registered before the next is sent.
        stats_until(&a, "the request registered", |s| registered(s) == 3 + n as u64).await;
    }
    let s = stats(&a).await;
    assert!(
        jobs(&s, "running") + jobs(&s, "done") <= 3,
        "a test job started early: {s}"
    );
    for t in tasks.into_iter().chain(blocking) {
        assert_eq!(t.await.unwrap().status, StatusCode::OK);
    }
    assert_eq!(*order.lock().unwrap(), [3, 2, 4, 1, 5]);

    // A request joining a queued job raises the job to its own priority.
    let blocking = occupy_the_worker(&a, &keys[8..11], 8).await;
    let order = Arc::new(Mutex::new(Vec::new()));
    let mut tasks = Vec::new();
    for (n, priority, test_waiters) in [(11, "1", 1), (12, "0", 2), (12, "5", 3)] {
        let uri = format!("{}?priority={priority}", chunk_uri(&keys[n]));
        tasks.push(spawn_noting(&a, uri, n, &order));
        // Each blocking request is either waiting or done; every test request is waiting.
        stats_until(&a, "the request waiting", |s| {
            jobs(s, "waiting") + jobs(s, "done") == 8 + 3 + test_waiters
        })
        .await;
    }
    let s = stats(&a).await;
    assert!(
        jobs(&s, "running") + jobs(&s, "done") <= 8 + 3,
        "a test job started early: {s}"
    );
    for t in tasks.into_iter().chain(blocking) {
        assert_eq!(t.await.unwrap().status, StatusCode::OK);
    }
    assert_eq!(*order.lock().unwrap(), [12, 12, 11]);
}

#[tokio::test]
async fn priority_must_be_a_finite_number() {
    let a = app(small_config());
    for bad in ["NaN", "inf", "-infinity", "high", "", "1e999"] {
        let r = get(&a, &format!("/api/v1/chunk/top/0/0/0/1?priority={bad}")).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "priority={bad}");
        let msg = r.json()["error"].as_str().unwrap().to_string();
        assert!(msg.contains("'priority' must be a finite number"), "{msg}");
    }
    for good in ["0", "-1.5", "1e300", "+3+"] {
        let r = get(&a, &format!("/api/v1/chunk/top/0/0/0/1?priority={good}")).await;
        assert_eq!(r.status, StatusCode::OK, "priority={good}");
    }
    let s = stats(&a).await;
    assert_eq!((jobs(&s, "done"), s["generated"].as_u64()), (1, Some(1)), "{s}");
}

/// The decoded chunk's vertices, in the planet frame.
fn vertices(body: &[u8]) -> (ChunkKey, Vec<DVec3>, usize) {
    let d = decode_chunk(body).unwrap();
    let v = d
        .positions
        .iter()
        .map(|p| d.origin + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
        .collect();
    (d.key, v, d.triangle_count())
}

#[tokio::test]
async fn chunks_of_every_level_over_one_region_are_served_and_cached_apart() {
    let a = app(ServerConfig {
        port: 0,
        threads: 2,
        ..ServerConfig::default()
    });
    let layout = Layout::default();
    let max_level = layout.max_level();
    assert_eq!(max_level, 3);
    let planet = Planet::new(PresetKind::Earthlike, 7, layout);
    let (low, high) = planet.terrain().density.radial_bounds().unwrap();
    let v = get(&a, "/api/v1/planet").await.json();
    assert_eq!(v["max_level"], max_level);
    let mut requested = 0;
    // Two regions: a face corner and a chunk inside a face, each named at level 0.
    for (face, i0, j0) in [(Face::Top, 0u32, 0u32), (Face::East, 5, 2)] {
        for level in 0..=max_level {
            let (i, j) = (i0 >> level, j0 >> level);
            let mut triangles = 0;
            for k in 0..layout.depth_chunks(level) {
                let key = ChunkKey { face, level, i, j, k };
                let r = get(&a, &chunk_uri(&key)).await;
                assert_eq!(r.status, StatusCode::OK, "{key}");
                requested += 1;
                let (decoded, points, tris) = vertices(&r.body);
                assert_eq!(decoded, key);
                let mut expected = Vec::new();
                encode_chunk(&planet.chunk_mesh(key), &mut expected).unwrap();
                assert!(r.body[..] == expected[..], "{key}: bytes differ");
                // Every vertex lies on the surface: within the terrain's radial bounds, give or
                // take one grid step of the level (and the sag of a chord).
                let step = layout.l_d() * f64::from(1u32 << level);
                for p in &points {
                    let r = p.length();
                    assert!(
                        r > low - step - 1e-3 * high && r < high + step,
                        "{key}: a vertex at radius {r}, surface within [{low}, {high}]"
                    );
                }
                triangles += tris;
            }
            // Each column spans the whole shell (solid at its floor, air at its top), so the
            // surface crosses it at every level.
            assert!(triangles > 0, "{face:?} {level}/{i}/{j}: no surface");
        }
    }
    // Every key (the level included) is its own cache entry.
    let s = stats(&a).await;
    assert_eq!(s["cached_chunks"], requested, "{s}");
    assert_eq!(s["generated"], requested, "{s}");
    // Asked again, each comes from the cache with its own level.
    for level in 0..=max_level {
        let key = ChunkKey {
            face: Face::Top,
            level,
            i: 0,
            j: 0,
            k: 0,
        };
        assert_eq!(decode_chunk(&get(&a, &chunk_uri(&key)).await.body).unwrap().key, key);
    }
    assert_eq!(stats(&a).await["generated"], requested);
}

/// The first content a subtree file names (a URL under `/tiles/r0/`).
fn first_content(subtree: &Value) -> Option<String> {
    fn find(node: &Value) -> Option<String> {
        let uri = node["content"]["uri"].as_str().filter(|u| u.ends_with(".glb"));
        uri.map(|u| format!("/tiles/r0/{}", u.trim_start_matches("../../../../../")))
            .or_else(|| node["children"].as_array()?.iter().find_map(find))
    }
    find(&subtree["root"])
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn tiles_are_made_by_the_chunk_workers_and_abandoned_ones_are_dropped() {
    let a = app(slow_config());
    let ts = get(&a, "/tiles/tileset.json").await.json();
    let face = ts["root"]["children"][0]["content"]["uri"]
        .as_str()
        .unwrap()
        .to_string();
    let sub = get(&a, &format!("/tiles/{face}")).await;
    assert_eq!(sub.status, StatusCode::OK);
    // the subtree file was a job of the generator
    let before = stats_until(&a, "the subtree file's job done", |s| jobs(s, "done") == 1).await;
    assert_eq!(jobs(&before, "running") + jobs(&before, "queued"), 0);
    let content = first_content(&sub.json()).expect("a content");
    // The one worker busy with a chunk: the tile's job waits in the chunks' queue.
    let blocker = spawn_get(&a, chunk_uri(&surface_chunks()[0]));
    stats_until(&a, "a running job", |s| jobs(s, "running") == 1).await;
    let tile = spawn_get(&a, content.clone());
    stats_until(&a, "the tile's job queued", |s| jobs(s, "queued") == 1).await;
    tile.abort();
    assert!(cancelled(tile.await));
    let s = stats_until(&a, "the tile's job dropped", |s| jobs(s, "dropped") == 1).await;
    assert_eq!(jobs(&s, "queued"), 0, "{s}");
    assert_eq!(blocker.await.unwrap().status, StatusCode::OK);
    // Asked for again, it is made (and was not left half-listed).
    let r = get(&a, &content).await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    assert_eq!(&r.body[..4], b"glTF");
    let s = stats_until(&a, "no job left", |s| jobs(s, "queued") + jobs(s, "running") == 0).await;
    assert_eq!(jobs(&s, "done"), 3, "the subtree file, the chunk, the tile: {s}");
    // A file made is served from the tiles' cache: no new job.
    assert_eq!(get(&a, &content).await.status, StatusCode::OK);
    assert_eq!(jobs(&stats(&a).await, "done"), 3);
}
