//! The `/api/v1` endpoints (`docs/specs/http-api-v1.md`).

use crate::generator::{ChunkError, ChunkId, PlanetId};
pub use crate::request::ApiError;
use crate::request::Params;
use crate::AppState;
use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::{header, HeaderValue, StatusCode, Uri};
use axum::response::{IntoResponse, Response};
use axum::Json;
use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face, SideMask};
use pmc_lod::bounds::{chunks_near, TooManyChunks};
use pmc_planet::{PresetKind, TerrainSpec};
use serde_json::{json, Value};

/// Default and largest `limit` of `/chunks`.
pub const DEFAULT_LIMIT: usize = 512;
/// Largest `limit` of `/chunks`.
pub const MAX_LIMIT: usize = 4096;
/// Most chunks one `/chunks` query may test (after the quadtree has skipped the far ones).
pub const MAX_TESTED_CHUNKS: usize = 200_000;

/// A JSON answer that browsers revalidate.
fn json_response(v: Value, cache: &'static str) -> Response {
    let mut r = Json(v).into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static(cache));
    r
}

async fn planet_of(state: &AppState, id: PlanetId) -> Result<std::sync::Arc<pmc_planet::Planet>, ApiError> {
    state.planet(id).await.map(|(p, _)| p).map_err(ApiError::internal)
}

/// `GET /api/v1/health`.
pub async fn health() -> Response {
    json_response(json!({ "ok": true, "version": env!("CARGO_PKG_VERSION") }), "no-store")
}

