//! MetaImage (ITK/VTK `.mha`, `.mhd`) reader.
//!
//! The header is `Key = Value` lines (keys compared case-insensitively) ending with
//! `ElementDataFile`. `ElementDataFile = LOCAL` means the data follows that line in the
//! same file (`.mha`, sometimes `.mhd`); otherwise it names a data file relative to the
//! header's folder (`HeaderSize` bytes are skipped there; `-1` means the data is at the end
//! of that file). File lists (`LIST`) and numbered file patterns are not supported.
//!
//! * `NDims` 1–3 (missing axes have size 1), `DimSize`, `ElementSpacing` (else
//!   `ElementSize`, else 1), `Offset` / `Position` / `Origin` (default 0).
//! * `TransformMatrix` / `Rotation` / `Orientation`: as in ITK, its `i`-th group of `NDims`
//!   numbers is the world direction of index axis `i`, i.e. a column of
//!   [`VolumeData::direction`].
//! * `ElementType` `MET_UCHAR`, `MET_CHAR`, `MET_USHORT`, `MET_SHORT`, `MET_UINT`,
//!   `MET_INT`, `MET_ULONG`/`MET_LONG` (32-bit in MetaIO), `MET_FLOAT`, `MET_DOUBLE` (an
//!   `_ARRAY` suffix is accepted), `ElementNumberOfChannels` 1–4 (interleaved).
//! * `BinaryData = False` (ASCII numbers), `BinaryDataByteOrderMSB` / `ElementByteOrderMSB`,
//!   `CompressedData = True` (zlib, or gzip detected by its magic bytes).

use std::borrow::Cow;
use std::path::Path;

use ferrovol_core::VolumeData;

use crate::decode::{
    decode_binary, inflate, lookup_type, next_line, numbers, parse_ascii, take_data, Fields,
    Geometry, Layout, TypeNames,
};
use crate::ReadError;

const FORMAT: &str = "MetaImage";
const SUPPORTED_TYPES: &str =
    "MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_ULONG, MET_LONG, MET_FLOAT and MET_DOUBLE";

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// The header's fields (keys as written) and where the data after it starts.
fn parse_header(bytes: &[u8]) -> Result<(Fields, usize), ReadError> {
    let mut fields = Vec::new();
    let mut pos = 0;
    let mut line_no = 0;
    while let Some((line, next)) = next_line(bytes, pos) {
        pos = next;
        line_no += 1;
        let text = String::from_utf8_lossy(line);
        let t = text.trim();
        if t.is_empty() {
            continue;
        }
        let Some((k, v)) = t.split_once('=') else {
            let shown: String = t.chars().take(60).collect();
            return Err(bad(format!(
                "line {line_no} ({shown:?}) is not 'Key = Value'{}",
                if line_no == 1 {
                    "; this does not look like a MetaImage file"
                } else {
                    " (the header must end with an ElementDataFile line)"
                }
            )));
        };
        let (k, v) = (k.trim().to_string(), v.trim().to_string());
        let last = k.eq_ignore_ascii_case("ElementDataFile");
        fields.push((k, v));
        if last {
            return Ok((Fields(fields), pos));
        }
    }
    Err(bad(
        "no ElementDataFile line (it ends the header and says where the data is: LOCAL or a file name)",
    ))
}

fn parse_bool(key: &str, v: &str) -> Result<bool, ReadError> {
    match v.to_ascii_lowercase().as_str() {
        "true" | "1" | "yes" => Ok(true),
        "false" | "0" | "no" => Ok(false),
        _ => Err(bad(format!("{key} = {v}: expected True or False"))),
    }
}

/// The value of the first of `keys` present, parsed by `parse`; `default` if none is.
fn field<T>(
    h: &Fields,
    keys: &[&str],
    default: T,
    parse: impl FnOnce(&str, &str) -> Result<T, ReadError>,
) -> Result<T, ReadError> {
    h.get(keys).map_or(Ok(default), |(k, v)| parse(k, v))
}

