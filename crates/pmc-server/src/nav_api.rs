//! The navigation endpoints of `docs/specs/http-api-v1.md`: `GET /api/v1/path` (a walking path
//! between two places, `docs/specs/path-v1.md`) and `GET /api/v1/navgrid` (the grid's nodes and
//! steps near a point, with their components, for drawing).

use crate::request::{ApiError, Params};
use crate::AppState;
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};
use axum::Json;
use pmc_geometry::glam::DVec3;
use pmc_geometry::Place;
use pmc_nav::{
    lazy_path_geojson, lazy_path_json, path_geojson, path_json, query, wants_lazy_grid, Agent, End, LazyGrid,
    LazyOptions, NodeId, SearchOptions,
};
use serde_json::{json, Value};

/// Columns searched around each end of a path for walkable ground.
pub const SNAP_RINGS: usize = 8;
/// Default `limit` of `/navgrid`.
pub const DEFAULT_NAV_LIMIT: usize = 20_000;
/// Largest `limit` of `/navgrid`.
pub const MAX_NAV_LIMIT: usize = 100_000;

fn no_store(v: Value) -> Response {
    let mut r = Json(v).into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

/// The agent the query names: `clearance`, `step_up`, `step_down`, `max_slope`, each optional.
fn agent(params: &Params) -> Result<Agent, ApiError> {
    let d = Agent::default();
    let mut a = d;
    for (name, slot) in [
        ("clearance", &mut a.clearance),
        ("step_up", &mut a.step_up),
        ("step_down", &mut a.step_down),
        ("max_slope", &mut a.max_slope),
    ] {
        if params.get(name).is_some() {
            *slot = params.finite(name)?;
        }
    }
    a.validate().map_err(|e| ApiError::bad_request(e.to_string()))?;
    Ok(a)
}

/// Parses `LAT,LON[,ALT]` of parameter `name` into a path end.
fn end(params: &Params, name: &str, datum: f64) -> Result<End, ApiError> {
    let raw = params
        .get(name)
        .ok_or_else(|| ApiError::bad_request(format!("missing query parameter '{name}' (LAT,LON or LAT,LON,ALT)")))?;
    let place = raw.parse::<Place>().map_err(|e| {
        ApiError::bad_request(format!(
            "{name}={raw}: {e}; give LAT,LON or LAT,LON,ALT (degrees, metres)"
        ))
    })?;
    Ok(End {
        dir: place.lat_lon().to_unit(),
        radius: place.alt().map(|alt| datum + alt),
    })
}

/// `GET /api/v1/path?from=LAT,LON[,ALT]&to=LAT,LON[,ALT]&format=json|geojson`.
pub async fn path(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let params = Params::parse(q);
    let id = params.planet(&state)?;
    let agent = agent(&params)?;
    let geojson = match params.get("format") {
        None | Some("json") => false,
        Some("geojson") => true,
        Some(other) => {
            return Err(ApiError::bad_request(format!(
                "format must be json or geojson, got '{other}'"
            )))
        }
    };
    // Checked before any grid is built.
    let (current, revision) = state.planet(id.clone()).await.map_err(ApiError::internal)?;
    let datum_probe = current.datum_radius();
    let (from, to) = (end(&params, "from", datum_probe)?, end(&params, "to", datum_probe)?);
    if wants_lazy_grid(current.layout()) {
        // A planet too large for a whole-planet grid (the Earth at true scale): a lazy grid of
        // the current (edited) planet, built tile by tile around this search within the default
        // bounds, then dropped.
        agent.validate().map_err(|e| ApiError::bad_request(e.to_string()))?;
        let doc = tokio::task::spawn_blocking(move || {
            let datum = current.datum_radius();
            let mut grid = LazyGrid::new(
                current.density().clone(),
                current.layout(),
                agent,
                LazyOptions::default(),
            )
            .map_err(|e| ApiError::bad_request(e.to_string()))?;
            let search = SearchOptions::default();
            let found = grid.query(from, to, SNAP_RINGS, &search);
            let mut doc = if geojson {
                lazy_path_geojson(&grid, &found, &search, from, to, datum)
            } else {
                lazy_path_json(&grid, &found, &search, from, to, datum)
            };
            doc["revision"] = json!(revision);
            Ok::<Value, ApiError>(doc)
        })
        .await
        .map_err(|e| ApiError::internal(format!("the path search failed: {e}")))??;
        return Ok(no_store(doc));
    }
    let (grid, planet, revision) = state.nav_grid(id, agent).await?;
    let datum = planet.datum_radius();
    let doc = tokio::task::spawn_blocking(move || {
        let answer = query(&grid, from, to, SNAP_RINGS);
        let mut doc = if geojson {
            path_geojson(&grid, &answer, from, to, datum)
        } else {
            path_json(&grid, &answer, from, to, datum)
        };
        doc["revision"] = json!(revision);
        doc
    })
    .await
    .map_err(|e| ApiError::internal(format!("the path search failed: {e}")))?;
    Ok(no_store(doc))
}

/// `GET /api/v1/navgrid?x=&y=&z=&range=&limit=`: nodes near a point with their components, and
/// the steps between them.
pub async fn navgrid(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let params = Params::parse(q);
    let id = params.planet(&state)?;
    let agent = agent(&params)?;
    let p = DVec3::new(params.finite("x")?, params.finite("y")?, params.finite("z")?);
    let range = params.range("range")?;
    let limit = params.limit(DEFAULT_NAV_LIMIT, MAX_NAV_LIMIT)?;
    let (grid, _, revision) = state.nav_grid(id, agent).await?;
    let doc = tokio::task::spawn_blocking(move || {
        let (nodes, truncated) = grid.nodes_near(p, range, limit);
        let index: std::collections::HashMap<NodeId, usize> = nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
        let mut positions = Vec::with_capacity(nodes.len() * 3);
        let mut components = Vec::with_capacity(nodes.len());
        // Each pair joined by a step either way, once (an agent with different step limits up
        // and down has steps that go one way only).
        let mut pairs = std::collections::BTreeSet::new();
        for (i, n) in nodes.iter().enumerate() {
            let q = grid.position(*n).unwrap_or(p) - p;
            positions.extend([q.x, q.y, q.z]);
            components.push(grid.component(*n).unwrap_or(u32::MAX));
            for s in grid.steps(*n) {
                if let Some(j) = index.get(&s.to) {
                    pairs.insert((i.min(*j) as u32, i.max(*j) as u32));
                }
            }
        }
        let edges: Vec<u32> = pairs.into_iter().flat_map(|(i, j)| [i, j]).collect();
        let sizes: Vec<u32> = components
            .iter()
            .map(|c| grid.component_sizes().get(*c as usize).copied().unwrap_or(0))
            .collect();
        json!({
            "revision": revision,
            "origin": p.to_array(),
            "positions": positions,
            "components": components,
            "component_sizes": sizes,
            "edges": edges,
            "truncated": truncated,
            "total_nodes": grid.node_count(),
            "total_components": grid.component_sizes().len(),
        })
    })
    .await
    .map_err(|e| ApiError::internal(format!("the grid query failed: {e}")))?;
    Ok(no_store(doc))
}
