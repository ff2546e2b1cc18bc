//! Tests of the .vti reader: every encoding and compression, both byte orders, cell data,
//! and damaged or hostile files.

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
    let attrs =
        "byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
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
        m.contains("truncated binary (base64) DataArray 'x' (data): expected 24 bytes, found 11"),
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
