//! Selection of the chunks to draw for one view (the rule is in the crate docs).

use crate::adjacency::{adjacent, OFFSETS};
use crate::bounds::{chunk_sphere, BoundingSphere};
use crate::cull::{sphere_below_horizon, sphere_in_frustum};
use pmc_geometry::glam::{DVec3, DVec4};
use pmc_geometry::{ChunkKey, ChunkSide, Layout, SideMask};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet};

/// The default of [`LodParams::max_chunks`].
pub const DEFAULT_MAX_CHUNKS: usize = 4096;

/// Where the camera is and how it projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The eye, planet-centred, in metres.
    pub eye: DVec3,
    /// The frustum's six planes `(n, d)`, inside where `n . p + d >= 0` (`n` of any length);
    /// `None` draws every chunk that is not below the horizon.
    pub frustum: Option<[DVec4; 6]>,
    /// The viewport's height in pixels.
    pub viewport_height_px: f64,
    /// The vertical field of view, in radians, in `(0, pi)`.
    pub fov_y: f64,
}

/// How fine the selection may get.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodParams {
    /// The largest screen-space error, in pixels, a drawn chunk may have (default 2).
    pub max_pixel_error: f64,
    /// The finest level the selection may reach (default 0, the finest there is); levels above
    /// the layout's coarsest mean the roots only.
    pub finest_level: u8,
    /// The most chunks the selection may hold (default [`DEFAULT_MAX_CHUNKS`]); the roots are
    /// always selected, even when there are more of them.
    pub max_chunks: usize,
}

impl Default for LodParams {
    fn default() -> Self {
        LodParams {
            max_pixel_error: 2.0,
            finest_level: 0,
            max_chunks: DEFAULT_MAX_CHUNKS,
        }
    }
}

/// One selected chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Selected {
    /// The chunk.
    pub key: ChunkKey,
    /// The sides across which the selected chunks are one level coarser, named in this chunk's
    /// face (across a face edge too): the mesher closes the seam on these sides.
    pub coarser: SideMask,
    /// Whether the chunk is to be drawn: `false` when its bounding sphere lies outside the
    /// frustum or below the horizon (it still counts for its neighbours' levels).
    pub drawn: bool,
}

/// The chunks selected for a view: leaves of the chunk octree that cover the planet's shell
/// exactly once, in key order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    /// The leaves, in key order.
    pub chunks: Vec<Selected>,
    /// Whether the budget [`LodParams::max_chunks`] stopped refinement (some chunks are coarser
    /// than the error bound asks).
    pub truncated: bool,
}

impl Selection {
    /// How many chunks were selected at each level (index = level), up to the coarsest selected.
    pub fn level_histogram(&self) -> Vec<usize> {
        let mut out = Vec::new();
        for s in &self.chunks {
            let l = usize::from(s.key.level);
            if out.len() <= l {
                out.resize(l + 1, 0);
            }
            out[l] += 1;
        }
        out
    }

    /// The chunks to draw.
    pub fn drawn(&self) -> impl Iterator<Item = &Selected> {
        self.chunks.iter().filter(|s| s.drawn)
    }

    /// The selected chunk covering `key` (`key` itself or one of its ancestors), if any.
    pub fn covering(&self, key: &ChunkKey) -> Option<&Selected> {
        let top = self.chunks.iter().map(|s| s.key.level).max()?;
        let mut k = *key;
        loop {
            if let Ok(n) = self.chunks.binary_search_by(|s| s.key.cmp(&k)) {
                return Some(&self.chunks[n]);
            }
            if k.level >= top {
                return None;
            }
            k = k.parent();
        }
    }
}

