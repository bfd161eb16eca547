//! OGC 3D Tiles 1.1 for planetary marching cubes (`docs/specs/tiles-v1.md`).
//!
//! A planet becomes one tileset: a root over six octrees, one per cube face, whose tiles are the
//! face's chunks of every level ([`octree`]: tile level 0 is the face's coarsest chunk). Each
//! tile's content is its chunk *closed* (`pmc_planet::Planet::chunk_mesh_closed`): the surface
//! plus caps on the chunk's six sides, so a client may put any level beside any other and still
//! show no inside of a solid through the crack between them (the argument is in
//! `pmc_mesh::caps`). Tiles are placed in Earth-centred, Earth-fixed metres on the WGS84
//! ellipsoid or on the planet's sphere ([`frame`]), with provable bounding spheres.
//!
//! The tree is written explicitly, three levels to a file: each *subtree file* is an external
//! tileset whose root is a chunk, holding the tiles of its levels and, under the deepest, one
//! tile per child subtree whose content is that subtree's file. (3D Tiles' implicit tiling cannot
//! carry this tree: a client derives the volume of each child subtree's root by halving the face
//! root's box, and culls the subtree by that volume before it reads its metadata; a chunk of the
//! cube sphere is no such half, so whole subtrees were culled in CesiumJS.)
//!
//! A [`TileSet`] answers the tileset JSON ([`TileSet::tileset_json`]) and builds one subtree at a
//! time with its tiles' contents ([`TileSet::build_subtree`]): the unit of work of a bake
//! ([`bake`]) and of a server.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod bake;
pub mod frame;
pub mod octree;
pub mod subtree;

pub use frame::TileFrame;
pub use octree::{TileCoord, Tiling, SUBTREE_LEVELS};

use octree::{demorton3, octree_tiles};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face, LatLon};
use pmc_mesh::ChunkMesh;
use pmc_planet::{ChunkScratch, Planet, TerrainSpec};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::cell::RefCell;
use std::sync::Arc;
use subtree::Bits;

/// What can go wrong building tiles.
#[derive(Debug, thiserror::Error)]
pub enum TilesError {
    /// The planet is a height-field planet: its patches have no volume to close.
    #[error("3D Tiles are made of marching-cubes chunks; a height-field planet (--mesher heightfield) has none")]
    Heightfield,
    /// The level errors do not match the planet's levels.
    #[error("{got} level errors for a planet of {want} levels of detail")]
    Errors {
        /// Errors given.
        got: usize,
        /// Levels of detail.
        want: usize,
    },
    /// A parameter is out of range.
    #[error("{0}")]
    Invalid(String),
    /// Writing a tile's content failed.
    #[error("writing tile {tile}: {source}")]
    Content {
        /// The tile.
        tile: String,
        /// Why.
        source: pmc_formats::ExportError,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// Which frame a planet's tiles go in, before its datum is known: what `--frame` and
/// `--tiles-frame` say.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrameChoice {
    /// WGS84 for a planet of the Earth's size, else its sphere ([`TileFrame::default_for`]).
    #[default]
    Auto,
    /// On the WGS84 ellipsoid.
    Wgs84,
    /// On the planet's own sphere.
    Sphere,
}

impl FrameChoice {
    /// The frame of a planet of datum radius `datum`.
    pub fn frame(self, datum: f64) -> TileFrame {
        match self {
            FrameChoice::Auto => TileFrame::default_for(datum),
            FrameChoice::Wgs84 => TileFrame::Wgs84 { datum },
            FrameChoice::Sphere => TileFrame::Sphere,
        }
    }
}

/// A region of the planet to tile: the tiles whose bounding spheres meet the ball of `radius`
/// metres around the place at `lat`, `lon` (degrees) on the datum sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Latitude, degrees.
    pub lat: f64,
    /// Longitude, degrees.
    pub lon: f64,
    /// Radius, metres.
    pub radius: f64,
}

/// Which tiles a tileset holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TileOptions {
    /// The deepest tile level (0 is a face's root); `None` for every level of detail.
    pub max_level: Option<u8>,
    /// Tiles above this tile level have no content (they stay in the tree as its path).
    pub min_level: u8,
    /// Only the tiles meeting this region (and the path to them).
    pub region: Option<Region>,
}

