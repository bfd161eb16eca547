//! Paths as documents: the JSON and GeoJSON of `docs/specs/path-v1.md`, written by `pmc path`
//! and the server's `/api/v1/path`, for the whole-planet grid and the lazy grid.

use crate::agent::Agent;
use crate::grid::{NavGrid, NodeId};
use crate::lazy::{LazyAnswer, LazyGrid};
use crate::search::{NoPath, Path, SearchOptions};
use crate::smooth::{smooth_path, SmoothPath};
use pmc_geometry::glam::DVec3;
use pmc_geometry::LatLon;
use serde_json::{json, Value};

/// The format name in the JSON document.
pub const PATH_FORMAT: &str = "pmc-path";
/// The format version.
pub const PATH_VERSION: u32 = 1;

/// Degrees rounded to 1e-9 (about 0.1 mm on Earth): enough for any planet, and free of
/// round-trip noise such as 29.999999999999996.
fn degrees(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

/// Latitude, longitude (degrees) and altitude above `datum` (metres) of a point.
pub fn waypoint(p: DVec3, datum: f64) -> Value {
    let ll = LatLon::from_point(p).unwrap_or(LatLon { lat: 0.0, lon: 0.0 });
    json!({ "lat": degrees(ll.lat), "lon": degrees(ll.lon), "alt": p.length() - datum })
}

/// One end of a path query: a direction from the planet centre and, optionally, the radius
/// (metres from the centre) of the floor wanted; without it, the highest floor (the ground seen
/// from above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct End {
    /// Direction from the planet centre (any non-zero length).
    pub dir: DVec3,
    /// Radius of the floor wanted.
    pub radius: Option<f64>,
}

impl End {
    fn json(&self, datum: f64) -> Value {
        let ll = LatLon::from_point(self.dir).unwrap_or(LatLon { lat: 0.0, lon: 0.0 });
        json!({ "lat": degrees(ll.lat), "lon": degrees(ll.lon), "alt": self.radius.map(|r| r - datum) })
    }
}

/// What a path query found: a path, no path (with why), or no walkable ground near an end. `N`
/// names the nodes: [`NodeId`] on the whole-planet grid, [`crate::NodeKey`] on the lazy grid.
#[derive(Clone, Debug, PartialEq)]
pub enum PathAnswer<N = NodeId> {
    /// A path.
    Found(Path<N>),
    /// Both ends are on the grid, and no path joins them (or none was found within the search
    /// bound, [`NoPath::SearchBound`]).
    NoPath(NoPath),
    /// No node lies near the start (`true`) or the goal (`false`).
    NoGround {
        /// Whether it is the start.
        start: bool,
    },
}

impl<N> PathAnswer<N> {
    /// Why there is no path, in words (`None` for a path).
    pub fn reason(&self) -> Option<String> {
        match self {
            PathAnswer::Found(_) => None,
            PathAnswer::NoPath(n) => Some(n.to_string()),
            PathAnswer::NoGround { start } => Some(format!(
                "no path: no walkable ground near the {} (every nearby column is rock to the top, or has no head room for the agent)",
                if *start { "start" } else { "goal" }
            )),
        }
    }

    /// The reason as a short name (`None` for a path): `no_ground`, or [`NoPath::cause`].
    pub fn cause(&self) -> Option<&'static str> {
        match self {
            PathAnswer::Found(_) => None,
            PathAnswer::NoPath(n) => Some(n.cause()),
            PathAnswer::NoGround { .. } => Some("no_ground"),
        }
    }
}

/// What a document says about the grid, beside the answer.
struct Facts {
    agent: Agent,
    /// The smoothed path of a path found on the whole-planet grid, and the ground its legs walk
    /// ([`SmoothPath::ground`]).
    smoothed: Option<(SmoothPath, Vec<DVec3>)>,
    /// The `grid` member.
    grid: Value,
    /// The component of a path found.
    component: Value,
    /// The `search` member of a lazy grid's documents.
    search: Option<Value>,
}

