//! Shared selection vectors: views on two layouts with fixed error tables and the selections
//! they give, kept in `tests/data/selection-vectors.json` so that other implementations of the
//! rule (the viewer's) can check they select the same chunks.
//!
//! `PMC_BLESS=1 cargo test -p pmc-lod --test lod vectors::` writes the file anew. The views are
//! drawn from a fixed generator and kept only when the selection is robust: it does not change when
//! the pixel error bound, the eye, the occluder and the frustum move by a relative 1e-9, so that
//! an implementation whose `sin`, `cos`, `tan` or `atan2` differ in the last bit selects the same
//! chunks.

use pmc_geometry::glam::{DVec3, DVec4};
use pmc_geometry::{ChunkKey, Face, Layout};
use pmc_lod::{frustum_planes, LodParams, Selection, Selector, View};
use serde_json::{json, Value};
use std::fmt::Write;
use std::path::PathBuf;

const FORMAT: &str = "pmc-lod-selection-vectors";
const VERSION: u64 = 1;

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/selection-vectors.json")
}

/// One case: everything the selection reads.
#[derive(Clone, Debug)]
struct Case {
    name: String,
    layout: Layout,
    errors: Vec<f64>,
    occluder: f64,
    view: View,
    params: LodParams,
}

impl Case {
    fn run(&self) -> Selection {
        Selector::new(self.layout, self.errors.clone(), self.occluder)
            .unwrap()
            .select(&self.view, &self.params)
            .unwrap()
    }

    fn to_json(&self) -> Value {
        let l = &self.layout;
        json!({
            "name": self.name,
            "layout": { "n_c": l.n_c(), "n_t": l.n_t(), "d_b": l.d_b(), "l_d": l.l_d(), "d_c": l.d_c() },
            "errors": self.errors,
            "occluder": self.occluder,
            "view": {
                "eye": self.view.eye.to_array(),
                "frustum": self.view.frustum.map(|f| f.map(|p| p.to_array())),
                "viewport_height_px": self.view.viewport_height_px,
                "fov_y": self.view.fov_y,
            },
            "params": {
                "max_pixel_error": self.params.max_pixel_error,
                "finest_level": self.params.finest_level,
                "max_chunks": self.params.max_chunks,
            },
        })
    }

    fn from_json(v: &Value) -> Case {
        let f = |v: &Value| v.as_f64().unwrap();
        let vec3 = |v: &Value| DVec3::new(f(&v[0]), f(&v[1]), f(&v[2]));
        let l = &v["layout"];
        let u = |v: &Value| u32::try_from(v.as_u64().unwrap()).unwrap();
        let layout = Layout::new(u(&l["n_c"]), u(&l["n_t"]), f(&l["d_b"]), f(&l["l_d"]), u(&l["d_c"])).unwrap();
        let frustum = v["view"]["frustum"].as_array().map(|planes| {
            let p: Vec<DVec4> = planes
                .iter()
                .map(|p| DVec4::new(f(&p[0]), f(&p[1]), f(&p[2]), f(&p[3])))
                .collect();
            [p[0], p[1], p[2], p[3], p[4], p[5]]
        });
        Case {
            name: v["name"].as_str().unwrap().to_string(),
            layout,
            errors: v["errors"].as_array().unwrap().iter().map(f).collect(),
            occluder: f(&v["occluder"]),
            view: View {
                eye: vec3(&v["view"]["eye"]),
                frustum,
                viewport_height_px: f(&v["view"]["viewport_height_px"]),
                fov_y: f(&v["view"]["fov_y"]),
            },
            params: LodParams {
                max_pixel_error: f(&v["params"]["max_pixel_error"]),
                finest_level: u8::try_from(v["params"]["finest_level"].as_u64().unwrap()).unwrap(),
                max_chunks: usize::try_from(v["params"]["max_chunks"].as_u64().unwrap()).unwrap(),
            },
        }
    }
}

