//! The `.pmcimg` imagery file, version 1 (`docs/specs/pmcimg-v1.md`): a checksummed header and
//! the RGB pixels, row by row from the north.

use crate::imagery::{check_size, content_digest, FORMAT_RGB8};
use crate::{Extent, Imagery, ImageryError};
use std::io::{Read, Write};
use std::path::Path;

/// The first eight bytes of every `.pmcimg` file.
pub const MAGIC: [u8; 8] = *b"\x89PMCIMG\n";
/// The format version this crate writes and reads.
pub const VERSION: u32 = 1;
/// Bytes of the header; the pixels follow it.
pub const HEADER_LEN: usize = 160;

/// Where the header's checksum lies (it covers the bytes before it).
const HEADER_CRC_AT: usize = 156;

fn le_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn le_u64(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

fn le_f64(b: &[u8], at: usize) -> f64 {
    f64::from_bits(le_u64(b, at))
}

/// The header of `img`.
fn header(img: &Imagery) -> [u8; HEADER_LEN] {
    let mut h = [0u8; HEADER_LEN];
    h[0..8].copy_from_slice(&MAGIC);
    h[8..12].copy_from_slice(&VERSION.to_le_bytes());
    h[12..16].copy_from_slice(&(HEADER_LEN as u32).to_le_bytes());
    h[16..20].copy_from_slice(&img.width().to_le_bytes());
    h[20..24].copy_from_slice(&img.height().to_le_bytes());
    h[24] = FORMAT_RGB8;
    for (i, v) in img.extent().to_array().iter().enumerate() {
        h[32 + 8 * i..40 + 8 * i].copy_from_slice(&v.to_le_bytes());
    }
    let len = HEADER_LEN as u64 + img.pixels().len() as u64;
    h[64..72].copy_from_slice(&len.to_le_bytes());
    h[72..76].copy_from_slice(&crc32fast::hash(img.pixels()).to_le_bytes());
    h[80..144].copy_from_slice(img.digest().as_bytes());
    let crc = crc32fast::hash(&h[..HEADER_CRC_AT]);
    h[HEADER_CRC_AT..].copy_from_slice(&crc.to_le_bytes());
    h
}

/// What a file starting with `head` appears to be.
pub(crate) fn looks_like(head: &[u8]) -> String {
    if head.is_empty() {
        "the file is empty (0 bytes)".to_owned()
    } else if head.starts_with(b"\x89PMCDEM") {
        "it is a .pmcdem elevation file (give it as the elevation model, not as imagery)".to_owned()
    } else if head.starts_with(b"\xff\xd8\xff") {
        "it is a JPEG image: import it first with `pmc imagery import`".to_owned()
    } else if head.starts_with(b"\x89PNG") {
        "it is a PNG image: import it first with `pmc imagery import`".to_owned()
    } else if head.starts_with(b"II*\0") || head.starts_with(b"MM\0*") {
        "it is a TIFF image: import it first with `pmc imagery import`".to_owned()
    } else if head.starts_with(b"CDF\x01") || head.starts_with(b"CDF\x02") {
        "it is a netCDF file (an elevation model? import it with `pmc dem import`)".to_owned()
    } else {
        format!("it starts with \"{}\"", head[..head.len().min(8)].escape_ascii())
    }
}

impl Imagery {
    /// Writes the imagery to `path` as a `.pmcimg` file, through a temporary file next to it
    /// renamed into place, so that `path` never holds a half-written file.
    ///
    /// Errors: [`ImageryError::Write`].
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), ImageryError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let err = |source| ImageryError::Write {
            file: file.clone(),
            source,
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
        let written = (|| {
            let mut out = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
            out.write_all(&header(self))?;
            out.write_all(self.pixels())?;
            out.into_inner().map_err(|e| e.into_error())?.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            return Err(err(e));
        }
        Ok(())
    }

    /// The `.pmcimg` file's bytes (what [`write`](Self::write) writes).
    pub fn to_pmcimg_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_LEN + self.pixels().len());
        out.extend_from_slice(&header(self));
        out.extend_from_slice(self.pixels());
        out
    }

    /// Reads the `.pmcimg` file at `path`, checking its header, its length, the pixels'
    /// checksum and the content digest before returning it.
    ///
    /// Errors, each naming `path` as displayed: [`ImageryError::Io`],
    /// [`ImageryError::NotImagery`], [`ImageryError::UnsupportedVersion`],
    /// [`ImageryError::Damaged`] (a checksum, the digest, a field or the length),
    /// [`ImageryError::TooLarge`].
    pub fn open(path: impl AsRef<Path>) -> Result<Imagery, ImageryError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let io = |source| ImageryError::Io {
            file: file.clone(),
            source,
        };
        let mut f = std::fs::File::open(path).map_err(io)?;
        let len = f.metadata().map_err(io)?.len();
        let mut head = Vec::with_capacity(HEADER_LEN);
        (&mut f).take(HEADER_LEN as u64).read_to_end(&mut head).map_err(io)?;
        let h = Header::parse(&file, &head, len)?;
        let mut pixels = vec![0u8; h.pixel_bytes()];
        f.read_exact(&mut pixels).map_err(io)?;
        h.finish(&file, pixels)
    }

    /// As [`open`](Self::open), for a file held in memory; `name` stands for the file in errors.
    pub fn from_pmcimg_bytes(name: &str, bytes: &[u8]) -> Result<Imagery, ImageryError> {
        let h = Header::parse(name, &bytes[..bytes.len().min(HEADER_LEN)], bytes.len() as u64)?;
        h.finish(name, bytes[HEADER_LEN..].to_vec())
    }
}

