//! `pmc._pmc`, the native module of PMC's Python package: planets, chunks, regions, densities,
//! paths, worlds, elevation imports and the units of a tile bake, as numpy arrays.
//!
//! Every operation is a call into the engine's crates; this module only converts arguments and
//! results, releases the GIL while the engine works, and turns the crates' errors into
//! [`PmcError`] with their messages. Nothing here panics on input from Python: indices, names,
//! coordinates and files are checked by the crates and answered with an error.
//!
//! The Python package (`python/pmc/`) wraps this module with keyword defaults, broadcasting,
//! docstrings for `help()`, the trimesh and pyvista conversions and the Dask bake.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pmc_edit::BrushOp;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{Face, LatLon, SideMask};
use pmc_mesh::ChunkMesh;
use pmc_planet::{Interpolation, LayoutChoice, Planet, PresetKind, TerrainSpec};
use pmc_tiles::bake::{self, SubtreeFiles};
use pmc_tiles::{FrameChoice, Region, TileCoord, TileOptions, TileSet};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use rayon::prelude::*;
use std::path::PathBuf;
use std::str::FromStr;
use std::sync::{Arc, Mutex};

pyo3::create_exception!(
    _pmc,
    PmcError,
    pyo3::exceptions::PyException,
    "An error of the PMC engine: a bad preset, chunk key, coordinate or file. The message says what is wrong and how to fix it."
);

/// The engine's error `e` as a [`PmcError`].
fn err(e: impl std::fmt::Display) -> PyErr {
    PmcError::new_err(e.to_string())
}

