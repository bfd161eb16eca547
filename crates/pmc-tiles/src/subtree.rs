//! The binary subtree file of 3D Tiles 1.1 implicit tiling (`.subtree`), as this crate writes
//! and reads it.
//!
//! Layout: a 24-byte header (magic `subt`, version 1, the JSON's and the binary part's lengths as
//! `u64`), the JSON padded with spaces to 8 bytes, the binary part padded with zeros to 8 bytes.
//! Bitstreams are little-endian in bit order (tile `n` is bit `n % 8` of byte `n / 8`), tiles in
//! level order and Morton order within a level; buffer views start on 8-byte boundaries.

use serde_json::{json, Value};

/// The magic of a subtree file.
pub const MAGIC: &[u8; 4] = b"subt";

/// A bitstream of availability, or a constant when every bit is equal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bits {
    bytes: Vec<u8>,
    len: usize,
}

impl Bits {
    /// `len` zero bits.
    pub fn zeros(len: usize) -> Bits {
        Bits {
            bytes: vec![0; len.div_ceil(8)],
            len,
        }
    }

    /// Sets bit `n`.
    pub fn set(&mut self, n: usize) {
        self.bytes[n / 8] |= 1 << (n % 8);
    }

    /// Bit `n`.
    pub fn get(&self, n: usize) -> bool {
        n < self.len && self.bytes[n / 8] >> (n % 8) & 1 == 1
    }

    /// How many bits are set.
    pub fn count(&self) -> usize {
        self.bytes.iter().map(|b| b.count_ones() as usize).sum()
    }

    /// The number of bits.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the stream has no bit.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `Some(value)` when every bit is `value`.
    fn constant(&self) -> Option<bool> {
        match self.count() {
            0 => Some(false),
            n if n == self.len => Some(true),
            _ => None,
        }
    }
}

/// A subtree's availability and tile metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct Subtree {
    /// Tile availability, one bit per tile of the subtree's levels.
    pub tiles: Bits,
    /// Content availability, one bit per tile.
    pub content: Bits,
    /// Child subtree availability, one bit per tile of the level below the subtree.
    pub children: Bits,
    /// Per available tile, in tile order: its bounding sphere (ECEF centre and radius, metres).
    pub spheres: Vec<[f64; 4]>,
    /// Per available tile, in tile order: its geometric error (metres).
    pub errors: Vec<f64>,
}

/// One piece of the binary part: its bytes, and the buffer view's index once placed.
struct Binary {
    data: Vec<u8>,
    views: Vec<Value>,
}

impl Binary {
    fn view(&mut self, bytes: &[u8]) -> usize {
        let offset = self.data.len();
        self.data.extend_from_slice(bytes);
        self.data.resize(self.data.len().div_ceil(8) * 8, 0);
        self.views
            .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
        self.views.len() - 1
    }

    /// An availability object: a constant, or a bitstream with its count.
    fn availability(&mut self, bits: &Bits) -> Value {
        match bits.constant() {
            Some(c) => json!({"constant": u8::from(c)}),
            None => {
                let v = self.view(&bits.bytes);
                json!({"bitstream": v, "availableCount": bits.count()})
            }
        }
    }
}