/// Why a selector or a selection was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LodError {
    /// The error table needs one entry per level, `0..=max_level`.
    #[error("the error table has {got} entries; the layout has levels 0..={max_level}, so it needs {} entries", usize::from(*max_level) + 1)]
    ErrorTableLength {
        /// Entries given.
        got: usize,
        /// The layout's coarsest level.
        max_level: u8,
    },
    /// Every level's error must be a finite number of metres, at least 0.
    #[error("the error of level {level} must be a finite number of metres, at least 0; got {value}")]
    LevelError {
        /// The level.
        level: usize,
        /// The refused value.
        value: f64,
    },
    /// The occluder radius must be finite and at least 0 (0 turns horizon culling off).
    #[error("the occluder radius must be a finite number of metres, at least 0; got {0}")]
    OccluderRadius(f64),
    /// The eye must be a finite point.
    #[error("the eye must be a finite point, got {0:?}")]
    Eye([f64; 3]),
    /// The viewport height must be finite and above 0.
    #[error("the viewport height must be a finite number of pixels above 0, got {0}")]
    ViewportHeight(f64),
    /// The field of view must be finite and strictly between 0 and pi.
    #[error("the vertical field of view must be in radians strictly between 0 and pi, got {0}")]
    FieldOfView(f64),
    /// Each frustum plane must be finite with a normal other than zero.
    #[error("frustum plane {0} must be finite with a normal other than zero")]
    FrustumPlane(usize),
    /// The pixel error bound must be finite and above 0.
    #[error("the largest pixel error must be a finite number above 0, got {0}")]
    MaxPixelError(f64),
}

/// Selects the chunks to draw for views of one planet layout (see the crate docs for the rule).
#[derive(Clone, Debug, PartialEq)]
pub struct Selector {
    layout: Layout,
    errors: Vec<f64>,
    occluder: f64,
}

