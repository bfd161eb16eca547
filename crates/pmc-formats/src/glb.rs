//! Binary glTF 2.0 (GLB) export, layout version 1 (`docs/specs/glb-v1.md`).
//!
//! One mesh and one node per chunk; vertex positions stay chunk-relative `f32`, and the node's
//! translation carries the chunk origin as a full-precision `f64` JSON number. The JSON is built
//! with `gltf-json`; the binary container (header, JSON chunk, BIN chunk) is written here, and the
//! vertex data is streamed straight from the chunk meshes without an intermediate copy.

use crate::check::{check_meshes, Checked};
use crate::export::Counting;
use crate::sea::{sea_faces, SeaFace, SEA_QUADS};
use crate::{ExportError, ExportMeta, ExportStats};
use gltf_json as gj;
use gltf_json::accessor::{ComponentType, GenericComponentType, Type};
use gltf_json::buffer::Target;
use gltf_json::mesh::{Mode, Semantic};
use gltf_json::validation::{Checked::Valid, USize64};
use gltf_json::{Index, Value};
use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use serde_json::json;
use std::collections::BTreeMap;
use std::io::Write;

/// GLB magic, `glTF` in ASCII.
const MAGIC: &[u8; 4] = b"glTF";
/// GLB container version.
const VERSION: u32 = 2;
/// Chunk type of the JSON chunk (`JSON`).
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
const CHUNK_BIN: u32 = 0x004E_4942;

/// A chunk's node and mesh name, fixed by version 1 of the layout (`docs/specs/glb-v1.md`):
/// `face/L<level>/<i>_<j>_<k>` (for example `top/L0/3_4_1`), or `chunk-N` for a mesh without a
/// key. Files keep these names so that readers of version 1 find their nodes; everywhere else a
/// key is written in its own text form, `face/level/i/j/k` (`ChunkKey`'s `Display`).
fn node_name(index: usize, mesh: &ChunkMesh) -> String {
    match &mesh.key {
        Some(k) => format!("{}/L{}/{}_{}_{}", k.face, k.level, k.i, k.j, k.k),
        None => format!("chunk-{index}"),
    }
}

/// Writes `meshes` as one binary glTF 2.0 file (layout: `docs/specs/glb-v1.md`).
///
/// Meshes without triangles are skipped. Every mesh is checked before the first byte is written;
/// an inconsistent mesh gives [`ExportError::InvalidMesh`]. With `meta.sea_radius` set, a sea
/// sphere is added under a node named `sea`.
pub fn write_glb<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<(), ExportError> {
    write(meshes, meta, out).map(|_| ())
}

/// Writes one mesh as a binary glTF 2.0 file of its own, as a 3D Tiles tile's content
/// (`docs/specs/tiles-v1.md`): the scene `tile` holds one node named `name`, translated by the
/// mesh's origin (written as an `f64` JSON number) and holding the mesh, with the attributes
/// laid out as in version 1 of the GLB layout (`docs/specs/glb-v1.md`); `extras` becomes the
/// asset's extras. Returns the bytes written.
///
/// A mesh with no triangle gives a node with no mesh (a tile whose chunk the bounds could not
/// tell empty, and that meshed to nothing).
///
/// # Errors
/// [`ExportError::InvalidMesh`] for an inconsistent mesh, and the writer's I/O errors.
pub fn write_tile_glb<W: Write>(
    mesh: &ChunkMesh,
    name: &str,
    generator: &str,
    extras: Value,
    out: W,
) -> Result<u64, ExportError> {
    let meshes = std::slice::from_ref(mesh);
    let checked = check_meshes(meshes)?;
    let mut b = Builder::new(generator);
    let node = match checked.first() {
        Some(c) => {
            let terrain = b.root.push(material("terrain", [1.0; 4], 0.9, false));
            b.chunk_node(c, name.to_string(), terrain)
        }
        // no triangle: a node with no mesh
        None => b.root.push(gj::Node {
            name: Some(name.to_string()),
            ..Default::default()
        }),
    };
    b.finish("tile", node, extras, out)
}

