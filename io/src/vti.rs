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

use ferrovol_core::{ScalarType, VolumeData};
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
    let h = describe(bytes)?;
    let (what, array, ty, binary) = (&h.what, &h.array, h.ty, h.binary);
    let big_endian = binary.big_endian;
    let scalars = match array.format.as_str() {
        "ascii" => parse_ascii(&format!("ascii {what}"), &array.text, ty, h.layout.count)?,
        "binary" => {
            let mut src = Source::Base64(Base64::new(array.text.as_bytes()));
            let what = format!("binary (base64) {what}");
            let raw = read_binary(&what, &mut src, binary, h.layout.nbytes)?;
            decode_binary(&raw, ty, big_endian)
        }
        "appended" => {
            let (encoding, offset) = appended_array(what, array, h.appended_encoding)?;
            let data = appended_section(bytes, h.xml_end)?;
            let what = format!("appended data of {what}");
            let rest = data
                .get(offset..)
                .ok_or_else(|| ReadError::truncated(&what, offset.saturating_add(1), data.len()))?;
            let mut src = match encoding {
                Encoding::Raw => Source::Raw { data: rest, pos: 0 },
                Encoding::Base64 => Source::Base64(Base64::new(rest)),
            };
            let raw = read_binary(&what, &mut src, binary, h.layout.nbytes)?;
            decode_binary(&raw, ty, big_endian)
        }
        other => {
            return Err(bad(format!(
                "{what} has format=\"{other}\"; expected ascii, binary or appended"
            )))
        }
    };
    h.layout.volume(h.geometry, scalars)
}

/// Where the data of a `.vti` file whose XML part lies in `prefix` (its first bytes) is, when
/// it can be read in place: an uncompressed array in raw appended data whose byte-count
/// header (in `prefix`) matches the extent. `None` otherwise (the in-memory reader then
/// reads the file, and names any problem).
pub(crate) fn raw_data(prefix: &[u8]) -> Result<Option<crate::raw::RawData>, ReadError> {
    use crate::raw::{RawData, RawStart};
    let h = describe(prefix)?;
    if h.array.format != "appended" || h.binary.compressed {
        return Ok(None);
    }
    let (encoding, offset) = appended_array(&h.what, &h.array, h.appended_encoding)?;
    if !matches!(encoding, Encoding::Raw) {
        return Ok(None);
    }
    let data = appended_section(prefix, h.xml_end)?;
    // the section's first byte, as an offset in the file
    let section = data.as_ptr() as usize - prefix.as_ptr() as usize;
    let width = if h.binary.header_u64 { 8 } else { 4 };
    let Some(count) = data.get(offset..).and_then(|d| d.get(..width)) else {
        return Ok(None);
    };
    let count = if h.binary.big_endian {
        count.iter().fold(0u64, |v, &x| (v << 8) | x as u64)
    } else {
        count.iter().rev().fold(0u64, |v, &x| (v << 8) | x as u64)
    };
    if count != h.layout.nbytes as u64 {
        return Ok(None);
    }
    Ok(Some(RawData {
        format: FORMAT,
        layout: h.layout,
        geometry: h.geometry,
        big_endian: h.binary.big_endian,
        file: None,
        start: RawStart::At((section + offset + width) as u64),
    }))
}

/// What the XML part of a `.vti` file says: the chosen array, its layout and geometry, and
/// how its binary data is stored.
struct Described {
    layout: Layout,
    geometry: Geometry,
    array: ArrayDesc,
    /// "DataArray 'name'", for messages.
    what: String,
    ty: ScalarType,
    binary: Binary,
    appended_encoding: Option<Encoding>,
    /// The end of the XML part (after the `<AppendedData>` start tag, if there is one).
    xml_end: usize,
}

/// The encoding and offset of an array with `format="appended"`.
fn appended_array(
    what: &str,
    array: &ArrayDesc,
    appended_encoding: Option<Encoding>,
) -> Result<(Encoding, usize), ReadError> {
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
    Ok((encoding, offset))
}

/// Reads the XML part of a `.vti` file (all of `bytes` up to any `<AppendedData>` start
/// tag) and checks what it describes.
fn describe(bytes: &[u8]) -> Result<Described, ReadError> {
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

    Ok(Described {
        layout,
        geometry,
        array,
        what,
        ty,
        binary,
        appended_encoding,
        xml_end,
    })
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
    // `nblocks` and `nbytes` come from the header: both vectors grow with the sizes and
    // blocks actually read.
    let mut sizes = Vec::new();
    for _ in 0..nblocks {
        sizes.push(uint(src, "compression header")?);
    }
    let mut out = Vec::new();
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
mod tests;
