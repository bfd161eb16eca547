//! The navigation endpoints: `/api/v1/path` and `/api/v1/navgrid`, on plain planets and on a
//! world whose grid follows its edits.

use crate::common::{get, send, small_config, small_layout};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::LatLon;
use pmc_nav::{query, Agent, End, NavGrid, PathAnswer};
use pmc_planet::{Planet, PresetKind};
use pmc_server::{router, AppState, ServerConfig};
use serde_json::{json, Value};

fn end(lat: f64, lon: f64) -> End {
    End {
        dir: LatLon::new(lat, lon).unwrap().to_unit(),
        radius: None,
    }
}

fn direct_length(planet: &Planet, from: End, to: End) -> f64 {
    let g = NavGrid::build(planet.density().as_ref(), planet.layout(), Agent::default()).unwrap();
    match query(&g, from, to, 8) {
        PathAnswer::Found(p) => p.length,
        other => panic!("{other:?}"),
    }
}

#[tokio::test]
async fn path_answers_the_walk_and_its_smoothed_form_as_json_or_geojson() {
    let a = router(AppState::new(small_config()).unwrap());
    let r = get(&a, "/api/v1/path?from=10,10&to=12,40").await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let v = r.json();
    assert_eq!(
        (v["format"].as_str(), v["found"].as_bool()),
        (Some("pmc-path"), Some(true)),
        "{v}"
    );
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    assert_eq!(
        v["length"].as_f64().unwrap(),
        direct_length(&planet, end(10.0, 10.0), end(12.0, 40.0))
    );
    assert_eq!(v["revision"], 0);
    // The walk pulled straight: shorter, its corners a subset of the waypoints.
    let smoothed = &v["smoothed"];
    assert!(
        smoothed["length"].as_f64().unwrap() <= v["length"].as_f64().unwrap() * 1.0001,
        "{v}"
    );
    assert_eq!(smoothed["waypoints"][0], v["waypoints"][0]);
    // Its line (for drawing) starts and ends at the walk's ends and passes every corner.
    let line = smoothed["line"].as_array().unwrap();
    let corners = smoothed["waypoints"].as_array().unwrap();
    assert!(line.len() >= corners.len(), "{smoothed}");
    assert_eq!(line.first(), corners.first());
    assert_eq!(line.last(), corners.last());
    assert!(corners.iter().all(|c| line.contains(c)), "{smoothed}");
    let g = get(&a, "/api/v1/path?from=10,10&to=12,40&format=geojson").await.json();
    let last = g["features"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["properties"]["role"], "smoothed");
    assert_eq!(last["properties"]["length"], smoothed["length"]);
    assert_eq!(g["type"], "FeatureCollection");
    assert_eq!(g["features"][0]["properties"]["length"], v["length"]);
    // Another agent, another grid: one that cannot climb any slope finds nothing.
    let v = get(
        &a,
        "/api/v1/path?from=10,10&to=12,40&max_slope=0.0001&step_up=0&step_down=0",
    )
    .await
    .json();
    assert_eq!(v["found"], false);
    assert!(v["reason"].as_str().unwrap().contains("component"));
}

#[tokio::test]
async fn bad_path_and_grid_queries_get_a_400() {
    let a = router(AppState::new(small_config()).unwrap());
    for (uri, needle) in [
        ("/api/v1/path?to=1,1", "missing query parameter 'from'"),
        ("/api/v1/path?from=1,1", "'to'"),
        ("/api/v1/path?from=100,1&to=1,1", "latitude"),
        ("/api/v1/path?from=1&to=1,1", "expected 2 or 3 numbers"),
        ("/api/v1/path?from=1,NaN&to=1,1", "finite"),
        ("/api/v1/path?from=1,1&to=1,1,inf", "finite"),
        ("/api/v1/path?from=1,1&to=2,2&format=kml", "json or geojson"),
        ("/api/v1/path?from=1,1&to=2,2&clearance=0", "clearance"),
        ("/api/v1/path?from=1,1&to=2,2&max_slope=x", "max_slope"),
        ("/api/v1/path?from=1,1&to=2,2&preset=venus", "unknown preset"),
        ("/api/v1/navgrid?x=0&y=0&range=10", "'z'"),
        ("/api/v1/navgrid?x=0&y=0&z=0&range=0", "range must be above 0"),
        ("/api/v1/navgrid?x=0&y=0&z=0&range=5&limit=0", "limit"),
        ("/api/v1/navgrid?x=0&y=0&z=0&range=5&limit=100001", "limit"),
        ("/api/v1/navgrid?x=0&y=0&z=0&range=5&step_up=-2", "step"),
    ] {
        let r = get(&a, uri).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "{uri}");
        let msg = r.json()["error"].as_str().unwrap().to_string();
        assert!(msg.contains(needle), "{uri}: '{needle}' not in '{msg}'");
    }
    let r = send(&a, Request::post("/api/v1/path").body(Body::empty()).unwrap()).await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
}

