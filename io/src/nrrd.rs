//! NRRD (`.nrrd` with attached data, `.nhdr` with a detached `data file`) reader,
//! versions NRRD0001 to NRRD0005.
//!
//! * `dimension` 1–3 gives spatial axes (missing ones have size 1). With `dimension` 4 the
//!   first axis holds the 1–4 components of each voxel; with `dimension` 2 or 3 the first
//!   axis is also taken as components when its `kinds` entry is not a spatial kind (e.g.
//!   `RGB-color`, `vector`) or its `space directions` entry is `none`.
//! * Geometry: `space directions` (spacing = vector length, direction = unit vector, so
//!   a column of [`VolumeData::direction`]) and `space origin`; without space
//!   directions, `spacings` (`nan`, "unknown", counts as 1). The `space` name (e.g.
//!   `left-posterior-superior`) is not used: coordinates are kept as written.
//! * `type`: every NRRD spelling of int8/uint8/int16/uint16/int32/uint32/float/double.
//! * `encoding`: `raw`, `gzip`/`gz`, `ascii`/`text`/`txt`, `hex`; `endian` little/big.
//! * `line skip` and `byte skip` (applied after decompression for gzip; `-1` means "the
//!   data is at the end of the file" and needs raw encoding). A `data file` is relative to
//!   the header's folder; `LIST` and numbered file patterns are not supported.

use std::path::Path;

use ferrovol_core::{Direction, ScalarType, Scalars, VolumeData};

use crate::decode::{
    decode_binary, inflate, lookup_type, next_line, numbers, parse_ascii, Fields, Geometry, Layout,
    TypeNames,
};
use crate::ReadError;

const FORMAT: &str = "NRRD";
const SUPPORTED_TYPES: &str =
    "int8, uint8, int16, uint16, int32, uint32, float and double (in any NRRD spelling, e.g. uchar, short, unsigned int)";

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// The scalar type of a `type` field's value (any case and spacing).
fn nrrd_type(name: &str) -> Option<ScalarType> {
    let words: Vec<&str> = name.split_ascii_whitespace().collect();
    lookup_type(TypeNames::Nrrd, &words.join(" ").to_ascii_lowercase())
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Encoding {
    Raw,
    Gzip,
    Ascii,
    Hex,
}

struct Header {
    /// Field name (lower case, spaces collapsed) and value.
    fields: Fields,
    /// Where attached data starts (after the blank line), if the header ended with one.
    data_start: Option<usize>,
}

impl Header {
    fn get(&self, keys: &[&str]) -> Option<&str> {
        self.fields.get(keys).map(|(_, v)| v)
    }
}

fn parse_header(bytes: &[u8]) -> Result<Header, ReadError> {
    let Some((magic, mut pos)) = next_line(bytes, 0) else {
        return Err(bad("the file is empty"));
    };
    let version_ok = magic.len() == 8
        && magic.starts_with(b"NRRD000")
        && magic.get(7).is_some_and(|d| (b'1'..=b'5').contains(d));
    if !version_ok {
        let shown: String = String::from_utf8_lossy(magic).chars().take(40).collect();
        return Err(bad(
            format!("the first line is {shown:?}, not NRRD0001 to NRRD0005; this is not a NRRD file (or a newer version)"),
        ));
    }
    let mut fields = Vec::new();
    let mut line_no = 1;
    while let Some((line, next)) = next_line(bytes, pos) {
        pos = next;
        line_no += 1;
        if line.iter().all(|b| b.is_ascii_whitespace()) {
            return Ok(Header {
                fields: Fields(fields),
                data_start: Some(pos),
            });
        }
        let text = String::from_utf8_lossy(line);
        if text.starts_with('#') {
            continue;
        }
        let field = text.find(": ");
        let keyvalue = text.find(":=");
        match (field, keyvalue) {
            (Some(f), kv) if kv.is_none_or(|kv| f < kv) => {
                let key = text[..f]
                    .split_ascii_whitespace()
                    .collect::<Vec<_>>()
                    .join(" ")
                    .to_ascii_lowercase();
                fields.push((key, text[f + 2..].trim().to_string()));
            }
            (_, Some(_)) => {} // key:=value pairs carry no geometry
            _ => {
                let shown: String = text.chars().take(60).collect();
                return Err(bad(
                    format!("line {line_no} ({shown:?}) is not 'field: value' (attached data must follow a blank line)"),
                ));
            }
        }
    }
    Ok(Header {
        fields: Fields(fields),
        data_start: None,
    })
}

/// Parses a list like `(1,0,0) (0, 2,0) none` into vectors (None for "none").
fn parse_vectors(field: &str, v: &str) -> Result<Vec<Option<Vec<f64>>>, ReadError> {
    let err = |why: &str| bad(format!("{field}: {v:?}: {why}"));
    let mut out = Vec::new();
    let mut rest = v.trim_start();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
        } else if let Some(r) = rest.strip_prefix('(') {
            let close = r
                .find(')')
                .ok_or_else(|| err("a '(' has no matching ')'"))?;
            let nums: Vec<f64> = r[..close]
                .split(',')
                .map(|t| t.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| err("a vector holds something that is not a number"))?;
            out.push(Some(nums));
            rest = r[close + 1..].trim_start();
        } else {
            return Err(err("expected vectors like (1,0,0) or none"));
        }
    }
    Ok(out)
}