/// `v` (`n` rows of `cols` values, row by row) as an `n x cols` numpy array, without a copy: the
/// array owns the vector.
fn rows<T: numpy::Element>(py: Python<'_>, v: Vec<T>, cols: usize) -> Bound<'_, PyArray2<T>> {
    let n = v.len() / cols;
    Array2::from_shape_vec((n, cols), v)
        .expect("the vector holds whole rows")
        .into_pyarray(py)
}

/// `v` as a one-dimensional numpy array, without a copy.
fn column<T: numpy::Element>(py: Python<'_>, v: Vec<T>) -> Bound<'_, PyArray1<T>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// A face from its index (0 to 5, in `Face::ALL` order) or its name.
fn face_of(face: &Bound<'_, PyAny>) -> PyResult<Face> {
    if let Ok(i) = face.extract::<i64>() {
        return usize::try_from(i)
            .ok()
            .and_then(|i| Face::ALL.get(i).copied())
            .ok_or_else(|| err(format!("face {i} is not a cube face: give 0 to 5 or a face's name")));
    }
    let name: String = face
        .extract()
        .map_err(|_| err("a face is an index from 0 to 5 or a face's name"))?;
    name.parse::<Face>().map_err(err)
}

/// A planet: a terrain (a procedural preset, or an elevation model) on a layout of chunks.
///
/// Immutable: a world's edits make a new planet (`World.planet`).
#[pyclass(module = "pmc._pmc", name = "Planet", frozen)]
struct PyPlanet {
    planet: Arc<Planet>,
    /// The world file it comes from, and its edits then.
    world: Option<(PathBuf, usize)>,
}

fn build_planet(terrain: &TerrainSpec, choice: &LayoutChoice) -> PyResult<Planet> {
    let layout = choice.resolve(terrain).map_err(err)?;
    Planet::from_terrain(terrain, layout).map_err(err)
}

/// The mesh `m` as a dict of numpy arrays.
fn mesh_dict(py: Python<'_>, m: ChunkMesh) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("origin", column(py, m.origin.to_array().to_vec()))?;
    let low = if m.positions_low.is_empty() {
        vec![0f32; m.positions.len() * 3]
    } else {
        m.positions_low.into_flattened()
    };
    d.set_item("positions", rows(py, m.positions.into_flattened(), 3))?;
    d.set_item("positions_low", rows(py, low, 3))?;
    d.set_item("normals", rows(py, m.normals.into_flattened(), 3))?;
    d.set_item("colors", rows(py, m.colors.into_flattened(), 4))?;
    d.set_item("heights", column(py, m.heights))?;
    d.set_item("water_depths", column(py, m.water_depths))?;
    d.set_item("materials", column(py, m.materials))?;
    d.set_item("indices", rows(py, m.indices, 3))?;
    // Each vertex's grid edge, the two packed voxel keys as four u64 (high, low, high, low):
    // copies of a vertex in neighbouring chunks have equal keys, the exact way to weld them.
    let keys: Vec<u64> = m
        .edge_keys
        .iter()
        .flat_map(|k| [(k.0 >> 64) as u64, k.0 as u64, (k.1 >> 64) as u64, k.1 as u64])
        .collect();
    d.set_item("edge_keys", rows(py, keys, 4))?;
    Ok(d)
}

#[pymethods]
impl PyPlanet {
    #[new]
    #[pyo3(signature = (preset="earthlike", seed=7, *, radius=None, n_c=None, n_t=None, d_b=None, l_d=None, d_c=None, dem=None, interpolation="bicubic"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        preset: &str,
        seed: u64,
        radius: Option<f64>,
        n_c: Option<u32>,
        n_t: Option<u32>,
        d_b: Option<f64>,
        l_d: Option<f64>,
        d_c: Option<u32>,
        dem: Option<PathBuf>,
        interpolation: &str,
    ) -> PyResult<PyPlanet> {
        let choice = LayoutChoice {
            radius,
            n_c,
            n_t,
            d_b,
            l_d,
            d_c,
        };
        let terrain = match dem {
            Some(path) => {
                let interp = Interpolation::from_str(interpolation).map_err(err)?;
                pmc_planet::dem_terrain(&path, interp, seed).map_err(err)?
            }
            None => TerrainSpec::preset(PresetKind::from_str(preset).map_err(err)?, seed),
        };
        let planet = py.detach(|| build_planet(&terrain, &choice))?;
        Ok(PyPlanet {
            planet: Arc::new(planet),
            world: None,
        })
    }

    /// The planet a spec describes (`Planet.spec()`): its terrain's canonical text and its
    /// layout, or a world file. An elevation model is opened at the path recorded and must have
    /// the digest recorded.
    #[staticmethod]
    fn from_spec(py: Python<'_>, terrain: &str, layout: [f64; 5], world: Option<PathBuf>) -> PyResult<PyPlanet> {
        if let Some(path) = world {
            return open_world_planet(py, &path).map(|(p, _)| p);
        }
        let spec = TerrainSpec::from_str(terrain).map_err(err)?;
        let whole = |v: f64, name: &str| -> PyResult<u32> {
            if v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&v) {
                Ok(v as u32)
            } else {
                Err(err(format!("the layout's {name} must be a whole number, got {v}")))
            }
        };
        let choice = LayoutChoice {
            radius: None,
            n_c: Some(whole(layout[0], "n_c")?),
            n_t: Some(whole(layout[1], "n_t")?),
            d_b: Some(layout[2]),
            l_d: Some(layout[3]),
            d_c: Some(whole(layout[4], "d_c")?),
        };
        let planet = py.detach(|| build_planet(&spec, &choice))?;
        Ok(PyPlanet {
            planet: Arc::new(planet),
            world: None,
        })
    }

    /// What a worker needs to build this planet again: `(terrain, layout, world)`.
    fn spec(&self) -> (String, [f64; 5], Option<PathBuf>) {
        let l = self.planet.layout();
        (
            self.planet.terrain().spec.to_string(),
            [
                f64::from(l.n_c()),
                f64::from(l.n_t()),
                l.d_b(),
                l.l_d(),
                f64::from(l.d_c()),
            ],
            self.world.as_ref().map(|(p, _)| p.clone()),
        )
    }

    /// The planet's description as a dict.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.planet;
        let l = p.layout();
        let t = p.terrain();
        let d = PyDict::new(py);
        d.set_item("terrain", t.spec.to_string())?;
        d.set_item("preset", t.spec.preset_kind().map_or("dem", |k| k.name()))?;
        d.set_item("seed", t.spec.seed())?;
        if let TerrainSpec::Dem(dem) = &t.spec {
            d.set_item("dem", dem.path.clone())?;
            d.set_item("dem_digest", dem.digest.clone())?;
            d.set_item("interpolation", dem.interpolation.to_string())?;
        }
        let layout = PyDict::new(py);
        layout.set_item("n_c", l.n_c())?;
        layout.set_item("n_t", l.n_t())?;
        layout.set_item("d_b", l.d_b())?;
        layout.set_item("l_d", l.l_d())?;
        layout.set_item("d_c", l.d_c())?;
        d.set_item("layout", layout)?;
        d.set_item("radius", l.radius())?;
        d.set_item("datum_radius", p.datum_radius())?;
        d.set_item("sea_radius", t.sea_radius)?;
        d.set_item("max_level", l.max_level())?;
        d.set_item("chunks", l.chunk_count())?;
        d.set_item(
            "materials",
            t.materials.iter().map(|m| m.to_string()).collect::<Vec<_>>(),
        )?;
        if let Some((path, edits)) = &self.world {
            d.set_item("world", path.clone())?;
            d.set_item("edits", *edits)?;
        }
        Ok(d)
    }

    /// The mesh of chunk `face/level/i/j/k` as numpy arrays; `seams` is the mask of sides whose
    /// neighbour is one level coarser (bits: u min, u max, v min, v max, inner, outer).
    #[pyo3(signature = (face, level, i, j, k, seams=0))]
    #[allow(clippy::too_many_arguments)]
    fn chunk<'py>(
        &self,
        py: Python<'py>,
        face: &Bound<'py, PyAny>,
        level: u64,
        i: u64,
        j: u64,
        k: u64,
        seams: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let face = face_of(face)?;
        let layout = self.planet.layout();
        let key = layout.chunk_key(face, level, i, j, k).map_err(err)?;
        if seams >= 64 {
            return Err(err(format!(
                "seams must be a side mask from 0 to 63 (bits: u min, u max, v min, v max, inner, outer), got {seams}"
            )));
        }
        let seams = SideMask(seams as u8 & layout.seam_sides(&key).0);
        let planet = self.planet.clone();
        let mesh = py.detach(move || planet.chunk_mesh_lod(key, seams));
        mesh_dict(py, mesh)
    }

    /// The surface within `radius_m` metres of the ground at `lat`, `lon`, from the chunks of
    /// one level of detail, welded into one mesh in f64 planet-centred metres.
    #[pyo3(signature = (lat, lon, radius_m, level=0))]
    fn region<'py>(
        &self,
        py: Python<'py>,
        lat: f64,
        lon: f64,
        radius_m: f64,
        level: u8,
    ) -> PyResult<Bound<'py, PyDict>> {
        let planet = self.planet.clone();
        let (welded, chunks) = py
            .detach(move || -> Result<_, String> {
                let centre = planet.place(lat, lon, None)?;
                let keys = pmc_lod::region_chunks(&planet, centre, radius_m, level, pmc_lod::REGION_BUDGET)
                    .map_err(|e| e.to_string())?;
                let meshes: Vec<ChunkMesh> = keys.par_iter().map(|k| planet.chunk_mesh(*k)).collect();
                let welded = pmc_formats::weld_arrays(&meshes).map_err(|e| e.to_string())?;
                Ok((welded, keys.len()))
            })
            .map_err(err)?;
        let d = PyDict::new(py);
        d.set_item("positions", rows(py, welded.positions.into_flattened(), 3))?;
        d.set_item("normals", rows(py, welded.normals.into_flattened(), 3))?;
        d.set_item("colors", rows(py, welded.colors.into_flattened(), 4))?;
        d.set_item("heights", column(py, welded.heights))?;
        d.set_item("water_depths", column(py, welded.water_depths))?;
        d.set_item("materials", column(py, welded.materials))?;
        d.set_item("indices", rows(py, welded.triangles.into_flattened(), 3))?;
        d.set_item("chunks", chunks)?;
        Ok(d)
    }

    /// The density at each row of an `n x 3` array of planet-centred points (metres):
    /// positive inside the ground, negative in air and water.
    fn density<'py>(&self, py: Python<'py>, points: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let shape = points.shape();
        if shape.len() != 2 || shape[1] != 3 {
            return Err(err(format!("points must be an n x 3 array, got shape {shape:?}")));
        }
        let a = points.as_array();
        let pts: Vec<DVec3> = a.rows().into_iter().map(|r| DVec3::new(r[0], r[1], r[2])).collect();
        if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
            return Err(err(format!("point {i} ({:?}) is not finite", pts[i].to_array())));
        }
        let planet = self.planet.clone();
        let out: Vec<f64> = py.detach(move || {
            let d = planet.density();
            pts.par_iter().map(|p| d.density(*p)).collect()
        });
        Ok(column(py, out))
    }

    /// The height of the ground above the datum at each `lat`, `lon` (degrees, arrays of one
    /// length): the first surface met going down from the top of the shell.
    fn surface_height<'py>(
        &self,
        py: Python<'py>,
        lat: PyReadonlyArray1<'py, f64>,
        lon: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (lat, lon) = (lat.as_array(), lon.as_array());
        if lat.len() != lon.len() {
            return Err(err(format!("{} latitudes but {} longitudes", lat.len(), lon.len())));
        }
        let dirs = lat
            .iter()
            .zip(lon.iter())
            .enumerate()
            .map(|(i, (&la, &lo))| {
                LatLon::new(la, lo)
                    .map(|l| l.to_unit())
                    .map_err(|e| err(format!("point {i}: {e}")))
            })
            .collect::<PyResult<Vec<DVec3>>>()?;
        let planet = self.planet.clone();
        let out: Vec<f64> = py.detach(move || {
            let datum = planet.datum_radius();
            dirs.par_iter().map(|d| planet.surface_radius(*d) - datum).collect()
        });
        Ok(column(py, out))
    }

    /// A walk over the ground from one place to another: each end `(lat, lon)` or
    /// `(lat, lon, alt)` (an altitude picks the floor nearest it, in a cave or on a bridge).
    /// Returns `(answer, points)`: the answer as `pmc path` prints it (JSON text), and the
    /// path's points (`n x 3`, planet-centred metres; empty when there is no path).
    #[pyo3(signature = (start, goal, *, clearance=None, step_up=None, step_down=None, max_slope=None, lazy=None))]
    #[allow(clippy::too_many_arguments)]
    fn path<'py>(
        &self,
        py: Python<'py>,
        start: Vec<f64>,
        goal: Vec<f64>,
        clearance: Option<f64>,
        step_up: Option<f64>,
        step_down: Option<f64>,
        max_slope: Option<f64>,
        lazy: Option<bool>,
    ) -> PyResult<(String, Bound<'py, PyArray2<f64>>)> {
        use pmc_nav::{Agent, End, LazyGrid, LazyOptions, NavGrid, PathAnswer, SearchOptions};
        let d = Agent::default();
        let agent = Agent {
            clearance: clearance.unwrap_or(d.clearance),
            step_up: step_up.unwrap_or(d.step_up),
            step_down: step_down.unwrap_or(d.step_down),
            max_slope: max_slope.unwrap_or(d.max_slope),
        };
        agent.validate().map_err(err)?;
        let datum = self.planet.datum_radius();
        let end = |v: &[f64], name: &str| -> PyResult<End> {
            let (lat, lon, alt) = match v {
                [lat, lon] => (*lat, *lon, None),
                [lat, lon, alt] => (*lat, *lon, Some(*alt)),
                _ => {
                    return Err(err(format!(
                        "{name} is (lat, lon) or (lat, lon, alt), got {} numbers",
                        v.len()
                    )))
                }
            };
            let dir = LatLon::new(lat, lon)
                .map_err(|e| err(format!("{name}: {e}")))?
                .to_unit();
            if let Some(a) = alt.filter(|a| !a.is_finite()) {
                return Err(err(format!(
                    "{name}: the altitude {a} is not a finite number of metres"
                )));
            }
            Ok(End {
                dir,
                radius: alt.map(|a| datum + a),
            })
        };
        let (a, b) = (end(&start, "start")?, end(&goal, "goal")?);
        let planet = self.planet.clone();
        const SNAP_RINGS: usize = 8;
        let (doc, points) = py
            .detach(move || -> Result<_, String> {
                let lazy = lazy.unwrap_or_else(|| pmc_nav::wants_lazy_grid(planet.layout()));
                if lazy {
                    let search = SearchOptions::default();
                    let mut grid =
                        LazyGrid::new(planet.density().clone(), planet.layout(), agent, LazyOptions::default())
                            .map_err(|e| e.to_string())?;
                    let found = grid.query(a, b, SNAP_RINGS, &search);
                    let points = match &found.answer {
                        PathAnswer::Found(p) => p.points.clone(),
                        _ => Vec::new(),
                    };
                    Ok((pmc_nav::lazy_path_json(&grid, &found, &search, a, b, datum), points))
                } else {
                    let grid =
                        NavGrid::build(planet.density().as_ref(), planet.layout(), agent).map_err(|e| e.to_string())?;
                    let answer = pmc_nav::query(&grid, a, b, SNAP_RINGS);
                    let points = match &answer {
                        PathAnswer::Found(p) => p.points.clone(),
                        _ => Vec::new(),
                    };
                    Ok((pmc_nav::path_json(&grid, &answer, a, b, datum), points))
                }
            })
            .map_err(err)?;
        let flat: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
        Ok((doc.to_string(), rows(py, flat, 3)))
    }

    fn __repr__(&self) -> String {
        let l = self.planet.layout();
        format!(
            "Planet({}, radius {} m, n_c {}, n_t {}, d_b {}, l_d {}, d_c {}{})",
            self.planet.terrain().spec,
            l.radius(),
            l.n_c(),
            l.n_t(),
            l.d_b(),
            l.l_d(),
            l.d_c(),
            self.world.as_ref().map_or(String::new(), |(p, n)| format!(
                ", world {} with {n} edits",
                p.display()
            ))
        )
    }
}

