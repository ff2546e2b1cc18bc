//! VTK XML ImageData (`.vti`) reader.
//!
//! Reads `WholeExtent`, `Origin`, `Spacing` and the optional VTK 9 `Direction` of
//! `<ImageData>`, and one data array of its single `<Piece>`:
//!
//! * from `<PointData>`: the array named by its `Scalars` attribute, else the first array;
//! * only if there is no point data array, from `<CellData>` the same way. Cell values
//!   are then treated as point samples at the cell centres: the volume gets the cell
//!   dimensions (`max(extent span, 1)` per axis) and its origin moves half a spacing
//!   along every axis that has cells.
//!
//! The first point of the extent (which need not start at 0) becomes the volume's
//! origin: `origin + direction · (spacing ⊙ extent_min)`.
//!
//! Data formats: `format="ascii"`, `format="binary"` (base64 with a `UInt32` or `UInt64`
//! header, `header_type`) and `format="appended"` with `<AppendedData encoding="raw">` or
//! `encoding="base64"`; binary and appended data may be compressed with
//! `compressor="vtkZLibDataCompressor"`; both byte orders. The raw appended section is not
//! XML: only the part of the file before it goes to the XML parser, and the data is
//! located by byte offset after the `_` marker.

use ferrovol_core::VolumeData;
use quick_xml::events::{BytesStart, Event};

use crate::base64::{Base64, TakeError};
use crate::decode::{
    decode_binary, inflate, lookup_type, numbers, parse_ascii, Geometry, Layout, TypeNames,
};
use crate::ReadError;

const FORMAT: &str = "VTK ImageData (.vti)";
const SUPPORTED_TYPES: &str =
    "Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32 and Float64 (also the legacy names char, unsigned_char, short, unsigned_short, int, unsigned_int, float, double)";

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// A `<DataArray>` of the point or cell data, with its inline text.
#[derive(Debug, Default)]
struct ArrayDesc {
    name: String,
    type_name: String,
    components: String,
    format: String,
    offset: Option<String>,
    text: String,
}

/// What the parser keeps of a `<PointData>` or `<CellData>` section: the array named by
/// the `Scalars` attribute and the first array (at most two arrays; others are skipped).
#[derive(Debug, Default)]
struct Section {
    scalars: Option<String>,
    kept: Vec<ArrayDesc>,
}

impl Section {
    fn wants(&self, name: &str) -> bool {
        self.kept.is_empty()
            || (self.scalars.as_deref() == Some(name) && !self.kept.iter().any(|a| a.name == name))
    }
    fn chosen(self) -> Option<ArrayDesc> {
        let scalars = self.scalars;
        let mut kept = self.kept;
        let i = kept
            .iter()
            .position(|a| Some(a.name.as_str()) == scalars.as_deref())
            .unwrap_or(0);
        (i < kept.len()).then(|| kept.swap_remove(i))
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Which {
    Point,
    Cell,
}

#[derive(Default)]
struct Header {
    saw_vtkfile: bool,
    file_type: Option<String>,
    byte_order: Option<String>,
    header_type: Option<String>,
    compressor: Option<String>,
    whole_extent: Option<String>,
    origin: Option<String>,
    spacing: Option<String>,
    direction: Option<String>,
    pieces: Vec<Option<String>>,
    point: Section,
    cell: Section,
    appended_encoding: Option<String>,
    saw_appended: bool,
}

fn attributes(e: &BytesStart) -> Result<Vec<(String, String)>, ReadError> {
    let mut out = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| bad(format!("malformed XML attribute: {err}")))?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a
            .unescape_value()
            .map_err(|err| bad(format!("malformed value of XML attribute {key}: {err}")))?
            .into_owned();
        out.push((key, value));
    }
    Ok(out)
}

fn get(attrs: &[(String, String)], key: &str) -> Option<String> {
    attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone())
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn rfind(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).rposition(|w| w == needle)
}

