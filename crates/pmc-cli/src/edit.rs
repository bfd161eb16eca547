//! `pmc edit`: dig and build on a planet kept in a world file (format pmc-world version 2,
//! docs/specs/world-sqlite-v2.md; version 1 files open too): apply a brush, undo, redo, list.

use crate::error::CliError;
use crate::planet_args::PlanetArgs;
use clap::{Args, Parser, ValueEnum};
use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{LatLon, Layout, Place};
use pmc_planet::{Interpolation, Planet, PresetKind, TerrainSpec};
use pmc_world::{Entry, World};
use std::io::Write;
use std::path::PathBuf;

/// With `--repeat N`, edit `k` (from 0) is centred at longitude `LON + k * REPEAT_LON_STEP`
/// degrees (latitude and altitude unchanged).
pub const REPEAT_LON_STEP: f64 = 0.01;

/// The brushes, by their command-line names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BrushName {
    /// Add material: the union with a ball.
    Add,
    /// Remove material: carve a ball.
    Remove,
    /// Smooth the surface toward its local average.
    Smooth,
    /// Flatten toward the plane through the centre, perpendicular to the local vertical.
    Flatten,
    /// Paint a material on the surface (needs --material).
    Paint,
}

/// Options of `pmc edit`.
#[derive(Args, Debug)]
pub struct EditArgs {
    /// The world file (SQLite, format pmc-world v2, docs/specs/world-sqlite-v2.md). Applying a brush to a missing file creates
    /// it with the planet options; an existing file keeps its own planet.
    #[arg(long, value_name = "FILE")]
    world: PathBuf,

    #[command(flatten)]
    planet: WorldPlanetArgs,

    /// The brush to apply.
    #[arg(value_enum, required_unless_present_any = ["undo", "redo", "list"])]
    brush: Option<BrushName>,

    /// Centre of the brush: latitude and longitude in degrees (north and east positive) and,
    /// optionally, the altitude in metres above the planet's datum (the sea surface, or the middle
    /// of the shell on planets without a sea). Without ALT the centre is put on the ground: the
    /// first surface met going down from the top of the shell. Write negative values as
    /// --at=-10,20 or --at -10,20.
    #[arg(long, value_name = "LAT,LON[,ALT]", allow_hyphen_values = true, requires = "brush")]
    at: Option<String>,

    /// Brush radius in metres, above 0 and at most 100000.
    #[arg(long, value_name = "METRES", allow_negative_numbers = true, requires = "brush")]
    radius: Option<f64>,

    /// Brush strength, above 0 and at most 1 [default: 1].
    #[arg(long, value_name = "S", allow_negative_numbers = true, requires = "brush")]
    strength: Option<f64>,

    /// Material to paint (paint only): its name (see `pmc info`) or its id.
    #[arg(long, value_name = "NAME|ID", requires = "brush")]
    material: Option<String>,

    /// Apply the brush N times, each committed and printed on its own; edit k (from 0) moves
    /// 0.01 degrees of longitude east per step: LON + 0.01 k.
    #[arg(long, value_name = "N", requires = "brush")]
    repeat: Option<u64>,

    /// Undo the last active edit (it is kept for --redo until the next edit).
    #[arg(long, conflicts_with_all = ["brush", "redo", "list"])]
    undo: bool,

    /// Redo the earliest undone edit.
    #[arg(long, conflicts_with_all = ["brush", "list"])]
    redo: bool,

    /// List the active edits in order (and how many are undone).
    #[arg(long, conflicts_with = "brush")]
    list: bool,

    /// With --list: print JSON instead of text.
    #[arg(long, requires = "list")]
    json: bool,
}

/// The planet options of `pmc generate`, all optional: they describe the planet of a world that
/// is created, and must agree with the world file when given for an existing one.
#[derive(Args, Debug, Clone, Default)]
pub struct WorldPlanetArgs {
    /// Terrain preset of a new world: sphere, earthlike, moon, mars or earth [default: earthlike].
    #[arg(long, value_parser = parse_preset)]
    preset: Option<PresetKind>,

    /// A new world on a real planet: a cube-face elevation file made by `pmc dem import`.
    #[arg(long, value_name = "FILE.pmcdem", conflicts_with = "preset")]
    dem: Option<PathBuf>,

    /// Interpolation of a new world's --dem: bicubic or bilinear [default: bicubic].
    #[arg(long, value_name = "METHOD", value_parser = parse_interpolation)]
    interpolation: Option<Interpolation>,

    /// Seed of a new world's terrain noise [default: 7].
    #[arg(long)]
    seed: Option<u64>,

