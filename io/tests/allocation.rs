//! Allocation bounds, measured: a header that claims 10^12 voxels fails at once with an
//! error naming the size it claims, and while a reader finds that out it holds no more heap
//! than its input can fill. This test binary counts every allocation of the thread that
//! parses.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::Write;
use std::time::{Duration, Instant};

use ferrovol_io::{no_data_file, Format, ReadError};

mod common;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting each thread's live bytes and their peak.
struct Counting;

fn add(size: usize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + size;
        live.set(now);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(now)));
    });
}

fn sub(size: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get().saturating_sub(size)));
}

// SAFETY: every call is passed on to `System` unchanged; only counters are added.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        add(layout.size());
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        add(layout.size());
        System.alloc_zeroed(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        sub(layout.size());
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        add(new_size);
        sub(layout.size());
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns what it returned, the most heap it held at once above what the
/// thread held before, and how long it took.
fn measure<T>(f: impl FnOnce() -> T) -> (T, usize, Duration) {
    let before = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(before));
    let start = Instant::now();
    let out = f();
    let took = start.elapsed();
    (out, PEAK.with(Cell::get) - before, took)
}

/// The most heap a reader may hold for an input of `len` bytes whose header claims far
/// more data than it holds: 128 KiB (header fields, messages, and a zlib or gzip
/// decoder's state, which is 75 KiB) plus 16 bytes per input byte (the data that is
/// there, decoded).
fn claim_bound(len: usize) -> usize {
    (128 << 10) + 16 * len
}

/// A header claiming 10^12 voxels: name, input, the data file it names (if any), words its
/// error must contain.
type Claim = (&'static str, Vec<u8>, Option<Vec<u8>>, &'static str);

/// Parses each claim and checks that it fails with its words, within 1 s, under
/// [`claim_bound`].
fn check(format: Format, cases: &[Claim]) {
    check_parse(&format!("{format:?}"), cases, |input, data| {
        format.parse(input, |n| match data {
            Some(d) => Ok(d.clone()),
            None => no_data_file(n),
        })
    })
}

/// [`check`] for any reader: `parse` takes the input and the data file.
fn check_parse<T>(
    label: &str,
    cases: &[Claim],
    parse: impl Fn(&[u8], &Option<Vec<u8>>) -> Result<T, ReadError>,
) {
    for (name, input, data, want) in cases {
        let (result, peak, took) = measure(|| parse(input, data));
        let message = match result {
            Ok(_) => panic!("{label} {name}: a result from a header claiming 10^12 values"),
            Err(e) => e.to_string(),
        };
        let len = input.len() + data.as_ref().map_or(0, Vec::len);
        let bound = claim_bound(len);
        println!(
            "{label} {name}: {len} input bytes, peak heap {peak} bytes (bound {bound}), {:.2} ms: {message}",
            took.as_secs_f64() * 1e3
        );
        assert!(
            message.contains(want),
            "{name}: wanted {want:?} in {message}"
        );
        assert!(
            peak <= bound,
            "{name}: peak heap {peak} bytes, bound {bound}"
        );
        assert!(took < Duration::from_secs(1), "{name}: took {took:?}");
    }
}