#[tokio::test]
async fn navgrid_lists_the_nodes_near_a_point_with_components_and_steps() {
    let a = router(AppState::new(small_config()).unwrap());
    let planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    let grid = NavGrid::build(planet.density().as_ref(), planet.layout(), Agent::default()).unwrap();
    let p = LatLon::new(20.0, 30.0).unwrap().to_unit() * planet.datum_radius();
    let uri = format!("/api/v1/navgrid?x={}&y={}&z={}&range=40", p.x, p.y, p.z);
    let v = get(&a, &uri).await.json();
    let (nodes, _) = grid.nodes_near(p, 40.0, usize::MAX);
    let positions = v["positions"].as_array().unwrap();
    assert_eq!(positions.len(), 3 * nodes.len());
    assert!(!nodes.is_empty());
    assert_eq!(v["truncated"], false);
    assert_eq!(v["total_nodes"].as_u64().unwrap() as usize, grid.node_count());
    for (i, n) in nodes.iter().enumerate() {
        let q = grid.position(*n).unwrap() - p;
        let got = DVec3::new(
            positions[3 * i].as_f64().unwrap(),
            positions[3 * i + 1].as_f64().unwrap(),
            positions[3 * i + 2].as_f64().unwrap(),
        );
        assert!((got - q).length() < 1e-9);
        assert_eq!(v["components"][i].as_u64(), grid.component(*n).map(u64::from));
    }
    let edges = v["edges"].as_array().unwrap();
    assert!(!edges.is_empty() && edges.len() % 2 == 0);
    for e in edges.chunks(2) {
        let (i, j) = (e[0].as_u64().unwrap() as usize, e[1].as_u64().unwrap() as usize);
        assert!(i < j && j < nodes.len());
        assert!(grid.steps(nodes[i]).iter().any(|s| s.to == nodes[j]));
    }
    // Every step between nodes of the answer is there (the default agent's steps go both ways).
    let pairs: usize = nodes
        .iter()
        .enumerate()
        .map(|(i, n)| grid.steps(*n).iter().filter(|s| nodes[i + 1..].contains(&s.to)).count())
        .sum();
    assert_eq!(edges.len() / 2, pairs);
    // An agent that climbs nothing but drops 8 m has one-way steps; they are listed too.
    let one_way = Agent {
        step_up: 0.0,
        ..Agent::default()
    };
    let g1 = NavGrid::build(planet.density().as_ref(), planet.layout(), one_way).unwrap();
    let v1 = get(&a, &format!("{uri}&step_up=0")).await.json();
    let (n1, _) = g1.nodes_near(p, 40.0, usize::MAX);
    let mut want = std::collections::BTreeSet::new();
    for (i, n) in n1.iter().enumerate() {
        for s in g1.steps(*n) {
            if let Some(j) = n1.iter().position(|m| *m == s.to) {
                want.insert((i.min(j) as u64, i.max(j) as u64));
            }
        }
    }
    let got: std::collections::BTreeSet<(u64, u64)> = v1["edges"]
        .as_array()
        .unwrap()
        .chunks(2)
        .map(|e| (e[0].as_u64().unwrap(), e[1].as_u64().unwrap()))
        .collect();
    assert_eq!(got, want);
    let v = get(&a, &format!("{uri}&limit=2")).await.json();
    assert_eq!(
        (v["positions"].as_array().unwrap().len(), v["truncated"].as_bool()),
        (6, Some(true))
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_worlds_grid_follows_its_edits() {
    let d = std::env::temp_dir().join(format!("pmc-server-nav-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let config = ServerConfig {
        world: Some(d.join("w.pmcw")),
        terrain: pmc_planet::TerrainSpec::preset(PresetKind::Sphere, small_config().terrain.seed()),
        ..small_config()
    };
    let a = router(AppState::new(config).unwrap());
    let path = |v: &Value| v["length"].as_f64().unwrap();
    let uri = "/api/v1/path?from=0,-20&to=0,20";
    let before = get(&a, uri).await.json();
    assert_eq!(before["found"], true);
    // A deep pit with sheer walls across the way.
    let planet = Planet::new(PresetKind::Sphere, 3, small_layout());
    let c = LatLon::new(0.0, 0.0).unwrap().to_unit() * planet.datum_radius();
    let op = BrushOp::new(BrushKind::Remove, c, 20.0, 1.0).unwrap();
    let body = json!({"brush": "remove", "x": c.x, "y": c.y, "z": c.z, "radius": 20.0});
    let req = Request::post("/api/v1/edits")
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    assert_eq!(send(&a, req).await.status, StatusCode::OK);
    let after = get(&a, uri).await.json();
    assert_eq!(after["revision"], 1);
    let edited = planet.clone().with_edits(vec![op].into());
    assert_eq!(path(&after), direct_length(&edited, end(0.0, -20.0), end(0.0, 20.0)));
    assert!(
        path(&after) > path(&before) + 1.0,
        "{} -> {}",
        path(&before),
        path(&after)
    );
    // Undone: the first way again.
    let req = Request::post("/api/v1/edits/undo").body(Body::empty()).unwrap();
    assert_eq!(send(&a, req).await.status, StatusCode::OK);
    let undone = get(&a, uri).await.json();
    assert_eq!((undone["revision"].as_u64(), path(&undone)), (Some(2), path(&before)));
}

#[tokio::test]
async fn a_planet_too_large_for_a_grid_gets_lazy_paths_and_a_400_for_the_grid() {
    let layout = pmc_geometry::Layout::new(128, 32, 1000.0, 1.0, 1).unwrap();
    assert!(pmc_nav::wants_lazy_grid(&layout));
    let config = ServerConfig {
        layout,
        ..small_config()
    };
    let a = router(AppState::new(config).unwrap());
    // The grid describes components, which a lazy grid has none of.
    let r = get(&a, "/api/v1/navgrid?x=0&y=1100&z=0&range=5").await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(r.json()["error"].as_str().unwrap().contains("columns"));
    // A path: the lazy grid's document, the same path as `pmc path` finds on the same planet.
    let v = get(&a, "/api/v1/path?from=1,1&to=1.2,1.3").await.json();
    assert_eq!(v["found"], true, "{v}");
    assert_eq!(v["revision"], 0);
    assert!(v["search"]["expanded"].as_u64().unwrap() > 0, "{v}");
    let planet = Planet::from_terrain(&small_config().terrain, layout).unwrap();
    let mut grid = pmc_nav::LazyGrid::new(
        planet.density().clone(),
        planet.layout(),
        Agent::default(),
        pmc_nav::LazyOptions::default(),
    )
    .unwrap();
    let search = pmc_nav::SearchOptions::default();
    let found = grid.query(end(1.0, 1.0), end(1.2, 1.3), 8, &search);
    let want = pmc_nav::lazy_path_json(
        &grid,
        &found,
        &search,
        end(1.0, 1.0),
        end(1.2, 1.3),
        planet.datum_radius(),
    );
    assert_eq!(v["length"], want["length"]);
    assert_eq!(v["waypoints"], want["waypoints"]);
    // Bad ends are still refused before any search.
    let r = get(&a, "/api/v1/path?from=91,1&to=1.2,1.3").await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
}

/// The HTTP inputs `cargo fuzz` found (`fuzz/regressions/http_request/`: the first byte picks
/// the endpoint as the fuzz target does, the rest up to a newline is the path's tail), replayed
/// against the router: each is answered, and none with a 500. `huge-clearance` (`/path` with a
/// clearance of 1.9e16 m) hung the server; now a 400.
#[tokio::test]
async fn fuzz_findings_are_answered_quickly() {
    const ENDPOINTS: [&str; 11] = [
        "/api/v1/chunks?",
        "/api/v1/chunk/",
        "/api/v1/planet?",
        "/api/v1/path?",
        "/api/v1/navgrid?",
        "/api/v1/edits?",
        "/api/v1/edits/undo?",
        "/api/v1/edits/redo?",
        "/api/v1/edits?",
        "/api/v1/stats?",
        "/api/v1/chunk-batch?",
    ];
    let a = router(AppState::new(small_config()).unwrap());
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions/http_request");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let (pick, rest) = bytes.split_first().unwrap();
        let tail = rest.split(|&b| b == b'\n').next().unwrap();
        let uri = format!(
            "{}{}",
            ENDPOINTS[usize::from(*pick) % ENDPOINTS.len()],
            String::from_utf8_lossy(tail)
        );
        let started = std::time::Instant::now();
        // (the GETs only: the kept inputs are queries)
        let r = tokio::time::timeout(std::time::Duration::from_secs(30), get(&a, &uri))
            .await
            .unwrap_or_else(|_| panic!("{}: {uri} hung", path.display()));
        assert_ne!(r.status, StatusCode::INTERNAL_SERVER_ERROR, "{uri}");
        eprintln!("{}: {} in {:?}", path.display(), r.status, started.elapsed());
        seen += 1;
    }
    assert!(seen >= 1);
    let huge = std::fs::read(dir.join("huge-clearance")).unwrap();
    let uri = format!("/api/v1/path?{}", String::from_utf8_lossy(&huge[1..]));
    let r = get(&a, &uri).await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(
        r.json()["error"].as_str().unwrap().contains("at most 1000"),
        "{}",
        r.json()
    );
}
