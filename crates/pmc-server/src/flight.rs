//! A flight benchmark through the server: a viewer's teleports, measured.
//!
//! For each stop of a flight (an eye and a point to look at), the level-of-detail selection of
//! [`pmc_lod`] is run for that view with the planet's measured level errors (as the viewer
//! does), every drawn chunk is requested from the server through its HTTP router with its
//! `seams` mask, a bounded number at a time (as a viewer does), and the stop is *converged* when
//! every one of them has answered. Reported per stop: the time to converge from the moment the
//! camera arrives, chunks and triangles drawn, chunks generated per second per level, the
//! process's peak memory, and the triangles a level-0-only mesh of the same chunks would have
//! (estimated as `4^L` times each level-`L` chunk's triangles: each level halves the cell size
//! along the surface).
//!
//! The requests go through [`crate::router`] in process (no socket), so the figures are the
//! server's: routing, the job queue, generation on the worker pool, encoding and the cache.

use crate::AppState;
use axum::body::Body;
use axum::http::{Request, StatusCode};
use futures_util::StreamExt;
use pmc_geometry::glam::DVec3;
use pmc_lod::{frustum_planes, LodParams, Selector, View};
use std::time::{Duration, Instant};
use tower::ServiceExt;

/// One stop of a flight.
#[derive(Clone, Debug)]
pub struct Stop {
    /// A name for the report (e.g. "orbit", "2 m").
    pub name: String,
    /// The eye, planet frame, metres.
    pub eye: DVec3,
    /// The point looked at, planet frame, metres.
    pub look_at: DVec3,
    /// The eye's height above the ground below it, metres.
    pub height: f64,
}

/// The camera and the selection's settings for every stop.
#[derive(Clone, Copy, Debug)]
pub struct FlightCamera {
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Viewport width over height.
    pub aspect: f64,
    /// Viewport height, pixels.
    pub viewport_height_px: f64,
    /// Largest screen-space error, pixels.
    pub max_pixel_error: f64,
    /// Most chunks a selection may hold.
    pub max_chunks: usize,
    /// Chunk requests in flight at once.
    pub concurrency: usize,
}

impl Default for FlightCamera {
    /// 60° field of view, 1920 × 1080, 2 px, 4096 chunks, 16 requests in flight.
    fn default() -> Self {
        FlightCamera {
            fov_y: 60f64.to_radians(),
            aspect: 16.0 / 9.0,
            viewport_height_px: 1080.0,
            max_pixel_error: 2.0,
            max_chunks: pmc_lod::DEFAULT_MAX_CHUNKS,
            concurrency: 16,
        }
    }
}

/// What one stop measured.
#[derive(Clone, Debug)]
pub struct StopReport {
    /// The stop's name.
    pub name: String,
    /// The eye's height above the ground below it, metres.
    pub height: f64,
    /// Time from the camera's arrival (selection included) to every drawn chunk answered.
    pub converged: Duration,
    /// Time the selection took.
    pub selection: Duration,
    /// Chunks selected (drawn or culled) and drawn.
    pub selected: usize,
    /// Drawn chunks per level (index = level).
    pub drawn_per_level: Vec<usize>,
    /// Triangles of the drawn chunks.
    pub triangles: u64,
    /// Estimated triangles of a level-0-only mesh of the same chunks.
    pub level0_triangles: f64,
    /// Chunks generated per second per level during the stop (chunks answered from the cache
    /// not counted), `None` for levels with none.
    pub chunks_per_second: Vec<Option<f64>>,
    /// Whether the selection hit its chunk budget.
    pub truncated: bool,
    /// Requests answered 503 (queue full) and retried.
    pub retries: u64,
    /// The process's peak resident memory so far, bytes (`VmHWM`), when the system tells.
    pub peak_rss: Option<u64>,
    /// How many cores the process kept busy on average from the camera's arrival to
    /// convergence (its CPU time over that wall time; 2.0 is two cores busy throughout), when
    /// the system tells.
    pub cores_busy: Option<f64>,
}