fn zlib(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

/// 10000^3 = 10^12 voxels.
const TEN_THOUSAND_CUBED: &str = "10000 10000 10000";

#[test]
fn vti_claims_fail_without_allocating() {
    let doc = |file_attrs: &str, format: &str, text: &str, appended: Option<(&str, Vec<u8>)>| {
        let mut s = format!(
            "<VTKFile type=\"ImageData\" {file_attrs}><ImageData WholeExtent=\"0 9999 0 9999 0 9999\"><Piece><PointData><DataArray type=\"UInt8\" Name=\"x\" format=\"{format}\" offset=\"0\">{text}</DataArray></PointData></Piece></ImageData>"
        )
        .into_bytes();
        if let Some((encoding, data)) = appended {
            s.extend(format!("<AppendedData encoding=\"{encoding}\">_").as_bytes());
            s.extend(data);
            s.extend(b"</AppendedData>");
        }
        s.extend(b"</VTKFile>");
        s
    };
    let b64 = |d: &[u8]| {
        use base64::Engine;
        base64::engine::general_purpose::STANDARD.encode(d)
    };
    let u64h = "header_type=\"UInt64\"";
    let claim = 1_000_000_000_000u64.to_le_bytes();
    // vtkZLibDataCompressor: one block of 10^12 bytes, its compressed size, the block.
    let block = zlib(&[7; 64]);
    let mut zlib_header: Vec<u8> = [1u64, 1_000_000_000_000, 0, block.len() as u64]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    zlib_header.extend(&block);
    let zlib_attrs = "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
    let expected = "expected 1000000000000 bytes";
    check(
        Format::Vti,
        &[
            (
                "ascii",
                doc("", "ascii", "1 2 3", None),
                None,
                "found 3 values, expected 1000000000000",
            ),
            (
                "binary",
                doc(u64h, "binary", &b64(&claim), None),
                None,
                expected,
            ),
            (
                "appended raw",
                doc(u64h, "appended", "", Some(("raw", claim.to_vec()))),
                None,
                expected,
            ),
            (
                "appended base64",
                doc(
                    u64h,
                    "appended",
                    "",
                    Some(("base64", b64(&claim).into_bytes())),
                ),
                None,
                expected,
            ),
            (
                "binary zlib",
                doc(zlib_attrs, "binary", &b64(&zlib_header), None),
                None,
                "inflates to 64 bytes, but the header says 1000000000000",
            ),
            (
                "appended raw zlib",
                doc(
                    zlib_attrs,
                    "appended",
                    "",
                    Some(("raw", zlib_header.clone())),
                ),
                None,
                "inflates to 64 bytes, but the header says 1000000000000",
            ),
        ],
    );
}

#[test]
fn vtu_claims_fail_without_allocating() {
    use common::vtu::{one_tetra, write, Enc, Opts};
    // The tetra file with `attr` (NumberOfPoints="4" or NumberOfCells="1") claiming more.
    let file = |o: Opts, attr: &str, claim: &str| {
        let mut bytes = write(&[one_tetra()], &o);
        let n = if attr == "NumberOfPoints" { 4 } else { 1 };
        let from = format!("{attr}=\"{n}\"").into_bytes();
        let at = bytes
            .windows(from.len())
            .position(|w| w == from)
            .expect("the attribute");
        bytes.splice(
            at..at + from.len(),
            format!("{attr}=\"{claim}\"").into_bytes(),
        );
        bytes
    };
    let twelve = "1000000000000";
    let mut cases: Vec<Claim> = vec![
        (
            "ascii points",
            file(Opts::ASCII, "NumberOfPoints", twelve),
            None,
            "found 12 values, expected 3000000000000",
        ),
        (
            "ascii cells",
            file(Opts::ASCII, "NumberOfCells", twelve),
            None,
            "found 1 values, expected 1000000000000",
        ),
    ];
    for (name, enc) in [
        ("binary points", Enc::Binary),
        ("appended raw points", Enc::AppendedRaw),
        ("appended base64 points", Enc::AppendedBase64),
    ] {
        cases.push((
            name,
            file(Opts::with(enc), "NumberOfPoints", twelve),
            None,
            "call for 24000000000000",
        ));
        let zlib = Opts {
            zlib: Some(64),
            ..Opts::with(enc)
        };
        cases.push((
            name,
            file(zlib, "NumberOfPoints", twelve),
            None,
            "24000000000000",
        ));
    }
    check_parse("Vtu", &cases, |input, _| ferrovol_io::vtu::parse(input));
}

/// A NIfTI header of `version` (1 or 2) for uint8 voxels of `dims`, data at byte 352
/// (NIfTI-1) or 544 (NIfTI-2), followed by 4 bytes of data.
fn nifti(version: u8, dims: [i16; 3]) -> Vec<u8> {
    let dim = [3, dims[0], dims[1], dims[2], 1, 1, 1, 1];
    let mut h;
    if version == 1 {
        h = vec![0u8; 352];
        h[0..4].copy_from_slice(&348i32.to_le_bytes());
        for (i, d) in dim.iter().enumerate() {
            h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
        }
        h[70..72].copy_from_slice(&2i16.to_le_bytes());
        h[108..112].copy_from_slice(&352f32.to_le_bytes());
        h[344..348].copy_from_slice(b"n+1\0");
    } else {
        h = vec![0u8; 544];
        h[0..4].copy_from_slice(&540i32.to_le_bytes());
        h[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
        h[12..14].copy_from_slice(&2i16.to_le_bytes());
        for (i, &d) in dim.iter().enumerate() {
            h[16 + 8 * i..24 + 8 * i].copy_from_slice(&i64::from(d).to_le_bytes());
        }
        h[168..176].copy_from_slice(&544i64.to_le_bytes());
    }
    for i in 1..4 {
        // pixdim[1..=3] = 1
        if version == 1 {
            h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
        } else {
            h[104 + 8 * i..112 + 8 * i].copy_from_slice(&1f64.to_le_bytes());
        }
    }
    h.extend([1, 2, 3, 4]);
    h
}

/// 10000^3 = 10^12 voxels.
const CLAIM: [i16; 3] = [10000, 10000, 10000];

#[test]
fn nifti_claims_fail_without_allocating() {
    let truncated = "expected 1000000000000 bytes, found 4";
    check(
        Format::Nifti,
        &[
            ("NIfTI-1", nifti(1, CLAIM), None, truncated),
            ("NIfTI-2", nifti(2, CLAIM), None, truncated),
            ("NIfTI-1 .gz", gzip(&nifti(1, CLAIM)), None, truncated),
            ("NIfTI-2 .gz", gzip(&nifti(2, CLAIM)), None, truncated),
        ],
    );
}

#[test]
fn metaimage_claims_fail_without_allocating() {
    let header = |extra: &str, file: &str| {
        format!("NDims = 3\nDimSize = {TEN_THOUSAND_CUBED}\nElementType = MET_UCHAR\n{extra}ElementDataFile = {file}\n")
            .into_bytes()
    };
    let with = |mut h: Vec<u8>, data: &[u8]| {
        h.extend(data);
        h
    };
    let truncated = "expected 1000000000000 bytes, found 4";
    check(
        Format::MetaImage,
        &[
            (
                "LOCAL raw",
                with(header("", "LOCAL"), &[1, 2, 3, 4]),
                None,
                truncated,
            ),
            (
                "LOCAL zlib",
                with(
                    header("CompressedData = True\n", "LOCAL"),
                    &zlib(&[1, 2, 3, 4]),
                ),
                None,
                "expected 1000000000000 bytes, found 4",
            ),
            (
                "LOCAL ascii",
                with(header("BinaryData = False\n", "LOCAL"), b"1 2 3 4"),
                None,
                "found 4 values, expected 1000000000000",
            ),
            (
                "LOCAL zlib ascii",
                with(
                    header("BinaryData = False\nCompressedData = True\n", "LOCAL"),
                    &zlib(b"1 2 3 4"),
                ),
                None,
                "found 4 values, expected 1000000000000",
            ),
            (
                "detached raw",
                header("", "v.raw"),
                Some(vec![1, 2, 3, 4]),
                truncated,
            ),
            (
                "detached, HeaderSize -1",
                header("HeaderSize = -1\n", "v.raw"),
                Some(vec![1, 2, 3, 4]),
                truncated,
            ),
        ],
    );
}

#[test]
fn nrrd_claims_fail_without_allocating() {
    let header = |encoding: &str, extra: &str| {
        format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: {TEN_THOUSAND_CUBED}\nencoding: {encoding}\n{extra}")
            .into_bytes()
    };
    let attached = |encoding: &str, extra: &str, data: &[u8]| {
        let mut f = header(encoding, extra);
        f.push(b'\n');
        f.extend(data);
        f
    };
    let truncated = "expected 1000000000000 bytes, found 4";
    check(
        Format::Nrrd,
        &[
            ("raw", attached("raw", "", &[1, 2, 3, 4]), None, truncated),
            (
                "gzip",
                attached("gzip", "", &gzip(&[1, 2, 3, 4])),
                None,
                truncated,
            ),
            (
                "ascii",
                attached("ascii", "", b"1 2 3 4"),
                None,
                "found 4 values, expected 1000000000000",
            ),
            ("hex", attached("hex", "", b"01020304"), None, truncated),
            (
                "byte skip -1",
                attached("raw", "byte skip: -1\n", &[1, 2, 3, 4]),
                None,
                truncated,
            ),
            (
                "detached",
                header("raw", "data file: v.raw\n"),
                Some(vec![1, 2, 3, 4]),
                truncated,
            ),
        ],
    );
}

/// Compressed data that inflates to far more than the header's size is inflated only up
/// to that size: a 10 KiB stream of 10 MiB of zeros, where the header wants 4 or 12 bytes.
#[test]
fn inflation_stops_at_the_claimed_size() {
    let bomb = |gz: bool| {
        let zeros = vec![0u8; 10 << 20];
        if gz {
            gzip(&zeros)
        } else {
            zlib(&zeros)
        }
    };
    let mha = {
        let mut f = b"NDims = 3\nDimSize = 3 2 2\nElementType = MET_UCHAR\nCompressedData = True\nElementDataFile = LOCAL\n".to_vec();
        f.extend(bomb(false));
        f
    };
    let nrrd = {
        let mut f =
            b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 2 2\nencoding: gzip\n\n".to_vec();
        f.extend(bomb(true));
        f
    };
    let nii = {
        let mut f = nifti(1, [2, 2, 1]);
        f.extend(vec![0u8; 10 << 20]);
        gzip(&f)
    };
    for (format, input) in [
        (Format::MetaImage, mha),
        (Format::Nrrd, nrrd),
        (Format::Nifti, nii),
    ] {
        let (result, peak, took) = measure(|| format.parse(&input, no_data_file));
        let bound = claim_bound(input.len());
        println!(
            "{format:?}: {} bytes inflating to 10 MiB, header 12 bytes: peak heap {peak} bytes (bound {bound}), {:.2} ms, {:?}",
            input.len(),
            took.as_secs_f64() * 1e3,
            result.as_ref().map(|v| v.dims)
        );
        let dims = result
            .expect("the first bytes after the header are the volume")
            .dims;
        assert!(dims == [3, 2, 2] || dims == [2, 2, 1], "{dims:?}");
        assert!(
            peak <= bound,
            "{format:?}: peak heap {peak} bytes, bound {bound}"
        );
    }
}
