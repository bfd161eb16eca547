//! The supported file formats and how a path selects one.

use crate::ExportError;
use std::path::Path;

/// A supported output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Binary glTF 2.0: one node per chunk, chunk-relative positions (see `docs/specs/glb-v1.md`).
    Glb,
    /// Wavefront OBJ: one welded world-space mesh (see `docs/specs/obj-v1.md`).
    Obj,
    /// Binary little-endian PLY: one welded world-space mesh with attributes (see
    /// `docs/specs/ply-v1.md`).
    Ply,
}

impl Format {
    /// All formats.
    pub const ALL: [Format; 3] = [Format::Glb, Format::Obj, Format::Ply];

    /// The format named by the extension of `path` (`.glb`, `.obj`, `.ply`, any letter case).
    ///
    /// ```
    /// use pmc_formats::Format;
    /// use std::path::Path;
    /// assert_eq!(Format::from_path(Path::new("out/Earth.GLB")).unwrap(), Format::Glb);
    /// assert!(Format::from_path(Path::new("earth.stl")).is_err());
    /// ```
    pub fn from_path(path: &Path) -> Result<Format, ExportError> {
        let ext = path.extension().map(|e| e.to_string_lossy().into_owned());
        let found = ext
            .as_deref()
            .and_then(|e| Format::ALL.into_iter().find(|f| f.extension().eq_ignore_ascii_case(e)));
        found.ok_or_else(|| ExportError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension: ext,
        })
    }

    /// The usual file extension, lower case, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Glb => "glb",
            Format::Obj => "obj",
            Format::Ply => "ply",
        }
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Format::Glb => "GLB",
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_format_by_extension_in_any_case() {
        for (p, f) in [
            ("a.glb", Format::Glb),
            ("dir.x/b.Obj", Format::Obj),
            ("C.PLY", Format::Ply),
        ] {
            assert_eq!(Format::from_path(Path::new(p)).unwrap(), f, "{p}");
        }
    }

    #[test]
    fn unknown_or_missing_extension_names_the_supported_ones() {
        for p in ["x.stl", "noext", "dir.glb/noext", "x.gltf", ".glb"] {
            let e = Format::from_path(Path::new(p)).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(".glb, .obj or .ply") && msg.contains(p), "{p}: {msg}");
        }
        let msg = Format::from_path(Path::new("x.stl")).unwrap_err().to_string();
        assert!(msg.contains("'.stl'"), "{msg}");
        let msg = Format::from_path(Path::new("noext")).unwrap_err().to_string();
        assert!(msg.contains("no extension"), "{msg}");
    }
}
