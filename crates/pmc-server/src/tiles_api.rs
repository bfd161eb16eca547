//! OGC 3D Tiles 1.1 of the served planet, live (`docs/specs/tiles-v1.md`):
//!
//! - `GET /tiles/tileset.json`: the tileset of the planet as it is now (with a world, its
//!   edits). Its subtree and content URLs carry the planet's edit revision, `r<N>/`, so a client
//!   that fetches the tileset again after an edit asks for new URLs and no cache serves it the
//!   old terrain.
//! - `GET /tiles/r<N>/subtrees/FACE/LEVEL/X/Y/Z.json`: a subtree file (an external tileset of
//!   three levels of tiles).
//! - `GET /tiles/r<N>/content/FACE/LEVEL/X/Y/Z.glb`: a tile's glTF content.
//! - `GET /tiles/wgs84/...` and `GET /tiles/sphere/...`: the same, placed in the frame the path
//!   names whatever the server's `--tiles-frame` (a client drawing the planet as its sphere, as
//!   PMC's viewer does, asks for `sphere`).
//!
//! A subtree file is made from the tiles' availability alone (`pmc_tiles::TileSet::subtree_file`:
//! nothing meshed), a content when a client asks for it (`pmc_tiles::TileSet::content`); both are
//! kept in a cache bounded by bytes (a quarter of the chunk cache's), and requests for one being
//! made wait for that one. The work goes through the chunk generator's queue and workers
//! ([`crate::generator::Generator::task`]), beside the chunks of `/api/v1/chunk`: it counts in
//! `/api/v1/stats`, and a request that goes away before its work starts withdraws it. An old revision's URLs are answered from the planet as it is
//! now: the revision names a version for caches, it is not kept.

use crate::chunk_cache::ByteCache;
use crate::request::ApiError;
use crate::AppState;
use axum::body::Bytes;
use axum::extract::rejection::PathRejection;
use axum::extract::{Path, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use pmc_geometry::Face;
use pmc_tiles::{FrameChoice, TileCoord, TileOptions, TileSet};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use tokio::sync::watch;

/// A file made: the frame, the planet's revision (for a content, the revision of the last edit
/// that changed its chunk), whether it is a content (else a subtree file), the tile.
type Key = (Frame, u64, bool, TileCoord);

/// The frame a URL asks for: the server's (`/tiles/...`) or one named (`/tiles/sphere/...`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Frame {
    /// The server's `--tiles-frame`.
    Served,
    /// On the WGS84 ellipsoid.
    Wgs84,
    /// On the planet's sphere.
    Sphere,
}

impl Frame {
    fn named(name: &str) -> Result<Frame, ApiError> {
        match name {
            "wgs84" => Ok(Frame::Wgs84),
            "sphere" => Ok(Frame::Sphere),
            other => Err(ApiError::not_found(format!(
                "/tiles/{other}/: a frame is `wgs84` or `sphere`"
            ))),
        }
    }

    fn choice(self, served: FrameChoice) -> FrameChoice {
        match self {
            Frame::Served => served,
            Frame::Wgs84 => FrameChoice::Wgs84,
            Frame::Sphere => FrameChoice::Sphere,
        }
    }
}
/// The file's bytes, or `None` for a tile with no content.
type Built = Result<Option<Bytes>, Arc<str>>;

/// The tiles of the served planet.
pub(crate) struct ServedTiles {
    frame: FrameChoice,
    cache: Mutex<ByteCache<Key, Option<Bytes>>>,
    building: Mutex<HashMap<Key, watch::Receiver<Option<Built>>>>,
    /// For each frame asked for, the tileset of the latest revision asked for.
    tilesets: Mutex<HashMap<Frame, (u64, Arc<TileSet>)>>,
}

