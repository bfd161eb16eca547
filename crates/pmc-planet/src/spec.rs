//! A planet as its user describes it: a terrain (a preset and seed, or an elevation file) and
//! the layout options given, resolved the same way by every front end (the command line, the
//! Python package).

use crate::terrain::{default_layout, TerrainError};
use pmc_density::terrain::{DemSpec, Interpolation, TerrainSpec};
use pmc_geometry::Layout;
use std::path::Path;

/// The layout options of a planet, each `None` when not given.
///
/// With `radius`, the preset's layout for that radius
/// ([`PresetKind::default_layout`](pmc_density::presets::PresetKind::default_layout)); it cannot be combined with the five layout parameters, nor
/// given for an elevation model (the file gives the body's radius). Without it, each parameter
/// given replaces that parameter of the terrain's own layout ([`default_layout`]: the Earth at
/// true scale for the earth preset, the 2000 m default planet for the other presets, the layout
/// for an elevation model's body radius).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayoutChoice {
    /// Planet radius in metres.
    pub radius: Option<f64>,
    /// `n_c`: chunks along each side of a cube face.
    pub n_c: Option<u32>,
    /// `n_t`: tiles along each side of a chunk.
    pub n_t: Option<u32>,
    /// `d_b`: the radius of the innermost voxel layer, metres.
    pub d_b: Option<f64>,
    /// `l_d`: the length of a depth tile edge, metres.
    pub l_d: Option<f64>,
    /// `d_c`: chunks along the depth axis.
    pub d_c: Option<u32>,
}

impl LayoutChoice {
    /// Whether any of the five layout parameters is given.
    pub fn has_parameters(&self) -> bool {
        self.n_c.is_some() || self.n_t.is_some() || self.d_b.is_some() || self.l_d.is_some() || self.d_c.is_some()
    }

    /// The validated layout for `terrain`.
    ///
    /// Errors: [`TerrainError::RadiusWithLayout`], [`TerrainError::RadiusWithDem`],
    /// [`TerrainError::Radius`] (a radius out of range), [`TerrainError::Layout`] (parameters
    /// that make no layout), and those of opening an elevation file to read its radius.
    pub fn resolve(&self, terrain: &TerrainSpec) -> Result<Layout, TerrainError> {
        if let Some(r) = self.radius {
            if self.has_parameters() {
                return Err(TerrainError::RadiusWithLayout);
            }
            return match terrain {
                TerrainSpec::Preset { kind, .. } => Ok(kind.default_layout(Some(r))?),
                TerrainSpec::Dem(_) => Err(TerrainError::RadiusWithDem),
            };
        }
        let base = default_layout(terrain)?;
        Ok(Layout::new(
            self.n_c.unwrap_or(base.n_c()),
            self.n_t.unwrap_or(base.n_t()),
            self.d_b.unwrap_or(base.d_b()),
            self.l_d.unwrap_or(base.l_d()),
            self.d_c.unwrap_or(base.d_c()),
        )?)
    }
}

/// The terrain of the elevation file at `path` (made by `pmc dem import`): the file is opened to
/// read its digest, and the path is kept absolute, so that a world made from it opens from any
/// directory.
pub fn dem_terrain(path: &Path, interpolation: Interpolation, seed: u64) -> Result<TerrainSpec, TerrainError> {
    let dem = pmc_dem::CubeDem::open(path)?;
    let abs = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let text = abs
        .to_str()
        .ok_or_else(|| TerrainError::PathNotUtf8(path.display().to_string()))?;
    Ok(TerrainSpec::Dem(DemSpec {
        path: text.to_string(),
        digest: dem.digest().to_string(),
        interpolation,
        seed,
    }))
}

impl crate::Planet {
    /// The point at latitude `lat`, longitude `lon` (degrees) and `alt` metres above the datum;
    /// without `alt`, on the ground there (the first surface met going down from the top of the
    /// shell). Errors name what is wrong: a latitude or longitude out of range or not finite, an
    /// altitude that is not finite or puts the point at or below the planet's centre.
    pub fn place(&self, lat: f64, lon: f64, alt: Option<f64>) -> Result<pmc_geometry::glam::DVec3, String> {
        let dir = pmc_geometry::LatLon::new(lat, lon)
            .map_err(|e| e.to_string())?
            .to_unit();
        let r = match alt {
            Some(a) if !a.is_finite() => return Err(format!("the altitude {a} is not a finite number of metres")),
            Some(a) => self.datum_radius() + a,
            None => self.surface_radius(dir),
        };
        if r <= 0.0 {
            return Err(format!(
                "altitude {} m puts the point at or below the planet's centre (the datum is {} m from it)",
                alt.unwrap_or(0.0),
                self.datum_radius()
            ));
        }
        Ok(dir * r)
    }