fn open_world_planet(py: Python<'_>, path: &std::path::Path) -> PyResult<(PyPlanet, pmc_world::World)> {
    let path = path.to_path_buf();
    py.detach(move || -> Result<_, String> {
        let world = pmc_world::World::open(&path).map_err(|e| e.to_string())?;
        let (terrain, layout) = world.planet_params();
        let planet = Planet::from_terrain(&terrain, layout).map_err(|e| format!("{}: {e}", path.display()))?;
        let edits = world.active_edits().map_err(|e| e.to_string())?;
        let n = edits.len();
        Ok((
            PyPlanet {
                planet: Arc::new(planet.with_edits(edits.into())),
                world: Some((path, n)),
            },
            world,
        ))
    })
    .map_err(err)
}

/// A world: a planet with its edits, kept in a SQLite world file (format pmc-world v2).
#[pyclass(module = "pmc._pmc", name = "World")]
struct PyWorld {
    world: Mutex<Option<pmc_world::World>>,
    planet: Py<PyPlanet>,
}

impl PyWorld {
    /// Runs `f` on the open world, then makes the planet again with the world's edits.
    fn change<T: Send>(
        &mut self,
        py: Python<'_>,
        f: impl FnOnce(&mut pmc_world::World, &Planet) -> Result<T, String> + Send,
    ) -> PyResult<T> {
        let base = self.planet.get().planet.clone();
        let world = &self.world;
        let (out, planet, n, path) = py
            .detach(move || -> Result<_, String> {
                let mut guard = world
                    .lock()
                    .map_err(|_| "the world is unusable after an earlier failure".to_string())?;
                let w = guard.as_mut().ok_or("the world is closed")?;
                let out = f(w, &base)?;
                let edits = w.active_edits().map_err(|e| e.to_string())?;
                let n = edits.len();
                let mut planet = (*base).clone();
                planet.set_edits(edits.into());
                Ok((out, planet, n, w.path().to_path_buf()))
            })
            .map_err(err)?;
        self.planet = Py::new(
            py,
            PyPlanet {
                planet: Arc::new(planet),
                world: Some((path, n)),
            },
        )?;
        Ok(out)
    }
}