impl Facts {
    fn eager(grid: &NavGrid, answer: &PathAnswer) -> Facts {
        let first = |p: &Path| p.nodes.first().copied();
        Facts {
            agent: *grid.agent(),
            smoothed: match answer {
                PathAnswer::Found(p) => {
                    let s = smooth_path(grid, p);
                    let ground = s.ground(grid);
                    Some((s, ground))
                }
                _ => None,
            },
            grid: json!({ "nodes": grid.node_count(), "components": grid.component_sizes().len() }),
            component: match answer {
                PathAnswer::Found(p) => json!(first(p).and_then(|n| grid.component(n))),
                _ => Value::Null,
            },
            search: None,
        }
    }

    fn lazy(grid: &LazyGrid, answer: &LazyAnswer, options: &SearchOptions) -> Facts {
        Facts {
            agent: *grid.agent(),
            smoothed: None,
            grid: json!({
                "lazy": true,
                "tiles": grid.cache_stats().tiles,
                "nodes": grid.cached_nodes(),
                "components": Value::Null,
            }),
            component: Value::Null,
            search: Some(json!({
                "expanded": answer.stats.expanded,
                "backward": answer.stats.backward,
                "tiles_built": answer.stats.tiles_built,
                "max_expanded": options.max_expanded,
                "max_tiles": options.max_tiles_built,
                "weight": options.weight,
            })),
        }
    }
}

fn json_document<N>(facts: Facts, answer: &PathAnswer<N>, from: End, to: End, datum: f64) -> Value {
    let a = facts.agent;
    let mut v = json!({
        "format": PATH_FORMAT,
        "version": PATH_VERSION,
        "found": matches!(answer, PathAnswer::Found(_)),
        "asked": { "from": from.json(datum), "to": to.json(datum) },
        "agent": { "clearance": a.clearance, "step_up": a.step_up, "step_down": a.step_down, "max_slope": a.max_slope },
        "grid": facts.grid,
    });
    if let Some(search) = facts.search {
        v["search"] = search;
    }
    match answer {
        PathAnswer::Found(p) => {
            let w: Vec<Value> = p.points.iter().map(|q| waypoint(*q, datum)).collect();
            v["length"] = json!(p.length);
            v["steps"] = json!(p.nodes.len().saturating_sub(1));
            v["component"] = facts.component;
            v["waypoints"] = json!(w);
            v["expanded"] = json!(p.expanded);
            if let Some((s, ground)) = &facts.smoothed {
                let corners: Vec<Value> = s.points.iter().map(|q| waypoint(*q, datum)).collect();
                let line: Vec<Value> = ground.iter().map(|q| waypoint(*q, datum)).collect();
                v["smoothed"] = json!({
                    "length": s.length, "legs": s.corners.len().saturating_sub(1), "waypoints": corners, "line": line,
                });
            }
        }
        other => {
            v["reason"] = json!(other.reason());
            v["cause"] = json!(other.cause());
            if let PathAnswer::NoPath(NoPath::DifferentComponents { from, to }) = other {
                v["components"] = json!([from, to]);
            }
        }
    }
    v
}

fn geojson_document<N>(facts: Facts, answer: &PathAnswer<N>, from: End, to: End, datum: f64) -> Value {
    let coords = |p: DVec3| {
        let w = waypoint(p, datum);
        json!([w["lon"], w["lat"], w["alt"]])
    };
    let point = |e: End, role: &str| {
        let w = e.json(datum);
        let c = match e.radius {
            Some(_) => json!([w["lon"], w["lat"], w["alt"]]),
            None => json!([w["lon"], w["lat"]]),
        };
        json!({ "type": "Feature", "geometry": { "type": "Point", "coordinates": c }, "properties": { "role": role } })
    };
    let mut features = Vec::new();
    if let PathAnswer::Found(p) = answer {
        let line: Vec<Value> = p.points.iter().map(|q| coords(*q)).collect();
        features.push(json!({
            "type": "Feature",
            "geometry": { "type": "LineString", "coordinates": line },
            "properties": { "role": "path", "length": p.length, "steps": p.nodes.len().saturating_sub(1),
                            "component": facts.component },
        }));
    }
    features.push(point(from, "from"));
    features.push(point(to, "to"));
    if let Some((s, _)) = &facts.smoothed {
        let line: Vec<Value> = s.points.iter().map(|q| coords(*q)).collect();
        features.push(json!({
            "type": "Feature",
            "geometry": { "type": "LineString", "coordinates": line },
            "properties": { "role": "smoothed", "length": s.length, "legs": s.corners.len().saturating_sub(1) },
        }));
    }
    let mut properties = json!({
        "format": PATH_FORMAT, "version": PATH_VERSION, "found": matches!(answer, PathAnswer::Found(_)),
        "reason": answer.reason(), "cause": answer.cause(),
    });
    if let Some(search) = facts.search {
        properties["search"] = search;
    }
    json!({ "type": "FeatureCollection", "features": features, "properties": properties })
}

