//! What a planet's terrain is made from: a named preset and a seed, or an elevation model.

use crate::presets::PresetKind;
use std::fmt;
use std::str::FromStr;

/// Where a planet's terrain comes from: the value a planet, a world file and the server's planet
/// identity are built from.
///
/// Two planets with equal specs (and equal layouts) have bit-identical terrain. The canonical
/// text form ([`Display`](fmt::Display) and [`FromStr`], also stored in world files) round-trips
/// exactly:
///
/// ```
/// use pmc_density::terrain::{DemSpec, Interpolation, TerrainSpec};
/// use pmc_density::presets::PresetKind;
///
/// let preset = TerrainSpec::preset(PresetKind::Earth, 7);
/// assert_eq!(preset.to_string(), "preset:earth:7");
///
/// let dem = TerrainSpec::Dem(DemSpec {
///     path: "data/earth.pmcdem".into(),
///     digest: "9f86d081884c7d65".into(),
///     interpolation: Interpolation::Bicubic,
///     seed: 0,
/// });
/// assert_eq!(dem.to_string(), "dem:bicubic:0:9f86d081884c7d65:data/earth.pmcdem");
/// for spec in [preset, dem] {
///     assert_eq!(spec.to_string().parse::<TerrainSpec>().unwrap(), spec);
/// }
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum TerrainSpec {
    /// A procedural preset.
    Preset {
        /// Which preset.
        kind: PresetKind,
        /// Its seed.
        seed: u64,
    },
    /// A digital elevation model reprojected onto the cube faces (a `.pmcdem` file), with
    /// procedural detail below its resolution and caves under its surface.
    Dem(DemSpec),
}

/// An elevation-model terrain: the cube-face elevation file and how it is sampled.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct DemSpec {
    /// The `.pmcdem` file, as given by the user (relative paths are resolved by whoever opens it).
    pub path: String,
    /// The content digest recorded in the file (lower-case hex): a planet is rebuilt only from
    /// the same data, whatever the file is called.
    pub digest: String,
    /// How heights between samples are interpolated.
    pub interpolation: Interpolation,
    /// The seed of the detail noise below the data's resolution and of the caves.
    pub seed: u64,
}

/// How an elevation model is interpolated between its samples; both return every sample's value
/// exactly at the sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// Bilinear in the face's sample indices: continuous, creased along sample rows.
    Bilinear,
    /// Catmull-Rom bicubic in the face's sample indices: a continuous first derivative within
    /// a face, no creases (the default). Samples past a face edge come from the neighbouring
    /// face, unfolded about the edge; along the two edges through a cube corner the samples past
    /// the corner are the corner's (clamped), so both faces of an edge interpolate it from the
    /// same samples.
    #[default]
    Bicubic,
}

impl Interpolation {
    /// The name used on the command line and in the canonical text.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Bilinear => "bilinear",
            Interpolation::Bicubic => "bicubic",
        }
    }
}

impl fmt::Display for Interpolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Interpolation {
    type Err = TerrainSpecError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "bilinear" => Ok(Interpolation::Bilinear),
            "bicubic" => Ok(Interpolation::Bicubic),
            _ => Err(TerrainSpecError(format!(
                "unknown interpolation {s:?} (choose bilinear or bicubic)"
            ))),
        }
    }
}

/// A terrain description that cannot be parsed; the message says what is wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("invalid terrain description: {0}")]
pub struct TerrainSpecError(pub String);

impl TerrainSpec {
    /// The preset `kind` with `seed`.
    pub fn preset(kind: PresetKind, seed: u64) -> TerrainSpec {
        TerrainSpec::Preset { kind, seed }
    }

    /// The preset, for a preset terrain.
    pub fn preset_kind(&self) -> Option<PresetKind> {
        match self {
            TerrainSpec::Preset { kind, .. } => Some(*kind),
            TerrainSpec::Dem(_) => None,
        }
    }

    /// The seed (of the preset, or of a DEM's detail noise and caves).
    pub fn seed(&self) -> u64 {
        match self {
            TerrainSpec::Preset { seed, .. } => *seed,
            TerrainSpec::Dem(d) => d.seed,
        }
    }

