//! The endpoints of `docs/specs/http-api-v1.md`, through the router.

use crate::common::{app, get, send, small_config, small_layout, stats};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use pmc_formats::chunk_encoding::{decode_chunk, encode_chunk};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face, Layout};
use pmc_lod::bounds::chunk_sphere;
use pmc_planet::{Planet, PresetKind};
use pmc_server::ServerConfig;
use serde_json::Value;
use std::io::Read;

#[tokio::test]
async fn health_answers() {
    let a = app(small_config());
    let r = get(&a, "/api/v1/health").await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.header("content-type"), Some("application/json"));
    let v = r.json();
    assert_eq!(v["ok"], true);
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
}

#[tokio::test]
async fn planet_describes_the_planet() {
    let a = app(small_config());
    let v = get(&a, "/api/v1/planet").await.json();
    assert_eq!(v["format"], "pmc-planet");
    assert_eq!(v["version"], 1);
    assert_eq!(v["preset"], "earthlike");
    assert_eq!(v["seed"], "3");
    let names: Vec<&str> = v["presets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["sphere", "earthlike", "moon", "mars", "earth"]);
    assert!(v["presets"][1]["description"].as_str().unwrap().contains("continents"));
    assert_eq!(
        v["layout"],
        serde_json::json!({"n_c": 2, "n_t": 8, "d_b": 100.0, "l_d": 2.0, "d_c": 2})
    );
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    assert_eq!(v["radius"], 132.0);
    assert_eq!(v["base_radius"], 100.0);
    assert_eq!(v["sea_radius"].as_f64(), planet.terrain().sea_radius);
    let b = v["surface_bounds"].as_array().unwrap();
    assert_eq!(b.len(), 2);
    assert!(b[0].as_f64().unwrap() < b[1].as_f64().unwrap());
    assert_eq!(v["chunk_count"], 48);
    assert_eq!(v["face_tiles"], 16);
    assert_eq!(v["depth_tiles"], 16);
    assert_eq!(v["max_level"], 1);
    let faces = v["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 6);
    assert_eq!(
        faces[0],
        serde_json::json!({"name": "top", "index": 0, "normal": [0, 1, 0], "u": [-1, 0, 0], "v": [0, 0, 1]})
    );
    assert_eq!(faces[4]["name"], "east");
    assert_eq!(faces[4]["normal"], serde_json::json!([1, 0, 0]));
    let materials: Vec<&str> = v["materials"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_str().unwrap())
        .collect();
    assert_eq!(materials, planet.terrain().materials);
    for c in ["a", "b"] {
        let rgb = v["palette"][c].as_array().unwrap();
        assert_eq!(rgb.len(), 3);
        assert!(rgb.iter().all(|x| (0.0..=1.0).contains(&x.as_f64().unwrap())));
    }

    // Another planet by query; big seeds stay exact as strings.
    let v = get(&a, "/api/v1/planet?preset=sphere&seed=18446744073709551615")
        .await
        .json();
    assert_eq!(v["preset"], "sphere");
    assert_eq!(v["seed"], "18446744073709551615");
    assert!(v["sea_radius"].is_null());
    assert_eq!(stats(&a).await["planets"], 2);
}

/// The chunks `/chunks` should list, computed directly.
fn expected_chunks(planet: &Planet, level: u8, p: DVec3, range: f64) -> Vec<(String, f64)> {
    let mut v: Vec<(ChunkKey, f64)> = planet
        .layout()
        .chunks(level)
        .into_iter()
        .filter(|k| planet.may_hold_surface(k))
        .map(|k| (k, chunk_sphere(planet.layout(), &k).distance(p)))
        .filter(|(_, d)| *d <= range)
        .collect();
    v.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    v.into_iter().map(|(k, d)| (k.to_string(), d)).collect()
}

fn listed(v: &Value) -> Vec<(String, f64)> {
    v["chunks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["key"].as_str().unwrap().to_string(), c["distance"].as_f64().unwrap()))
        .collect()
}

/// Same keys in the same order, same distances (to within JSON's decimal rounding).
fn assert_same(a: &[(String, f64)], b: &[(String, f64)], what: &str) {
    let keys = |v: &[(String, f64)]| v.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(keys(a), keys(b), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert!((x.1 - y.1).abs() <= 1e-9 * (1.0 + y.1), "{what}: {x:?} vs {y:?}");
    }
}

#[tokio::test]
async fn chunks_are_listed_nearest_first_within_range() {
    let a = app(small_config());
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    let p = DVec3::new(10.0, 120.0, -30.0);
    for (range, level) in [(5.0, 0u8), (40.0, 0), (1000.0, 0), (30.0, 1)] {
        let uri = format!(
            "/api/v1/chunks?x={}&y={}&z={}&range={range}&level={level}",
            p.x, p.y, p.z
        );
        let r = get(&a, &uri).await;
        assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
        let v = r.json();
        let expected = expected_chunks(&planet, level, p, range);
        assert_same(&listed(&v), &expected, &format!("range {range} level {level}"));
        assert_eq!(v["total_in_range"], expected.len());
        for c in v["chunks"].as_array().unwrap() {
            let key: Vec<&str> = c["key"].as_str().unwrap().split('/').collect();
            assert_eq!(key[0], c["face"]);
            assert_eq!(key[1], c["level"].to_string());
            assert_eq!(key[2..], [c["i"].to_string(), c["j"].to_string(), c["k"].to_string()]);
            let centre: Vec<f64> = c["center"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let d = (DVec3::from_slice(&centre) - p).length() - c["radius"].as_f64().unwrap();
            assert!((d.max(0.0) - c["distance"].as_f64().unwrap()).abs() < 1e-9);
        }
    }
    // Everything within a huge range: every chunk that may hold surface, not the others.
    let v = get(&a, "/api/v1/chunks?x=0&y=0&z=0&range=1e9&preset=sphere")
        .await
        .json();
    let sphere = Planet::new(PresetKind::Sphere, 3, small_layout());
    let holding = small_layout()
        .chunks(0)
        .iter()
        .filter(|k| sphere.may_hold_surface(k))
        .count();
    assert_eq!(holding, 24, "the sphere lies in the outer chunk layer only");
    assert_eq!(v["total_in_range"], holding);
    // A limit keeps the nearest.
    let all = listed(&get(&a, "/api/v1/chunks?x=10&y=120&z=-30&range=1000").await.json());
    let v = get(&a, "/api/v1/chunks?x=10&y=120&z=-30&range=1000&limit=3")
        .await
        .json();
    assert_same(&listed(&v), &all[..3], "limit");
    assert_eq!(v["total_in_range"], all.len());
    assert!(all.len() > 3);
}

#[tokio::test]
async fn a_chunk_is_the_encoding_of_the_planets_mesh() {
    let a = app(small_config());
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    let mut seen_surface = false;
    let mut seen_empty = false;
    for key in small_layout().chunks(0).into_iter().chain(small_layout().chunks(1)) {
        let uri = format!("/api/v1/chunk/{key}");
        let r = get(&a, &uri).await;
        assert_eq!(r.status, StatusCode::OK, "{uri}");
        assert_eq!(r.header("content-type"), Some("application/octet-stream"));
        let mesh = planet.chunk_mesh(key);
        let mut expected = Vec::new();
        encode_chunk(&mesh, &mut expected).unwrap();
        assert!(r.body[..] == expected[..], "{uri}: bytes differ");
        let d = decode_chunk(&r.body).unwrap();
        assert_eq!(d.key, key);
        assert_eq!(d.positions, mesh.positions);
        seen_surface |= d.triangle_count() > 0;
        seen_empty |= d.vertex_count() == 0;
    }
    assert!(seen_surface && seen_empty);
    // Another planet by query parameters.
    let key = ChunkKey::new(Face::West, 1, 0, 1);
    let r = get(&a, "/api/v1/chunk/west/0/1/0/1?preset=moon&seed=9").await;
    let mut expected = Vec::new();
    encode_chunk(
        &Planet::new(PresetKind::Moon, 9, small_layout()).chunk_mesh(key),
        &mut expected,
    )
    .unwrap();
    assert!(r.body[..] == expected[..]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn concurrent_requests_for_one_chunk_generate_it_once() {
    let a = app(ServerConfig {
        // Large enough chunks that all requests arrive while the one job runs.
        layout: Layout::new(2, 48, 100.0, 2.0, 2).unwrap(),
        ..small_config()
    });
    let mut tasks = tokio::task::JoinSet::new();
    for _ in 0..16 {
        let a = a.clone();
        tasks.spawn(async move { get(&a, "/api/v1/chunk/top/0/1/0/1").await });
    }
    let mut bodies = Vec::new();
    while let Some(r) = tasks.join_next().await {
        let r = r.unwrap();
        assert_eq!(r.status, StatusCode::OK);
        bodies.push(r.body);
    }
    assert!(bodies.windows(2).all(|w| w[0] == w[1]));
    assert!(bodies[0].len() > 56);
    let s = stats(&a).await;
    assert_eq!(s["generated"], 1, "{s}");
    assert_eq!(s["cached_chunks"], 1);
    assert_eq!(s["cached_bytes"], bodies[0].len());
    assert_eq!((s["queued"].as_u64(), s["in_flight"].as_u64()), (Some(0), Some(0)));
    // And later requests come from the cache.
    get(&a, "/api/v1/chunk/top/0/1/0/1").await;
    assert_eq!(stats(&a).await["generated"], 1);
}

#[tokio::test]
async fn the_cache_stays_within_its_byte_bound() {
    let keys = ["top/0/0/0/1", "top/0/1/0/1", "top/0/0/1/1"];
    // Sizes of the three chunks, from a server with a large cache.
    let big = app(small_config());
    let mut sizes = Vec::new();
    for k in keys {
        sizes.push(get(&big, &format!("/api/v1/chunk/{k}")).await.body.len() as u64);
    }
    assert!(sizes.iter().all(|&s| s > 56), "{sizes:?}");
    let bound = sizes.iter().max().unwrap() * 3 / 2;
    let a = app(ServerConfig {
        cache_bytes: bound,
        ..small_config()
    });
    for k in keys {
        assert_eq!(get(&a, &format!("/api/v1/chunk/{k}")).await.status, StatusCode::OK);
        let s = stats(&a).await;
        assert!(s["cached_bytes"].as_u64().unwrap() <= bound, "{s}");
    }
    let s = stats(&a).await;
    assert_eq!(s["generated"], 3);
    assert_eq!(s["cached_chunks"], 1, "{s}");
    assert_eq!(s["cached_bytes"], sizes[2]);
    // The first chunk was evicted: asking again generates it again; the last one is cached.
    get(&a, &format!("/api/v1/chunk/{}", keys[0])).await;
    assert_eq!(stats(&a).await["generated"], 4);
    get(&a, &format!("/api/v1/chunk/{}", keys[0])).await;
    assert_eq!(stats(&a).await["generated"], 4);
}

#[tokio::test]
async fn planets_beyond_the_limit_are_dropped_with_their_chunks() {
    let a = app(ServerConfig {
        max_planets: 1,
        ..small_config()
    });
    get(&a, "/api/v1/chunk/top/0/0/0/1").await;
    assert_eq!(stats(&a).await["cached_chunks"], 1);
    get(&a, "/api/v1/planet?preset=mars").await;
    let s = stats(&a).await;
    assert_eq!(
        (s["planets"].as_u64(), s["cached_chunks"].as_u64()),
        (Some(1), Some(0)),
        "{s}"
    );
}

#[tokio::test]
async fn malformed_requests_get_a_json_4xx() {
    let a = app(small_config());
    let cases: &[(&str, u16, &str)] = &[
        ("/api/v1/planet?preset=venus", 400, "unknown preset 'venus'"),
        ("/api/v1/planet?seed=-1", 400, "seed"),
        ("/api/v1/planet?seed=abc", 400, "seed"),
        ("/api/v1/planet?seed=18446744073709551616", 400, "seed"),
        ("/api/v1/chunks?y=0&z=0&range=1", 400, "missing query parameter 'x'"),
        ("/api/v1/chunks?x=0&y=0&range=1", 400, "'z'"),
        ("/api/v1/chunks?x=0&y=0&z=0", 400, "'range'"),
        ("/api/v1/chunks?x=NaN&y=0&z=0&range=1", 400, "finite"),
        ("/api/v1/chunks?x=0&y=inf&z=0&range=1", 400, "finite"),
        ("/api/v1/chunks?x=0&y=0&z=-infinity&range=1", 400, "finite"),
        ("/api/v1/chunks?x=&y=0&z=0&range=1", 400, "finite"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=0", 400, "range must be above 0"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=-5", 400, "range must be above 0"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=1&limit=0", 400, "limit"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=1&limit=4097", 400, "limit"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=1&limit=ten", 400, "limit"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=1&level=2", 400, "max level"),
        ("/api/v1/chunks?x=0&y=0&z=0&range=1&preset=pluto", 400, "unknown preset"),
        ("/api/v1/chunk/up/0/0/0/0", 400, "unknown face 'up'"),
        ("/api/v1/chunk/top/x/0/0/0", 400, "level"),
        ("/api/v1/chunk/top/0/-1/0/0", 400, "chunk i"),
        ("/api/v1/chunk/top/0/0/1.5/0", 400, "chunk j"),
        ("/api/v1/chunk/top/0/0/0/%FF", 400, "malformed"),
        ("/api/v1/chunk/top/0/0/0/0?seed=x", 400, "seed"),
        (
            "/api/v1/chunk/top/0/0/0/0?priority=NaN",
            400,
            "'priority' must be a finite number",
        ),
        ("/api/v1/chunk/top/0/0/0/0?priority=", 400, "priority"),
        ("/api/v1/chunk/top/0/2/0/0", 404, "not part of this planet"),
        ("/api/v1/chunk/top/0/0/0/2", 404, "k below 2"),
        ("/api/v1/chunk/top/1/1/0/0", 404, "not part of this planet"),
        ("/api/v1/chunk/top/2/0/0/0", 404, "above the layout's max level 1"),
        ("/api/v1/chunk/top/300/0/0/0", 404, "max level"),
        ("/api/v1/chunk/top/0/0/0/99999999999", 404, "not part"),
        ("/api/v1/chunk/top/0/0/0", 404, "no such API endpoint"),
        ("/api/v1/chunk/top/0/0/0/0/0", 404, "no such API endpoint"),
        ("/api/v2/planet", 404, "no such API endpoint"),
        ("/api/", 404, "no such API endpoint"),
        ("/api", 404, "no such API endpoint"),
    ];
    for &(uri, status, needle) in cases {
        let r = get(&a, uri).await;
        assert_eq!(r.status.as_u16(), status, "{uri}: {}", String::from_utf8_lossy(&r.body));
        assert_eq!(r.header("content-type"), Some("application/json"), "{uri}");
        let v = r.json();
        let msg = v["error"]
            .as_str()
            .unwrap_or_else(|| panic!("{uri}: no error field in {v}"));
        assert!(msg.contains(needle), "{uri}: '{needle}' not in '{msg}'");
    }
    let r = send(&a, Request::post("/api/v1/health").body(Body::empty()).unwrap()).await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
    assert!(r.json()["error"].is_string());
    // Nothing was generated for any of them.
    assert_eq!(stats(&a).await["generated"], 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_full_queue_answers_503() {
    let a = app(ServerConfig {
        layout: Layout::new(4, 48, 100.0, 1.0, 2).unwrap(),
        threads: 1,
        queue_limit: 2,
        ..small_config()
    });
    let planet = Planet::new(PresetKind::Earthlike, 3, Layout::new(4, 48, 100.0, 1.0, 2).unwrap());
    let keys: Vec<ChunkKey> = planet
        .layout()
        .chunks(0)
        .into_iter()
        .filter(|k| planet.may_hold_surface(k))
        .take(40)
        .collect();
    assert_eq!(keys.len(), 40);
    // Make sure the planet exists, so every request goes straight to the queue.
    get(&a, "/api/v1/planet").await;
    let mut tasks = tokio::task::JoinSet::new();
    for key in keys {
        let a = a.clone();
        tasks.spawn(async move { get(&a, &format!("/api/v1/chunk/{key}")).await });
    }
    let (mut ok, mut busy) = (0u64, 0u64);
    while let Some(r) = tasks.join_next().await {
        let r = r.unwrap();
        match r.status {
            StatusCode::OK => ok += 1,
            StatusCode::SERVICE_UNAVAILABLE => {
                busy += 1;
                assert_eq!(r.header("retry-after"), Some("1"));
                assert!(r.json()["error"].as_str().unwrap().contains("busy"));
            }
            s => panic!("unexpected status {s}"),
        }
    }
    assert!(ok >= 1 && busy >= 1, "ok {ok}, busy {busy}");
    let s = stats(&a).await;
    assert_eq!(s["rejected_busy"], busy);
    assert_eq!(s["generated"], ok);
    assert_eq!((s["queued"].as_u64(), s["in_flight"].as_u64()), (Some(0), Some(0)));
}

#[tokio::test]
async fn the_root_serves_html_and_unknown_files_are_404() {
    let a = app(small_config());
    let r = get(&a, "/").await;
    assert_eq!(r.status, StatusCode::OK);
    assert!(r.header("content-type").unwrap().starts_with("text/html"));
    let html = String::from_utf8_lossy(&r.body).to_lowercase();
    assert!(html.contains("<html"), "{html}");
    let etag = r.header("etag").unwrap().to_string();
    let again = send(
        &a,
        Request::get("/index.html")
            .header("if-none-match", &etag)
            .body(Body::empty())
            .unwrap(),
    )
    .await;
    assert_eq!(again.status, StatusCode::NOT_MODIFIED);
    assert_eq!(get(&a, "/no/such/file.js").await.status, StatusCode::NOT_FOUND);
}

fn gunzip(b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(b).read_to_end(&mut out).unwrap();
    out
}

#[tokio::test]
async fn answers_are_gzipped_when_the_client_accepts_it() {
    let a = app(small_config());
    let gz = |uri: &str| {
        Request::get(uri)
            .header("accept-encoding", "gzip")
            .body(Body::empty())
            .unwrap()
    };
    let plain = get(&a, "/api/v1/planet").await;
    let r = send(&a, gz("/api/v1/planet")).await;
    assert_eq!(r.header("content-encoding"), Some("gzip"));
    assert!(r.body.len() < plain.body.len());
    assert_eq!(gunzip(&r.body), plain.body);
    let plain = get(&a, "/api/v1/chunk/top/0/0/0/1").await;
    assert_eq!(plain.header("content-encoding"), None);
    let r = send(&a, gz("/api/v1/chunk/top/0/0/0/1")).await;
    assert_eq!(r.header("content-encoding"), Some("gzip"));
    assert_eq!(gunzip(&r.body), plain.body);
    assert!(decode_chunk(&gunzip(&r.body)).is_ok());
}

#[tokio::test]
async fn stats_has_every_field() {
    let a = app(small_config());
    let s = stats(&a).await;
    for f in [
        "planets",
        "cached_chunks",
        "cached_bytes",
        "generated",
        "queued",
        "in_flight",
        "rejected_busy",
    ] {
        assert!(s[f].is_u64(), "{f} in {s}");
    }
    for f in ["queued", "running", "waiting", "done", "dropped"] {
        assert_eq!(s["jobs"][f], 0, "jobs.{f} in {s}");
    }
    assert_eq!(s["planets"], 0);
}

/// Level-of-detail chunks: `/planet` describes the levels and their measured errors, and a
/// chunk asked with `seams` is the planet's mesh with those seams closed (normalised to the
/// sides where a coarser neighbour can lie); malformed masks are refused.
#[tokio::test]
async fn lod_chunks_close_the_seams_they_are_asked_for() {
    let a = app(small_config());
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    let v = get(&a, "/api/v1/planet").await.json();
    let lod = &v["lod"];
    let max_level = planet.layout().max_level();
    assert_eq!(lod["max_level"], u64::from(max_level));
    let errors: Vec<f64> = lod["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_f64().unwrap())
        .collect();
    assert_eq!(errors.len(), usize::from(max_level) + 1);
    assert_eq!(errors[0], 0.0);
    assert!(
        errors.windows(2).all(|w| w[0] <= w[1] && w[1].is_finite()),
        "{errors:?}"
    );
    assert!(lod["occluder_radius"].as_f64().unwrap() > 0.0);

    let key = planet
        .layout()
        .chunks(0)
        .into_iter()
        .filter(|k| !planet.layout().seam_sides(k).is_empty())
        .max_by_key(|k| planet.chunk_mesh(*k).triangle_count())
        .unwrap();
    let sides = planet.layout().seam_sides(&key);
    let path = format!("/api/v1/chunk/{}/0/{}/{}/{}", key.face.name(), key.i, key.j, key.k);
    let encode = |m: &pmc_mesh::ChunkMesh| {
        let mut out = Vec::new();
        encode_chunk(m, &mut out).unwrap();
        out
    };
    let closed = get(&a, &format!("{path}?seams=63")).await;
    assert_eq!(closed.status, StatusCode::OK);
    assert_eq!(
        closed.body.as_ref(),
        encode(&planet.chunk_mesh_lod(key, sides)).as_slice()
    );
    let plain = get(&a, &path).await;
    assert_eq!(plain.body.as_ref(), encode(&planet.chunk_mesh(key)).as_slice());
    assert_ne!(plain.body, closed.body, "closing the seams adds patches");
    for bad in ["64", "-1", "x", "1.5"] {
        let r = get(&a, &format!("{path}?seams={bad}")).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "seams={bad}");
        assert!(String::from_utf8_lossy(&r.body).contains("seams"));
    }
}

/// `GET /api/v1/chunks` on `earth` refused a 50 m range at level 0 and a 20 km range at level 4
/// ("more than 200000 chunks ... lie near the point"): the search went through the shell's whole
/// thickness around the point. Both answer now, and a range with more chunks than the budget is
/// still refused with the reason.
#[tokio::test]
async fn the_earth_answers_chunks_near_a_point_at_fine_and_coarse_levels() {
    let layout = PresetKind::Earth.default_layout(None).unwrap();
    let a = app(ServerConfig {
        port: 0,
        terrain: pmc_planet::TerrainSpec::preset(PresetKind::Earth, 7),
        layout,
        threads: 2,
        ..ServerConfig::default()
    });
    let p = pmc_geometry::LatLon::new(39.0, 0.0).unwrap().to_unit() * 6_371_000.0;
    for (level, range) in [(0u8, 50.0), (4, 20_000.0)] {
        let uri = format!(
            "/api/v1/chunks?x={}&y={}&z={}&range={range}&level={level}",
            p.x, p.y, p.z
        );
        let r = get(&a, &uri).await;
        assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
        let v = r.json();
        let total = v["total_in_range"].as_u64().unwrap();
        let listed = v["chunks"].as_array().unwrap();
        assert!(
            total > 0 && listed.len() as u64 == total.min(512),
            "level {level}: {total}"
        );
        assert!(listed
            .iter()
            .all(|c| c["distance"].as_f64().unwrap() <= range && c["level"] == level));
    }
    let uri = format!("/api/v1/chunks?x={}&y={}&z={}&range=200000&level=4", p.x, p.y, p.z);
    let r = get(&a, &uri).await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(String::from_utf8_lossy(&r.body).contains("more than 200000 chunks of level 4 lie within range"));
}