#[pymethods]
impl PyWorld {
    /// Opens the world file at `path`.
    #[staticmethod]
    fn open(py: Python<'_>, path: PathBuf) -> PyResult<PyWorld> {
        let (planet, world) = open_world_planet(py, &path)?;
        Ok(PyWorld {
            world: Mutex::new(Some(world)),
            planet: Py::new(py, planet)?,
        })
    }

    /// Creates the world file at `path` for `planet` (it must not exist).
    #[staticmethod]
    fn create(py: Python<'_>, path: PathBuf, planet: &PyPlanet) -> PyResult<PyWorld> {
        if planet.world.is_some() {
            return Err(err(
                "the planet is a world's: open that world, or create one from a planet made anew",
            ));
        }
        if std::fs::symlink_metadata(&path).is_ok() {
            return Err(err(format!(
                "{} exists: open it with World.open, or give a new path",
                path.display()
            )));
        }
        let p = planet.planet.clone();
        let world = py
            .detach(|| pmc_world::World::create(&path, &p.terrain().spec, p.layout()))
            .map_err(err)?;
        Ok(PyWorld {
            world: Mutex::new(Some(world)),
            planet: Py::new(
                py,
                PyPlanet {
                    planet: p,
                    world: Some((path, 0)),
                },
            )?,
        })
    }