impl Subtree {
    /// The subtree file's bytes. The property table `tile` (class `tile` of the tileset's
    /// schema) holds `boundingSphere` and `geometricError` of each available tile.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bin = Binary {
            data: Vec::new(),
            views: Vec::new(),
        };
        let tiles = bin.availability(&self.tiles);
        let content = bin.availability(&self.content);
        let children = bin.availability(&self.children);
        let mut doc = json!({
            "tileAvailability": tiles,
            "contentAvailability": [content],
            "childSubtreeAvailability": children,
        });
        if !self.spheres.is_empty() {
            let spheres: Vec<u8> = self.spheres.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
            let errors: Vec<u8> = self.errors.iter().flat_map(|x| x.to_le_bytes()).collect();
            let (s, e) = (bin.view(&spheres), bin.view(&errors));
            doc["propertyTables"] = json!([{
                "class": "tile",
                "count": self.spheres.len(),
                "properties": {
                    "boundingSphere": {"values": s},
                    "geometricError": {"values": e},
                }
            }]);
            doc["tileMetadata"] = json!(0);
        }
        if !bin.data.is_empty() {
            doc["buffers"] = json!([{"byteLength": bin.data.len()}]);
            doc["bufferViews"] = Value::Array(bin.views);
        }
        let mut json = serde_json::to_vec(&doc).expect("a JSON value serialises");
        json.resize(json.len().div_ceil(8) * 8, b' ');
        let mut out = Vec::with_capacity(24 + json.len() + bin.data.len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&1u32.to_le_bytes());
        out.extend_from_slice(&(json.len() as u64).to_le_bytes());
        out.extend_from_slice(&(bin.data.len() as u64).to_le_bytes());
        out.extend_from_slice(&json);
        out.extend_from_slice(&bin.data);
        out
    }

    /// Reads a subtree file written by [`Subtree::to_bytes`] back, given the number of tiles and
    /// of child subtrees its levels hold. Refuses anything else with a message saying what is
    /// wrong.
    pub fn from_bytes(bytes: &[u8], tile_count: usize, child_count: usize) -> Result<Subtree, String> {
        if bytes.len() < 24 || &bytes[..4] != MAGIC {
            return Err("not a subtree file (no `subt` magic)".into());
        }
        let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
        let version = u32::from_le_bytes(bytes[4..8].try_into().expect("4 bytes"));
        if version != 1 {
            return Err(format!("subtree version {version}; only version 1 is read"));
        }
        let (json_len, bin_len) = (word(8), word(16));
        let end = 24u64
            .checked_add(json_len)
            .and_then(|x| x.checked_add(bin_len))
            .filter(|e| *e == bytes.len() as u64)
            .ok_or("the header's lengths do not match the file's")?;
        let json_end = 24 + json_len as usize;
        let doc: Value = serde_json::from_slice(&bytes[24..json_end]).map_err(|e| format!("its JSON: {e}"))?;
        let bin = &bytes[json_end..end as usize];
        let view = |v: &Value| -> Result<&[u8], String> {
            let i = v.as_u64().ok_or("a buffer view index is not a number")? as usize;
            let bv = &doc["bufferViews"][i];
            let (o, l) = (
                bv["byteOffset"].as_u64().unwrap_or(0) as usize,
                bv["byteLength"].as_u64().ok_or("a buffer view has no length")? as usize,
            );
            bin.get(o..o + l)
                .ok_or_else(|| format!("buffer view {i} lies past the binary part"))
        };
        let bits = |v: &Value, len: usize| -> Result<Bits, String> {
            if let Some(c) = v.get("constant") {
                let mut b = Bits::zeros(len);
                if c.as_u64() == Some(1) {
                    (0..len).for_each(|n| b.set(n));
                }
                return Ok(b);
            }
            let data = view(&v["bitstream"])?;
            if data.len() != len.div_ceil(8) {
                return Err(format!("a bitstream of {} bytes for {len} bits", data.len()));
            }
            Ok(Bits {
                bytes: data.to_vec(),
                len,
            })
        };
        let tiles = bits(&doc["tileAvailability"], tile_count)?;
        let content = bits(&doc["contentAvailability"][0], tile_count)?;
        let children = bits(&doc["childSubtreeAvailability"], child_count)?;
        let (mut spheres, mut errors) = (Vec::new(), Vec::new());
        if let Some(table) = doc.get("propertyTables").and_then(|t| t.get(0)) {
            let count = table["count"].as_u64().ok_or("the property table has no count")? as usize;
            let f64s = |v: &Value| -> Result<Vec<f64>, String> {
                Ok(view(v)?
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                    .collect())
            };
            let s = f64s(&table["properties"]["boundingSphere"]["values"])?;
            let e = f64s(&table["properties"]["geometricError"]["values"])?;
            if s.len() != 4 * count || e.len() != count {
                return Err("the property table's values do not match its count".into());
            }
            spheres = s.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
            errors = e;
        }
        Ok(Subtree {
            tiles,
            content,
            children,
            spheres,
            errors,
        })
    }
}
