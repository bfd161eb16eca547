//! The editing endpoints of `docs/specs/http-api-v1.md`: `POST /api/v1/edits`, `/edits/undo`,
//! `/edits/redo`, `GET /api/v1/edits` and the server push `GET /api/v1/events`.

use crate::editing::{Action, EditEvent, Editing};
use crate::generator::PlanetId;
use crate::request::{read_body, require_json, ApiError, Params};
use crate::AppState;
use axum::extract::{ConnectInfo, RawQuery, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::Json;
use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::glam::DVec3;
use serde::Deserialize;
use serde_json::{json, Value};
use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::broadcast;

/// Largest edit request body, bytes.
pub const MAX_EDIT_BODY: usize = 16 * 1024;
/// Interval of the comment lines that keep an event stream open.
pub const KEEP_ALIVE: Duration = Duration::from_secs(15);

/// The brushes, by their API names.
const BRUSHES: [&str; 5] = ["add", "remove", "smooth", "flatten", "paint"];

/// The `edit` object of `/api/v1/planet`.
pub(crate) fn edit_info(state: &AppState, id: PlanetId) -> Value {
    let Some(editing) = state.editing() else {
        return json!({
            "enabled": false,
            "reason": "this server has no world: start it with `pmc serve --world FILE` to edit",
            "brushes": BRUSHES,
        });
    };
    if editing.id != id {
        return json!({
            "enabled": false,
            "reason": format!(
                "only the world's planet ({}, seed {}) can be edited; this one is shown unedited",
                editing.id.name(),
                editing.id.seed()
            ),
            "brushes": BRUSHES,
        });
    }
    let c = editing.current();
    let l = &editing.limits;
    json!({
        "enabled": true,
        "world": editing.path().file_name().map(|n| n.to_string_lossy().into_owned()),
        "revision": c.revision,
        "active": c.active,
        "redo": c.redo,
        "min_brush_radius": l.min_brush_radius,
        "max_brush_radius": l.max_brush_radius,
        "rate_per_second": l.rate_per_second,
        "burst": l.burst,
        "brushes": BRUSHES,
    })
}

/// The world to edit for a request on planet `id`, or why there is none.
fn editing_for(state: &AppState, query: Option<String>) -> Result<Arc<Editing>, ApiError> {
    let Some(editing) = state.editing() else {
        return Err(ApiError {
            status: StatusCode::FORBIDDEN,
            message: "editing is off: this server has no world; start it with `pmc serve --world FILE`".into(),
        });
    };
    let id = Params::parse(query).planet(state)?;
    if editing.id != id {
        return Err(ApiError {
            status: StatusCode::CONFLICT,
            message: format!(
                "only the world's planet ({}, seed {}) can be edited, not {}, seed {}",
                editing.id.name(),
                editing.id.seed(),
                id.name(),
                id.seed()
            ),
        });
    }
    Ok(Arc::clone(editing))
}

/// Takes one token of the client's rate; when it has none, the 429 answer (with `Retry-After`).
fn rate_limited(editing: &Editing, req: &Request) -> Option<Response> {
    let client = req
        .extensions()
        .get::<ConnectInfo<SocketAddr>>()
        .map(|ConnectInfo(a)| a.ip());
    editing.rate.take(client, Instant::now()).err().map(|wait| {
        let secs = wait.as_secs_f64().ceil().max(1.0) as u64;
        let l = &editing.limits;
        let mut r = ApiError {
            status: StatusCode::TOO_MANY_REQUESTS,
            message: format!(
                "too many edits: at most {} at once and {} per second from one client; retry in {secs} s",
                l.burst, l.rate_per_second
            ),
        }
        .into_response();
        r.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from(secs));
        r
    })
}

/// The body of `POST /api/v1/edits`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EditRequest {
    brush: String,
    x: f64,
    y: f64,
    z: f64,
    radius: f64,
    #[serde(default)]
    strength: Option<f64>,
    #[serde(default)]
    material: Option<MaterialRef>,
}

