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

use std::path::{Path, PathBuf};

use ferrovol_core::{ScalarType, VolumeData, IDENTITY_DIRECTION};

use super::{decode_binary, next_line, parse_ascii, read_file, take_data, value_count, ReadError};

const FORMAT: &str = "MetaImage";
const SUPPORTED_TYPES: &str =
    "MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_ULONG, MET_LONG, MET_FLOAT and MET_DOUBLE";

fn bad(path: &Path, message: impl Into<String>) -> ReadError {
    ReadError::bad_header(path, FORMAT, message)
}

fn met_type(name: &str) -> Option<ScalarType> {
    let base = name.strip_suffix("_ARRAY").unwrap_or(name);
    Some(match base {
        "MET_UCHAR" => ScalarType::U8,
        "MET_CHAR" => ScalarType::I8,
        "MET_USHORT" => ScalarType::U16,
        "MET_SHORT" => ScalarType::I16,
        "MET_UINT" | "MET_ULONG" => ScalarType::U32,
        "MET_INT" | "MET_LONG" => ScalarType::I32,
        "MET_FLOAT" => ScalarType::F32,
        "MET_DOUBLE" => ScalarType::F64,
        _ => return None,
    })
}

/// The header: (key as written, value) pairs in order, and where the data starts.
struct Header {
    fields: Vec<(String, String)>,
    data_start: usize,
}

impl Header {
    /// The value of the first of `keys` present (case-insensitive).
    fn get(&self, keys: &[&str]) -> Option<(&str, &str)> {
        keys.iter().find_map(|k| {
            self.fields
                .iter()
                .find(|(key, _)| key.eq_ignore_ascii_case(k))
                .map(|(key, v)| (key.as_str(), v.as_str()))
        })
    }
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header, ReadError> {
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
            return Err(bad(
                path,
                format!(
                    "line {line_no} ({shown:?}) is not 'Key = Value'{}",
                    if line_no == 1 {
                        "; this does not look like a MetaImage file"
                    } else {
                        " (the header must end with an ElementDataFile line)"
                    }
                ),
            ));
        };
        let (k, v) = (k.trim().to_string(), v.trim().to_string());
        let last = k.eq_ignore_ascii_case("ElementDataFile");
        fields.push((k, v));
        if last {
            return Ok(Header {
                fields,
                data_start: pos,
            });
        }
    }
    Err(bad(
        path,
        "no ElementDataFile line (it ends the header and says where the data is: LOCAL or a file name)",
    ))
}

fn parse_bool(path: &Path, key: &str, v: &str) -> Result<bool, ReadError> {
    match v.to_ascii_lowercase().as_str() {
        "true" | "1" | "yes" => Ok(true),
        "false" | "0" | "no" => Ok(false),
        _ => Err(bad(path, format!("{key} = {v}: expected True or False"))),
    }
}

fn parse_numbers<T: std::str::FromStr>(
    path: &Path,
    key: &str,
    v: &str,
    n: usize,
    what: &str,
) -> Result<Vec<T>, ReadError> {
    let err = || bad(path, format!("{key} = {v}: expected {n} {what}"));
    let vals: Vec<T> = v
        .split_ascii_whitespace()
        .map(|t| t.parse::<T>())
        .collect::<Result<_, _>>()
        .map_err(|_| err())?;
    if vals.len() != n {
        return Err(err());
    }
    Ok(vals)
}

