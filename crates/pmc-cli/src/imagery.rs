//! `pmc imagery`: import a colour image (JPEG, PNG, GeoTIFF) into a `.pmcimg` imagery file to
//! drape on a planet (`pmc serve --imagery`), describe such a file, look up its colour at a place.

use crate::error::CliError;
use clap::{Args, Subcommand};
use pmc_imagery::{Extent, Imagery, ImageryError};
use std::path::{Path, PathBuf};

/// `pmc imagery` and its subcommands.
#[derive(Args, Debug)]
pub struct ImageryArgs {
    #[command(subcommand)]
    command: ImageryCommand,
}

#[derive(Subcommand, Debug)]
enum ImageryCommand {
    /// Import an equirectangular colour image (JPEG, PNG or GeoTIFF) into a .pmcimg file.
    Import(ImportArgs),
    /// Describe a .pmcimg file: size, extent, digest (the file's checksums are checked).
    Info(InfoArgs),
    /// Print the colour of a .pmcimg file at a place (bilinear, as the viewer samples it).
    Probe(ProbeArgs),
}

/// `pmc imagery import`.
#[derive(Args, Debug)]
struct ImportArgs {
    /// The image: JPEG, PNG or TIFF (told by its first bytes); row 0 the northern edge.
    input: PathBuf,
    /// The .pmcimg file to write (never left half-written: it appears only when complete).
    #[arg(short, long, value_name = "FILE.pmcimg")]
    output: PathBuf,
    /// The image's extent WEST,SOUTH,EAST,NORTH in degrees: the outer edges of its pixels
    /// [default: a GeoTIFF's georeferencing, else the whole globe -180,-90,180,90].
    #[arg(long, value_name = "W,S,E,N", allow_hyphen_values = true)]
    extent: Option<String>,
    /// Print nothing.
    #[arg(long)]
    quiet: bool,
}

/// `pmc imagery info`.
#[derive(Args, Debug)]
struct InfoArgs {
    /// The .pmcimg file.
    file: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `pmc imagery probe`.
#[derive(Args, Debug)]
struct ProbeArgs {
    /// The .pmcimg file.
    file: PathBuf,
    /// Latitude, degrees north.
    #[arg(long, allow_negative_numbers = true)]
    lat: f64,
    /// Longitude, degrees east.
    #[arg(long, allow_negative_numbers = true)]
    lon: f64,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `pmc imagery`.
pub fn run(args: &ImageryArgs) -> Result<(), CliError> {
    match &args.command {
        ImageryCommand::Import(a) => import(a),
        ImageryCommand::Info(a) => info(a),
        ImageryCommand::Probe(a) => probe(a),
    }
}

/// Reads the image `input` (for `pmc imagery import` and `pmc dem import --imagery`) over
/// `extent` (text `WEST,SOUTH,EAST,NORTH`; see [`Imagery::import`] for the default).
pub fn read_image(input: &Path, extent: Option<&str>) -> Result<Imagery, CliError> {
    let extent = extent
        .map(|s| {
            s.parse::<Extent>().map_err(|detail| ImageryError::InvalidExtent {
                file: format!("--extent for {}", input.display()),
                detail,
            })
        })
        .transpose()?;
    Ok(Imagery::import(input, extent)?)
}

/// Writes `img` to `output` and, unless `quiet`, says what was written.
pub fn write_image(img: &Imagery, input: &Path, output: &Path, quiet: bool) -> Result<(), CliError> {
    img.write(output)?;
    if !quiet {
        eprintln!(
            "imported {} ({} x {}, extent {}) into {}: {:.1} MB; digest {}",
            input.display(),
            img.width(),
            img.height(),
            img.extent(),
            output.display(),
            (pmc_imagery::pmcimg::HEADER_LEN + img.pixels().len()) as f64 / 1e6,
            img.digest()
        );
    }
    Ok(())
}

/// The `.pmcimg` file written beside the elevation file `dem` by `pmc dem import --imagery`:
/// the same path with the extension `.pmcimg`.
pub fn beside(dem: &Path) -> PathBuf {
    dem.with_extension("pmcimg")
}

fn import(a: &ImportArgs) -> Result<(), CliError> {
    let img = read_image(&a.input, a.extent.as_deref())?;
    write_image(&img, &a.input, &a.output, a.quiet)
}

fn info(a: &InfoArgs) -> Result<(), CliError> {
    let img = Imagery::open(&a.file)?;
    let e = img.extent();
    if a.json {
        let v = serde_json::json!({
            "file": a.file.display().to_string(),
            "width": img.width(),
            "height": img.height(),
            "extent": e.to_array(),
            "wraps": e.wraps(),
            "digest": img.digest(),
        });
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        return Ok(());
    }
    outln!("file     {}", a.file.display());
    outln!("size     {} x {} pixels, 8-bit RGB (sRGB)", img.width(), img.height());
    outln!(
        "extent   west {}, east {}, south {}, north {} (pixel edges){}",
        e.west(),
        e.east(),
        e.south(),
        e.north(),
        if e.wraps() { ", round the globe" } else { "" }
    );
    outln!(
        "pixel    {} x {} degrees",
        e.lon_span() / f64::from(img.width()),
        e.lat_span() / f64::from(img.height())
    );
    outln!("digest   {}", img.digest());
    Ok(())
}

fn probe(a: &ProbeArgs) -> Result<(), CliError> {
    let img = Imagery::open(&a.file)?;
    let color = img.color_at(a.lat, a.lon);
    if a.json {
        let v = serde_json::json!({ "lat": a.lat, "lon": a.lon, "rgb": color });
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        return Ok(());
    }
    match color {
        Some([r, g, b]) => outln!("{r} {g} {b}"),
        None => outln!("outside the image (extent {})", img.extent()),
    }
    Ok(())
}