    /// n_c of a new world: chunks along each side of a cube face [default: the preset's layout].
    #[arg(long = "n-c", value_name = "N")]
    n_c: Option<u32>,

    /// n_t of a new world: tiles along each side of a chunk, 1..=128 [default: the preset's layout].
    #[arg(long = "n-t", value_name = "N")]
    n_t: Option<u32>,

    /// d_b of a new world: radius in metres of the innermost voxel layer [default: the preset's layout].
    #[arg(long = "d-b", value_name = "METRES", allow_negative_numbers = true)]
    d_b: Option<f64>,

    /// l_d of a new world: radial tile length in metres [default: the preset's layout].
    #[arg(long = "l-d", value_name = "METRES", allow_negative_numbers = true)]
    l_d: Option<f64>,

    /// d_c of a new world: chunks along the depth axis [default: the preset's layout].
    #[arg(long = "d-c", value_name = "N")]
    d_c: Option<u32>,
}

fn parse_preset(s: &str) -> Result<PresetKind, String> {
    s.parse::<PresetKind>().map_err(|e| e.to_string())
}

fn parse_interpolation(s: &str) -> Result<Interpolation, String> {
    s.parse::<Interpolation>().map_err(|e| e.to_string())
}

/// The defaults of the shared planet options, read from their single definition.
#[derive(Parser)]
struct DefaultPlanet {
    #[command(flatten)]
    planet: PlanetArgs,
}

impl WorldPlanetArgs {
    /// The options of `planet` that `given` says were typed on the command line.
    pub(crate) fn typed(planet: &PlanetArgs, given: &dyn Fn(&str) -> bool) -> WorldPlanetArgs {
        WorldPlanetArgs {
            preset: given("preset").then_some(planet.preset),
            dem: planet.dem.clone(),
            interpolation: given("interpolation").then_some(planet.interpolation),
            seed: given("seed").then_some(planet.seed),
            n_c: given("n_c").then_some(planet.n_c),
            n_t: given("n_t").then_some(planet.n_t),
            d_b: given("d_b").then_some(planet.d_b),
            l_d: given("l_d").then_some(planet.l_d),
            d_c: given("d_c").then_some(planet.d_c),
        }
    }

    /// The planet of a new world: the given options, the defaults of `pmc generate` elsewhere.
    fn for_new_world(&self) -> Result<(TerrainSpec, Layout), CliError> {
        let d = DefaultPlanet::parse_from(["pmc"]).planet;
        let seed = self.seed.unwrap_or(d.seed);
        let terrain = match &self.dem {
            Some(path) => crate::planet_args::dem_terrain(path, self.interpolation.unwrap_or(d.interpolation), seed)?,
            None => TerrainSpec::preset(self.preset.unwrap_or(d.preset), seed),
        };
        // The terrain's own layout (the earth's is true scale, an elevation model's is for its
        // body's radius) where no option was typed.
        let base = pmc_planet::default_layout(&terrain).map_err(|e| CliError::Dem(e.to_string()))?;
        let layout = Layout::new(
            self.n_c.unwrap_or(base.n_c()),
            self.n_t.unwrap_or(base.n_t()),
            self.d_b.unwrap_or(base.d_b()),
            self.l_d.unwrap_or(base.l_d()),
            self.d_c.unwrap_or(base.d_c()),
        )?;
        Ok((terrain, layout))
    }