/// A planet as a 3D Tiles tileset.
#[derive(Clone, Debug)]
pub struct TileSet {
    planet: Arc<Planet>,
    frame: TileFrame,
    tiling: Tiling,
    errors: Vec<f64>,
    options: TileOptions,
    region: Option<(DVec3, f64)>,
    generator: String,
}

/// A built subtree: its file and the contents of its tiles that have one.
#[derive(Clone, Debug, Default)]
pub struct SubtreeBuild {
    /// The subtree file's bytes.
    pub subtree: Vec<u8>,
    /// Each tile with content and its glTF binary, in tile order.
    pub contents: Vec<(TileCoord, Vec<u8>)>,
    /// The roots of the available child subtrees.
    pub children: Vec<TileCoord>,
    /// Available tiles in the subtree.
    pub available: usize,
}

thread_local! {
    static SCRATCH: RefCell<ChunkScratch> = RefCell::new(ChunkScratch::default());
}

/// A planet's description for a tileset's `extras.pmc` and a bake's manifest: its terrain (an
/// elevation model by its content digest, not its path), its layout, its datum radius and, for
/// a world, how many edits it holds.
pub fn planet_extras(planet: &Planet, edits: Option<usize>) -> Value {
    let l = planet.layout();
    let terrain = match &planet.terrain().spec {
        TerrainSpec::Dem(d) => format!("dem:{}:{}:{}", d.interpolation, d.seed, d.digest),
        spec => spec.to_string(),
    };
    let mut v = json!({
        "terrain": terrain,
        "layout": {"n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c()},
        "datumRadius": planet.datum_radius(),
    });
    if let Some(n) = edits {
        v["edits"] = json!(n);
    }
    v
}

/// The material id of a cap's vertices in a tile (`docs/specs/tiles-v1.md`): a client can tell
/// the caps (seen only through a crack between levels) from the surface.
pub const CAP_MATERIAL: u8 = 255;

/// How far a tile's caps are moved out from its chunk's centre (and as far down), as a fraction
/// of their horizontal distance to it: a ten-thousandth (2 mm on a 38 m chunk, 2 m on a 40 km
/// one), far beyond the `f32`
/// rounding of a client drawing each tile relative to its own centre (about 1e-7 of the
/// distance to the eye), far below a pixel.
pub const CAP_OFFSET: f64 = 1e-4;

/// Gives a closed chunk's caps vertices of their own, copies of the surface's border vertices
/// with material [`CAP_MATERIAL`], moved out from `centre` (relative to the mesh's origin) and
/// down, and joins each border edge of the surface to its cap by a *flange* (two triangles): the
/// tile stays closed, and its caps now lie a hair past the chunk's sides, so that two tiles
/// meeting there overlap by that hair instead of touching. A client that draws them with `f32`
/// rounding then leaves no pinhole along their seam: a pixel's ray that slips between the two
/// surfaces meets a flange. The surface is the triangles of the mesh's cubes; the caps are the
/// triangles after them.
///
/// The move: out along the vertex's horizontal offset from the centre (perpendicular to the
/// planet's radius through the vertex; the planet's centre is at `-origin`) by [`CAP_OFFSET`] of
/// it, and down toward the planet's centre by as much. Never up: a cap's top edge moved up
/// would stand above a neighbour's surface that falls away from the seam, a sliver of wall seen
/// from above (a dashed line along the faces' edges from orbit); moved down it stays under any
/// neighbour that falls less steeply than 45 degrees within the hair.
fn separate_caps(mesh: &mut ChunkMesh, centre: DVec3, origin: DVec3) {
    let surface = 3 * mesh.cube_runs.last().map_or(0, |r| r[1] as usize);
    if surface == mesh.indices.len() {
        return;
    }
    // The caps' edges, before their vertices are copied.
    let mut cap_edges: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    for t in mesh.indices[surface..].chunks_exact(3) {
        for e in 0..3 {
            cap_edges.insert((t[e], t[(e + 1) % 3]));
        }
    }
    // Each cap vertex is shaded as the surface above it: its attributes are those of the
    // surface's border vertex nearest to it across the radius (itself, on the border), so that
    // a pixel where a client shows a cap (a seam's rounding, a crack) has the surface's colour.
    let position = |m: &ChunkMesh, i: usize| {
        let low = m.positions_low.get(i).copied().unwrap_or([0.0; 3]);
        DVec3::from(m.positions[i].map(f64::from)) + DVec3::from(low.map(f64::from))
    };
    let on_surface: std::collections::HashSet<u32> = mesh.indices[..surface].iter().copied().collect();
    let mut border: Vec<u32> = mesh.indices[surface..]
        .iter()
        .copied()
        .filter(|v| on_surface.contains(v))
        .collect();
    border.sort_unstable();
    border.dedup();
    let border: Vec<(u32, DVec3)> = border.into_iter().map(|v| (v, position(mesh, v as usize))).collect();
    let above = |m: &ChunkMesh, v: u32| -> usize {
        if on_surface.contains(&v) {
            return v as usize;
        }
        let p = position(m, v as usize);
        let up = (p + origin).normalize_or_zero();
        let across = |q: DVec3| {
            let d = q - p;
            (d - up * d.dot(up)).length_squared()
        };
        border
            .iter()
            .min_by(|a, b| across(a.1).total_cmp(&across(b.1)))
            .map_or(v as usize, |b| b.0 as usize)
    };
    let mut copy: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for n in surface..mesh.indices.len() {
        let v = mesh.indices[n];
        let c = *copy.entry(v).or_insert_with(|| {
            let i = v as usize;
            let from = above(mesh, v);
            let p = position(mesh, i);
            let m = &mut *mesh;
            let up = (p + origin).normalize_or_zero();
            let d = p - centre;
            let out = d - up * d.dot(up);
            let step = CAP_OFFSET * out.length();
            let moved = p + out * CAP_OFFSET - up * step;
            let high = moved.as_vec3();
            m.positions.push(high.to_array());
            if !m.positions_low.is_empty() {
                m.positions_low.push((moved - high.as_dvec3()).as_vec3().to_array());
            }
            m.normals.push(m.normals[from]);
            m.edge_keys.push(m.edge_keys[i]);
            m.heights.push(m.heights[from]);
            m.water_depths.push(m.water_depths[from]);
            m.colors.push(m.colors[from]);
            m.materials.push(CAP_MATERIAL);
            if !m.vertex_edges.is_empty() {
                m.vertex_edges.push(m.vertex_edges[i]);
            }
            (m.positions.len() - 1) as u32
        });
        mesh.indices[n] = c;
    }
    // Flanges: a surface edge a -> b whose cap runs b -> a becomes a quad a, b, b', a'.
    let mut flanges = Vec::new();
    for t in mesh.indices[..surface].chunks_exact(3) {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            if cap_edges.contains(&(b, a)) {
                let (a2, b2) = (copy[&a], copy[&b]);
                flanges.extend_from_slice(&[b, a, a2, b, a2, b2]);
            }
        }
    }
    mesh.indices.extend_from_slice(&flanges);
}

