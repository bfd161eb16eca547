//! A bounds check of a netCDF classic header, made before the `netcdf3` crate parses it.
//!
//! The `netcdf3` crate trusts the counts in a header: it reserves memory for as many list entries
//! as the header announces, and computes record sizes with unchecked arithmetic. A damaged header
//! could then exhaust memory or panic. This pass walks the same grammar (the netCDF classic and
//! 64-bit offset formats, CDF-1 and CDF-2) without building anything, and checks that every count
//! fits in the file, that every size fits in 64 bits, and that every data offset is sane. It also
//! returns where each variable's data lie, so that a truncated file is refused before any data
//! are read. Decoding the header (names, attributes, the data set) is left to `netcdf3`.

/// Where one variable's data lie in the file.
#[derive(Debug, Clone)]
pub(crate) struct VarExtent {
    /// The variable's name, as in the header.
    pub name: String,
    /// Offset of its first byte.
    pub begin: u64,
    /// Bytes of one record's chunk (a record variable) or of the whole variable, without padding.
    pub chunk_bytes: u64,
    /// Whether the variable's first dimension is the record (unlimited) dimension.
    pub is_record: bool,
}

/// What the bounds check learnt from a header that passed it.
#[derive(Debug, Clone)]
pub(crate) struct HeaderInfo {
    /// Number of records; `None` when the header leaves it to be computed from the file size.
    pub numrecs: Option<u64>,
    /// Bytes from one record to the next (the padded chunks of all record variables).
    pub record_size: u64,
    /// Every variable, in header order.
    pub vars: Vec<VarExtent>,
}

impl HeaderInfo {
    /// The offset just past the data of `var`, or `None` if it would not fit in 64 bits.
    pub fn data_end(&self, var: &VarExtent, file_len: u64) -> Option<u64> {
        if !var.is_record {
            return var.begin.checked_add(var.chunk_bytes);
        }
        let numrecs = match self.numrecs {
            Some(n) => n,
            // Computed by the reader from the file size: whatever fits.
            None => file_len
                .saturating_sub(var.begin)
                .checked_div(self.record_size)
                .unwrap_or(0),
        };
        if numrecs == 0 || var.chunk_bytes == 0 {
            return Some(var.begin);
        }
        (numrecs - 1)
            .checked_mul(self.record_size)?
            .checked_add(var.begin)?
            .checked_add(var.chunk_bytes)
    }

    /// The extent of the variable named `name`.
    pub fn var(&self, name: &str) -> Option<&VarExtent> {
        self.vars.iter().find(|v| v.name == name)
    }
}

/// Why a header did not pass.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum HeaderProblem {
    /// Not a netCDF classic file; says what it is instead.
    NotNetcdf(String),
    /// The header runs past the end of the file, or announces more than the file can hold.
    Truncated {
        /// The smallest file size the header requires.
        needed: u64,
    },
    /// The header is damaged.
    Corrupt(String),
    /// The header is longer than [`MAX_HEADER_BYTES`] (it holds at least this many bytes).
    TooLarge {
        /// Bytes of header seen so far.
        at_least: u64,
    },
    /// The bytes given end before the header does, but the file is longer: call again with more.
    NeedMore,
}

/// The longest header accepted, in bytes. Headers are normally a few kilobytes; the `netcdf3`
/// crate parses them in time quadratic in their length (about 1.5 s for 1 MiB).
pub const MAX_HEADER_BYTES: u64 = 1 << 20;

const TAG_DIMENSION: u32 = 0x0A;
const TAG_VARIABLE: u32 = 0x0B;
const TAG_ATTRIBUTE: u32 = 0x0C;
/// `numrecs` value meaning "computed from the file size" (streaming).
const STREAMING: u32 = u32::MAX;

/// Fewest header bytes one entry of each list takes, to bound counts by the file size.
const MIN_DIM_BYTES: u64 = 8;
const MIN_ATTR_BYTES: u64 = 12;
const MIN_VAR_BYTES: u64 = 24;

