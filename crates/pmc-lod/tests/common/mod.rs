//! Brute-force references shared by the tests: chunks as closed boxes of canonical voxels.

#![allow(dead_code)]

use pmc_geometry::{ChunkKey, Layout, VoxelKey};
use pmc_lod::Selection;
use std::collections::{HashMap, HashSet};

/// The two small layouts the tests run on.
pub fn small_layouts() -> [Layout; 2] {
    [
        Layout::new(4, 4, 100.0, 1.0, 4).unwrap(),
        Layout::new(8, 4, 100.0, 1.0, 3).unwrap(),
    ]
}

/// The canonical voxels on the boundary of chunk `key`'s closed box, every `step` level-0 grid
/// steps (`step` must divide the chunk's span). Two chunks touch (across a side, an edge or a
/// corner, across face edges too) exactly when these sets meet, at a step that divides both
/// spans.
pub fn boundary_voxels(layout: &Layout, key: &ChunkKey, step: i64) -> Vec<VoxelKey> {
    let span = layout.chunk_span(key.level);
    let (i0, j0, k0) = (
        i64::from(key.i) * span,
        i64::from(key.j) * span,
        i64::from(key.k) * span,
    );
    let m = span / step;
    let mut out = Vec::new();
    for c in 0..=m {
        for b in 0..=m {
            for a in 0..=m {
                if a != 0 && a != m && b != 0 && b != m && c != 0 && c != m {
                    continue;
                }
                let v = layout
                    .voxel_key(key.face, i0 + a * step, j0 + b * step, k0 + c * step)
                    .expect("a chunk's own voxels lie on its face");
                out.push(v);
            }
        }
    }
    out
}

/// Every voxel on some leaf's boundary, with the leaves (indices into `selection.chunks`) whose
/// boundary holds it, at level-0 resolution.
pub fn voxel_owners(layout: &Layout, selection: &Selection) -> HashMap<VoxelKey, Vec<usize>> {
    let mut owners: HashMap<VoxelKey, Vec<usize>> = HashMap::new();
    for (n, s) in selection.chunks.iter().enumerate() {
        for v in boundary_voxels(layout, &s.key, 1) {
            owners.entry(v).or_default().push(n);
        }
    }
    owners
}

/// The leaf (index) covering level-0 chunk `cell`, by scanning every leaf.
pub fn leaves_covering(selection: &Selection, cell: &ChunkKey) -> Vec<usize> {
    selection
        .chunks
        .iter()
        .enumerate()
        .filter(|(_, s)| is_ancestor_or_self(&s.key, cell))
        .map(|(n, _)| n)
        .collect()
}

/// Whether `a` is `b` or holds it in the octree.
pub fn is_ancestor_or_self(a: &ChunkKey, b: &ChunkKey) -> bool {
    a.face == b.face
        && a.level >= b.level
        && (b.i >> (a.level - b.level)) == a.i
        && (b.j >> (a.level - b.level)) == a.j
        && (b.k >> (a.level - b.level)) == a.k
}

/// Checks that the leaves cover every level-0 chunk exactly once and are chunks of the layout.
pub fn assert_partition(layout: &Layout, selection: &Selection) {
    for s in &selection.chunks {
        assert!(layout.contains_chunk(&s.key), "{} is not a chunk", s.key);
    }
    let keys: HashSet<ChunkKey> = selection.chunks.iter().map(|s| s.key).collect();
    assert_eq!(keys.len(), selection.chunks.len(), "a leaf is listed twice");
    for cell in layout.chunks(0) {
        let mut hits = 0;
        let mut k = cell;
        loop {
            if keys.contains(&k) {
                hits += 1;
            }
            if k.level >= layout.max_level() {
                break;
            }
            k = k.parent();
        }
        assert_eq!(hits, 1, "level-0 chunk {cell} is covered {hits} times");
    }
}

/// Checks 2:1 balance by brute force: leaves whose boxes share a voxel differ by at most one level.
pub fn assert_balanced(selection: &Selection, owners: &HashMap<VoxelKey, Vec<usize>>) {
    for (v, leaves) in owners {
        let lo = leaves.iter().map(|n| selection.chunks[*n].key.level).min().unwrap();
        let hi = leaves.iter().map(|n| selection.chunks[*n].key.level).max().unwrap();
        assert!(
            hi - lo <= 1,
            "leaves of levels {lo} and {hi} touch at {v:?}: {:?}",
            leaves
                .iter()
                .map(|n| selection.chunks[*n].key.to_string())
                .collect::<Vec<_>>()
        );
    }
}

/// Whether voxel `x` lies on the line through the (adjacent) voxels `p` and `q`.
fn on_line(p: &VoxelKey, q: &VoxelKey, x: &VoxelKey) -> bool {
    if p.lattice == q.lattice {
        return x.lattice == p.lattice;
    }
    if x.k != p.k {
        return false;
    }
    let d: [i64; 3] = std::array::from_fn(|a| i64::from(q.lattice[a]) - i64::from(p.lattice[a]));
    let e: [i64; 3] = std::array::from_fn(|a| i64::from(x.lattice[a]) - i64::from(p.lattice[a]));
    d[1] * e[2] - d[2] * e[1] == 0 && d[2] * e[0] - d[0] * e[2] == 0 && d[0] * e[1] - d[1] * e[0] == 0
}

