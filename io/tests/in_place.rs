//! `open_volume`: raw data read in place (NRRD and MetaImage, detached and attached, and
//! `.vti` raw appended data; both byte orders) gives the values `read_volume` reads into
//! memory; a data file shorter than its header says is an error that names it, never a
//! panic.

use std::path::Path;

use ferrovol_core::VolumeData;
use ferrovol_io::{open_volume, read_volume};

mod common;
use common::TempDir;

/// Every value of `v`, read in runs of 7 (so runs cross rows and the end).
fn values(v: &VolumeData) -> Vec<f64> {
    let n = v.scalars.len();
    let mut out = vec![0.0; n];
    for start in (0..n).step_by(7) {
        let end = (start + 7).min(n);
        v.scalars.read_run(start, &mut out[start..end]).unwrap();
    }
    out
}

/// Opens `p` in place and in memory: the same volume, the in-place one a source.
fn check_same(p: &Path) {
    let a = open_volume(p).unwrap();
    let b = read_volume(p).unwrap();
    assert!(
        a.scalars.source().is_some(),
        "{} not read in place",
        p.display()
    );
    assert!(b.scalars.source().is_none());
    assert_eq!(
        (a.dims, a.components, a.spacing, a.origin, a.direction),
        (b.dims, b.components, b.spacing, b.origin, b.direction)
    );
    assert_eq!(a.scalars.scalar_type(), b.scalars.scalar_type());
    assert_eq!(values(&a), values(&b), "{}", p.display());
    assert_eq!(a.range(0), b.range(0));
}

const DIMS: [usize; 3] = [5, 4, 3];

fn f32_bytes(big: bool) -> Vec<u8> {
    (0..DIMS.iter().product::<usize>())
        .flat_map(|i| {
            let v = i as f32 * 1.5 - 20.0;
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        })
        .collect()
}

fn u16_bytes(big: bool, comps: usize) -> Vec<u8> {
    (0..DIMS.iter().product::<usize>() * comps)
        .flat_map(|i| {
            let v = (i * 997 % 65536) as u16;
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        })
        .collect()
}

#[test]
fn raw_files_read_in_place_equal_the_in_memory_read() {
    let dir = TempDir::new("same");
    for big in [false, true] {
        let endian = if big { "big" } else { "little" };
        let msb = if big { "True" } else { "False" };
        // NRRD, detached, with a byte skip
        let mut data = vec![7u8; 16];
        data.extend(f32_bytes(big));
        dir.write(&format!("f-{endian}.raw"), &data);
        let p = dir.write(
            &format!("f-{endian}.nhdr"),
            format!(
                "NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nspacings: 0.5 1 2\nencoding: raw\nendian: {endian}\nbyte skip: 16\ndata file: f-{endian}.raw\n"
            )
            .as_bytes(),
        );
        check_same(&p);
        // NRRD, attached, two components
        let mut nrrd = format!(
            "NRRD0005\ntype: unsigned short\ndimension: 4\nsizes: 2 5 4 3\nkinds: vector domain domain domain\nencoding: raw\nendian: {endian}\n\n"
        )
        .into_bytes();
        nrrd.extend(u16_bytes(big, 2));
        check_same(&dir.write(&format!("a-{endian}.nrrd"), &nrrd));
        // MetaImage, detached, data at the end of the file
        let mut data = vec![1u8; 9];
        data.extend(u16_bytes(big, 1));
        dir.write(&format!("m-{endian}.raw"), &data);
        let p = dir.write(
            &format!("m-{endian}.mhd"),
            format!(
                "ObjectType = Image\nNDims = 3\nDimSize = 5 4 3\nElementType = MET_USHORT\nElementSpacing = 1 2 3\nOffset = 1 2 3\nBinaryDataByteOrderMSB = {msb}\nHeaderSize = -1\nElementDataFile = m-{endian}.raw\n"
            )
            .as_bytes(),
        );
        check_same(&p);
        // MetaImage, attached (.mha)
        let mut mha = format!(
            "NDims = 3\nDimSize = 5 4 3\nElementType = MET_FLOAT\nElementByteOrderMSB = {msb}\nElementDataFile = LOCAL\n"
        )
        .into_bytes();
        mha.extend(f32_bytes(big));
        check_same(&dir.write(&format!("l-{endian}.mha"), &mha));
    }
}

#[test]
fn compressed_data_is_read_into_memory() {
    let dir = TempDir::new("ascii");
    let text: Vec<String> = (0..60).map(|i| i.to_string()).collect();
    let p = dir.write(
        "t.nrrd",
        format!(
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 3\nencoding: ascii\n\n{}\n",
            text.join(" ")
        )
        .as_bytes(),
    );
    let v = open_volume(&p).unwrap();
    assert!(v.scalars.source().is_none());
    assert_eq!(v.scalars, read_volume(&p).unwrap().scalars);
}