pub(crate) fn read(path: &Path) -> Result<VolumeData, ReadError> {
    let bytes = read_file(path)?;
    let h = parse_header(path, &bytes)?;

    if let Some((k, v)) = h.get(&["ObjectType"]) {
        if !v.eq_ignore_ascii_case("Image") {
            return Err(ReadError::unsupported(
                path,
                format!("{k} = {v}; only MetaImage Image objects hold volumes"),
            ));
        }
    }
    let (dk, dv) = h
        .get(&["DimSize"])
        .ok_or_else(|| bad(path, "no DimSize line (the image dimensions)"))?;
    let ndims = match h.get(&["NDims"]) {
        Some((k, v)) => v
            .parse::<usize>()
            .map_err(|_| bad(path, format!("{k} = {v}: expected a whole number")))?,
        None => dv.split_ascii_whitespace().count(),
    };
    if !(1..=3).contains(&ndims) {
        return Err(ReadError::unsupported(
            path,
            format!(
                "NDims = {ndims}; ferrovol reads 1- to 3-dimensional images (extract a 3D volume first)"
            ),
        ));
    }
    let size: Vec<u64> = parse_numbers(path, dk, dv, ndims, "whole numbers")?;
    let mut dims = [1u64; 3];
    dims[..ndims].copy_from_slice(&size);

    let mut spacing = [1.0f64; 3];
    if let Some((k, v)) = h.get(&["ElementSpacing", "ElementSize"]) {
        let s: Vec<f64> = parse_numbers(path, k, v, ndims, "numbers")?;
        spacing[..ndims].copy_from_slice(&s);
    }
    let mut origin = [0.0f64; 3];
    if let Some((k, v)) = h.get(&["Offset", "Position", "Origin"]) {
        let o: Vec<f64> = parse_numbers(path, k, v, ndims, "numbers")?;
        origin[..ndims].copy_from_slice(&o);
    }
    let mut direction = IDENTITY_DIRECTION;
    if let Some((k, v)) = h.get(&["TransformMatrix", "Rotation", "Orientation"]) {
        let m: Vec<f64> = parse_numbers(path, k, v, ndims * ndims, "numbers")?;
        for (r, row) in direction.iter_mut().enumerate().take(ndims) {
            for (axis, x) in row.iter_mut().enumerate().take(ndims) {
                *x = m.get(axis * ndims + r).copied().unwrap_or(0.0);
            }
        }
    }

    let (_, tv) = h.get(&["ElementType"]).ok_or_else(|| {
        bad(
            path,
            "no ElementType line (the scalar type, e.g. MET_SHORT)",
        )
    })?;
    let ty = met_type(&tv.to_ascii_uppercase()).ok_or_else(|| ReadError::UnsupportedType {
        path: path.to_path_buf(),
        type_name: tv.to_string(),
        supported: SUPPORTED_TYPES,
    })?;
    let components: u64 = match h.get(&["ElementNumberOfChannels"]) {
        Some((k, v)) => v
            .parse()
            .map_err(|_| bad(path, format!("{k} = {v}: expected a whole number")))?,
        None => 1,
    };
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(
            path,
            format!("{components} channels per voxel (ElementNumberOfChannels); ferrovol renders 1 to 4"),
        ));
    }
    let binary = match h.get(&["BinaryData"]) {
        Some((k, v)) => parse_bool(path, k, v)?,
        None => true,
    };
    let big_endian = match h.get(&["BinaryDataByteOrderMSB", "ElementByteOrderMSB"]) {
        Some((k, v)) => parse_bool(path, k, v)?,
        None => false,
    };
    let compressed = match h.get(&["CompressedData"]) {
        Some((k, v)) => parse_bool(path, k, v)?,
        None => false,
    };
    let header_size: i64 = match h.get(&["HeaderSize"]) {
        Some((k, v)) => v
            .parse()
            .map_err(|_| bad(path, format!("{k} = {v}: expected a whole number (or -1)")))?,
        None => 0,
    };
    let (count, nbytes) = value_count(path, FORMAT, &dims, components, ty)?;

    // Where the data is.
    let (_, file_value) = h
        .get(&["ElementDataFile"])
        .ok_or_else(|| bad(path, "no ElementDataFile line"))?;
    let external;
    let (data_path, data): (PathBuf, &[u8]) = if file_value.eq_ignore_ascii_case("LOCAL") {
        (path.to_path_buf(), bytes.get(h.data_start..).unwrap_or(&[]))
    } else if file_value.eq_ignore_ascii_case("LIST") || file_value.contains('%') {
        return Err(ReadError::unsupported(
            path,
            format!("ElementDataFile = {file_value}: data split over several files; merge the slices into one volume (e.g. save it again as .mha)"),
        ));
    } else if file_value.is_empty() {
        return Err(bad(
            path,
            "ElementDataFile is empty; it must be LOCAL or a file name",
        ));
    } else {
        let p = path
            .parent()
            .map(|d| d.join(file_value))
            .unwrap_or_else(|| PathBuf::from(file_value));
        external = read_file(&p)?;
        let skipped = if header_size == -1 && !compressed && binary {
            external.len().saturating_sub(nbytes)
        } else if header_size >= 0 {
            usize::try_from(header_size).unwrap_or(usize::MAX)
        } else {
            return Err(bad(
                path,
                format!("HeaderSize = {header_size}; expected a byte count or -1 (uncompressed binary data only)"),
            ));
        };
        let d = external
            .get(skipped..)
            .ok_or_else(|| ReadError::Truncated {
                path: p.clone(),
                what: format!("MetaImage data file (HeaderSize {header_size})"),
                expected: skipped as u64,
                found: external.len() as u64,
            })?;
        (p, d)
    };

    let scalars = if binary {
        let raw = take_data(&data_path, "MetaImage voxel data", data, compressed, nbytes)?;
        decode_binary(&raw, ty, big_endian)
    } else {
        let raw = if compressed {
            std::borrow::Cow::Owned(super::inflate(
                &data_path,
                "MetaImage ASCII data",
                data,
                usize::MAX - 1,
            )?)
        } else {
            std::borrow::Cow::Borrowed(data)
        };
        let text = String::from_utf8_lossy(&raw);
        parse_ascii(&data_path, "MetaImage ASCII data", &text, ty, count)?
    };

    Ok(VolumeData {
        dims: [dims[0] as u32, dims[1] as u32, dims[2] as u32],
        spacing,
        origin,
        direction,
        components: components as u32,
        scalars,
    })
}