    /// Refuses options that disagree with the world's planet, naming each.
    pub(crate) fn check_against(&self, world: &World) -> Result<(), CliError> {
        let (terrain, l) = world.planet_params();
        let mut diffs = Vec::new();
        let mut cmp = |name: &str, given: Option<String>, stored: String| {
            if let Some(g) = given.filter(|g| *g != stored) {
                diffs.push(format!("--{name} {g} (the world has {stored})"));
            }
        };
        let stored_preset = terrain
            .preset_kind()
            .map_or("none (an elevation model)".to_string(), |k| k.name().to_string());
        cmp("preset", self.preset.map(|p| p.name().to_string()), stored_preset);
        cmp("seed", self.seed.map(|s| s.to_string()), terrain.seed().to_string());
        cmp("n-c", self.n_c.map(|v| v.to_string()), l.n_c().to_string());
        cmp("n-t", self.n_t.map(|v| v.to_string()), l.n_t().to_string());
        // Compared as numbers, printed exactly.
        let real = |given: Option<f64>, stored: f64| given.filter(|g| *g != stored).map(|g| format!("{g:?}"));
        cmp("d-b", real(self.d_b, l.d_b()), format!("{:?}", l.d_b()));
        cmp("l-d", real(self.l_d, l.l_d()), format!("{:?}", l.l_d()));
        cmp("d-c", self.d_c.map(|v| v.to_string()), l.d_c().to_string());
        if let (Some(i), TerrainSpec::Dem(a)) = (self.interpolation, &terrain) {
            cmp(
                "interpolation",
                Some(i.name().to_string()),
                a.interpolation.name().to_string(),
            );
        }
        if let Some(path) = &self.dem {
            let given = crate::planet_args::dem_terrain(path, Interpolation::default(), 0)?;
            match (&terrain, &given) {
                (TerrainSpec::Dem(a), TerrainSpec::Dem(b)) if a.digest == b.digest => {}
                (TerrainSpec::Dem(a), _) => diffs.push(format!(
                    "--dem {} (the world was made from another elevation file, {})",
                    path.display(),
                    a.path
                )),
                _ => diffs.push(format!(
                    "--dem {} (the world's planet is the preset {})",
                    path.display(),
                    terrain.name()
                )),
            }
        }
        if diffs.is_empty() {
            return Ok(());
        }
        Err(CliError::Edit(format!(
            "{} already holds another planet: {}; leave those options out (an existing world keeps its planet) or give another --world",
            world.path().display(),
            diffs.join(", ")
        )))
    }
}

fn parse_at(s: &str) -> Result<Place, CliError> {
    parse_place("--at", s)
}

/// Parses the value `s` of option `opt` as `LAT,LON[,ALT]`.
pub(crate) fn parse_place(opt: &str, s: &str) -> Result<Place, CliError> {
    s.parse::<Place>()
        .map_err(|e| CliError::Edit(format!("{opt} {s}: {e}; give LAT,LON or LAT,LON,ALT (degrees, metres)")))
}

/// The centre of edit `k` of a `--repeat` run.
fn center(planet: &Planet, at: Place, k: u64) -> Result<DVec3, CliError> {
    let lon = at.lon() + k as f64 * REPEAT_LON_STEP;
    let dir = LatLon::new(at.lat(), lon)
        .map_err(|e| CliError::Edit(format!("--at: {e}")))?
        .to_unit();
    let r = match at.alt() {
        Some(alt) => planet.datum_radius() + alt,
        None => planet.surface_radius(dir),
    };
    if r <= 0.0 {
        return Err(CliError::Edit(format!(
            "--at: altitude {} m puts the centre at or below the planet's centre (the datum is {} m from it)",
            at.alt().unwrap_or(0.0),
            planet.datum_radius()
        )));
    }
    Ok(dir * r)
}

/// Resolves `--material NAME|ID` against the planet's materials.
fn material(planet: &Planet, given: &str) -> Result<u8, CliError> {
    let names = planet.terrain().materials;
    let id = match given.trim().parse::<usize>() {
        Ok(id) => Some(id).filter(|&i| i < names.len()),
        Err(_) => names.iter().position(|n| n.eq_ignore_ascii_case(given.trim())),
    };
    id.and_then(|i| u8::try_from(i).ok()).ok_or_else(|| {
        let list: Vec<String> = names.iter().enumerate().map(|(i, n)| format!("{n} ({i})")).collect();
        CliError::Edit(format!(
            "unknown material '{given}' for {}; choose one of: {}",
            planet.terrain().spec.name(),
            list.join(", ")
        ))
    })
}

/// The brush kind, checking that `--material` is given exactly for paint.
fn brush_kind(planet: &Planet, brush: BrushName, mat: Option<&str>) -> Result<BrushKind, CliError> {
    match (brush, mat) {
        (BrushName::Paint, Some(m)) => Ok(BrushKind::Paint {
            material: material(planet, m)?,
        }),
        (BrushName::Paint, None) => Err(CliError::Edit(format!(
            "paint needs --material NAME|ID; the materials of {} are: {}",
            planet.terrain().spec.name(),
            planet.terrain().materials.join(", ")
        ))),
        (_, Some(_)) => Err(CliError::Edit("--material applies to paint only".into())),
        (BrushName::Add, None) => Ok(BrushKind::Add),
        (BrushName::Remove, None) => Ok(BrushKind::Remove),
        (BrushName::Smooth, None) => Ok(BrushKind::Smooth),
        (BrushName::Flatten, None) => Ok(BrushKind::Flatten),
    }
}