impl Selector {
    /// A selector for `layout` with the geometric error of each level (`errors[L]` in metres,
    /// one entry per level `0..=max_level`, for instance from
    /// [`measure_level_errors`](crate::measure_level_errors)) and the radius of the solid ball
    /// that hides what lies below the horizon (for instance
    /// [`occluder_radius`](crate::occluder_radius); 0 culls nothing by the horizon).
    pub fn new(layout: Layout, errors: Vec<f64>, occluder: f64) -> Result<Selector, LodError> {
        let max_level = layout.max_level();
        if errors.len() != usize::from(max_level) + 1 {
            return Err(LodError::ErrorTableLength {
                got: errors.len(),
                max_level,
            });
        }
        if let Some((level, value)) = errors.iter().enumerate().find(|(_, e)| !(e.is_finite() && **e >= 0.0)) {
            return Err(LodError::LevelError { level, value: *value });
        }
        if !(occluder.is_finite() && occluder >= 0.0) {
            return Err(LodError::OccluderRadius(occluder));
        }
        Ok(Selector {
            layout,
            errors,
            occluder,
        })
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The error table, metres by level.
    pub fn errors(&self) -> &[f64] {
        &self.errors
    }

    /// The occluder radius used for horizon culling.
    pub fn occluder(&self) -> f64 {
        self.occluder
    }

    /// The chunks to draw for `view`. Fails only on a malformed view or parameters (non-finite
    /// numbers, a field of view outside `(0, pi)`, ...).
    pub fn select(&self, view: &View, params: &LodParams) -> Result<Selection, LodError> {
        check(view, params)?;
        let cap = params.finest_level.min(self.layout.max_level());
        let mut spheres = Spheres::new(&self.layout);
        let (roots, splits, mut truncated) = self.refinement(view, params, cap, &mut spheres);
        let build = |n: usize| Tree::new(&self.layout, &roots, &splits[..n], cap);
        let mut tree = build(splits.len());
        if tree.leaves.len() > params.max_chunks && !splits.is_empty() {
            truncated = true;
            // The longest prefix of the splits whose balanced tree fits, by bisection (the
            // balanced size grows with the prefix).
            let (mut lo, mut hi) = (0, splits.len());
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if build(mid).leaves.len() <= params.max_chunks {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            tree = build(lo);
        }
        let mut keys: Vec<ChunkKey> = tree.leaves.iter().copied().collect();
        keys.sort_unstable();
        let chunks = keys
            .into_iter()
            .map(|key| {
                let sphere = spheres.get(&key);
                let visible = view.frustum.as_ref().is_none_or(|f| sphere_in_frustum(f, &sphere))
                    && !sphere_below_horizon(view.eye, self.occluder, &sphere);
                Selected {
                    key,
                    coarser: tree.coarser(&key),
                    drawn: visible,
                }
            })
            .collect();
        Ok(Selection { chunks, truncated })
    }

    /// The roots, the splits refinement makes in order (nearest chunk first), and whether the
    /// budget stopped it.
    fn refinement(
        &self,
        view: &View,
        params: &LodParams,
        cap: u8,
        spheres: &mut Spheres,
    ) -> (Vec<ChunkKey>, Vec<ChunkKey>, bool) {
        let roots = self.layout.chunks(self.layout.max_level());
        if roots.len() > params.max_chunks {
            return (roots, Vec::new(), true);
        }
        // Refine while errors[L] h / (2 tan(fov / 2) d) > max_pixel_error, without dividing.
        let scale = view.viewport_height_px / (2.0 * (0.5 * view.fov_y).tan());
        let mut heap: BinaryHeap<Candidate> = roots
            .iter()
            .map(|k| Candidate {
                distance: spheres.get(k).distance(view.eye),
                key: *k,
            })
            .collect();
        let mut count = roots.len();
        let mut splits = Vec::new();
        let mut truncated = false;
        while let Some(c) = heap.pop() {
            if c.key.level <= cap {
                continue;
            }
            let error = self.errors[usize::from(c.key.level)];
            let too_coarse = error * scale > params.max_pixel_error * c.distance;
            if !too_coarse {
                continue;
            }
            let children = existing_children(&self.layout, &c.key);
            if count - 1 + children.len() > params.max_chunks {
                truncated = true;
                break;
            }
            count += children.len() - 1;
            splits.push(c.key);
            for key in children {
                heap.push(Candidate {
                    distance: spheres.get(&key).distance(view.eye),
                    key,
                });
            }
        }
        (roots, splits, truncated)
    }
}

/// Checks a view and parameters.
fn check(view: &View, params: &LodParams) -> Result<(), LodError> {
    if !view.eye.is_finite() {
        return Err(LodError::Eye(view.eye.to_array()));
    }
    if !(view.viewport_height_px.is_finite() && view.viewport_height_px > 0.0) {
        return Err(LodError::ViewportHeight(view.viewport_height_px));
    }
    if !(view.fov_y.is_finite() && view.fov_y > 0.0 && view.fov_y < std::f64::consts::PI) {
        return Err(LodError::FieldOfView(view.fov_y));
    }
    if let Some(planes) = &view.frustum {
        if let Some(n) = planes
            .iter()
            .position(|p| !p.is_finite() || p.truncate().length_squared() == 0.0)
        {
            return Err(LodError::FrustumPlane(n));
        }
    }
    if !(params.max_pixel_error.is_finite() && params.max_pixel_error > 0.0) {
        return Err(LodError::MaxPixelError(params.max_pixel_error));
    }
    Ok(())
}

/// A chunk waiting to be refined: the heap pops the nearest first, ties by key.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    distance: f64,
    key: ChunkKey,
}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: `BinaryHeap` pops the greatest.
        other
            .distance
            .total_cmp(&self.distance)
            .then_with(|| other.key.cmp(&self.key))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Candidate {}

/// The bounding sphere of each chunk, computed once per selection.
struct Spheres<'a> {
    layout: &'a Layout,
    map: HashMap<ChunkKey, BoundingSphere>,
}

impl<'a> Spheres<'a> {
    fn new(layout: &'a Layout) -> Self {
        Spheres {
            layout,
            map: HashMap::new(),
        }
    }

    fn get(&mut self, key: &ChunkKey) -> BoundingSphere {
        *self.map.entry(*key).or_insert_with(|| chunk_sphere(self.layout, key))
    }
}

