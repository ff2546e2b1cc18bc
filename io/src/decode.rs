//! What the volume readers share: the volume's layout with its size checks, header lines
//! and number lists, type-name tables, and decoding of binary, ASCII and compressed data.

use std::borrow::Cow;
use std::io::Read;

use ferrovol_core::{Direction, ScalarType, Scalars, VolumeData, IDENTITY_DIRECTION};

use crate::error::Problem;
use crate::ReadError;

/// The shape of a volume's data as a header describes it, checked: every dimension is
/// 1 to `u32::MAX`, and the value and byte counts fit `usize`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    pub dims: [u64; 3],
    pub components: u64,
    pub ty: ScalarType,
    /// `dims[0] * dims[1] * dims[2] * components`.
    pub count: usize,
    /// The byte size of `count` values of `ty`.
    pub nbytes: usize,
}

impl Layout {
    /// Checks `dims` and `components` (1 to 4) of `ty` from a `format` header. Sizes are
    /// only counted here: readers compare `nbytes` with the data actually present before
    /// they allocate anything for it.
    pub fn new(
        format: &'static str,
        dims: [u64; 3],
        components: u64,
        ty: ScalarType,
    ) -> Result<Layout, ReadError> {
        let bad = |message: String| ReadError::bad_header(format, message);
        for d in dims {
            if d == 0 {
                return Err(bad(format!(
                    "dimensions {dims:?} contain 0; every dimension must be at least 1"
                )));
            }
            if d > u32::MAX as u64 {
                return Err(bad(format!(
                    "dimension {d} is larger than {} (the largest ferrovol accepts)",
                    u32::MAX
                )));
            }
        }
        let too_big = || {
            bad(format!(
                "dimensions {dims:?} with {components} component(s) of {} hold more values than this machine can address",
                ty.name()
            ))
        };
        let mut count: usize = 1;
        for d in dims.into_iter().chain([components]) {
            let d = usize::try_from(d).map_err(|_| too_big())?;
            count = count.checked_mul(d).ok_or_else(too_big)?;
        }
        let nbytes = count.checked_mul(ty.size_bytes()).ok_or_else(too_big)?;
        Ok(Layout {
            dims,
            components,
            ty,
            count,
            nbytes,
        })
    }

    /// The volume of these dimensions with `scalars` placed by `geometry`, validated.
    pub fn volume(&self, geometry: Geometry, scalars: Scalars) -> Result<VolumeData, ReadError> {
        let volume = VolumeData {
            // Checked in `new`: every dimension fits u32.
            dims: self.dims.map(|d| d as u32),
            spacing: geometry.spacing,
            origin: geometry.origin,
            direction: geometry.direction,
            components: self.components as u32,
            scalars,
            coordinates: None,
        };
        volume.validate().map_err(Problem::InvalidVolume)?;
        Ok(volume)
    }
}

/// Where a volume lies in world space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Geometry {
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    pub direction: Direction,
}

impl Default for Geometry {
    /// Unit spacing at the origin, axis-aligned.
    fn default() -> Self {
        Geometry {
            spacing: [1.0; 3],
            origin: [0.0; 3],
            direction: IDENTITY_DIRECTION,
        }
    }
}

/// A format's names for the scalar types: a column of [`TYPE_NAMES`].
#[derive(Clone, Copy)]
pub(crate) enum TypeNames {
    Vti,
    MetaImage,
    Nrrd,
}

/// Each scalar type's names, comma-separated: in VTK XML (and legacy VTK), in MetaImage
/// (without the optional `_ARRAY` suffix) and in NRRD (lower case, single spaces).
const TYPE_NAMES: [(ScalarType, [&str; 3]); 8] = [
    (
        ScalarType::I8,
        [
            "Int8,char,signed_char",
            "MET_CHAR",
            "signed char,int8,int8_t",
        ],
    ),
    (
        ScalarType::U8,
        [
            "UInt8,unsigned_char",
            "MET_UCHAR",
            "uchar,unsigned char,uint8,uint8_t",
        ],
    ),
    (
        ScalarType::I16,
        [
            "Int16,short",
            "MET_SHORT",
            "short,short int,signed short,signed short int,int16,int16_t",
        ],
    ),
    (
        ScalarType::U16,
        [
            "UInt16,unsigned_short",
            "MET_USHORT",
            "ushort,unsigned short,unsigned short int,uint16,uint16_t",
        ],
    ),
    (
        ScalarType::I32,
        [
            "Int32,int",
            "MET_INT,MET_LONG",
            "int,signed int,int32,int32_t",
        ],
    ),
    (
        ScalarType::U32,
        [
            "UInt32,unsigned_int",
            "MET_UINT,MET_ULONG",
            "uint,unsigned int,uint32,uint32_t",
        ],
    ),
    (ScalarType::F32, ["Float32,float", "MET_FLOAT", "float"]),
    (ScalarType::F64, ["Float64,double", "MET_DOUBLE", "double"]),
];