/// Parses a `.vti` file from its bytes.
pub fn parse(bytes: &[u8]) -> Result<VolumeData, ReadError> {
    // The XML part ends with the <AppendedData ...> start tag, if there is one; what
    // follows it may be raw binary.
    let appended_tag = find(bytes, b"<AppendedData");
    let xml_end = match appended_tag {
        Some(p) => match bytes
            .get(p..)
            .and_then(|rest| rest.iter().position(|&b| b == b'>'))
        {
            Some(q) => p + q + 1,
            None => return Err(bad("the <AppendedData> tag is not closed with '>'")),
        },
        None => bytes.len(),
    };
    let xml = bytes.get(..xml_end).unwrap_or(bytes);
    let xml = std::str::from_utf8(xml).map_err(|e| {
        bad(format!(
            "the XML is not UTF-8 text (byte {}); is this really a .vti file?",
            e.valid_up_to()
        ))
    })?;
    let h = parse_xml(xml)?;

    // The VTKFile element.
    if !h.saw_vtkfile {
        return Err(bad(
            "no <VTKFile> element; this is not a VTK XML file (save it from VTK or ParaView as .vti)",
        ));
    }
    match h.file_type.as_deref() {
        Some("ImageData") => {}
        Some(other) => {
            return Err(ReadError::unsupported(
                format!(
                    "the file holds VTK {other} data, not ImageData; resample it to an image (e.g. ParaView's Resample To Image) and save as .vti"
                ),
            ))
        }
        None => return Err(bad("the <VTKFile> element has no type attribute")),
    }
    let big_endian = flag("byte_order", &h.byte_order, ["LittleEndian", "BigEndian"])?;
    let header_u64 = flag("header_type", &h.header_type, ["UInt32", "UInt64"])?;
    let compressed = match h.compressor.as_deref() {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(other) => {
            return Err(ReadError::unsupported(
                format!(
                    "compressor {other}; only vtkZLibDataCompressor (zlib) is supported (save the file again with ZLib compression or none)"
                ),
            ))
        }
    };

    let binary = Binary {
        header_u64,
        big_endian,
        compressed,
    };

    // Geometry.
    let whole = h
        .whole_extent
        .as_deref()
        .ok_or_else(|| bad("<ImageData> has no WholeExtent attribute"))?;
    let extent = parse_extent("WholeExtent", whole)?;
    match h.pieces.len() {
        0 => return Err(bad("<ImageData> has no <Piece> element")),
        1 => {}
        n => {
            return Err(ReadError::unsupported(
                format!("{n} pieces in one file; save the image as a single piece (ParaView: Merge Blocks, then save as .vti)"),
            ))
        }
    }
    if let Some(Some(piece)) = h.pieces.first() {
        let pe = parse_extent("Piece Extent", piece)?;
        if pe != extent {
            return Err(ReadError::unsupported(
                format!(
                    "the piece's Extent {pe:?} differs from the WholeExtent {extent:?} (part of a parallel .pvti dataset?); load the .pvti in ParaView and save it as one .vti"
                ),
            ));
        }
    }
    let mut geometry = Geometry::default();
    if let Some(s) = &h.origin {
        geometry.origin = vec3("Origin", s)?;
    }
    if let Some(s) = &h.spacing {
        geometry.spacing = vec3("Spacing", s)?;
    }
    if let Some(s) = &h.direction {
        let v: Vec<f64> = numbers(s, 9).ok_or_else(|| {
            bad(format!(
                "Direction=\"{s}\" is not 9 numbers (a row-major 3x3 matrix)"
            ))
        })?;
        geometry.direction = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
    }

    let appended_encoding = match (h.saw_appended, h.appended_encoding.as_deref()) {
        (false, _) => None,
        (true, Some("raw")) => Some(Encoding::Raw),
        (true, Some("base64")) => Some(Encoding::Base64),
        (true, None) => {
            return Err(bad(
                "<AppendedData> has no encoding attribute (raw or base64)",
            ))
        }
        (true, Some(other)) => {
            return Err(bad(format!(
                "<AppendedData encoding=\"{other}\">; expected raw or base64"
            )))
        }
    };

    // The array.
    let Header { point, cell, .. } = h;
    let (which, array) = match point.chosen() {
        Some(a) => (Which::Point, a),
        None => match cell.chosen() {
            Some(a) => (Which::Cell, a),
            None => {
                return Err(bad(
                    "the piece has no <DataArray> in <PointData> or <CellData>; there is nothing to render",
                ))
            }
        },
    };
    let what = format!("DataArray '{}'", array.name);
    let ty = lookup_type(TypeNames::Vti, &array.type_name)
        .ok_or_else(|| ReadError::unsupported_type(&array.type_name, SUPPORTED_TYPES))?;
    let components: u64 = if array.components.is_empty() {
        1
    } else {
        array.components.trim().parse().map_err(|_| {
            bad(format!(
                "{what}: NumberOfComponents=\"{}\" is not a number",
                array.components
            ))
        })?
    };
    if !(1..=4).contains(&components) {
        return Err(ReadError::unsupported(
            format!(
                "{what} has {components} components; ferrovol renders 1 to 4 (extract the components you need, e.g. with ParaView's Calculator)"
            ),
        ));
    }

    let mut dims = [0u64; 3];
    let mut first = [0.0f64; 3];
    for a in 0..3 {
        let span = (extent[2 * a + 1] as i128) - (extent[2 * a] as i128);
        let n = match which {
            Which::Point => span + 1,
            Which::Cell => span.max(1),
        };
        dims[a] = u64::try_from(n).unwrap_or(u64::MAX);
        let half = if which == Which::Cell && span > 0 {
            0.5
        } else {
            0.0
        };
        first[a] = geometry.spacing[a] * (extent[2 * a] as f64 + half);
    }
    let layout = Layout::new(FORMAT, dims, components, ty)?;
    let d = geometry.direction;
    for (r, o) in geometry.origin.iter_mut().enumerate() {
        *o += d[r][0] * first[0] + d[r][1] * first[1] + d[r][2] * first[2];
    }

    let scalars = match array.format.as_str() {
        "ascii" => parse_ascii(&format!("ascii {what}"), &array.text, ty, layout.count)?,
        "binary" => {
            let mut src = Source::Base64(Base64::new(array.text.as_bytes()));
            let what = format!("binary (base64) {what}");
            let raw = read_binary(&what, &mut src, binary, layout.nbytes)?;
            decode_binary(&raw, ty, big_endian)
        }
        "appended" => {
            let encoding = appended_encoding.ok_or_else(|| {
                bad(format!(
                    "{what} is format=\"appended\" but the file has no <AppendedData> section"
                ))
            })?;
            let offset = array.offset.as_deref().ok_or_else(|| {
                bad(format!(
                    "{what} is format=\"appended\" but has no offset attribute"
                ))
            })?;
            let offset: usize = offset.trim().parse().map_err(|_| {
                bad(format!(
                    "{what}: offset=\"{offset}\" is not a non-negative integer"
                ))
            })?;
            let data = appended_section(bytes, xml_end)?;
            let what = format!("appended data of {what}");
            let rest = data
                .get(offset..)
                .ok_or_else(|| ReadError::truncated(&what, offset.saturating_add(1), data.len()))?;
            let mut src = match encoding {
                Encoding::Raw => Source::Raw { data: rest, pos: 0 },
                Encoding::Base64 => Source::Base64(Base64::new(rest)),
            };
            let raw = read_binary(&what, &mut src, binary, layout.nbytes)?;
            decode_binary(&raw, ty, big_endian)
        }
        other => {
            return Err(bad(format!(
                "{what} has format=\"{other}\"; expected ascii, binary or appended"
            )))
        }
    };

    layout.volume(geometry, scalars)
}

