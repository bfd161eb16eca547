//! Terrain presets: a density, a sea level and a shader, built for a layout and a seed.

mod craters;
mod earth;
mod earthlike;
pub(crate) mod features;
mod layouts;
mod mars;
mod material;
mod moon;
pub(crate) mod shading;
mod sphere;
#[cfg(test)]
pub(crate) mod testing;

use crate::{Density, ShellColumns};
pub use layouts::{layout_for_radius, RadiusError, EARTH_RADIUS, MAX_RADIUS, MIN_RADIUS};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{Layout, VertexEdge};
use std::sync::Arc;

/// The named presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PresetKind {
    /// An exact sphere (for checks): no relief, no sea.
    Sphere,
    /// Continents, seas, ridged mountains, caves and overhangs (the default).
    Earthlike,
    /// Grey, cratered, airless, with lava tubes.
    Moon,
    /// Red, dry, with canyons, volcanoes, dunes, polar caps and caves.
    Mars,
    /// The Earth at true scale on its own layout ([`PresetKind::default_layout`]): sea level at
    /// 6 371 000 m, ocean basins, trenches, mountain ranges, hills, rocks, cliffs and caves down
    /// to 1 m voxels; the same planet shrunk onto any other layout.
    Earth,
}

impl PresetKind {
    /// Every preset, in the order `--help` lists them.
    pub const ALL: [PresetKind; 5] = [
        PresetKind::Sphere,
        PresetKind::Earthlike,
        PresetKind::Moon,
        PresetKind::Mars,
        PresetKind::Earth,
    ];

    /// The preset's command-line name.
    pub fn name(self) -> &'static str {
        match self {
            PresetKind::Sphere => "sphere",
            PresetKind::Earthlike => "earthlike",
            PresetKind::Moon => "moon",
            PresetKind::Mars => "mars",
            PresetKind::Earth => "earth",
        }
    }

    /// One line describing the preset.
    pub fn description(self) -> &'static str {
        match self {
            PresetKind::Sphere => "an exact sphere in the middle of the shell, for checks",
            PresetKind::Earthlike => "continents, seas, ridged mountains, caves and overhangs",
            PresetKind::Moon => "grey cratered highlands and maria, lava tubes, no sea",
            PresetKind::Mars => "red deserts, canyons, volcanoes, polar caps and caves, no sea",
            PresetKind::Earth => {
                "the Earth at true scale: oceans, trenches, continents, mountain ranges, hills, rocks, cliffs and caves, 1 m voxels"
            }
        }
    }
}

impl std::fmt::Display for PresetKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown preset name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown preset '{0}' (choose one of: sphere, earthlike, moon, mars, earth)")]
pub struct UnknownPreset(pub String);

impl std::str::FromStr for PresetKind {
    type Err = UnknownPreset;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PresetKind::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownPreset(s.to_string()))
    }
}

/// How a surface point looks: a colour and a material id.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shade {
    /// Linear RGBA colour (glTF `COLOR_0` space).
    pub color: [u8; 4],
    /// Material id, an index into [`Terrain::materials`].
    pub material: u8,
}

/// Colours a surface point. Deterministic and thread-safe.
pub trait Shader: Send + Sync {
    /// The shade at world point `p` with unit outward normal `normal`.
    fn shade(&self, p: DVec3, normal: DVec3) -> Shade;

    /// [`Shader::shade`] for a point known to lie on the terrain's surface (a height-field
    /// vertex): a shader that would look the surface up along `p`'s direction may take `|p|`
    /// instead. The default is `shade`.
    fn shade_on_surface(&self, p: DVec3, normal: DVec3) -> Shade {
        self.shade(p, normal)
    }

    /// The shades at many points: `out[i]` (after `out` is cleared) is
    /// [`shade`](Self::shade)`(points[i], normals[i])`, or with `on_surface`
    /// [`shade_on_surface`](Self::shade_on_surface), the same values as one call per point.
    /// Shaders that look noise up at each point override it to sample the noise over all the
    /// points at once (a chunk's vertices).
    ///
    /// Panics when the slices differ in length (a caller's bug).
    fn shade_many(&self, points: &[DVec3], normals: &[DVec3], on_surface: bool, out: &mut Vec<Shade>) {
        assert_eq!(points.len(), normals.len(), "one normal per point");
        out.clear();
        out.extend(points.iter().zip(normals).map(|(p, n)| {
            if on_surface {
                self.shade_on_surface(*p, *n)
            } else {
                self.shade(*p, *n)
            }
        }));
    }