/// A material by index or by name.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum MaterialRef {
    Index(u64),
    Name(String),
}

/// Checks an edit request against the planet and the limits and builds its operation.
fn brush_op(req: &EditRequest, editing: &Editing) -> Result<BrushOp, ApiError> {
    let bad = ApiError::bad_request;
    let planet = editing.current().planet;
    let materials = planet.terrain().materials;
    let kind = match (req.brush.as_str(), &req.material) {
        ("paint", None) => {
            return Err(bad(format!(
                "paint needs a material: one of {} (a name or its index)",
                materials.join(", ")
            )))
        }
        ("paint", Some(m)) => {
            let index = match m {
                MaterialRef::Index(i) => usize::try_from(*i).ok().filter(|i| *i < materials.len()),
                MaterialRef::Name(n) => materials.iter().position(|x| x.eq_ignore_ascii_case(n.trim())),
            };
            let material = index.and_then(|i| u8::try_from(i).ok()).ok_or_else(|| {
                let list: Vec<String> = materials
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{n} ({i})"))
                    .collect();
                bad(format!(
                    "unknown material {m:?} for this planet; choose one of: {}",
                    list.join(", ")
                ))
            })?;
            BrushKind::Paint { material }
        }
        (_, Some(_)) if BRUSHES.contains(&req.brush.as_str()) => {
            return Err(bad("material applies to the paint brush only".into()))
        }
        ("add", None) => BrushKind::Add,
        ("remove", None) => BrushKind::Remove,
        ("smooth", None) => BrushKind::Smooth,
        ("flatten", None) => BrushKind::Flatten,
        (other, _) => {
            return Err(bad(format!(
                "unknown brush '{other}'; choose one of: {}",
                BRUSHES.join(", ")
            )))
        }
    };
    let l = &editing.limits;
    if !(req.radius >= l.min_brush_radius && req.radius <= l.max_brush_radius) {
        return Err(bad(format!(
            "radius must be from {} to {} m on this server, got {}",
            l.min_brush_radius, l.max_brush_radius, req.radius
        )));
    }
    let strength = req.strength.unwrap_or(1.0);
    let center = DVec3::new(req.x, req.y, req.z);
    let op = BrushOp::new(kind, center, req.radius, strength).map_err(|e| bad(e.to_string()))?;
    let layout = planet.layout();
    let (r, reach) = (center.length(), op.reach());
    let (lo, hi) = (layout.d_b() - reach, layout.radius() + reach);
    if !(r >= lo && r <= hi) {
        return Err(bad(format!(
            "the brush centre is {r:.3} m from the planet centre, so a brush reaching {reach} m cannot touch the \
             planet's shell ({} to {} m from the centre); x, y, z are metres in the planet frame",
            layout.d_b(),
            layout.radius()
        )));
    }
    Ok(op)
}

/// Runs `action` and answers with its outcome.
async fn perform(state: &AppState, editing: Arc<Editing>, action: Action) -> Result<Response, ApiError> {
    let outcome = state.edit(editing, action).await.map_err(|e| {
        tracing::error!("an edit could not be saved: {e}");
        ApiError::internal(format!("the edit could not be saved, so it was not applied: {e}"))
    })?;
    if let Some(id) = outcome.id {
        tracing::info!(
            "edit {id}: {:?}, {} chunks changed, revision {}",
            action,
            outcome.chunks.len(),
            outcome.revision
        );
    }
    let mut r = Json(outcome).into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(r)
}