    /// The planet with the world's active edits.
    #[getter]
    fn planet(&self, py: Python<'_>) -> Py<PyPlanet> {
        self.planet.clone_ref(py)
    }

    /// Applies a brush and saves it before returning: `brush` is add, remove, smooth, flatten
    /// or paint (with `material`); the centre is at `lat`, `lon` and `alt` metres above the
    /// datum, or on the ground there without `alt`. Returns the edit's id.
    #[pyo3(signature = (brush, lat, lon, radius, *, alt=None, strength=1.0, material=None))]
    #[allow(clippy::too_many_arguments)]
    fn edit(
        &mut self,
        py: Python<'_>,
        brush: &str,
        lat: f64,
        lon: f64,
        radius: f64,
        alt: Option<f64>,
        strength: f64,
        material: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<u64> {
        let material = material.map(|m| m.str().map(|s| s.to_string())).transpose()?;
        let brush = brush.to_string();
        // `planet` holds the world's active edits (`change` keeps it so): a brush put on the
        // ground lands on the edited ground.
        self.change(py, move |w, planet| {
            let kind = planet.brush_kind(&brush, material.as_deref())?;
            let centre = planet.place(lat, lon, alt)?;
            let op = BrushOp::new(kind, centre, radius, strength).map_err(|e| e.to_string())?;
            w.append(&op).map(|id| id.0).map_err(|e| e.to_string())
        })
    }

    /// Undoes the last active edit; returns its id, or None when there is none.
    fn undo(&mut self, py: Python<'_>) -> PyResult<Option<u64>> {
        self.change(py, |w, _| w.undo().map(|id| id.map(|i| i.0)).map_err(|e| e.to_string()))
    }

    /// Redoes the earliest undone edit; returns its id, or None when there is none.
    fn redo(&mut self, py: Python<'_>) -> PyResult<Option<u64>> {
        self.change(py, |w, _| w.redo().map(|id| id.map(|i| i.0)).map_err(|e| e.to_string()))
    }

    /// The active edits, oldest first, as dicts.
    fn edits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let guard = self
            .world
            .lock()
            .map_err(|_| err("the world is unusable after an earlier failure"))?;
        let w = guard.as_ref().ok_or_else(|| err("the world is closed"))?;
        let list = PyList::empty(py);
        for op in w.active_edits().map_err(err)? {
            let d = PyDict::new(py);
            d.set_item("brush", op.kind.name())?;
            d.set_item("center", op.center.to_array().to_vec())?;
            d.set_item("radius", op.radius)?;
            d.set_item("strength", op.strength)?;
            if let pmc_edit::BrushKind::Paint { material } = op.kind {
                d.set_item("material", material)?;
            }
            list.append(d)?;
        }
        Ok(list)
    }

