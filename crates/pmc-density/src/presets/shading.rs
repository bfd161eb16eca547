//! Colour helpers for the preset shaders: sRGB to linear conversion and two-colour materials
//! blended by a noise value (Fisher et al., seed 003 Sec. 7).

use super::Shade;
use crate::noise::{Fbm, FbmParams};
use pmc_geometry::glam::DVec3;

use pmc_geometry::math::round_to_byte;
pub(crate) use pmc_geometry::math::srgb_to_linear;

/// A material: two colours, linear RGB in `[0, 1]`, mixed by a noise value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Material {
    a: [f64; 3],
    b: [f64; 3],
}

impl Material {
    /// A material from two sRGB colours (as an artist would pick them).
    pub fn srgb(a: [u8; 3], b: [u8; 3]) -> Self {
        Material {
            a: a.map(srgb_to_linear),
            b: b.map(srgb_to_linear),
        }
    }

    /// The colour at mix `t` in `[0, 1]` (0 gives the first colour), opaque, linear RGBA u8.
    pub fn color(&self, t: f64) -> [u8; 4] {
        let t = t.clamp(0.0, 1.0);
        let ch = |i: usize| round_to_byte((self.a[i] + (self.b[i] - self.a[i]) * t) * 255.0);
        [ch(0), ch(1), ch(2), 255]
    }
}

/// A palette: one [`Material`] per material id, and the noise that mixes each material's two
/// colours.
#[derive(Clone, Debug)]
pub(crate) struct Palette {
    materials: Vec<Material>,
    mix: Fbm,
    inv_len: f64,
}

impl Palette {
    /// A palette of `materials` (indexed by material id) whose colour mix varies over about
    /// `length` metres.
    pub fn new(seed: u64, materials: Vec<Material>, length: f64) -> Self {
        Palette {
            materials,
            mix: Fbm::new(seed, FbmParams::new(1.0, 3)),
            inv_len: 1.0 / length,
        }
    }

    /// The mix value at `p`, in `[0, 1]` (spread over most of the range).
    pub fn mix_at(&self, p: DVec3) -> f64 {
        (0.5 + 2.5 * self.mix.sample(p * self.inv_len)).clamp(0.0, 1.0)
    }

    /// [`mix_at`](Self::mix_at) at many points into `out` (cleared first), the same values,
    /// with the mixing noise sampled over all the points at once.
    pub fn mix_many(&self, points: &[DVec3], out: &mut Vec<f64>) {
        let q: Vec<DVec3> = points.iter().map(|p| *p * self.inv_len).collect();
        let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            q.iter().map(|p| p.x).collect(),
            q.iter().map(|p| p.y).collect(),
            q.iter().map(|p| p.z).collect(),
        );
        out.clear();
        out.resize(points.len(), 0.0);
        self.mix.sample_slices(&x, &y, &z, out);
        for v in out.iter_mut() {
            *v = (0.5 + 2.5 * *v).clamp(0.0, 1.0);
        }
    }

    /// The shade of material `id` with mix value `mix` (from [`mix_at`](Self::mix_at)).
    pub fn shade_mixed(&self, id: u8, mix: f64) -> Shade {
        Shade {
            color: self.materials[usize::from(id)].color(mix),
            material: id,
        }
    }

    /// The shade of material `id` at `p`; ids past the palette get [`super::UNKNOWN_MATERIAL_COLOR`].
    pub fn shade_or_unknown(&self, id: u8, p: DVec3) -> Shade {
        if usize::from(id) < self.materials.len() {
            self.shade(id, p)
        } else {
            Shade {
                color: super::UNKNOWN_MATERIAL_COLOR,
                material: id,
            }
        }
    }

    /// The shade of material `id` at `p`.
    pub fn shade(&self, id: u8, p: DVec3) -> Shade {
        self.shade_mixed(id, self.mix_at(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_conversion() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert!((srgb_to_linear(255) - 1.0).abs() < 1e-12);
        // Mid grey in sRGB is about 21% linear.
        assert!((srgb_to_linear(128) - 0.2158).abs() < 1e-3);
    }

    #[test]
    fn materials_blend_between_their_colours() {
        let m = Material::srgb([255, 0, 0], [0, 0, 255]);
        assert_eq!(m.color(0.0), [255, 0, 0, 255]);
        assert_eq!(m.color(1.0), [0, 0, 255, 255]);
        assert_eq!(m.color(2.0), [0, 0, 255, 255]);
        let p = Palette::new(1, vec![m], 10.0);
        let mut seen = std::collections::HashSet::new();
        for i in 0..200 {
            let s = p.shade(0, DVec3::new(i as f64 * 3.7, 1.0, 2.0));
            assert_eq!(s.material, 0);
            seen.insert(s.color);
        }
        assert!(seen.len() > 20, "the noise should vary the colour: {}", seen.len());
    }
}
