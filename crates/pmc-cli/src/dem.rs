//! `pmc dem`: import elevation models onto the cube faces, describe the files, probe a place.

use crate::error::CliError;
use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pmc_dem::{CubeDem, DemError, EquirectSource, FormatChoice, ImportOptions, PngExtent};
use pmc_geometry::LatLon;
use pmc_planet::{Interpolation, Planet, TerrainSpec};
use std::path::{Path, PathBuf};

/// `pmc dem` and its subcommands.
#[derive(Args, Debug)]
pub struct DemArgs {
    #[command(subcommand)]
    command: DemCommand,
}

#[derive(Subcommand, Debug)]
enum DemCommand {
    /// Import an equirectangular elevation model (netCDF classic such as NOAA ETOPO, GeoTIFF,
    /// or a 16-bit PNG with --extent) into one .pmcdem file: the grid itself, from which heights
    /// are interpolated (equal to the data at every data point), and its reprojection onto six
    /// cube faces of 2^n + 1 samples. Then reports, over every data point, how far the planet's
    /// height lies from the data (max, 99th percentile, RMS) and the file's size.
    Import(ImportArgs),
    /// Describe a .pmcdem file: its source, levels and the storage table (size and metres per
    /// sample at each level).
    Info(InfoArgs),
    /// Print, at a place, the elevation model's value, the interpolated height and the height of
    /// the meshed surface at every level of detail.
    Probe(ProbeArgs),
}

/// Input formats of `pmc dem import`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum InputFormat {
    /// netCDF classic or 64-bit offset (CDF-1, CDF-2).
    Netcdf,
    /// GeoTIFF, geographic (latitude and longitude) grids.
    Geotiff,
    /// A 16-bit greyscale PNG (needs --extent).
    Png,
}

/// Sample formats of `pmc dem import`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Bits {
    /// 16-bit integers when every value is a whole number of metres in range, else 32-bit floats.
    Auto,
    /// 16-bit integers scaled to the data's range (lossy for fractional data).
    #[value(name = "16")]
    I16,
    /// 32-bit floats.
    #[value(name = "32")]
    F32,
}

/// `pmc dem import`.
#[derive(Args, Debug)]
struct ImportArgs {
    /// The elevation model to import.
    input: PathBuf,
    /// The .pmcdem file to write (never left half-written: it appears only when complete).
    #[arg(short, long, value_name = "FILE.pmcdem")]
    output: PathBuf,
    /// The input's format [default: from the file's first bytes].
    #[arg(long, value_enum)]
    format: Option<InputFormat>,
    /// netCDF: the variable holding the heights [default: the only 2-D grid with coordinates].
    #[arg(long, value_name = "NAME")]
    variable: Option<String>,
    /// Data level n: faces of 2^n + 1 samples a side, and the spacing of the coarsest detail
    /// octave [default: the smallest n whose spacing at a face's centre is at most the input's at
    /// the equator]. Heights come from the input grid itself at any level: the level does not
    /// change them at the data points.
    #[arg(long, value_name = "N")]
    level: Option<u32>,
    /// Sample format.
    #[arg(long, value_enum, default_value = "auto")]
    bits: Bits,
    /// Body radius in metres (6371000: the Earth; 3389500: Mars; 1737400: the Moon).
    #[arg(long, value_name = "METRES", default_value_t = pmc_dem::DEFAULT_RADIUS)]
    radius: f64,
    /// Most megabytes of input rows held at once: a model larger than memory imports band by band.
    #[arg(long = "memory-mb", value_name = "MB", default_value_t = 512)]
    memory_mb: usize,
    /// PNG: the extent WEST,SOUTH,EAST,NORTH in degrees (cell edges).
    #[arg(long, value_name = "W,S,E,N", allow_hyphen_values = true)]
    extent: Option<String>,
    /// PNG: metres per unit of the 16-bit value.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    scale: f64,
    /// PNG: metres added after scaling.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    offset: f64,
    /// PNG: the 16-bit value that marks missing samples.
    #[arg(long, value_name = "VALUE")]
    nodata: Option<u16>,
    /// Worker threads; 0 uses every core.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Skip the check of the heights at every data point (a few seconds for ETOPO5).
    #[arg(long)]
    no_check: bool,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
    /// Also import this colour image (JPEG, PNG or GeoTIFF; the whole globe unless a GeoTIFF
    /// says otherwise) into imagery beside the output: the same name with extension .pmcimg
    /// (see `pmc imagery import`, which also takes an extent).
    #[arg(long, value_name = "IMAGE")]
    imagery: Option<PathBuf>,
}

