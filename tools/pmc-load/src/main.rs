//! `pmc-load`: many viewers at once against `pmc serve`.
//!
//! Each simulated viewer flies its own random path over the planet (seeded: the same paths every
//! run): it drifts along a heading at a speed that follows its height, climbs and descends, and
//! now and then jumps elsewhere (a teleport, a go-to). About once a second it runs the
//! level-of-detail selection of `pmc_lod` for its camera (as the viewer's worker does, with the
//! planet's measured level errors from `/api/v1/planet`), requests every drawn chunk it has not
//! got with its seams mask, at most six at a time over their own connections (as a browser does
//! per host), and drops the requests for chunks the new selection no longer wants (closing the
//! connection: the server withdraws the chunk's job when no one else waits for it). A 503 is
//! retried after its `Retry-After`.
//!
//! After the run the viewers leave; ten seconds later `/api/v1/stats` must show no job queued or
//! running. Reported: the answers by status (anything but 200, 304 and 503 with `Retry-After` is
//! a failure), p50 / p90 / p99 / max latency of the chunks answered, requests cancelled, the
//! server's peak RSS (when this tool started it, or was given its pid), the chunks generated and
//! the jobs dropped. Exit status 1 when a check fails.
//!
//! ```text
//! pmc-load --pmc target/release/pmc --preset earth --viewers 50 --seconds 60
//! pmc-load --url http://127.0.0.1:8080/ --pid 12345
//! ```

use bytes::Bytes;
use clap::Parser;
use http_body_util::{BodyExt, Empty};
use hyper_util::rt::TokioIo;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Layout};
use pmc_lod::{frustum_planes, LodParams, Selector, View};
use serde_json::Value;
use std::collections::{HashMap, HashSet};
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::io::AsyncBufReadExt;
use tokio::sync::{mpsc, Semaphore};

#[derive(Parser, Debug)]
#[command(
    name = "pmc-load",
    about = "Simulated viewers against pmc serve: latency, statuses, memory, jobs left"
)]
struct Args {
    /// Start this `pmc` binary as `pmc serve --port 0` with the planet options below (and stop it
    /// at the end).
    #[arg(long, conflicts_with = "url")]
    pmc: Option<String>,
    /// Or load a server already running at this URL.
    #[arg(long)]
    url: Option<String>,
    /// The pid of the server given by --url, to read its memory.
    #[arg(long)]
    pid: Option<u32>,
    /// The preset to serve (with --pmc).
    #[arg(long, default_value = "earth")]
    preset: String,
    /// The seed (with --pmc).
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// More options for `pmc serve` (with --pmc), e.g. `--serve-arg=--cache-mb --serve-arg=64`.
    #[arg(long = "serve-arg", allow_hyphen_values = true)]
    serve_args: Vec<String>,
    /// Simulated viewers.
    #[arg(long, default_value_t = 50)]
    viewers: usize,
    /// How long they fly, seconds.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// How long after they leave the queue must be empty, seconds.
    #[arg(long, default_value_t = 10.0)]
    settle: f64,
    /// Chunk requests in flight per viewer.
    #[arg(long, default_value_t = 6)]
    concurrency: usize,
    /// The seed of the viewers' paths.
    #[arg(long, default_value_t = 1)]
    rng_seed: u64,
    /// The viewers' screens: height in pixels (16:9), largest pixel error, chunk budget.
    #[arg(long, default_value_t = 720.0)]
    viewport_height: f64,
    #[arg(long, default_value_t = 2.0)]
    pixel_error: f64,
    #[arg(long, default_value_t = 2500)]
    max_chunks: usize,
    /// The largest server RSS allowed, MiB.
    #[arg(long, default_value_t = 1024)]
    max_rss_mb: u64,
}

#[derive(Debug, thiserror::Error)]
enum LoadError {
    #[error("{0}")]
    Setup(String),
    #[error("{0}")]
    Http(String),
}

/// SplitMix64: the viewers' paths.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
}

/// One answer of the server (or none).
#[derive(Debug)]
enum Outcome {
    Answer {
        status: u16,
        retry_after: Option<f64>,
        seconds: f64,
    },
    /// The connection failed (refused, reset).
    Transport(String),
}

