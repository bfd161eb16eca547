//! The state shared by every request.

use crate::editing::{Action, Editing, Outcome};
use crate::generator::{ChunkError, ChunkId, Generator, PlanetId};
use crate::planets::Planets;
use crate::{ServerConfig, ServerError};
use axum::body::Bytes;
use pmc_nav::{Agent, NavGrid};
use pmc_planet::Planet;
use std::sync::{Arc, PoisonError};

/// The server's state: its settings, the planets it holds, the chunk generator and cache. Cheap
/// to clone (shared).
#[derive(Clone)]
pub struct AppState {
    inner: Arc<Inner>,
}

struct Inner {
    config: ServerConfig,
    planets: Planets,
    generator: Arc<Generator>,
    editing: Option<Arc<Editing>>,
    /// The imagery draped on the default planet, if any.
    imagery: Option<Arc<crate::imagery_api::ServedImagery>>,
    /// The relief of the default planet when it is an elevation model's.
    relief: Option<Arc<crate::relief_api::ServedRelief>>,
    /// Navigation grids recently used, most recent last.
    navs: std::sync::Mutex<std::collections::VecDeque<NavEntry>>,
    /// Set when the server begins to stop: long-lived answers (the event streams) end.
    stopping: tokio::sync::watch::Sender<bool>,
    /// The 3D Tiles of the default planet.
    tiles: crate::tiles_api::ServedTiles,
    /// Measured level-of-detail errors (metres per level) by planet, computed once each.
    lod_errors: std::sync::Mutex<std::collections::HashMap<PlanetId, Arc<Vec<f64>>>>,
}

/// Most cells measured per level when measuring level-of-detail errors (fewer where the
/// estimate settles first): the 18 levels of the earth preset at true scale take a few tenths of
/// a second on one core.
const LOD_ERROR_SAMPLES: usize = 1024;

/// Navigation grids kept besides the world's default one.
const MAX_NAV_GRIDS: usize = 3;

/// A navigation grid of a planet version for an agent.
struct NavEntry {
    planet: PlanetId,
    revision: u64,
    agent: [u64; 4],
    grid: Arc<NavGrid>,
}

fn agent_key(a: &Agent) -> [u64; 4] {
    [a.clearance, a.step_up, a.step_down, a.max_slope].map(f64::to_bits)
}

/// A snapshot of the counters of `/api/v1/stats`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Planets held.
    pub planets: usize,
    /// Encoded chunks in the cache.
    pub cached_chunks: usize,
    /// Bytes of encoded chunks in the cache.
    pub cached_bytes: u64,
    /// Chunks generated since start (once per generation, however many requests shared it).
    pub generated: u64,
    /// Chunk jobs waiting for a worker (the same as `jobs.queued`).
    pub queued: usize,
    /// Chunk jobs being generated (the same as `jobs.running`).
    pub in_flight: usize,
    /// Chunk requests answered 503 because the queue was full.
    pub rejected_busy: u64,
    /// The chunk jobs.
    pub jobs: JobStats,
}

/// The chunk jobs of `/api/v1/stats` (one job per chunk generation, however many requests
/// share it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct JobStats {
    /// Jobs waiting for a worker.
    pub queued: usize,
    /// Jobs a worker is generating.
    pub running: usize,
    /// Requests waiting for a queued or running job (several may share one job).
    pub waiting: usize,
    /// Jobs a worker ran to the end since start, failed ones included.
    pub done: u64,
    /// Jobs dropped from the queue without being generated since start, because every request
    /// waiting for them went away (the clients hung up) before a worker took them.
    pub dropped: u64,
    /// Jobs since start that meshed a chunk of the world again after an edit from its mesh before
    /// the edit: the shading of the vertices the edit did not touch and, without transition
    /// patches, the cubes it cannot change.
    pub reused_shading: u64,
}

impl std::fmt::Debug for AppState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AppState").field("config", &self.inner.config).finish()
    }
}