impl ServedTiles {
    /// Tiles placed in `frame`, with `cache_bytes` of files made.
    pub(crate) fn new(frame: FrameChoice, cache_bytes: u64) -> ServedTiles {
        ServedTiles {
            frame,
            cache: Mutex::new(ByteCache::new(cache_bytes)),
            building: Mutex::new(HashMap::new()),
            tilesets: Mutex::new(HashMap::new()),
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The tileset of the served planet in `frame` at its current revision (made once per revision).
async fn tileset(state: &AppState, frame: Frame) -> Result<(u64, Arc<TileSet>), ApiError> {
    let tiles = state.tiles();
    let id = Arc::new(state.config().terrain.clone());
    let (planet, revision) = state.planet(id).await.map_err(ApiError::internal)?;
    if let Some((r, t)) = lock(&tiles.tilesets).get(&frame) {
        if *r == revision {
            return Ok((*r, t.clone()));
        }
    }
    let errors = state.lod_errors_of_default().await.map_err(ApiError::internal)?;
    let choice = frame.choice(tiles.frame);
    let frame_of_planet = choice.frame(planet.datum_radius());
    let generator = format!("pmc {}", env!("CARGO_PKG_VERSION"));
    let set = TileSet::new(
        planet,
        (*errors).clone(),
        frame_of_planet,
        TileOptions::default(),
        &generator,
    )
    .map_err(|e| ApiError::not_found(format!("this planet has no 3D Tiles: {e}")))?;
    let set = Arc::new(set);
    lock(&tiles.tilesets).insert(frame, (revision, set.clone()));
    Ok((revision, set))
}

fn respond(bytes: Bytes, content_type: &'static str, cache: &'static str) -> Response {
    let mut r = bytes.into_response();
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static(cache));
    // Public, read-only data: a page of any origin may load it (a CesiumJS app elsewhere).
    h.insert(header::ACCESS_CONTROL_ALLOW_ORIGIN, HeaderValue::from_static("*"));
    r
}

/// `GET /tiles/tileset.json`.
pub async fn tileset_json(State(state): State<AppState>) -> Result<Response, ApiError> {
    tileset_json_in(&state, Frame::Served).await
}

/// `GET /tiles/{frame}/tileset.json`.
pub async fn tileset_json_framed(
    State(state): State<AppState>,
    path: Result<Path<String>, PathRejection>,
) -> Result<Response, ApiError> {
    let Path(frame) = path.map_err(|e| ApiError::bad_request(format!("malformed tileset path: {e}")))?;
    tileset_json_in(&state, Frame::named(&frame)?).await
}

async fn tileset_json_in(state: &AppState, frame: Frame) -> Result<Response, ApiError> {
    let (revision, set) = tileset(state, frame).await?;
    let edits = state.editing().map(|e| e.current().active);
    let extras = pmc_tiles::planet_extras(set.planet(), edits);
    let mut extras = extras;
    extras["revision"] = serde_json::json!(revision);
    let json = set.tileset_json(&format!("r{revision}/"), extras);
    let body = serde_json::to_vec(&json).map_err(|e| ApiError::internal(e.to_string()))?;
    Ok(respond(Bytes::from(body), "application/json", "no-cache"))
}

/// The parts of a tile path: revision, kind, face, level, x, y, and the last part `Z.EXT`.
type TilePath = (String, String, String, String, String, String, String);
/// A frame's name, then the parts of a tile path.
type FramedTilePath = (String, String, String, String, String, String, String, String);

/// The tile named by a path, checked against the tileset: 400 when malformed, 404 when not one
/// of its tiles.
fn parse(set: &TileSet, p: &TilePath, ext: &str) -> Result<(u64, TileCoord), ApiError> {
    let (rev, _, face, level, x, y, last) = p;
    let shown = format!("{face}/{level}/{x}/{y}/{last}");
    let revision = rev
        .strip_prefix('r')
        .and_then(|r| r.parse::<u64>().ok())
        .ok_or_else(|| ApiError::bad_request(format!("'{rev}' is not a revision (r followed by a number)")))?;
    let z = last
        .strip_suffix(ext)
        .ok_or_else(|| ApiError::not_found(format!("{shown}: expected a name ending in {ext}")))?;
    let face: Face = face.parse().map_err(ApiError::bad_request)?;
    let num = |name: &str, s: &str| {
        s.parse::<u32>()
            .map_err(|_| ApiError::bad_request(format!("tile {name} must be a non-negative integer, got '{s}'")))
    };
    let level = num("level", level)?;
    let t = TileCoord {
        face,
        level: u8::try_from(level).unwrap_or(u8::MAX),
        x: num("x", x)?,
        y: num("y", y)?,
        z: num("z", z)?,
    };
    if level >= u32::from(set.available_levels()) || !set.tiling().exists(&t) {
        return Err(ApiError::not_found(format!("{shown} is not a tile of this planet")));
    }
    Ok((revision, t))
}

/// The subtree file rooted at `t` (`content` false) or the content of tile `t`, from the cache,
/// from the one being made, or made now.
async fn made(state: &AppState, set: Arc<TileSet>, key: Key) -> Result<Option<Bytes>, ApiError> {
    let tiles = state.tiles();
    let (_, _, content, t) = key;
    if let Some(b) = lock(&tiles.cache).get(&key) {
        return Ok(b.clone());
    }
    // Join the work under way, or start it.
    let (mut rx, tx) = {
        let mut building = lock(&tiles.building);
        match building.get(&key) {
            Some(rx) => (rx.clone(), None),
            None => {
                let (tx, rx) = watch::channel(None);
                building.insert(key, rx.clone());
                (rx, Some(tx))
            }
        }
    };
    if let Some(tx) = tx {
        // This request does the work, queued with the chunks. Leaving before a worker starts it
        // withdraws it, and un-lists it so that the next request starts it again.
        let started = Arc::new(AtomicBool::new(false));
        struct Unlist<'a>(&'a ServedTiles, Key, Arc<AtomicBool>);
        impl Drop for Unlist<'_> {
            fn drop(&mut self) {
                if !self.2.load(Ordering::SeqCst) {
                    lock(&self.0.building).remove(&self.1);
                }
            }
        }
        let _unlist = Unlist(tiles, key, started.clone());
        let st = state.clone();
        let task = move || {
            started.store(true, Ordering::SeqCst);
            let made = if content {
                set.content(&t).map(|c| c.map(Bytes::from))
            } else {
                set.subtree_file(t).map(|b| Some(Bytes::from(b.subtree)))
            };
            let built: Built = made.map_err(|e| Arc::from(e.to_string()));
            let tiles = st.tiles();
            if let Ok(b) = &built {
                let size = 64 + b.as_ref().map_or(0, |b| b.len());
                lock(&tiles.cache).insert(key, b.clone(), size as u64);
            }
            lock(&tiles.building).remove(&key);
            let _ = tx.send(Some(built));
        };
        // (coarser tiles first: a client shows them before their children)
        let priority = -f64::from(t.level);
        if let Err(e) = state.generator().task(priority, task).await {
            // The task failed without listing its end (a bug): un-list it, so that the requests
            // waiting for it ask again.
            let mut building = lock(&tiles.building);
            if building.get(&key).is_some_and(|r| r.same_channel(&rx)) {
                building.remove(&key);
            }
            let why = match e {
                crate::generator::ChunkError::Failed(m) => m.to_string(),
                other => format!("{other:?}"),
            };
            return Err(ApiError::internal(format!("making the tile failed: {why}")));
        }
        // (the task sent its file to every receiver, this request's too)
        let built = rx
            .borrow()
            .clone()
            .unwrap_or_else(|| Err(Arc::from("the tile's task ended without a file")));
        return built.map_err(|e| ApiError::internal(e.to_string()));
    }
    loop {
        if let Some(b) = rx.borrow_and_update().clone() {
            return b.map_err(|e| ApiError::internal(e.to_string()));
        }
        if rx.changed().await.is_err() {
            // The one doing it went away before starting: ask again.
            return Box::pin(made(state, set, key)).await;
        }
    }
}