    /// A short name for people: the preset's name, or `dem` and the file's name.
    pub fn name(&self) -> String {
        match self {
            TerrainSpec::Preset { kind, .. } => kind.name().to_string(),
            TerrainSpec::Dem(d) => {
                let file = d.path.rsplit(['/', '\\']).next().unwrap_or(&d.path);
                format!("dem {file}")
            }
        }
    }
}

impl fmt::Display for TerrainSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TerrainSpec::Preset { kind, seed } => write!(f, "preset:{}:{seed}", kind.name()),
            TerrainSpec::Dem(d) => write!(f, "dem:{}:{}:{}:{}", d.interpolation, d.seed, d.digest, d.path),
        }
    }
}

impl FromStr for TerrainSpec {
    type Err = TerrainSpecError;

    /// Parses the canonical text: `preset:NAME:SEED` or `dem:INTERPOLATION:SEED:DIGEST:PATH`
    /// (the path last, so it may hold colons).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = |what: String| TerrainSpecError(what);
        let seed = |t: &str| -> Result<u64, TerrainSpecError> {
            t.parse()
                .map_err(|_| bad(format!("seed {t:?} is not a decimal number from 0 to 2^64-1")))
        };
        if let Some(rest) = s.strip_prefix("preset:") {
            let (name, sd) = rest
                .split_once(':')
                .ok_or_else(|| bad(format!("{s:?}: expected preset:NAME:SEED")))?;
            let kind = name.parse::<PresetKind>().map_err(|e| bad(e.to_string()))?;
            return Ok(TerrainSpec::Preset { kind, seed: seed(sd)? });
        }
        if let Some(rest) = s.strip_prefix("dem:") {
            let mut parts = rest.splitn(4, ':');
            let (Some(interp), Some(sd), Some(digest), Some(path)) =
                (parts.next(), parts.next(), parts.next(), parts.next())
            else {
                return Err(bad(format!("{s:?}: expected dem:INTERPOLATION:SEED:DIGEST:PATH")));
            };
            if digest.is_empty() || !digest.bytes().all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase()) {
                return Err(bad(format!("digest {digest:?} is not lower-case hexadecimal")));
            }
            if path.is_empty() || path.chars().any(char::is_control) {
                return Err(bad(format!("path {path:?} is empty or holds control characters")));
            }
            return Ok(TerrainSpec::Dem(DemSpec {
                path: path.to_string(),
                digest: digest.to_string(),
                interpolation: interp.parse()?,
                seed: seed(sd)?,
            }));
        }
        Err(bad(format!(
            "{s:?}: expected preset:NAME:SEED or dem:INTERPOLATION:SEED:DIGEST:PATH"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn bad_texts_are_refused() {
        for s in [
            "",
            "preset:venus:1",
            "preset:earth",
            "preset:earth:-1",
            "preset:earth:1.5",
            "dem:bicubic:0:abc",
            "dem:trilinear:0:abc:x.pmcdem",
            "dem:bicubic:0:ABC:x.pmcdem",
            "dem:bicubic:0::x.pmcdem",
            "dem:bicubic:0:abc:",
            "dem:bicubic:0:abc:a\nb",
            "earth",
        ] {
            assert!(s.parse::<TerrainSpec>().is_err(), "{s:?} parsed");
        }
    }

    proptest! {
        #[test]
        fn the_text_round_trips(seed: u64, k in 0usize..5, digest in "[0-9a-f]{1,64}", path in "[a-zA-Z0-9 ./:_é\\\\-]{1,40}", cubic: bool) {
            let specs = [
                TerrainSpec::preset(PresetKind::ALL[k], seed),
                TerrainSpec::Dem(DemSpec {
                    path,
                    digest,
                    interpolation: if cubic { Interpolation::Bicubic } else { Interpolation::Bilinear },
                    seed,
                }),
            ];
            for s in specs {
                prop_assert_eq!(s.to_string().parse::<TerrainSpec>().unwrap(), s);
            }
        }
    }
}