/// An attribute with two values: false for `off` (also where the attribute is missing),
/// true for `on`.
fn flag(attr: &str, value: &Option<String>, [off, on]: [&str; 2]) -> Result<bool, ReadError> {
    match value.as_deref() {
        None => Ok(false),
        Some(v) if v == off => Ok(false),
        Some(v) if v == on => Ok(true),
        Some(v) => Err(bad(format!("{attr}=\"{v}\"; expected {off} or {on}"))),
    }
}

/// How binary arrays are stored (attributes of `<VTKFile>`).
#[derive(Clone, Copy)]
struct Binary {
    /// Block headers are UInt64, not UInt32.
    header_u64: bool,
    big_endian: bool,
    /// vtkZLibDataCompressor blocks.
    compressed: bool,
}

#[derive(Clone, Copy)]
enum Encoding {
    Raw,
    Base64,
}

/// Parses the XML part of the file (everything up to and including the
/// `<AppendedData>` start tag).
fn parse_xml(xml: &str) -> Result<Header, ReadError> {
    let mut h = Header::default();
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut section: Option<Which> = None;
    // The array being read, if it is one we keep, and how deep we are in its children
    // (`<InformationKey>` elements, whose text is not data).
    let mut current: Option<ArrayDesc> = None;
    let mut nested = 0usize;
    loop {
        let event = reader.read_event().map_err(|e| {
            bad(format!(
                "XML syntax error near byte {}: {e}",
                reader.error_position()
            ))
        })?;
        match event {
            Event::Eof => break,
            Event::Start(_) if current.is_some() => nested += 1,
            Event::Empty(_) if current.is_some() => {}
            Event::End(_) if current.is_some() && nested > 0 => nested -= 1,
            Event::Start(ref e) | Event::Empty(ref e) => {
                let empty = matches!(event, Event::Empty(_));
                let attrs = attributes(e)?;
                match e.name().as_ref() {
                    b"VTKFile" => {
                        h.saw_vtkfile = true;
                        h.file_type = get(&attrs, "type");
                        h.byte_order = get(&attrs, "byte_order");
                        h.header_type = get(&attrs, "header_type");
                        h.compressor = get(&attrs, "compressor");
                    }
                    b"ImageData" => {
                        h.whole_extent = get(&attrs, "WholeExtent");
                        h.origin = get(&attrs, "Origin");
                        h.spacing = get(&attrs, "Spacing");
                        h.direction = get(&attrs, "Direction");
                    }
                    b"Piece" => h.pieces.push(get(&attrs, "Extent")),
                    b"PointData" | b"CellData" if !empty => {
                        let which = if e.name().as_ref() == b"PointData" {
                            Which::Point
                        } else {
                            Which::Cell
                        };
                        let sec = match which {
                            Which::Point => &mut h.point,
                            Which::Cell => &mut h.cell,
                        };
                        sec.scalars = get(&attrs, "Scalars");
                        section = Some(which);
                    }
                    b"DataArray" => {
                        if let Some(which) = section {
                            let sec = match which {
                                Which::Point => &mut h.point,
                                Which::Cell => &mut h.cell,
                            };
                            let name = get(&attrs, "Name").unwrap_or_default();
                            if sec.wants(&name) {
                                let desc = ArrayDesc {
                                    name,
                                    type_name: get(&attrs, "type").unwrap_or_default(),
                                    components: get(&attrs, "NumberOfComponents")
                                        .unwrap_or_default(),
                                    format: get(&attrs, "format").unwrap_or_default(),
                                    offset: get(&attrs, "offset"),
                                    text: String::new(),
                                };
                                if empty {
                                    sec.kept.push(desc);
                                } else {
                                    current = Some(desc);
                                }
                            }
                        }
                    }
                    b"AppendedData" => {
                        h.saw_appended = true;
                        h.appended_encoding = get(&attrs, "encoding");
                    }
                    _ => {}
                }
            }
            Event::End(ref e) => match e.name().as_ref() {
                b"PointData" | b"CellData" => section = None,
                b"DataArray" => {
                    if let (Some(desc), Some(which)) = (current.take(), section) {
                        match which {
                            Which::Point => h.point.kept.push(desc),
                            Which::Cell => h.cell.kept.push(desc),
                        }
                    }
                }
                _ => {}
            },
            Event::Text(ref t) if nested == 0 => {
                if let Some(cur) = current.as_mut() {
                    cur.text.push_str(&String::from_utf8_lossy(t));
                }
            }
            Event::CData(ref t) if nested == 0 => {
                if let Some(cur) = current.as_mut() {
                    cur.text.push_str(&String::from_utf8_lossy(t));
                }
            }
            _ => {}
        }
    }
    // A file cut inside a <DataArray>: keep what was read, so that the short data is
    // reported as truncated.
    if let (Some(desc), Some(which)) = (current, section) {
        match which {
            Which::Point => h.point.kept.push(desc),
            Which::Cell => h.cell.kept.push(desc),
        }
    }
    Ok(h)
}

