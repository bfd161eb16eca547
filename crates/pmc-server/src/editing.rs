//! Editing the world's planet: the world file, its edit list mirrored in memory, the current
//! edited planet, and the events that tell subscribers what changed.
//!
//! Every change is serialised by one lock and runs on a blocking thread: the world file commits
//! it durably, the mirror and the planet follow, the generator forgets the chunks it changed,
//! and only then are subscribers told. A client that fetches a chunk after the answer (or after
//! the event) gets the edited mesh.

use crate::generator::{ChunkId, Generator, PlanetId};
use crate::rate::RateLimiter;
use crate::{EditLimits, ServerError};
use pmc_edit::{affected_chunks_lod, BrushOp, EditSnapshot};
use pmc_geometry::ChunkKey;
use pmc_geometry::SideMask;
use pmc_nav::NavGrid;
use pmc_planet::{Planet, TerrainSpec};
use pmc_world::{Entry, World, WorldError};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, RwLock};
use tokio::sync::broadcast;

/// Events kept for subscribers that read slowly; one that falls further behind gets `resync`.
const EVENT_BACKLOG: usize = 256;

/// What a client asks the world to do.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Action {
    /// Append an edit.
    Apply(BrushOp),
    /// Take back the last active edit.
    Undo,
    /// Re-apply the most recently undone edit.
    Redo,
}

impl Action {
    fn name(&self) -> &'static str {
        match self {
            Action::Apply(_) => "apply",
            Action::Undo => "undo",
            Action::Redo => "redo",
        }
    }
}

/// What an action did.
#[derive(Clone, Debug, serde::Serialize)]
pub(crate) struct Outcome {
    /// The edit applied, undone or redone (`None`: nothing to undo or redo).
    pub id: Option<u64>,
    /// The revision after the action.
    pub revision: u64,
    /// Active edits after the action.
    pub active: usize,
    /// Undone edits kept for redo after the action.
    pub redo: usize,
    /// The chunks whose meshes the action can change (written as `face/level/i/j/k`).
    #[serde(serialize_with = "keys_as_text")]
    pub chunks: Vec<ChunkKey>,
}

/// A change pushed to subscribers of `/api/v1/events`.
#[derive(Clone, Debug, serde::Serialize)]
pub(crate) struct EditEvent {
    /// `apply`, `undo`, `redo`, or `resync` (reload everything).
    #[serde(skip)]
    pub event: &'static str,
    /// The revision after the change.
    pub revision: u64,
    /// `apply`, `undo` or `redo` (absent for `resync`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub action: Option<&'static str>,
    /// The edit (absent for `resync`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<u64>,
    /// The chunks to reload (empty for `resync`: all of them), written as `face/level/i/j/k`.
    #[serde(serialize_with = "keys_as_text")]
    pub chunks: Vec<ChunkKey>,
}

/// Writes chunk keys in their text form (`face/level/i/j/k`, as the chunk paths of the API).
fn keys_as_text<S: serde::Serializer>(keys: &[ChunkKey], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(keys.iter().map(|k| k.to_string()))
}

/// The edited planet and the counts clients see, replaced as one after each change.
#[derive(Clone, Debug)]
pub(crate) struct Current {
    /// The planet with the active edits.
    pub planet: Arc<Planet>,
    /// Changes since start, plus the active edits at start.
    pub revision: u64,
    /// Active edits.
    pub active: usize,
    /// Undone edits kept for redo.
    pub redo: usize,
}

/// The world file and its mirror, touched only under the lock, on blocking threads.
struct Editor {
    world: World,
    /// Every stored edit in id order: the active ones first, then the undone ones.
    entries: Vec<Entry>,
    /// The file's `data_version` when the mirror was last read from it.
    data_version: i64,
}

impl Editor {
    fn active(&self) -> usize {
        self.entries.iter().take_while(|e| e.active).count()
    }

    fn snapshot(&self) -> EditSnapshot {
        let ops: Vec<BrushOp> = self.entries.iter().filter(|e| e.active).map(|e| e.op).collect();
        EditSnapshot::from(ops)
    }
}

