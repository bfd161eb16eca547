//! The sphere preset: an exact ball in the middle of the shell, for checks.

use super::shading::Material;
use super::{PresetKind, Shade, Shader, Terrain};
use crate::Sphere;
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Material names, indexed by [`Shade::material`].
pub(crate) const MATERIALS: &[&str] = &["stone"];

/// The radius of the sphere preset: mid-shell plus `0.37 l_d`, so the surface never lies exactly
/// on a voxel layer.
pub(crate) fn radius(layout: &Layout) -> f64 {
    let t = layout.l_d() * layout.depth_tiles() as f64;
    layout.d_b() + 0.5 * t + 0.37 * layout.l_d()
}

/// A plain grey shader.
struct Grey([u8; 4]);

impl Shader for Grey {
    fn shade(&self, _p: DVec3, _normal: DVec3) -> Shade {
        Shade {
            color: self.0,
            material: 0,
        }
    }
    fn shade_material(&self, material: u8, _p: DVec3) -> Shade {
        let color = if usize::from(material) < MATERIALS.len() {
            self.0
        } else {
            super::UNKNOWN_MATERIAL_COLOR
        };
        Shade { color, material }
    }
}

/// Builds the sphere terrain.
pub(crate) fn build(seed: u64, layout: &Layout) -> Terrain {
    Terrain {
        spec: crate::terrain::TerrainSpec::preset(PresetKind::Sphere, seed),
        density: Arc::new(Sphere { radius: radius(layout) }),
        sea_radius: None,
        shader: Arc::new(Grey(Material::srgb([150, 150, 146], [150, 150, 146]).color(0.0))),
        materials: MATERIALS,
        blend_colors: [[0.60, 0.60, 0.60], [0.48, 0.50, 0.56]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::testing::*;

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
