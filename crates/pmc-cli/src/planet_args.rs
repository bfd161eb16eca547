//! The options that describe a planet, shared by every command.
//!
//! The layout comes from the preset unless options say otherwise: `--radius R` picks the
//! preset's layout for that radius ([`PresetKind::default_layout`]) and cannot be combined with
//! the five layout options; without it, each of `--n-c`, `--n-t`, `--d-b`, `--l-d`, `--d-c` that
//! is typed replaces that parameter of the preset's own layout (the Earth at true scale for
//! `--preset earth`, the 2000 m default planet for the others).

use crate::error::CliError;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, Command, FromArgMatches};
use pmc_geometry::Layout;
use pmc_planet::{Interpolation, LayoutChoice, Planet, PresetKind, TerrainError, TerrainSpec};

/// The ids of the five layout options, in the order of [`Layout::new`]'s parameters.
const LAYOUT_IDS: [&str; 5] = ["n_c", "n_t", "d_b", "l_d", "d_c"];

/// The planet options as clap parses them.
#[derive(Args, Debug, Clone)]
struct PlanetOptions {
    /// Terrain preset: sphere (an exact sphere, for checks), earthlike (continents, seas,
    /// mountains, caves and overhangs), moon (craters, maria, lava tubes), mars (canyons,
    /// volcanoes, polar caps, caves) or earth (the Earth at true scale, 6 371 km with 1 m voxels,
    /// on its own layout unless layout options are given).
    #[arg(long, default_value = "earthlike", value_parser = parse_preset)]
    preset: PresetKind,

    /// A real planet instead of a preset: a cube-face elevation file made by `pmc dem import`
    /// (the body's radius gives the layout; detail noise below the data's resolution and caves
    /// under its land come from --seed).
    #[arg(long, value_name = "FILE.pmcdem", conflicts_with = "preset")]
    dem: Option<std::path::PathBuf>,

    /// How heights of --dem are interpolated between samples: bicubic or bilinear (both exact at
    /// the samples).
    #[arg(long, value_name = "METHOD", default_value = "bicubic", value_parser = parse_interpolation)]
    interpolation: Interpolation,

    /// Seed for the terrain noise: the same seed and parameters give byte-identical output.
    #[arg(long, default_value_t = 7)]
    seed: u64,

    /// Planet radius in metres (100 to 1e8): picks the preset's layout for it, with the middle of
    /// the shell (the sea of the earth preset) at this radius, voxels of 1 to 2 m and chunks per
    /// face side a power of two. Cannot be combined with --n-c, --n-t, --d-b, --l-d, --d-c.
    #[arg(
        long,
        value_name = "METRES",
        allow_negative_numbers = true,
        conflicts_with_all = LAYOUT_IDS
    )]
    radius: Option<f64>,

    /// n_c: chunks along each side of a cube face [preset's layout: 8; earth: 262144].
    #[arg(long = "n-c", default_value_t = 8, value_name = "N", hide_default_value = true)]
    n_c: u32,

    /// n_t: tiles (marching cubes) along each side of a chunk, 1..=128 [preset's layout: 32].
    #[arg(long = "n-t", default_value_t = 32, value_name = "N", hide_default_value = true)]
    n_t: u32,

    /// d_b: base depth, the radius in metres of the innermost voxel layer (at least l_d)
    /// [preset's layout: 1744; earth: 6354616].
    #[arg(
        long = "d-b",
        default_value_t = 1744.0,
        value_name = "METRES",
        allow_negative_numbers = true,
        hide_default_value = true
    )]
    d_b: f64,

    /// l_d: length of a depth (radial) tile edge in metres, above 0 [preset's layout: 4; earth: 1].
    #[arg(
        long = "l-d",
        default_value_t = 4.0,
        value_name = "METRES",
        allow_negative_numbers = true,
        hide_default_value = true
    )]
    l_d: f64,

    /// d_c: chunks along the depth axis. The planet radius is d_b + l_d * n_t * d_c
    /// [preset's layout: 2; earth: 1024].
    #[arg(long = "d-c", default_value_t = 2, value_name = "N", hide_default_value = true)]
    d_c: u32,
}

fn parse_preset(s: &str) -> Result<PresetKind, String> {
    s.parse::<PresetKind>().map_err(|e| e.to_string())
}

fn parse_interpolation(s: &str) -> Result<Interpolation, String> {
    s.parse::<Interpolation>().map_err(|e| e.to_string())
}

/// Preset, seed and layout (`--radius`, or the parameters of seed 000 Sec. 4.3 under the
/// paper's names). The layout fields hold what was typed, or the default planet's value when
/// nothing was; [`PlanetArgs::layout`] resolves them against the preset's layout.
#[derive(Debug, Clone)]
pub struct PlanetArgs {
    /// Terrain preset.
    pub preset: PresetKind,
    /// The elevation file, if `--dem` was given (it replaces the preset).
    pub dem: Option<std::path::PathBuf>,
    /// Interpolation of `--dem`.
    pub interpolation: Interpolation,
    /// Noise seed.
    pub seed: u64,
    /// Planet radius in metres, if `--radius` was given.
    pub radius: Option<f64>,
    /// `n_c` as typed (or 8).
    pub n_c: u32,
    /// `n_t` as typed (or 32).
    pub n_t: u32,
    /// `d_b` as typed (or 1744).
    pub d_b: f64,
    /// `l_d` as typed (or 4).
    pub l_d: f64,
    /// `d_c` as typed (or 2).
    pub d_c: u32,
    /// Which of the five layout options were typed, in [`LAYOUT_IDS`] order.
    typed: [bool; 5],
}