/// `pmc dem info`.
#[derive(Args, Debug)]
struct InfoArgs {
    /// The .pmcdem file.
    file: PathBuf,
    /// Read and check every tile (checksums), not only the header.
    #[arg(long)]
    verify: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `pmc dem probe`.
#[derive(Args, Debug)]
struct ProbeArgs {
    /// The .pmcdem file.
    file: PathBuf,
    /// Latitude, degrees north.
    #[arg(long, allow_negative_numbers = true)]
    lat: f64,
    /// Longitude, degrees east.
    #[arg(long, allow_negative_numbers = true)]
    lon: f64,
    /// Interpolation between samples.
    #[arg(long, default_value = "bicubic", value_parser = parse_interpolation)]
    interpolation: Interpolation,
    /// Seed of the detail noise and caves.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

fn parse_interpolation(s: &str) -> Result<Interpolation, String> {
    s.parse::<Interpolation>().map_err(|e| e.to_string())
}

/// Runs `pmc dem`.
pub fn run(args: &DemArgs) -> Result<(), CliError> {
    match &args.command {
        DemCommand::Import(a) => import(a),
        DemCommand::Info(a) => info(a),
        DemCommand::Probe(a) => probe(a),
    }
}

fn dem_error(e: DemError) -> CliError {
    CliError::Dem(e.to_string())
}

/// The format of `path` from its first bytes.
fn sniff(path: &Path) -> Result<InputFormat, CliError> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .map_err(|e| CliError::Dem(format!("{}: cannot read the file: {e}", path.display())))?;
    let head = &head[..n];
    if head.starts_with(b"CDF") {
        Ok(InputFormat::Netcdf)
    } else if head.starts_with(b"II*\0") || head.starts_with(b"MM\0*") {
        Ok(InputFormat::Geotiff)
    } else if head.starts_with(b"\x89PNG") {
        Ok(InputFormat::Png)
    } else {
        Err(CliError::Dem(format!(
            "{}: not a netCDF classic, GeoTIFF or PNG file (by its first bytes); give --format if it is one",
            path.display()
        )))
    }
}

fn parse_extent(s: &str) -> Result<[f64; 4], CliError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| CliError::Dem(format!("--extent {s:?}: expected WEST,SOUTH,EAST,NORTH in degrees")))?;
    <[f64; 4]>::try_from(v).map_err(|_| CliError::Dem(format!("--extent {s:?}: expected four numbers")))
}