/// `POST /api/v1/edits`.
pub async fn post_edit(
    State(state): State<AppState>,
    RawQuery(q): RawQuery,
    req: Request,
) -> Result<Response, Response> {
    let editing = editing_for(&state, q)?;
    require_json(&req, "the edit")?;
    if let Some(r) = rate_limited(&editing, &req) {
        return Err(r);
    }
    let body = read_body(req, MAX_EDIT_BODY, "the edit body").await?;
    let parsed: EditRequest = serde_json::from_slice(&body).map_err(|e| {
        ApiError::bad_request(format!(
            "malformed edit: {e}; send {{\"brush\": \"remove\", \"x\": .., \"y\": .., \"z\": .., \"radius\": .., \
             \"strength\": ..}} (see docs/specs/http-api-v1.md)"
        ))
    })?;
    let op = brush_op(&parsed, &editing)?;
    Ok(perform(&state, editing, Action::Apply(op)).await?)
}

/// `POST /api/v1/edits/undo`.
pub async fn undo(State(state): State<AppState>, RawQuery(q): RawQuery, req: Request) -> Result<Response, Response> {
    let editing = editing_for(&state, q)?;
    if let Some(r) = rate_limited(&editing, &req) {
        return Err(r);
    }
    Ok(perform(&state, editing, Action::Undo).await?)
}

/// `POST /api/v1/edits/redo`.
pub async fn redo(State(state): State<AppState>, RawQuery(q): RawQuery, req: Request) -> Result<Response, Response> {
    let editing = editing_for(&state, q)?;
    if let Some(r) = rate_limited(&editing, &req) {
        return Err(r);
    }
    Ok(perform(&state, editing, Action::Redo).await?)
}

/// `GET /api/v1/edits`.
pub async fn list(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let editing = editing_for(&state, q)?;
    let c = editing.current();
    let edits: Vec<Value> = editing
        .entries()
        .iter()
        .map(|e| {
            let material = match e.op.kind {
                BrushKind::Paint { material } => Some(material),
                _ => None,
            };
            json!({
                "id": e.id.0,
                "brush": e.op.kind.name(),
                "center": e.op.center.to_array(),
                "radius": e.op.radius,
                "strength": e.op.strength,
                "material": material,
                "active": e.active,
            })
        })
        .collect();
    let mut r = Json(json!({
        "revision": c.revision,
        "active": c.active,
        "redo": c.redo,
        "edits": edits,
    }))
    .into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(r)
}

/// One server-sent event.
fn sse_event(name: &str, data: &impl serde::Serialize) -> Event {
    let data = serde_json::to_string(data).unwrap_or_else(|_| "{}".into());
    Event::default().event(name).data(data)
}

/// `GET /api/v1/events`: `hello`, then `edit` and `resync` events.
pub async fn events(State(state): State<AppState>, RawQuery(q): RawQuery) -> Result<Response, ApiError> {
    let editing = editing_for(&state, q)?;
    // Subscribe before reading the revision, so no change falls between the two.
    let rx = editing.subscribe();
    let hello = sse_event("hello", &json!({ "revision": editing.current().revision }));
    let stop = state.stopping();
    let stream = futures_util::stream::unfold(
        (Some(hello), rx, editing, stop),
        |(first, mut rx, editing, mut stop)| async move {
            if let Some(hello) = first {
                return Some((Ok::<Event, Infallible>(hello), (None, rx, editing, stop)));
            }
            let received = tokio::select! {
                r = rx.recv() => r,
                // The server is stopping (or gone): end the stream.
                _ = stop.wait_for(|s| *s) => return None,
            };
            let event = match received {
                Ok(e) => sse_event(e.event, &e),
                Err(broadcast::error::RecvError::Lagged(_)) => {
                    // Too far behind to replay: reload everything at the current revision.
                    let e = EditEvent {
                        event: "resync",
                        revision: editing.current().revision,
                        action: None,
                        id: None,
                        chunks: Vec::new(),
                    };
                    sse_event(e.event, &e)
                }
                Err(broadcast::error::RecvError::Closed) => return None,
            };
            Some((Ok(event), (None, rx, editing, stop)))
        },
    );
    let mut r = Sse::new(stream)
        .keep_alive(KeepAlive::new().interval(KEEP_ALIVE))
        .into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(r)
}