#[test]
fn a_truncated_raw_file_is_a_clear_error() {
    let dir = TempDir::new("short");
    let data = f32_bytes(false);
    let short = dir.write("short.raw", &data[..data.len() - 5]);
    let cases = [
        (
            "h.nhdr",
            "NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nendian: little\ndata file: short.raw\n",
        ),
        (
            "s.nhdr",
            "NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nendian: little\nbyte skip: -1\ndata file: short.raw\n",
        ),
        (
            "h.mhd",
            "NDims = 3\nDimSize = 5 4 3\nElementType = MET_FLOAT\nElementDataFile = short.raw\n",
        ),
        (
            "e.mhd",
            "NDims = 3\nDimSize = 5 4 3\nElementType = MET_FLOAT\nHeaderSize = -1\nElementDataFile = short.raw\n",
        ),
    ];
    for (name, header) in cases {
        let p = dir.write(name, header.as_bytes());
        let m = open_volume(&p).unwrap_err().to_string();
        println!("{m}");
        let want = format!("{}: truncated", short.display());
        assert!(m.starts_with(&want), "wanted {want:?} in {m}");
        assert!(m.contains("expected 240 bytes, found 235"), "{m}");
    }
    // attached data cut short: the header's own file
    let mut nrrd =
        b"NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nendian: little\n\n"
            .to_vec();
    nrrd.extend(&data[..100]);
    let p = dir.write("cut.nrrd", &nrrd);
    let m = open_volume(&p).unwrap_err().to_string();
    assert!(m.starts_with(&format!("{}: truncated", p.display())), "{m}");
    // a missing data file
    let p = dir.write(
        "gone.nhdr",
        b"NRRD0004\ntype: uchar\ndimension: 1\nsizes: 4\nencoding: raw\ndata file: gone.raw\n",
    );
    let m = open_volume(&p).unwrap_err().to_string();
    assert!(m.contains("gone.raw"), "{m}");
}

/// A `.vti` with raw appended data: a first array `skip` (3 bytes of data, so the chosen
/// array's offset is not 0), then `values` as `ty` in point data (its `Scalars`), with
/// `header` (UInt32 or UInt64) byte-count headers in `order`; `count` overrides the chosen
/// array's header.
fn vti_appended(ty: &str, values: &[u8], header: &str, big: bool, count: Option<u64>) -> Vec<u8> {
    let order = if big { "BigEndian" } else { "LittleEndian" };
    let width = if header == "UInt64" { 8 } else { 4 };
    let uint = |n: u64| -> Vec<u8> {
        let b = if big {
            n.to_be_bytes()
        } else {
            n.to_le_bytes()
        };
        if big {
            b[8 - width..].to_vec()
        } else {
            b[..width].to_vec()
        }
    };
    let offset = width + 3;
    let mut f = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"{order}\" header_type=\"{header}\">\n\
         <ImageData WholeExtent=\"2 6 0 3 0 2\" Origin=\"1 2 3\" Spacing=\"0.5 1 2\">\n<Piece Extent=\"2 6 0 3 0 2\">\n\
         <PointData Scalars=\"density\">\n\
         <DataArray type=\"UInt8\" Name=\"skip\" format=\"appended\" offset=\"0\"/>\n\
         <DataArray type=\"{ty}\" Name=\"density\" format=\"appended\" offset=\"{offset}\"/>\n\
         </PointData>\n</Piece>\n</ImageData>\n<AppendedData encoding=\"raw\">\n   _"
    )
    .into_bytes();
    f.extend(uint(3));
    f.extend([9, 9, 9]);
    f.extend(uint(count.unwrap_or(values.len() as u64)));
    f.extend(values);
    f.extend(b"\n</AppendedData>\n</VTKFile>\n");
    f
}

#[test]
fn raw_appended_vti_reads_in_place() {
    let dir = TempDir::new("vti");
    for big in [false, true] {
        for header in ["UInt32", "UInt64"] {
            let name = format!("f-{big}-{header}.vti");
            let f = vti_appended("Float32", &f32_bytes(big), header, big, None);
            check_same(&dir.write(&name, &f));
            let name = format!("u-{big}-{header}.vti");
            let f = vti_appended("UInt16", &u16_bytes(big, 1), header, big, None);
            check_same(&dir.write(&name, &f));
        }
    }
    // a byte-count header that disagrees with the extent: the in-memory reader's error
    let f = vti_appended("Float32", &f32_bytes(false), "UInt32", false, Some(236));
    let p = dir.write("wrong.vti", &f);
    let m = open_volume(&p).unwrap_err().to_string();
    assert_eq!(m, read_volume(&p).unwrap_err().to_string());
    assert!(m.contains("header says 236 bytes"), "{m}");
    // cut short: named, as for NRRD and MetaImage
    let f = vti_appended("Float32", &f32_bytes(false), "UInt32", false, None);
    let p = dir.write("cut.vti", &f[..f.len() - 60]);
    let m = open_volume(&p).unwrap_err().to_string();
    println!("{m}");
    assert!(m.starts_with(&format!("{}: truncated", p.display())), "{m}");
}

/// Rendering reads a source brick by brick, one run per row of a brick: every brick's runs
/// of the in-place `.vti` equal the in-memory reader's values.
#[test]
fn raw_appended_vti_bricks_equal_the_in_memory_ones() {
    let dir = TempDir::new("vti-bricks");
    let p = dir.write(
        "b.vti",
        &vti_appended("UInt16", &u16_bytes(false, 1), "UInt64", false, None),
    );
    let a = open_volume(&p).unwrap();
    let b = read_volume(&p).unwrap();
    assert!(a.scalars.source().is_some());
    let [nx, ny, nz] = a.dims.map(|d| d as usize);
    // bricks of 2³ cells: 3 × 3 × 2 points each (overlapping by one), clamped to the volume
    for (z0, y0, x0) in (0..nz - 1).step_by(2).flat_map(|z| {
        (0..ny - 1)
            .step_by(2)
            .flat_map(move |y| (0..nx - 1).step_by(2).map(move |x| (z, y, x)))
    }) {
        for z in z0..(z0 + 3).min(nz) {
            for y in y0..(y0 + 3).min(ny) {
                let x1 = (x0 + 3).min(nx);
                let start = (z * ny + y) * nx + x0;
                let mut run = vec![0.0; x1 - x0];
                a.scalars.read_run(start, &mut run).unwrap();
                let want: Vec<f64> = (start..start + run.len())
                    .map(|i| b.scalars.get(i))
                    .collect();
                assert_eq!(run, want, "brick at ({x0}, {y0}, {z0}), row ({y}, {z})");
            }
        }
    }
}
