//! The sphere preset: an exact ball in the middle of the shell, for checks.

use super::features::Scales;
use super::shading::{Look, Uniform};
use super::{PresetKind, Terrain};
use crate::Sphere;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`super::Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["stone"];

/// The radius of the sphere preset: mid-shell plus `0.37 l_d`, so the surface never lies exactly
/// on a voxel layer.
pub(crate) fn radius(layout: &Layout) -> f64 {
    let t = layout.l_d() * layout.depth_tiles() as f64;
    layout.d_b() + 0.5 * t + 0.37 * layout.l_d()
}

/// The sphere's colour: one plain grey.
const LOOK: Look = Look {
    names: MATERIALS,
    colors: &[[[150, 150, 146], [150, 150, 146]]],
    mix_salt: 1,
    mix_tiles: 1.5,
    blend_colors: [[0.60, 0.60, 0.60], [0.48, 0.50, 0.56]],
};

/// Builds the sphere terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    let density = Arc::new(Sphere { radius: radius(layout) });
    let spec = crate::terrain::TerrainSpec::preset(PresetKind::Sphere, seed);
    LOOK.terrain(spec, density, None, Uniform(0), Scales::new(layout).tile)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::testing::*;
    use pmc_geometry::glam::DVec3;

    #[test]
    fn sphere_sits_between_layers_with_exact_bounds() {
        let layout = Layout::default();
        let t = build(0, &layout);
        let r = radius(&layout);
        assert_eq!(r, 1744.0 + 128.0 + 0.37 * 4.0);
        let k = (r - layout.d_b()) / layout.l_d();
        assert!((k - k.round()).abs() > 0.3, "the surface must not sit on a voxel layer");
        assert_eq!(t.density.radial_bounds(), Some((r, r)));
        assert!(t.sea_radius.is_none());
        check_surface_within_bounds(&t, &layout);
        let p = sphere_dirs(10)[4] * 1900.0;
        assert!((t.density.density(p) - (r - 1900.0)).abs() < 1e-9);
        assert_eq!(t.shader.shade(p, DVec3::Y).material, 0);
        assert_eq!(t.materials, &["stone"]);
    }
}
