//! What the VTK XML readers ([`crate::vti`], [`crate::vtu`]) share: the XML part of a
//! file (the `<VTKFile>` attributes, the dataset element, its pieces with their
//! `<PointData>`, `<CellData>`, `<Points>` and `<Cells>` arrays) and the decoding of a
//! `<DataArray>`'s data: `format="ascii"`, `format="binary"` (base64 with a `UInt32` or
//! `UInt64` header, `header_type`) and `format="appended"` with
//! `<AppendedData encoding="raw">` or `encoding="base64"`; binary and appended data may be
//! compressed with `compressor="vtkZLibDataCompressor"` in one or several blocks; both
//! byte orders. The raw appended section is not XML: only the part of the file before it
//! goes to the XML parser, and an array is located by byte offset after the `_` marker.
//! Sizes come from the caller (what the dataset's header calls for) and are checked
//! against the data present before anything is allocated for them.

use std::cell::OnceCell;

use ferrovol_core::{ScalarType, Scalars};
use quick_xml::events::{BytesStart, Event};

use crate::base64::{Base64, TakeError};
use crate::decode::{decode_binary, inflate, parse_ascii};
use crate::ReadError;

/// The scalar types of data arrays, as VTK XML names them (for messages).
pub(crate) const SUPPORTED_TYPES: &str =
    "Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32 and Float64 (also the legacy names char, unsigned_char, short, unsigned_short, int, unsigned_int, float, double)";

/// A `<DataArray>`, with its inline text.
#[derive(Debug, Default)]
pub(crate) struct ArrayDesc {
    pub name: String,
    pub type_name: String,
    pub components: String,
    pub format: String,
    pub offset: Option<String>,
    pub text: String,
}

/// The sections of a piece whose arrays the parser keeps.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Which {
    Point,
    Cell,
    Points,
    Cells,
}

/// What the parser keeps of a section: for `<PointData>` and `<CellData>`, the array named
/// by the `Scalars` attribute and the first array (at most two; others are skipped); for
/// `<Points>`, the first array; for `<Cells>`, the first `connectivity`, `offsets` and
/// `types` arrays.
#[derive(Debug, Default)]
pub(crate) struct Section {
    pub scalars: Option<String>,
    pub kept: Vec<ArrayDesc>,
}

impl Section {
    fn wants(&self, which: Which, name: &str) -> bool {
        let named = |n: &str| self.kept.iter().any(|a| a.name == n);
        match which {
            Which::Point | Which::Cell => {
                self.kept.is_empty() || (self.scalars.as_deref() == Some(name) && !named(name))
            }
            Which::Points => self.kept.is_empty(),
            Which::Cells => matches!(name, "connectivity" | "offsets" | "types") && !named(name),
        }
    }

    /// The array named by `Scalars`, else the first.
    pub fn chosen(self) -> Option<ArrayDesc> {
        let scalars = self.scalars;
        let mut kept = self.kept;
        let i = kept
            .iter()
            .position(|a| Some(a.name.as_str()) == scalars.as_deref())
            .unwrap_or(0);
        (i < kept.len()).then(|| kept.swap_remove(i))
    }

    /// The array called `name`.
    pub fn take(&mut self, name: &str) -> Option<ArrayDesc> {
        let i = self.kept.iter().position(|a| a.name == name)?;
        Some(self.kept.swap_remove(i))
    }
}

/// A `<Piece>`: its attributes and sections.
#[derive(Debug, Default)]
pub(crate) struct Piece {
    pub attrs: Vec<(String, String)>,
    pub point: Section,
    pub cell: Section,
    pub points: Section,
    pub cells: Section,
}

impl Piece {
    fn section(&mut self, which: Which) -> &mut Section {
        match which {
            Which::Point => &mut self.point,
            Which::Cell => &mut self.cell,
            Which::Points => &mut self.points,
            Which::Cells => &mut self.cells,
        }
    }
}

/// What the XML part of a VTK XML file says.
#[derive(Default)]
pub(crate) struct Header {
    pub saw_vtkfile: bool,
    pub file_type: Option<String>,
    pub byte_order: Option<String>,
    pub header_type: Option<String>,
    pub compressor: Option<String>,
    /// The attributes of the dataset element (`<ImageData>`, `<UnstructuredGrid>`).
    pub dataset: Vec<(String, String)>,
    pub pieces: Vec<Piece>,
    pub appended_encoding: Option<String>,
    pub saw_appended: bool,
}