/// Checks the header at the start of `prefix`, the first bytes of a file of `file_len` bytes.
pub(crate) fn check(prefix: &[u8], file_len: u64) -> Result<HeaderInfo, HeaderProblem> {
    signature(prefix, file_len)?;
    let mut w = Walker {
        buf: prefix,
        pos: 4,
        file_len,
    };
    let offset_bytes = if prefix[3] == 1 { 4 } else { 8 };

    let numrecs = match w.u32()? {
        STREAMING => None,
        n if n > i32::MAX as u32 => return Err(corrupt(format!("the number of records is negative ({})", n as i32))),
        n => Some(u64::from(n)),
    };

    // Dimensions: (size, is the record dimension).
    let mut dims: Vec<(u64, bool)> = Vec::new();
    let n = w.list(TAG_DIMENSION, "dimensions", MIN_DIM_BYTES)?;
    for _ in 0..n {
        w.name("a dimension name")?;
        let size = w.non_negative("a dimension size")?;
        dims.push((size, size == 0));
    }
    if dims.iter().filter(|d| d.1).count() > 1 {
        return Err(corrupt("more than one dimension is unlimited".to_owned()));
    }

    w.attributes()?;

    let mut vars = Vec::new();
    let n = w.list(TAG_VARIABLE, "variables", MIN_VAR_BYTES)?;
    for _ in 0..n {
        let name = w.name("a variable name")?;
        let ndims = w.non_negative("a number of dimensions")?;
        w.fits(ndims, 4)?;
        let mut elements: u64 = 1;
        let mut is_record = false;
        for i in 0..ndims {
            let id = w.non_negative("a dimension id")?;
            let (size, unlimited) = *usize::try_from(id).ok().and_then(|id| dims.get(id)).ok_or_else(|| {
                corrupt(format!(
                    "variable {name:?} uses dimension id {id}, but only {} are defined",
                    dims.len()
                ))
            })?;
            if unlimited {
                if i != 0 {
                    return Err(corrupt(format!(
                        "variable {name:?} uses the unlimited dimension other than first"
                    )));
                }
                is_record = true;
            } else {
                elements = elements
                    .checked_mul(size)
                    .ok_or_else(|| corrupt(format!("variable {name:?} declares more than 2^64 values")))?;
            }
        }
        w.attributes()?;
        let type_size = w.data_type()?;
        let _vsize = w.u32()?; // recomputed from the dimensions, as readers do
        let begin = if offset_bytes == 4 {
            i64::from(w.u32()? as i32)
        } else {
            let hi = u64::from(w.u32()?);
            let lo = u64::from(w.u32()?);
            ((hi << 32) | lo) as i64
        };
        let begin = u64::try_from(begin).map_err(|_| {
            corrupt(format!(
                "the data of variable {name:?} start at a negative offset ({begin})"
            ))
        })?;
        let chunk_bytes = elements
            .checked_mul(type_size)
            .ok_or_else(|| corrupt(format!("variable {name:?} declares more than 2^64 bytes")))?;
        vars.push(VarExtent {
            name,
            begin,
            chunk_bytes,
            is_record,
        });
    }
    let header_len = w.pos as u64;

    let mut record_size: u64 = 0;
    for v in &vars {
        if v.begin < header_len {
            return Err(corrupt(format!(
                "the data of variable {:?} start at byte {}, inside the header ({header_len} bytes)",
                v.name, v.begin
            )));
        }
        if v.is_record {
            record_size = v
                .chunk_bytes
                .checked_add(padding(v.chunk_bytes))
                .and_then(|c| record_size.checked_add(c))
                .ok_or_else(|| corrupt("the record size exceeds 2^64 bytes".to_owned()))?;
            if numrecs.is_none() && v.begin > file_len {
                // The reader computes the number of records from the file size and this offset.
                return Err(HeaderProblem::Truncated { needed: v.begin });
            }
        }
    }
    if record_size > file_len && numrecs.is_none_or(|n| n > 0) {
        // One record must fit in the file whenever there is one (and the reader subtracts it).
        return Err(HeaderProblem::Truncated {
            needed: header_len.saturating_add(record_size),
        });
    }
    Ok(HeaderInfo {
        numrecs,
        record_size,
        vars,
    })
}

