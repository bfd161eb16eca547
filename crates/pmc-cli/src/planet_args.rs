//! The options that describe a planet, shared by every command.

use clap::Args;
use pmc_geometry::{Layout, LayoutError};
use pmc_planet::{Planet, PresetKind};

/// Preset, seed and the layout parameters of seed 000 Sec. 4.3, under the paper's names.
#[derive(Args, Debug, Clone)]
pub struct PlanetArgs {
    /// Terrain preset: sphere (an exact sphere, for checks), earthlike (continents, seas,
    /// mountains, caves and overhangs), moon (craters, maria, lava tubes) or mars (canyons,
    /// volcanoes, polar caps, caves).
    #[arg(long, default_value = "earthlike", value_parser = parse_preset)]
    pub preset: PresetKind,

    /// Seed for the terrain noise: the same seed and parameters give byte-identical output.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,

    /// n_c: chunks along each side of a cube face.
    #[arg(long = "n-c", default_value_t = 8, value_name = "N")]
    pub n_c: u32,

    /// n_t: tiles (marching cubes) along each side of a chunk, 1..=128.
    #[arg(long = "n-t", default_value_t = 32, value_name = "N")]
    pub n_t: u32,

    /// d_b: base depth, the radius in metres of the innermost voxel layer (at least l_d).
    #[arg(
        long = "d-b",
        default_value_t = 1744.0,
        value_name = "METRES",
        allow_negative_numbers = true
    )]
    pub d_b: f64,

    /// l_d: length of a depth (radial) tile edge in metres, above 0.
    #[arg(
        long = "l-d",
        default_value_t = 4.0,
        value_name = "METRES",
        allow_negative_numbers = true
    )]
    pub l_d: f64,

    /// d_c: chunks along the depth axis. The planet radius is d_b + l_d * n_t * d_c.
    #[arg(long = "d-c", default_value_t = 2, value_name = "N")]
    pub d_c: u32,
}

fn parse_preset(s: &str) -> Result<PresetKind, String> {
    s.parse::<PresetKind>().map_err(|e| e.to_string())
}

impl PlanetArgs {
    /// The validated layout.
    pub fn layout(&self) -> Result<Layout, LayoutError> {
        Layout::new(self.n_c, self.n_t, self.d_b, self.l_d, self.d_c)
    }

    /// Builds the planet.
    pub fn planet(&self) -> Result<Planet, LayoutError> {
        Ok(Planet::new(self.preset, self.seed, self.layout()?))
    }
}