/// The glTF coordinates of an ECEF vector: 3D Tiles turns glTF's Y-up into Z-up by
/// `(x, y, z) -> (x, -z, y)`, so glTF holds `(X, Z, -Y)`.
fn gltf_axes(e: DVec3) -> DVec3 {
    DVec3::new(e.x, e.z, -e.y)
}

/// How much a level's geometric error at least exceeds the next finer level's (see
/// [`strictly_growing`]).
pub const ERROR_STEP: f64 = 1.0 / 1024.0;

/// The measured level errors (non-decreasing in the level, `pmc_lod`'s running maximum) made
/// strictly growing wherever they are positive: a level whose error equals the finer one's gets
/// that error times `1 + ERROR_STEP`. Still an upper bound of the level's error; and a 3D Tiles
/// client never sees a child whose error is not below its parent's, which some clients
/// (3DTilesRendererJS) take for a tile to refine past unconditionally.
fn strictly_growing(mut errors: Vec<f64>) -> Vec<f64> {
    for l in 1..errors.len() {
        let finer = errors[l - 1];
        if finer > 0.0 && errors[l] <= finer * (1.0 + ERROR_STEP) {
            errors[l] = finer * (1.0 + ERROR_STEP);
        }
    }
    errors
}

impl TileSet {
    /// The tileset of `planet` placed in `frame`, with the planet's measured geometric error of
    /// each level of detail (`pmc_lod::measure_level_errors`, metres, index = level).
    pub fn new(
        planet: Arc<Planet>,
        errors: Vec<f64>,
        frame: TileFrame,
        options: TileOptions,
        generator: &str,
    ) -> Result<TileSet, TilesError> {
        if planet.heightfield_mode().is_some() {
            return Err(TilesError::Heightfield);
        }
        let layout = *planet.layout();
        let tiling = Tiling::new(layout);
        let want = usize::from(layout.max_level()) + 1;
        if errors.len() != want || errors.iter().any(|e| !e.is_finite() || *e < 0.0) {
            return Err(TilesError::Errors {
                got: errors.len(),
                want,
            });
        }
        if let Some(m) = options.max_level {
            if m >= tiling.levels() {
                return Err(TilesError::Invalid(format!(
                    "--max-level {m}: this planet's tiles have levels 0 to {}",
                    tiling.levels() - 1
                )));
            }
        }
        if let TileFrame::Wgs84 { datum } = frame {
            if !(datum.is_finite() && datum > 0.0) {
                return Err(TilesError::Invalid(format!("datum radius {datum} m")));
            }
        }
        let region = match options.region {
            None => None,
            Some(r) => {
                if !(r.radius.is_finite() && r.radius > 0.0) {
                    return Err(TilesError::Invalid(format!(
                        "region radius {} m: it must be a positive number of metres",
                        r.radius
                    )));
                }
                let dir = LatLon::new(r.lat, r.lon)
                    .map_err(|e| TilesError::Invalid(format!("region: {e}")))?
                    .to_unit();
                Some((dir * planet.datum_radius(), r.radius))
            }
        };
        Ok(TileSet {
            planet,
            frame,
            tiling,
            errors: strictly_growing(errors),
            options,
            region,
            generator: generator.to_string(),
        })
    }

