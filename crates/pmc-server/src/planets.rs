//! The few most recently used planets.

use crate::generator::PlanetId;
use pmc_geometry::Layout;
use pmc_planet::Planet;
use quick_cache::unsync::Cache;
use quick_cache::{DefaultHashBuilder, Lifecycle, UnitWeighter};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// Collects the ids of the planets the cache drops, so that their chunks can be dropped too.
#[derive(Clone, Copy, Debug, Default)]
struct CollectDropped;

impl Lifecycle<PlanetId, Arc<Planet>> for CollectDropped {
    type RequestState = Vec<PlanetId>;

    fn on_evict(&self, dropped: &mut Vec<PlanetId>, id: PlanetId, _planet: Arc<Planet>) {
        dropped.push(id);
    }
}

type PlanetCache = Cache<PlanetId, Arc<Planet>, UnitWeighter, DefaultHashBuilder, CollectDropped>;

/// At most `max` planets of one layout; when full, planets asked for again are kept over
/// planets asked for once (`quick_cache`'s policy).
pub(crate) struct Planets {
    layout: Layout,
    /// The only planet served, already built (a height-field planet, whose layout is its own).
    pinned: Option<(PlanetId, Planet)>,
    cache: Mutex<PlanetCache>,
}

impl Planets {
    /// An empty set of at most `max` planets.
    pub fn new(layout: Layout, max: usize, pinned: Option<(PlanetId, Planet)>) -> Planets {
        let max = max.max(1);
        Planets {
            layout,
            pinned,
            cache: Mutex::new(Cache::with(
                max,
                max as u64,
                UnitWeighter,
                DefaultHashBuilder::default(),
                CollectDropped,
            )),
        }
    }

    fn cache(&self) -> MutexGuard<'_, PlanetCache> {
        self.cache.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The planet `id`, marked as used, if it is held.
    pub fn get(&self, id: PlanetId) -> Option<Arc<Planet>> {
        self.cache().get(&id).cloned()
    }

    /// Builds planet `id` (the caller runs this off the async runtime).
    pub fn build(&self, id: &PlanetId) -> Result<Planet, String> {
        if let Some((pinned, planet)) = &self.pinned {
            return if pinned == id {
                Ok(planet.clone())
            } else {
                Err(format!(
                    "this server meshes {} as a height field and serves no other planet",
                    pinned.name()
                ))
            };
        }
        Planet::from_terrain(id, self.layout).map_err(|e| e.to_string())
    }

    /// Adds `planet` as `id` (keeping one already added by a concurrent request) and returns the
    /// planet to use and the planets dropped to make room.
    pub fn insert(&self, id: PlanetId, planet: Planet) -> (Arc<Planet>, Vec<PlanetId>) {
        let mut cache = self.cache();
        if let Some(held) = cache.get(&id) {
            return (Arc::clone(held), Vec::new());
        }
        let planet = Arc::new(planet);
        let mut dropped = Vec::new();
        cache.insert_with_lifecycle(id, Arc::clone(&planet), &mut dropped);
        (planet, dropped)
    }

    /// Number of planets held.
    pub fn len(&self) -> usize {
        self.cache().len()
    }
}