/// Checks the first four bytes: `CDF` and version 1 or 2.
fn signature(prefix: &[u8], file_len: u64) -> Result<(), HeaderProblem> {
    const HDF5: &[u8] = b"\x89HDF\r\n\x1a\n";
    if file_len == 0 {
        return Err(HeaderProblem::NotNetcdf("the file is empty (0 bytes)".to_owned()));
    }
    if (prefix.len() as u64) < file_len.min(8) {
        return Err(HeaderProblem::NeedMore);
    }
    let head = &prefix[..prefix.len().min(8)];
    if head.starts_with(HDF5) {
        return Err(HeaderProblem::NotNetcdf(
            "it is an HDF5 file (netCDF-4, perhaps); convert it with `nccopy -k classic IN OUT`".to_owned(),
        ));
    }
    if head.len() >= 4 && head.starts_with(b"CDF") {
        return match head[3] {
            1 | 2 => Ok(()),
            5 => Err(HeaderProblem::NotNetcdf(
                "it is a CDF-5 (64-bit data) file, which this reader does not support; convert it with `nccopy -k classic IN OUT`"
                    .to_owned(),
            )),
            v => Err(HeaderProblem::NotNetcdf(format!(
                "unknown netCDF format version byte {v} (1 or 2 expected)"
            ))),
        };
    }
    if head.len() < 4 && b"CDF".starts_with(head) {
        // The whole file is the start of a signature: cut short. The smallest classic file
        // (no dimensions, attributes or variables) has 32 bytes.
        return Err(HeaderProblem::Truncated { needed: 32 });
    }
    Err(HeaderProblem::NotNetcdf(format!(
        "it starts with \"{}\" where a netCDF classic file starts with \"CDF\\x01\" or \"CDF\\x02\"",
        head.escape_ascii()
    )))
}

fn corrupt(detail: String) -> HeaderProblem {
    HeaderProblem::Corrupt(detail)
}

/// Bytes of zero padding after `n` bytes, to a multiple of 4.
fn padding(n: u64) -> u64 {
    (4 - n % 4) % 4
}

/// A position in the header.
struct Walker<'a> {
    buf: &'a [u8],
    pos: usize,
    file_len: u64,
}