/// Parses a NRRD file (`.nrrd`) or a detached header (`.nhdr`) with its data: attached
/// data follows the header in `bytes`; a `data file` field's name is passed to
/// `data_file`, which returns that file's bytes (see [`crate::Format::parse`]).
pub fn parse(
    bytes: &[u8],
    data_file: impl FnOnce(&str) -> Result<Vec<u8>, ReadError>,
) -> Result<VolumeData, ReadError> {
    let Plan {
        layout,
        geometry,
        stored,
        data,
    } = plan(bytes)?;
    let scalars = match data {
        Data::File(f) => {
            let external = data_file(&f)?;
            decode(&external, layout, stored).map_err(|e| e.in_file(Path::new(&f)))?
        }
        Data::Attached(s) => decode(bytes.get(s..).unwrap_or(&[]), layout, stored)?,
    };
    layout.volume(geometry, scalars)
}

/// Where raw (uncompressed binary) data lies, for reading it in place: the header (any
/// prefix of the file holding the whole header) says the data is raw with no line skip.
/// `None` for data that must be decoded (gzip, ASCII, hex, line skip).
pub(crate) fn raw_data(header: &[u8]) -> Result<Option<crate::raw::RawData>, ReadError> {
    use crate::raw::{RawData, RawStart};
    let Plan {
        layout,
        geometry,
        stored,
        data,
    } = plan(header)?;
    if stored.encoding != Encoding::Raw || stored.line_skip != 0 {
        return Ok(None);
    }
    let start = if stored.byte_skip == -1 {
        RawStart::FromEnd
    } else {
        RawStart::At(stored.byte_skip as u64)
    };
    let (file, start) = match data {
        Data::File(f) => (Some(f), start),
        Data::Attached(s) => match start {
            RawStart::At(skip) => (None, RawStart::At(s as u64 + skip)),
            RawStart::FromEnd => (None, RawStart::FromEnd),
        },
    };
    Ok(Some(RawData {
        format: FORMAT,
        layout,
        geometry,
        big_endian: stored.big_endian,
        file,
        start,
    }))
}

/// What a header says about the volume and where its data is.
struct Plan {
    layout: Layout,
    geometry: Geometry,
    stored: Stored,
    data: Data,
}

/// Where the data is: a detached file (as the header names it) or after the header.
enum Data {
    File(String),
    Attached(usize),
}