/// The JSON document of a path query from `from` to `to` (the points asked for, planet frame);
/// a path found comes with its smoothed form ([`smooth_path`]) in a `smoothed` member (spec 1.2),
/// with the ground its legs walk as a `line` (spec 1.3).
pub fn path_json(grid: &NavGrid, answer: &PathAnswer, from: End, to: End, datum: f64) -> Value {
    json_document(Facts::eager(grid, answer), answer, from, to, datum)
}

/// The GeoJSON (RFC 7946) of a path query: a `FeatureCollection` holding the path as a
/// `LineString` of `[lon, lat, alt]` (when found) and the two ends asked for as `Point`s
/// (`[lon, lat]`, with the altitude when one was asked for), then the smoothed path
/// ([`smooth_path`]) as a `LineString` of its corners with `role` `smoothed` (spec 1.2).
pub fn path_geojson(grid: &NavGrid, answer: &PathAnswer, from: End, to: End, datum: f64) -> Value {
    geojson_document(Facts::eager(grid, answer), answer, from, to, datum)
}

/// [`path_json`] of a query of the lazy grid ([`LazyGrid::query`] with `options`): the grid is
/// described by the tiles its cache holds, components are null (a lazy grid has none), and a
/// `search` member gives the search's counts and bounds (`docs/specs/path-v1.md`, 1.1).
pub fn lazy_path_json(
    grid: &LazyGrid,
    answer: &LazyAnswer,
    options: &SearchOptions,
    from: End,
    to: End,
    datum: f64,
) -> Value {
    json_document(Facts::lazy(grid, answer, options), &answer.answer, from, to, datum)
}

/// [`path_geojson`] of a query of the lazy grid, with the `search` member in the top-level
/// properties.
pub fn lazy_path_geojson(
    grid: &LazyGrid,
    answer: &LazyAnswer,
    options: &SearchOptions,
    from: End,
    to: End,
    datum: f64,
) -> Value {
    geojson_document(Facts::lazy(grid, answer, options), &answer.answer, from, to, datum)
}

/// Finds a path between the walkable ground nearest to `from` and `to`: each end is, in the
/// nearest column with nodes within `max_rings` columns, the node nearest to the radius asked
/// for, or the highest one. The walk comes from the hierarchical search
/// ([`crate::find_path_hierarchical`]: the same answer as [`crate::find_path`] on whether a path
/// exists, the walk within [`crate::HIERARCHICAL_WEIGHT`] times the shortest in its corridor).
pub fn query(grid: &NavGrid, from: End, to: End, max_rings: usize) -> PathAnswer {
    query_by(grid, from, to, max_rings, crate::hierarchical::find_path_hierarchical)
}

/// [`query`] with the exact search ([`crate::find_path`]): a shortest walk, found by A* over the
/// whole grid (slower across long distances on rough ground).
pub fn query_exact(grid: &NavGrid, from: End, to: End, max_rings: usize) -> PathAnswer {
    query_by(grid, from, to, max_rings, crate::search::find_path)
}

fn query_by(
    grid: &NavGrid,
    from: End,
    to: End,
    max_rings: usize,
    search: impl Fn(&NavGrid, NodeId, NodeId) -> Result<Path, NoPath>,
) -> PathAnswer {
    let Some(a) = grid.node_near(from.dir, from.radius, max_rings) else {
        return PathAnswer::NoGround { start: true };
    };
    let Some(b) = grid.node_near(to.dir, to.radius, max_rings) else {
        return PathAnswer::NoGround { start: false };
    };
    match search(grid, a, b) {
        Ok(p) => PathAnswer::Found(p),
        Err(e) => PathAnswer::NoPath(e),
    }
}
