//! The selection rule of the crate docs written the plain way, for tests: every bounding sphere
//! from every border sample, the leaves in a hash set, a leaf's test and its seam sides by
//! [`adjacent`] and a walk up the ancestors, every leaf tested in the first balance round and
//! every prefix of the bisection balanced from scratch. [`Selector::select`] must give exactly
//! what this gives.

use crate::adjacency::{adjacent, OFFSETS};
use crate::bounds::{angle_between, BoundingSphere, LIPSCHITZ, RADIUS_FACTOR};
use crate::cull::{sphere_below_horizon, sphere_in_frustum};
use crate::select::{LodParams, Selected, Selection, Selector, View};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{face_uv_to_sphere, ChunkKey, ChunkSide, Face, Layout, SideMask};
use std::collections::{BinaryHeap, HashMap, HashSet};

/// The cap angle above which the sphere is centred on the planet (as in `bounds`).
const MAX_CAP_ANGLE: f64 = 1.5;

/// The cap of a face rectangle from `atan2` at every border sample.
fn rect_cap(face: Face, u0: f64, u1: f64, v0: f64, v1: f64, samples: u32) -> (DVec3, f64) {
    let axis = face_uv_to_sphere(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1)).normalize();
    let mut angle: f64 = 0.0;
    let m = f64::from(samples);
    for s in 0..=samples {
        let t = f64::from(s) / m;
        let (u, v) = (u0 + (u1 - u0) * t, v0 + (v1 - v0) * t);
        for (su, sv) in [(u, v0), (u, v1), (u0, v), (u1, v)] {
            angle = angle.max(angle_between(axis, face_uv_to_sphere(face, su, sv).normalize()));
        }
    }
    let spacing = (u1 - u0).max(v1 - v0) / m;
    (axis, angle + LIPSCHITZ * 0.5 * spacing)
}

/// [`crate::bounds::chunk_sphere`], the plain way.
pub(crate) fn chunk_sphere(layout: &Layout, key: &ChunkKey) -> BoundingSphere {
    let (n, s) = (layout.face_tiles(), i64::from(layout.n_t()) << key.level);
    let uv = |t: i64| 2.0 * t as f64 / n as f64 - 1.0;
    let (ti, tj) = (i64::from(key.i) * s, i64::from(key.j) * s);
    let (axis, angle) = rect_cap(key.face, uv(ti), uv(ti + s), uv(tj), uv(tj + s), layout.n_t());
    let stride = 1i64 << key.level;
    let top = (layout.depth_tiles() + stride - 1) / stride * stride;
    let (lo, hi) = (i64::from(key.k) * s, (i64::from(key.k + 1) * s).min(top));
    let (r0, r1) = (layout.layer_radius(lo), layout.layer_radius(hi.max(lo)));
    let pad = |radius: f64| radius * RADIUS_FACTOR + 1e-9 * r1;
    if angle >= MAX_CAP_ANGLE {
        return BoundingSphere {
            center: DVec3::ZERO,
            radius: pad(r1),
        };
    }
    let dist2 = |r: f64, h: f64| {
        let s = (0.5 * angle).sin();
        (r - h) * (r - h) + 4.0 * r * h * s * s
    };
    let c = angle.cos();
    let (h, d2) = [r0 * c, r1 * c, 0.5 * (r0 + r1) / c, r1]
        .into_iter()
        .map(|h| h.clamp(0.0, r1))
        .map(|h| (h, dist2(r0, h).max(dist2(r1, h))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((r1, 0.0));
    BoundingSphere {
        center: axis * h,
        radius: pad(d2.sqrt()),
    }
}

fn existing_children(layout: &Layout, key: &ChunkKey) -> Vec<ChunkKey> {
    key.children()
        .map(|c| c.into_iter().filter(|k| layout.contains_chunk(k)).collect())
        .unwrap_or_default()
}

/// A refinement candidate: nearest first, ties by key.
#[derive(PartialEq)]
struct Candidate(f64, ChunkKey);

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.0.total_cmp(&self.0).then_with(|| other.1.cmp(&self.1))
    }
}

/// The leaves of the octree, balanced in rounds over every leaf.
struct Tree<'a> {
    layout: &'a Layout,
    leaves: HashSet<ChunkKey>,
}