impl AppState {
    /// The measured geometric error of each level of detail of a planet (metres, index =
    /// level; `pmc_lod::measure_level_errors` with a fixed seed), computed on first use and
    /// kept. Runs on a blocking thread.
    pub(crate) async fn lod_errors(&self, id: PlanetId, planet: Arc<pmc_planet::Planet>) -> Arc<Vec<f64>> {
        if let Some(e) = self
            .inner
            .lod_errors
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .get(&id)
        {
            return e.clone();
        }
        let measured =
            tokio::task::spawn_blocking(move || pmc_lod::measure_level_errors(&planet, LOD_ERROR_SAMPLES, 0x5eed))
                .await
                .map(Arc::new)
                .unwrap_or_else(|_| Arc::new(Vec::new()));
        self.inner
            .lod_errors
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .entry(id)
            .or_insert(measured)
            .clone()
    }

    /// Checks `config`, opens (or creates) its world when it names one, and starts the worker
    /// threads. With a world, [`AppState::config`] holds the world's preset, seed and layout.
    pub fn new(mut config: ServerConfig) -> Result<AppState, ServerError> {
        config.validate()?;
        let imagery = match &config.imagery {
            Some(path) => Some(Arc::new(crate::imagery_api::ServedImagery::new(
                pmc_imagery::Imagery::open(path)?,
            ))),
            None => None,
        };
        let editing = match &config.world {
            None => None,
            Some(path) => {
                let (editing, created) = Editing::open(
                    path,
                    &config.terrain,
                    &config.layout,
                    config.edit_limits,
                    config.base_cache_chunks,
                )?;
                let c = editing.current();
                tracing::info!(
                    "{} world {}: {} active edits, {} undone",
                    if created { "created" } else { "opened" },
                    path.display(),
                    c.active,
                    c.redo
                );
                config.terrain = (*editing.id).clone();
                config.layout = *editing.layout();
                Some(Arc::new(editing))
            }
        };
        let relief = crate::relief_api::ServedRelief::of(&config.terrain, &config.layout)?.map(Arc::new);
        // A height-field planet brings its own (patch) layout: built now, kept as the server's.
        let heightfield = match config.mesher {
            crate::config::Mesher::Heightfield => {
                let planet =
                    pmc_planet::Planet::heightfield(&config.terrain).map_err(|e| ServerError::Config(e.to_string()))?;
                config.layout = *planet.layout();
                Some(planet)
            }
            crate::config::Mesher::Volumetric => None,
        };
        // With a world, the meshes of its planet are kept for reusing their shading after an
        // edit: a quarter of the chunk cache's bytes on top of it.
        let edited = editing.as_ref().map(|e| (e.id.clone(), config.cache_bytes / 4));
        let generator =
            Generator::new(config.threads, config.queue_limit, config.cache_bytes, edited).map_err(|reason| {
                ServerError::Threads {
                    threads: config.threads,
                    reason,
                }
            })?;
        Ok(AppState {
            inner: Arc::new(Inner {
                planets: Planets::new(
                    config.layout,
                    config.max_planets,
                    heightfield.map(|p| (Arc::new(config.terrain.clone()), p)),
                ),
                generator: Arc::new(generator),
                editing,
                imagery,
                relief,
                navs: std::sync::Mutex::new(std::collections::VecDeque::new()),
                lod_errors: std::sync::Mutex::new(std::collections::HashMap::new()),
                // a quarter of the chunk cache's bytes for built subtrees and their contents
                tiles: crate::tiles_api::ServedTiles::new(config.tiles_frame, config.cache_bytes / 4),
                stopping: tokio::sync::watch::Sender::new(false),
                config,
            }),
        })
    }

    /// Tells long-lived answers (the event streams of `/api/v1/events`) to end, so a graceful
    /// shutdown does not wait for clients that never hang up. [`Server::run`](crate::Server::run)
    /// calls it when its shutdown signal completes.
    pub fn begin_shutdown(&self) {
        self.inner.stopping.send_replace(true);
    }