/// The scalar type a format calls `name` (compared exactly).
pub(crate) fn lookup_type(names: TypeNames, name: &str) -> Option<ScalarType> {
    TYPE_NAMES
        .iter()
        .find(|(_, n)| n[names as usize].split(',').any(|n| n == name))
        .map(|&(ty, _)| ty)
}

/// A header's `key: value` fields in file order.
pub(crate) struct Fields(pub Vec<(String, String)>);

impl Fields {
    /// The first of `keys` present (compared case-insensitively): the key as written and
    /// its value.
    pub fn get(&self, keys: &[&str]) -> Option<(&str, &str)> {
        keys.iter().find_map(|k| {
            self.0
                .iter()
                .find(|(key, _)| key.eq_ignore_ascii_case(k))
                .map(|(key, v)| (key.as_str(), v.as_str()))
        })
    }
}

/// Splits text into lines at `\n`, stripping a trailing `\r`; returns (line, offset of
/// the byte after the line's end).
pub(crate) fn next_line(bytes: &[u8], start: usize) -> Option<(&[u8], usize)> {
    let rest = bytes.get(start..)?;
    if rest.is_empty() {
        return None;
    }
    let (line, next) = match rest.iter().position(|&b| b == b'\n') {
        Some(i) => (&rest[..i], start + i + 1),
        None => (rest, bytes.len()),
    };
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    Some((line, next))
}

/// Parses whitespace-separated numbers, exactly `n` of them.
pub(crate) fn numbers<T: std::str::FromStr>(text: &str, n: usize) -> Option<Vec<T>> {
    let v: Vec<T> = text
        .split_ascii_whitespace()
        .map(|t| t.parse::<T>())
        .collect::<Result<_, _>>()
        .ok()?;
    (v.len() == n).then_some(v)
}

/// Reads a fixed-size number from bytes in either byte order.
pub(crate) trait FromBytes<const N: usize>: Sized {
    fn from_bytes(bytes: [u8; N], big_endian: bool) -> Self;
}

macro_rules! from_bytes {
    ($($t:ty),*) => {$(
        impl FromBytes<{ std::mem::size_of::<$t>() }> for $t {
            fn from_bytes(b: [u8; std::mem::size_of::<$t>()], big_endian: bool) -> Self {
                if big_endian {
                    <$t>::from_be_bytes(b)
                } else {
                    <$t>::from_le_bytes(b)
                }
            }
        }
    )*};
}
from_bytes!(i16, u16, i32, u32, i64, f32, f64);

/// Converts `bytes` (whose length must be a multiple of the type's size; extra bytes are
/// ignored) into scalars of `ty`.
pub(crate) fn decode_binary(bytes: &[u8], ty: ScalarType, big_endian: bool) -> Scalars {
    fn conv<T: FromBytes<N>, const N: usize>(bytes: &[u8], big_endian: bool) -> Vec<T> {
        bytes
            .chunks_exact(N)
            .map(|c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                T::from_bytes(a, big_endian)
            })
            .collect()
    }
    match ty {
        ScalarType::U8 => Scalars::U8(bytes.to_vec()),
        ScalarType::I8 => Scalars::I8(bytes.iter().map(|&b| b as i8).collect()),
        ScalarType::U16 => Scalars::U16(conv(bytes, big_endian)),
        ScalarType::I16 => Scalars::I16(conv(bytes, big_endian)),
        ScalarType::U32 => Scalars::U32(conv(bytes, big_endian)),
        ScalarType::I32 => Scalars::I32(conv(bytes, big_endian)),
        ScalarType::F32 => Scalars::F32(conv(bytes, big_endian)),
        ScalarType::F64 => Scalars::F64(conv(bytes, big_endian)),
    }
}

/// Parses exactly `count` whitespace-separated numbers of type `ty` from `text`.
/// `what` names the data section in error messages.
pub(crate) fn parse_ascii(
    what: &str,
    text: &str,
    ty: ScalarType,
    count: usize,
) -> Result<Scalars, ReadError> {
    fn parse_all<T: std::str::FromStr>(
        what: &str,
        text: &str,
        ty: ScalarType,
        count: usize,
    ) -> Result<Vec<T>, ReadError> {
        // Cap the up-front reservation: `count` comes from the header.
        let mut out = Vec::with_capacity(count.min(text.len() / 2 + 1));
        for (i, token) in text.split_ascii_whitespace().enumerate() {
            if i >= count {
                return Err(ReadError::corrupt(what, format!(
                    "more than the {count} values the header's dimensions call for (check the dimensions in the header)"
                )));
            }
            let v = token.parse::<T>().map_err(|_| {
                ReadError::corrupt(
                    what,
                    format!(
                        "value #{} '{}' is not a valid {} number (fix or re-export the data)",
                        i + 1,
                        token.chars().take(40).collect::<String>(),
                        ty.name()
                    ),
                )
            })?;
            out.push(v);
        }
        if out.len() != count {
            return Err(ReadError::corrupt(what, format!(
                "found {} values, expected {count} (the data is incomplete or the header's dimensions are wrong)",
                out.len()
            )));
        }
        Ok(out)
    }
    Ok(match ty {
        ScalarType::U8 => Scalars::U8(parse_all(what, text, ty, count)?),
        ScalarType::I8 => Scalars::I8(parse_all(what, text, ty, count)?),
        ScalarType::U16 => Scalars::U16(parse_all(what, text, ty, count)?),
        ScalarType::I16 => Scalars::I16(parse_all(what, text, ty, count)?),
        ScalarType::U32 => Scalars::U32(parse_all(what, text, ty, count)?),
        ScalarType::I32 => Scalars::I32(parse_all(what, text, ty, count)?),
        ScalarType::F32 => Scalars::F32(parse_all(what, text, ty, count)?),
        ScalarType::F64 => Scalars::F64(parse_all(what, text, ty, count)?),
    })
}

