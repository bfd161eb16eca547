//! Selection of the chunks to draw for one view (the rule is in the crate docs): refinement
//! nearest first over bounding spheres computed once per selection from one cap per chunk
//! column, then the balance and the budget's bisection over the octree of the `tree` module.

use crate::bounds::{cap_sphere, column_cap, layer_range, BoundingSphere, Cap};
use crate::cull::{sphere_below_horizon, sphere_in_frustum};
use crate::radii::ChunkRadii;
use crate::tree::{KeyMap, Tree};
use pmc_geometry::glam::{DVec3, DVec4};
use pmc_geometry::{ChunkKey, Layout, SideMask};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::{Arc, Mutex, PoisonError};

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
///
/// A selector keeps the bounding caps of the chunk columns its selections computed (they depend
/// on the layout alone, and are the costly part of the bounding spheres) for the next selections,
/// up to [`MAX_KEPT_CAPS`] of them; a clone starts without them.
///
/// A chunk's sphere bounds the voxel layers of its column between its depth bounds, or tighter
/// radii where a [`ChunkRadii`] source knows them ([`Selector::with_radii`]).
pub struct Selector {
    layout: Layout,
    errors: Vec<f64>,
    occluder: f64,
    radii: Option<Arc<dyn ChunkRadii>>,
    caps: Mutex<KeyMap<Cap>>,
}

/// The most column caps a [`Selector`] keeps between selections (some 6 MB): a few selections'
/// worth, cleared when passed.
pub const MAX_KEPT_CAPS: usize = 100_000;

impl Clone for Selector {
    fn clone(&self) -> Self {
        Selector {
            layout: self.layout,
            errors: self.errors.clone(),
            occluder: self.occluder,
            radii: self.radii.clone(),
            caps: Mutex::default(),
        }
    }
}

impl PartialEq for Selector {
    /// Selectors are equal when they select the same: same layout, errors and occluder, and
    /// the same source of radii (or none).
    fn eq(&self, other: &Self) -> bool {
        let same_radii = match (&self.radii, &other.radii) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        };
        self.layout == other.layout && self.errors == other.errors && self.occluder == other.occluder && same_radii
    }
}

impl std::fmt::Debug for Selector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Selector")
            .field("layout", &self.layout)
            .field("errors", &self.errors)
            .field("occluder", &self.occluder)
            .field("radii", &self.radii.is_some())
            .finish_non_exhaustive()
    }
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
            radii: None,
            caps: Mutex::default(),
        })
    }

    /// This selector bounding chunks by the radii of `radii` where it knows them (intersected
    /// with the chunks' layers): for a height-field planet, its patches' own heights
    /// ([`planet_radii`](crate::planet_radii)), so that near the ground only the patches near
    /// the eye are refined, not every patch whose column of the shell the eye is in.
    pub fn with_radii(mut self, radii: Arc<dyn ChunkRadii>) -> Selector {
        self.radii = Some(radii);
        self
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
        // The caps kept by earlier selections; a selection running meanwhile starts without them.
        let kept = std::mem::take(&mut *self.caps.lock().unwrap_or_else(PoisonError::into_inner));
        let mut spheres = Spheres::new(&self.layout, kept, self.radii.as_deref());
        let (roots, splits, mut truncated) = self.refinement(view, params, cap, &mut spheres);
        let budget = params.max_chunks;
        let mut tree = Tree::new(&self.layout);
        // Balancing may stop as soon as the tree holds more than the budget: then only the
        // bisection below needs it, and only its size.
        tree.build(&roots, &splits, cap, budget);
        if tree.leaf_count() > budget && !splits.is_empty() {
            truncated = true;
            // The longest prefix of the splits whose balanced tree fits, by bisection (the
            // balanced size grows with the prefix). The tree of the best prefix so far is kept.
            let mut best = Tree::new(&self.layout);
            best.build(&roots, &[], cap, usize::MAX);
            let (mut lo, mut hi) = (0, splits.len());
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                tree.build(&roots, &splits[..mid], cap, budget);
                if tree.leaf_count() <= budget {
                    lo = mid;
                    std::mem::swap(&mut tree, &mut best);
                } else {
                    hi = mid;
                }
            }
            tree = best;
        }
        let leaves = tree.leaves();
        // (the leaves the balance made were never refinement candidates: their radii at once)
        if self.radii.is_some() {
            spheres.prepare(&leaves.iter().map(|(key, _)| *key).collect::<Vec<_>>());
        }
        let chunks = leaves
            .into_iter()
            .map(|(key, node)| {
                let sphere = spheres.get(&key);
                let visible = view.frustum.as_ref().is_none_or(|f| sphere_in_frustum(f, &sphere))
                    && !sphere_below_horizon(view.eye, self.occluder, &sphere);
                Selected {
                    key,
                    coarser: tree.coarser(node),
                    drawn: visible,
                }
            })
            .collect();
        let mut caps = spheres.caps;
        if caps.len() > MAX_KEPT_CAPS {
            caps.clear();
        }
        *self.caps.lock().unwrap_or_else(PoisonError::into_inner) = caps;
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
        spheres.prepare(&roots);
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
            spheres.prepare(&children);
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