/// GET `path` from `addr` over a connection of its own; dropping the future closes it.
async fn get(addr: SocketAddr, path: &str) -> Outcome {
    let start = Instant::now();
    let run = async {
        let stream = tokio::net::TcpStream::connect(addr).await.map_err(|e| e.to_string())?;
        stream.set_nodelay(true).ok();
        let (mut sender, conn) = hyper::client::conn::http1::handshake(TokioIo::new(stream))
            .await
            .map_err(|e| e.to_string())?;
        let request = async move {
            let req = hyper::Request::get(path)
                .header("host", addr.to_string())
                .body(Empty::<Bytes>::new())
                .map_err(|e| e.to_string())?;
            let resp = sender.send_request(req).await.map_err(|e| e.to_string())?;
            let status = resp.status().as_u16();
            let retry_after = resp
                .headers()
                .get("retry-after")
                .and_then(|v| v.to_str().ok())
                .and_then(|v| v.trim().parse::<f64>().ok());
            resp.into_body().collect().await.map_err(|e| e.to_string())?;
            Ok::<_, String>((status, retry_after))
        };
        tokio::pin!(conn);
        tokio::pin!(request);
        tokio::select! {
            r = &mut request => r,
            c = &mut conn => match c {
                Ok(()) => request.await,
                Err(e) => Err(e.to_string()),
            },
        }
    };
    match run.await {
        Ok((status, retry_after)) => Outcome::Answer {
            status,
            retry_after,
            seconds: start.elapsed().as_secs_f64(),
        },
        Err(e) => Outcome::Transport(e),
    }
}

/// GET `path` as JSON.
async fn get_json(addr: SocketAddr, path: &str) -> Result<Value, LoadError> {
    let stream = tokio::net::TcpStream::connect(addr)
        .await
        .map_err(|e| LoadError::Http(format!("{addr}: {e}")))?;
    let (mut sender, conn) = hyper::client::conn::http1::handshake(TokioIo::new(stream))
        .await
        .map_err(|e| LoadError::Http(e.to_string()))?;
    let task = tokio::spawn(conn);
    let req = hyper::Request::get(path)
        .header("host", addr.to_string())
        .body(Empty::<Bytes>::new())
        .map_err(|e| LoadError::Http(e.to_string()))?;
    let resp = sender
        .send_request(req)
        .await
        .map_err(|e| LoadError::Http(format!("{path}: {e}")))?;
    let status = resp.status();
    let body = resp
        .into_body()
        .collect()
        .await
        .map_err(|e| LoadError::Http(e.to_string()))?
        .to_bytes();
    task.abort();
    if !status.is_success() {
        return Err(LoadError::Http(format!(
            "{path}: {status}: {}",
            String::from_utf8_lossy(&body)
        )));
    }
    serde_json::from_slice(&body).map_err(|e| LoadError::Http(format!("{path}: {e}")))
}

/// What every viewer adds up.
#[derive(Default)]
struct Totals {
    by_status: HashMap<u16, u64>,
    /// 503s that came without a `Retry-After`.
    busy_without_retry_after: u64,
    /// Answers other than 200, 304 and 503 (status and path), the first few.
    unexpected: Vec<String>,
    unexpected_count: u64,
    transport_errors: u64,
    transport_examples: Vec<String>,
    cancelled: u64,
    /// Seconds from request to whole answer, of the 200s.
    latencies: Vec<f64>,
    selections: u64,
    selection_seconds: f64,
}

/// The planet as the selection needs it.
struct PlanetView {
    layout: Layout,
    selector: Selector,
    datum: f64,
}

/// A viewer's camera: place, height over the datum, heading.
struct Camera {
    lat: f64,
    lon: f64,
    alt: f64,
    heading: f64,
}

impl Camera {
    fn random(rng: &mut Rng) -> Camera {
        Camera {
            lat: rng.range(-1.0, 1.0).asin().to_degrees(),
            lon: rng.range(-180.0, 180.0),
            // from 2 m to 10 000 km, even in the logarithm
            alt: 2.0 * (5.0e6f64).powf(rng.unit()),
            heading: rng.range(0.0, 360.0),
        }
    }