/// A selection as the file writes it: `[face index, level, i, j, k, coarser mask, drawn 0/1]`.
fn rows(s: &Selection) -> Vec<[u64; 7]> {
    s.chunks
        .iter()
        .map(|c| {
            [
                c.key.face.index() as u64,
                u64::from(c.key.level),
                u64::from(c.key.i),
                u64::from(c.key.j),
                u64::from(c.key.k),
                u64::from(c.coarser.0),
                u64::from(c.drawn),
            ]
        })
        .collect()
}

fn row_key(r: &[u64; 7]) -> String {
    let key = ChunkKey {
        face: Face::ALL[r[0] as usize],
        level: r[1] as u8,
        i: r[2] as u32,
        j: r[3] as u32,
        k: r[4] as u32,
    };
    key.to_string()
}

/// A small deterministic generator for the views.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn dir(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            if (0.1..=1.0).contains(&v.length()) {
                return v.normalize();
            }
        }
    }
}

/// Whether the case selects the same under relative nudges of 1e-9 to its real inputs.
fn robust(case: &Case, expected: &Selection) -> bool {
    let e = 1e-9;
    let mut nudged = Vec::new();
    for s in [1.0 - e, 1.0 + e] {
        let mut c = case.clone();
        c.params.max_pixel_error *= s;
        nudged.push(c);
        let mut c = case.clone();
        c.occluder *= s;
        nudged.push(c);
        let mut c = case.clone();
        c.view.eye *= s;
        nudged.push(c);
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            let mut c = case.clone();
            c.view.eye += axis * (s - 1.0) * case.view.eye.length().max(1.0);
            nudged.push(c);
        }
        if let Some(f) = case.view.frustum {
            let mut c = case.clone();
            let scale = case.view.eye.length().max(case.layout.radius());
            c.view.frustum = Some(f.map(|p| DVec4::new(p.x, p.y, p.z, p.w + (s - 1.0) * scale)));
            nudged.push(c);
        }
    }
    nudged.iter().all(|c| c.run() == *expected)
}

/// The cases: for each layout, views drawn from a fixed generator (far, orbiting, low over the
/// surface, inside the shell; with and without a frustum; some with a budget or a level cap),
/// keeping only robust ones.
fn generate() -> Vec<Case> {
    let small = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
    let setups = [
        ("default", Layout::default(), vec![0.0, 1.5, 3.0, 6.0], 1800.0),
        ("small", small, vec![0.0, 0.25, 0.5], 95.0),
    ];
    let mut rng = Lcg(0x5eed_10d5);
    let mut out = Vec::new();
    for (name, layout, errors, occluder) in setups {
        let r = layout.radius();
        // Heights over the centre, as multiples of the radius.
        let heights = [1000.0, 5.0, 2.0, 1.3, 1.05, 1.01, 1.003, 0.99, 0.95, 1.02, 1.5, 1.1];
        for (n, h) in heights.into_iter().enumerate() {
            for _attempt in 0..50 {
                let eye = rng.dir() * h * r;
                let to_centre = -eye.normalize();
                let look = (to_centre + rng.dir() * rng.range(0.0, 0.9)).normalize();
                let fov = rng.range(0.4, 1.4);
                let frustum =
                    (n % 3 != 1).then(|| frustum_planes(eye, look, rng.dir(), fov, rng.range(1.0, 2.0), 0.1, 40.0 * r));
                let params = LodParams {
                    max_pixel_error: rng.range(1.0, 6.0),
                    finest_level: if n % 5 == 4 { 1 } else { 0 },
                    max_chunks: if n % 4 == 3 { 120 } else { 100_000 },
                };
                let case = Case {
                    name: format!("{name}-{n}"),
                    layout,
                    errors: errors.clone(),
                    occluder,
                    view: View {
                        eye,
                        frustum,
                        viewport_height_px: rng.range(400.0, 1600.0).round(),
                        fov_y: fov,
                    },
                    params,
                };
                let s = case.run();
                if s.chunks.len() <= 700 && robust(&case, &s) {
                    out.push(case);
                    break;
                }
            }
        }
    }
    out
}