    /// Closes the world file (checkpointing its journal); the world cannot be edited after.
    fn close(&mut self, py: Python<'_>) -> PyResult<()> {
        let taken = self
            .world
            .lock()
            .map_err(|_| err("the world is unusable after an earlier failure"))?
            .take();
        match taken {
            Some(w) => py.detach(|| w.close()).map_err(err),
            None => Ok(()),
        }
    }
}

/// Imports a grid of heights held in memory into a cube-face elevation file (`.pmcdem`), as
/// `pmc dem import` imports a file. Returns the import's report as a dict.
#[pyfunction]
#[pyo3(signature = (heights, west, south, east, north, output, *, north_first=true, cell_centres=true, nodata=None, name="array", level=None, bits="auto", radius=None))]
#[allow(clippy::too_many_arguments)]
fn import_dem_array<'py>(
    py: Python<'py>,
    heights: PyReadonlyArray2<'py, f32>,
    west: f64,
    south: f64,
    east: f64,
    north: f64,
    output: PathBuf,
    north_first: bool,
    cell_centres: bool,
    nodata: Option<f32>,
    name: &str,
    level: Option<u32>,
    bits: &str,
    radius: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let shape = heights.shape();
    let (h, w) = (shape[0], shape[1]);
    let values: Vec<f32> = heights.as_array().iter().copied().collect();
    let extent = pmc_dem::PngExtent {
        west,
        south,
        east,
        north,
        scale: 1.0,
        offset: 0.0,
        nodata: None,
        cell_centres,
    };
    let format = match bits {
        "auto" => pmc_dem::FormatChoice::Auto,
        "i16" => pmc_dem::FormatChoice::I16,
        "f32" => pmc_dem::FormatChoice::F32,
        other => return Err(err(format!("bits is auto, i16 or f32, got '{other}'"))),
    };
    let mut options = pmc_dem::ImportOptions {
        level,
        format,
        ..pmc_dem::ImportOptions::default()
    };
    if let Some(r) = radius {
        options.radius = r;
    }
    let name = name.to_string();
    let report = py
        .detach(move || -> Result<_, String> {
            let dem = pmc_dem::EquirectDem::from_heights(&name, w, h, north_first, &values, &extent, nodata)
                .map_err(|e| e.to_string())?;
            pmc_dem::import_cube(&dem, &output, &options, &|_, _| {}).map_err(|e| e.to_string())
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("level", report.level)?;
    d.set_item("format", format!("{:?}", report.format))?;
    d.set_item("digest", report.digest.to_string())?;
    d.set_item("bytes", report.bytes)?;
    d.set_item("source_filled", report.source_filled)?;
    Ok(d)
}

/// A tile by `(face, level, x, y, z)`, as Python sees it.
type Root = (u8, u8, u32, u32, u32);

/// A file of a subtree's bake: its path, its tile level (None for the subtree file), its bytes.
type BakeFile<'py> = (String, Option<u8>, Bound<'py, PyBytes>);