    /// One second of flight: along the heading at the height per second, the height drifting;
    /// one time in fifteen, a jump elsewhere.
    fn step(&mut self, rng: &mut Rng, datum: f64) {
        if rng.unit() < 1.0 / 15.0 {
            *self = Camera::random(rng);
            return;
        }
        let angle = (self.alt.max(2.0) / datum).min(0.2);
        let (lat, lon, h) = (self.lat.to_radians(), self.lon.to_radians(), self.heading.to_radians());
        let lat2 = (lat.sin() * angle.cos() + lat.cos() * angle.sin() * h.cos()).asin();
        let lon2 = lon + (h.sin() * angle.sin() * lat.cos()).atan2(angle.cos() - lat.sin() * lat2.sin());
        self.lat = lat2.to_degrees();
        self.lon = (lon2.to_degrees() + 540.0).rem_euclid(360.0) - 180.0;
        self.alt = (self.alt * (rng.range(-0.4, 0.4)).exp()).clamp(2.0, 1.0e7);
        self.heading = (self.heading + rng.range(-20.0, 20.0)).rem_euclid(360.0);
    }

    /// The view: from high up straight down, near the ground 15° under the horizon.
    fn view(&self, datum: f64, height_px: f64) -> View {
        let (lat, lon) = (self.lat.to_radians(), self.lon.to_radians());
        let up = DVec3::new(lat.cos() * lon.cos(), lat.sin(), -lat.cos() * lon.sin());
        let east = DVec3::Y.cross(up).normalize_or(DVec3::X);
        let north = up.cross(east);
        let h = self.heading.to_radians();
        let ahead = north * h.cos() + east * h.sin();
        let pitch: f64 = if self.alt > 0.05 * datum { -89.0 } else { -15.0 };
        let p = pitch.to_radians();
        let forward = ahead * p.cos() + up * p.sin();
        let eye = up * (datum + self.alt);
        let fov = 60f64.to_radians();
        let near = (0.5 * self.alt).clamp(0.05, 1.0e5);
        View {
            eye,
            frustum: Some(frustum_planes(
                eye,
                forward,
                up,
                fov,
                16.0 / 9.0,
                near,
                eye.length() + 2.5 * datum,
            )),
            viewport_height_px: height_px,
            fov_y: fov,
        }
    }
}

/// What one request was for.
type Want = (ChunkKey, u8);

fn chunk_path(w: &Want) -> String {
    let k = w.0;
    format!(
        "/api/v1/chunk/{}/{}/{}/{}/{}?seams={}",
        k.face.name(),
        k.level,
        k.i,
        k.j,
        k.k,
        w.1
    )
}

