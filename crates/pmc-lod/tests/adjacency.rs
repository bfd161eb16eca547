//! The 26-neighbourhood found by stepping across sides equals the chunks that share a voxel,
//! across face edges and next to cube corners, at every level.

use crate::common::{boundary_voxels, small_layouts};
use pmc_geometry::{ChunkKey, Face, Layout, VoxelKey};
use pmc_lod::{adjacent, OFFSETS};
use std::collections::{BTreeSet, HashMap};

/// The chunks of `level` that share a voxel with `key` (itself excluded).
fn touching(layout: &Layout, level: u8) -> HashMap<ChunkKey, BTreeSet<ChunkKey>> {
    let step = 1i64 << level;
    let mut owners: HashMap<VoxelKey, Vec<ChunkKey>> = HashMap::new();
    for key in layout.chunks(level) {
        for v in boundary_voxels(layout, &key, step) {
            owners.entry(v).or_default().push(key);
        }
    }
    let mut out: HashMap<ChunkKey, BTreeSet<ChunkKey>> = HashMap::new();
    for keys in owners.values() {
        for a in keys {
            for b in keys {
                if a != b {
                    out.entry(*a).or_default().insert(*b);
                }
            }
        }
    }
    out
}

#[test]
fn stepping_finds_exactly_the_touching_chunks() {
    let mut layouts = small_layouts().to_vec();
    // One chunk per face side at the coarsest level, two at the next: every chunk is on a face
    // edge, many next to a cube corner.
    layouts.push(Layout::new(2, 2, 20.0, 1.0, 2).unwrap());
    for layout in layouts {
        for level in 0..=layout.max_level() {
            let expected = touching(&layout, level);
            for key in layout.chunks(level) {
                let found: Vec<ChunkKey> = OFFSETS.iter().filter_map(|o| adjacent(&layout, &key, *o)).collect();
                let set: BTreeSet<ChunkKey> = found.iter().copied().collect();
                assert_eq!(set.len(), found.len(), "{key}: a chunk reached by two offsets");
                let want = expected.get(&key).cloned().unwrap_or_default();
                assert_eq!(set, want, "{key} at level {level}");
            }
        }
    }
}

/// Spelled out on one face edge and one cube corner of the smallest layout.
#[test]
fn steps_across_a_face_edge_and_at_a_cube_corner() {
    let layout = Layout::new(2, 2, 20.0, 1.0, 1).unwrap();
    let key = |face, i, j| ChunkKey::new(face, i, j, 0);
    // Top (u = -X, v = +Z), chunk (1, 0): its u-max side is Top's -X edge, shared with West.
    let corner_free = adjacent(&layout, &key(Face::Top, 1, 0), [1, 1, 0]).unwrap();
    let via_edge = layout
        .neighbour(&key(Face::Top, 1, 1), pmc_geometry::ChunkSide::UMax, 0)
        .unwrap();
    assert_eq!(corner_free, via_edge);
    assert_eq!(corner_free.face, Face::West);
    // Top (1, 1) sits at a cube corner: the diagonal beyond both face edges does not exist.
    assert_eq!(adjacent(&layout, &key(Face::Top, 1, 1), [1, 1, 0]), None);
    // Depth steps past the one-chunk-deep shell do not exist either.
    assert_eq!(adjacent(&layout, &key(Face::Top, 0, 0), [0, 0, 1]), None);
}

/// Stepping there and back returns home, at every level.
#[test]
fn steps_are_mutual() {
    for layout in small_layouts() {
        for level in 0..=layout.max_level() {
            for key in layout.chunks(level) {
                for o in OFFSETS {
                    let Some(n) = adjacent(&layout, &key, o) else { continue };
                    let back = OFFSETS
                        .iter()
                        .filter(|p| adjacent(&layout, &n, **p) == Some(key))
                        .count();
                    assert_eq!(back, 1, "{key} {o:?} -> {n}");
                }
            }
        }
    }
}