    /// The planet.
    pub fn planet(&self) -> &Arc<Planet> {
        &self.planet
    }

    /// The frame.
    pub fn frame(&self) -> TileFrame {
        self.frame
    }

    /// The tiling.
    pub fn tiling(&self) -> &Tiling {
        &self.tiling
    }

    /// Tile levels in the tileset.
    pub fn available_levels(&self) -> u8 {
        self.options.max_level.map_or(self.tiling.levels(), |m| m + 1)
    }

    /// The tile's bounding sphere in the planet's frame: its chunk's provable sphere
    /// (`pmc_lod::chunk_sphere`), or for a virtual tile the ball of the shell's outer radius.
    fn planet_sphere(&self, t: &TileCoord) -> (DVec3, f64) {
        match self.tiling.key(t) {
            Some(key) => {
                let s = pmc_lod::bounds::chunk_sphere(self.tiling.layout(), &key);
                (s.center, s.radius)
            }
            None => (DVec3::ZERO, self.tiling.layout().radius() * (1.0 + 1e-9)),
        }
    }

    /// The tile's bounding sphere in ECEF metres: it holds every vertex of the tile's content
    /// and of its descendants' (REPLACE refinement), as stored: grown by twice [`CAP_OFFSET`]
    /// for the caps moved out from the chunk's centre, and for the `f32` rounding of positions
    /// relative to its centre (at most `√3 · 2^-24` of the radius).
    pub fn sphere(&self, t: &TileCoord) -> (DVec3, f64) {
        let (c, r) = self.planet_sphere(t);
        let (c, r) = self.frame.ball(c, r * (1.0 + CAP_OFFSET));
        (c, r * (1.0 + CAP_OFFSET + 1e-6))
    }

    /// The tile's geometric error, metres: its level's measured error (made strictly growing
    /// with the level by at least [`ERROR_STEP`]), stretched by the frame; a virtual tile's is
    /// twice its children's.
    pub fn geometric_error(&self, t: &TileCoord) -> f64 {
        let stretch = self.frame.stretch(self.tiling.layout().d_b());
        match self.tiling.chunk_level(t.level) {
            Some(l) => self.errors[usize::from(l)] * stretch,
            None => {
                let top = *self.errors.last().expect("one error per level");
                let up = self.tiling.virtual_levels() - t.level;
                top * stretch * f64::from(1u32 << up)
            }
        }
    }