    /// The brush named `name` (add, remove, smooth, flatten or paint) on this planet; paint
    /// takes a `material` by name or index among the terrain's materials, the others none.
    pub fn brush_kind(&self, name: &str, material: Option<&str>) -> Result<pmc_edit::BrushKind, String> {
        use pmc_edit::BrushKind;
        let names = self.terrain().materials;
        let list = || {
            names
                .iter()
                .enumerate()
                .map(|(i, n)| format!("{n} ({i})"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (name, material) {
            ("paint", None) => Err(format!("paint needs a material: one of {}", list())),
            ("paint", Some(m)) => {
                let index = match m.trim().parse::<usize>() {
                    Ok(i) => Some(i).filter(|&i| i < names.len()),
                    Err(_) => names.iter().position(|n| n.eq_ignore_ascii_case(m.trim())),
                };
                index
                    .and_then(|i| u8::try_from(i).ok())
                    .map(|material| BrushKind::Paint { material })
                    .ok_or_else(|| format!("unknown material '{m}' for this planet; choose one of: {}", list()))
            }
            ("add" | "remove" | "smooth" | "flatten", Some(_)) => {
                Err("a material applies to the paint brush only".into())
            }
            ("add", None) => Ok(BrushKind::Add),
            ("remove", None) => Ok(BrushKind::Remove),
            ("smooth", None) => Ok(BrushKind::Smooth),
            ("flatten", None) => Ok(BrushKind::Flatten),
            (other, _) => Err(format!(
                "unknown brush '{other}'; choose one of: add, remove, smooth, flatten, paint"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Planet, PresetKind};

    #[test]
    fn a_layout_choice_replaces_only_what_it_gives() {
        let earth = TerrainSpec::preset(PresetKind::Earth, 7);
        let base = default_layout(&earth).unwrap();
        assert_eq!(LayoutChoice::default().resolve(&earth).unwrap(), base);
        let l = LayoutChoice {
            d_c: Some(2048),
            ..LayoutChoice::default()
        }
        .resolve(&earth)
        .unwrap();
        assert_eq!((l.n_c(), l.d_b(), l.d_c()), (base.n_c(), base.d_b(), 2048));
        let moon = TerrainSpec::preset(PresetKind::Moon, 3);
        let r = LayoutChoice {
            radius: Some(1_737_400.0),
            ..LayoutChoice::default()
        };
        assert_eq!(
            r.resolve(&moon).unwrap(),
            PresetKind::Moon.default_layout(Some(1_737_400.0)).unwrap()
        );
        let both = LayoutChoice { n_c: Some(4), ..r };
        assert!(matches!(both.resolve(&moon), Err(TerrainError::RadiusWithLayout)));
        let bad = LayoutChoice {
            radius: Some(-1.0),
            ..LayoutChoice::default()
        };
        assert!(matches!(bad.resolve(&moon), Err(TerrainError::Radius(_))));
        let zero = LayoutChoice {
            n_t: Some(0),
            ..LayoutChoice::default()
        };
        assert!(matches!(zero.resolve(&moon), Err(TerrainError::Layout(_))));
    }

    #[test]
    fn places_and_brushes_are_checked() {
        let planet = Planet::new(PresetKind::Moon, 3, Layout::default());
        let ground = planet.place(10.0, 20.0, None).unwrap();
        assert!((ground.length() - planet.surface_radius(ground.normalize())).abs() < 1e-9);
        let up = planet.place(10.0, 20.0, Some(50.0)).unwrap();
        assert!((up.length() - planet.datum_radius() - 50.0).abs() < 1e-9);
        assert!(planet.place(91.0, 0.0, None).is_err());
        assert!(planet.place(0.0, f64::NAN, None).is_err());
        assert!(planet
            .place(0.0, 0.0, Some(f64::INFINITY))
            .unwrap_err()
            .contains("finite"));
        assert!(planet.place(0.0, 0.0, Some(-1e9)).unwrap_err().contains("centre"));
        use pmc_edit::BrushKind;
        assert_eq!(planet.brush_kind("remove", None).unwrap(), BrushKind::Remove);
        assert_eq!(
            planet.brush_kind("paint", Some("Mare")).unwrap(),
            BrushKind::Paint { material: 1 }
        );
        assert_eq!(
            planet.brush_kind("paint", Some("2")).unwrap(),
            BrushKind::Paint { material: 2 }
        );
        assert!(planet.brush_kind("paint", None).unwrap_err().contains("regolith (0)"));
        assert!(planet
            .brush_kind("paint", Some("cheese"))
            .unwrap_err()
            .contains("unknown material"));
        assert!(planet
            .brush_kind("add", Some("rock"))
            .unwrap_err()
            .contains("paint brush only"));
        assert!(planet
            .brush_kind("explode", None)
            .unwrap_err()
            .contains("unknown brush"));
    }
}