/// `n` whitespace-separated numbers, `what` in the error message.
fn parse_numbers<T: std::str::FromStr>(
    key: &str,
    v: &str,
    n: usize,
    what: &str,
) -> Result<Vec<T>, ReadError> {
    numbers(v, n).ok_or_else(|| bad(format!("{key} = {v}: expected {n} {what}")))
}

/// A whole number.
fn whole<T: std::str::FromStr>(key: &str, v: &str, hint: &str) -> Result<T, ReadError> {
    v.parse()
        .map_err(|_| bad(format!("{key} = {v}: expected a whole number{hint}")))
}

/// Parses a MetaImage header (`.mha`, `.mhd`) with its data. `ElementDataFile = LOCAL`
/// data follows the header in `bytes`; any other file name is passed to `data_file`,
/// which returns that file's bytes (see [`crate::Format::parse`]).
pub fn parse(
    bytes: &[u8],
    data_file: impl FnOnce(&str) -> Result<Vec<u8>, ReadError>,
) -> Result<VolumeData, ReadError> {
    let p = plan(bytes)?;
    let Some(file_value) = p.file.as_deref() else {
        let data = bytes.get(p.data_start..).unwrap_or(&[]);
        let scalars = decode(data, p.layout, p.binary, p.big_endian, p.compressed)?;
        return p.layout.volume(p.geometry, scalars);
    };
    let external = data_file(file_value)?;
    let in_data_file = |e: ReadError| e.in_file(Path::new(file_value));
    let header_size = p.header_size;
    let skipped = match usize::try_from(header_size) {
        Ok(skip) => skip,
        // -1: the data is at the end of the file.
        Err(_) if header_size == -1 && !p.compressed && p.binary => {
            external.len().saturating_sub(p.layout.nbytes)
        }
        Err(_) => {
            return Err(bad(format!(
                "HeaderSize = {header_size}; expected a byte count or -1 (uncompressed binary data only)"
            )))
        }
    };
    let data = external
        .get(skipped..)
        .ok_or_else(|| {
            ReadError::truncated(
                format!("MetaImage data file (HeaderSize {header_size})"),
                skipped,
                external.len(),
            )
        })
        .map_err(in_data_file)?;
    let scalars =
        decode(data, p.layout, p.binary, p.big_endian, p.compressed).map_err(in_data_file)?;
    p.layout.volume(p.geometry, scalars)
}

/// Where uncompressed binary data lies, for reading it in place (`header`: any prefix of
/// the file holding the whole header). `None` for ASCII or compressed data.
pub(crate) fn raw_data(header: &[u8]) -> Result<Option<crate::raw::RawData>, ReadError> {
    use crate::raw::{RawData, RawStart};
    let p = plan(header)?;
    if !p.binary || p.compressed {
        return Ok(None);
    }
    let (file, start) = match p.file {
        Some(f) => match u64::try_from(p.header_size) {
            Ok(skip) => (Some(f), RawStart::At(skip)),
            Err(_) if p.header_size == -1 => (Some(f), RawStart::FromEnd),
            Err(_) => return Ok(None), // the in-memory reader names the problem
        },
        None => (None, RawStart::At(p.data_start as u64)),
    };
    Ok(Some(RawData {
        format: FORMAT,
        layout: p.layout,
        geometry: p.geometry,
        big_endian: p.big_endian,
        file,
        start,
    }))
}

/// What a header says about the volume and where its data is.
struct Plan {
    layout: Layout,
    geometry: Geometry,
    binary: bool,
    big_endian: bool,
    compressed: bool,
    header_size: i64,
    /// The detached data file, as the header names it (None: LOCAL).
    file: Option<String>,
    /// Where LOCAL data starts.
    data_start: usize,
}