/// A header read and checked against the file's length.
struct Header {
    width: u32,
    height: u32,
    extent: Extent,
    pixel_crc: u32,
    digest: String,
}

impl Header {
    /// Checks the first bytes of a file of `len` bytes (`head`: up to [`HEADER_LEN`] of them).
    fn parse(file: &str, head: &[u8], len: u64) -> Result<Header, ImageryError> {
        let damaged = |detail: String| ImageryError::Damaged {
            file: file.to_owned(),
            detail,
        };
        if !head.starts_with(&MAGIC) {
            if !head.is_empty() && MAGIC.starts_with(head) {
                return Err(damaged(format!(
                    "it holds {len} bytes, fewer than the {HEADER_LEN} of a header"
                )));
            }
            return Err(ImageryError::NotImagery {
                file: file.to_owned(),
                detail: format!("{}; a .pmcimg file starts with \"\\x89PMCIMG\\n\"", looks_like(head)),
            });
        }
        if head.len() < 16 {
            return Err(damaged(format!(
                "it holds {len} bytes, fewer than the {HEADER_LEN} of a header"
            )));
        }
        let version = le_u32(head, 8);
        if version != VERSION {
            return Err(ImageryError::UnsupportedVersion {
                file: file.to_owned(),
                version,
            });
        }
        if head.len() < HEADER_LEN {
            return Err(damaged(format!(
                "it holds {len} bytes, fewer than the {HEADER_LEN} of a header"
            )));
        }
        let crc = crc32fast::hash(&head[..HEADER_CRC_AT]);
        let stored = le_u32(head, HEADER_CRC_AT);
        if crc != stored {
            return Err(damaged(format!(
                "the header's checksum is {stored:08x} but its bytes give {crc:08x}"
            )));
        }
        let header_len = le_u32(head, 12);
        if header_len as usize != HEADER_LEN {
            return Err(damaged(format!("the header length is {header_len}, not {HEADER_LEN}")));
        }
        let (width, height) = (le_u32(head, 16), le_u32(head, 20));
        if head[24] != FORMAT_RGB8 {
            return Err(damaged(format!(
                "the pixel format is {}, not {FORMAT_RGB8} (8-bit RGB)",
                head[24]
            )));
        }
        check_size(file, u64::from(width), u64::from(height)).map_err(|e| match e {
            ImageryError::Corrupt { detail, .. } => damaged(detail),
            e => e,
        })?;
        // West, east, south, north.
        let extent = Extent::new(le_f64(head, 32), le_f64(head, 48), le_f64(head, 40), le_f64(head, 56))
            .map_err(|e| damaged(format!("its extent is unusable: {e}")))?;
        let expected = HEADER_LEN as u64 + u64::from(width) * u64::from(height) * 3;
        let recorded = le_u64(head, 64);
        if recorded != expected {
            return Err(damaged(format!(
                "the header records a length of {recorded} bytes where {width} x {height} pixels need {expected}"
            )));
        }
        if len != expected {
            return Err(damaged(format!(
                "it holds {len} bytes where its header needs {expected} (cut short or with bytes appended)"
            )));
        }
        let digest = std::str::from_utf8(&head[80..144])
            .ok()
            .filter(|d| d.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)))
            .ok_or_else(|| damaged("the digest is not 64 lower-case hexadecimal digits".to_owned()))?
            .to_owned();
        Ok(Header {
            width,
            height,
            extent,
            pixel_crc: le_u32(head, 72),
            digest,
        })
    }

    fn pixel_bytes(&self) -> usize {
        self.width as usize * self.height as usize * 3
    }

    /// Checks the pixels' checksum and the digest.
    fn finish(self, file: &str, pixels: Vec<u8>) -> Result<Imagery, ImageryError> {
        let damaged = |detail: String| ImageryError::Damaged {
            file: file.to_owned(),
            detail,
        };
        let crc = crc32fast::hash(&pixels);
        if crc != self.pixel_crc {
            return Err(damaged(format!(
                "the pixels' checksum is {crc:08x} but the header records {:08x}",
                self.pixel_crc
            )));
        }
        let digest = content_digest(self.width, self.height, &self.extent, &pixels);
        if digest != self.digest {
            return Err(damaged(format!(
                "the content digest is {digest} but the header records {}",
                self.digest
            )));
        }
        Ok(Imagery::from_parts(
            self.width,
            self.height,
            self.extent,
            pixels,
            digest,
        ))
    }
}