#[cfg(test)]
mod tests {
    use super::super::read_volume;
    use super::super::test_util::{gzip, msg, zlib, TempDir};
    use ferrovol_core::Scalars;

    fn mha(header: &str, data: &[u8]) -> Vec<u8> {
        let mut f = header.as_bytes().to_vec();
        f.extend_from_slice(data);
        f
    }

    #[test]
    fn readers_mha_local_short_with_transform() {
        let dir = TempDir::new("mha");
        let vals: Vec<i16> = (0..12).map(|i| i * 100 - 600).collect();
        let data: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let header = "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 1 2 3\nCenterOfRotation = 0 0 0\nElementSpacing = 0.5 1 2\nDimSize = 3 2 2\nAnatomicalOrientation = RAI\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
        let v = read_volume(&dir.write("a.mha", &mha(header, &data))).unwrap();
        assert_eq!(v.dims, [3, 2, 2]);
        assert_eq!(v.spacing, [0.5, 1.0, 2.0]);
        assert_eq!(v.origin, [1.0, 2.0, 3.0]);
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
        let dir = TempDir::new("mha");
        let vals: Vec<f32> = (0..12).map(|i| i as f32 * 0.5).collect();
        let mut raw = vec![9u8, 9, 9];
        raw.extend(vals.iter().flat_map(|v| v.to_be_bytes()));
        dir.write("vol data.raw", &raw);
        let header = "ObjectType = Image\r\nNDims = 3\r\nDimSize = 3 2 2\r\nElementSize = 1 1 4\r\nPosition = -1 -2 -3\r\nElementByteOrderMSB = True\r\nHeaderSize = 3\r\nElementType = MET_FLOAT\r\nElementDataFile = vol data.raw\r\n";
        let v = read_volume(&dir.write("a.mhd", header.as_bytes())).unwrap();
        assert_eq!(v.spacing, [1.0, 1.0, 4.0]);
        assert_eq!(v.origin, [-1.0, -2.0, -3.0]);
        assert_eq!(v.scalars, Scalars::F32(vals.clone()));

        // HeaderSize = -1: the data is at the end of the file.
        let header = header.replace("HeaderSize = 3", "HeaderSize = -1");
        let v = read_volume(&dir.write("b.mhd", header.as_bytes())).unwrap();
        assert_eq!(v.scalars, Scalars::F32(vals));
    }

    #[test]
    fn readers_mha_compressed_rgb_and_mhd_gzip_double() {
        let dir = TempDir::new("mha");
        let rgb: Vec<u8> = (0..36).map(|i| i * 7).collect();
        let header = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nCompressedData = True\nCompressedDataSize = 99\nElementNumberOfChannels = 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
        let v = read_volume(&dir.write("c.mha", &mha(header, &zlib(&rgb)))).unwrap();
        assert_eq!(v.components, 3);
        assert_eq!(v.scalars, Scalars::U8(rgb));

        let d: Vec<f64> = (0..12).map(|i| i as f64 - 0.25).collect();
        dir.write(
            "d.zraw",
            &gzip(&d.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>()),
        );
        let header = "NDims = 3\nDimSize = 3 2 2\nCompressedData = True\nElementType = MET_DOUBLE\nElementDataFile = d.zraw\n";
        let v = read_volume(&dir.write("d.mhd", header.as_bytes())).unwrap();
        assert_eq!(v.scalars, Scalars::F64(d));
    }