pub(crate) fn attributes(
    format: &'static str,
    e: &BytesStart,
) -> Result<Vec<(String, String)>, ReadError> {
    let bad = |m: String| ReadError::bad_header(format, m);
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

pub(crate) fn get(attrs: &[(String, String)], key: &str) -> Option<String> {
    attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone())
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn rfind(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).rposition(|w| w == needle)
}

/// An attribute with two values: false for `off` (also where the attribute is missing),
/// true for `on`.
pub(crate) fn flag(
    format: &'static str,
    attr: &str,
    value: &Option<String>,
    [off, on]: [&str; 2],
) -> Result<bool, ReadError> {
    match value.as_deref() {
        None => Ok(false),
        Some(v) if v == off => Ok(false),
        Some(v) if v == on => Ok(true),
        Some(v) => Err(ReadError::bad_header(
            format,
            format!("{attr}=\"{v}\"; expected {off} or {on}"),
        )),
    }
}

/// How binary arrays are stored (attributes of `<VTKFile>`).
#[derive(Clone, Copy)]
pub(crate) struct Binary {
    /// Block headers are UInt64, not UInt32.
    pub header_u64: bool,
    pub big_endian: bool,
    /// vtkZLibDataCompressor blocks.
    pub compressed: bool,
}

#[derive(Clone, Copy)]
pub(crate) enum Encoding {
    Raw,
    Base64,
}

/// Reads and checks the XML part of a `format` file whose dataset element is `dataset`
/// (`ImageData`) and whose extension is `ext`; `hint` says what to do with a file of
/// another type. Returns the header, how binary arrays are stored and where the XML part
/// ends.
pub(crate) fn read_xml(
    format: &'static str,
    dataset: &str,
    ext: &str,
    hint: &str,
    bytes: &[u8],
) -> Result<(Header, Binary, usize), ReadError> {
    let (xml, xml_end) = xml_part(format, ext, bytes)?;
    let h = parse_xml(format, dataset.as_bytes(), xml)?;
    let binary = check_vtkfile(format, &h, dataset, ext, hint)?;
    Ok((h, binary, xml_end))
}

/// The XML part of a file (`bytes` up to and including any `<AppendedData>` start tag,
/// after which raw binary may follow) and where it ends. `ext` (".vti") names the file
/// type in the message for text that is not UTF-8.
fn xml_part<'a>(
    format: &'static str,
    ext: &str,
    bytes: &'a [u8],
) -> Result<(&'a str, usize), ReadError> {
    let bad = |m: String| ReadError::bad_header(format, m);
    let appended_tag = find(bytes, b"<AppendedData");
    let xml_end = match appended_tag {
        Some(p) => match bytes
            .get(p..)
            .and_then(|rest| rest.iter().position(|&b| b == b'>'))
        {
            Some(q) => p + q + 1,
            None => return Err(bad("the <AppendedData> tag is not closed with '>'".into())),
        },
        None => bytes.len(),
    };
    let xml = bytes.get(..xml_end).unwrap_or(bytes);
    let xml = std::str::from_utf8(xml).map_err(|e| {
        bad(format!(
            "the XML is not UTF-8 text (byte {}); is this really a {ext} file?",
            e.valid_up_to()
        ))
    })?;
    Ok((xml, xml_end))
}

/// The `<VTKFile>` attributes: it must be there, of type `file_type`; `hint` says what to
/// do with a file of another type. Returns how binary data is stored.
fn check_vtkfile(
    format: &'static str,
    h: &Header,
    file_type: &str,
    ext: &str,
    hint: &str,
) -> Result<Binary, ReadError> {
    if !h.saw_vtkfile {
        return Err(ReadError::bad_header(
            format,
            format!("no <VTKFile> element; this is not a VTK XML file (save it from VTK or ParaView as {ext})"),
        ));
    }
    match h.file_type.as_deref() {
        Some(t) if t == file_type => {}
        Some(other) => {
            return Err(ReadError::unsupported(format!(
                "the file holds VTK {other} data, not {file_type}; {hint}"
            )))
        }
        None => {
            return Err(ReadError::bad_header(
                format,
                "the <VTKFile> element has no type attribute",
            ))
        }
    }
    let big_endian = flag(
        format,
        "byte_order",
        &h.byte_order,
        ["LittleEndian", "BigEndian"],
    )?;
    let header_u64 = flag(format, "header_type", &h.header_type, ["UInt32", "UInt64"])?;
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
    Ok(Binary {
        header_u64,
        big_endian,
        compressed,
    })
}