/// Parses the header and checks what it says.
fn plan(bytes: &[u8]) -> Result<Plan, ReadError> {
    let h = parse_header(bytes)?;
    let need = |keys: &[&str], what: &str| {
        h.get(keys)
            .ok_or_else(|| bad(format!("no '{}' field ({what})", keys[0])))
    };

    let type_name = need(&["type"], "the scalar type")?;
    let ty = nrrd_type(type_name)
        .ok_or_else(|| ReadError::unsupported_type(type_name, SUPPORTED_TYPES))?;
    let dim_text = need(&["dimension"], "the number of axes")?;
    let dimension: usize = dim_text
        .parse()
        .map_err(|_| bad(format!("dimension: {dim_text:?} is not a whole number")))?;
    if !(1..=4).contains(&dimension) {
        return Err(ReadError::unsupported(
            format!("dimension {dimension}; ferrovol reads 1 to 3 spatial axes plus an optional first axis of 1-4 components"),
        ));
    }
    let sizes_text = need(&["sizes"], "the axis sizes")?;
    let sizes: Vec<u64> = numbers(sizes_text, dimension).ok_or_else(|| {
        bad(format!(
            "sizes: {sizes_text:?} is not {dimension} whole numbers"
        ))
    })?;

    let kinds: Option<Vec<String>> = h
        .get(&["kinds"])
        .map(|k| k.split_ascii_whitespace().map(str::to_string).collect());
    if let Some(k) = &kinds {
        if k.len() != dimension {
            return Err(bad(format!(
                "kinds: {} entries for {dimension} axes",
                k.len()
            )));
        }
    }
    let directions = match h.get(&["space directions"]) {
        Some(v) => {
            let d = parse_vectors("space directions", v)?;
            if d.len() != dimension {
                return Err(bad(format!(
                    "space directions: {} entries for {dimension} axes",
                    d.len()
                )));
            }
            Some(d)
        }
        None => None,
    };

    // Which axis, if any, holds components.
    let first_kind = kinds
        .as_ref()
        .and_then(|k| k.first())
        .map(|k| k.to_ascii_lowercase());
    let first_is_domain = matches!(first_kind.as_deref(), Some("domain" | "space" | "time"));
    let first_is_component = first_kind
        .as_deref()
        .is_some_and(|k| !matches!(k, "domain" | "space" | "time" | "???" | "none"));
    let first_dir_none = directions
        .as_ref()
        .and_then(|d| d.first())
        .is_some_and(|d| d.is_none());
    let comp_axis = if dimension == 4 {
        if first_is_domain {
            return Err(ReadError::unsupported(
                "a 4D image whose first axis is spatial (a time series?); extract one 3D volume first (e.g. with unu slice)",
            ));
        }
        true
    } else {
        dimension >= 2 && (first_is_component || first_dir_none)
    };
    let components = if comp_axis { sizes[0] } else { 1 };
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(format!(
            "{components} components per voxel on the first axis; ferrovol renders 1 to 4"
        )));
    }
    let first_spatial = usize::from(comp_axis);
    let spatial: Vec<usize> = (first_spatial..dimension).collect();
    let mut dims = [1u64; 3];
    for (i, &a) in spatial.iter().enumerate() {
        dims[i] = sizes[a];
    }

    // Geometry.
    let mut geometry = Geometry::default();
    let Geometry {
        spacing,
        origin,
        direction,
    } = &mut geometry;
    if let Some(dirs) = &directions {
        let mut have = [false; 3];
        for (i, &a) in spatial.iter().enumerate() {
            let v = dirs
                .get(a)
                .cloned()
                .flatten()
                .ok_or_else(|| bad(format!("space directions: spatial axis {a} is 'none'")))?;
            if v.len() > 3 {
                return Err(ReadError::unsupported(
                    format!("a {}-dimensional space (space directions); ferrovol places volumes in 3D space", v.len()),
                ));
            }
            let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !len.is_finite() || len <= 0.0 {
                return Err(bad(
                    format!("space directions: axis {a} has the zero or invalid vector {v:?}, so its spacing would be {len}"),
                ));
            }
            spacing[i] = len;
            for (r, row) in direction.iter_mut().enumerate() {
                row[i] = v.get(r).copied().unwrap_or(0.0) / len;
            }
            have[i] = true;
        }
        complete_direction(direction, have);
    } else if let Some(v) = h.get(&["spacings"]) {
        let s: Vec<f64> = numbers(v, dimension)
            .ok_or_else(|| bad(format!("spacings: {v:?} is not {dimension} numbers")))?;
        for (i, &a) in spatial.iter().enumerate() {
            spacing[i] = if s[a].is_nan() { 1.0 } else { s[a] };
        }
    }
    if let Some(v) = h.get(&["space origin"]) {
        let o = parse_vectors("space origin", v)?;
        match o.as_slice() {
            [Some(o)] if o.len() <= 3 => origin[..o.len()].copy_from_slice(o),
            _ => {
                return Err(bad(format!(
                    "space origin: {v:?} is not one vector like (0,0,0)"
                )))
            }
        }
    }

    // Encoding and byte order.
    let enc_text = need(&["encoding"], "how the data is stored, e.g. raw or gzip")?;
    let encoding = match enc_text.to_ascii_lowercase().as_str() {
        "raw" => Encoding::Raw,
        "gzip" | "gz" => Encoding::Gzip,
        "ascii" | "text" | "txt" => Encoding::Ascii,
        "hex" => Encoding::Hex,
        "bzip2" | "bz2" | "zstd" => {
            return Err(ReadError::unsupported(
                format!("encoding {enc_text}; re-save with raw or gzip encoding (e.g. unu save -f nrrd -e gzip)"),
            ))
        }
        other => return Err(bad(format!("encoding: unknown encoding {other:?}"))),
    };
    let big_endian = match h.get(&["endian"]).map(|e| e.to_ascii_lowercase()) {
        Some(e) if e == "little" => false,
        Some(e) if e == "big" => true,
        Some(e) => return Err(bad(format!("endian: {e:?}; expected little or big"))),
        None if ty.size_bytes() > 1 && encoding != Encoding::Ascii => {
            return Err(bad(
                "no 'endian' field, which multi-byte binary data needs (add 'endian: little' or 'endian: big')",
            ))
        }
        None => false,
    };
    let line_skip: usize = match h.get(&["line skip", "lineskip"]) {
        Some(v) => v
            .parse()
            .map_err(|_| bad(format!("line skip: {v:?} is not a whole number")))?,
        None => 0,
    };
    let byte_skip: i64 = match h.get(&["byte skip", "byteskip"]) {
        Some(v) => v
            .parse()
            .map_err(|_| bad(format!("byte skip: {v:?} is not a whole number")))?,
        None => 0,
    };
    if byte_skip < -1 || (byte_skip == -1 && encoding != Encoding::Raw) {
        return Err(bad(format!(
            "byte skip {byte_skip}: only -1 (with raw encoding) or a byte count is allowed"
        )));
    }
    let layout = Layout::new(FORMAT, dims, components, ty)?;

    // Where the data is.
    let stored = Stored {
        encoding,
        big_endian,
        line_skip,
        byte_skip,
    };
    let data = match h.get(&["data file", "datafile"]) {
        Some(f) => {
            let first = f.split_ascii_whitespace().next().unwrap_or("");
            if first == "LIST" || f.contains('%') {
                return Err(ReadError::unsupported(format!(
                    "data file: {f}: data split over several files; join them into one file (e.g. with unu join, then unu save)"
                )));
            }
            Data::File(f.to_string())
        }
        None => match h.data_start {
            Some(s) => Data::Attached(s),
            None => {
                return Err(bad(
                    "no 'data file' field and no blank line followed by data; a detached header (.nhdr) must name its data file",
                ))
            }
        },
    };
    Ok(Plan {
        layout,
        geometry,
        stored,
        data,
    })
}