/// The file's text: one case per block, one selected chunk per line.
fn render(cases: &[Case]) -> String {
    let mut text = String::new();
    writeln!(text, "{{").unwrap();
    writeln!(text, "  \"format\": \"{FORMAT}\",").unwrap();
    writeln!(text, "  \"version\": {VERSION},").unwrap();
    writeln!(
        text,
        "  \"chunks\": \"each selected chunk is [face index (Face::ALL order: top, bottom, north, south, east, west), level, i, j, k, coarser side mask (bit n = ChunkSide::ALL[n]: u_min, u_max, v_min, v_max, inner, outer), drawn (0 or 1)], in key order\","
    )
    .unwrap();
    writeln!(text, "  \"cases\": [").unwrap();
    for (n, case) in cases.iter().enumerate() {
        let s = case.run();
        let input = case.to_json();
        writeln!(text, "    {{").unwrap();
        for field in ["name", "layout", "errors", "occluder", "view", "params"] {
            writeln!(
                text,
                "      \"{field}\": {},",
                serde_json::to_string(&input[field]).unwrap()
            )
            .unwrap();
        }
        writeln!(text, "      \"expected\": {{").unwrap();
        writeln!(text, "        \"truncated\": {},", s.truncated).unwrap();
        writeln!(text, "        \"chunks\": [").unwrap();
        let r = rows(&s);
        for (m, row) in r.iter().enumerate() {
            let sep = if m + 1 < r.len() { "," } else { "" };
            writeln!(text, "          {}{sep}", serde_json::to_string(row).unwrap()).unwrap();
        }
        writeln!(text, "        ]").unwrap();
        writeln!(text, "      }}").unwrap();
        writeln!(text, "    }}{}", if n + 1 < cases.len() { "," } else { "" }).unwrap();
    }
    writeln!(text, "  ]").unwrap();
    writeln!(text, "}}").unwrap();
    text
}

#[test]
fn selections_match_the_shared_vectors() {
    if std::env::var_os("PMC_BLESS").is_some_and(|v| v == "1") {
        let cases = generate();
        std::fs::write(path(), render(&cases)).unwrap();
    }
    let text = std::fs::read_to_string(path())
        .unwrap_or_else(|e| panic!("{}: {e}; run with PMC_BLESS=1 to write it", path().display()));
    let doc: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(doc["format"], FORMAT);
    assert_eq!(doc["version"], VERSION);
    let cases = doc["cases"].as_array().unwrap();
    assert!(cases.len() >= 20, "only {} cases", cases.len());
    let (mut truncated, mut culled, mut coarse_sides) = (0, 0, 0);
    for v in cases {
        let case = Case::from_json(v);
        let s = case.run();
        let expected: Vec<[u64; 7]> = v["expected"]["chunks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| std::array::from_fn(|n| r[n].as_u64().unwrap()))
            .collect();
        let got = rows(&s);
        if let Some(n) = (0..got.len().max(expected.len())).find(|n| got.get(*n) != expected.get(*n)) {
            panic!(
                "case {}: chunk {n} differs: got {:?} ({}), expected {:?} ({})",
                case.name,
                got.get(n),
                got.get(n).map(row_key).unwrap_or_default(),
                expected.get(n),
                expected.get(n).map(row_key).unwrap_or_default(),
            );
        }
        assert_eq!(
            Some(s.truncated),
            v["expected"]["truncated"].as_bool(),
            "case {}",
            case.name
        );
        truncated += usize::from(s.truncated);
        culled += s.chunks.iter().filter(|c| !c.drawn).count();
        coarse_sides += s.chunks.iter().filter(|c| !c.coarser.is_empty()).count();
    }
    // The vectors exercise the budget, the culling and the seams.
    assert!(truncated > 0 && culled > 0 && coarse_sides > 0);
}