/// A tile set being baked: the planet's tiles, the unit of work of a distributed bake.
#[pyclass(module = "pmc._pmc", name = "TileBake", frozen)]
struct PyTileBake {
    tiles: Arc<TileSet>,
    extras: serde_json::Value,
}

fn tile_coord(t: &TileCoord) -> Root {
    (t.face as u8, t.level, t.x, t.y, t.z)
}

#[pymethods]
impl PyTileBake {
    /// The tiles of `planet` for a bake: up to `max_level`, from `min_level`, near `region`
    /// `(lat, lon, radius_m)`, in `frame` (auto, wgs84 or sphere), as `pmc tiles bake` makes them.
    #[new]
    #[pyo3(signature = (planet, *, max_level=None, min_level=0, region=None, frame="auto"))]
    fn new(
        py: Python<'_>,
        planet: &PyPlanet,
        max_level: Option<u8>,
        min_level: u8,
        region: Option<(f64, f64, f64)>,
        frame: &str,
    ) -> PyResult<PyTileBake> {
        let frame = match frame {
            "auto" => FrameChoice::Auto,
            "wgs84" => FrameChoice::Wgs84,
            "sphere" => FrameChoice::Sphere,
            other => return Err(err(format!("frame is auto, wgs84 or sphere, got '{other}'"))),
        };
        let options = TileOptions {
            max_level,
            min_level,
            region: region.map(|(lat, lon, radius)| Region { lat, lon, radius }),
        };
        let extras = pmc_tiles::planet_extras(&planet.planet, planet.world.as_ref().map(|(_, n)| *n));
        let p = planet.planet.clone();
        let tiles = py.detach(move || bake::tile_set(p, frame, options)).map_err(err)?;
        Ok(PyTileBake {
            tiles: Arc::new(tiles),
            extras,
        })
    }

    /// The subtree roots a bake starts from, as `(face, level, x, y, z)`.
    fn roots(&self) -> Vec<Root> {
        bake::roots(&self.tiles).iter().map(tile_coord).collect()
    }