/// A slice of vertex or index data, as it goes into the BIN chunk.
#[derive(Clone, Copy)]
enum Data<'a> {
    /// `VEC3` of `f32` (positions, normals).
    Vec3(&'a [[f32; 3]]),
    /// `VEC4` of `u8` (colours).
    Rgba(&'a [[u8; 4]]),
    /// `SCALAR` `f32` (heights, water depths).
    Float(&'a [f32]),
    /// `SCALAR` `u8` stored as `f32` (material ids).
    ByteAsFloat(&'a [u8]),
    /// `SCALAR` `u32` (indices).
    Index(&'a [u32]),
}

impl Data<'_> {
    fn count(&self) -> usize {
        match self {
            Data::Vec3(d) => d.len(),
            Data::Rgba(d) => d.len(),
            Data::Float(d) => d.len(),
            Data::ByteAsFloat(d) => d.len(),
            Data::Index(d) => d.len(),
        }
    }

    fn element_size(&self) -> u64 {
        match self {
            Data::Vec3(_) => 12,
            _ => 4,
        }
    }

    fn byte_len(&self) -> u64 {
        self.count() as u64 * self.element_size()
    }

    fn accessor_type(&self) -> (ComponentType, Type, bool) {
        match self {
            Data::Vec3(_) => (ComponentType::F32, Type::Vec3, false),
            Data::Rgba(_) => (ComponentType::U8, Type::Vec4, true),
            Data::Float(_) | Data::ByteAsFloat(_) => (ComponentType::F32, Type::Scalar, false),
            Data::Index(_) => (ComponentType::U32, Type::Scalar, false),
        }
    }

    /// Streams the data little-endian through a small buffer.
    fn write_to<W: Write>(&self, out: &mut W, buf: &mut Vec<u8>) -> std::io::Result<()> {
        const BATCH: usize = 4096;
        fn batches<T, W: Write>(
            d: &[T],
            out: &mut W,
            buf: &mut Vec<u8>,
            mut put: impl FnMut(&T, &mut Vec<u8>),
        ) -> std::io::Result<()> {
            for part in d.chunks(BATCH) {
                buf.clear();
                for x in part {
                    put(x, buf);
                }
                out.write_all(buf)?;
            }
            Ok(())
        }
        match *self {
            Data::Vec3(d) => batches(d, out, buf, |v, b| {
                v.iter().for_each(|c| b.extend_from_slice(&c.to_le_bytes()))
            }),
            Data::Rgba(d) => batches(d, out, buf, |v, b| b.extend_from_slice(v)),
            Data::Float(d) => batches(d, out, buf, |v, b| b.extend_from_slice(&v.to_le_bytes())),
            Data::ByteAsFloat(d) => batches(d, out, buf, |v, b| b.extend_from_slice(&f32::from(*v).to_le_bytes())),
            Data::Index(d) => batches(d, out, buf, |v, b| b.extend_from_slice(&v.to_le_bytes())),
        }
    }
}

/// The glTF document under construction, with the BIN chunk's layout.
struct Builder<'a> {
    root: gj::Root,
    /// Each buffer view's data and byte offset, in offset order.
    blobs: Vec<(u64, Data<'a>)>,
    /// Bytes of BIN data so far.
    len: u64,
    /// Node translations to write as `f64` after serialisation (node index, translation).
    translations: Vec<(usize, DVec3)>,
}

fn align4(x: u64) -> u64 {
    x.div_ceil(4) * 4
}

impl Builder<'_> {
    /// An empty glTF 2.0 document written by `generator`.
    fn new(generator: &str) -> Self {
        Builder {
            root: gj::Root {
                asset: gj::Asset {
                    version: "2.0".to_string(),
                    generator: Some(generator.to_string()),
                    ..Default::default()
                },
                ..Default::default()
            },
            blobs: Vec::new(),
            len: 0,
            translations: Vec::new(),
        }
    }
}

impl<'a> Builder<'a> {
    /// Adds a buffer view and an accessor over `data`; `bounds` go into the accessor's min/max.
    fn accessor(&mut self, data: Data<'a>, target: Target, bounds: Option<(Value, Value)>) -> Index<gj::Accessor> {
        let offset = align4(self.len);
        let view = self.root.push(gj::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64(data.byte_len()),
            byte_offset: Some(USize64(offset)),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: Default::default(),
        });
        self.blobs.push((offset, data));
        self.len = offset + data.byte_len();
        let (component, type_, normalized) = data.accessor_type();
        let (min, max) = bounds.unzip();
        self.root.push(gj::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(data.count() as u64),
            component_type: Valid(GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// Adds a one-primitive triangle mesh with the given attributes.
    fn mesh(
        &mut self,
        name: &str,
        attributes: BTreeMap<gj::validation::Checked<Semantic>, Index<gj::Accessor>>,
        indices: Index<gj::Accessor>,
        material: Index<gj::Material>,
    ) -> Index<gj::Mesh> {
        self.root.push(gj::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.to_string()),
            primitives: vec![gj::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Valid(Mode::Triangles),
                targets: None,
            }],
            weights: None,
        })
    }

    /// Adds a node holding `mesh`, translated by `translation` (written as `f64`).
    fn node(&mut self, name: String, mesh: Index<gj::Mesh>, translation: DVec3) -> Index<gj::Node> {
        let node = self.root.push(gj::Node {
            name: Some(name),
            mesh: Some(mesh),
            ..Default::default()
        });
        self.translations.push((node.value(), translation));
        node
    }
}

impl<'a> Builder<'a> {
    /// A chunk's mesh under a node translated to its origin, its attributes as version 1 lays
    /// them out.
    fn chunk_node(&mut self, c: &Checked<'a>, name: String, terrain: Index<gj::Material>) -> Index<gj::Node> {
        let m = c.mesh;
        let mut attrs = BTreeMap::new();
        attrs.insert(
            Valid(Semantic::Positions),
            self.accessor(
                Data::Vec3(&m.positions),
                Target::ArrayBuffer,
                Some(bounds(&m.positions)),
            ),
        );
        attrs.insert(
            Valid(Semantic::Normals),
            self.accessor(Data::Vec3(&m.normals), Target::ArrayBuffer, None),
        );
        if c.attributes {
            attrs.insert(
                Valid(Semantic::Colors(0)),
                self.accessor(Data::Rgba(&m.colors), Target::ArrayBuffer, None),
            );
            let extra = [
                ("HEIGHT", Data::Float(&m.heights)),
                ("WATER_DEPTH", Data::Float(&m.water_depths)),
                ("MATERIAL", Data::ByteAsFloat(&m.materials)),
            ];
            for (sem, data) in extra {
                attrs.insert(
                    Valid(Semantic::Extras(sem.to_string())),
                    self.accessor(data, Target::ArrayBuffer, None),
                );
            }
        }
        let indices = self.accessor(Data::Index(&m.indices), Target::ElementArrayBuffer, None);
        let mesh = self.mesh(&name, attrs, indices, terrain);
        self.node(name, mesh, m.origin)
    }
}

impl Builder<'_> {
    /// Adds the scene over `root`, the buffer, and writes the GLB container: header, JSON chunk
    /// (with `extras` as the asset's extras and the nodes' translations as `f64`), BIN chunk.
    /// Returns the bytes written.
    fn finish<W: Write>(
        mut self,
        scene: &str,
        root: Index<gj::Node>,
        extras: Value,
        out: W,
    ) -> Result<u64, ExportError> {
        let scene = self.root.push(gj::Scene {
            extensions: None,
            extras: Default::default(),
            name: Some(scene.to_string()),
            nodes: vec![root],
        });
        self.root.scene = Some(scene);
        if self.len > 0 {
            self.root.push(gj::Buffer {
                byte_length: USize64(self.len),
                name: None,
                uri: None,
                extensions: None,
                extras: Default::default(),
            });
        }

        // gltf-json stores translations as f32; write the f64 values into the JSON directly.
        let mut value = self.root.to_value()?;
        for &(node, t) in &self.translations {
            value["nodes"][node]["translation"] = json!([t.x, t.y, t.z]);
        }
        value["asset"]["extras"] = extras;
        let mut json = serde_json::to_vec(&value)?;
        json.resize(align4(json.len() as u64) as usize, b' ');

        let bin_len = align4(self.len);
        let total = 12 + 8 + json.len() as u64 + if bin_len > 0 { 8 + bin_len } else { 0 };
        let total = u32::try_from(total)
            .map_err(|_| ExportError::TooLarge(format!("{total} bytes, more than a GLB file can hold (4 GiB)")))?;

        let mut out = Counting::new(out);
        out.write_all(MAGIC)?;
        out.write_all(&VERSION.to_le_bytes())?;
        out.write_all(&total.to_le_bytes())?;
        out.write_all(&(json.len() as u32).to_le_bytes())?;
        out.write_all(&CHUNK_JSON.to_le_bytes())?;
        out.write_all(&json)?;
        if bin_len > 0 {
            out.write_all(&(bin_len as u32).to_le_bytes())?;
            out.write_all(&CHUNK_BIN.to_le_bytes())?;
            let mut at = 0u64;
            let mut buf = Vec::with_capacity(4096 * 12);
            for (offset, data) in &self.blobs {
                out.write_all(&[0u8; 4][..(offset - at) as usize])?;
                data.write_to(&mut out, &mut buf)?;
                at = offset + data.byte_len();
            }
            out.write_all(&[0u8; 4][..(bin_len - at) as usize])?;
        }
        out.flush()?;
        Ok(out.bytes())
    }
}

