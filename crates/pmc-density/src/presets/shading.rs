//! The shader of every terrain: a [`MaterialMap`] (which material lies where) coloured by a
//! [`Palette`] of two-colour materials blended by a noise value (Fisher et al., seed 003 Sec. 7),
//! and the [`Look`] a planet states (material names, colours, renderer blend colours).

use super::{EdgeVertices, Shade, Shader, Terrain};
use crate::noise::{derive_seed, Fbm, FbmParams};
use crate::terrain::TerrainSpec;
use crate::Density;
use pmc_geometry::glam::DVec3;
use std::sync::Arc;

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

/// Which material lies where on a planet: what a [`PaletteShader`] colours.
pub(crate) trait MaterialMap: Send + Sync + 'static {
    /// The material id at world point `p` with unit outward normal `normal`.
    fn material(&self, p: DVec3, normal: DVec3) -> u8;

    /// [`material`](Self::material) for a point known to lie on the terrain's surface
    /// ([`Shader::shade_on_surface`]). The default is `material`.
    fn material_on_surface(&self, p: DVec3, normal: DVec3) -> u8 {
        self.material(p, normal)
    }

    /// The materials at many points into `out` (cleared first): the same values as
    /// [`material`](Self::material) (with `on_surface`,
    /// [`material_on_surface`](Self::material_on_surface)) one point at a time. Maps that look
    /// columns or noise up override it to do so for all the points at once.
    fn materials(&self, points: &[DVec3], normals: &[DVec3], on_surface: bool, out: &mut Vec<u8>) {
        out.clear();
        out.extend(points.iter().zip(normals).map(|(p, n)| {
            if on_surface {
                self.material_on_surface(*p, *n)
            } else {
                self.material(*p, *n)
            }
        }));
    }

    /// The materials of a chunk's edge vertices ([`Shader::shade_edges`]) into `out` (cleared
    /// first). The default is [`materials`](Self::materials) at the vertices' points.
    fn edge_materials(&self, vertices: &EdgeVertices<'_>, out: &mut Vec<u8>) {
        self.materials(vertices.points, vertices.normals, false, out);
    }
}

/// One material everywhere.
pub(crate) struct Uniform(pub u8);

impl MaterialMap for Uniform {
    fn material(&self, _p: DVec3, _normal: DVec3) -> u8 {
        self.0
    }
}

/// A [`MaterialMap`] coloured by a [`Palette`]: the shader of every preset and height-field
/// terrain. Batches ([`Shader::shade_many`], [`Shader::shade_edges`]) take the map's batch and
/// the palette's mixing noise over all the points at once, the same values as point by point.
pub(crate) struct PaletteShader<M> {
    map: M,
    palette: Palette,
}

impl<M: MaterialMap> PaletteShader<M> {
    /// The shader colouring `map` with `palette`.
    pub fn new(map: M, palette: Palette) -> Self {
        PaletteShader { map, palette }
    }

    /// The shades of materials `ids` at `points` into `out` (cleared first).
    fn shade_ids(&self, points: &[DVec3], ids: &[u8], out: &mut Vec<Shade>) {
        let mut mix = Vec::with_capacity(points.len());
        self.palette.mix_many(points, &mut mix);
        out.clear();
        out.extend(ids.iter().zip(&mix).map(|(id, m)| self.palette.shade_mixed(*id, *m)));
    }
}

impl<M: MaterialMap> Shader for PaletteShader<M> {
    fn shade(&self, p: DVec3, normal: DVec3) -> Shade {
        self.palette.shade(self.map.material(p, normal), p)
    }

    fn shade_on_surface(&self, p: DVec3, normal: DVec3) -> Shade {
        self.palette.shade(self.map.material_on_surface(p, normal), p)
    }

    fn shade_many(&self, points: &[DVec3], normals: &[DVec3], on_surface: bool, out: &mut Vec<Shade>) {
        assert_eq!(points.len(), normals.len(), "one normal per point");
        let mut ids = Vec::with_capacity(points.len());
        self.map.materials(points, normals, on_surface, &mut ids);
        self.shade_ids(points, &ids, out);
    }

    fn shade_edges(&self, vertices: &EdgeVertices<'_>, out: &mut Vec<Shade>) {
        vertices.check();
        let mut ids = Vec::with_capacity(vertices.points.len());
        self.map.edge_materials(vertices, &mut ids);
        self.shade_ids(vertices.points, &ids, out);
    }

    fn shade_material(&self, material: u8, p: DVec3) -> Shade {
        self.palette.shade_or_unknown(material, p)
    }
}

/// How a planet looks, as it states it: its materials with their colours, and the colours a
/// renderer blends over it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Look {
    /// Material names, indexed by material id ([`Terrain::materials`]).
    pub names: &'static [&'static str],
    /// Each material's two sRGB colours, mixed by noise; indexed like `names`.
    pub colors: &'static [[[u8; 3]; 2]],
    /// The salt of the mixing noise's seed ([`derive_seed`] of the planet's seed).
    pub mix_salt: u64,
    /// About how far the mix varies, in tiles.
    pub mix_tiles: f64,
    /// [`Terrain::blend_colors`].
    pub blend_colors: [[f32; 3]; 2],
}

impl Look {
    /// The palette of a planet of `seed` whose tiles are `tile` metres across.
    pub fn palette(&self, seed: u64, tile: f64) -> Palette {
        assert_eq!(self.names.len(), self.colors.len(), "one colour pair per material");
        let materials = self.colors.iter().map(|[a, b]| Material::srgb(*a, *b)).collect();
        Palette::new(derive_seed(seed, self.mix_salt), materials, self.mix_tiles * tile)
    }

    /// The terrain made of `spec`, `density` and `sea_radius`, with `map`'s materials in this
    /// look's colours (the palette from `spec`'s seed and the tile size `tile`).
    pub fn terrain(
        &self,
        spec: TerrainSpec,
        density: Arc<dyn Density>,
        sea_radius: Option<f64>,
        map: impl MaterialMap,
        tile: f64,
    ) -> Terrain {
        let palette = self.palette(spec.seed(), tile);
        Terrain {
            spec,
            density,
            sea_radius,
            shader: Arc::new(PaletteShader::new(map, palette)),
            materials: self.names,
            blend_colors: self.blend_colors,
        }
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