/// The encoding of the `<AppendedData>` section, if there is one.
pub(crate) fn appended_encoding(
    format: &'static str,
    h: &Header,
) -> Result<Option<Encoding>, ReadError> {
    let bad = |m: String| ReadError::bad_header(format, m);
    match (h.saw_appended, h.appended_encoding.as_deref()) {
        (false, _) => Ok(None),
        (true, Some("raw")) => Ok(Some(Encoding::Raw)),
        (true, Some("base64")) => Ok(Some(Encoding::Base64)),
        (true, None) => Err(bad(
            "<AppendedData> has no encoding attribute (raw or base64)".into(),
        )),
        (true, Some(other)) => Err(bad(format!(
            "<AppendedData encoding=\"{other}\">; expected raw or base64"
        ))),
    }
}

/// The encoding and offset of an array with `format="appended"`.
pub(crate) fn appended_array(
    format: &'static str,
    what: &str,
    array: &ArrayDesc,
    appended_encoding: Option<Encoding>,
) -> Result<(Encoding, usize), ReadError> {
    let bad = |m: String| ReadError::bad_header(format, m);
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

/// How the arrays of a file are read: what [`check_vtkfile`] and [`appended_encoding`]
/// found, and the whole file.
pub(crate) struct Arrays<'a> {
    pub format: &'static str,
    pub bytes: &'a [u8],
    pub binary: Binary,
    pub appended_encoding: Option<Encoding>,
    /// The end of the XML part.
    pub xml_end: usize,
    /// The appended section, found once: finding its end scans it, and a file may have
    /// many arrays there.
    appended: OnceCell<&'a [u8]>,
}

impl<'a> Arrays<'a> {
    pub fn new(
        format: &'static str,
        bytes: &'a [u8],
        binary: Binary,
        appended_encoding: Option<Encoding>,
        xml_end: usize,
    ) -> Arrays<'a> {
        Arrays {
            format,
            bytes,
            binary,
            appended_encoding,
            xml_end,
            appended: OnceCell::new(),
        }
    }

    /// The appended section ([`appended_section`]).
    fn appended(&self) -> Result<&'a [u8], ReadError> {
        if let Some(&data) = self.appended.get() {
            return Ok(data);
        }
        let data = appended_section(self.format, self.bytes, self.xml_end)?;
        Ok(self.appended.get_or_init(|| data))
    }

    /// Exactly `nbytes` bytes of a binary or appended array's data (decompressed);
    /// `what` names the array ("DataArray 'name'").
    pub fn bytes(
        &self,
        array: &ArrayDesc,
        what: &str,
        nbytes: usize,
    ) -> Result<Vec<u8>, ReadError> {
        match array.format.as_str() {
            "binary" => {
                let mut src = Source::Base64(Base64::new(array.text.as_bytes()));
                let what = format!("binary (base64) {what}");
                read_binary(&what, &mut src, self.binary, nbytes)
            }
            "appended" => {
                let (encoding, offset) =
                    appended_array(self.format, what, array, self.appended_encoding)?;
                let data = self.appended()?;
                let what = format!("appended data of {what}");
                let rest = data.get(offset..).ok_or_else(|| {
                    ReadError::truncated(&what, offset.saturating_add(1), data.len())
                })?;
                let mut src = match encoding {
                    Encoding::Raw => Source::Raw { data: rest, pos: 0 },
                    Encoding::Base64 => Source::Base64(Base64::new(rest)),
                };
                read_binary(&what, &mut src, self.binary, nbytes)
            }
            other => Err(ReadError::bad_header(
                self.format,
                format!("{what} has format=\"{other}\"; expected ascii, binary or appended"),
            )),
        }
    }

    /// `count` values of `ty`, from any format.
    pub fn values(
        &self,
        array: &ArrayDesc,
        what: &str,
        ty: ScalarType,
        count: usize,
    ) -> Result<Scalars, ReadError> {
        if array.format == "ascii" {
            return parse_ascii(&format!("ascii {what}"), &array.text, ty, count);
        }
        let nbytes = count.checked_mul(ty.size_bytes()).ok_or_else(|| {
            ReadError::bad_header(
                self.format,
                format!(
                    "{what}: {count} values of {} are more than this machine can address",
                    ty.name()
                ),
            )
        })?;
        let raw = self.bytes(array, what, nbytes)?;
        Ok(decode_binary(&raw, ty, self.binary.big_endian))
    }
}