/// Parses the header and checks what it says.
fn plan(bytes: &[u8]) -> Result<Plan, ReadError> {
    let (h, data_start) = parse_header(bytes)?;

    if let Some((k, v)) = h.get(&["ObjectType"]) {
        if !v.eq_ignore_ascii_case("Image") {
            return Err(ReadError::unsupported(format!(
                "{k} = {v}; only MetaImage Image objects hold volumes"
            )));
        }
    }
    let (dk, dv) = h
        .get(&["DimSize"])
        .ok_or_else(|| bad("no DimSize line (the image dimensions)"))?;
    let ndims = field(
        &h,
        &["NDims"],
        dv.split_ascii_whitespace().count(),
        |k, v| whole(k, v, ""),
    )?;
    if !(1..=3).contains(&ndims) {
        return Err(ReadError::unsupported(format!(
            "NDims = {ndims}; ferrovol reads 1- to 3-dimensional images (extract a 3D volume first)"
        )));
    }
    let size: Vec<u64> = parse_numbers(dk, dv, ndims, "whole numbers")?;
    let mut dims = [1u64; 3];
    dims[..ndims].copy_from_slice(&size);

    let mut geometry = Geometry::default();
    if let Some((k, v)) = h.get(&["ElementSpacing", "ElementSize"]) {
        let s: Vec<f64> = parse_numbers(k, v, ndims, "numbers")?;
        geometry.spacing[..ndims].copy_from_slice(&s);
    }
    if let Some((k, v)) = h.get(&["Offset", "Position", "Origin"]) {
        let o: Vec<f64> = parse_numbers(k, v, ndims, "numbers")?;
        geometry.origin[..ndims].copy_from_slice(&o);
    }
    if let Some((k, v)) = h.get(&["TransformMatrix", "Rotation", "Orientation"]) {
        let m: Vec<f64> = parse_numbers(k, v, ndims * ndims, "numbers")?;
        for (r, row) in geometry.direction.iter_mut().enumerate().take(ndims) {
            for (axis, x) in row.iter_mut().enumerate().take(ndims) {
                *x = m.get(axis * ndims + r).copied().unwrap_or(0.0);
            }
        }
    }

    let (_, tv) = h
        .get(&["ElementType"])
        .ok_or_else(|| bad("no ElementType line (the scalar type, e.g. MET_SHORT)"))?;
    let upper = tv.to_ascii_uppercase();
    let ty = lookup_type(
        TypeNames::MetaImage,
        upper.strip_suffix("_ARRAY").unwrap_or(&upper),
    )
    .ok_or_else(|| ReadError::unsupported_type(tv, SUPPORTED_TYPES))?;
    let components: u64 = field(&h, &["ElementNumberOfChannels"], 1, |k, v| whole(k, v, ""))?;
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(format!(
            "{components} channels per voxel (ElementNumberOfChannels); ferrovol renders 1 to 4"
        )));
    }
    let binary = field(&h, &["BinaryData"], true, parse_bool)?;
    let big_endian = field(
        &h,
        &["BinaryDataByteOrderMSB", "ElementByteOrderMSB"],
        false,
        parse_bool,
    )?;
    let compressed = field(&h, &["CompressedData"], false, parse_bool)?;
    let header_size: i64 = field(&h, &["HeaderSize"], 0, |k, v| whole(k, v, " (or -1)"))?;
    let layout = Layout::new(FORMAT, dims, components, ty)?;

    // Where the data is.
    let (_, file_value) = h
        .get(&["ElementDataFile"])
        .ok_or_else(|| bad("no ElementDataFile line"))?;
    let file = if file_value.eq_ignore_ascii_case("LOCAL") {
        None
    } else if file_value.eq_ignore_ascii_case("LIST") || file_value.contains('%') {
        return Err(ReadError::unsupported(format!(
            "ElementDataFile = {file_value}: data split over several files; merge the slices into one volume (e.g. save it again as .mha)"
        )));
    } else if file_value.is_empty() {
        return Err(bad(
            "ElementDataFile is empty; it must be LOCAL or a file name",
        ));
    } else {
        Some(file_value.to_string())
    };
    Ok(Plan {
        layout,
        geometry,
        binary,
        big_endian,
        compressed,
        header_size,
        file,
        data_start,
    })
}