/// The planet of a world file, with its active edits.
pub(crate) fn planet_of(world: &World) -> Result<Planet, CliError> {
    let (terrain, layout) = world.planet_params();
    let planet = Planet::from_terrain(&terrain, layout)
        .map_err(|e| CliError::Dem(format!("{}: {e}", world.path().display())))?;
    // The world's edits are part of the planet: a brush placed "on the surface" lands on the
    // edited ground (digging twice in one place goes deeper).
    let edits = world.active_edits()?;
    Ok(planet.with_edits(edits.into()))
}

/// Runs `pmc edit`.
pub fn run(args: &EditArgs) -> Result<(), CliError> {
    let Some(brush) = args.brush else {
        let mut world = World::open(&args.world)?;
        args.planet.check_against(&world)?;
        if args.list {
            return list(&world, args.json);
        }
        let (done, verb, past) = if args.undo {
            (world.undo()?, "undo", "undid")
        } else {
            (world.redo()?, "redo", "redid")
        };
        let line = match done {
            Some(id) => format!("{past} edit {id} ({} edits active)", world.edit_count()?),
            None => format!("nothing to {verb}"),
        };
        return say(&line);
    };
    let at = parse_at(args.at.as_deref().ok_or_else(|| {
        CliError::Edit(format!(
            "{} needs --at LAT,LON[,ALT] and --radius METRES",
            brush
                .to_possible_value()
                .map(|v| v.get_name().to_string())
                .unwrap_or_default()
        ))
    })?)?;
    let radius = args
        .radius
        .ok_or_else(|| CliError::Edit("a brush needs --radius METRES".into()))?;
    let strength = args.strength.unwrap_or(1.0);
    // Radius and strength are checked before any file is touched.
    BrushOp::new(BrushKind::Add, DVec3::ZERO, radius, strength)?;
    let repeat = args.repeat.unwrap_or(1);
    if repeat == 0 {
        return Err(CliError::Edit("--repeat must be at least 1".into()));
    }

    // An existing world is opened; a missing one is only created once the edit is known valid.
    let existing = std::fs::symlink_metadata(&args.world).is_ok();
    let (world, planet) = if existing {
        let world = World::open(&args.world)?;
        args.planet.check_against(&world)?;
        let planet = planet_of(&world)?;
        (Some(world), planet)
    } else {
        let (terrain, layout) = args.planet.for_new_world()?;
        (
            None,
            Planet::from_terrain(&terrain, layout).map_err(|e| CliError::Dem(e.to_string()))?,
        )
    };
    let kind = brush_kind(&planet, brush, args.material.as_deref())?;
    let first = BrushOp::new(kind, center(&planet, at, 0)?, radius, strength)?;
    let mut world = match world {
        Some(w) => w,
        None => {
            let t = planet.terrain();
            let l = planet.layout();
            let (w, created) = World::open_or_create(&args.world, &t.spec, l)?;
            if created {
                eprintln!(
                    "created world {} ({}, seed {}, n_c {}, n_t {}, d_b {} m, l_d {} m, d_c {})",
                    args.world.display(),
                    t.spec.name(),
                    t.spec.seed(),
                    l.n_c(),
                    l.n_t(),
                    l.d_b(),
                    l.l_d(),
                    l.d_c()
                );
            } else {
                // Another program created it meanwhile: it must hold the same planet.
                args.planet.check_against(&w)?;
            }
            w
        }
    };
    let datum = planet.datum_radius();
    let mut out = std::io::stdout().lock();
    for k in 0..repeat {
        let op = if k == 0 {
            first
        } else {
            BrushOp::new(kind, center(&planet, at, k)?, radius, strength)?
        };
        let id = world.append(&op)?;
        // The edit is durable: acknowledge it at once.
        let ll = LatLon::from_point(op.center).unwrap_or(LatLon { lat: 0.0, lon: 0.0 });
        let mut line = format!(
            "applied edit {id}: {} at lat {:.6}, lon {:.6}, {} m above the datum, radius {} m, strength {}",
            kind.name(),
            ll.lat,
            ll.lon,
            metres(op.center.length() - datum),
            op.radius,
            op.strength
        );
        if let BrushKind::Paint { material } = kind {
            let name = planet
                .terrain()
                .materials
                .get(usize::from(material))
                .copied()
                .unwrap_or("?");
            line.push_str(&format!(", material {name}"));
        }
        writeln!(out, "{line}")
            .and_then(|()| out.flush())
            .map_err(|e| stdout_error(&e))?;
    }
    Ok(())
}

/// Metres with two decimals, without a sign on a rounded zero.
fn metres(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" {
        "0.00".into()
    } else {
        s
    }
}