    /// Whether the tile may be in the tileset, by what costs nothing to tell: it exists, is within
    /// the levels asked for and meets the region, and its chunk lies within the planet's radial
    /// bounds ([`pmc_planet::Planet::may_hold_surface`]). [`TileSet::available`] then samples
    /// the chunk.
    pub fn candidate(&self, t: &TileCoord) -> bool {
        if t.level >= self.available_levels() || !self.tiling.exists(t) {
            return false;
        }
        if let Some((c, r)) = self.region {
            let (tc, tr) = self.planet_sphere(t);
            if (tc - c).length() > tr + r {
                return false;
            }
        }
        self.tiling.key(t).is_none_or(|key| self.planet.may_hold_surface(&key))
    }

    /// Whether the tile is in the tileset, its parent being in it: a [`TileSet::candidate`] whose
    /// chunk meshes to something (`Planet::chunk_is_empty`: told by the density's bounds where
    /// they can, else by sampling the chunk). So the tree follows the surface: air and rock end
    /// their branches, and a client never walks a subtree with nothing to draw. A feature
    /// smaller than a level's voxels inside a chunk whose every sample is of one sign (a small
    /// cave deep in rock) is not reached through that chunk.
    pub fn available(&self, t: &TileCoord) -> bool {
        self.candidate(t)
            && self.tiling.key(t).is_none_or(|key| {
                SCRATCH.with(|s| match s.try_borrow_mut() {
                    Ok(mut s) => !self.planet.chunk_is_empty(&key, &mut s),
                    Err(_) => !self.planet.chunk_is_empty(&key, &mut ChunkScratch::default()),
                })
            })
    }

    /// The chunk of a tile closed and shaded, or `None` when it has no surface or no chunk.
    fn closed_mesh(&self, key: ChunkKey) -> ChunkMesh {
        SCRATCH.with(|s| {
            let mut out = ChunkMesh::default();
            match s.try_borrow_mut() {
                Ok(mut s) => self.planet.chunk_mesh_closed_into(key, &mut s, &mut out),
                Err(_) => self
                    .planet
                    .chunk_mesh_closed_into(key, &mut ChunkScratch::default(), &mut out),
            }
            out
        })
    }

    /// Whether an available tile has content: it is a chunk's (not virtual) at or below the
    /// tileset's least level with content. Told without meshing, so a subtree file names its
    /// contents before they are made.
    pub fn has_content(&self, t: &TileCoord) -> bool {
        t.level >= self.options.min_level && self.tiling.key(t).is_some()
    }

    /// The tile's content, a binary glTF (see `docs/specs/tiles-v1.md`): every available tile of
    /// a chunk at or below the tileset's least level has one ([`TileSet::has_content`]). `None`
    /// for the others. Positions are `f32` relative to the tile's sphere's centre in glTF axes, the
    /// centre the node's `f64` translation.
    pub fn content(&self, t: &TileCoord) -> Result<Option<Vec<u8>>, TilesError> {
        if !self.available(t) {
            return Ok(None);
        }
        self.content_of_available(t)
    }

    /// [`TileSet::content`] of a tile known to be available (a subtree's build has tested it).
    fn content_of_available(&self, t: &TileCoord) -> Result<Option<Vec<u8>>, TilesError> {
        let Some(key) = self.tiling.key(t).filter(|_| self.has_content(t)) else {
            return Ok(None);
        };
        let mut mesh = self.closed_mesh(key);
        let origin = mesh.origin;
        separate_caps(&mut mesh, self.planet_sphere(t).0 - origin, origin);
        let (centre, _) = self.sphere(t);
        for i in 0..mesh.vertex_count() {
            let w = mesh.world_position_full(i);
            let n = DVec3::from(mesh.normals[i].map(f64::from));
            let e = self.frame.to_ecef(w) - centre;
            mesh.positions[i] = gltf_axes(e).as_vec3().to_array();
            mesh.normals[i] = gltf_axes(self.frame.normal_to_ecef(w, n)).as_vec3().to_array();
        }
        mesh.origin = gltf_axes(centre);
        mesh.positions_low.clear();
        let mut out = Vec::new();
        let name = key.to_string();
        pmc_formats::write_tile_glb(&mesh, &name, &self.generator, json!({"pmc": {"chunk": name}}), &mut out).map_err(
            |source| TilesError::Content {
                tile: format!("{}/{}", t.face, t.path()),
                source,
            },
        )?;
        Ok(Some(out))
    }

