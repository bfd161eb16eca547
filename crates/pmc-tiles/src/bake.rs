//! Baking a tileset to a folder any web server can host, resumably.
//!
//! The folder holds `tileset.json`, `subtrees/FACE/LEVEL/X/Y/Z.json`,
//! `content/FACE/LEVEL/X/Y/Z.glb` and `bake.json` (what was baked, so that a bake resumed into
//! the folder is the same one). Every file is written under `.partial/` and renamed into place,
//! so no file in the tileset is ever half-written; `.partial/` is emptied when a bake starts. A
//! subtree's contents are written before its subtree file, and `tileset.json` last: a killed
//! bake resumes by skipping every subtree whose file exists, and the output is the same bytes as
//! a bake never killed. Subtrees are baked depth first, a few at a time, each meshing its tiles
//! on every core, so memory stays bounded at any depth.

use crate::{FrameChoice, TileCoord, TileOptions, TileSet, TilesError};
use pmc_geometry::Face;
use pmc_planet::Planet;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Per tile level: tiles with content, and their bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelStats {
    /// Tiles with content written at this level.
    pub tiles: u64,
    /// Their bytes.
    pub bytes: u64,
}

/// What a bake did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BakeStats {
    /// Subtree files written.
    pub subtrees: u64,
    /// Subtrees found already baked (a resumed bake).
    pub resumed: u64,
    /// Tile contents written, per tile level.
    pub levels: Vec<LevelStats>,
    /// Bytes of subtree files written.
    pub subtree_bytes: u64,
}

impl BakeStats {
    /// Tile contents written.
    pub fn tiles(&self) -> u64 {
        self.levels.iter().map(|l| l.tiles).sum()
    }

    /// Bytes written (contents and subtrees).
    pub fn bytes(&self) -> u64 {
        self.levels.iter().map(|l| l.bytes).sum::<u64>() + self.subtree_bytes
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> TilesError + '_ {
    move |source| TilesError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The folder's files, written through `.partial/`.
struct Folder {
    root: PathBuf,
    partial: PathBuf,
    next: AtomicU64,
}

impl Folder {
    /// Writes `bytes` to `rel` under the folder: into `.partial/` first, then renamed.
    fn write(&self, rel: &str, bytes: &[u8]) -> Result<(), TilesError> {
        let path = self.root.join(rel);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(io(dir))?;
        }
        let tmp = self
            .partial
            .join(format!("{}.tmp", self.next.fetch_add(1, Ordering::Relaxed)));
        std::fs::write(&tmp, bytes).map_err(io(&tmp))?;
        std::fs::rename(&tmp, &path).map_err(io(&path))
    }
}

/// The subtree file of a subtree root, relative to the folder.
pub fn subtree_path(t: &TileCoord) -> String {
    format!("subtrees/{}/{}.json", t.face.name(), t.path())
}

/// The content file of a tile, relative to the folder.
pub fn content_path(t: &TileCoord) -> String {
    format!("content/{}/{}.glb", t.face.name(), t.path())
}

/// Bakes `tiles` into the folder `out` (created if missing), resuming a bake of the same
/// tileset found there. `extras` describe the planet (its terrain and layout): they go into
/// `tileset.json` and `bake.json`, and a folder whose `bake.json` differs is refused.
/// `progress` is called after each subtree with the running figures.
pub fn bake(
    tiles: &TileSet,
    out: &Path,
    extras: Value,
    progress: &(dyn Fn(&BakeStats) + Sync),
) -> Result<BakeStats, TilesError> {
    std::fs::create_dir_all(out).map_err(io(out))?;
    let manifest = manifest(tiles, extras.clone());
    let manifest_path = out.join("bake.json");
    match std::fs::read(&manifest_path) {
        Ok(bytes) => {
            let found: Value = serde_json::from_slice(&bytes).unwrap_or(Value::Null);
            if found != manifest {
                return Err(TilesError::Invalid(format!(
                    "{} holds a bake of another tileset ({}); bake into an empty folder, or remove it first",
                    out.display(),
                    manifest_path.display()
                )));
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let has_files = std::fs::read_dir(out)
                .map_err(io(out))?
                .filter_map(Result::ok)
                .any(|e| e.file_name() != ".partial");
            if has_files {
                return Err(TilesError::Invalid(format!(
                    "{} is not empty and holds no bake.json; bake into an empty folder",
                    out.display()
                )));
            }
        }
        Err(e) => return Err(io(&manifest_path)(e)),
    }
    let partial = out.join(".partial");
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(io(&partial))?;
    }
    std::fs::create_dir_all(&partial).map_err(io(&partial))?;
    let folder = Folder {
        root: out.to_path_buf(),
        partial: partial.clone(),
        next: AtomicU64::new(0),
    };
    folder.write("bake.json", &json_bytes(&manifest))?;

    let mut stats = BakeStats {
        levels: vec![LevelStats::default(); usize::from(tiles.available_levels())],
        ..BakeStats::default()
    };
    let mut stack: Vec<TileCoord> = roots(tiles).into_iter().rev().collect();
    let batch = batch();
    while !stack.is_empty() {
        let take = stack.len().min(batch);
        let work: Vec<TileCoord> = stack.split_off(stack.len() - take);
        let done: Vec<Result<Done, TilesError>> = work.par_iter().map(|root| bake_one(tiles, &folder, *root)).collect();
        let mut children = Vec::new();
        for d in done {
            let d = d?;
            match d.written {
                Some((levels, subtree_bytes)) => {
                    stats.subtrees += 1;
                    stats.subtree_bytes += subtree_bytes;
                    for (l, s) in levels.into_iter().enumerate() {
                        stats.levels[l].tiles += s.tiles;
                        stats.levels[l].bytes += s.bytes;
                    }
                }
                None => stats.resumed += 1,
            }
            children.extend(d.children);
        }
        // Depth first: the children go on top, in reverse so the first is baked first.
        stack.extend(children.into_iter().rev());
        progress(&stats);
    }
    folder.write("tileset.json", &tileset_bytes(tiles, extras))?;
    std::fs::remove_dir_all(&partial).map_err(io(&partial))?;
    Ok(stats)
}

/// How many subtrees a bake meshes side by side, each on every core: enough to keep the cores
/// busy between subtrees, few enough to bound memory (twice the threads of the rayon pool it
/// runs in, at least 2).
pub fn batch() -> usize {
    (2 * rayon::current_num_threads()).max(2)
}

/// The text of `generator` in a bake's tileset (`asset.generator`): `pmc` and its version.
pub fn generator() -> String {
    format!("pmc {}", env!("CARGO_PKG_VERSION"))
}

/// The tile set a bake of `planet` writes: the geometric error of each level measured as every
/// bake measures it (`pmc_lod::measure_level_errors`, 1024 samples, a fixed seed), the frame
/// chosen for the planet's datum radius. Run it inside the thread pool that should measure.
pub fn tile_set(planet: Arc<Planet>, frame: FrameChoice, options: TileOptions) -> Result<TileSet, TilesError> {
    let errors = pmc_lod::measure_level_errors(&planet, 1024, 0x5eed);
    let frame = frame.frame(planet.datum_radius());
    TileSet::new(planet, errors, frame, options, &generator())
}

/// The manifest of a bake (`bake.json`): what was baked, so that a bake resumed into a folder is
/// the same one.
pub fn manifest(tiles: &TileSet, extras: Value) -> Value {
    json!({
        "format": "pmc-tiles-bake",
        "version": 1,
        "tiles": "tiles-v1",
        "frame": tiles.frame().name(),
        "availableLevels": tiles.available_levels(),
        "options": {
            "minLevel": tiles.options.min_level,
            "region": tiles.options.region.map(|r| json!([r.lat, r.lon, r.radius])),
        },
        "planet": extras,
    })
}

/// A JSON document as a bake writes it (pretty-printed).
pub fn json_bytes(v: &Value) -> Vec<u8> {
    serde_json::to_vec_pretty(v).expect("JSON serialises")
}

/// The bytes of a bake's `tileset.json`.
pub fn tileset_bytes(tiles: &TileSet, extras: Value) -> Vec<u8> {
    json_bytes(&tiles.tileset_json("", extras))
}

/// The subtree roots a bake starts from: the root tile of each face that has tiles, in face
/// order.
pub fn roots(tiles: &TileSet) -> Vec<TileCoord> {
    Face::ALL
        .into_iter()
        .map(TileCoord::root)
        .filter(|t| tiles.available(t))
        .collect()
}

/// One file of a subtree's bake.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BakeFile {
    /// Its path in the folder, `/`-separated.
    pub path: String,
    /// The tile level of a content file; `None` for the subtree file.
    pub level: Option<u8>,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

/// What baking one subtree writes, and the subtrees below it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SubtreeFiles {
    /// The subtree's tile contents, then its subtree file (the order a bake writes them in: a
    /// subtree file found in the folder means its contents are there too).
    pub files: Vec<BakeFile>,
    /// The roots of its child subtrees that hold tiles.
    pub children: Vec<TileCoord>,
}