/// Why a flight failed.
#[derive(Debug, thiserror::Error)]
pub enum FlightError {
    /// The selection refused its input.
    #[error("level-of-detail selection: {0}")]
    Selection(#[from] pmc_lod::LodError),
    /// The server answered a chunk request with an error.
    #[error("chunk {path}: the server answered {status}: {body}")]
    Chunk {
        /// The request path.
        path: String,
        /// The status.
        status: StatusCode,
        /// The answer's text.
        body: String,
    },
    /// A chunk could not be decoded.
    #[error("chunk {path}: {reason}")]
    Decode {
        /// The request path.
        path: String,
        /// What was wrong.
        reason: String,
    },
}

/// The process's peak resident memory (`VmHWM` of `/proc/self/status`), bytes.
pub fn peak_rss() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The CPU time the process has used so far (user and system, all threads), seconds, from
/// `/proc/self/stat` (in the kernel's fixed 100 ticks a second), when the system tells.
pub fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name (which may hold spaces) are space-separated; utime and
    // stime are the 14th and 15th of the line, the 12th and 13th after the name.
    let rest = &s[s.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace().skip(11);
    let utime: u64 = fields.next()?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some((utime + stime) as f64 / 100.0)
}

/// Flies through `stops` on the server's default planet, one after the other without clearing
/// the cache (as a user flying down would), and measures each.
pub async fn fly(state: &AppState, stops: &[Stop], camera: &FlightCamera) -> Result<Vec<StopReport>, FlightError> {
    let id = std::sync::Arc::new(state.config().terrain.clone());
    let planet = state.default_planet().await.map_err(|reason| FlightError::Decode {
        path: "/api/v1/planet".into(),
        reason,
    })?;
    let errors = state.lod_errors(id, planet.clone()).await;
    let mut selector = Selector::new(*planet.layout(), errors.to_vec(), pmc_lod::occluder_radius(&planet))?;
    // A height-field planet's patches are bounded by their own heights, not the whole relief.
    if let Some(radii) = pmc_lod::planet_radii(&planet) {
        selector = selector.with_radii(radii);
    }
    let router = crate::router(state.clone());
    let datum = planet.datum_radius();
    let mut reports = Vec::with_capacity(stops.len());
    for stop in stops {
        let start = Instant::now();
        let cpu_start = process_cpu_seconds();
        let forward = stop.look_at - stop.eye;
        let up = stop.eye.normalize_or(DVec3::Y);
        let up = if forward.cross(up).length_squared() < 1e-12 * forward.length_squared() {
            DVec3::Y
        } else {
            up
        };
        let altitude = stop.eye.length() - datum;
        let near = (0.5 * altitude.abs().min(stop.height.abs())).clamp(0.05, 1.0e5);
        let far = stop.eye.length() + planet.layout().radius() * 2.0;
        let view = View {
            eye: stop.eye,
            frustum: Some(frustum_planes(
                stop.eye,
                forward,
                up,
                camera.fov_y,
                camera.aspect,
                near,
                far,
            )),
            viewport_height_px: camera.viewport_height_px,
            fov_y: camera.fov_y,
        };
        let params = LodParams {
            max_pixel_error: camera.max_pixel_error,
            max_chunks: camera.max_chunks,
            ..LodParams::default()
        };
        let selection = selector.select(&view, &params)?;
        let selection_time = start.elapsed();
        let levels = usize::from(planet.layout().max_level()) + 1;
        let drawn: Vec<_> = selection.chunks.iter().filter(|s| s.drawn).copied().collect();
        let before = state.stats();
        let results = futures_util::stream::iter(drawn.iter().map(|s| {
            let router = router.clone();
            let k = s.key;
            let path = format!(
                "/api/v1/chunk/{}/{}/{}/{}/{}?seams={}",
                k.face.name(),
                k.level,
                k.i,
                k.j,
                k.k,
                s.coarser.0
            );
            async move {
                fetch(router, path)
                    .await
                    .map(|(tris, retries)| (k.level, tris, retries))
            }
        }))
        .buffer_unordered(camera.concurrency.max(1))
        .collect::<Vec<_>>()
        .await;
        let converged = start.elapsed();
        let cpu = process_cpu_seconds().zip(cpu_start).map(|(b, a)| b - a);
        let after = state.stats();
        let mut drawn_per_level = vec![0usize; levels];
        let (mut triangles, mut level0, mut retries) = (0u64, 0f64, 0u64);
        for r in results {
            let (level, tris, tries) = r?;
            drawn_per_level[usize::from(level)] += 1;
            triangles += tris;
            level0 += tris as f64 * 4f64.powi(i32::from(level));
            retries += tries;
        }
        // Chunks generated during the stop, by level: the drawn chunks not answered from the
        // cache. The generator counts jobs in total; attribute them to levels in proportion.
        let generated = after.generated.saturating_sub(before.generated);
        let drawn_total = drawn.len().max(1) as f64;
        let seconds = (converged - selection_time).as_secs_f64().max(1e-9);
        let chunks_per_second = drawn_per_level
            .iter()
            .map(|n| (*n > 0 && generated > 0).then(|| generated as f64 * (*n as f64 / drawn_total) / seconds))
            .collect();
        reports.push(StopReport {
            name: stop.name.clone(),
            height: stop.height,
            converged,
            selection: selection_time,
            selected: selection.chunks.len(),
            drawn_per_level,
            triangles,
            level0_triangles: level0,
            chunks_per_second,
            truncated: selection.truncated,
            retries,
            peak_rss: peak_rss(),
            cores_busy: cpu.map(|c| c / converged.as_secs_f64().max(1e-9)),
        });
    }
    Ok(reports)
}

/// Requests one chunk until it is answered (retrying 503s after a short pause) and returns its
/// triangle count and the number of retries.
async fn fetch(router: axum::Router, path: String) -> Result<(u64, u64), FlightError> {
    let mut retries = 0;
    loop {
        let req = Request::get(&path).body(Body::empty()).expect("a valid request");
        let resp = router.clone().oneshot(req).await.expect("the router is infallible");
        let status = resp.status();
        let bytes = axum::body::to_bytes(resp.into_body(), usize::MAX)
            .await
            .map_err(|e| FlightError::Decode {
                path: path.clone(),
                reason: e.to_string(),
            })?;
        if status == StatusCode::SERVICE_UNAVAILABLE {
            retries += 1;
            tokio::time::sleep(Duration::from_millis(5)).await;
            continue;
        }
        if status != StatusCode::OK {
            return Err(FlightError::Chunk {
                path,
                status,
                body: String::from_utf8_lossy(&bytes).into_owned(),
            });
        }
        let chunk = pmc_formats::chunk_encoding::decode_chunk(&bytes).map_err(|e| FlightError::Decode {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        return Ok(((chunk.indices.len() / 3) as u64, retries));
    }
}

/// The stops of a descent over `lat`, `lon` (degrees) at the given heights above the ground
/// (metres; the ground is the surface under the point, or the datum where the column holds
/// none): from high up the camera looks at the planet's centre, from low down at the ground
/// ahead, 15° below the horizon, facing north (east at the poles).
pub fn descent(
    planet: &pmc_planet::Planet,
    lat: f64,
    lon: f64,
    heights: &[(String, f64)],
) -> Result<Vec<Stop>, String> {
    let dir = pmc_geometry::LatLon::new(lat, lon)
        .map_err(|e| e.to_string())?
        .to_unit();
    let ground = planet.surface_radius(dir);
    let north = (DVec3::Y - dir * dir.y).normalize_or(DVec3::X);
    Ok(heights
        .iter()
        .map(|(name, h)| {
            let eye = dir * (ground + h);
            let look_at = if *h > 0.1 * planet.layout().radius() {
                DVec3::ZERO
            } else {
                let ahead = north * 15f64.to_radians().cos() - dir * 15f64.to_radians().sin();
                eye + ahead * h.max(1.0) * 10.0
            };
            Stop {
                name: name.clone(),
                eye,
                look_at,
                height: *h,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    #[test]
    fn process_cpu_time_counts_the_work_of_every_thread() {
        let before = process_cpu_seconds().expect("Linux has /proc/self/stat");
        // A fixed amount of work (a chain of 10^8 dependent multiply-adds, at least 0.1 s of
        // CPU on any current processor) on each of two threads, however they are scheduled.
        let spin = || {
            let mut x = 1u64;
            for _ in 0..100_000_000u64 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
            x
        };
        std::thread::scope(|s| {
            s.spawn(spin);
            s.spawn(spin);
        });
        let used = process_cpu_seconds().unwrap() - before;
        assert!(used >= 0.1, "{used} s");
    }
}