    /// Builds the subtree file rooted at `root` (a tile at a multiple of [`SUBTREE_LEVELS`]): an
    /// external tileset whose root is `root`, holding the available tiles of its levels with
    /// their bounding spheres, geometric errors and contents (meshed in parallel), and, under its
    /// deepest tiles, one tile per available child subtree whose content is that subtree's file.
    /// The same bytes every time, on any thread count.
    pub fn build_subtree(&self, root: TileCoord) -> Result<SubtreeBuild, TilesError> {
        self.build(root, true)
    }

    /// The subtree file rooted at `root` alone, as [`TileSet::build_subtree`] writes it, without
    /// meshing its tiles: what a server answers before a client asks for the contents one by one
    /// ([`TileSet::content`]).
    pub fn subtree_file(&self, root: TileCoord) -> Result<SubtreeBuild, TilesError> {
        self.build(root, false)
    }

    fn build(&self, root: TileCoord, with_contents: bool) -> Result<SubtreeBuild, TilesError> {
        if !root.level.is_multiple_of(SUBTREE_LEVELS) {
            return Err(TilesError::Invalid(format!(
                "tile {}/{} is not the root of a subtree",
                root.face,
                root.path()
            )));
        }
        let count = octree_tiles(SUBTREE_LEVELS) as usize;
        let (coords, tiles) = self.availability(root);
        let contents: Vec<Option<Vec<u8>>> = if with_contents {
            (0..count)
                .into_par_iter()
                .map(|n| {
                    if tiles.get(n) {
                        self.content_of_available(&coords[n])
                    } else {
                        Ok(None)
                    }
                })
                .collect::<Result<_, _>>()?
        } else {
            vec![None; count]
        };
        let child_roots = self.children_of(root, &tiles);
        // URLs are relative to the subtree file, `subtrees/FACE/LEVEL/X/Y/Z.json`.
        let up = "../../../../../";
        let index: std::collections::HashMap<TileCoord, usize> =
            coords.iter().enumerate().map(|(n, t)| (*t, n)).collect();
        let node = |t: &TileCoord| -> Value {
            let (c, r) = self.sphere(t);
            json!({"boundingVolume": {"sphere": [c.x, c.y, c.z, r]}, "geometricError": self.geometric_error(t)})
        };
        // Deepest first, so a tile's children are made before it.
        let mut made: Vec<Option<Value>> = vec![None; count];
        for n in (0..count).rev() {
            if !tiles.get(n) {
                continue;
            }
            let t = coords[n];
            let mut v = node(&t);
            if self.has_content(&t) {
                v["content"] = json!({"uri": format!("{up}content/{}/{}.glb", t.face.name(), t.path())});
            }
            let mut children = Vec::new();
            if t.level + 1 < root.level + SUBTREE_LEVELS {
                for m in 0..8u32 {
                    let c = t.descendant(1, m & 1, m >> 1 & 1, m >> 2 & 1);
                    if let Some(c) = index.get(&c).and_then(|&i| made[i].take()) {
                        children.push(c);
                    }
                }
            } else {
                for c in child_roots.iter().filter(|c| c.parent() == Some(t)) {
                    let mut v = node(c);
                    v["content"] = json!({"uri": format!("{up}subtrees/{}/{}.json", c.face.name(), c.path())});
                    children.push(v);
                }
            }
            if !children.is_empty() {
                v["children"] = Value::Array(children);
            }
            made[n] = Some(v);
        }
        let mut top = made[0].take().unwrap_or_else(|| node(&root));
        top["refine"] = json!("REPLACE");
        let doc = json!({
            "asset": {"version": "1.1", "generator": self.generator},
            "geometricError": self.geometric_error(&root),
            "root": top,
        });
        let available = tiles.count();
        Ok(SubtreeBuild {
            subtree: serde_json::to_vec(&doc).expect("JSON serialises"),
            contents: coords
                .into_iter()
                .zip(contents)
                .filter_map(|(t, c)| c.map(|c| (t, c)))
                .collect(),
            children: child_roots,
            available,
        })
    }