impl Tree<'_> {
    fn split(&mut self, key: &ChunkKey) -> Vec<ChunkKey> {
        self.leaves.remove(key);
        let children = existing_children(self.layout, key);
        self.leaves.extend(children.iter().copied());
        children
    }

    fn covering(&self, cell: &ChunkKey) -> Option<ChunkKey> {
        let mut c = *cell;
        loop {
            if self.leaves.contains(&c) {
                return Some(c);
            }
            if c.level >= self.layout.max_level() {
                return None;
            }
            c = c.parent();
        }
    }

    fn level_at(&self, cell: &ChunkKey) -> i32 {
        self.covering(cell)
            .map_or(i32::from(cell.level) - 1, |l| i32::from(l.level))
    }

    fn must_split(&self, key: &ChunkKey, cap: u8) -> bool {
        if key.level <= cap {
            return false;
        }
        let level = i32::from(key.level);
        let Some(children) = key.children() else {
            return false;
        };
        for (n, child) in children.iter().enumerate() {
            if !self.layout.contains_chunk(child) {
                continue;
            }
            let out = [
                (n >> 2 & 1) as i8 * 2 - 1,
                (n >> 1 & 1) as i8 * 2 - 1,
                (n & 1) as i8 * 2 - 1,
            ];
            let towards =
                |mask: usize| -> [i8; 3] { std::array::from_fn(|a| if mask >> a & 1 == 1 { out[a] } else { 0 }) };
            for mask in 1..8 {
                if let Some(cell) = adjacent(self.layout, child, towards(mask)) {
                    if self.covering(&cell).is_none() {
                        return true;
                    }
                }
            }
            for (p, q) in [(1usize, 2usize), (1, 4), (2, 4)] {
                let beside_p = adjacent(self.layout, child, towards(p));
                let beside_q = adjacent(self.layout, child, towards(q));
                let across = adjacent(self.layout, child, towards(p | q));
                if let (Some(bp), Some(bq), Some(ac)) = (beside_p, beside_q, across) {
                    if level.min(self.level_at(&ac)) > self.level_at(&bp).max(self.level_at(&bq)) {
                        return true;
                    }
                }
            }
        }
        false
    }

    fn balance(&mut self, cap: u8) {
        let mut candidates: Vec<ChunkKey> = self.leaves.iter().copied().collect();
        loop {
            candidates.sort_unstable();
            candidates.dedup();
            let splits: Vec<ChunkKey> = candidates
                .iter()
                .filter(|k| self.leaves.contains(k) && self.must_split(k, cap))
                .copied()
                .collect();
            if splits.is_empty() {
                return;
            }
            candidates.clear();
            for key in &splits {
                let children = self.split(key);
                candidates.extend(children);
            }
            for key in &splits {
                for offset in OFFSETS {
                    if let Some(leaf) = adjacent(self.layout, key, offset).and_then(|c| self.covering(&c)) {
                        candidates.push(leaf);
                    }
                }
            }
        }
    }

    fn coarser(&self, key: &ChunkKey) -> SideMask {
        let mut mask = SideMask::NONE;
        for side in ChunkSide::ALL {
            let Some(cell) = self.layout.neighbour(key, side, key.level) else {
                continue;
            };
            if self.covering(&cell).is_some_and(|l| l.level == key.level + 1) {
                mask = mask.with(side);
            }
        }
        mask
    }
}

fn build<'a>(layout: &'a Layout, roots: &[ChunkKey], splits: &[ChunkKey], cap: u8) -> Tree<'a> {
    let mut tree = Tree {
        layout,
        leaves: roots.iter().copied().collect(),
    };
    for key in splits {
        tree.split(key);
    }
    if !splits.is_empty() {
        tree.balance(cap);
    }
    tree
}

/// The selection of `selector` for `view`, the plain way (the input is assumed valid).
pub(crate) fn select(selector: &Selector, view: &View, params: &LodParams) -> Selection {
    let layout = selector.layout();
    let cap = params.finest_level.min(layout.max_level());
    let mut spheres: HashMap<ChunkKey, BoundingSphere> = HashMap::new();
    let mut sphere = |k: &ChunkKey| *spheres.entry(*k).or_insert_with(|| chunk_sphere(layout, k));
    let roots = layout.chunks(layout.max_level());
    let mut splits = Vec::new();
    let mut truncated = false;
    if roots.len() > params.max_chunks {
        truncated = true;
    } else {
        let scale = view.viewport_height_px / (2.0 * (0.5 * view.fov_y).tan());
        let mut heap: BinaryHeap<Candidate> = roots
            .iter()
            .map(|k| Candidate(sphere(k).distance(view.eye), *k))
            .collect();
        let mut count = roots.len();
        while let Some(Candidate(distance, key)) = heap.pop() {
            if key.level <= cap {
                continue;
            }
            let too_coarse = selector.errors()[usize::from(key.level)] * scale > params.max_pixel_error * distance;
            if !too_coarse {
                continue;
            }
            let children = existing_children(layout, &key);
            if count - 1 + children.len() > params.max_chunks {
                truncated = true;
                break;
            }
            count += children.len() - 1;
            splits.push(key);
            for k in children {
                heap.push(Candidate(sphere(&k).distance(view.eye), k));
            }
        }
    }
    let mut tree = build(layout, &roots, &splits, cap);
    if tree.leaves.len() > params.max_chunks && !splits.is_empty() {
        truncated = true;
        let (mut lo, mut hi) = (0, splits.len());
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if build(layout, &roots, &splits[..mid], cap).leaves.len() <= params.max_chunks {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        tree = build(layout, &roots, &splits[..lo], cap);
    }
    let mut keys: Vec<ChunkKey> = tree.leaves.iter().copied().collect();
    keys.sort_unstable();
    let chunks = keys
        .into_iter()
        .map(|key| {
            let s = sphere(&key);
            let visible = view.frustum.as_ref().is_none_or(|f| sphere_in_frustum(f, &s))
                && !sphere_below_horizon(view.eye, selector.occluder(), &s);
            Selected {
                key,
                coarser: tree.coarser(&key),
                drawn: visible,
            }
        })
        .collect();
    Selection { chunks, truncated }
}
