//! Imagery draped on the default planet: the `imagery` field of `/api/v1/planet` and the image
//! at `/api/v1/imagery` (docs/specs/http-api-v1.md).

use crate::common::{app, get, send, small_config};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use pmc_imagery::{Extent, Imagery};
use pmc_server::{AppState, ServerConfig, ServerError};
use std::path::PathBuf;

/// A 16 x 8 global image whose pixel `(c, r)` is `(16c, 32r, c + r)`, written to a fresh
/// directory.
fn imagery_file(test: &str) -> (PathBuf, Imagery) {
    let dir = std::env::temp_dir().join(format!("pmc-server-imagery-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut px = Vec::new();
    for r in 0..8u8 {
        for c in 0..16u8 {
            px.extend([c * 16, r * 32, c + r]);
        }
    }
    let img = Imagery::new(16, 8, Extent::GLOBAL, px).unwrap();
    let path = dir.join("earth.pmcimg");
    img.write(&path).unwrap();
    (path, img)
}

fn config_with(path: &std::path::Path) -> ServerConfig {
    ServerConfig {
        imagery: Some(path.to_owned()),
        ..small_config()
    }
}

fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

#[tokio::test]
async fn without_imagery_the_field_is_null_and_the_image_404() {
    let a = app(small_config());
    let v = get(&a, "/api/v1/planet").await.json();
    assert!(v["imagery"].is_null(), "{}", v["imagery"]);
    let r = get(&a, "/api/v1/imagery").await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert_eq!(r.header("content-type"), Some("application/json"));
    assert!(r.json()["error"].as_str().unwrap().contains("--imagery"));
}

#[tokio::test]
async fn the_planet_describes_its_imagery() {
    let (path, img) = imagery_file("planet");
    let a = app(config_with(&path));
    let v = get(&a, "/api/v1/planet").await.json();
    assert_eq!(
        v["imagery"],
        serde_json::json!({
            "url": "/api/v1/imagery",
            "extent": [-180.0, 180.0, -90.0, 90.0],
            "width": 16,
            "height": 8,
            "digest": img.digest(),
            "wraps": true,
            "color_space": "srgb",
        })
    );
    // Another planet asked for by name has no imagery.
    let v = get(&a, "/api/v1/planet?preset=mars").await.json();
    assert!(v["imagery"].is_null());
    let v = get(&a, "/api/v1/planet?preset=earthlike&seed=3").await.json();
    assert_eq!(
        v["imagery"]["digest"],
        img.digest(),
        "the default planet named explicitly"
    );
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

#[tokio::test]
async fn the_image_is_a_png_with_its_digest_as_etag() {
    let (path, img) = imagery_file("png");
    let a = app(config_with(&path));
    let r = get(&a, "/api/v1/imagery").await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.header("content-type"), Some("image/png"));
    let etag = format!("\"{}\"", img.digest());
    assert_eq!(r.header("etag"), Some(etag.as_str()));
    assert_eq!(r.header("cache-control"), Some("no-cache"));
    assert_eq!(decode_png(&r.body), (16, 8, img.pixels().to_vec()));

    // Revalidation: the same tag answers 304 without a body; another tag gets the image.
    let req = |tag: &str| {
        Request::get("/api/v1/imagery")
            .header("if-none-match", tag)
            .body(Body::empty())
            .unwrap()
    };
    let r = send(&a, req(&etag)).await;
    assert_eq!(r.status, StatusCode::NOT_MODIFIED);
    assert!(r.body.is_empty());
    assert_eq!(r.header("etag"), Some(etag.as_str()));
    let r = send(&a, req("\"something-else\"")).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(decode_png(&r.body).2, img.pixels());

    // Compression leaves the PNG alone.
    let r = send(
        &a,
        Request::get("/api/v1/imagery")
            .header("accept-encoding", "gzip")
            .body(Body::empty())
            .unwrap(),
    )
    .await;
    assert_eq!(r.header("content-encoding"), None);
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

#[tokio::test]
async fn smaller_levels_are_halvings_with_their_own_tags() {
    let (path, img) = imagery_file("levels");
    let a = app(config_with(&path));
    for (max, size) in [(16, (16, 8)), (100, (16, 8)), (8, (8, 4)), (5, (4, 2)), (1, (1, 1))] {
        let r = get(&a, &format!("/api/v1/imagery?max={max}")).await;
        assert_eq!(r.status, StatusCode::OK, "max={max}");
        let (w, h, px) = decode_png(&r.body);
        assert_eq!((w, h), size, "max={max}");
        let level = img.downsampled(max);
        assert_eq!(px, level.pixels(), "max={max}");
        let tag = if size == (16, 8) {
            format!("\"{}\"", img.digest())
        } else {
            format!("\"{}-{}x{}\"", img.digest(), size.0, size.1)
        };
        assert_eq!(r.header("etag"), Some(tag.as_str()), "max={max}");
    }
    // Asked twice: the same bytes (kept).
    let a1 = get(&a, "/api/v1/imagery?max=8").await.body;
    let a2 = get(&a, "/api/v1/imagery?max=8").await.body;
    assert_eq!(a1, a2);
    for bad in ["0", "-1", "abc", "1.5", "99999999999"] {
        let r = get(&a, &format!("/api/v1/imagery?max={bad}")).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "max={bad}");
        assert!(r.json()["error"].as_str().unwrap().contains("max"));
    }
    let r = send(&a, Request::post("/api/v1/imagery").body(Body::empty()).unwrap()).await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

#[tokio::test]
async fn a_damaged_or_missing_imagery_file_stops_the_start() {
    let (path, _) = imagery_file("damaged");
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&path, &bytes).unwrap();
    let e = AppState::new(config_with(&path)).unwrap_err();
    assert!(matches!(e, ServerError::Imagery(_)), "{e}");
    let text = e.to_string();
    assert!(text.contains("earth.pmcimg") && text.contains("damaged"), "{text}");
    let missing = path.with_file_name("missing.pmcimg");
    let e = AppState::new(config_with(&missing)).unwrap_err();
    assert!(e.to_string().contains("missing.pmcimg"), "{e}");
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}