/// Prints one line on standard output, flushed; a closed output is an error, not a panic.
fn say(line: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")
        .and_then(|()| out.flush())
        .map_err(|e| stdout_error(&e))
}

fn stdout_error(e: &std::io::Error) -> CliError {
    CliError::Output {
        path: PathBuf::from("standard output"),
        reason: format!("{e} (the edits printed so far are saved)"),
    }
}

/// `--list`: the active edits in order, as text or JSON.
fn list(world: &World, json: bool) -> Result<(), CliError> {
    let planet = planet_of(world)?;
    let entries: Vec<Entry> = world.entries()?;
    let undone = entries.iter().filter(|e| !e.active).count();
    let datum = planet.datum_radius();
    let materials = planet.terrain().materials;
    let describe = |e: &Entry| {
        let ll = LatLon::from_point(e.op.center).unwrap_or(LatLon { lat: 0.0, lon: 0.0 });
        let material = match e.op.kind {
            BrushKind::Paint { material } => Some((material, materials.get(usize::from(material)).copied())),
            _ => None,
        };
        (ll, e.op.center.length() - datum, material)
    };
    let (terrain, l) = world.planet_params();
    let (name, seed) = (terrain.name(), terrain.seed());
    let mut out = std::io::stdout().lock();
    let text = if json {
        let edits: Vec<serde_json::Value> = entries
            .iter()
            .filter(|e| e.active)
            .map(|e| {
                let (ll, alt, material) = describe(e);
                serde_json::json!({
                    "id": e.id.0,
                    "kind": e.op.kind.name(),
                    "material": material.map(|(id, name)| serde_json::json!({ "id": id, "name": name })),
                    "center": [e.op.center.x, e.op.center.y, e.op.center.z],
                    "lat": ll.lat,
                    "lon": ll.lon,
                    "alt": alt,
                    "radius": e.op.radius,
                    "strength": e.op.strength,
                })
            })
            .collect();
        let v = serde_json::json!({
            "world": world.path().display().to_string(),
            "preset": terrain.preset_kind().map(|k| k.name()),
            "terrain": terrain.to_string(),
            "seed": seed,
            "layout": { "n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c() },
            "edits": edits,
            "undone": undone,
        });
        serde_json::to_string_pretty(&v).unwrap_or_default() + "\n"
    } else {
        let mut s = format!(
            "world {}: {name}, seed {seed}, n_c {}, n_t {}, d_b {} m, l_d {} m, d_c {}\n",
            world.path().display(),
            l.n_c(),
            l.n_t(),
            l.d_b(),
            l.l_d(),
            l.d_c()
        );
        s.push_str(&format!(
            "{} active edits, {undone} undone (kept for --redo until the next edit)\n",
            entries.len() - undone
        ));
        for e in entries.iter().filter(|e| e.active) {
            let (ll, alt, material) = describe(e);
            s.push_str(&format!(
                "{:>6} {:<8} lat {:>11.6} lon {:>11.6} alt {:>9} m radius {} m strength {}",
                e.id.0,
                e.op.kind.name(),
                ll.lat,
                ll.lon,
                metres(alt),
                e.op.radius,
                e.op.strength
            ));
            if let Some((id, name)) = material {
                s.push_str(&format!(" material {} ({id})", name.unwrap_or("unknown")));
            }
            s.push('\n');
        }
        s
    };
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| stdout_error(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_is_parsed_and_checked() {
        let a = parse_at("10,-20.5").unwrap();
        assert_eq!((a.lat(), a.lon(), a.alt()), (10.0, -20.5, None));
        let a = parse_at("-10, 20, -3.5").unwrap();
        assert_eq!((a.lat(), a.lon(), a.alt()), (-10.0, 20.0, Some(-3.5)));
        for bad in ["91,0", "NaN,0", "0,inf", "0,0,NaN", "0", "1,2,3,4", "a,b", "0,0,inf"] {
            assert!(parse_at(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_surface_of_the_sphere_is_found() {
        let layout = Layout::new(1, 8, 100.0, 2.0, 2).unwrap();
        let planet = Planet::new(PresetKind::Sphere, 1, layout);
        let density = &planet.terrain().density;
        for dir in [DVec3::Y, DVec3::new(1.0, -2.0, 0.5).normalize()] {
            let r = planet.surface_radius(dir);
            assert!(density.density(dir * (r - 1e-6)) > 0.0, "solid just below {r}");
            assert!(density.density(dir * (r + 1e-6)) <= 0.0, "air just above {r}");
        }
    }
}