/// The bounding sphere of each chunk, computed once per selection, from the cap of its column
/// (shared by the chunks of the column, and the costly part), computed once per selector.
struct Spheres<'a> {
    layout: &'a Layout,
    caps: KeyMap<Cap>,
    spheres: KeyMap<BoundingSphere>,
    radii: Option<&'a dyn ChunkRadii>,
    /// The radii of the chunks prepared and not yet bounded.
    prepared: KeyMap<Option<(f64, f64)>>,
}

impl<'a> Spheres<'a> {
    fn new(layout: &'a Layout, caps: KeyMap<Cap>, radii: Option<&'a dyn ChunkRadii>) -> Self {
        Spheres {
            layout,
            caps,
            spheres: KeyMap::default(),
            radii,
            prepared: KeyMap::default(),
        }
    }

    /// Asks the radii source (if any) for the chunks of `keys` not yet bounded, all at once (a
    /// source may compute them in parallel).
    fn prepare(&mut self, keys: &[ChunkKey]) {
        let Some(radii) = self.radii else {
            return;
        };
        let keys: Vec<ChunkKey> = keys
            .iter()
            .filter(|k| !self.spheres.contains_key(k) && !self.prepared.contains_key(k))
            .copied()
            .collect();
        let mut out = vec![None; keys.len()];
        radii.radii(&keys, &mut out);
        self.prepared.extend(keys.into_iter().zip(out));
    }

    /// [`chunk_sphere`](crate::bounds::chunk_sphere) of `key`, between the radii of the source
    /// where it has them.
    fn get(&mut self, key: &ChunkKey) -> BoundingSphere {
        if let Some(s) = self.spheres.get(key) {
            return *s;
        }
        let layout = self.layout;
        let column = ChunkKey { k: 0, ..*key };
        let cap = *self
            .caps
            .entry(column)
            .or_insert_with(|| column_cap(layout, key.face, key.level, key.i, key.j));
        let (mut r0, mut r1) = layer_range(layout, key.level, key.k);
        let tighter = match self.prepared.remove(key) {
            Some(r) => r,
            None => self.radii.and_then(|radii| {
                let mut out = [None];
                radii.radii(std::slice::from_ref(key), &mut out);
                out[0]
            }),
        };
        if let Some((a, b)) = tighter {
            // Within the layers (a sound source never says otherwise; a range outside them
            // keeps the layers').
            let (lo, hi) = (r0.max(a), r1.min(b));
            if lo <= hi {
                (r0, r1) = (lo, hi);
            }
        }
        let sphere = cap_sphere(cap, r0, r1);
        self.spheres.insert(*key, sphere);
        sphere
    }
}