/// `GET /tiles/{rev}/subtrees/{face}/{level}/{x}/{y}/{z}.json` and
/// `GET /tiles/{rev}/content/{face}/{level}/{x}/{y}/{z}.glb`.
pub async fn tile_file(
    State(state): State<AppState>,
    path: Result<Path<TilePath>, PathRejection>,
) -> Result<Response, ApiError> {
    let Path(p) = path.map_err(|e| ApiError::bad_request(format!("malformed tile path: {e}")))?;
    tile_file_in(&state, Frame::Served, p).await
}

/// `GET /tiles/{frame}/{rev}/subtrees/...` and `GET /tiles/{frame}/{rev}/content/...`.
pub async fn tile_file_framed(
    State(state): State<AppState>,
    path: Result<Path<FramedTilePath>, PathRejection>,
) -> Result<Response, ApiError> {
    let Path((frame, rev, kind, face, level, x, y, last)) =
        path.map_err(|e| ApiError::bad_request(format!("malformed tile path: {e}")))?;
    tile_file_in(&state, Frame::named(&frame)?, (rev, kind, face, level, x, y, last)).await
}

async fn tile_file_in(state: &AppState, frame: Frame, p: TilePath) -> Result<Response, ApiError> {
    match p.1.as_str() {
        "subtrees" => subtree_file(state, frame, p).await,
        "content" => content_file(state, frame, p).await,
        other => Err(ApiError::not_found(format!(
            "/tiles/{}/{other}/...: tiles have `subtrees` and `content`",
            p.0
        ))),
    }
}