/// One viewer, until `end`.
#[allow(clippy::too_many_arguments)]
async fn viewer(
    index: usize,
    args: Arc<Args>,
    addr: SocketAddr,
    planet: Arc<PlanetView>,
    cpu: Arc<Semaphore>,
    totals: Arc<Mutex<Totals>>,
    end: Instant,
) {
    let mut rng = Rng(args.rng_seed.wrapping_mul(0x1000_0001).wrapping_add(index as u64));
    let mut camera = Camera::random(&mut rng);
    let (done_tx, mut done_rx) = mpsc::unbounded_channel::<(Want, Outcome)>();
    let mut inflight: HashMap<Want, tokio::task::JoinHandle<()>> = HashMap::new();
    let mut loaded: HashSet<Want> = HashSet::new();
    let mut wanted: Vec<Want> = Vec::new();
    let mut retry_at: HashMap<Want, Instant> = HashMap::new();
    // the viewers start spread over the first second
    let mut next_tick = Instant::now() + Duration::from_secs_f64(rng.unit());
    loop {
        let now = Instant::now();
        if now >= end {
            break;
        }
        if now >= next_tick {
            camera.step(&mut rng, planet.datum);
            let view = camera.view(planet.datum, args.viewport_height);
            let params = LodParams {
                max_pixel_error: args.pixel_error,
                max_chunks: args.max_chunks,
                ..LodParams::default()
            };
            let permit = cpu.clone().acquire_owned().await.expect("the semaphore stays open");
            let p = planet.clone();
            let t0 = Instant::now();
            let selection = tokio::task::spawn_blocking(move || {
                let _permit = permit;
                p.selector.select(&view, &params)
            })
            .await
            .expect("the selection runs");
            let spent = t0.elapsed().as_secs_f64();
            if let Ok(sel) = selection {
                // coarse first: the whole view covers quickly, as in the viewer
                let mut drawn: Vec<_> = sel.chunks.iter().filter(|s| s.drawn).collect();
                drawn.sort_by_key(|s| std::cmp::Reverse(s.key.level));
                wanted = drawn.iter().map(|s| (s.key, s.coarser.0)).collect();
                let keep: HashSet<Want> = wanted.iter().copied().collect();
                inflight.retain(|w, task| {
                    let still = keep.contains(w);
                    if !still {
                        task.abort();
                        totals.lock().unwrap().cancelled += 1;
                    }
                    still
                });
                if loaded.len() > 4 * args.max_chunks {
                    loaded.retain(|w| keep.contains(w));
                }
                retry_at.retain(|w, _| keep.contains(w));
            }
            let mut t = totals.lock().unwrap();
            t.selections += 1;
            t.selection_seconds += spent;
            drop(t);
            next_tick = Instant::now() + Duration::from_secs_f64(rng.range(0.8, 1.2));
        }
        // request what is wanted and not there, a few at a time
        let now = Instant::now();
        for w in &wanted {
            if inflight.len() >= args.concurrency {
                break;
            }
            if loaded.contains(w) || inflight.contains_key(w) || retry_at.get(w).is_some_and(|t| *t > now) {
                continue;
            }
            let tx = done_tx.clone();
            let want = *w;
            let task = tokio::spawn(async move {
                let outcome = get(addr, &chunk_path(&want)).await;
                let _ = tx.send((want, outcome));
            });
            inflight.insert(want, task);
        }
        let wait = next_tick.min(end).saturating_duration_since(Instant::now());
        tokio::select! {
            Some((want, outcome)) = done_rx.recv() => {
                if inflight.remove(&want).is_none() {
                    continue; // cancelled meanwhile
                }
                let mut t = totals.lock().unwrap();
                match outcome {
                    Outcome::Answer { status: 200, seconds, .. } | Outcome::Answer { status: 304, seconds, .. } => {
                        t.latencies.push(seconds);
                        *t.by_status.entry(200).or_default() += 1;
                        loaded.insert(want);
                    }
                    Outcome::Answer { status: 503, retry_after, .. } => {
                        *t.by_status.entry(503).or_default() += 1;
                        if retry_after.is_none() {
                            t.busy_without_retry_after += 1;
                        }
                        retry_at.insert(want, Instant::now() + Duration::from_secs_f64(retry_after.unwrap_or(1.0).clamp(0.05, 10.0)));
                    }
                    Outcome::Answer { status, .. } => {
                        *t.by_status.entry(status).or_default() += 1;
                        t.unexpected_count += 1;
                        if t.unexpected.len() < 10 {
                            t.unexpected.push(format!("{status} {}", chunk_path(&want)));
                        }
                        loaded.insert(want); // not asked again
                    }
                    Outcome::Transport(e) => {
                        t.transport_errors += 1;
                        if t.transport_examples.len() < 5 {
                            t.transport_examples.push(e);
                        }
                        retry_at.insert(want, Instant::now() + Duration::from_secs(1));
                    }
                }
            }
            _ = tokio::time::sleep(wait) => {}
        }
    }
    // the viewer leaves: its requests go with it
    for (_, task) in inflight.drain() {
        task.abort();
        totals.lock().unwrap().cancelled += 1;
    }
}

/// `VmRSS` or `VmHWM` of `pid`, bytes.
fn memory(pid: u32, field: &str) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = s.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((p / 100.0) * (sorted.len() - 1) as f64).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

