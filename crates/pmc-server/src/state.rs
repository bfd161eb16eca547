//! The state shared by every request.

use crate::generator::{ChunkError, ChunkId, Generator, PlanetId};
use crate::planets::Planets;
use crate::{ServerConfig, ServerError};
use axum::body::Bytes;
use pmc_planet::Planet;
use std::sync::atomic::Ordering;
use std::sync::Arc;

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
    /// Chunk jobs waiting for a worker.
    pub queued: usize,
    /// Chunk jobs being generated.
    pub in_flight: usize,
    /// Chunk requests answered 503 because the queue was full.
    pub rejected_busy: u64,
}

impl std::fmt::Debug for AppState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AppState").field("config", &self.inner.config).finish()
    }
}

impl AppState {
    /// Checks `config` and starts the worker threads.
    pub fn new(config: ServerConfig) -> Result<AppState, ServerError> {
        config.validate()?;
        let generator = Generator::new(config.threads, config.queue_limit, config.cache_bytes).map_err(|reason| {
            ServerError::Threads {
                threads: config.threads,
                reason,
            }
        })?;
        Ok(AppState {
            inner: Arc::new(Inner {
                planets: Planets::new(config.layout, config.max_planets),
                generator: Arc::new(generator),
                config,
            }),
        })
    }

    /// The settings.
    pub fn config(&self) -> &ServerConfig {
        &self.inner.config
    }

    /// The counters of `/api/v1/stats`.
    pub fn stats(&self) -> Stats {
        let g = &self.inner.generator;
        let (cached_chunks, cached_bytes) = g.cache_usage();
        Stats {
            planets: self.inner.planets.len(),
            cached_chunks,
            cached_bytes,
            generated: g.counters.generated.load(Ordering::Relaxed),
            queued: g.counters.queued.load(Ordering::SeqCst),
            in_flight: g.counters.in_flight.load(Ordering::SeqCst),
            rejected_busy: g.counters.rejected_busy.load(Ordering::Relaxed),
        }
    }

    /// The planet `id`, built (off the async runtime) when it is not held.
    pub(crate) async fn planet(&self, id: PlanetId) -> Result<Arc<Planet>, String> {
        if let Some(p) = self.inner.planets.get(id) {
            return Ok(p);
        }
        let this = self.clone();
        let planet = tokio::task::spawn_blocking(move || this.inner.planets.build(id))
            .await
            .map_err(|e| format!("building the planet failed: {e}"))?;
        let (planet, dropped) = self.inner.planets.insert(id, planet);
        for old in dropped {
            self.inner.generator.forget_planet(old);
        }
        Ok(planet)
    }

    /// The encoded chunk `id` of `planet`.
    pub(crate) async fn chunk(&self, planet: Arc<Planet>, id: ChunkId) -> Result<Bytes, ChunkError> {
        self.inner.generator.chunk(planet, id).await
    }
}