/// How the data is stored: the header's `encoding`, `endian`, `line skip` and
/// `byte skip` fields.
#[derive(Clone, Copy)]
struct Stored {
    encoding: Encoding,
    big_endian: bool,
    line_skip: usize,
    byte_skip: i64,
}

/// The values in `data`: skips lines, then bytes (after decompression for gzip), then
/// converts.
fn decode(mut data: &[u8], layout: Layout, stored: Stored) -> Result<Scalars, ReadError> {
    let Stored {
        encoding,
        big_endian,
        line_skip,
        byte_skip,
    } = stored;
    for _ in 0..line_skip {
        data = match data.iter().position(|&b| b == b'\n') {
            Some(i) => data.get(i + 1..).unwrap_or(&[]),
            None => {
                return Err(ReadError::truncated(
                    format!("NRRD data (line skip {line_skip})"),
                    line_skip,
                    0,
                ))
            }
        };
    }
    let nbytes = layout.nbytes;
    let truncated = |found: usize| ReadError::truncated("NRRD data", nbytes, found);
    let skip = usize::try_from(byte_skip.max(0)).unwrap_or(usize::MAX);
    Ok(match encoding {
        Encoding::Raw => {
            let start = if byte_skip == -1 {
                data.len()
                    .checked_sub(nbytes)
                    .ok_or_else(|| truncated(data.len()))?
            } else {
                skip
            };
            let d = data.get(start..).unwrap_or(&[]);
            let d = d.get(..nbytes).ok_or_else(|| truncated(d.len()))?;
            decode_binary(d, layout.ty, big_endian)
        }
        Encoding::Gzip => {
            let limit = nbytes.saturating_add(skip);
            let out = inflate("gzip NRRD data", data, limit)?;
            let d = out.get(skip..).unwrap_or(&[]);
            let d = d.get(..nbytes).ok_or_else(|| truncated(d.len()))?;
            decode_binary(d, layout.ty, big_endian)
        }
        Encoding::Ascii => {
            let d = data.get(skip..).unwrap_or(&[]);
            let text = String::from_utf8_lossy(d);
            parse_ascii("ASCII NRRD data", &text, layout.ty, layout.count)?
        }
        Encoding::Hex => {
            let d = data.get(skip..).unwrap_or(&[]);
            let raw = decode_hex(d, nbytes)?;
            decode_binary(&raw, layout.ty, big_endian)
        }
    })
}