/// The children of `key` that are chunks of the layout (the octree's depth axis may end
/// between two children), in key order.
fn existing_children(layout: &Layout, key: &ChunkKey) -> Vec<ChunkKey> {
    key.children()
        .map(|c| c.into_iter().filter(|k| layout.contains_chunk(k)).collect())
        .unwrap_or_default()
}

/// The leaves of the octree being balanced.
struct Tree<'a> {
    layout: &'a Layout,
    leaves: HashSet<ChunkKey>,
    max_level: u8,
}

impl<'a> Tree<'a> {
    /// The roots with `splits` applied in order, then balanced.
    fn new(layout: &'a Layout, roots: &[ChunkKey], splits: &[ChunkKey], cap: u8) -> Tree<'a> {
        let mut tree = Tree {
            layout,
            leaves: roots.iter().copied().collect(),
            max_level: layout.max_level(),
        };
        for key in splits {
            tree.split(key);
        }
        // The roots alone are all of one level: balanced already.
        if !splits.is_empty() {
            tree.balance(cap);
        }
        tree
    }

    /// Replaces the leaf `key` by its children, returning them.
    fn split(&mut self, key: &ChunkKey) -> Vec<ChunkKey> {
        self.leaves.remove(key);
        let children = existing_children(self.layout, key);
        self.leaves.extend(children.iter().copied());
        children
    }

    /// The leaf holding `cell` (`cell` itself or an ancestor), `None` when `cell` is split
    /// into finer leaves.
    fn covering(&self, cell: &ChunkKey) -> Option<ChunkKey> {
        let mut c = *cell;
        loop {
            if self.leaves.contains(&c) {
                return Some(c);
            }
            if c.level >= self.max_level {
                return None;
            }
            c = c.parent();
        }
    }

    /// The level of the leaves in `cell`: the covering leaf's, or one below the cell's when it
    /// is split (any finer level compares the same in the rules below).
    fn level_at(&self, cell: &ChunkKey) -> i32 {
        self.covering(cell)
            .map_or(i32::from(cell.level) - 1, |l| i32::from(l.level))
    }

    /// Whether the leaf `key` must split: a touching leaf is more than one level finer, or one of
    /// its edges has the checkerboard (this leaf and the leaf diagonally across the edge coarser
    /// than both leaves beside it).
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
            // Outward from this child along u, v and depth.
            let out = [
                (n >> 2 & 1) as i8 * 2 - 1,
                (n >> 1 & 1) as i8 * 2 - 1,
                (n & 1) as i8 * 2 - 1,
            ];
            let towards =
                |mask: usize| -> [i8; 3] { std::array::from_fn(|a| if mask >> a & 1 == 1 { out[a] } else { 0 }) };
            // The level-(L-1) cells around the child outside this chunk must not be split.
            for mask in 1..8 {
                if let Some(cell) = adjacent(self.layout, child, towards(mask)) {
                    if self.covering(&cell).is_none() {
                        return true;
                    }
                }
            }
            // The half of each edge of this chunk that the child holds.
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

    /// Splits leaves until none must split. Each round tests the candidates against the tree as
    /// it stands, then splits all that must; the next candidates are the new children and the
    /// leaves of their parent's level or coarser around each split chunk (no other leaf's test
    /// can change: finer leaves around it only see leaves at least as coarse as themselves
    /// appear).
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

    /// The sides of leaf `key` across which the leaf is one level coarser.
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

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Face;

    fn view(eye: DVec3) -> View {
        View {
            eye,
            frustum: None,
            viewport_height_px: 1000.0,
            fov_y: 1.0,
        }
    }

    #[test]
    fn malformed_input_is_refused_not_panicked_on() {
        let layout = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
        assert!(matches!(
            Selector::new(layout, vec![0.0; 2], 90.0),
            Err(LodError::ErrorTableLength { got: 2, max_level: 2 })
        ));
        assert!(matches!(
            Selector::new(layout, vec![0.0, f64::NAN, 1.0], 90.0),
            Err(LodError::LevelError { level: 1, .. })
        ));
        assert!(Selector::new(layout, vec![0.0, 1.0, 2.0], -1.0).is_err());
        let s = Selector::new(layout, vec![0.0, 1.0, 2.0], 90.0).unwrap();
        let p = LodParams::default();
        assert!(s.select(&view(DVec3::splat(f64::NAN)), &p).is_err());
        assert!(s
            .select(
                &View {
                    fov_y: 4.0,
                    ..view(DVec3::X)
                },
                &p
            )
            .is_err());
        assert!(s
            .select(
                &View {
                    viewport_height_px: 0.0,
                    ..view(DVec3::X)
                },
                &p
            )
            .is_err());
        let zero = [DVec4::ZERO; 6];
        assert_eq!(
            s.select(
                &View {
                    frustum: Some(zero),
                    ..view(DVec3::X)
                },
                &p
            ),
            Err(LodError::FrustumPlane(0))
        );
        let bad = LodParams {
            max_pixel_error: 0.0,
            ..p
        };
        assert!(s.select(&view(DVec3::X), &bad).is_err());
        // A budget below the roots gives the roots, marked truncated.
        let tiny = LodParams { max_chunks: 0, ..p };
        let sel = s.select(&view(DVec3::X * 150.0), &tiny).unwrap();
        assert!(sel.truncated);
        assert_eq!(sel.chunks.len(), layout.chunks(2).len());
    }

    #[test]
    fn candidates_pop_nearest_first_then_by_key() {
        let a = ChunkKey::new(Face::Top, 0, 0, 0);
        let b = ChunkKey::new(Face::Top, 1, 0, 0);
        let mut heap = BinaryHeap::new();
        heap.push(Candidate { distance: 2.0, key: a });
        heap.push(Candidate { distance: 1.0, key: b });
        heap.push(Candidate { distance: 1.0, key: a });
        let order: Vec<_> = std::iter::from_fn(|| heap.pop()).map(|c| (c.distance, c.key)).collect();
        assert_eq!(order, vec![(1.0, a), (1.0, b), (2.0, a)]);
    }

    /// Two diagonally opposite level-1 chunks split around the vertical line through the middle
    /// of a face: balanced, but a checkerboard, so the two coarse ones must split too.
    #[test]
    fn a_checkerboard_around_an_edge_is_split() {
        let layout = Layout::new(4, 2, 100.0, 1.0, 4).unwrap();
        let key = |level, i, j, k| ChunkKey {
            face: Face::Top,
            level,
            i,
            j,
            k,
        };
        let roots = layout.chunks(2);
        let mut splits = roots.clone();
        splits.push(key(1, 0, 0, 0));
        splits.push(key(1, 1, 1, 0));
        let mut tree = Tree {
            layout: &layout,
            leaves: roots.iter().copied().collect(),
            max_level: 2,
        };
        for s in &splits {
            tree.split(s);
        }
        let coarse = [key(1, 1, 0, 0), key(1, 0, 1, 0)];
        for c in &coarse {
            assert!(tree.leaves.contains(c));
            assert!(tree.must_split(c, 0), "{c}");
        }
        // Nothing else must split: the tree is 2:1 balanced.
        let others = tree
            .leaves
            .iter()
            .filter(|k| !coarse.contains(k) && tree.must_split(k, 0))
            .count();
        assert_eq!(others, 0);
        tree.balance(0);
        for c in &coarse {
            assert!(!tree.leaves.contains(c));
        }
        assert!(tree.leaves.iter().all(|k| !tree.must_split(k, 0)));
    }

    #[test]
    fn histogram_and_covering() {
        let layout = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
        let s = Selector::new(layout, vec![0.0, 4.0, 8.0], 0.0).unwrap();
        let sel = s.select(&view(DVec3::Y * 104.0), &LodParams::default()).unwrap();
        let h = sel.level_histogram();
        assert_eq!(h.iter().sum::<usize>(), sel.chunks.len());
        assert!(h[0] > 0, "{h:?}");
        for key in layout.chunks(0) {
            let c = sel.covering(&key).unwrap();
            assert_eq!(c.key.face, key.face);
        }
    }
}