/// Checks, by brute force, that no line where four leaves meet has them alternating coarse,
/// fine, coarse, fine. Returns how many four-leaf segments were examined.
pub fn assert_no_checkerboard(layout: &Layout, selection: &Selection, owners: &HashMap<VoxelKey, Vec<usize>>) -> usize {
    // The voxels each pair of touching leaves shares.
    let mut shared: HashMap<(usize, usize), Vec<VoxelKey>> = HashMap::new();
    for (v, leaves) in owners {
        for a in leaves {
            for b in leaves {
                if a < b {
                    shared.entry((*a, *b)).or_default().push(*v);
                }
            }
        }
    }
    let mut examined = 0;
    let mut seen = HashSet::new();
    for s in &selection.chunks {
        let key = s.key;
        let span = layout.chunk_span(key.level);
        let (i0, j0, k0) = (
            i64::from(key.i) * span,
            i64::from(key.j) * span,
            i64::from(key.k) * span,
        );
        // Unit segments along the twelve edges of this leaf.
        for axis in 0..3 {
            for p in [0, span] {
                for q in [0, span] {
                    for t in 0..span {
                        let at = |t: i64| -> VoxelKey {
                            let mut c = [0i64; 3];
                            c[axis] = t;
                            c[(axis + 1) % 3] = p;
                            c[(axis + 2) % 3] = q;
                            layout.voxel_key(key.face, i0 + c[0], j0 + c[1], k0 + c[2]).unwrap()
                        };
                        let (a, b) = (at(t), at(t + 1));
                        let seg = if a < b { (a, b) } else { (b, a) };
                        if !seen.insert(seg) {
                            continue;
                        }
                        let around: Vec<usize> =
                            owners[&a].iter().filter(|n| owners[&b].contains(n)).copied().collect();
                        if around.len() != 4 {
                            continue;
                        }
                        examined += 1;
                        let diagonal = |x: usize, y: usize| {
                            let pair = (x.min(y), x.max(y));
                            shared[&pair].iter().all(|v| on_line(&a, &b, v))
                        };
                        let x = around[0];
                        let partners: Vec<usize> = around[1..].iter().copied().filter(|y| diagonal(x, *y)).collect();
                        assert_eq!(partners.len(), 1, "four leaves around a line pair up two by two");
                        let y = partners[0];
                        let others: Vec<usize> = around[1..].iter().copied().filter(|z| *z != y).collect();
                        assert!(diagonal(others[0], others[1]));
                        let lv = |n: usize| selection.chunks[n].key.level;
                        let (c1, c2) = (lv(x).min(lv(y)), lv(others[0]).min(lv(others[1])));
                        let (f1, f2) = (lv(x).max(lv(y)), lv(others[0]).max(lv(others[1])));
                        assert!(
                            !(c1 > f2 || c2 > f1),
                            "checkerboard around a line: {} {} vs {} {}",
                            selection.chunks[x].key,
                            selection.chunks[y].key,
                            selection.chunks[others[0]].key,
                            selection.chunks[others[1]].key
                        );
                    }
                }
            }
        }
    }
    examined
}

/// Checks each leaf's `coarser` mask against the leaves found across each side, level-0 chunk by
/// level-0 chunk, by scanning the selection.
pub fn assert_coarser_masks(layout: &Layout, selection: &Selection) {
    use pmc_geometry::ChunkSide;
    for s in &selection.chunks {
        let key = s.key;
        let per = 1u32 << key.level;
        for side in ChunkSide::ALL {
            let mut levels = HashSet::new();
            for a in 0..per {
                for b in 0..per {
                    // The level-0 chunk of this leaf on `side`, at position (a, b) along it.
                    let edge = if side.is_max() { per - 1 } else { 0 };
                    let (di, dj, dk) = match side.axis() {
                        0 => (edge, a, b),
                        1 => (a, edge, b),
                        _ => (a, b, edge),
                    };
                    let cell = ChunkKey {
                        face: key.face,
                        level: 0,
                        i: key.i * per + di,
                        j: key.j * per + dj,
                        k: key.k * per + dk,
                    };
                    if !layout.contains_chunk(&cell) {
                        continue;
                    }
                    let Some(across) = layout.neighbour(&cell, side, 0) else {
                        continue;
                    };
                    let cover = leaves_covering(selection, &across);
                    assert_eq!(cover.len(), 1, "{across} covered {} times", cover.len());
                    levels.insert(selection.chunks[cover[0]].key.level);
                }
            }
            let coarser = levels.contains(&(key.level + 1));
            if coarser {
                assert_eq!(
                    levels.len(),
                    1,
                    "{key} {side:?}: mixed levels {levels:?} across a coarser side"
                );
            }
            assert_eq!(
                s.coarser.contains(side),
                coarser,
                "{key} {side:?}: levels across {levels:?}"
            );
        }
    }
}
