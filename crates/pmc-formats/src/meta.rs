//! What an exported file says about the planet it holds.

use crate::ExportError;
use serde_json::{json, Value};

/// Describes the planet being exported; written into every file (GLB `asset.extras`, OBJ `#`
/// comments, PLY `comment` lines).
///
/// `n_c, n_t, d_b, l_d, d_c` are the layout parameters of seed 000 (chunks per face axis, tiles
/// per chunk axis, base depth in metres, layer depth in metres, chunks along depth).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportMeta {
    /// Name of the terrain preset (e.g. `"earth"`).
    pub preset: String,
    /// Seed of the terrain noise.
    pub seed: u64,
    /// Chunks per face axis.
    pub n_c: u32,
    /// Tiles per chunk axis.
    pub n_t: u32,
    /// Base depth (radius of the innermost shell), metres.
    pub d_b: f64,
    /// Layer depth (radial size of one tile), metres.
    pub l_d: f64,
    /// Chunks along the depth axis.
    pub d_c: u32,
    /// Outer radius of the meshed shell, metres.
    pub radius: f64,
    /// Sea-level radius in metres, or `None` for a planet without sea. When set, GLB files get a
    /// sea sphere of this radius.
    pub sea_radius: Option<f64>,
    /// Names of the material ids used in the meshes' `materials` buffers (id = position).
    pub materials: Vec<String>,
    /// The program that wrote the file, e.g. `"pmc 0.1.0"`.
    pub generator: String,
}

impl ExportMeta {
    /// Checks what the writers rely on.
    pub(crate) fn check(&self) -> Result<(), ExportError> {
        if let Some(r) = self.sea_radius {
            if !(r.is_finite() && r > 0.0) {
                return Err(ExportError::InvalidMeta(format!(
                    "sea_radius is {r}; it must be a positive finite number of metres, or None for no sea"
                )));
            }
        }
        Ok(())
    }

    /// The metadata as a JSON object for GLB `asset.extras`. The seed is a decimal string, so
    /// readers that parse JSON numbers as doubles (JavaScript) do not round it.
    pub(crate) fn to_json(&self, format: &str) -> Value {
        json!({
            "pmc_format": format,
            "pmc_format_version": 1,
            "generator": self.generator,
            "preset": self.preset,
            "seed": self.seed.to_string(),
            "n_c": self.n_c,
            "n_t": self.n_t,
            "d_b": self.d_b,
            "l_d": self.l_d,
            "d_c": self.d_c,
            "radius": self.radius,
            "sea_radius": self.sea_radius,
            "materials": self.materials,
            "frame": FRAME,
        })
    }

    /// The metadata as `key value` lines for OBJ and PLY comments: strings JSON-quoted with every
    /// non-ASCII character escaped, so each line is one line of ASCII.
    pub(crate) fn comment_lines(&self, format: &str) -> Vec<String> {
        let num = |x: f64| x.to_string();
        let materials: Vec<String> = self.materials.iter().map(|m| quote(m)).collect();
        vec![
            format!("{format} version 1"),
            format!("generator {}", quote(&self.generator)),
            format!("preset {}", quote(&self.preset)),
            format!("seed {}", self.seed),
            format!("n_c {}", self.n_c),
            format!("n_t {}", self.n_t),
            format!("d_b {}", num(self.d_b)),
            format!("l_d {}", num(self.l_d)),
            format!("d_c {}", self.d_c),
            format!("radius {}", num(self.radius)),
            format!("sea_radius {}", self.sea_radius.map_or("none".to_string(), num)),
            format!("materials [{}]", materials.join(",")),
            format!("frame {}", quote(FRAME)),
        ]
    }
}

/// One-line description of the coordinate frame, written into every file.
const FRAME: &str =
    "metres, planet-centred, Y-up right-handed: +Y north pole, +Z latitude 0 longitude 0, +X longitude 90 E";

/// JSON string literal of `s` with all non-ASCII characters as `\uXXXX` escapes.
pub(crate) fn quote(s: &str) -> String {
    let json = Value::String(s.to_string()).to_string();
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{u:04x}"));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quote_is_ascii_and_round_trips() {
        for s in ["plain", "line\nbreak \"q\" \\", "Zürich 🌍", ""] {
            let q = quote(s);
            assert!(q.is_ascii() && !q.contains('\n'), "{q}");
            assert_eq!(serde_json::from_str::<String>(&q).unwrap(), s);
        }
    }

    #[test]
    fn rejects_bad_sea_radius() {
        for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let m = ExportMeta {
                sea_radius: Some(r),
                ..Default::default()
            };
            assert!(matches!(m.check(), Err(ExportError::InvalidMeta(_))), "{r}");
        }
        assert!(ExportMeta {
            sea_radius: Some(1.0),
            ..Default::default()
        }
        .check()
        .is_ok());
    }

    #[test]
    fn json_keeps_big_seeds_exact() {
        let m = ExportMeta {
            seed: u64::MAX,
            sea_radius: None,
            ..Default::default()
        };
        let v = m.to_json("pmc-glb");
        assert_eq!(v["seed"], "18446744073709551615");
        assert!(v["sea_radius"].is_null());
        assert_eq!(v["pmc_format_version"], 1);
    }
}
