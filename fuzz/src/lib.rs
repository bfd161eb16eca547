//! What each fuzz target does with its input: parse it as one kind of outside bytes and check
//! that the reader either accepts it (and what it read is consistent) or refuses it with an
//! error. Any panic, a hang (libFuzzer's `-timeout`) or runaway memory (`-rss_limit_mb`) is a
//! finding. See `fuzz/README.md` for how to run them and `docs/BENCHMARKS.md` for the counts.

use axum::body::Body;
use axum::http::{Method, Request, StatusCode};
use pmc_geometry::Layout;
use pmc_planet::{PresetKind, TerrainSpec};
use pmc_server::{router, AppState, ServerConfig};
use std::path::PathBuf;
use std::sync::OnceLock;
use tower::ServiceExt;

/// The chunk mesh decoder: a decoded chunk is consistent (every section as long as the vertex
/// count says, every index below it, a finite origin).
pub fn chunk_decode(data: &[u8]) {
    if let Ok(c) = pmc_formats::chunk_encoding::decode_chunk(data) {
        let v = c.positions.len();
        assert!(c.normals.len() == v && c.colors.len() == v && c.heights.len() == v);
        assert!(c.water_depths.len() == v && c.materials.len() == v);
        assert!(c.positions_low.is_empty() || c.positions_low.len() == v);
        assert!(c.indices.len() % 3 == 0);
        assert!(c.indices.iter().all(|&i| (i as usize) < v));
        assert!(c.origin.is_finite());
    }
}

/// netCDF classic, whole and as a source of rows (`pmc_dem::fuzz` checks what was read).
pub fn dem_netcdf(data: &[u8]) {
    pmc_dem::fuzz::parse_netcdf(data);
    pmc_dem::fuzz::parse_netcdf_source(data);
}

/// GeoTIFF, whole and as a source of rows.
pub fn dem_geotiff(data: &[u8]) {
    pmc_dem::fuzz::parse_geotiff(data);
    pmc_dem::fuzz::parse_geotiff_source(data);
}

/// 16-bit PNG.
pub fn dem_png(data: &[u8]) {
    pmc_dem::fuzz::parse_png(data);
}

/// `.pmcdem`: opened, sampled anywhere and verified tile by tile.
pub fn pmcdem(data: &[u8]) {
    pmc_dem::fuzz::parse_pmcdem(data);
}

/// A file of this process for inputs that readers take as files.
fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("pmc-fuzz-{}-{name}", std::process::id()))
}

/// A world file: opened as `pmc serve --world` does; an opened world answers its reads (the
/// planet, the edits, an integrity check) with values or errors.
pub fn world_file(data: &[u8]) {
    let path = scratch("world.pmcw");
    for suffix in ["-wal", "-shm", "-journal"] {
        let _ = std::fs::remove_file(format!("{}{suffix}", path.display()));
    }
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok(world) = pmc_world::World::open(&path) {
        let _ = world.planet_params();
        let _ = world.format_version();
        let _ = world.entries();
        let _ = world.active_edits();
        let _ = world.edit_count();
        let _ = world.redo_count();
        let _ = world.integrity_check();
        let _ = world.close();
    }
}

/// The server of the HTTP target: a small planet (2 x 2 chunks per face side, 8 tiles each)
/// with a world, on a runtime of one thread.
struct Server {
    runtime: tokio::runtime::Runtime,
    app: axum::Router,
}

fn server() -> &'static Server {
    static SERVER: OnceLock<Server> = OnceLock::new();
    SERVER.get_or_init(|| {
        let world = scratch("http.pmcw");
        let _ = std::fs::remove_file(&world);
        let config = ServerConfig {
            port: 0,
            terrain: TerrainSpec::preset(PresetKind::Earthlike, 3),
            layout: Layout::new(2, 8, 100.0, 2.0, 2).expect("the small layout"),
            threads: 1,
            world: Some(world),
            ..ServerConfig::default()
        };
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_time()
            .build()
            .expect("a runtime");
        let app = runtime.block_on(async { router(AppState::new(config).expect("the server's state")) });
        Server { runtime, app }
    })
}

/// The endpoints the HTTP target sends to: the first byte of an input picks one; the rest, up to
/// its first newline, is appended to the path (a query string, or a chunk's path), and what
/// follows the newline is the body.
const ENDPOINTS: [(Method, &str); 11] = [
    (Method::GET, "/api/v1/chunks?"),
    (Method::GET, "/api/v1/chunk/"),
    (Method::GET, "/api/v1/planet?"),
    (Method::GET, "/api/v1/path?"),
    (Method::GET, "/api/v1/navgrid?"),
    (Method::POST, "/api/v1/edits?"),
    (Method::POST, "/api/v1/edits/undo?"),
    (Method::POST, "/api/v1/edits/redo?"),
    (Method::GET, "/api/v1/edits?"),
    (Method::GET, "/api/v1/stats?"),
    (Method::POST, "/api/v1/chunk-batch?"),
];

/// One request to the server's router: any answer but a server error (500) is fine; a 503 is a
/// busy server, also fine.
pub fn http_request(data: &[u8]) {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let (method, prefix) = &ENDPOINTS[usize::from(pick) % ENDPOINTS.len()];
    let (tail, body) = match rest.iter().position(|&b| b == b'\n') {
        Some(n) => (&rest[..n], &rest[n + 1..]),
        None => (rest, &[][..]),
    };
    let uri = format!("{prefix}{}", String::from_utf8_lossy(tail));
    let Ok(request) = Request::builder()
        .method(method.clone())
        .uri(&uri)
        .header("content-type", "application/json")
        .body(Body::from(body.to_vec()))
    else {
        // not a URI: the HTTP layer refuses it before the server sees it
        return;
    };
    let s = server();
    let (status, body) = s.runtime.block_on(async {
        let response = s.app.clone().oneshot(request).await.expect("the router answers");
        let status = response.status();
        let body = axum::body::to_bytes(response.into_body(), 1 << 26)
            .await
            .expect("the body is read");
        (status, body)
    });
    assert!(
        status != StatusCode::INTERNAL_SERVER_ERROR,
        "{method} {uri}: 500 for a request from outside"
    );
    if prefix.starts_with("/api/v1/chunk-batch") && status == StatusCode::OK {
        batch_records_are_no_server_errors(&body, &uri);
    }
}

/// A chunk batch's answer (`docs/specs/http-api-v1.md`) is whole, with one record a chunk and
/// none of them a server error (500).
fn batch_records_are_no_server_errors(body: &[u8], uri: &str) {
    assert!(body.len() >= 10 && &body[..4] == b"PMCB", "{uri}: not a batch answer");
    let count = u32::from_le_bytes(body[6..10].try_into().expect("four bytes")) as usize;
    let (mut at, mut records) = (10, 0);
    while at < body.len() {
        let len = u32::from_le_bytes(body[at..at + 4].try_into().expect("four bytes")) as usize;
        let status = u16::from_le_bytes([body[at + 6], body[at + 7]]);
        assert!(status != 500, "{uri}: a record with status 500: {}", String::from_utf8_lossy(&body[at + 8..at + 4 + len]));
        at += 4 + len;
        records += 1;
    }
    assert_eq!((at, records), (body.len(), count), "{uri}: records");
}