    /// The shades of a chunk's mesh vertices, each on an edge between two of the chunk's samples:
    /// `out[i]` (after `out` is cleared) is the shade of vertex `i`. Shaders that compute
    /// something once per column (a direction from the planet's centre) override it to compute
    /// it at the chunk's column directions only, or take it from the density batch's
    /// [`ShellColumns`], and read each vertex's value from its edge's two ends, interpolated
    /// across the surface at the vertex. The result depends only on the vertex's point, normal
    /// and edge and on the directions, never on whether the batch's columns were kept. The
    /// default is [`shade_many`](Self::shade_many) at the points.
    ///
    /// Panics when the slices of `vertices` differ in length or an edge names a direction past
    /// `vertices.dirs` (a caller's bug).
    fn shade_edges(&self, vertices: &EdgeVertices<'_>, out: &mut Vec<Shade>) {
        vertices.check();
        self.shade_many(vertices.points, vertices.normals, false, out);
    }

    /// The shade of material `material` (an index into [`Terrain::materials`]) at world point
    /// `p`, whatever the terrain would put there (used to paint materials by hand). The default is
    /// a neutral grey; the presets use their palettes. Ids past the material list get the grey.
    fn shade_material(&self, material: u8, p: DVec3) -> Shade {
        let _ = p;
        Shade {
            color: UNKNOWN_MATERIAL_COLOR,
            material,
        }
    }
}

/// Mesh vertices on the edges of a chunk's sample grid, for [`Shader::shade_edges`].
#[derive(Clone, Copy, Debug)]
pub struct EdgeVertices<'a> {
    /// World positions (metres, planet-centred).
    pub points: &'a [DVec3],
    /// Unit outward normals.
    pub normals: &'a [DVec3],
    /// Per vertex, its edge: the columns of the two ends (indices into `dirs`; equal for an edge
    /// along the depth axis) and where the vertex lies between them, `t` in `[0, 1]` from the
    /// first end.
    pub edges: &'a [VertexEdge],
    /// The unit directions of the chunk's columns.
    pub dirs: &'a [DVec3],
    /// What the density batch over `dirs` kept ([`Density::sample_shell_keeping`]), or empty.
    pub columns: &'a ShellColumns,
}

impl EdgeVertices<'_> {
    /// Panics on slices of different lengths or an edge past the directions.
    pub(crate) fn check(&self) {
        assert_eq!(self.points.len(), self.normals.len(), "one normal per point");
        assert_eq!(self.points.len(), self.edges.len(), "one edge per point");
        let n = self.dirs.len();
        assert!(
            self.edges.iter().all(|e| (e.a as usize) < n && (e.b as usize) < n),
            "an edge names a direction past the chunk's"
        );
    }
}

/// The neutral grey of a material a shader does not know (linear RGBA).
pub const UNKNOWN_MATERIAL_COLOR: [u8; 4] = [128, 128, 128, 255];

/// A planet's terrain: density, sea and look, ready to mesh.
#[derive(Clone)]
pub struct Terrain {
    /// What it was built from (a preset and a seed, or an elevation model).
    pub spec: crate::terrain::TerrainSpec,
    /// The density field (positive solid).
    pub density: Arc<dyn Density>,
    /// Radius of the sea surface, if the planet has a sea.
    pub sea_radius: Option<f64>,
    /// The shader.
    pub shader: Arc<dyn Shader>,
    /// Material names, indexed by [`Shade::material`].
    pub materials: &'static [&'static str],
    /// The planet's two blend colours (linear RGB, 0..1): renderers mix them by a noise value
    /// over the terrain for large-scale variety (Fisher et al., seed 003 Sec. 7).
    pub blend_colors: [[f32; 3]; 2],
}

impl std::fmt::Debug for Terrain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Terrain")
            .field("spec", &self.spec)
            .field("sea_radius", &self.sea_radius)
            .finish()
    }
}