impl FromArgMatches for PlanetArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let o = PlanetOptions::from_arg_matches(matches)?;
        let typed = LAYOUT_IDS.map(|id| matches.value_source(id) == Some(ValueSource::CommandLine));
        Ok(PlanetArgs {
            preset: o.preset,
            dem: o.dem,
            interpolation: o.interpolation,
            seed: o.seed,
            radius: o.radius,
            n_c: o.n_c,
            n_t: o.n_t,
            d_b: o.d_b,
            l_d: o.l_d,
            d_c: o.d_c,
            typed,
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = PlanetArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

impl Args for PlanetArgs {
    fn group_id() -> Option<clap::Id> {
        PlanetOptions::group_id()
    }
    fn augment_args(cmd: Command) -> Command {
        PlanetOptions::augment_args(cmd)
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        PlanetOptions::augment_args_for_update(cmd)
    }
}

impl PlanetArgs {
    /// The terrain: the preset and seed, or the `--dem` file (opened to read its digest; the
    /// path is kept absolute, so a world made from it opens from any directory).
    pub fn terrain(&self) -> Result<TerrainSpec, CliError> {
        match &self.dem {
            None => Ok(TerrainSpec::preset(self.preset, self.seed)),
            Some(path) => dem_terrain(path, self.interpolation, self.seed),
        }
    }

    /// The validated layout for `terrain` (from [`PlanetArgs::terrain`]): the preset's layout
    /// for `--radius`, or the terrain's own layout (the preset's, or the one for an elevation
    /// model's body radius) with each typed layout option replacing its parameter.
    pub fn layout_for(&self, terrain: &TerrainSpec) -> Result<Layout, CliError> {
        let typed = |i: usize| self.typed[i];
        let choice = LayoutChoice {
            radius: self.radius,
            n_c: typed(0).then_some(self.n_c),
            n_t: typed(1).then_some(self.n_t),
            d_b: typed(2).then_some(self.d_b),
            l_d: typed(3).then_some(self.l_d),
            d_c: typed(4).then_some(self.d_c),
        };
        choice.resolve(terrain).map_err(|e| match e {
            TerrainError::Radius(r) => CliError::from(r),
            TerrainError::Layout(l) => CliError::from(l),
            TerrainError::RadiusWithDem => {
                CliError::Dem("--radius does not apply to --dem: the elevation file gives the body's radius".into())
            }
            e => CliError::Dem(e.to_string()),
        })
    }

    /// Builds the planet.
    pub fn planet(&self) -> Result<Planet, CliError> {
        let terrain = self.terrain()?;
        let layout = self.layout_for(&terrain)?;
        Planet::from_terrain(&terrain, layout).map_err(|e| CliError::Dem(e.to_string()))
    }
}

/// The terrain of the elevation file at `path` ([`pmc_planet::dem_terrain`]).
pub(crate) fn dem_terrain(
    path: &std::path::Path,
    interpolation: Interpolation,
    seed: u64,
) -> Result<TerrainSpec, CliError> {
    pmc_planet::dem_terrain(path, interpolation, seed).map_err(|e| CliError::Dem(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        planet: PlanetArgs,
    }

    fn layout(args: &[&str]) -> Result<Layout, String> {
        let cli = Cli::try_parse_from(std::iter::once("pmc").chain(args.iter().copied())).map_err(|e| e.to_string())?;
        let p = &cli.planet;
        p.terrain().and_then(|t| p.layout_for(&t)).map_err(|e| e.to_string())
    }

    #[test]
    fn layouts_follow_the_preset_radius_and_typed_options() {
        assert_eq!(layout(&[]).unwrap(), Layout::default());
        let earth = PresetKind::Earth.default_layout(None).unwrap();
        assert_eq!(layout(&["--preset", "earth"]).unwrap(), earth);
        // A typed option replaces only its parameter of the preset's layout.
        let l = layout(&["--preset", "earth", "--d-c", "2048"]).unwrap();
        assert_eq!(
            (l.n_c(), l.d_b(), l.l_d(), l.d_c()),
            (earth.n_c(), earth.d_b(), 1.0, 2048)
        );
        let l = layout(&["--preset", "moon", "--n-c", "16"]).unwrap();
        assert_eq!((l.n_c(), l.d_b(), l.d_c()), (16, 1744.0, 2));
        // Typing the default value still counts as typed.
        let l = layout(&["--preset", "earth", "--n-c", "8"]).unwrap();
        assert_eq!((l.n_c(), l.d_c()), (8, 1024));
        let moon = layout(&["--preset", "moon", "--radius", "1737400"]).unwrap();
        assert_eq!(moon, PresetKind::Moon.default_layout(Some(1_737_400.0)).unwrap());
    }

    #[test]
    fn radius_errors_are_clear() {
        let e = layout(&["--radius", "5000", "--n-c", "4"]).unwrap_err();
        assert!(e.contains("--radius") && e.contains("--n-c"), "{e}");
        for (r, needle) in [
            ("-5", "above 0"),
            ("0", "above 0"),
            ("NaN", "finite"),
            ("1e9", "between"),
            ("50", "between"),
        ] {
            let e = layout(&["--radius", r]).unwrap_err();
            assert!(e.contains(needle), "{r}: {e}");
        }
        assert!(layout(&["--radius", "abc"]).unwrap_err().contains("--radius"));
    }
}

/// The meshers, by their command-line names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MesherName {
    /// Marching cubes in spherical space.
    Volumetric,
    /// The height-field quadtree of 65 x 65 patches.
    Heightfield,
}

impl From<MesherName> for pmc_server::Mesher {
    fn from(m: MesherName) -> Self {
        match m {
            MesherName::Volumetric => pmc_server::Mesher::Volumetric,
            MesherName::Heightfield => pmc_server::Mesher::Heightfield,
        }
    }
}