async fn run(args: Args) -> Result<bool, LoadError> {
    let args = Arc::new(args);
    let mut child = None;
    let (base, pid) = match (&args.pmc, &args.url) {
        (Some(pmc), _) => {
            let mut cmd = tokio::process::Command::new(pmc);
            cmd.args([
                "serve",
                "--port",
                "0",
                "--preset",
                &args.preset,
                "--seed",
                &args.seed.to_string(),
            ])
            .args(&args.serve_args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .kill_on_drop(true);
            let mut c = cmd.spawn().map_err(|e| LoadError::Setup(format!("{pmc}: {e}")))?;
            let pid = c.id();
            let mut lines = tokio::io::BufReader::new(c.stdout.take().expect("piped")).lines();
            let url = loop {
                match lines.next_line().await {
                    Ok(Some(l)) => {
                        if let Some(u) = l.split("PMC viewer: ").nth(1) {
                            break u.trim().to_string();
                        }
                    }
                    _ => return Err(LoadError::Setup(format!("{pmc} serve ended before printing its URL"))),
                }
            };
            // keep reading its output so that it never blocks on a full pipe
            tokio::spawn(async move { while let Ok(Some(_)) = lines.next_line().await {} });
            child = Some(c);
            (url, pid)
        }
        (None, Some(url)) => (url.clone(), args.pid),
        (None, None) => return Err(LoadError::Setup("give --pmc PATH or --url URL".into())),
    };
    let host = base
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .split('/')
        .next()
        .unwrap_or_default()
        .to_string();
    let addr: SocketAddr = tokio::net::lookup_host(&host)
        .await
        .map_err(|e| LoadError::Setup(format!("{host}: {e}")))?
        .next()
        .ok_or_else(|| LoadError::Setup(format!("{host}: no address")))?;

    let info = get_json(addr, "/api/v1/planet").await?;
    let l = &info["layout"];
    let num = |v: &Value, what: &str| {
        v.as_f64()
            .ok_or_else(|| LoadError::Setup(format!("/planet lacks {what}")))
    };
    let layout = Layout::new(
        num(&l["n_c"], "layout.n_c")? as u32,
        num(&l["n_t"], "layout.n_t")? as u32,
        num(&l["d_b"], "layout.d_b")?,
        num(&l["l_d"], "layout.l_d")?,
        num(&l["d_c"], "layout.d_c")? as u32,
    )
    .map_err(|e| LoadError::Setup(format!("the server's layout: {e}")))?;
    let errors: Vec<f64> = info["lod"]["errors"]
        .as_array()
        .ok_or_else(|| LoadError::Setup("/planet lacks lod.errors".into()))?
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::INFINITY))
        .collect();
    let occluder = num(&info["lod"]["occluder_radius"], "lod.occluder_radius")?;
    let datum = info["sea_radius"]
        .as_f64()
        .unwrap_or((layout.d_b() + layout.radius()) / 2.0);
    let selector =
        Selector::new(layout, errors, occluder).map_err(|e| LoadError::Setup(format!("the selection: {e}")))?;
    let planet = Arc::new(PlanetView {
        layout,
        selector,
        datum,
    });
    let before = get_json(addr, "/api/v1/stats").await?;
    println!(
        "{} viewers for {} s against {base} ({} {}, radius {:.0} m, {} levels), {} requests each at most",
        args.viewers,
        args.seconds,
        info["preset"].as_str().unwrap_or("elevation model"),
        info["seed"].as_str().unwrap_or("?"),
        planet.layout.radius(),
        usize::from(planet.layout.max_level()) + 1,
        args.concurrency
    );

    let totals = Arc::new(Mutex::new(Totals::default()));
    // the selections run on one core: the server keeps the other
    let cpu = Arc::new(Semaphore::new(1));
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(args.seconds);
    let peak = Arc::new(Mutex::new(0u64));
    let sampler = pid.map(|pid| {
        let peak = peak.clone();
        tokio::spawn(async move {
            loop {
                if let Some(rss) = memory(pid, "VmRSS:") {
                    let mut p = peak.lock().unwrap();
                    *p = (*p).max(rss);
                }
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
        })
    });
    let tasks: Vec<_> = (0..args.viewers)
        .map(|i| {
            tokio::spawn(viewer(
                i,
                args.clone(),
                addr,
                planet.clone(),
                cpu.clone(),
                totals.clone(),
                end,
            ))
        })
        .collect();
    for t in tasks {
        let _ = t.await;
    }
    let flown = start.elapsed().as_secs_f64();
    tokio::time::sleep(Duration::from_secs_f64(args.settle)).await;
    let after = get_json(addr, "/api/v1/stats").await?;
    if let Some(s) = sampler {
        s.abort();
    }
    let hwm = pid.and_then(|p| memory(p, "VmHWM:"));
    let peak_rss = hwm.unwrap_or(0).max(*peak.lock().unwrap());

    let mut t = std::mem::take(&mut *totals.lock().unwrap());
    t.latencies.sort_by(f64::total_cmp);
    let ms = |s: f64| s * 1000.0;
    let answered: u64 = t.by_status.values().sum();
    let mut statuses: Vec<_> = t.by_status.iter().collect();
    statuses.sort();
    println!(
        "flown {flown:.1} s; {} selections, {:.1} ms each on average",
        t.selections,
        ms(t.selection_seconds / t.selections.max(1) as f64)
    );
    println!(
        "answers: {answered} ({}), {} cancelled, {} connection errors",
        statuses
            .iter()
            .map(|(s, n)| format!("{s}: {n}"))
            .collect::<Vec<_>>()
            .join(", "),
        t.cancelled,
        t.transport_errors
    );
    println!(
        "chunk latency (200): p50 {:.0} ms, p90 {:.0} ms, p99 {:.0} ms, max {:.0} ms over {} answers",
        ms(percentile(&t.latencies, 50.0)),
        ms(percentile(&t.latencies, 90.0)),
        ms(percentile(&t.latencies, 99.0)),
        ms(t.latencies.last().copied().unwrap_or(f64::NAN)),
        t.latencies.len()
    );
    let jobs = &after["jobs"];
    let gen = |v: &Value| v["generated"].as_u64().unwrap_or(0);
    let dropped = |v: &Value| v["jobs"]["dropped"].as_u64().unwrap_or(0);
    println!(
        "server: {} chunks generated, {} jobs dropped (their clients hung up), {} answered 503; {:.0} s after the viewers left: {} jobs queued, {} running, {} requests waiting",
        gen(&after) - gen(&before),
        dropped(&after) - dropped(&before),
        after["rejected_busy"].as_u64().unwrap_or(0) - before["rejected_busy"].as_u64().unwrap_or(0),
        args.settle,
        jobs["queued"],
        jobs["running"],
        jobs["waiting"]
    );
    if pid.is_some() {
        println!("server peak RSS: {:.0} MiB", peak_rss as f64 / (1u64 << 20) as f64);
    } else {
        println!("server RSS: unknown (give --pid with --url)");
    }

    let mut ok = true;
    let mut fail = |what: String| {
        ok = false;
        println!("FAIL: {what}");
    };
    if t.unexpected_count > 0 {
        fail(format!(
            "{} answers other than 200, 304 and 503: {}",
            t.unexpected_count,
            t.unexpected.join("; ")
        ));
    }
    if t.busy_without_retry_after > 0 {
        fail(format!("{} 503s without Retry-After", t.busy_without_retry_after));
    }
    if t.transport_errors > 0 {
        fail(format!(
            "{} connection errors: {}",
            t.transport_errors,
            t.transport_examples.join("; ")
        ));
    }
    if jobs["queued"].as_u64() != Some(0) || jobs["running"].as_u64() != Some(0) {
        fail(format!("jobs left {} s after the viewers left: {jobs}", args.settle));
    }
    if pid.is_some() && peak_rss > args.max_rss_mb << 20 {
        fail(format!(
            "server RSS {} MiB over {} MiB",
            peak_rss >> 20,
            args.max_rss_mb
        ));
    }
    if t.latencies.is_empty() {
        fail("no chunk was answered".into());
    }
    if let Some(mut c) = child {
        let _ = c.kill().await;
    }
    println!("{}", if ok { "load test passed" } else { "load test FAILED" });
    Ok(ok)
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a runtime");
    match runtime.block_on(run(args)) {
        Ok(true) => std::process::ExitCode::SUCCESS,
        Ok(false) => std::process::ExitCode::from(1),
        Err(e) => {
            eprintln!("pmc-load: {e}");
            std::process::ExitCode::from(2)
        }
    }
}