async fn subtree_file(state: &AppState, frame: Frame, p: TilePath) -> Result<Response, ApiError> {
    let (current, set) = tileset(state, frame).await?;
    let (revision, t) = parse(&set, &p, ".json")?;
    check_revision(revision, current)?;
    if t.subtree_root() != t {
        return Err(ApiError::not_found(format!(
            "{}/{} is not the root of a subtree (subtrees start every {} levels)",
            t.face,
            t.path(),
            pmc_tiles::SUBTREE_LEVELS
        )));
    }
    let b = made(state, set, (frame, current, false, t)).await?;
    let b = b.ok_or_else(|| ApiError::internal("a subtree file is always made"))?;
    Ok(respond(b, "application/json", "public, max-age=3600"))
}

async fn content_file(state: &AppState, frame: Frame, p: TilePath) -> Result<Response, ApiError> {
    let (mut current, mut set) = tileset(state, frame).await?;
    let (revision, t) = parse(&set, &p, ".glb")?;
    check_revision(revision, current)?;
    // A content is its chunk's closed mesh: the same bytes from the revision of the last edit
    // that changed the chunk on. Kept under that revision, so that after an edit the tiles it
    // did not touch are served from the cache under their new URLs.
    let planet = Arc::new(state.config().terrain.clone());
    let changed = |set: &TileSet| {
        set.tiling()
            .key(&t)
            .map_or(0, |key| state.generator().changed_revision(&planet, key))
    };
    let mut version = changed(&set);
    if version > current {
        // an edit landed since the tileset was taken: take the planet with it
        (current, set) = tileset(state, frame).await?;
        version = changed(&set);
    }
    match made(state, set, (frame, version.min(current), true, t)).await? {
        Some(glb) => Ok(respond(glb, "model/gltf-binary", "public, max-age=3600")),
        None => Err(ApiError::not_found(format!(
            "tile {}/{} has no content (its subtree file says so)",
            t.face,
            t.path()
        ))),
    }
}

/// A revision later than the planet's is not one it had.
fn check_revision(asked: u64, current: u64) -> Result<(), ApiError> {
    if asked > current {
        return Err(ApiError {
            status: StatusCode::NOT_FOUND,
            message: format!("revision {asked} is later than the planet's ({current})"),
        });
    }
    Ok(())
}