/// The world being served and edited.
pub(crate) struct Editing {
    path: PathBuf,
    /// The planet's identity for requests.
    pub id: PlanetId,
    /// The unedited planet (its base-sample cache shared by every edited version).
    base: Planet,
    editor: Mutex<Editor>,
    current: RwLock<Current>,
    events: broadcast::Sender<EditEvent>,
    /// The navigation grid of the default agent and the revision it is of, once a client asked
    /// for it; kept up to date after each edit by rebuilding only the tiles the edit touched.
    nav: Mutex<Option<(u64, Arc<NavGrid>)>>,
    /// The per-client limit on actions.
    pub rate: RateLimiter,
    /// The limits on brushes and rate.
    pub limits: EditLimits,
}

impl std::fmt::Debug for Editing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Editing")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Editing {
    /// Opens the world at `path`, creating it for `terrain` and `layout` when missing, and
    /// builds its planet with the active edits. Returns the editing state and whether the file
    /// was created.
    pub fn open(
        path: &Path,
        terrain: &TerrainSpec,
        layout: &pmc_geometry::Layout,
        limits: EditLimits,
        base_cache_chunks: usize,
    ) -> Result<(Editing, bool), ServerError> {
        let (world, created) = World::open_or_create(path, terrain, layout)?;
        let (terrain, layout) = world.planet_params();
        let entries = world.entries()?;
        let data_version = world.data_version()?;
        let base = Planet::from_terrain(&terrain, layout)
            .map_err(|e| ServerError::Config(format!("{}: {e}", path.display())))?
            .with_base_cache(base_cache_chunks);
        let editor = Editor {
            world,
            entries,
            data_version,
        };
        let active = editor.active();
        let current = Current {
            planet: Arc::new(base.clone().with_edits(editor.snapshot())),
            revision: active as u64,
            active,
            redo: editor.entries.len() - active,
        };
        let (events, _) = broadcast::channel(EVENT_BACKLOG);
        Ok((
            Editing {
                path: path.to_path_buf(),
                id: Arc::new(terrain),
                base,
                editor: Mutex::new(editor),
                current: RwLock::new(current),
                nav: Mutex::new(None),
                events,
                rate: RateLimiter::new(limits.rate_per_second, limits.burst),
                limits,
            },
            created,
        ))
    }

    /// The world file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The layout of the world's planet.
    pub fn layout(&self) -> &pmc_geometry::Layout {
        self.base.layout()
    }

    /// The current edited planet and counts.
    pub fn current(&self) -> Current {
        self.current.read().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// A new subscriber to the events.
    pub fn subscribe(&self) -> broadcast::Receiver<EditEvent> {
        self.events.subscribe()
    }

    /// The stored edits, oldest first (active ones, then undone ones).
    pub fn entries(&self) -> Vec<Entry> {
        lock(&self.editor).entries.clone()
    }

    /// Performs `action` durably and publishes it (blocking: call it off the async runtime).
    pub fn perform(&self, action: Action, generator: &Generator) -> Result<Outcome, WorldError> {
        let mut ed = lock(&self.editor);
        // Another program may have written the file since we last read it: take its edits first,
        // so undo and redo act on what the file holds.
        self.sync_locked(&mut ed, generator)?;
        let done = match action {
            Action::Apply(op) => {
                let id = ed.world.append(&op)?;
                let active = ed.active();
                ed.entries.truncate(active);
                ed.entries.push(Entry { id, op, active: true });
                Some((id, op))
            }
            Action::Undo => match ed.world.undo()? {
                None => None,
                Some(id) => Some((id, self.flip(&mut ed, id, false)?)),
            },
            Action::Redo => match ed.world.redo()? {
                None => None,
                Some(id) => Some((id, self.flip(&mut ed, id, true)?)),
            },
        };
        let Some((id, op)) = done else {
            let c = self.current();
            return Ok(Outcome {
                id: None,
                revision: c.revision,
                active: c.active,
                redo: c.redo,
                chunks: Vec::new(),
            });
        };
        let keys = affected_chunks_lod(self.base.layout(), &op);
        let current = self.publish(&ed, generator, Some((&keys, &op)));
        self.follow_with_nav(&current, Some(&op));
        let _ = self.events.send(EditEvent {
            event: "edit",
            revision: current.revision,
            action: Some(action.name()),
            id: Some(id.0),
            chunks: keys.clone(),
        });
        Ok(Outcome {
            id: Some(id.0),
            revision: current.revision,
            active: current.active,
            redo: current.redo,
            chunks: keys,
        })
    }

    /// Sets the mirror's entry `id` active or undone and returns its operation. The world picked
    /// `id` by the same rule the mirror follows, so it is the last active (undo) or first undone
    /// (redo) entry; anything else means the mirror is out of step, and it is read again.
    fn flip(&self, ed: &mut Editor, id: pmc_world::EditId, active: bool) -> Result<BrushOp, WorldError> {
        let at = ed.active();
        let expected = if active { at } else { at.wrapping_sub(1) };
        match ed.entries.get_mut(expected).filter(|e| e.id == id) {
            Some(e) => {
                e.active = active;
                Ok(e.op)
            }
            None => {
                ed.entries = ed.world.entries()?;
                ed.entries
                    .iter()
                    .find(|e| e.id == id)
                    .map(|e| e.op)
                    .ok_or_else(|| WorldError::Corrupt {
                        path: self.path.clone(),
                        detail: format!("edit {id} vanished while it was being undone or redone"),
                    })
            }
        }
    }

    /// Builds the planet of the mirror's active edits, makes it current (one revision later),
    /// and makes the generator forget the chunks `keys` that the edit `op` changed (every chunk
    /// when `None`).
    fn publish(&self, ed: &Editor, generator: &Generator, keys: Option<(&[ChunkKey], &BrushOp)>) -> Current {
        let planet = Arc::new(self.base.clone().with_edits(ed.snapshot()));
        let active = ed.active();
        let current = {
            let mut c = self.current.write().unwrap_or_else(PoisonError::into_inner);
            *c = Current {
                planet,
                revision: c.revision + 1,
                active,
                redo: ed.entries.len() - active,
            };
            c.clone()
        };
        // The new planet is current before the old meshes are forgotten: a job started from
        // here on meshes the edit (see `Generator::invalidate`).
        match keys {
            Some((keys, op)) => {
                let layout = self.base.layout();
                generator.invalidate(
                    keys.iter().flat_map(|key| {
                        // Every seam variant of the chunk: the submasks of its seam sides.
                        let sides = layout.seam_sides(key).0;
                        (0..=sides).filter(move |m| m & !sides == 0).map(move |m| ChunkId {
                            planet: self.id.clone(),
                            key: *key,
                            seams: SideMask(m),
                        })
                    }),
                    current.revision,
                    Some(op),
                )
            }
            None => generator.invalidate_planet(self.id.clone(), current.revision),
        }
        current
    }

    /// Brings the default agent's navigation grid to `current` after one edit `op` (rebuilding
    /// the tiles it touched), or drops it when the change was not one edit or the grid was not of
    /// the revision before. Called under the editor lock, so edits reach the grid in order.
    fn follow_with_nav(&self, current: &Current, op: Option<&BrushOp>) {
        let mut nav = lock(&self.nav);
        let next = match (nav.take(), op) {
            (Some((rev, mut grid)), Some(op)) if rev + 1 == current.revision => {
                // In place unless a query is reading it right now.
                // From the planet's base cache where it holds the chunks: only the edits are
                // applied.
                Arc::make_mut(&mut grid).rebuild_for_from(current.planet.as_ref(), op);
                Some((current.revision, grid))
            }
            _ => None,
        };
        *nav = next;
    }

    /// The default agent's navigation grid, if one is held for `revision`.
    pub fn nav_grid(&self, revision: u64) -> Option<Arc<NavGrid>> {
        lock(&self.nav)
            .as_ref()
            .filter(|(rev, _)| *rev == revision)
            .map(|(_, g)| Arc::clone(g))
    }

    /// Keeps `grid`, built for `revision`, as the default agent's grid if that is still the
    /// current revision (an edit may have come meanwhile).
    pub fn keep_nav_grid(&self, revision: u64, grid: Arc<NavGrid>) {
        let mut nav = lock(&self.nav);
        if self.current().revision == revision && nav.as_ref().is_none_or(|(rev, _)| *rev < revision) {
            *nav = Some((revision, grid));
        }
    }

    /// Reads the world file again when another program changed it, making its edits current and
    /// telling subscribers to reload everything. Returns whether it changed (blocking).
    pub fn sync(&self, generator: &Generator) -> Result<bool, WorldError> {
        let mut ed = lock(&self.editor);
        self.sync_locked(&mut ed, generator)
    }

    fn sync_locked(&self, ed: &mut Editor, generator: &Generator) -> Result<bool, WorldError> {
        let version = ed.world.data_version()?;
        if version == ed.data_version {
            return Ok(false);
        }
        let entries = ed.world.entries()?;
        ed.data_version = version;
        if entries == ed.entries {
            return Ok(false);
        }
        let step = one_step(&ed.entries, &entries);
        ed.entries = entries;
        let keys = step.map(|(_, _, op)| affected_chunks_lod(self.base.layout(), &op));
        let current = self.publish(ed, generator, keys.as_deref().zip(step.as_ref().map(|(_, _, op)| op)));
        self.follow_with_nav(&current, step.as_ref().map(|(_, _, op)| op));
        tracing::info!(
            "{} was changed by another program: {} active edits, revision {}",
            self.path.display(),
            current.active,
            current.revision
        );
        let event = match (step, keys) {
            (Some((action, id, _)), Some(keys)) => EditEvent {
                event: "edit",
                revision: current.revision,
                action: Some(action),
                id: Some(id.0),
                chunks: keys,
            },
            _ => EditEvent {
                event: "resync",
                revision: current.revision,
                action: None,
                id: None,
                chunks: Vec::new(),
            },
        };
        let _ = self.events.send(event);
        Ok(true)
    }
}

