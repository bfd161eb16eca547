//! The shell boundary contract: what makes the union of all chunk meshes closed.
//!
//! The voxel grid is a shell between layer 0 (radius `d_b`) and layer `D` (the planet radius). A
//! surface that reached either boundary layer would be cut open there. [`close_shell`] forces the
//! innermost layer (and the padding below it) solid and the outermost layer (and above) air, so
//! the surface always closes inside the shell. Every chunk applies it to its samples before
//! meshing; with canonical voxel identity this makes the planet one closed 2-manifold.

use pmc_geometry::ChunkGrid;

/// Density written into forced-solid samples (the innermost layer) when they were not solid.
pub const FORCED_SOLID: f32 = 1.0;
/// Density written into forced-air samples (the outermost layer) when they were not air.
pub const FORCED_AIR: f32 = -1.0;

/// The shell contract for one sample at depth index `k`: what [`close_shell`] makes of `d`.
#[inline]
pub fn close_sample(k: i64, depth_tiles: i64, d: f32) -> f32 {
    if k <= 0 {
        if crate::is_solid(d) {
            d
        } else {
            FORCED_SOLID
        }
    } else if k >= depth_tiles {
        if d.is_nan() || d > 0.0 {
            FORCED_AIR
        } else {
            d
        }
    } else if d.is_nan() {
        FORCED_AIR
    } else {
        d
    }
}

/// Forces samples at depth index `<= 0` solid and `>= depth_tiles` air (see the module docs).
/// Also replaces NaN samples by air, so a faulty source cannot poison the mesh.
///
/// # Panics
/// If `densities.len() != grid.sample_count()`.
pub fn close_shell(grid: &ChunkGrid, depth_tiles: i64, densities: &mut [f32]) {
    assert_eq!(
        densities.len(),
        grid.sample_count(),
        "densities must cover the padded chunk grid"
    );
    let layer = grid.padded * grid.padded;
    for (c, slab) in densities.chunks_exact_mut(layer).enumerate() {
        let k = grid.k0 + (c as i64 - 1) * grid.stride;
        // Selects rather than branches: every sample is written back, so the loops vectorise.
        if k <= 0 {
            for d in slab.iter_mut() {
                *d = if crate::is_solid(*d) { *d } else { FORCED_SOLID };
            }
        } else if k >= depth_tiles {
            for d in slab.iter_mut() {
                *d = if d.is_nan() || *d > 0.0 { FORCED_AIR } else { *d };
            }
        } else {
            for d in slab.iter_mut() {
                *d = if d.is_nan() { FORCED_AIR } else { *d };
            }
        }
    }
}