fn parse_extent(attr: &str, s: &str) -> Result<[i64; 6], ReadError> {
    let v: Vec<i64> = s
        .split_ascii_whitespace()
        .map(|t| t.parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("{attr}=\"{s}\" is not 6 integers")))?;
    let e: [i64; 6] = v
        .try_into()
        .map_err(|_| bad(format!("{attr}=\"{s}\" is not 6 integers")))?;
    for a in 0..3 {
        if e[2 * a + 1] < e[2 * a] {
            return Err(bad(format!(
                "{attr}=\"{s}\" is empty along {} (max < min); the image has no points",
                ["x", "y", "z"][a]
            )));
        }
    }
    Ok(e)
}

fn vec3(attr: &str, s: &str) -> Result<[f64; 3], ReadError> {
    let v: Vec<f64> =
        numbers(s, 3).ok_or_else(|| bad(format!("{attr}=\"{s}\" is not 3 numbers")))?;
    Ok([v[0], v[1], v[2]])
}

/// The appended data: from the byte after the `_` that follows the `<AppendedData>` start
/// tag (ending at `xml_end`) to the closing `</AppendedData>` tag, or to the end of the
/// file if that is missing (truncated file).
fn appended_section(bytes: &[u8], xml_end: usize) -> Result<&[u8], ReadError> {
    let after = bytes.get(xml_end..).unwrap_or(&[]);
    let start = match after.iter().position(|b| !b.is_ascii_whitespace()) {
        Some(i) if after.get(i) == Some(&b'_') => i + 1,
        _ => {
            return Err(bad(
                "the <AppendedData> section does not start with the '_' marker",
            ))
        }
    };
    let data = after.get(start..).unwrap_or(&[]);
    let end = rfind(data, b"</AppendedData>").unwrap_or(data.len());
    Ok(data.get(..end).unwrap_or(data))
}

/// Where binary array bytes come from: raw bytes or base64 text, decoded on the fly.
enum Source<'a> {
    Raw { data: &'a [u8], pos: usize },
    Base64(Base64<'a>),
}

impl Source<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>, TakeError> {
        match self {
            Source::Raw { data, pos } => {
                let rest = data.get(*pos..).unwrap_or(&[]);
                match rest.get(..n) {
                    Some(d) => {
                        *pos += n;
                        Ok(d.to_vec())
                    }
                    None => Err(TakeError::Short { found: rest.len() }),
                }
            }
            Source::Base64(b) => b.take(n),
        }
    }
}

