//! The few most recently used planets.

use crate::generator::PlanetId;
use pmc_geometry::Layout;
use pmc_planet::Planet;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// At most `max` planets of one layout, most recently used last.
pub(crate) struct Planets {
    layout: Layout,
    max: usize,
    /// The only planet served, already built (a height-field planet, whose layout is its own).
    pinned: Option<(PlanetId, Planet)>,
    list: Mutex<VecDeque<(PlanetId, Arc<Planet>)>>,
}

impl Planets {
    /// An empty set of at most `max` planets.
    pub fn new(layout: Layout, max: usize, pinned: Option<(PlanetId, Planet)>) -> Planets {
        Planets {
            layout,
            max: max.max(1),
            pinned,
            list: Mutex::new(VecDeque::new()),
        }
    }

    fn list(&self) -> MutexGuard<'_, VecDeque<(PlanetId, Arc<Planet>)>> {
        self.list.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The planet `id`, marked as just used, if it is held.
    pub fn get(&self, id: PlanetId) -> Option<Arc<Planet>> {
        let mut list = self.list();
        let at = list.iter().position(|(p, _)| *p == id)?;
        let entry = list.remove(at)?;
        let planet = Arc::clone(&entry.1);
        list.push_back(entry);
        Some(planet)
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
        let mut list = self.list();
        if let Some(at) = list.iter().position(|(p, _)| *p == id) {
            if let Some(entry) = list.remove(at) {
                let planet = Arc::clone(&entry.1);
                list.push_back(entry);
                return (planet, Vec::new());
            }
        }
        let planet = Arc::new(planet);
        list.push_back((id, Arc::clone(&planet)));
        let mut dropped = Vec::new();
        while list.len() > self.max {
            if let Some((old, _)) = list.pop_front() {
                dropped.push(old);
            }
        }
        (planet, dropped)
    }

    /// Number of planets held.
    pub fn len(&self) -> usize {
        self.list().len()
    }
}