    /// The tiles of the subtree rooted at `root`, in level order and Morton order within a
    /// level, and which are available: top-down, a tile only under an available parent.
    fn availability(&self, root: TileCoord) -> (Vec<TileCoord>, Bits) {
        let count = octree_tiles(SUBTREE_LEVELS) as usize;
        let mut coords = Vec::with_capacity(count);
        for d in 0..SUBTREE_LEVELS {
            for m in 0..1u64 << (3 * u32::from(d)) {
                let (x, y, z) = demorton3(m);
                coords.push(root.descendant(d, x, y, z));
            }
        }
        let mut tiles = Bits::zeros(count);
        // Level by level (a tile needs its parent), the tiles of a level tested in parallel.
        for d in 0..SUBTREE_LEVELS {
            let first = octree_tiles(d) as usize;
            let level = &coords[first..first + (1usize << (3 * u32::from(d)))];
            let ok: Vec<bool> = level
                .par_iter()
                .map(|t| {
                    let parent_ok = match d {
                        0 => true,
                        _ => {
                            let p = t.parent().expect("below the root");
                            let pd = u32::from(d - 1);
                            let (px, py, pz) = (p.x - (root.x << pd), p.y - (root.y << pd), p.z - (root.z << pd));
                            tiles.get(octree_tiles(d - 1) as usize + octree::morton3(px, py, pz) as usize)
                        }
                    };
                    parent_ok && self.available(t)
                })
                .collect();
            for (i, ok) in ok.into_iter().enumerate() {
                if ok {
                    tiles.set(first + i);
                }
            }
        }
        (coords, tiles)
    }

    /// The child subtrees of the subtree rooted at `root` whose tiles are `tiles`: the tiles one
    /// level below it that are available (sampled: never a leaf without content, see
    /// `docs/specs/tiles-v1.md`) under an available tile, in Morton order.
    fn children_of(&self, root: TileCoord, tiles: &Bits) -> Vec<TileCoord> {
        let below = 1u64 << (3 * u32::from(SUBTREE_LEVELS));
        let last = octree_tiles(SUBTREE_LEVELS - 1) as usize;
        (0..below)
            .into_par_iter()
            .filter_map(|m| {
                let (x, y, z) = demorton3(m);
                let t = root.descendant(SUBTREE_LEVELS, x, y, z);
                (tiles.get(last + (m >> 3) as usize) && self.available(&t)).then_some(t)
            })
            .collect()
    }

    /// The roots of the available child subtrees of the subtree rooted at `root`, from the
    /// availability alone (nothing is meshed).
    pub fn child_subtrees(&self, root: TileCoord) -> Vec<TileCoord> {
        let (_, tiles) = self.availability(root);
        self.children_of(root, &tiles)
    }

    /// The tileset JSON. `prefix` goes before every subtree URL (for example a revision,
    /// `r12/`, so that a client fetching the tileset again after an edit finds new URLs);
    /// `extras` are written under `extras.pmc`. Its root holds the six faces' roots, each an
    /// external tileset: the face's first subtree file.
    pub fn tileset_json(&self, prefix: &str, extras: Value) -> Value {
        // Drawing nothing misses the whole planet: the root's error is the planet's radius, so
        // a client refines it at any distance from which the planet shows.
        let root_error = self.tiling.layout().radius();
        let faces: Vec<Value> = Face::ALL
            .into_iter()
            .map(TileCoord::root)
            .filter(|t| self.available(t))
            .map(|t| {
                let (c, r) = self.sphere(&t);
                json!({
                    "boundingVolume": {"sphere": [c.x, c.y, c.z, r]},
                    "geometricError": self.geometric_error(&t),
                    "content": {"uri": format!("{prefix}subtrees/{}/{}.json", t.face.name(), t.path())},
                })
            })
            .collect();
        let (_, planet_r) = self.frame.ball(DVec3::ZERO, self.tiling.layout().radius());
        let mut extras_all = json!({
            "frame": self.frame.name(),
            "subtreeLevels": SUBTREE_LEVELS,
            "levels": self.available_levels(),
            "virtualLevels": self.tiling.virtual_levels(),
            "minLevel": self.options.min_level,
        });
        if let TileFrame::Wgs84 { datum } = self.frame {
            extras_all["datum"] = json!(datum);
        }
        if let Value::Object(m) = extras {
            for (k, v) in m {
                extras_all[k] = v;
            }
        }
        json!({
            "asset": {"version": "1.1", "generator": self.generator},
            "extras": {"pmc": extras_all},
            "geometricError": root_error,
            "root": {
                "boundingVolume": {"sphere": [0.0, 0.0, 0.0, planet_r]},
                "geometricError": root_error,
                "refine": "REPLACE",
                "children": faces,
            },
        })
    }
}