/// The voxel values in `data`: binary (maybe compressed) or ASCII numbers.
fn decode(
    data: &[u8],
    layout: Layout,
    binary: bool,
    big_endian: bool,
    compressed: bool,
) -> Result<ferrovol_core::Scalars, ReadError> {
    if binary {
        let raw = take_data("MetaImage voxel data", data, compressed, layout.nbytes)?;
        return Ok(decode_binary(&raw, layout.ty, big_endian));
    }
    let raw = if compressed {
        Cow::Owned(inflate("MetaImage ASCII data", data, usize::MAX - 1)?)
    } else {
        Cow::Borrowed(data)
    };
    let text = String::from_utf8_lossy(&raw);
    parse_ascii("MetaImage ASCII data", &text, layout.ty, layout.count)
}

#[cfg(test)]
mod tests {
    use crate::test_util::{assert_geometry, check_errors, gzip, msg, never_panics, zlib};
    use crate::{no_data_file, ReadError};
    use ferrovol_core::{Scalars, VolumeData};

    fn parse(bytes: &[u8]) -> Result<VolumeData, ReadError> {
        super::parse(bytes, no_data_file)
    }

    /// A data-file function that has only `name`, with `bytes`.
    fn only<'a>(
        name: &'a str,
        bytes: &'a [u8],
    ) -> impl Fn(&str) -> Result<Vec<u8>, ReadError> + Copy + 'a {
        move |n| match n == name {
            true => Ok(bytes.to_vec()),
            false => no_data_file(n),
        }
    }

    fn mha(header: &str, data: &[u8]) -> Vec<u8> {
        let mut f = header.as_bytes().to_vec();
        f.extend_from_slice(data);
        f
    }

    #[test]
    fn readers_mha_local_short_with_transform() {
        let vals: Vec<i16> = (0..12).map(|i| i * 100 - 600).collect();
        let data: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let header = "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 1 2 3\nCenterOfRotation = 0 0 0\nElementSpacing = 0.5 1 2\nDimSize = 3 2 2\nAnatomicalOrientation = RAI\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
        let v = parse(&mha(header, &data)).unwrap();
        assert_geometry(&v, [3, 2, 2], [0.5, 1.0, 2.0], [1.0, 2.0, 3.0]);
        // ITK: the first three numbers are the direction of index axis 0 (a column).
        assert_eq!(
            v.direction,
            [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(v.components, 1);
        assert_eq!(v.scalars, Scalars::I16(vals));
    }

    #[test]
    fn readers_mhd_external_big_endian_float_with_header_size() {
        let vals: Vec<f32> = (0..12).map(|i| i as f32 * 0.5).collect();
        let mut raw = vec![9u8, 9, 9];
        raw.extend(vals.iter().flat_map(|v| v.to_be_bytes()));
        let header = "ObjectType = Image\r\nNDims = 3\r\nDimSize = 3 2 2\r\nElementSize = 1 1 4\r\nPosition = -1 -2 -3\r\nElementByteOrderMSB = True\r\nHeaderSize = 3\r\nElementType = MET_FLOAT\r\nElementDataFile = vol data.raw\r\n";
        let v = super::parse(header.as_bytes(), only("vol data.raw", &raw)).unwrap();
        assert_eq!(v.spacing, [1.0, 1.0, 4.0]);
        assert_eq!(v.origin, [-1.0, -2.0, -3.0]);
        assert_eq!(v.scalars, Scalars::F32(vals.clone()));

        // HeaderSize = -1: the data is at the end of the file.
        let header = header.replace("HeaderSize = 3", "HeaderSize = -1");
        let v = super::parse(header.as_bytes(), only("vol data.raw", &raw)).unwrap();
        assert_eq!(v.scalars, Scalars::F32(vals));
    }

    #[test]
    fn readers_mha_compressed_rgb_and_mhd_gzip_double() {
        let rgb: Vec<u8> = (0..36).map(|i| i * 7).collect();
        let header = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nCompressedData = True\nCompressedDataSize = 99\nElementNumberOfChannels = 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
        let v = parse(&mha(header, &zlib(&rgb))).unwrap();
        assert_eq!(v.components, 3);
        assert_eq!(v.scalars, Scalars::U8(rgb));

        let d: Vec<f64> = (0..12).map(|i| i as f64 - 0.25).collect();
        let zraw = gzip(&d.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>());
        let header = "NDims = 3\nDimSize = 3 2 2\nCompressedData = True\nElementType = MET_DOUBLE\nElementDataFile = d.zraw\n";
        let v = super::parse(header.as_bytes(), only("d.zraw", &zraw)).unwrap();
        assert_eq!(v.scalars, Scalars::F64(d));
    }

    #[test]
    fn readers_mha_ascii_2d_and_other_types() {
        let header = "ObjectType = Image\nNDims = 2\nDimSize = 3 2\nElementSpacing = 2 3\nOffset = 5 6\nBinaryData = False\nElementType = MET_INT\nElementDataFile = LOCAL\n";
        let v = parse(&mha(header, b"1 -2 3\n4 5 -600000\n")).unwrap();
        assert_geometry(&v, [3, 2, 1], [2.0, 3.0, 1.0], [5.0, 6.0, 0.0]);
        assert_eq!(v.scalars, Scalars::I32(vec![1, -2, 3, 4, 5, -600000]));

        for (ty, want) in [
            ("MET_CHAR", Scalars::I8(vec![-1, 2])),
            ("MET_USHORT", Scalars::U16(vec![0xfeff, 0x0102])),
            (
                "MET_UINT_ARRAY",
                Scalars::U32(vec![0x0102feff, 0x0304_0506]),
            ),
        ] {
            let n = match want {
                Scalars::I8(_) => 1,
                Scalars::U16(_) => 2,
                _ => 4,
            };
            let bytes: Vec<u8> =
                [0xffu8, 0xfe, 0x02, 0x01, 0x06, 0x05, 0x04, 0x03][..2 * n].to_vec();
            let bytes = if n == 1 { vec![0xff, 0x02] } else { bytes };
            let header =
                format!("NDims = 1\nDimSize = 2\nElementType = {ty}\nElementDataFile = LOCAL\n");
            let v = parse(&mha(&header, &bytes)).unwrap();
            assert_eq!(v.scalars, want, "{ty}");
        }
    }

    #[test]
    fn readers_mha_errors() {
        let base = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
        let twelve = [1u8; 12];
        // The base header with `from` replaced by `to`, or with one more line.
        let edit = |from: &str, to: &str, data: &[u8]| mha(&base.replace(from, to), data);
        let with = |line: &str, data: &[u8]| edit("NDims = 3", &format!("NDims = 3\n{line}"), data);
        let nan = [&[0u8, 0, 0xc0, 0x7f][..], &[0; 44]].concat();
        let cases: Vec<(&str, Vec<u8>, &str)> = vec![
            (
                "trunc",
                mha(base, &twelve[..7]),
                "truncated MetaImage voxel data: expected 12 bytes, found 7",
            ),
            (
                "ll",
                edit("MET_UCHAR", "MET_LONG_LONG", &[0; 96]),
                "unsupported scalar type 'MET_LONG_LONG'",
            ),
            (
                "nd4",
                edit(
                    "NDims = 3\nDimSize = 3 2 2",
                    "NDims = 4\nDimSize = 3 2 2 2",
                    &[0; 24],
                ),
                "NDims = 4",
            ),
            (
                "zero",
                with("ElementSpacing = 1 0 1", &twelve),
                "spacing along y is 0",
            ),
            ("nan", edit("MET_UCHAR", "MET_FLOAT", &nan), "NaN"),
            (
                "nodim",
                edit("DimSize = 3 2 2\n", "", &twelve),
                "no DimSize",
            ),
            (
                "dimcount",
                edit("3 2 2", "3 2", &twelve),
                "expected 3 whole numbers",
            ),
            ("dimzero", edit("3 2 2", "3 0 2", &twelve), "at least 1"),
            (
                "noend",
                b"ObjectType = Image\nNDims = 3\n".to_vec(),
                "no ElementDataFile",
            ),
            (
                "junk",
                vec![0x89, b'P', b'N', b'G', b'\n', 0, 0],
                "not 'Key = Value'",
            ),
            ("list", edit("LOCAL", "LIST", &[]), "several files"),
            (
                "pattern",
                edit("LOCAL", "slice%03d.raw 1 10 1", &[]),
                "several files",
            ),
            (
                "mesh",
                edit("= Image", "= Mesh", &twelve),
                "ObjectType = Mesh",
            ),
            (
                "bool",
                with("CompressedData = maybe", &twelve),
                "expected True or False",
            ),
            (
                "chan",
                with("ElementNumberOfChannels = 5", &twelve),
                "5 channels",
            ),
            (
                "z",
                with("CompressedData = True", &[0x78, 0x9c, 1, 2, 3]),
                "decompression failed",
            ),
            (
                "zshort",
                with("CompressedData = True", &zlib(&[1; 5])),
                "expected 12 bytes, found 5",
            ),
            (
                "ascii",
                with("BinaryData = False", b"1 2 3"),
                "found 3 values, expected 12",
            ),
        ];
        check_errors(parse, &cases);

        // A problem in a data file names it as the header does.
        let header = base.replace("LOCAL", "short.raw");
        let m = msg(super::parse(
            header.as_bytes(),
            only("short.raw", &[1, 2, 3]),
        ));
        assert!(
            m.starts_with("short.raw: truncated MetaImage voxel data: expected 12 bytes, found 3"),
            "{m}"
        );
        let m = msg(parse(base.replace("LOCAL", "gone.raw").as_bytes()));
        assert!(m.contains("\"gone.raw\", which was not given"), "{m}");
    }

    /// 10^12 voxels of double (8 TB) in a few bytes: an error, not an allocation.
    #[test]
    fn readers_mha_absurd_size_fails_before_allocating() {
        let header = "NDims = 3\nDimSize = 10000 10000 10000\nElementType = MET_DOUBLE\n";
        let cases = [
            (
                "raw",
                mha(&format!("{header}ElementDataFile = LOCAL\n"), &[0; 16]),
                "expected 8000000000000 bytes, found 16",
            ),
            (
                "zlib",
                mha(
                    &format!("{header}CompressedData = True\nElementDataFile = LOCAL\n"),
                    &zlib(&[0; 16]),
                ),
                "expected 8000000000000 bytes, found 16",
            ),
            (
                "ascii",
                mha(
                    &format!("{header}BinaryData = False\nElementDataFile = LOCAL\n"),
                    b"1 2",
                ),
                "found 2 values, expected 1000000000000",
            ),
        ];
        check_errors(parse, &cases);
        let header = format!("{header}HeaderSize = -1\nElementDataFile = d.raw\n");
        let m = msg(super::parse(header.as_bytes(), only("d.raw", &[0; 16])));
        assert!(m.contains("expected 8000000000000 bytes, found 16"), "{m}");
    }

    #[test]
    fn readers_mha_never_panics_on_damaged_files() {
        let header = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nElementSpacing = 1 1 1\nCompressedData = True\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
        let f = mha(header, &zlib(&[7u8; 24]));
        never_panics(parse, &f, &[0, b'9', b'-', b' ', b'\n', 0xff]);
    }
}