/// Parses the XML part of a file (everything up to and including the `<AppendedData>`
/// start tag); `dataset` is the dataset element's name (`ImageData`).
fn parse_xml(format: &'static str, dataset: &[u8], xml: &str) -> Result<Header, ReadError> {
    let mut h = Header::default();
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut section: Option<Which> = None;
    // The array being read, if it is one we keep, and how deep we are in its children
    // (`<InformationKey>` elements, whose text is not data).
    let mut current: Option<ArrayDesc> = None;
    let mut nested = 0usize;
    loop {
        let event = reader.read_event().map_err(|e| {
            ReadError::bad_header(
                format,
                format!(
                    "XML syntax error near byte {}: {e}",
                    reader.error_position()
                ),
            )
        })?;
        match event {
            Event::Eof => break,
            Event::Start(_) if current.is_some() => nested += 1,
            Event::Empty(_) if current.is_some() => {}
            Event::End(_) if current.is_some() && nested > 0 => nested -= 1,
            Event::Start(ref e) | Event::Empty(ref e) => {
                let empty = matches!(event, Event::Empty(_));
                let attrs = attributes(format, e)?;
                match e.name().as_ref() {
                    b"VTKFile" => {
                        h.saw_vtkfile = true;
                        h.file_type = get(&attrs, "type");
                        h.byte_order = get(&attrs, "byte_order");
                        h.header_type = get(&attrs, "header_type");
                        h.compressor = get(&attrs, "compressor");
                    }
                    name if name == dataset => h.dataset = attrs,
                    b"Piece" => h.pieces.push(Piece {
                        attrs,
                        ..Piece::default()
                    }),
                    b"PointData" | b"CellData" | b"Points" | b"Cells" if !empty => {
                        let which = match e.name().as_ref() {
                            b"PointData" => Which::Point,
                            b"CellData" => Which::Cell,
                            b"Points" => Which::Points,
                            _ => Which::Cells,
                        };
                        if let Some(piece) = h.pieces.last_mut() {
                            piece.section(which).scalars = get(&attrs, "Scalars");
                            section = Some(which);
                        }
                    }
                    b"DataArray" => {
                        if let (Some(which), Some(piece)) = (section, h.pieces.last_mut()) {
                            let sec = piece.section(which);
                            let name = get(&attrs, "Name").unwrap_or_default();
                            if sec.wants(which, &name) {
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
                b"PointData" | b"CellData" | b"Points" | b"Cells" => section = None,
                b"DataArray" => keep(&mut h, section, current.take()),
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
    keep(&mut h, section, current);
    Ok(h)
}

/// Keeps the array just read in its section of the last piece.
fn keep(h: &mut Header, section: Option<Which>, desc: Option<ArrayDesc>) {
    if let (Some(desc), Some(which), Some(piece)) = (desc, section, h.pieces.last_mut()) {
        piece.section(which).kept.push(desc);
    }
}

/// The appended data: from the byte after the `_` that follows the `<AppendedData>` start
/// tag (ending at `xml_end`) to the closing `</AppendedData>` tag, or to the end of the
/// file if that is missing (truncated file).
pub(crate) fn appended_section<'a>(
    format: &'static str,
    bytes: &'a [u8],
    xml_end: usize,
) -> Result<&'a [u8], ReadError> {
    let after = bytes.get(xml_end..).unwrap_or(&[]);
    let start = match after.iter().position(|b| !b.is_ascii_whitespace()) {
        Some(i) if after.get(i) == Some(&b'_') => i + 1,
        _ => {
            return Err(ReadError::bad_header(
                format,
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
            "its header says {found} bytes, but the dataset's extent or sizes and NumberOfComponents call for {nbytes} (the header or the data is wrong; export the file again)"
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