    /// `bake.json`'s bytes.
    fn manifest<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &bake::json_bytes(&bake::manifest(&self.tiles, self.extras.clone())))
    }

    /// `tileset.json`'s bytes.
    fn tileset<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &bake::tileset_bytes(&self.tiles, self.extras.clone()))
    }

    /// The path of a subtree root's subtree file in the folder.
    fn subtree_path(&self, root: Root) -> PyResult<String> {
        Ok(bake::subtree_path(&self.coord(root)?))
    }

    /// The tile levels of the bake (levels 0 to `levels - 1` have tiles): a subtree rooted at
    /// `levels - 3` or deeper has no child subtrees.
    #[getter]
    fn levels(&self) -> u8 {
        self.tiles.available_levels()
    }

    /// Bakes several subtrees in memory side by side (on every core), each as
    /// [`PyTileBake::subtree`] does: what a task of a distributed bake does with the small
    /// subtrees at the bottom of the tree, which would cost more as tasks of their own than
    /// they take to bake.
    fn subtrees<'py>(&self, py: Python<'py>, roots: Vec<Root>) -> PyResult<Vec<(Vec<BakeFile<'py>>, Vec<Root>)>> {
        let roots = roots.into_iter().map(|r| self.coord(r)).collect::<PyResult<Vec<_>>>()?;
        let tiles = self.tiles.clone();
        let done = py
            .detach(move || {
                roots
                    .par_iter()
                    .map(|r| bake::subtree_files(&tiles, *r))
                    .collect::<Result<Vec<_>, _>>()
            })
            .map_err(err)?;
        Ok(done.into_iter().map(|d| subtree_to_py(py, d)).collect())
    }

    /// The roots of the child subtrees of `root` that hold tiles (what a resumed bake walks
    /// into without baking `root` again).
    fn children(&self, root: Root) -> PyResult<Vec<Root>> {
        Ok(self
            .tiles
            .child_subtrees(self.coord(root)?)
            .iter()
            .map(tile_coord)
            .collect())
    }

    /// Bakes one subtree in memory: `(files, children)`, the files as `(path, level, bytes)`
    /// (level None for the subtree file, which comes last) and the child subtrees' roots.
    fn subtree<'py>(&self, py: Python<'py>, root: Root) -> PyResult<(Vec<BakeFile<'py>>, Vec<Root>)> {
        let root = self.coord(root)?;
        let tiles = self.tiles.clone();
        let done = py.detach(move || bake::subtree_files(&tiles, root)).map_err(err)?;
        Ok(subtree_to_py(py, done))
    }
}

/// A subtree's bake as Python sees it: its files as `(path, level, bytes)`, its children's roots.
fn subtree_to_py(py: Python<'_>, SubtreeFiles { files, children }: SubtreeFiles) -> (Vec<BakeFile<'_>>, Vec<Root>) {
    (
        files
            .into_iter()
            .map(|f| (f.path, f.level, PyBytes::new(py, &f.bytes)))
            .collect(),
        children.iter().map(tile_coord).collect(),
    )
}

impl PyTileBake {
    /// The subtree root `(face, level, x, y, z)` of this bake, checked.
    fn coord(&self, (face, level, x, y, z): Root) -> PyResult<TileCoord> {
        let face = Face::ALL
            .get(usize::from(face))
            .copied()
            .ok_or_else(|| err(format!("face {face} is not a cube face (0 to 5)")))?;
        let t = TileCoord { face, level, x, y, z };
        if level % pmc_tiles::SUBTREE_LEVELS != 0 {
            return Err(err(format!(
                "tile {}/{} is no subtree root: their levels are multiples of {}",
                face.name(),
                t.path(),
                pmc_tiles::SUBTREE_LEVELS
            )));
        }
        // (`candidate`, not `available`: the latter samples the tile's chunk, which the callers
        // do anyway or do not need)
        if !self.tiles.candidate(&t) {
            return Err(err(format!(
                "tile {}/{} is not a tile of this bake",
                face.name(),
                t.path()
            )));
        }
        Ok(t)
    }
}

/// How many subtrees a bake meshes side by side in this process ([`bake::batch`]).
#[pyfunction]
fn bake_batch() -> usize {
    bake::batch()
}

/// The native module.
#[pymodule]
fn _pmc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("PmcError", m.py().get_type::<PmcError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PRESETS", PresetKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>())?;
    m.add("FACES", Face::ALL.iter().map(|f| f.name()).collect::<Vec<_>>())?;
    m.add_class::<PyPlanet>()?;
    m.add_class::<PyWorld>()?;
    m.add_class::<PyTileBake>()?;
    m.add_function(wrap_pyfunction!(import_dem_array, m)?)?;
    m.add_function(wrap_pyfunction!(bake_batch, m)?)?;
    Ok(())
}