/// Fills the direction columns of axes that have none (images with fewer than 3 spatial
/// axes) so that the matrix stays non-singular: the cross product of the other two
/// columns, or a unit axis.
fn complete_direction(d: &mut Direction, have: [bool; 3]) {
    let col = |d: &[[f64; 3]; 3], j: usize| [d[0][j], d[1][j], d[2][j]];
    for j in 0..3 {
        if have[j] {
            continue;
        }
        let a = col(d, (j + 1) % 3);
        let b = col(d, (j + 2) % 3);
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        if len > 1e-9 && len.is_finite() {
            for (row, x) in d.iter_mut().zip(c) {
                row[j] = x / len;
            }
        } else {
            // Pick the unit axis least aligned with the existing columns.
            let mut best = (f64::INFINITY, 0);
            for (e, row) in d.iter().enumerate() {
                let score: f64 = (0..3).filter(|&k| k != j).map(|k| row[k].abs()).sum();
                if score < best.0 {
                    best = (score, e);
                }
            }
            for (r, row) in d.iter_mut().enumerate() {
                row[j] = if r == best.1 { 1.0 } else { 0.0 };
            }
        }
    }
}

/// Decodes hex text (two digits per byte, whitespace ignored) into `nbytes` bytes.
fn decode_hex(text: &[u8], nbytes: usize) -> Result<Vec<u8>, ReadError> {
    let mut out = Vec::with_capacity(nbytes.min(text.len() / 2 + 1));
    let mut hi: Option<u8> = None;
    for (i, &c) in text.iter().enumerate() {
        if out.len() == nbytes {
            break;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        let v = (c as char).to_digit(16).ok_or_else(|| {
            ReadError::corrupt(
                "hex NRRD data",
                format!(
                    "{:?} at byte {i} is not a hex digit (fix or re-export the data)",
                    c as char
                ),
            )
        })? as u8;
        match hi.take() {
            None => hi = Some(v),
            Some(h) => out.push(h << 4 | v),
        }
    }
    if out.len() < nbytes {
        return Err(ReadError::truncated("hex NRRD data", nbytes, out.len()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::nrrd_type;
    use crate::test_util::{assert_geometry, check_errors, gzip, never_panics};
    use crate::{no_data_file, ReadError};
    use ferrovol_core::{ScalarType, Scalars, VolumeData};

    fn parse(bytes: &[u8]) -> Result<VolumeData, ReadError> {
        super::parse(bytes, no_data_file)
    }

    fn nrrd(header: &str, data: &[u8]) -> Vec<u8> {
        let mut f = header.trim_end_matches('\n').as_bytes().to_vec();
        f.extend_from_slice(b"\n\n");
        f.extend_from_slice(data);
        f
    }

    fn short_data(be: bool) -> (Vec<i16>, Vec<u8>) {
        let vals: Vec<i16> = (0..12).map(|i| i * 300 - 1000).collect();
        let bytes = vals
            .iter()
            .flat_map(|v| if be { v.to_be_bytes() } else { v.to_le_bytes() })
            .collect();
        (vals, bytes)
    }

    const SHORT: &str = "NRRD0004\n# Complete NRRD file format specification at:\n# http://teem.sourceforge.net/nrrd/format.html\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 3 2 2\nspace directions: (0,0.5,0) (-1, 0, 0) (0,0,2)\nkinds: domain domain domain\nendian: little\nencoding: raw\nspace origin: (10,20,30)\nDICOM:=whatever: stuff\n";

    #[test]
    fn readers_nrrd_raw_short_space_directions() {
        let (vals, bytes) = short_data(false);
        let v = parse(&nrrd(SHORT, &bytes)).unwrap();
        assert_geometry(&v, [3, 2, 2], [0.5, 1.0, 2.0], [10.0, 20.0, 30.0]);
        assert_eq!(
            v.direction,
            [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(v.scalars, Scalars::I16(vals));
    }

    #[test]
    fn readers_nrrd_gzip_big_endian_float_spacings() {
        let vals: Vec<f32> = (0..12).map(|i| i as f32 * 0.75).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_be_bytes()).collect();
        let header = "NRRD0005\ntype: float\ndimension: 3\nsizes: 3 2 2\nspacings: 0.5 1.5 3\nendian: big\nencoding: gz";
        let v = parse(&nrrd(header, &gzip(&bytes))).unwrap();
        assert_geometry(&v, [3, 2, 2], [0.5, 1.5, 3.0], [0.0; 3]);
        assert_eq!(v.scalars, Scalars::F32(vals));
    }

    #[test]
    fn readers_nrrd_ascii_and_hex() {
        let header = "NRRD0001\ntype: unsigned char\ndimension: 3\nsizes: 2 2 1\nencoding: ascii";
        let v = parse(&nrrd(header, b"0 1\n254 255\n")).unwrap();
        assert_eq!(v.dims, [2, 2, 1]);
        assert_eq!(v.scalars, Scalars::U8(vec![0, 1, 254, 255]));

        let header =
            "NRRD0004\ntype: uint16_t\ndimension: 2\nsizes: 2 1\nendian: big\nencoding: hex";
        let v = parse(&nrrd(header, b"0102\nFFfe\n")).unwrap();
        assert_eq!(v.dims, [2, 1, 1]);
        assert_eq!(v.scalars, Scalars::U16(vec![0x0102, 0xfffe]));
    }

    #[test]
    fn readers_nhdr_detached_with_skips() {
        let (vals, bytes) = short_data(true);
        let mut raw = b"first line\nsecond line\nXYZ".to_vec();
        raw.extend(&bytes);
        let mut z = vec![0u8; 5];
        z.extend(short_data(false).1);
        let z = gzip(&z);
        let files = |name: &str| match name {
            "sub/vol.raw" => Ok(raw.clone()),
            "vol.raw.gz" => Ok(z.clone()),
            _ => no_data_file(name),
        };
        let header = SHORT.replace("endian: little", "endian: big")
            + "data file: sub/vol.raw\nline skip: 2\nbyte skip: 3\n";
        let v = super::parse(header.as_bytes(), files).unwrap();
        assert_eq!(v.scalars, Scalars::I16(vals.clone()));

        // byte skip -1: the data is at the end of the file; old "datafile" spelling.
        let header = SHORT.replace("endian: little", "endian: big")
            + "datafile: sub/vol.raw\nbyteskip: -1\n";
        let v = super::parse(header.as_bytes(), files).unwrap();
        assert_eq!(v.scalars, Scalars::I16(vals.clone()));

        // gzip data file; byte skip applies after decompression.
        let header = SHORT.replace("encoding: raw", "encoding: gzip")
            + "data file: vol.raw.gz\nbyte skip: 5\n";
        let v = super::parse(header.as_bytes(), files).unwrap();
        assert_eq!(v.scalars, Scalars::I16(vals));

        // A problem in the data file names it as the header does.
        let header = SHORT.to_string() + "data file: sub/vol.raw\nbyte skip: 30\n";
        let m = super::parse(header.as_bytes(), files)
            .unwrap_err()
            .to_string();
        assert!(
            m.starts_with("sub/vol.raw: truncated NRRD data: expected 24 bytes, found 20"),
            "{m}"
        );
    }

    #[test]
    fn readers_nrrd_components() {
        let rgb: Vec<u8> = (0..36).collect();
        let header = "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 3 2 2\nkinds: RGB-color domain domain domain\nspace directions: none (1,0,0) (0,1,0) (0,0,1)\nspacings: nan 1 1 1\nencoding: raw";
        let v = parse(&nrrd(header, &rgb)).unwrap();
        assert_eq!(v.dims, [3, 2, 2]);
        assert_eq!(v.components, 3);
        assert_eq!(v.scalars, Scalars::U8(rgb.clone()));

        // dimension 3 with a non-spatial first axis: a 2D image with components.
        let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 3\nspace dimension: 3\nspace directions: none (0,2,0) (2,0,0)\nspace origin: (1,2,3)\nencoding: raw";
        let v = parse(&nrrd(header, &rgb)).unwrap();
        assert_eq!(v.dims, [4, 3, 1]);
        assert_eq!(v.components, 3);
        assert_eq!(v.spacing, [2.0, 2.0, 1.0]);
        assert_eq!(v.origin, [1.0, 2.0, 3.0]);
        // The missing third column completes a non-singular matrix.
        assert_eq!(
            v.direction,
            [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]
        );
    }

    #[test]
    fn readers_nrrd_type_spellings() {
        let cases = [
            (ScalarType::I8, &["signed char", "int8", "int8_t"][..]),
            (
                ScalarType::U8,
                &["uchar", "unsigned char", "uint8", "uint8_t"][..],
            ),
            (
                ScalarType::I16,
                &[
                    "short",
                    "short int",
                    "signed short",
                    "signed short int",
                    "int16",
                    "int16_t",
                ][..],
            ),
            (
                ScalarType::U16,
                &[
                    "ushort",
                    "unsigned short",
                    "unsigned short int",
                    "uint16",
                    "uint16_t",
                ][..],
            ),
            (
                ScalarType::I32,
                &["int", "signed int", "int32", "int32_t"][..],
            ),
            (
                ScalarType::U32,
                &["uint", "unsigned int", "uint32", "uint32_t"][..],
            ),
            (ScalarType::F32, &["float"][..]),
            (ScalarType::F64, &["double"][..]),
        ];
        for (ty, names) in cases {
            for n in names {
                assert_eq!(nrrd_type(n), Some(ty), "{n}");
            }
        }
        for n in [
            "longlong",
            "long long int",
            "int64",
            "uint64_t",
            "ulonglong",
            "block",
            "char",
        ] {
            assert_eq!(nrrd_type(n), None, "{n}");
        }
    }

    #[test]
    fn readers_nrrd_errors() {
        let (_, bytes) = short_data(false);
        let s = |from: &str, to: &str| SHORT.replace(from, to);
        let cases: Vec<(&str, Vec<u8>, &str)> = vec![
            ("trunc.nrrd", nrrd(SHORT, &bytes[..10]), "truncated NRRD data: expected 24 bytes, found 10"),
            ("gztrunc.nrrd", nrrd(&s("raw", "gzip"), &gzip(&bytes[..10])), "expected 24 bytes, found 10"),
            ("i64.nrrd", nrrd(&s("type: short", "type: long long"), &[0; 96]), "unsupported scalar type 'long long'"),
            ("dim5.nrrd", nrrd(&s("dimension: 3", "dimension: 5"), &bytes), "dimension 5"),
            ("sizes.nrrd", nrrd(&s("sizes: 3 2 2", "sizes: 3 2"), &bytes), "sizes"),
            ("endian.nrrd", nrrd(&s("endian: little\n", ""), &bytes), "no 'endian' field"),
            ("magic.nrrd", nrrd(&s("NRRD0004", "NRRD0009"), &bytes), "not NRRD0001 to NRRD0005"),
            ("zerodir.nrrd", nrrd(&s("(-1, 0, 0)", "(0,0,0)"), &bytes), "zero or invalid vector"),
            ("zerosp.nrrd", nrrd("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 1\nspacings: 1 0 1\nencoding: raw", &[1, 2, 3, 4]), "spacing along y is 0"),
            ("negsp.nrrd", nrrd("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 1\nspacings: -1 1 1\nencoding: raw", &[1, 2, 3, 4]), "spacing along x is -1"),
            ("nan.nrrd", nrrd("NRRD0004\ntype: double\ndimension: 1\nsizes: 2\nendian: little\nencoding: raw", &[&1f64.to_le_bytes()[..], &f64::NAN.to_le_bytes()[..]].concat()), "NaN"),
            ("bz.nrrd", nrrd(&s("raw", "bzip2"), &bytes), "bzip2"),
            ("list.nhdr", (s("encoding", "data file: LIST\nencoding")).into_bytes(), "several files"),
            ("nodata.nhdr", SHORT.trim_end().as_bytes().to_vec(), "no 'data file' field"),
            ("missing.nhdr", (SHORT.to_string() + "data file: nothere.raw\n").into_bytes(), "\"nothere.raw\", which was not given"),
            ("time.nrrd", nrrd("NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 2 2 2\nkinds: domain domain domain time\nencoding: raw", &[0; 16]), "time series"),
            ("comp5.nrrd", nrrd("NRRD0004\ntype: uchar\ndimension: 4\nsizes: 5 1 1 1\nencoding: raw", &[0; 5]), "5 components"),
            ("vec.nrrd", nrrd(&s("(0,0,2)", "(0,0,2"), &bytes), "no matching ')'"),
            ("vec2.nrrd", nrrd(&s("(0,0.5,0)", "(0,0.5,0"), &bytes), "not a number"),
            ("ascii.nrrd", nrrd(&s("raw", "ascii"), b"1 2 3 x"), "'x' is not a valid int16"),
            ("hex.nrrd", nrrd(&s("raw", "hex"), b"01zz"), "not a hex digit"),
            ("noblank.nrrd", b"NRRD0004\ntype: uchar\nthis is data".to_vec(), "not 'field: value'"),
            ("skip.nrrd", nrrd(&(SHORT.to_string() + "byte skip: -1\n").replace("raw", "gzip"), &gzip(&bytes)), "byte skip -1"),
            ("empty.nrrd", Vec::new(), "empty"),
        ];
        check_errors(parse, &cases);
    }

    /// 10^12 voxels of double (8 TB) in a few bytes: an error, not an allocation.
    #[test]
    fn readers_nrrd_absurd_size_fails_before_allocating() {
        let header =
            "NRRD0004\ntype: double\ndimension: 3\nsizes: 10000 10000 10000\nendian: little";
        let cases = [
            (
                "raw",
                nrrd(&format!("{header}\nencoding: raw"), &[0; 16]),
                "expected 8000000000000 bytes, found 16",
            ),
            (
                "gzip",
                nrrd(&format!("{header}\nencoding: gzip"), &gzip(&[0; 16])),
                "expected 8000000000000 bytes, found 16",
            ),
            (
                "ascii",
                nrrd(&format!("{header}\nencoding: ascii"), b"1 2"),
                "found 2 values, expected 1000000000000",
            ),
            (
                "hex",
                nrrd(&format!("{header}\nencoding: hex"), b"0102"),
                "expected 8000000000000 bytes, found 2",
            ),
        ];
        check_errors(parse, &cases);
    }

    #[test]
    fn readers_nrrd_never_panics_on_damaged_files() {
        let (_, bytes) = short_data(false);
        let f = nrrd(&SHORT.replace("raw", "gzip"), &gzip(&bytes));
        never_panics(
            parse,
            &f,
            &[0, b'9', b'-', b' ', b'\n', b'(', b')', b',', 0xff],
        );
    }
}