    #[test]
    fn readers_mha_ascii_2d_and_other_types() {
        let dir = TempDir::new("mha");
        let header = "ObjectType = Image\nNDims = 2\nDimSize = 3 2\nElementSpacing = 2 3\nOffset = 5 6\nBinaryData = False\nElementType = MET_INT\nElementDataFile = LOCAL\n";
        let v = read_volume(&dir.write("e.mha", &mha(header, b"1 -2 3\n4 5 -600000\n"))).unwrap();
        assert_eq!(v.dims, [3, 2, 1]);
        assert_eq!(v.spacing, [2.0, 3.0, 1.0]);
        assert_eq!(v.origin, [5.0, 6.0, 0.0]);
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
            let v = read_volume(&dir.write("t.mha", &mha(&header, &bytes))).unwrap();
            assert_eq!(v.scalars, want, "{ty}");
        }
    }

    #[test]
    fn readers_mha_errors() {
        let dir = TempDir::new("mha");
        let base = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
        let twelve = [1u8; 12];
        let cases: Vec<(&str, Vec<u8>, &str)> = vec![
            (
                "trunc.mha",
                mha(base, &twelve[..7]),
                "truncated MetaImage voxel data: expected 12 bytes, found 7",
            ),
            (
                "ll.mha",
                mha(&base.replace("MET_UCHAR", "MET_LONG_LONG"), &[0; 96]),
                "unsupported scalar type 'MET_LONG_LONG'",
            ),
            (
                "nd4.mha",
                mha(
                    &base
                        .replace("NDims = 3", "NDims = 4")
                        .replace("3 2 2", "3 2 2 2"),
                    &[0; 24],
                ),
                "NDims = 4",
            ),
            (
                "zero.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nElementSpacing = 1 0 1"),
                    &twelve,
                ),
                "spacing along y is 0",
            ),
            (
                "nan.mha",
                mha(
                    &base.replace("MET_UCHAR", "MET_FLOAT"),
                    &[&[0u8, 0, 0xc0, 0x7f][..], &[0; 44]].concat(),
                ),
                "NaN",
            ),
            (
                "nodim.mha",
                mha(&base.replace("DimSize = 3 2 2\n", ""), &twelve),
                "no DimSize",
            ),
            (
                "dimcount.mha",
                mha(&base.replace("3 2 2", "3 2"), &twelve),
                "expected 3 whole numbers",
            ),
            (
                "dimzero.mha",
                mha(&base.replace("3 2 2", "3 0 2"), &twelve),
                "at least 1",
            ),
            (
                "noend.mha",
                b"ObjectType = Image\nNDims = 3\n".to_vec(),
                "no ElementDataFile",
            ),
            (
                "junk.mha",
                vec![0x89, b'P', b'N', b'G', b'\n', 0, 0],
                "not 'Key = Value'",
            ),
            (
                "list.mhd",
                base.replace("LOCAL", "LIST").into_bytes(),
                "several files",
            ),
            (
                "pattern.mhd",
                base.replace("LOCAL", "slice%03d.raw 1 10 1").into_bytes(),
                "several files",
            ),
            (
                "mesh.mha",
                mha(&base.replace("= Image", "= Mesh"), &twelve),
                "ObjectType = Mesh",
            ),
            (
                "bool.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nCompressedData = maybe"),
                    &twelve,
                ),
                "expected True or False",
            ),
            (
                "chan.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nElementNumberOfChannels = 5"),
                    &twelve,
                ),
                "5 channels",
            ),
            (
                "z.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nCompressedData = True"),
                    &[0x78, 0x9c, 1, 2, 3],
                ),
                "decompression failed",
            ),
            (
                "zshort.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nCompressedData = True"),
                    &zlib(&[1; 5]),
                ),
                "expected 12 bytes, found 5",
            ),
            (
                "ascii.mha",
                mha(
                    &base.replace("NDims = 3", "NDims = 3\nBinaryData = False"),
                    b"1 2 3",
                ),
                "found 3 values, expected 12",
            ),
        ];
        for (name, bytes, want) in cases {
            let p = dir.write(name, &bytes);
            let m = msg(read_volume(&p));
            assert!(m.starts_with(&format!("{}: ", p.display())), "{name}: {m}");
            assert!(m.contains(want), "{name}: wanted {want:?} in {m}");
        }

        // A missing data file is named in the message.
        let p = dir.write("missing.mhd", base.replace("LOCAL", "gone.raw").as_bytes());
        let m = msg(read_volume(&p));
        assert!(m.contains("gone.raw: cannot read the file"), "{m}");
        // A short data file too.
        dir.write("short.raw", &[1, 2, 3]);
        let p = dir.write("short.mhd", base.replace("LOCAL", "short.raw").as_bytes());
        let m = msg(read_volume(&p));
        assert!(
            m.contains("short.raw: truncated MetaImage voxel data: expected 12 bytes, found 3"),
            "{m}"
        );
    }

    #[test]
    fn readers_mha_never_panics_on_damaged_files() {
        let dir = TempDir::new("mha");
        let header = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 2\nElementSpacing = 1 1 1\nCompressedData = True\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
        let f = mha(header, &zlib(&[7u8; 24]));
        let p = dir.path().join("x.mha");
        for cut in 0..f.len() {
            std::fs::write(&p, &f[..cut]).unwrap();
            let _ = read_volume(&p);
        }
        for i in 0..f.len() {
            for x in [0u8, b'9', b'-', b' ', b'\n', 0xff] {
                let mut g = f.clone();
                g[i] = x;
                std::fs::write(&p, &g).unwrap();
                if let Ok(v) = read_volume(&p) {
                    v.validate().unwrap();
                }
            }
        }
    }
}