/// The single step (apply, undo or redo) that turns the edit list `old` into `new`, if there is
/// one.
fn one_step(old: &[Entry], new: &[Entry]) -> Option<(&'static str, pmc_world::EditId, BrushOp)> {
    let active_old = old.iter().take_while(|e| e.active).count();
    // One edit appended after the active ones (the undone ones discarded).
    if new.len() == active_old + 1 && new[..active_old] == old[..active_old] {
        let last = new[active_old];
        if last.active && old.iter().all(|e| e.id != last.id) {
            return Some(("apply", last.id, last.op));
        }
    }
    // One edit undone or redone: the same edits, one flag changed.
    if new.len() == old.len() && new.iter().zip(old).all(|(a, b)| a.id == b.id && a.op == b.op) {
        let mut changed = new.iter().zip(old).filter(|(a, b)| a.active != b.active);
        if let (Some((e, _)), None) = (changed.next(), changed.next()) {
            return Some((if e.active { "redo" } else { "undo" }, e.id, e.op));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_edit::BrushKind;
    use pmc_geometry::glam::DVec3;
    use pmc_world::EditId;

    fn entry(id: u64, active: bool) -> Entry {
        Entry {
            id: EditId(id),
            op: BrushOp::new(BrushKind::Remove, DVec3::new(id as f64, 0.0, 100.0), 2.0, 1.0).unwrap(),
            active,
        }
    }

    #[test]
    fn single_steps_are_recognised_and_others_are_not() {
        let old = vec![entry(1, true), entry(2, true), entry(3, false)];
        let applied = vec![entry(1, true), entry(2, true), entry(4, true)];
        assert_eq!(one_step(&old, &applied).map(|s| (s.0, s.1)), Some(("apply", EditId(4))));
        let undone = vec![entry(1, true), entry(2, false), entry(3, false)];
        assert_eq!(one_step(&old, &undone).map(|s| (s.0, s.1)), Some(("undo", EditId(2))));
        let redone = vec![entry(1, true), entry(2, true), entry(3, true)];
        assert_eq!(one_step(&old, &redone).map(|s| (s.0, s.1)), Some(("redo", EditId(3))));
        let two = vec![entry(1, true), entry(2, true), entry(4, true), entry(5, true)];
        assert!(one_step(&old, &two).is_none(), "two appends are not one step");
        let both = vec![entry(1, false), entry(2, false), entry(3, false)];
        assert!(one_step(&old, &both).is_none(), "two undos are not one step");
        let replaced = vec![entry(1, true), entry(2, true), entry(3, true), entry(7, true)];
        assert!(one_step(&old, &replaced).is_none());
        assert!(one_step(&old, &[]).is_none(), "a cleared world is not one step");
    }
}