fn import(a: &ImportArgs) -> Result<(), CliError> {
    // The imagery is read first, so that a bad image fails before the long import.
    let imagery = (a.imagery.as_deref())
        .map(|p| crate::imagery::read_image(p, None))
        .transpose()?;
    let format = match a.format {
        Some(f) => f,
        None => sniff(&a.input)?,
    };
    if a.extent.is_some() && format != InputFormat::Png {
        return Err(CliError::Dem(
            "--extent applies to PNG input only (other formats carry their extent)".into(),
        ));
    }
    let source: Box<dyn EquirectSource> = match format {
        InputFormat::Netcdf => {
            Box::new(pmc_dem::NetcdfSource::open(&a.input, a.variable.as_deref()).map_err(dem_error)?)
        }
        InputFormat::Geotiff => Box::new(pmc_dem::GeoTiffSource::open(&a.input).map_err(dem_error)?),
        InputFormat::Png => {
            let Some(extent) = &a.extent else {
                return Err(CliError::Dem(
                    "a PNG holds no georeferencing: give --extent WEST,SOUTH,EAST,NORTH (and --scale, --offset, --nodata as needed)".into(),
                ));
            };
            let [west, south, east, north] = parse_extent(extent)?;
            let ext = PngExtent {
                west,
                south,
                east,
                north,
                scale: a.scale,
                offset: a.offset,
                nodata: a.nodata,
                cell_centres: true,
            };
            Box::new(pmc_dem::EquirectDem::read_png16(&a.input, &ext).map_err(dem_error)?)
        }
    };
    let options = ImportOptions {
        level: a.level,
        format: match a.bits {
            Bits::Auto => FormatChoice::Auto,
            Bits::I16 => FormatChoice::I16,
            Bits::F32 => FormatChoice::F32,
        },
        memory_budget: a.memory_mb.max(1).saturating_mul(1 << 20),
        radius: a.radius,
        ..ImportOptions::default()
    };
    let bar = if a.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} reprojecting tiles {bar:40} {pos}/{len} ({elapsed}, eta {eta})")
            .expect("valid template"),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()
        .map_err(|e| CliError::Threads {
            threads: a.threads,
            reason: e.to_string(),
        })?;
    let start = std::time::Instant::now();
    let report = pool
        .install(|| {
            pmc_dem::import_cube(source.as_ref(), &a.output, &options, &|done, total| {
                bar.set_length(total);
                bar.set_position(done);
            })
        })
        .map_err(dem_error)?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    if !a.quiet {
        eprintln!(
            "imported {} ({} x {}) into {}: level {} ({} samples a face side), {:?}, {} samples filled, {:.1} MB (source grid {:.1} MB) in {:.2} s; digest {}",
            source.name(),
            source.width(),
            source.height(),
            a.output.display(),
            report.level,
            (1u64 << report.level) + 1,
            report.format,
            report.source_filled,
            report.bytes as f64 / 1e6,
            report.source_bytes as f64 / 1e6,
            seconds,
            report.digest
        );
    }
    let checks = if a.no_check {
        Vec::new()
    } else {
        let cube = CubeDem::open(&a.output).map_err(dem_error)?;
        let detail = pmc_dem::DetailNoise::default();
        [Interpolation::Bilinear, Interpolation::Bicubic]
            .into_iter()
            .map(|interp| pool.install(|| pmc_dem::cube::accuracy(&cube, source.as_ref(), interp, &detail)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(dem_error)?
    };
    if !a.quiet {
        for c in &checks {
            eprintln!(
                "{:?} heights at the {} data points (detail on): error max {:.3} m, 99th percentile {:.3} m, RMS {:.3} m",
                c.interpolation, c.samples, c.max, c.p99, c.rms
            );
        }
    }
    if a.json {
        let accuracy: Vec<serde_json::Value> = checks
            .iter()
            .map(|c| {
                serde_json::json!({
                    "interpolation": c.interpolation.to_string(),
                    "samples": c.samples,
                    "missing": c.missing,
                    "max_error_m": c.max,
                    "p99_error_m": c.p99,
                    "rms_error_m": c.rms,
                    "worst": c.worst.map(|w| serde_json::json!({
                        "lat": w.lat, "lon": w.lon, "value_m": w.value, "height_m": w.height,
                    })),
                })
            })
            .collect();
        let out = serde_json::json!({
            "output": a.output.display().to_string(),
            "source": source.name(),
            "width": source.width(),
            "height": source.height(),
            "level": report.level,
            "bytes": report.bytes,
            "source_bytes": report.source_bytes,
            "source_filled": report.source_filled,
            "seconds": seconds,
            "digest": report.digest,
            "accuracy": accuracy,
        });
        outln!("{}", serde_json::to_string_pretty(&out).expect("JSON"));
    }
    if let (Some(img), Some(input)) = (&imagery, &a.imagery) {
        crate::imagery::write_image(img, input, &crate::imagery::beside(&a.output), a.quiet)?;
    }
    Ok(())
}

fn info(a: &InfoArgs) -> Result<(), CliError> {
    let dem = CubeDem::open(&a.file).map_err(dem_error)?;
    if a.verify {
        dem.verify().map_err(dem_error)?;
    }
    let table = dem.storage_table();
    let (lo, hi) = dem.value_range();
    if a.json {
        let rows: Vec<serde_json::Value> = table
            .iter()
            .map(|r| {
                serde_json::json!({
                    "log2": r.log2,
                    "samples_per_side": r.samples_per_side,
                    "stored": r.stored,
                    "bytes_16bit": r.bytes_16bit,
                    "bytes_stored": r.bytes_stored,
                    "metres_per_sample_centre": r.metres_at_centre,
                    "metres_per_sample_equator": r.metres_at_equator,
                })
            })
            .collect();
        let v = serde_json::json!({
            "file": a.file.display().to_string(),
            "source": dem.source_name(),
            "radius": dem.radius(),
            "data_level": dem.data_level(),
            "format": format!("{:?}", dem.format()),
            "digest": dem.digest(),
            "filled_samples": dem.filled_samples(),
            "source_extent": dem.source_extent(),
            "version": dem.version(),
            "source_grid": dem.source_size().map(|(w, h)| serde_json::json!({
                "width": w, "height": h, "bytes": dem.source_bytes(),
            })),
            "value_range": [lo, hi],
            "verified": a.verify,
            "levels": rows,
        });
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        return Ok(());
    }
    outln!("file         {}", a.file.display());
    outln!("source       {}", dem.source_name());
    let [west, east, south, north] = dem.source_extent();
    outln!("extent       {west}..{east} E, {south}..{north} N (degrees, sample positions)");
    outln!("body radius  {} m", dem.radius());
    outln!(
        "data level   {} ({} samples a face side), {:?} samples, {} filled",
        dem.data_level(),
        (1u64 << dem.data_level()) + 1,
        dem.format(),
        dem.filled_samples()
    );
    match dem.source_size() {
        Some((w, h)) => outln!(
            "source grid  {w} x {h} samples, {} (heights interpolated from it: version {})",
            human(dem.source_bytes()),
            dem.version()
        ),
        None => outln!(
            "source grid  not kept (version {}: heights interpolated from the faces)",
            dem.version()
        ),
    }
    outln!("heights      {lo} m to {hi} m");
    outln!("digest       {}", dem.digest());
    if a.verify {
        outln!("verified     every tile's checksum");
    }
    outln!();
    outln!("samples a face side   six faces at 16 bits   in this file   m/sample (face centre)   m/sample (equator)");
    for r in &table {
        outln!(
            "{:>19}  {:>21}  {:>13}  {:>23.2}  {:>19.2}",
            format!("2^{} + 1 = {}", r.log2, r.samples_per_side),
            human(r.bytes_16bit),
            r.bytes_stored.map_or_else(|| "detail noise".to_string(), human),
            r.metres_at_centre,
            r.metres_at_equator
        );
    }
    Ok(())
}

/// Bytes in KB, MB, GB, TB or PB (powers of 1000, as seed 003 Fig. 13 prints them).
fn human(b: u64) -> String {
    let b = b as f64;
    if b >= 1e15 {
        format!("{:.1} PB", b / 1e15)
    } else if b >= 1e12 {
        format!("{:.1} TB", b / 1e12)
    } else if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else {
        format!("{:.1} KB", b / 1e3)
    }
}

fn probe(a: &ProbeArgs) -> Result<(), CliError> {
    let ll = LatLon::new(a.lat, a.lon).map_err(|e| CliError::Dem(format!("--lat/--lon: {e}")))?;
    let dir = ll.to_unit();
    let spec = crate::planet_args::dem_terrain(&a.file, a.interpolation, a.seed)?;
    let TerrainSpec::Dem(dem_spec) = &spec else {
        unreachable!("dem_terrain gives an elevation-model terrain")
    };
    let layout = pmc_planet::default_layout(&spec).map_err(|e| CliError::Dem(e.to_string()))?;
    let planet = Planet::from_terrain(&spec, layout).map_err(|e| CliError::Dem(e.to_string()))?;
    let dem = std::sync::Arc::new(CubeDem::open(&a.file).map_err(dem_error)?);
    let sample = pmc_dem::nearest_sample(&dem, dir).map_err(dem_error)?;
    let (heights, _) = pmc_dem::dem_heights(dem, dem_spec, &layout);
    let interpolated = pmc_dem::HeightField::height(&heights, dir);
    let sea = planet.datum_radius();
    let levels: Vec<(u8, Option<f64>)> = (0..=layout.max_level())
        .map(|level| {
            (
                level,
                pmc_lod::probe::meshed_surface_radius(&planet, dir, level).map(|r| r - sea),
            )
        })
        .collect();
    if a.json {
        let v = serde_json::json!({
            "lat": a.lat,
            "lon": a.lon,
            "nearest_sample": { "lat": sample.lat, "lon": sample.lon, "value": sample.value, "distance_m": sample.distance },
            "interpolated": interpolated,
            "meshed": levels.iter().map(|(l, h)| serde_json::json!({"level": l, "height": h})).collect::<Vec<_>>(),
        });
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        return Ok(());
    }
    outln!("place           {}, {}", a.lat, a.lon);
    outln!(
        "DEM sample      {} m (nearest sample at {:.4}, {:.4}, {:.0} m away)",
        sample.value,
        sample.lat,
        sample.lon,
        sample.distance
    );
    outln!(
        "interpolated    {interpolated:.3} m ({}, with detail noise)",
        a.interpolation
    );
    for (level, h) in &levels {
        match h {
            Some(h) => outln!("meshed level {level:>2} {h:.3} m ({:+.3} m)", h - interpolated),
            None => outln!("meshed level {level:>2} no surface met"),
        }
    }
    Ok(())
}