/// Builds the terrain of `kind` for `layout` and `seed`.
///
/// Scales follow the layout: relief is set in fractions of the shell thickness
/// `T = l_d n_t d_c` (the earth preset: in metres times `T / 32 768 m`, so true scale on its own
/// layout), horizontal noise frequencies relative to the planet radius (3D noise on the unit
/// sphere, seed 000 Sec. 4.6), caves and overhangs in voxel depths `l_d` and horizontal tile
/// sizes `(pi / 2) R / (n_c n_t)`. The same kind, seed and layout give bit-identical terrain.
/// [`PresetKind::default_layout`] gives each preset's own layout.
pub fn build(kind: PresetKind, seed: u64, layout: &Layout) -> Terrain {
    match kind {
        PresetKind::Sphere => sphere::build(seed, layout),
        PresetKind::Earthlike => earthlike::build(seed, layout),
        PresetKind::Moon => moon::build(seed, layout),
        PresetKind::Mars => mars::build(seed, layout),
        PresetKind::Earth => earth::build(seed, layout),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse() {
        assert_eq!("EarthLike".parse::<PresetKind>(), Ok(PresetKind::Earthlike));
        assert_eq!(" moon ".parse::<PresetKind>(), Ok(PresetKind::Moon));
        assert_eq!("venus".parse::<PresetKind>(), Err(UnknownPreset("venus".into())));
        for k in PresetKind::ALL {
            assert_eq!(k.to_string().parse::<PresetKind>(), Ok(k));
        }
    }

    #[test]
    fn every_preset_builds_deterministically_with_valid_shades() {
        let layout = Layout::default();
        let dirs = testing::sphere_dirs(300);
        let radii: Vec<f64> = (0..=16).map(|k| layout.layer_radius(4 * k)).collect();
        for kind in PresetKind::ALL {
            let a = build(kind, 11, &layout);
            let b = build(kind, 11, &layout);
            assert_eq!(a.spec, crate::terrain::TerrainSpec::preset(kind, 11));
            assert!(!a.materials.is_empty());
            let mut va = vec![0.0f32; dirs.len() * radii.len()];
            let mut vb = va.clone();
            a.density.sample_shell(&dirs, &radii, &mut va);
            b.density.sample_shell(&dirs, &radii, &mut vb);
            assert!(
                va.iter().zip(&vb).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{kind} is not deterministic"
            );
            for d in &dirs {
                let p = *d * layout.d_b() * 1.1;
                let s = a.shader.shade(p, *d);
                assert_eq!(s, b.shader.shade(p, *d));
                assert!(
                    usize::from(s.material) < a.materials.len(),
                    "{kind}: material {} out of range",
                    s.material
                );
                assert_eq!(s.color[3], 255);
            }
            assert_eq!(
                a.sea_radius.is_some(),
                matches!(kind, PresetKind::Earthlike | PresetKind::Earth),
                "{kind}"
            );
        }
    }

    #[test]
    fn every_material_can_be_shaded_by_id() {
        let layout = Layout::default();
        let p = testing::sphere_dirs(5)[2] * layout.radius();
        for kind in PresetKind::ALL {
            let t = build(kind, 4, &layout);
            let mut colors = std::collections::HashSet::new();
            for id in 0..t.materials.len() as u8 {
                let s = t.shader.shade_material(id, p);
                assert_eq!((s.material, s.color[3]), (id, 255), "{kind}");
                colors.insert(s.color);
            }
            assert_eq!(colors.len(), t.materials.len(), "{kind}: one colour per material");
            let past = t.shader.shade_material(t.materials.len() as u8, p);
            assert_eq!(past.color, [128, 128, 128, 255], "{kind}: unknown ids are grey");
        }
    }

    /// Each preset's shades for a fixed seed, bit for bit: a change here changes how every
    /// planet of that preset looks, and must be deliberate.
    #[test]
    fn preset_shades_golden() {
        let want = [
            (PresetKind::Sphere, 0xa356_ba77_c009_f9b1),
            (PresetKind::Earthlike, 0xdfdb_6711_945a_8599),
            (PresetKind::Moon, 0x82d2_381b_53cd_bce5),
            (PresetKind::Mars, 0x45f1_f814_fedb_1295),
            // Earth: chunk vertices shaded from the columns at their edge's ends (the batch's).
            (PresetKind::Earth, 0xafe7_85e5_4e1d_a828),
        ];
        for (kind, digest) in want {
            let layout = kind.default_layout(None).unwrap();
            let got = testing::shade_digest(&build(kind, 42, &layout), &layout);
            assert_eq!(got, digest, "{kind}: digest now {got:#x}");
        }
    }

    #[test]
    fn presets_work_at_earth_radius() {
        // 6.4e6 m radius, 2 m voxels: the noise must neither quantise nor repeat, and the relief
        // still follows the shell.
        let layout = Layout::new(4096, 32, 6.4e6, 2.0, 2).unwrap();
        for kind in PresetKind::ALL {
            let t = build(kind, 3, &layout);
            testing::check_surface_within_bounds(&t, &layout);
            if kind != PresetKind::Sphere {
                let (lo, hi) = t.density.radial_bounds().unwrap();
                let dirs = testing::sphere_dirs(400);
                let heights: Vec<f64> = dirs
                    .iter()
                    .map(|d| {
                        let mut r = hi;
                        while r > lo && t.density.density(*d * r) <= 0.0 {
                            r -= 0.5;
                        }
                        r
                    })
                    .collect();
                let spread =
                    heights.iter().cloned().fold(f64::MIN, f64::max) - heights.iter().cloned().fold(f64::MAX, f64::min);
                assert!(spread > 0.1 * (hi - lo), "{kind}: relief {spread} m");
                // Neighbouring voxel columns (2 m apart) give close but distinct values.
                let d = dirs[7];
                let e = (d + d.any_orthonormal_vector() * (2.0 / 6.4e6)).normalize();
                let r = 0.5 * (lo + hi);
                let (a, b) = (t.density.density(d * r), t.density.density(e * r));
                assert!(a != b && (a - b).abs() < 5.0, "{kind}: {a} vs {b}");
            }
        }
    }
}