/// `GET /api/v1/planet`.
pub async fn planet(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let params = Params::parse(q);
    let id = params.planet(&state)?;
    let planet = planet_of(&state, id.clone()).await?;
    let errors = state.lod_errors(id.clone(), planet.clone()).await;
    let l = planet.layout();
    let t = planet.terrain();
    let lod = json!({
        "max_level": l.max_level(),
        "errors": errors.as_slice(),
        "occluder_radius": pmc_lod::occluder_radius(&planet),
        "seam_sides": ["u_min", "u_max", "v_min", "v_max", "inner", "outer"],
    });
    let faces: Vec<Value> = Face::ALL
        .iter()
        .map(|f| {
            let fr = f.frame();
            json!({
                "name": f.name(),
                "index": f.index(),
                "normal": fr.n.to_array(),
                "u": fr.u.to_array(),
                "v": fr.v.to_array(),
            })
        })
        .collect();
    let presets: Vec<Value> = PresetKind::ALL
        .iter()
        .map(|p| json!({ "name": p.name(), "description": p.description() }))
        .collect();
    let v = json!({
        "format": "pmc-planet",
        "version": 1,
        "preset": t.spec.preset_kind().map(|k| k.name()),
        "terrain": terrain_json(&t.spec),
        "seed": t.spec.seed().to_string(),
        "presets": presets,
        "layout": { "n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c() },
        "radius": l.radius(),
        "lod": lod,
        "base_radius": l.d_b(),
        "sea_radius": t.sea_radius,
        "surface_bounds": t.density.radial_bounds().map(|(a, b)| [a, b]),
        "chunk_count": l.chunk_count(),
        "face_tiles": l.face_tiles(),
        "depth_tiles": l.depth_tiles(),
        "max_level": l.max_level(),
        "faces": faces,
        "materials": t.materials,
        "palette": { "a": t.blend_colors[0], "b": t.blend_colors[1] },
        "imagery": crate::imagery_api::planet_field(&state, *id == state.config().terrain),
        "relief": crate::relief_api::planet_field(&state, &t.spec, &planet, *id == state.config().terrain),
        "edit": crate::edit_api::edit_info(&state, id),
    });
    Ok(json_response(v, "no-cache"))
}

/// `GET /api/v1/chunks?x=&y=&z=&range=&limit=&level=`.
pub async fn chunks(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let params = Params::parse(q);
    let id = params.planet(&state)?;
    let p = DVec3::new(params.finite("x")?, params.finite("y")?, params.finite("z")?);
    let range = params.range("range")?;
    let limit = params.limit(DEFAULT_LIMIT, MAX_LIMIT)?;
    let max_level = state.config().layout.max_level();
    let level = match params.get("level") {
        None => 0,
        Some(s) => match s.trim().parse::<u8>() {
            Ok(n) if n <= max_level => n,
            _ => {
                return Err(ApiError::bad_request(format!(
                    "level must be an integer from 0 to {max_level} (this layout's max level), got '{s}'"
                )))
            }
        },
    };
    let planet = planet_of(&state, id).await?;
    let found = tokio::task::spawn_blocking(move || chunks_near(&planet, level, p, range, limit, MAX_TESTED_CHUNKS))
        .await
        .map_err(|e| ApiError::internal(format!("the chunk search failed: {e}")))?;
    let (hits, total) = found.map_err(|TooManyChunks { budget }| {
        ApiError::bad_request(format!(
            "range {range} m is too large for this planet: more than {budget} chunks of level {level} lie within range \
             of the point; lower range or ask for a coarser level"
        ))
    })?;
    let chunks: Vec<Value> = hits
        .iter()
        .map(|h| {
            let k = h.key;
            json!({
                "key": k.to_string(),
                "face": k.face.name(),
                "level": k.level,
                "i": k.i,
                "j": k.j,
                "k": k.k,
                "center": h.sphere.center.to_array(),
                "radius": h.sphere.radius,
                "distance": h.distance,
            })
        })
        .collect();
    Ok(json_response(
        json!({ "chunks": chunks, "total_in_range": total }),
        "no-cache",
    ))
}

/// Parses one numeric part of a chunk path.
fn index_part(name: &str, s: &str) -> Result<u64, ApiError> {
    s.parse::<u64>()
        .map_err(|_| ApiError::bad_request(format!("chunk {name} must be a non-negative integer, got '{s}'")))
}

/// The five parts of a chunk path, as text: face, level, i, j, k.
type ChunkPath = (String, String, String, String, String);

/// `GET /api/v1/chunk/{face}/{level}/{i}/{j}/{k}?seams=&priority=`.
///
/// A client that hangs up before the answer withdraws its request: the chunk's job, when no
/// other request waits for it and no worker has started it, is dropped without being generated.
pub async fn chunk(
    State(state): State<AppState>,
    RawQuery(q): RawQuery,
    path: Result<Path<ChunkPath>, PathRejection>,
) -> Result<Response, ApiError> {
    let Path((face, level, i, j, k)) = path.map_err(|e| ApiError::bad_request(format!("malformed chunk path: {e}")))?;
    let params = Params::parse(q);
    let id = params.planet(&state)?;
    let priority = params.priority()?;
    let layout = state.config().layout;
    let key = chunk_key(&layout, &face, &level, &i, &j, &k)?;
    let seams = SideMask(params.seams()? & layout.seam_sides(&key).0);
    match state.chunk(ChunkId { planet: id, key, seams }, priority).await {
        Ok(bytes) => {
            let mut r = bytes.into_response();
            let h = r.headers_mut();
            h.insert(
                header::CONTENT_TYPE,
                HeaderValue::from_static("application/octet-stream"),
            );
            h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
            Ok(r)
        }
        Err(e) => Err(chunk_error(e)),
    }
}

/// The chunk named by the five parts of a chunk path (`face/level/i/j/k`): 400 when a part is
/// malformed, 404 when it is not a chunk of `layout`.
pub(crate) fn chunk_key(
    layout: &pmc_geometry::Layout,
    face: &str,
    level: &str,
    i: &str,
    j: &str,
    k: &str,
) -> Result<ChunkKey, ApiError> {
    let face: Face = face.parse().map_err(ApiError::bad_request)?;
    let (level, i, j, k) = (
        index_part("level", level)?,
        index_part("i", i)?,
        index_part("j", j)?,
        index_part("k", k)?,
    );
    layout
        .chunk_key(face, level, i, j, k)
        .map_err(|e| ApiError::not_found(e.0))
}

/// The answer to a chunk the generator could not serve.
pub(crate) fn chunk_error(e: ChunkError) -> ApiError {
    match e {
        ChunkError::Busy => ApiError {
            status: StatusCode::SERVICE_UNAVAILABLE,
            message: "the server is busy generating chunks; retry in a second".into(),
        },
        ChunkError::Failed(e) => ApiError::internal(e.to_string()),
        ChunkError::Stale => ApiError::internal("the chunk's planet changed while it was requested"),
    }
}

/// `GET /api/v1/stats`.
pub async fn stats(State(state): State<AppState>) -> Response {
    json_response(json!(state.stats()), "no-store")
}

/// Any other path under `/api`.
pub async fn not_found(uri: Uri) -> ApiError {
    ApiError::not_found(format!(
        "no such API endpoint: {}; see docs/specs/http-api-v1.md (GET /api/v1/health, /planet, /chunks, \
         /chunk/FACE/LEVEL/I/J/K, /stats, /imagery, /relief, /edits, /events, /path, /navgrid; POST /api/v1/edits, /edits/undo, \
         /edits/redo)",
        uri.path()
    ))
}

/// A method an API path does not take.
pub async fn method_not_allowed(uri: Uri) -> ApiError {
    let post = ["/api/v1/edits", "/api/v1/edits/undo", "/api/v1/edits/redo"];
    let allowed = match uri.path() {
        "/api/v1/edits" => "GET and POST",
        p if post.contains(&p) => "POST",
        _ => "GET",
    };
    ApiError {
        status: StatusCode::METHOD_NOT_ALLOWED,
        message: format!("{} takes {allowed} only", uri.path()),
    }
}

/// A terrain in the planet description: its kind, name and, for an elevation model, its file.
fn terrain_json(spec: &TerrainSpec) -> Value {
    match spec {
        TerrainSpec::Preset { kind, seed } => json!({
            "kind": "preset",
            "name": kind.name(),
            "seed": seed.to_string(),
        }),
        TerrainSpec::Dem(d) => json!({
            "kind": "dem",
            "name": spec.name(),
            "file": d.path.rsplit(['/', '\\']).next().unwrap_or(&d.path),
            "digest": d.digest,
            "interpolation": d.interpolation.name(),
            "seed": d.seed.to_string(),
        }),
    }
}
