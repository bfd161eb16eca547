//! The edit log: an ordered list of brush operations with undo and redo, and cheap snapshots for
//! readers.
//!
//! The editor owns the [`EditLog`] and appends to it; meshing threads hold an [`EditSnapshot`], an
//! immutable, reference-counted copy of the active operations, so they always see one consistent
//! list however the log changes meanwhile. Cloning a snapshot is one atomic increment; taking one
//! from the log copies the active list once after each change (and is free until the next one).

use crate::brush::BrushOp;
use std::sync::{Arc, OnceLock};

/// Identity of an operation pushed onto an [`EditLog`]: unique within the log, increasing in push
/// order (a redone operation keeps its id).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EditId(pub u64);

/// An immutable list of brush operations, in the order they apply. Cheap to clone and to share
/// between threads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EditSnapshot {
    ops: Arc<[BrushOp]>,
}

impl EditSnapshot {
    /// A snapshot holding `ops`, applied in order.
    pub fn new(ops: impl Into<Arc<[BrushOp]>>) -> EditSnapshot {
        EditSnapshot { ops: ops.into() }
    }

    /// The operations, in the order they apply.
    pub fn ops(&self) -> &[BrushOp] {
        &self.ops
    }

    /// Whether the snapshot holds no operation.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// Number of operations.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Whether two snapshots share the same storage (so are equal without comparing).
    pub fn ptr_eq(&self, other: &EditSnapshot) -> bool {
        Arc::ptr_eq(&self.ops, &other.ops)
    }
}

impl std::ops::Deref for EditSnapshot {
    type Target = [BrushOp];
    fn deref(&self) -> &[BrushOp] {
        &self.ops
    }
}

impl From<Vec<BrushOp>> for EditSnapshot {
    fn from(ops: Vec<BrushOp>) -> Self {
        EditSnapshot::new(ops)
    }
}

impl From<&[BrushOp]> for EditSnapshot {
    fn from(ops: &[BrushOp]) -> Self {
        EditSnapshot::new(ops)
    }
}

/// An ordered list of brush operations with undo and redo.
///
/// The first [`EditLog::active`] operations apply; the ones after them are the redo tail (undone
/// operations, most recently undone first in line). Pushing a new operation drops the redo tail.
#[derive(Clone, Debug, Default)]
pub struct EditLog {
    ops: Vec<BrushOp>,
    ids: Vec<EditId>,
    active: usize,
    next_id: u64,
    snapshot: OnceLock<EditSnapshot>,
}

impl EditLog {
    /// An empty log.
    pub fn new() -> EditLog {
        EditLog::default()
    }

    /// A log whose active operations are `ops`, in order (for instance loaded from a world file),
    /// with ids `0, 1, ...` and nothing to redo.
    pub fn from_ops(ops: impl IntoIterator<Item = BrushOp>) -> EditLog {
        let mut log = EditLog::new();
        for op in ops {
            log.push(op);
        }
        log
    }

    fn changed(&mut self) {
        self.snapshot = OnceLock::new();
    }

    /// Appends `op` after the active operations, dropping the redo tail, and returns its id.
    pub fn push(&mut self, op: BrushOp) -> EditId {
        self.ops.truncate(self.active);
        self.ids.truncate(self.active);
        let id = EditId(self.next_id);
        self.next_id += 1;
        self.ops.push(op);
        self.ids.push(id);
        self.active += 1;
        self.changed();
        id
    }

    /// Undoes the last active operation and returns it (`None` when there is nothing to undo).
    /// It moves to the front of the redo tail.
    pub fn undo(&mut self) -> Option<BrushOp> {
        if self.active == 0 {
            return None;
        }
        self.active -= 1;
        self.changed();
        Some(self.ops[self.active])
    }

    /// Re-applies the most recently undone operation and returns it (`None` when there is nothing
    /// to redo).
    pub fn redo(&mut self) -> Option<BrushOp> {
        if self.active == self.ops.len() {
            return None;
        }
        self.active += 1;
        self.changed();
        Some(self.ops[self.active - 1])
    }

    /// The operations that apply, in order.
    pub fn active(&self) -> &[BrushOp] {
        &self.ops[..self.active]
    }

    /// The ids of the active operations, parallel to [`EditLog::active`].
    pub fn active_ids(&self) -> &[EditId] {
        &self.ids[..self.active]
    }

    /// Number of active operations.
    pub fn len(&self) -> usize {
        self.active
    }

    /// Whether no operation is active.
    pub fn is_empty(&self) -> bool {
        self.active == 0
    }

    /// Whether [`EditLog::undo`] would undo something.
    pub fn can_undo(&self) -> bool {
        self.active > 0
    }

    /// Whether [`EditLog::redo`] would redo something.
    pub fn can_redo(&self) -> bool {
        self.active < self.ops.len()
    }

    /// Number of undone operations that [`EditLog::redo`] can bring back.
    pub fn redo_len(&self) -> usize {
        self.ops.len() - self.active
    }

    /// An immutable snapshot of the active operations, for readers on other threads. Repeated
    /// calls without a change in between return the same storage.
    pub fn snapshot(&self) -> EditSnapshot {
        self.snapshot.get_or_init(|| EditSnapshot::new(self.active())).clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::BrushKind;
    use pmc_geometry::glam::DVec3;

    fn op(x: f64) -> BrushOp {
        BrushOp::new(BrushKind::Remove, DVec3::new(x, 0.0, 100.0), 4.0, 1.0).unwrap()
    }

    #[test]
    fn undo_redo_and_push_drops_the_redo_tail() {
        let mut log = EditLog::new();
        assert_eq!(log.undo(), None);
        assert_eq!(log.redo(), None);
        let a = log.push(op(1.0));
        let b = log.push(op(2.0));
        assert!(a < b);
        assert_eq!(log.active(), &[op(1.0), op(2.0)]);
        assert_eq!(log.undo(), Some(op(2.0)));
        assert_eq!(log.undo(), Some(op(1.0)));
        assert_eq!(log.undo(), None);
        assert!(log.is_empty() && log.can_redo() && log.redo_len() == 2);
        assert_eq!(log.redo(), Some(op(1.0)));
        assert_eq!(log.active(), &[op(1.0)]);
        assert_eq!(log.active_ids(), &[a]);
        // Pushing after an undo drops what could have been redone.
        let c = log.push(op(3.0));
        assert!(c > b);
        assert_eq!(log.redo(), None);
        assert!(!log.can_redo());
        assert_eq!(log.active(), &[op(1.0), op(3.0)]);
        assert_eq!(log.active_ids(), &[a, c]);
        assert_eq!(log.len(), 2);
    }

    #[test]
    fn snapshots_are_consistent_and_shared() {
        let mut log = EditLog::from_ops([op(1.0), op(2.0)]);
        let s1 = log.snapshot();
        assert!(s1.ptr_eq(&log.snapshot()), "no change, same storage");
        log.push(op(3.0));
        let s2 = log.snapshot();
        assert_eq!(s1.ops(), &[op(1.0), op(2.0)], "a reader's snapshot does not move");
        assert_eq!(s2.len(), 3);
        log.undo();
        assert_eq!(log.snapshot().ops(), s1.ops());
        assert!(!log.snapshot().ptr_eq(&s1));
        let shared = s2.clone();
        assert!(shared.ptr_eq(&s2));
        let t = std::thread::spawn(move || shared.iter().map(|o| o.center.x).sum::<f64>());
        assert_eq!(t.join().unwrap(), 6.0);
    }
}