impl<'a> Walker<'a> {
    /// The next `n` bytes.
    fn take(&mut self, n: u64) -> Result<&'a [u8], HeaderProblem> {
        let end = (self.pos as u64).saturating_add(n);
        if end > self.file_len {
            return Err(HeaderProblem::Truncated { needed: end });
        }
        if end > MAX_HEADER_BYTES {
            return Err(HeaderProblem::TooLarge { at_least: end });
        }
        if end > self.buf.len() as u64 {
            return Err(HeaderProblem::NeedMore);
        }
        let end = end as usize; // at most buf.len()
        let bytes = &self.buf[self.pos..end];
        self.pos = end;
        Ok(bytes)
    }

    fn u32(&mut self) -> Result<u32, HeaderProblem> {
        let b = self.take(4)?;
        Ok(u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// A count or size, which the format stores as a non-negative 32-bit integer.
    fn non_negative(&mut self, what: &str) -> Result<u64, HeaderProblem> {
        let v = self.u32()?;
        if v > i32::MAX as u32 {
            return Err(corrupt(format!("{what} is negative ({})", v as i32)));
        }
        Ok(u64::from(v))
    }

    /// Checks that `count` entries of at least `min_bytes` each fit in the rest of the file.
    fn fits(&self, count: u64, min_bytes: u64) -> Result<(), HeaderProblem> {
        let needed = (self.pos as u64).saturating_add(count.saturating_mul(min_bytes));
        if needed > self.file_len {
            return Err(HeaderProblem::Truncated { needed });
        }
        Ok(())
    }

    /// The tag and count that open a list; returns the count (0 for an absent list).
    fn list(&mut self, tag: u32, what: &str, min_bytes: u64) -> Result<u64, HeaderProblem> {
        let found = self.u32()?;
        let count = self.non_negative(&format!("the number of {what}"))?;
        if found == 0 {
            if count != 0 {
                return Err(corrupt(format!(
                    "the list of {what} is marked absent but counts {count}"
                )));
            }
            return Ok(0);
        }
        if found != tag {
            return Err(corrupt(format!(
                "the list of {what} starts with tag {found:#x}, not {tag:#x}"
            )));
        }
        self.fits(count, min_bytes)?;
        Ok(count)
    }

    /// A name: a length, then that many bytes, padded to a multiple of 4.
    fn name(&mut self, what: &str) -> Result<String, HeaderProblem> {
        let len = self.non_negative(&format!("the length of {what}"))?;
        let bytes = self.take(len.saturating_add(padding(len)))?;
        let len = len as usize; // fits: the bytes are in memory
        Ok(String::from_utf8_lossy(&bytes[..len]).into_owned())
    }

    /// A data type code; returns the size of one value in bytes.
    fn data_type(&mut self) -> Result<u64, HeaderProblem> {
        match self.u32()? {
            1 | 2 => Ok(1),
            3 => Ok(2),
            4 | 5 => Ok(4),
            6 => Ok(8),
            t => Err(corrupt(format!("unknown data type code {t} (1 to 6 expected)"))),
        }
    }

    /// An attribute list, skipped.
    fn attributes(&mut self) -> Result<(), HeaderProblem> {
        let n = self.list(TAG_ATTRIBUTE, "attributes", MIN_ATTR_BYTES)?;
        for _ in 0..n {
            self.name("an attribute name")?;
            let size = self.data_type()?;
            let count = self.non_negative("the length of an attribute")?;
            let bytes = count.saturating_mul(size);
            self.take(bytes.saturating_add(padding(bytes)))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture() -> Vec<u8> {
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/etopo60.cdf")).unwrap()
    }

    #[test]
    fn fixture_passes_and_locates_the_variables() {
        let bytes = fixture();
        let info = check(&bytes, bytes.len() as u64).unwrap();
        let names: Vec<&str> = info.vars.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["ETOPO60X", "ETOPO60Y", "ROSE"]);
        let rose = info.var("ROSE").unwrap();
        assert_eq!(rose.chunk_bytes, 360 * 180 * 4);
        assert!(!rose.is_record);
        assert_eq!(info.data_end(rose, bytes.len() as u64), Some(bytes.len() as u64));
    }

    #[test]
    fn a_short_prefix_asks_for_more_and_a_short_file_is_truncated() {
        let bytes = fixture();
        assert_eq!(
            check(&bytes[..40], bytes.len() as u64).unwrap_err(),
            HeaderProblem::NeedMore
        );
        assert!(matches!(
            check(&bytes[..40], 40).unwrap_err(),
            HeaderProblem::Truncated { .. }
        ));
        assert!(matches!(check(b"CD", 2).unwrap_err(), HeaderProblem::Truncated { .. }));
        assert!(matches!(
            check(b"CDF\x01", 4).unwrap_err(),
            HeaderProblem::Truncated { .. }
        ));
    }

    #[test]
    fn huge_counts_are_refused_before_anything_is_reserved() {
        let bytes = fixture();
        // Bytes 8..12 are the dimension list tag, 12..16 its count.
        assert_eq!(&bytes[8..12], &[0, 0, 0, 0x0A]);
        for count in [0x7FFF_FFFFu32, 0x0100_0000, 100_000] {
            let mut b = bytes.clone();
            b[12..16].copy_from_slice(&count.to_be_bytes());
            assert!(matches!(
                check(&b, b.len() as u64).unwrap_err(),
                HeaderProblem::Truncated { .. }
            ));
        }
        let mut b = bytes.clone();
        b[12..16].copy_from_slice(&0x8000_0000u32.to_be_bytes());
        assert!(matches!(
            check(&b, b.len() as u64).unwrap_err(),
            HeaderProblem::Corrupt(_)
        ));
    }

    #[test]
    fn other_formats_are_named() {
        let e = |b: &[u8]| check(b, b.len() as u64).unwrap_err();
        assert!(matches!(e(b""), HeaderProblem::NotNetcdf(d) if d.contains("empty")));
        assert!(matches!(e(b"\x89HDF\r\n\x1a\n rest"), HeaderProblem::NotNetcdf(d) if d.contains("HDF5")));
        assert!(matches!(e(b"CDF\x05\0\0\0\0"), HeaderProblem::NotNetcdf(d) if d.contains("CDF-5")));
        assert!(matches!(e(b"hello, world"), HeaderProblem::NotNetcdf(d) if d.contains("hello")));
    }
}