/// The children of `key` that are chunks of the layout (the octree's depth axis may end
/// between two children), in key order.
fn existing_children(layout: &Layout, key: &ChunkKey) -> Vec<ChunkKey> {
    key.children()
        .map(|c| c.into_iter().filter(|k| layout.contains_chunk(k)).collect())
        .unwrap_or_default()
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
        let mut tree = Tree::new(&layout);
        tree.build(&roots, &[], 0, usize::MAX);
        let mut children = Vec::new();
        for s in &splits {
            tree.split_key(s, &mut children);
        }
        let coarse = [key(1, 1, 0, 0), key(1, 0, 1, 0)];
        for c in &coarse {
            assert!(tree.is_leaf(c));
            assert!(tree.must_split_key(c, 0), "{c}");
        }
        // Nothing else must split: the tree is 2:1 balanced.
        let others = tree
            .leaves()
            .iter()
            .filter(|(k, _)| !coarse.contains(k) && tree.must_split_key(k, 0))
            .count();
        assert_eq!(others, 0);
        tree.balance(0, usize::MAX);
        for c in &coarse {
            assert!(!tree.is_leaf(c));
        }
        assert!(tree.leaves().iter().all(|(k, _)| !tree.must_split_key(k, 0)));
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

    /// Layouts for the comparison with the plain rule: even and odd tile counts, depths that do
    /// not halve evenly (coarse chunks overhanging the shell, children missing past the depth),
    /// faces of one to sixteen chunks a side.
    fn layouts() -> Vec<Layout> {
        vec![
            Layout::new(4, 4, 100.0, 1.0, 4).unwrap(),
            Layout::new(8, 2, 60.0, 2.0, 3).unwrap(),
            Layout::new(16, 2, 200.0, 1.0, 5).unwrap(),
            Layout::new(2, 8, 50.0, 1.0, 7).unwrap(),
            Layout::new(12, 2, 80.0, 1.0, 2).unwrap(),
            Layout::new(3, 3, 30.0, 1.0, 2).unwrap(),
            Layout::default(),
        ]
    }

    fn doubling(layout: &Layout, scale: f64) -> Vec<f64> {
        (0..=layout.max_level())
            .map(|l| {
                if l == 0 {
                    0.0
                } else {
                    scale * f64::from(1u32 << (l - 1))
                }
            })
            .collect()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(160))]

        /// The selection equals the plain rule's, chunk for chunk, seams and culling included:
        /// eyes far, near and inside the shell (next to face edges and cube corners too), with
        /// and without a frustum, budgets that cut the refinement, a finest level.
        #[test]
        fn select_equals_the_plain_rule(
            which in 0usize..7,
            dir in proptest::array::uniform3(-1.0f64..1.0),
            look in proptest::array::uniform3(-1.0f64..1.0),
            height in proptest::prop_oneof![0.5f64..1.0, 0.95f64..1.05, 1.05f64..3.0],
            corner in proptest::bool::ANY,
            scale in 0.02f64..2.0,
            pixels in 0.5f64..6.0,
            budget in proptest::prop_oneof![10usize..80, 80usize..600, 600usize..100_000],
            finest in 0u8..3,
            with_frustum in proptest::bool::ANY,
        ) {
            let layout = layouts()[which];
            let d = DVec3::from_array(dir);
            let d = if corner { d.signum() + d * 0.05 } else { d };
            let eye = d.normalize_or(DVec3::Y) * height * layout.radius();
            let frustum = with_frustum.then(|| {
                crate::frustum_planes(eye, DVec3::from_array(look) - eye * 0.5 / eye.length(), DVec3::Y, 1.0, 1.5, 0.1, 1e5)
            });
            let selector = Selector::new(layout, doubling(&layout, scale * layout.l_d()), 0.9 * layout.d_b()).unwrap();
            let view = View { eye, frustum, viewport_height_px: 900.0, fov_y: 1.0 };
            let params = LodParams { max_pixel_error: pixels, finest_level: finest, max_chunks: budget };
            let fast = selector.select(&view, &params).unwrap();
            let plain = crate::reference::select(&selector, &view, &params);
            proptest::prop_assert_eq!(fast, plain);
        }
    }

    /// At the earth's scale (nineteen levels, a thousand chunks of depth), views from the ground
    /// and from orbit select what the plain rule selects, budget cut or not.
    #[test]
    fn earth_scale_selections_equal_the_plain_rule() {
        let layout = Layout::new(1 << 18, 32, 6_371_000.0 - 16_384.0, 1.0, 1 << 10).unwrap();
        let errors: Vec<f64> = (0..=layout.max_level())
            .map(|l| if l == 0 { 0.0 } else { 0.8 * 2f64.powi(i32::from(l) - 1) })
            .collect();
        let selector = Selector::new(layout, errors, 6_360_000.0).unwrap();
        let mut compared = 0;
        for (dir, height, budget) in [
            (DVec3::new(0.3, 0.9, 0.1), 2.0, 700),
            (DVec3::new(1.0, 1.0, 0.999), 50.0, 500),
            (DVec3::new(-0.2, 0.1, 1.0), 3000.0, 900),
            (DVec3::new(0.5, -0.7, 0.2), 2.0 * 6_371_000.0, 4096),
        ] {
            let eye = dir.normalize() * (6_371_000.0 + height);
            let frustum = crate::frustum_planes(eye, DVec3::Y - eye.normalize(), eye, 1.0, 1.7, 0.5, 1e8);
            for frustum in [None, Some(frustum)] {
                let view = View {
                    eye,
                    frustum,
                    viewport_height_px: 1080.0,
                    fov_y: 1.0,
                };
                let params = LodParams {
                    max_chunks: budget,
                    ..LodParams::default()
                };
                let fast = selector.select(&view, &params).unwrap();
                assert_eq!(
                    fast,
                    crate::reference::select(&selector, &view, &params),
                    "{dir} {height}"
                );
                compared += fast.chunks.len();
            }
        }
        assert!(compared > 2000, "{compared}");
    }

    /// The bounding spheres (their caps from border samples, `atan2` only near the largest
    /// tangent) have the bits of the plain computation, on small layouts and at the earth's
    /// scale, at every level.
    #[test]
    fn spheres_have_the_bits_of_the_plain_computation() {
        let earth = Layout::new(1 << 18, 32, 6_371_000.0 - 16_384.0, 1.0, 1 << 10).unwrap();
        // The finest grid there is: 2^24 tiles a face side, chunks a few 1e-7 rad across.
        let finest = Layout::new(1 << 22, 4, 1e7, 1.0, 4).unwrap();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move |n: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % u64::from(n)) as u32
        };
        let mut compared = 0;
        for layout in layouts().into_iter().chain([earth, finest]) {
            for level in 0..=layout.max_level() {
                let (n, d) = (layout.chunks_per_side(level), layout.depth_chunks(level));
                for _ in 0..40 {
                    let key = ChunkKey {
                        face: Face::ALL[next(6) as usize],
                        level,
                        i: next(n),
                        j: next(n),
                        k: next(d),
                    };
                    assert_eq!(
                        crate::bounds::chunk_sphere(&layout, &key),
                        crate::reference::chunk_sphere(&layout, &key),
                        "{key}"
                    );
                    compared += 1;
                }
            }
        }
        assert!(compared > 1000);
    }
}