/// Bakes the subtree rooted at `root` in memory: the unit of work of a bake, in one process or
/// spread over many (the Python package's distributed bake). The same root gives the same
/// bytes wherever it is baked.
pub fn subtree_files(tiles: &TileSet, root: TileCoord) -> Result<SubtreeFiles, TilesError> {
    let built = tiles.build_subtree(root)?;
    let mut files: Vec<BakeFile> = built
        .contents
        .into_iter()
        .map(|(t, bytes)| BakeFile {
            path: content_path(&t),
            level: Some(t.level),
            bytes,
        })
        .collect();
    files.push(BakeFile {
        path: subtree_path(&root),
        level: None,
        bytes: built.subtree,
    });
    Ok(SubtreeFiles {
        files,
        children: built.children,
    })
}

/// One subtree's bake: what was written (per level, and the subtree file's bytes), or `None`
/// when its file was there; and its child subtrees.
struct Done {
    written: Option<(Vec<LevelStats>, u64)>,
    children: Vec<TileCoord>,
}

fn bake_one(tiles: &TileSet, folder: &Folder, root: TileCoord) -> Result<Done, TilesError> {
    let rel = subtree_path(&root);
    if folder.root.join(&rel).exists() {
        return Ok(Done {
            written: None,
            children: tiles.child_subtrees(root),
        });
    }
    let files = subtree_files(tiles, root)?;
    let mut levels = vec![LevelStats::default(); usize::from(tiles.available_levels())];
    let mut subtree_bytes = 0;
    for f in &files.files {
        folder.write(&f.path, &f.bytes)?;
        match f.level {
            Some(level) => {
                let l = &mut levels[usize::from(level)];
                l.tiles += 1;
                l.bytes += f.bytes.len() as u64;
            }
            None => subtree_bytes = f.bytes.len() as u64,
        }
    }
    Ok(Done {
        written: Some((levels, subtree_bytes)),
        children: files.children,
    })
}