    /// A receiver that turns true when the server begins to stop.
    pub(crate) fn stopping(&self) -> tokio::sync::watch::Receiver<bool> {
        self.inner.stopping.subscribe()
    }

    /// The settings.
    pub fn config(&self) -> &ServerConfig {
        &self.inner.config
    }

    /// The counters of `/api/v1/stats`.
    pub fn stats(&self) -> Stats {
        let g = &self.inner.generator;
        let (cached_chunks, cached_bytes) = g.cache_usage();
        let jobs = g.job_counts();
        Stats {
            planets: self.inner.planets.len(),
            cached_chunks,
            cached_bytes,
            generated: jobs.generated,
            queued: jobs.queued,
            in_flight: jobs.running,
            rejected_busy: jobs.rejected_busy,
            jobs: JobStats {
                queued: jobs.queued,
                running: jobs.running,
                waiting: jobs.waiting,
                done: jobs.done,
                dropped: jobs.dropped,
                reused_shading: jobs.reused,
            },
        }
    }

    /// The chunk generator: its queue and workers also make the 3D Tiles files.
    pub(crate) fn generator(&self) -> &Arc<Generator> {
        &self.inner.generator
    }

    /// The 3D Tiles of the default planet.
    pub(crate) fn tiles(&self) -> &crate::tiles_api::ServedTiles {
        &self.inner.tiles
    }

    /// The imagery draped on the default planet, if the server has one.
    pub fn imagery(&self) -> Option<&Arc<crate::imagery_api::ServedImagery>> {
        self.inner.imagery.as_ref()
    }

    /// The relief of the default planet, if it is an elevation model's that keeps its source grid.
    pub fn relief(&self) -> Option<&Arc<crate::relief_api::ServedRelief>> {
        self.inner.relief.as_ref()
    }

    /// The world being edited, if the server has one.
    pub(crate) fn editing(&self) -> Option<&Arc<Editing>> {
        self.inner.editing.as_ref()
    }

    /// The world being edited, when `id` is its planet.
    pub(crate) fn editing_of(&self, id: PlanetId) -> Option<&Arc<Editing>> {
        self.editing().filter(|e| e.id == id)
    }

    /// The planet `id` and its edit revision (0 for planets that are not edited), built (off the
    /// async runtime) when it is not held.
    /// [`AppState::lod_errors`] of the default planet.
    pub async fn lod_errors_of_default(&self) -> Result<Arc<Vec<f64>>, String> {
        let c = self.config();
        let planet = self.default_planet().await?;
        Ok(self.lod_errors(Arc::new(c.terrain.clone()), planet).await)
    }

    /// The server's default planet (the world's, with its edits, when serving a world).
    pub async fn default_planet(&self) -> Result<Arc<Planet>, String> {
        let c = self.config();
        self.planet(Arc::new(c.terrain.clone())).await.map(|(p, _)| p)
    }

    pub(crate) async fn planet(&self, id: PlanetId) -> Result<(Arc<Planet>, u64), String> {
        if let Some(e) = self.editing_of(id.clone()) {
            let c = e.current();
            return Ok((c.planet, c.revision));
        }
        self.plain_planet(id).await.map(|p| (p, 0))
    }

    async fn plain_planet(&self, id: PlanetId) -> Result<Arc<Planet>, String> {
        if let Some(p) = self.inner.planets.get(id.clone()) {
            return Ok(p);
        }
        let this = self.clone();
        let build_id = id.clone();
        let planet = tokio::task::spawn_blocking(move || this.inner.planets.build(&build_id))
            .await
            .map_err(|e| format!("building the planet failed: {e}"))??;
        let (planet, dropped) = self.inner.planets.insert(id, planet);
        for old in dropped {
            self.inner.generator.forget_planet(old);
        }
        Ok(planet)
    }

