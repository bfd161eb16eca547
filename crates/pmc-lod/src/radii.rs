//! Radial bounds of chunks tighter than their voxel layers: a height-field planet's patches.
//!
//! A height-field planet has one chunk along depth whose layers span the whole relief (about
//! 20 km on the Earth), so a patch's bounding sphere from its layers holds its whole column and
//! every patch whose column the eye is in looks as near as can be: near the ground the selection
//! refines them all to the finest level. A patch's own vertices span a few metres to a few
//! kilometres; bounded by those ([`PatchRadii`]), the selection refines only what is near.

use crate::tree::KeyMap;
use pmc_geometry::{ChunkKey, Layout};
use pmc_planet::heightfield::HeightfieldMode;
use pmc_planet::Planet;
use rayon::prelude::*;
use std::sync::{Arc, Mutex, PoisonError};

/// Radii between which the vertices of chunks' meshes lie, where a source knows them tighter
/// than the chunks' voxel layers (see [`Selector::with_radii`](crate::Selector::with_radii)).
///
/// # Contract
///
/// Every vertex of the mesh of chunk `key` (with any sides stitched) lies at a distance from the
/// planet's centre within the radii given for `key`; the answer is a function of the key alone.
pub trait ChunkRadii: Send + Sync {
    /// For each of `keys`, into the same place of `out` (as long as `keys`): the least and the
    /// greatest radius (metres from the planet's centre) of the chunk's vertices, or `None` where
    /// the chunk's layers are the bound.
    fn radii(&self, keys: &[ChunkKey], out: &mut [Option<(f64, f64)>]);
}

/// The most patch ranges a [`PatchRadii`] keeps (some 6 MB); cleared when passed.
pub const MAX_KEPT_RADII: usize = 200_000;

/// The radii of a height-field planet's patches, from their vertices' heights
/// ([`HeightfieldMode::patch_radii`]), computed in parallel for the keys asked together and kept
/// for the next selections.
///
/// Patches wider than [`WIDE_PATCH`] times the shell's thickness are left to their layers: their
/// sphere is as wide as they are whatever their heights, so their heights (the costliest ones, a
/// data tile per vertex) would barely move it.
pub struct PatchRadii {
    mode: Arc<HeightfieldMode>,
    /// The coarsest chunk level whose patches get their own radii.
    coarsest: u8,
    kept: Mutex<KeyMap<Option<(f64, f64)>>>,
}

/// See [`PatchRadii`]: a patch gets its own radii when at most this many shell thicknesses wide.
pub const WIDE_PATCH: f64 = 8.0;

impl PatchRadii {
    /// The radii of the patches of `mode`, whose patch layout is `layout`.
    pub fn new(mode: Arc<HeightfieldMode>, layout: &Layout) -> PatchRadii {
        let thickness = layout.radius() - layout.d_b();
        // A chunk of level L is a patch about (pi / 2) radius 2^L / n_c wide.
        let finest_width = std::f64::consts::FRAC_PI_2 * layout.radius() / f64::from(layout.n_c());
        let coarsest = (0..=layout.max_level())
            .take_while(|&l| finest_width * f64::from(1u32 << l) <= WIDE_PATCH * thickness)
            .last()
            .unwrap_or(0);
        PatchRadii {
            mode,
            coarsest,
            kept: Mutex::default(),
        }
    }
}

impl std::fmt::Debug for PatchRadii {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PatchRadii")
            .field("mode", &self.mode)
            .finish_non_exhaustive()
    }
}

impl ChunkRadii for PatchRadii {
    fn radii(&self, keys: &[ChunkKey], out: &mut [Option<(f64, f64)>]) {
        assert_eq!(keys.len(), out.len(), "one answer per key");
        let mut missing = Vec::new();
        {
            let kept = self.kept.lock().unwrap_or_else(PoisonError::into_inner);
            for (n, key) in keys.iter().enumerate() {
                match kept.get(key) {
                    Some(r) => out[n] = *r,
                    None => missing.push(n),
                }
            }
        }
        if missing.is_empty() {
            return;
        }
        let found: Vec<Option<(f64, f64)>> = missing
            .par_iter()
            .map(|&n| {
                let key = &keys[n];
                (key.level <= self.coarsest)
                    .then(|| self.mode.patch_radii(key))
                    .flatten()
            })
            .collect();
        let mut kept = self.kept.lock().unwrap_or_else(PoisonError::into_inner);
        if kept.len() + found.len() > MAX_KEPT_RADII {
            kept.clear();
        }
        for (&n, r) in missing.iter().zip(found) {
            out[n] = r;
            kept.insert(keys[n], r);
        }
    }
}

/// The tighter radii of `planet`'s chunks where it has them: its patches' when it is meshed as a
/// height field, else `None` (a volumetric planet's chunks are bounded by their layers).
pub fn planet_radii(planet: &Planet) -> Option<Arc<dyn ChunkRadii>> {
    planet
        .heightfield_shared()
        .map(|mode| Arc::new(PatchRadii::new(mode, planet.layout())) as Arc<dyn ChunkRadii>)
}