/// Decompresses `data` (zlib or gzip, detected by the gzip magic) and returns at most
/// `limit + 1` bytes: enough for the caller to tell "too short", "exact" and "too long"
/// apart without inflating a hostile stream without bound. The output grows with the
/// data actually inflated, whatever `limit` is.
pub(crate) fn inflate(what: &str, data: &[u8], limit: usize) -> Result<Vec<u8>, ReadError> {
    let mut out = Vec::new();
    let cap = (limit as u64).saturating_add(1);
    let result = if data.starts_with(&[0x1f, 0x8b]) {
        flate2::read::MultiGzDecoder::new(data)
            .take(cap)
            .read_to_end(&mut out)
    } else {
        flate2::read::ZlibDecoder::new(data)
            .take(cap)
            .read_to_end(&mut out)
    };
    result.map_err(|e| {
        ReadError::corrupt(
            what,
            format!(
                "decompression failed after {} bytes: {e} (the compressed data is damaged or truncated; export the file again)",
                out.len()
            ),
        )
    })?;
    Ok(out)
}

/// Returns the first `needed` bytes of `data`, after decompressing it (zlib or gzip) if
/// `compressed`; a short section is a [`ReadError::Truncated`]. Bytes after the needed
/// ones are ignored.
pub(crate) fn take_data<'a>(
    what: &str,
    data: &'a [u8],
    compressed: bool,
    needed: usize,
) -> Result<Cow<'a, [u8]>, ReadError> {
    if !compressed {
        return data
            .get(..needed)
            .map(Cow::Borrowed)
            .ok_or_else(|| ReadError::truncated(what, needed, data.len()));
    }
    let mut out = inflate(what, data, needed)?;
    if out.len() < needed {
        return Err(ReadError::truncated(
            format!("{what} (after decompression)"),
            needed,
            out.len(),
        ));
    }
    out.truncate(needed);
    Ok(Cow::Owned(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::msg;

    #[test]
    fn layout_checks_sizes() {
        let e = Layout::new("NRRD", [u32::MAX as u64; 3], 4, ScalarType::F64);
        if usize::BITS == 64 {
            assert!(msg(e).contains("more values than"));
        }
        assert!(msg(Layout::new("NRRD", [1 << 33, 1, 1], 1, ScalarType::U8)).contains("larger"));
        assert!(msg(Layout::new("NRRD", [4, 0, 1], 1, ScalarType::U8)).contains("at least 1"));
        let l = Layout::new("NRRD", [2, 3, 4], 2, ScalarType::U16).unwrap();
        assert_eq!((l.count, l.nbytes), (48, 96));
    }

    #[test]
    fn decode_binary_endianness() {
        let b = [0x01, 0x02, 0x03, 0x04];
        assert_eq!(
            decode_binary(&b, ScalarType::U16, false),
            Scalars::U16(vec![0x0201, 0x0403])
        );
        assert_eq!(
            decode_binary(&b, ScalarType::U16, true),
            Scalars::U16(vec![0x0102, 0x0304])
        );
        assert_eq!(
            decode_binary(&1.5f32.to_be_bytes(), ScalarType::F32, true),
            Scalars::F32(vec![1.5])
        );
    }

    #[test]
    fn parse_ascii_errors() {
        assert_eq!(
            parse_ascii("x", " 1 2\n3 ", ScalarType::I8, 3).unwrap(),
            Scalars::I8(vec![1, 2, 3])
        );
        assert!(
            msg(parse_ascii("x", "1 2", ScalarType::I8, 3)).contains("found 2 values, expected 3")
        );
        assert!(msg(parse_ascii("x", "1 2 3 4", ScalarType::I8, 3)).contains("more than"));
        assert!(msg(parse_ascii("x", "1 300 3", ScalarType::U8, 3)).contains("'300'"));
    }

    #[test]
    fn numbers_wants_exactly_n() {
        assert_eq!(numbers::<f64>(" 1 2.5\t3 ", 3), Some(vec![1.0, 2.5, 3.0]));
        assert_eq!(numbers::<f64>("1 2", 3), None);
        assert_eq!(numbers::<u64>("1 -2 3", 3), None);
    }
}