/// Reads one binary array (its header, then its data) and returns exactly `nbytes` bytes.
fn read_binary(
    what: &str,
    src: &mut Source,
    binary: Binary,
    nbytes: usize,
) -> Result<Vec<u8>, ReadError> {
    let take = |src: &mut Source, n: usize, part: &str| -> Result<Vec<u8>, ReadError> {
        src.take(n).map_err(|e| match e {
            TakeError::Short { found } => {
                ReadError::truncated(format!("{what} ({part})"), n, found)
            }
            TakeError::BadBase64(message) => ReadError::corrupt(
                what,
                format!("{message} (the file is damaged; export it again)"),
            ),
        })
    };
    let uint = |src: &mut Source, part: &str| -> Result<u64, ReadError> {
        let b = take(src, if binary.header_u64 { 8 } else { 4 }, part)?;
        Ok(if binary.big_endian {
            b.iter().fold(0u64, |v, &x| (v << 8) | x as u64)
        } else {
            b.iter().rev().fold(0u64, |v, &x| (v << 8) | x as u64)
        })
    };
    let corrupt = |message: String| ReadError::corrupt(what, message);
    let mismatch = |found: u64| {
        corrupt(format!(
            "its header says {found} bytes, but the extent and NumberOfComponents call for {nbytes} (the header or the data is wrong; export the file again)"
        ))
    };

    if !binary.compressed {
        let n = uint(src, "byte count header")?;
        if n != nbytes as u64 {
            return Err(mismatch(n));
        }
        return take(src, nbytes, "data");
    }

    // vtkZLibDataCompressor: [#blocks, block size, last block size, compressed sizes…].
    let nblocks = uint(src, "compression header")?;
    let block_size = uint(src, "compression header")?;
    let last_size = uint(src, "compression header")?;
    let total = if nblocks == 0 {
        Some(0)
    } else {
        let last = if last_size == 0 {
            block_size
        } else {
            last_size
        };
        (nblocks - 1)
            .checked_mul(block_size)
            .and_then(|t| t.checked_add(last))
    };
    match total {
        Some(t) if t == nbytes as u64 => {}
        Some(t) => return Err(mismatch(t)),
        None => {
            return Err(corrupt(format!(
                "its compression header ({nblocks} blocks of {block_size} bytes) describes an impossible size (the file is damaged; export it again)"
            )))
        }
    }
    let mut sizes = Vec::with_capacity(usize::try_from(nblocks).unwrap_or(0).min(1 << 16));
    for _ in 0..nblocks {
        sizes.push(uint(src, "compression header")?);
    }
    // `nbytes` comes from the header: grow with the data actually inflated.
    let mut out = Vec::with_capacity(nbytes.min(1 << 26));
    for (i, &csize) in sizes.iter().enumerate() {
        let usize_of = |v: u64| usize::try_from(v).map_err(|_| mismatch(v));
        let compressed_block = take(
            src,
            usize_of(csize)?,
            &format!("compressed block {}", i + 1),
        )?;
        let want = if i + 1 == sizes.len() && last_size != 0 {
            last_size
        } else {
            block_size
        };
        let want = usize_of(want)?;
        let block = inflate(
            &format!("{what} (compressed block {})", i + 1),
            &compressed_block,
            want,
        )?;
        if block.len() != want {
            return Err(corrupt(format!(
                "compressed block {} inflates to {}{} bytes, but the header says {want} (the file is damaged; export it again)",
                i + 1,
                if block.len() > want { "more than " } else { "" },
                block.len().min(want)
            )));
        }
        out.extend_from_slice(&block);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::parse;
    use crate::test_util::{assert_geometry, check_errors, msg, never_panics, zlib};
    use base64::Engine;
    use ferrovol_core::{Scalars, VolumeData};

    fn b64(d: &[u8]) -> String {
        base64::engine::general_purpose::STANDARD.encode(d)
    }

    fn uint(v: usize, u64h: bool, be: bool) -> Vec<u8> {
        match (u64h, be) {
            (true, false) => (v as u64).to_le_bytes().to_vec(),
            (true, true) => (v as u64).to_be_bytes().to_vec(),
            (false, false) => (v as u32).to_le_bytes().to_vec(),
            (false, true) => (v as u32).to_be_bytes().to_vec(),
        }
    }

    /// An uncompressed binary block: byte count header, then the data.
    fn raw_block(data: &[u8], u64h: bool, be: bool) -> Vec<u8> {
        let mut v = uint(data.len(), u64h, be);
        v.extend_from_slice(data);
        v
    }

    /// A vtkZLibDataCompressor block: (header, compressed blocks).
    fn zlib_block(data: &[u8], block: usize, u64h: bool, be: bool) -> (Vec<u8>, Vec<u8>) {
        let chunks: Vec<&[u8]> = data.chunks(block).collect();
        let last = data.len() % block;
        let mut header = uint(chunks.len(), u64h, be);
        header.extend(uint(block, u64h, be));
        header.extend(uint(last, u64h, be));
        let mut body = Vec::new();
        for c in chunks {
            let z = zlib(c);
            header.extend(uint(z.len(), u64h, be));
            body.extend(z);
        }
        (header, body)
    }

    /// A .vti document: `file_attrs` on <VTKFile>, `image_attrs` on <ImageData>, the
    /// piece's content, and an optional (encoding, bytes) appended section.
    fn doc(
        file_attrs: &str,
        image_attrs: &str,
        piece: &str,
        appended: Option<(&str, &[u8])>,
    ) -> Vec<u8> {
        let extent = image_attrs
            .split("WholeExtent=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap_or("0 2 0 1 0 1");
        let mut s = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" {file_attrs}>\n  <ImageData {image_attrs}>\n  <Piece Extent=\"{extent}\">\n{piece}\n  </Piece>\n  </ImageData>\n"
        )
        .into_bytes();
        if let Some((enc, data)) = appended {
            s.extend(format!("  <AppendedData encoding=\"{enc}\">\n   _").as_bytes());
            s.extend_from_slice(data);
            s.extend(b"\n  </AppendedData>\n");
        }
        s.extend(b"</VTKFile>\n");
        s
    }

    const GEOM: &str = r#"WholeExtent="0 2 0 1 0 1" Origin="1 2 3" Spacing="0.5 1 2""#;

    fn u16_values() -> Vec<u16> {
        (0..12).map(|i| i * 1000 + 7).collect()
    }

    fn check_geom(v: &VolumeData) {
        assert_geometry(v, [3, 2, 2], [0.5, 1.0, 2.0], [1.0, 2.0, 3.0]);
    }

    #[test]
    fn readers_vti_ascii_float32_extent_and_direction() {
        let values: Vec<f32> = (0..12).map(|i| i as f32 * 1.5 - 3.0).collect();
        let text: Vec<String> = values.iter().map(|v| format!("{v:e}")).collect();
        let piece = format!(
            "<PointData Scalars=\"s\"><DataArray type=\"Float32\" Name=\"s\" format=\"ascii\">\n{}\n<InformationKey name=\"L2_NORM_RANGE\"><Value index=\"0\">99 98</Value></InformationKey>\n</DataArray></PointData>",
            text.join(" ")
        );
        let image = r#"WholeExtent="1 3 0 1 2 3" Origin="1 2 3" Spacing="0.5 1 2" Direction="0 1 0 -1 0 0 0 0 1""#;
        let v = parse(&doc("byte_order=\"LittleEndian\"", image, &piece, None)).unwrap();
        assert_eq!(v.dims, [3, 2, 2]);
        assert_eq!(
            v.direction,
            [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        );
        // The first point is extent (1, 0, 2): origin + D·(0.5, 0, 4).
        assert_eq!(v.origin, [1.0, 1.5, 7.0]);
        assert_eq!(v.components, 1);
        assert_eq!(v.scalars, Scalars::F32(values));
    }

    #[test]
    fn readers_vti_binary_base64_uint16() {
        let vals = u16_values();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let piece = format!(
            "<PointData><DataArray type=\"UInt16\" Name=\"x\" format=\"binary\">\n  {}\n</DataArray></PointData>",
            b64(&raw_block(&bytes, false, false))
        );
        let v = parse(&doc(
            "byte_order=\"LittleEndian\" header_type=\"UInt32\"",
            GEOM,
            &piece,
            None,
        ))
        .unwrap();
        check_geom(&v);
        assert_eq!(v.scalars, Scalars::U16(vals));
    }

    #[test]
    fn readers_vti_binary_separately_encoded_header_big_endian_int16() {
        let vals: Vec<i16> = (0..12).map(|i| i * -300 + 5).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_be_bytes()).collect();
        let text = format!("{}{}", b64(&uint(bytes.len(), true, true)), b64(&bytes));
        assert!(
            text[..12].ends_with('='),
            "the header must be padded on its own"
        );
        let piece = format!(
            "<PointData><DataArray type=\"Int16\" Name=\"x\" format=\"binary\">{text}</DataArray></PointData>"
        );
        let v = parse(&doc(
            "byte_order=\"BigEndian\" header_type=\"UInt64\"",
            GEOM,
            &piece,
            None,
        ))
        .unwrap();
        check_geom(&v);
        assert_eq!(v.scalars, Scalars::I16(vals));
    }

    #[test]
    fn readers_vti_binary_zlib_multiblock_float64() {
        let vals: Vec<f64> = (0..12).map(|i| i as f64 * 0.25).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let (header, body) = zlib_block(&bytes, 40, true, false);
        let piece = format!(
            "<PointData><DataArray type=\"Float64\" Name=\"x\" format=\"binary\">{}{}</DataArray></PointData>",
            b64(&header),
            b64(&body)
        );
        let attrs = "byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
        let v = parse(&doc(attrs, GEOM, &piece, None)).unwrap();
        check_geom(&v);
        assert_eq!(v.scalars, Scalars::F64(vals));
    }

    #[test]
    fn readers_vti_appended_raw_picks_scalars_attribute() {
        let a: Vec<u8> = (0..12i32).flat_map(|v| (v * 9).to_le_bytes()).collect();
        let b: Vec<u8> = (0..36u8).map(|v| v * 7).collect();
        let mut data = raw_block(&a, false, false);
        let off_b = data.len();
        data.extend(raw_block(&b, false, false));
        let piece = format!(
            "<PointData Scalars=\"rgb\">\n<DataArray type=\"Int32\" Name=\"first\" format=\"appended\" offset=\"0\"/>\n<DataArray type=\"UInt8\" Name=\"rgb\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{off_b}\"/>\n</PointData>"
        );
        let read = |piece: &str| {
            parse(&doc(
                "byte_order=\"LittleEndian\"",
                GEOM,
                piece,
                Some(("raw", &data)),
            ))
            .unwrap()
        };
        let v = read(&piece);
        check_geom(&v);
        assert_eq!(v.components, 3);
        assert_eq!(v.scalars, Scalars::U8(b));

        // Without a Scalars attribute the first array is used.
        let v = read(&piece.replace(" Scalars=\"rgb\"", ""));
        assert_eq!(v.scalars, Scalars::I32((0..12).map(|v| v * 9).collect()));
    }

    #[test]
    fn readers_vti_appended_base64_float32() {
        let vals: Vec<f32> = (0..12).map(|i| i as f32 / 8.0).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let text = format!("{}{}", b64(&uint(bytes.len(), true, false)), b64(&bytes));
        let piece = "<PointData><DataArray type=\"Float32\" Name=\"f\" format=\"appended\" offset=\"0\"/></PointData>";
        let attrs = "byte_order=\"LittleEndian\" header_type=\"UInt64\"";
        let v = parse(&doc(attrs, GEOM, piece, Some(("base64", text.as_bytes())))).unwrap();
        check_geom(&v);
        assert_eq!(v.scalars, Scalars::F32(vals));
    }

    #[test]
    fn readers_vti_appended_base64_zlib_uint8() {
        let vals: Vec<u8> = (0..12).map(|i| 200 - i).collect();
        let (header, body) = zlib_block(&vals, 5, false, false);
        let text = format!("{}{}", b64(&header), b64(&body));
        let piece = "<PointData><DataArray type=\"UInt8\" Name=\"f\" format=\"appended\" offset=\"0\"/></PointData>";
        let attrs = "byte_order=\"LittleEndian\" compressor=\"vtkZLibDataCompressor\"";
        let v = parse(&doc(attrs, GEOM, piece, Some(("base64", text.as_bytes())))).unwrap();
        assert_eq!(v.scalars, Scalars::U8(vals));
    }

    #[test]
    fn readers_vti_appended_raw_zlib_big_endian_uint32() {
        let vals: Vec<u32> = (0..12).map(|i| 4_000_000_000 - i * 17).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_be_bytes()).collect();
        let (mut data, body) = zlib_block(&bytes, 48, false, true);
        data.extend(body);
        let piece = "<PointData><DataArray type=\"UInt32\" Name=\"f\" format=\"appended\" offset=\"0\"/></PointData>";
        let attrs =
            "byte_order=\"BigEndian\" header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"";
        let v = parse(&doc(attrs, GEOM, piece, Some(("raw", &data)))).unwrap();
        assert_eq!(v.scalars, Scalars::U32(vals));
    }

    #[test]
    fn readers_vti_cell_data_becomes_cell_centred_points() {
        let piece = "<PointData></PointData><CellData Scalars=\"c\"><DataArray type=\"Int8\" Name=\"c\" format=\"ascii\">-3 4</DataArray></CellData>";
        let v = parse(&doc("", GEOM, piece, None)).unwrap();
        assert_eq!(v.dims, [2, 1, 1]);
        assert_eq!(v.spacing, [0.5, 1.0, 2.0]);
        assert_eq!(v.origin, [1.25, 2.5, 4.0]);
        assert_eq!(v.scalars, Scalars::I8(vec![-3, 4]));
    }

    #[test]
    fn readers_vti_legacy_type_names() {
        let piece = "<PointData><DataArray type=\"unsigned_short\" format=\"ascii\">1 2 3 4 5 6 7 8 9 10 11 12</DataArray></PointData>";
        let v = parse(&doc("", GEOM, piece, None)).unwrap();
        assert_eq!(v.scalars, Scalars::U16((1..=12).collect()));
    }

    #[test]
    fn readers_vti_truncated_appended_data() {
        let bytes: Vec<u8> = u16_values().iter().flat_map(|v| v.to_le_bytes()).collect();
        let piece = "<PointData><DataArray type=\"UInt16\" Name=\"heart\" format=\"appended\" offset=\"0\"/></PointData>";
        let file = doc(
            "byte_order=\"LittleEndian\"",
            GEOM,
            piece,
            Some(("raw", &raw_block(&bytes, false, false))),
        );
        let marker = file.windows(5).position(|w| w == b"\n   _").unwrap() + 5;
        let cut = marker + 4 + 10;
        let m = msg(parse(&file[..cut]));
        assert!(
            m.starts_with("truncated appended data of DataArray 'heart'"),
            "{m}"
        );
        assert!(m.contains("expected 24 bytes, found 10"), "{m}");
    }

    #[test]
    fn readers_vti_truncated_inline_binary() {
        let bytes: Vec<u8> = u16_values().iter().flat_map(|v| v.to_le_bytes()).collect();
        let text = b64(&raw_block(&bytes, false, false));
        let piece = format!(
            "<PointData><DataArray type=\"UInt16\" Name=\"x\" format=\"binary\">{text}</DataArray></PointData>"
        );
        let file = doc("", GEOM, &piece, None);
        let cut = file
            .windows(text.len())
            .position(|w| w == text.as_bytes())
            .unwrap()
            + 20;
        let m = msg(parse(&file[..cut]));
        assert!(
            m.contains(
                "truncated binary (base64) DataArray 'x' (data): expected 24 bytes, found 11"
            ),
            "{m}"
        );
    }

    /// 10^12 points of float64 (8 TB) in a few bytes: an error, not an allocation.
    #[test]
    fn readers_vti_absurd_size_fails_before_allocating() {
        let image = r#"WholeExtent="0 9999 0 9999 0 9999""#;
        let claim = uint(8_000_000_000_000, true, false);
        let array = |format: &str| {
            format!("<PointData><DataArray type=\"Float64\" Name=\"x\" format=\"{format}\" offset=\"0\">AAAA</DataArray></PointData>")
        };
        let u64h = "header_type=\"UInt64\"";
        let zlib_attrs = "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
        let mut zheader = uint(1, true, false);
        zheader.extend(uint(8_000_000_000_000, true, false));
        zheader.extend(uint(0, true, false));
        zheader.extend(uint(1 << 40, true, false));
        let cases = [
            (
                "ascii",
                doc("", image, &array("ascii").replace("AAAA", "1"), None),
                "found 1 values, expected 1000000000000",
            ),
            (
                "binary",
                doc(
                    u64h,
                    image,
                    &array("binary").replace("AAAA", &b64(&claim)),
                    None,
                ),
                "expected 8000000000000 bytes, found 0",
            ),
            (
                "raw",
                doc(u64h, image, &array("appended"), Some(("raw", &claim))),
                "expected 8000000000000 bytes",
            ),
            (
                "base64",
                doc(
                    u64h,
                    image,
                    &array("appended"),
                    Some(("base64", b64(&claim).as_bytes())),
                ),
                "expected 8000000000000 bytes",
            ),
            (
                "zlib",
                doc(
                    zlib_attrs,
                    image,
                    &array("appended"),
                    Some(("raw", &zheader)),
                ),
                "expected 1099511627776 bytes",
            ),
        ];
        check_errors(parse, &cases);
    }

    #[test]
    fn readers_vti_errors() {
        let ascii = |ty: &str, extra: &str, vals: &str| {
            format!("<PointData><DataArray type=\"{ty}\" {extra} format=\"ascii\">{vals}</DataArray></PointData>")
        };
        let twelve = "1 2 3 4 5 6 7 8 9 10 11 12";
        let cases: Vec<(&str, Vec<u8>, &str)> = vec![
            ("nan.vti", doc("", GEOM, &ascii("Float32", "", "1 2 3 nan 5 6 7 8 9 10 11 12"), None), "NaN"),
            ("zero.vti", doc("", r#"WholeExtent="0 2 0 1 0 1" Spacing="1 0 1""#, &ascii("UInt8", "", twelve), None), "spacing along y is 0"),
            ("neg.vti", doc("", r#"WholeExtent="0 2 0 1 0 1" Spacing="1 1 -2""#, &ascii("UInt8", "", twelve), None), "spacing along z is -2"),
            ("i64.vti", doc("", GEOM, &ascii("Int64", "", twelve), None), "unsupported scalar type 'Int64'"),
            ("five.vti", doc("", GEOM, &ascii("UInt8", "NumberOfComponents=\"5\"", twelve), None), "5 components"),
            ("short.vti", doc("", GEOM, &ascii("UInt8", "", "1 2 3"), None), "found 3 values, expected 12"),
            ("word.vti", doc("", GEOM, &ascii("UInt8", "", "1 2 x"), None), "'x' is not a valid uint8"),
            ("noext.vti", doc("", "Spacing=\"1 1 1\"", &ascii("UInt8", "", twelve), None), "no WholeExtent"),
            ("badext.vti", doc("", r#"WholeExtent="0 2 0 1""#, &ascii("UInt8", "", twelve), None), "not 6 integers"),
            ("empty.vti", doc("", r#"WholeExtent="0 2 1 0 0 1""#, &ascii("UInt8", "", twelve), None), "max < min"),
            ("nodata.vti", doc("", GEOM, "<PointData></PointData>", None), "no <DataArray>"),
            ("lz4.vti", doc("compressor=\"vtkLZ4DataCompressor\"", GEOM, &ascii("UInt8", "", twelve), None), "vtkLZ4DataCompressor"),
            ("fmt.vti", doc("", GEOM, "<PointData><DataArray type=\"UInt8\" format=\"hex\">00</DataArray></PointData>", None), "format=\"hex\""),
            ("noapp.vti", doc("", GEOM, "<PointData><DataArray type=\"UInt8\" format=\"appended\" offset=\"0\"/></PointData>", None), "no <AppendedData>"),
            ("poly.vti", doc("", GEOM, "", None).replace_type(), "PolyData"),
            ("notxml.vti", b"hello, world".to_vec(), "no <VTKFile>"),
            ("garbage.vti", b"<VTKFile <<<>".to_vec(), "XML"),
            ("b64.vti", doc("", GEOM, "<PointData><DataArray type=\"UInt8\" format=\"binary\">DAAA*AAA</DataArray></PointData>", None), "invalid base64"),
            ("count.vti", doc("", GEOM, &format!("<PointData><DataArray type=\"UInt8\" format=\"binary\">{}</DataArray></PointData>", b64(&raw_block(&[1; 11], false, false))), None), "header says 11 bytes"),
            ("zbad.vti", doc("compressor=\"vtkZLibDataCompressor\"", GEOM, &format!("<PointData><DataArray type=\"UInt8\" format=\"binary\">{}</DataArray></PointData>", b64(&[1, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0, 0, 4, 0, 0, 0, 1, 2, 3, 4])), None), "decompression failed"),
        ];
        check_errors(parse, &cases);
    }

    trait ReplaceType {
        fn replace_type(self) -> Vec<u8>;
    }
    impl ReplaceType for Vec<u8> {
        fn replace_type(self) -> Vec<u8> {
            String::from_utf8(self)
                .unwrap()
                .replace("type=\"ImageData\"", "type=\"PolyData\"")
                .into_bytes()
        }
    }

    /// Cutting or corrupting a file anywhere must give an error or a volume, never a panic.
    #[test]
    fn readers_vti_never_panics_on_damaged_files() {
        let vals = u16_values();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let (mut data, body) = zlib_block(&bytes, 10, false, false);
        data.extend(body);
        let piece = "<PointData><DataArray type=\"UInt16\" Name=\"f\" format=\"appended\" offset=\"0\"/></PointData>";
        let zraw = doc(
            "compressor=\"vtkZLibDataCompressor\"",
            GEOM,
            piece,
            Some(("raw", &data)),
        );
        let (h, b) = zlib_block(&bytes, 10, true, false);
        let piece = format!("<PointData><DataArray type=\"UInt16\" Name=\"f\" format=\"binary\">{}{}</DataArray></PointData>", b64(&h), b64(&b));
        let zb64 = doc(
            "compressor=\"vtkZLibDataCompressor\" header_type=\"UInt64\"",
            GEOM,
            &piece,
            None,
        );
        for file in [zraw, zb64] {
            never_panics(parse, &file, &[0x00, 0xff, b'<', b'"', b'9']);
        }
    }
}