/// Per-component min and max of positions, as JSON arrays (exact `f32` values).
fn bounds(p: &[[f32; 3]]) -> (Value, Value) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for v in p {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let arr = |a: [f32; 3]| json!([f64::from(a[0]), f64::from(a[1]), f64::from(a[2])]);
    (arr(lo), arr(hi))
}

fn material(name: &str, color: [f32; 4], roughness: f32, blend: bool) -> gj::Material {
    gj::Material {
        name: Some(name.to_string()),
        alpha_mode: Valid(if blend {
            gj::material::AlphaMode::Blend
        } else {
            gj::material::AlphaMode::Opaque
        }),
        double_sided: false,
        pbr_metallic_roughness: gj::material::PbrMetallicRoughness {
            base_color_factor: gj::material::PbrBaseColorFactor(color),
            metallic_factor: gj::material::StrengthFactor(0.0),
            roughness_factor: gj::material::StrengthFactor(roughness),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Upper bound of the BIN chunk size, checked before building anything.
fn bin_size(meshes: &[Checked<'_>], sea: &[SeaFace]) -> u64 {
    let chunks: u64 = meshes
        .iter()
        .map(|c| {
            let n = c.mesh.positions.len() as u64;
            let attr = if c.attributes { 16 * n } else { 0 };
            24 * n + attr + 4 * c.mesh.indices.len() as u64
        })
        .sum();
    let sea: u64 = sea
        .iter()
        .map(|f| 24 * f.positions.len() as u64 + 4 * f.indices.len() as u64)
        .sum();
    chunks + sea
}

/// Writes the GLB and returns what it wrote.
pub(crate) fn write<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<ExportStats, ExportError> {
    meta.check()?;
    let checked = check_meshes(meshes)?;
    let sea = meta.sea_radius.map(|r| sea_faces(r, SEA_QUADS)).unwrap_or_default();
    // Every accessor holds at least 4 bytes, so this also keeps object counts far below u32::MAX.
    let bound = bin_size(&checked, &sea);
    if bound > u64::from(u32::MAX) {
        return Err(ExportError::TooLarge(format!(
            "{bound} bytes of vertex data, more than a GLB file can hold (4 GiB)"
        )));
    }

    let mut b = Builder::new(&meta.generator);
    let planet = b.root.push(gj::Node {
        name: Some("planet".to_string()),
        ..Default::default()
    });
    let mut children = Vec::new();

    if !checked.is_empty() {
        let terrain = b.root.push(material("terrain", [1.0; 4], 0.9, false));
        for c in &checked {
            let name = node_name(c.index, c.mesh);
            children.push(b.chunk_node(c, name, terrain));
        }
    }

    if !sea.is_empty() {
        let water = b.root.push(material("sea", [0.02, 0.18, 0.45, 0.6], 0.1, true));
        let mut faces = Vec::new();
        for f in &sea {
            let name = format!("sea/{}", f.face);
            let mut attrs = BTreeMap::new();
            attrs.insert(
                Valid(Semantic::Positions),
                b.accessor(
                    Data::Vec3(&f.positions),
                    Target::ArrayBuffer,
                    Some(bounds(&f.positions)),
                ),
            );
            attrs.insert(
                Valid(Semantic::Normals),
                b.accessor(Data::Vec3(&f.normals), Target::ArrayBuffer, None),
            );
            let indices = b.accessor(Data::Index(&f.indices), Target::ElementArrayBuffer, None);
            let mesh = b.mesh(&name, attrs, indices, water);
            faces.push(b.node(name, mesh, f.centre));
        }
        children.push(b.root.push(gj::Node {
            name: Some("sea".to_string()),
            children: Some(faces),
            ..Default::default()
        }));
    }

    if !children.is_empty() {
        b.root.nodes[planet.value()].children = Some(children);
    }
    let bytes = b.finish("planet", planet, meta.to_json("pmc-glb"), out)?;
    Ok(ExportStats {
        bytes,
        vertices: checked.iter().map(|c| c.mesh.positions.len() as u64).sum(),
        triangles: checked.iter().map(|c| c.mesh.indices.len() as u64 / 3).sum(),
        meshes: checked.len(),
    })
}