    /// The encoded chunk `id`, meshed from the current version of its planet; queued jobs are
    /// served highest `priority` (finite) first. Dropping the future withdraws the request (see
    /// [`Generator::chunk`]).
    pub(crate) async fn chunk(&self, id: ChunkId, priority: f64) -> Result<Bytes, ChunkError> {
        // An edit between taking the planet and asking the generator makes the planet stale for
        // the chunks it changed; take the new one and ask again (edits are rate-limited, so this
        // ends).
        loop {
            let (planet, revision) = self
                .planet(id.planet.clone())
                .await
                .map_err(|e| ChunkError::Failed(e.into()))?;
            match self.inner.generator.chunk(planet, revision, id.clone(), priority).await {
                Err(ChunkError::Stale) => continue,
                other => return other,
            }
        }
    }

    /// The navigation grid of planet `id` (its current version) for `agent`, with the planet and
    /// its revision: the world's default-agent grid (kept up to date edit by edit), a recently
    /// used one, or a new one built off the async runtime.
    pub(crate) async fn nav_grid(
        &self,
        id: PlanetId,
        agent: Agent,
    ) -> Result<(Arc<NavGrid>, Arc<Planet>, u64), crate::request::ApiError> {
        use crate::request::ApiError;
        let (planet, revision) = self.planet(id.clone()).await.map_err(ApiError::internal)?;
        let world = self
            .editing_of(id.clone())
            .filter(|_| agent == Agent::default())
            .cloned();
        if let Some(g) = world.as_ref().and_then(|e| e.nav_grid(revision)) {
            return Ok((g, planet, revision));
        }
        let key = agent_key(&agent);
        {
            let mut navs = self.inner.navs.lock().unwrap_or_else(PoisonError::into_inner);
            let at = navs
                .iter()
                .position(|e| e.planet == id && e.revision == revision && e.agent == key);
            if let Some(e) = at.and_then(|at| navs.remove(at)) {
                let g = Arc::clone(&e.grid);
                navs.push_back(e);
                return Ok((g, planet, revision));
            }
        }
        let p = Arc::clone(&planet);
        let grid = tokio::task::spawn_blocking(move || NavGrid::build(p.density().as_ref(), p.layout(), agent))
            .await
            .map_err(|e| ApiError::internal(format!("building the navigation grid failed: {e}")))?
            // Invalid agent limits are checked before, so this is a planet too large for a grid:
            // a limit of the request, not a failure.
            .map_err(|e| ApiError::bad_request(e.to_string()))?;
        let grid = Arc::new(grid);
        match world {
            Some(e) => e.keep_nav_grid(revision, Arc::clone(&grid)),
            None => {
                let mut navs = self.inner.navs.lock().unwrap_or_else(PoisonError::into_inner);
                navs.retain(|e| !(e.planet == id && e.agent == key));
                navs.push_back(NavEntry {
                    planet: id,
                    revision,
                    agent: key,
                    grid: Arc::clone(&grid),
                });
                while navs.len() > MAX_NAV_GRIDS {
                    navs.pop_front();
                }
            }
        }
        Ok((grid, planet, revision))
    }

    /// Performs an edit action on the world (off the async runtime).
    pub(crate) async fn edit(&self, editing: Arc<Editing>, action: Action) -> Result<Outcome, String> {
        let generator = Arc::clone(&self.inner.generator);
        tokio::task::spawn_blocking(move || editing.perform(action, &generator))
            .await
            .map_err(|e| format!("the edit task failed: {e}"))?
            .map_err(|e| e.to_string())
    }

    /// Takes edits made to the world file by other programs (off the async runtime); returns
    /// whether there were any.
    pub async fn sync_world(&self) -> Result<bool, String> {
        let Some(editing) = self.editing().cloned() else {
            return Ok(false);
        };
        let generator = Arc::clone(&self.inner.generator);
        tokio::task::spawn_blocking(move || editing.sync(&generator))
            .await
            .map_err(|e| format!("the world check failed: {e}"))?
            .map_err(|e| e.to_string())
    }
}
