//! NIfTI-1 and NIfTI-2 single-file (`.nii`, `.nii.gz`) reader.
//!
//! The header (348 bytes for NIfTI-1, 540 for NIfTI-2, either byte order) is parsed here
//! directly, so that every inconsistency becomes an error instead of a panic.
//!
//! * Dimensions: `dim[1..=3]` (missing ones are 1). A 5th dimension (`dim[5]`, NIfTI's
//!   vector/"intent" axis) of 2–4 with `dim[4] == 1` becomes interleaved components; time
//!   series (`dim[4] > 1`) and higher dimensions are rejected.
//! * Spacing: `pixdim[1..=3]` as stored (the units of `xyzt_units` are not converted);
//!   non-positive spacing is an error. Axes beyond `dim[0]` get spacing 1.
//! * Types: `uint8`, `int8`, `int16`, `uint16`, `int32`, `uint32`, `float32`, `float64`,
//!   `RGB24` (3 × u8 components) and `RGBA32` (4 × u8); the type is kept.
//! * Intensity scaling: when `scl_slope` is finite and non-zero and `(slope, inter)` is
//!   not `(1, 0)`, values become `slope · v + inter`, stored as `F32` (`F64` for `float64`
//!   data). Otherwise the raw values are kept.
//! * Orientation: the origin comes from the sform (`srow_*[3]`) when `sform_code > 0`,
//!   else from the qform (`qoffset_*`) when `qform_code > 0`, else it is 0 (nibabel's
//!   order of preference). The direction comes from the same transform when it is
//!   orthonormal: the sform's columns divided by their lengths (spacing stays `pixdim`), or
//!   the qform quaternion with `qfac = pixdim[0]`. A sheared sform leaves the identity
//!   direction. Coordinates stay in NIfTI's RAS+ world space (no conversion to LPS).
//! * Separate `.hdr`/`.img` pairs and Analyze 7.5 files are rejected with a hint.

use std::io::Read;

use ferrovol_core::{Direction, ScalarType, Scalars, VolumeData, IDENTITY_DIRECTION};

use crate::decode::{decode_binary, FromBytes, Geometry, Layout};
use crate::ReadError;

const FORMAT: &str = "NIfTI";
const SUPPORTED_TYPES: &str =
    "uint8, int8, int16, uint16, int32, uint32, float32, float64, RGB24 and RGBA32";

/// Parses a `.nii` file, or a gzip-compressed one (`.nii.gz`), from its bytes.
pub fn parse(file: &[u8]) -> Result<VolumeData, ReadError> {
    if file.starts_with(&[0x1f, 0x8b]) {
        // gzip: decompress only as much as the header asks for.
        let corrupt = |e: std::io::Error| {
            ReadError::corrupt(
                "gzip stream",
                format!(
                    "{e} (the .nii.gz file is damaged or incomplete; compress or copy it again)"
                ),
            )
        };
        let mut dec = flate2::read::MultiGzDecoder::new(file);
        let mut buf = Vec::new();
        (&mut dec)
            .take(540)
            .read_to_end(&mut buf)
            .map_err(corrupt)?;
        let header = parse_header(&buf)?;
        let needed = header.needed_bytes()?;
        let more = needed.saturating_sub(buf.len());
        (&mut dec)
            .take(more as u64)
            .read_to_end(&mut buf)
            .map_err(corrupt)?;
        build(&header, &buf)
    } else {
        let header = parse_header(file)?;
        build(&header, file)
    }
}

fn bad(message: impl Into<String>) -> ReadError {
    ReadError::bad_header(FORMAT, message)
}

/// The header fields the reader uses, widened to NIfTI-2's types.
#[derive(Debug)]
struct Header {
    big_endian: bool,
    dim: [i64; 8],
    pixdim: [f64; 8],
    /// scl_slope, scl_inter.
    scl: [f64; 2],
    /// qform_code, sform_code.
    codes: [i32; 2],
    /// quatern_b, c, d, qoffset_x, y, z.
    quatern: [f64; 6],
    srow: [[f64; 4]; 3],
    /// Dimensions x, y, z; `datatype`'s scalar type; components per voxel:
    /// `type_components` (RGB24: 3) times `vector` (dim[5]).
    layout: Layout,
    type_components: u64,
    vector: u64,
    data_offset: usize,
}

impl Header {
    fn needed_bytes(&self) -> Result<usize, ReadError> {
        self.data_offset
            .checked_add(self.layout.nbytes)
            .ok_or_else(|| bad("vox_offset plus the data size overflows"))
    }
}

/// How a header field's number is stored.
#[derive(Clone, Copy)]
enum Num {
    I16,
    I32,
    I64,
    F32,
    F64,
}

/// A field: how it is stored and its byte offset.
type Field = (Num, usize);

/// Element `i` of the array that starts at `field`.
fn nth((num, off): Field, i: usize) -> Field {
    let width = match num {
        Num::I16 => 2,
        Num::I32 | Num::F32 => 4,
        Num::I64 | Num::F64 => 8,
    };
    (num, off + width * i)
}

/// Where a NIfTI version keeps the fields the reader uses. `scl` is scl_slope (then
/// scl_inter), `codes` qform_code (then sform_code), `quatern` quatern_b (then c, d and
/// qoffset_x, y, z), `srow` srow_x\[0\] (the 3x4 sform, row by row).
struct Version {
    size: usize,
    magic: usize,
    datatype: Field,
    dim: Field,
    pixdim: Field,
    vox_offset: Field,
    scl: Field,
    codes: Field,
    quatern: Field,
    srow: Field,
}

const NIFTI1: Version = Version {
    size: 348,
    magic: 344,
    datatype: (Num::I16, 70),
    dim: (Num::I16, 40),
    pixdim: (Num::F32, 76),
    vox_offset: (Num::F32, 108),
    scl: (Num::F32, 112),
    codes: (Num::I16, 252),
    quatern: (Num::F32, 256),
    srow: (Num::F32, 280),
};

const NIFTI2: Version = Version {
    size: 540,
    magic: 4,
    datatype: (Num::I16, 12),
    dim: (Num::I64, 16),
    pixdim: (Num::F64, 104),
    vox_offset: (Num::I64, 168),
    scl: (Num::F64, 176),
    codes: (Num::I32, 344),
    quatern: (Num::F64, 352),
    srow: (Num::F64, 400),
};

/// Reads header fields; the caller has checked the slice is long enough (missing bytes
/// read as zero rather than panic).
struct Fields<'a> {
    b: &'a [u8],
    be: bool,
}

impl Fields<'_> {
    fn arr<const N: usize>(&self, off: usize) -> [u8; N] {
        off.checked_add(N)
            .and_then(|end| self.b.get(off..end))
            .and_then(|s| s.try_into().ok())
            .unwrap_or([0; N])
    }
    fn num<T: FromBytes<N>, const N: usize>(&self, off: usize) -> T {
        T::from_bytes(self.arr(off), self.be)
    }
    /// An integer field (a float field is truncated toward zero).
    fn int(&self, field: Field) -> i64 {
        match field {
            (Num::I16, off) => self.num::<i16, 2>(off).into(),
            (Num::I32, off) => self.num::<i32, 4>(off).into(),
            (Num::I64, off) => self.num(off),
            (Num::F32 | Num::F64, _) => self.float(field) as i64,
        }
    }
    /// A field as a float.
    fn float(&self, field: Field) -> f64 {
        match field {
            (Num::F32, off) => self.num::<f32, 4>(off).into(),
            (Num::F64, off) => self.num(off),
            (Num::I16 | Num::I32 | Num::I64, _) => self.int(field) as f64,
        }
    }
}

fn type_of(datatype: i32) -> Result<(ScalarType, u64), &'static str> {
    Ok(match datatype {
        2 => (ScalarType::U8, 1),
        4 => (ScalarType::I16, 1),
        8 => (ScalarType::I32, 1),
        16 => (ScalarType::F32, 1),
        64 => (ScalarType::F64, 1),
        256 => (ScalarType::I8, 1),
        512 => (ScalarType::U16, 1),
        768 => (ScalarType::U32, 1),
        128 => (ScalarType::U8, 3),
        2304 => (ScalarType::U8, 4),
        0 => return Err("unknown (datatype 0)"),
        1 => return Err("binary (datatype 1)"),
        32 => return Err("complex64 (datatype 32)"),
        1024 => return Err("int64 (datatype 1024)"),
        1280 => return Err("uint64 (datatype 1280)"),
        1536 => return Err("float128 (datatype 1536)"),
        1792 => return Err("complex128 (datatype 1792)"),
        2048 => return Err("complex256 (datatype 2048)"),
        _ => return Err("unknown"),
    })
}

fn parse_header(b: &[u8]) -> Result<Header, ReadError> {
    let first4: [u8; 4] = b
        .get(..4)
        .and_then(|s| s.try_into().ok())
        .ok_or_else(|| ReadError::truncated("NIfTI header", 348, b.len()))?;
    let (nifti2, be) = match (i32::from_le_bytes(first4), i32::from_be_bytes(first4)) {
        (348, _) => (false, false),
        (_, 348) => (false, true),
        (540, _) => (true, false),
        (_, 540) => (true, true),
        (le, _) => {
            return Err(bad(format!(
            "sizeof_hdr is {le}, expected 348 (NIfTI-1) or 540 (NIfTI-2); this is not a NIfTI file"
        )))
        }
    };
    let v = if nifti2 { &NIFTI2 } else { &NIFTI1 };
    let header_size = v.size;
    if b.len() < header_size {
        return Err(ReadError::truncated("NIfTI header", header_size, b.len()));
    }
    let f = Fields { b, be };
    let magic: [u8; 4] = f.arr(v.magic);
    let magic_text = String::from_utf8_lossy(&magic[..3]).into_owned();
    match &magic[..3] {
        b"n+1" | b"n+2" => {}
        b"ni1" | b"ni2" => {
            return Err(ReadError::unsupported(
                "this is the header of a separate .hdr/.img NIfTI pair; convert it to a single .nii file (e.g. with nibabel or fslchfiletype NIFTI)",
            ))
        }
        _ => {
            return Err(ReadError::unsupported(
                format!("magic {magic_text:?} is not NIfTI's n+1/n+2 (an Analyze 7.5 file?); convert it to NIfTI"),
            ))
        }
    }

    let dim: [i64; 8] = std::array::from_fn(|i| f.int(nth(v.dim, i)));
    let pixdim: [f64; 8] = std::array::from_fn(|i| f.float(nth(v.pixdim, i)));
    let srow: [[f64; 4]; 3] =
        std::array::from_fn(|r| std::array::from_fn(|c| f.float(nth(v.srow, 4 * r + c))));
    let quatern: [f64; 6] = std::array::from_fn(|i| f.float(nth(v.quatern, i)));
    let datatype = f.int(v.datatype) as i32;
    let vox_offset = f.float(v.vox_offset);
    let scl: [f64; 2] = std::array::from_fn(|i| f.float(nth(v.scl, i)));
    let codes: [i32; 2] = std::array::from_fn(|i| f.int(nth(v.codes, i)) as i32);

    let (ty, type_components) =
        type_of(datatype).map_err(|name| ReadError::unsupported_type(name, SUPPORTED_TYPES))?;

    let nd = dim[0];
    if !(1..=7).contains(&nd) {
        return Err(bad(format!(
            "dim[0] (the number of dimensions) is {nd}; it must be 1 to 7"
        )));
    }
    let nd = nd as usize;
    let mut d = [1u64; 8];
    for i in 1..=nd {
        if dim[i] < 1 {
            return Err(bad(format!(
                "dim[{i}] is {}; every dimension must be at least 1",
                dim[i]
            )));
        }
        d[i] = dim[i] as u64;
    }
    if d[4] > 1 {
        return Err(ReadError::unsupported(
            format!(
                "a 4D series of {} volumes (dim[4]); extract one volume first (e.g. fslroi in.nii.gz out.nii.gz 0 1)",
                d[4]
            ),
        ));
    }
    if d[6] > 1 || d[7] > 1 {
        return Err(ReadError::unsupported(
            format!("dimensions 6 and 7 are {} and {}; only 3D volumes (with up to 4 components in dim[5]) are supported", d[6], d[7]),
        ));
    }
    let vector = d[5];
    let components = type_components.saturating_mul(vector);
    if components > 4 {
        return Err(ReadError::unsupported(format!(
            "{components} components per voxel (dim[5] = {vector}); ferrovol renders 1 to 4"
        )));
    }
    let dims = [d[1], d[2], d[3]];
    let layout = Layout::new(FORMAT, dims, components, ty)?;

    if !vox_offset.is_finite() || vox_offset < 0.0 || vox_offset.fract() != 0.0 || vox_offset > 1e15
    {
        return Err(bad(format!(
            "vox_offset is {vox_offset}; it must be a non-negative whole number of bytes"
        )));
    }
    // Single-file NIfTI puts data after the header and a 4-byte extension flag; treat
    // smaller offsets (some writers put 0) as that minimum.
    let data_offset = (vox_offset as usize).max(header_size + 4);

    Ok(Header {
        big_endian: be,
        dim,
        pixdim,
        scl,
        codes,
        quatern,
        srow,
        layout,
        type_components,
        vector,
        data_offset,
    })
}

fn build(h: &Header, file: &[u8]) -> Result<VolumeData, ReadError> {
    let end = h.needed_bytes()?;
    let data = file.get(h.data_offset..end).ok_or_else(|| {
        ReadError::truncated(
            "NIfTI voxel data",
            h.layout.nbytes,
            file.len().saturating_sub(h.data_offset),
        )
    })?;
    let mut scalars = decode_binary(data, h.layout.ty, h.big_endian);
    if h.vector > 1 {
        // dim[5] is the slowest axis in the file: make it interleaved.
        let nvox = h.layout.count / h.layout.components as usize;
        scalars = interleave(scalars, nvox, h.vector as usize, h.type_components as usize);
    }

    // Intensity scaling.
    let [slope, inter] = h.scl;
    if h.type_components == 1
        && slope.is_finite()
        && inter.is_finite()
        && slope != 0.0
        && (slope != 1.0 || inter != 0.0)
    {
        scalars = match scalars {
            Scalars::F64(v) => Scalars::F64(v.into_iter().map(|x| x * slope + inter).collect()),
            other => {
                let n = other.len();
                Scalars::F32(
                    (0..n)
                        .map(|i| (other.get(i) * slope + inter) as f32)
                        .collect(),
                )
            }
        };
    }

    // Geometry.
    let mut geometry = Geometry::default();
    let nd = h.dim[0].clamp(0, 3) as usize;
    geometry.spacing[..nd].copy_from_slice(&h.pixdim[1..=nd]);
    (geometry.origin, geometry.direction) = orientation(h);
    h.layout.volume(geometry, scalars)
}

/// Origin and direction from the sform or qform (see the module documentation).
fn orientation(h: &Header) -> ([f64; 3], Direction) {
    let [qform_code, sform_code] = h.codes;
    if sform_code > 0 {
        let m = [
            [h.srow[0][0], h.srow[0][1], h.srow[0][2]],
            [h.srow[1][0], h.srow[1][1], h.srow[1][2]],
            [h.srow[2][0], h.srow[2][1], h.srow[2][2]],
        ];
        let origin = [h.srow[0][3], h.srow[1][3], h.srow[2][3]];
        let direction = match normalize_columns(m) {
            Some((_, d)) if is_orthonormal(&d) => d,
            _ => IDENTITY_DIRECTION,
        };
        return (origin, direction);
    }
    if qform_code > 0 {
        let [mut b, mut c, mut d, x, y, z] = h.quatern;
        let s = b * b + c * c + d * d;
        let a = if s > 1.0 {
            // Not a unit quaternion: normalize (b, c, d) and use a = 0, as nifti1_io does.
            let n = s.sqrt();
            b /= n;
            c /= n;
            d /= n;
            0.0
        } else {
            (1.0 - s).sqrt()
        };
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let mut r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - b * b - c * c,
            ],
        ];
        for row in r.iter_mut() {
            row[2] *= qfac;
        }
        let direction = if is_orthonormal(&r) {
            r
        } else {
            IDENTITY_DIRECTION
        };
        return ([x, y, z], direction);
    }
    ([0.0; 3], IDENTITY_DIRECTION)
}

/// Normalizes the columns of `m` (row-major; column `j` is the world direction of index
/// axis `j`). Returns the column lengths and the normalized matrix, or `None` if a column
/// is zero or not finite.
fn normalize_columns(m: [[f64; 3]; 3]) -> Option<([f64; 3], [[f64; 3]; 3])> {
    let mut lens = [0.0; 3];
    let mut d = m;
    for j in 0..3 {
        let len = (m[0][j] * m[0][j] + m[1][j] * m[1][j] + m[2][j] * m[2][j]).sqrt();
        if !len.is_finite() || len <= 0.0 {
            return None;
        }
        lens[j] = len;
        for row in d.iter_mut() {
            row[j] /= len;
        }
    }
    Some((lens, d))
}

/// Whether the row-major matrix is orthonormal (to 1e-4): a rotation or a reflection.
fn is_orthonormal(m: &[[f64; 3]; 3]) -> bool {
    for a in 0..3 {
        for b in 0..3 {
            let dot = m[0][a] * m[0][b] + m[1][a] * m[1][b] + m[2][a] * m[2][b];
            let want = if a == b { 1.0 } else { 0.0 };
            // Written so that NaN also fails.
            if (dot - want).abs().partial_cmp(&1e-4) != Some(std::cmp::Ordering::Less) {
                return false;
            }
        }
    }
    true
}

/// Reorders `vector` planar blocks of `nvox` voxels (each voxel `per` values) into
/// interleaved order: voxel 0's values of block 0, block 1, …, then voxel 1, …
fn interleave(s: Scalars, nvox: usize, vector: usize, per: usize) -> Scalars {
    fn go<T: Copy>(v: Vec<T>, nvox: usize, vector: usize, per: usize) -> Vec<T> {
        let mut out = Vec::with_capacity(v.len());
        for p in 0..nvox {
            for c in 0..vector {
                let start = (c * nvox + p) * per;
                if let Some(vals) = v.get(start..start + per) {
                    out.extend_from_slice(vals);
                }
            }
        }
        out
    }
    match s {
        Scalars::U8(v) => Scalars::U8(go(v, nvox, vector, per)),
        Scalars::I8(v) => Scalars::I8(go(v, nvox, vector, per)),
        Scalars::U16(v) => Scalars::U16(go(v, nvox, vector, per)),
        Scalars::I16(v) => Scalars::I16(go(v, nvox, vector, per)),
        Scalars::U32(v) => Scalars::U32(go(v, nvox, vector, per)),
        Scalars::I32(v) => Scalars::I32(go(v, nvox, vector, per)),
        Scalars::F32(v) => Scalars::F32(go(v, nvox, vector, per)),
        Scalars::F64(v) => Scalars::F64(go(v, nvox, vector, per)),
        // decoded data is always in memory
        s @ Scalars::Source(_) => s,
    }
}

#[cfg(test)]
mod tests {
    use super::parse;
    use crate::test_util::{assert_geometry, check_errors, gzip, never_panics};
    use ferrovol_core::Scalars;

    /// Fields of a test header; written as NIfTI-1 or NIfTI-2.
    #[derive(Clone)]
    struct Hdr {
        be: bool,
        dim: [i64; 8],
        datatype: i16,
        pixdim: [f64; 8],
        slope: f64,
        inter: f64,
        qform_code: i16,
        sform_code: i16,
        quatern: [f64; 6],
        srow: [[f64; 4]; 3],
        magic: &'static [u8],
    }

    impl Hdr {
        fn new(datatype: i16) -> Hdr {
            Hdr {
                be: false,
                dim: [3, 3, 2, 2, 1, 1, 1, 1],
                datatype,
                pixdim: [1.0, 0.5, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0],
                slope: 0.0,
                inter: 0.0,
                qform_code: 0,
                sform_code: 0,
                quatern: [0.0; 6],
                srow: [[0.0; 4]; 3],
                magic: b"n+1\0",
            }
        }

        fn put(&self, buf: &mut [u8], off: usize, b: &[u8]) {
            let mut b = b.to_vec();
            if self.be {
                b.reverse();
            }
            buf[off..off + b.len()].copy_from_slice(&b);
        }

        /// NIfTI-1 header + 4-byte extension flag (vox_offset 352).
        fn nifti1(&self) -> Vec<u8> {
            let mut b = vec![0u8; 352];
            self.put(&mut b, 0, &348i32.to_le_bytes());
            for i in 0..8 {
                self.put(&mut b, 40 + 2 * i, &(self.dim[i] as i16).to_le_bytes());
                self.put(&mut b, 76 + 4 * i, &(self.pixdim[i] as f32).to_le_bytes());
            }
            self.put(&mut b, 70, &self.datatype.to_le_bytes());
            self.put(&mut b, 108, &352f32.to_le_bytes());
            self.put(&mut b, 112, &(self.slope as f32).to_le_bytes());
            self.put(&mut b, 116, &(self.inter as f32).to_le_bytes());
            self.put(&mut b, 252, &self.qform_code.to_le_bytes());
            self.put(&mut b, 254, &self.sform_code.to_le_bytes());
            for i in 0..6 {
                self.put(&mut b, 256 + 4 * i, &(self.quatern[i] as f32).to_le_bytes());
            }
            for r in 0..3 {
                for c in 0..4 {
                    self.put(
                        &mut b,
                        280 + 16 * r + 4 * c,
                        &(self.srow[r][c] as f32).to_le_bytes(),
                    );
                }
            }
            b[344..348].copy_from_slice(self.magic);
            b
        }

        /// NIfTI-2 header + 4-byte extension flag (vox_offset 544).
        fn nifti2(&self) -> Vec<u8> {
            let mut b = vec![0u8; 544];
            self.put(&mut b, 0, &540i32.to_le_bytes());
            b[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
            self.put(&mut b, 12, &self.datatype.to_le_bytes());
            for i in 0..8 {
                self.put(&mut b, 16 + 8 * i, &self.dim[i].to_le_bytes());
                self.put(&mut b, 104 + 8 * i, &self.pixdim[i].to_le_bytes());
            }
            self.put(&mut b, 168, &544i64.to_le_bytes());
            self.put(&mut b, 176, &self.slope.to_le_bytes());
            self.put(&mut b, 184, &self.inter.to_le_bytes());
            self.put(&mut b, 344, &(self.qform_code as i32).to_le_bytes());
            self.put(&mut b, 348, &(self.sform_code as i32).to_le_bytes());
            for i in 0..6 {
                self.put(&mut b, 352 + 8 * i, &self.quatern[i].to_le_bytes());
            }
            for r in 0..3 {
                for c in 0..4 {
                    self.put(&mut b, 400 + 32 * r + 8 * c, &self.srow[r][c].to_le_bytes());
                }
            }
            b
        }
    }

    fn le_or_be<const N: usize>(v: impl IntoIterator<Item = [u8; N]>, be: bool) -> Vec<u8> {
        v.into_iter()
            .flat_map(|mut b| {
                if be {
                    b.reverse();
                }
                b
            })
            .collect()
    }

    #[test]
    fn readers_nifti_u8_with_qform() {
        let mut h = Hdr::new(2);
        let s = 0.5f64.sqrt();
        h.qform_code = 1;
        h.quatern = [0.0, 0.0, s, 5.0, 6.0, 7.0]; // 90° about z
        let vals: Vec<u8> = (0..12).map(|i| i * 20).collect();
        let mut f = h.nifti1();
        f.extend(&vals);
        let v = parse(&f).unwrap();
        assert_geometry(&v, [3, 2, 2], [0.5, 1.0, 2.0], [5.0, 6.0, 7.0]);
        let want = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        for (got, want) in v.direction.iter().flatten().zip(want.iter().flatten()) {
            assert!((got - want).abs() < 1e-6, "{:?}", v.direction);
        }
        assert_eq!(v.scalars, Scalars::U8(vals.clone()));

        // qfac = pixdim[0] = -1 flips the third axis.
        h.pixdim[0] = -1.0;
        let mut f = h.nifti1();
        f.extend(&vals);
        let v = parse(&f).unwrap();
        assert!((v.direction[2][2] + 1.0).abs() < 1e-6, "{:?}", v.direction);
    }

    #[test]
    fn readers_nifti_gz_big_endian_int16_with_sform() {
        let mut h = Hdr::new(4);
        h.be = true;
        h.sform_code = 2;
        h.qform_code = 1; // ignored: the sform wins
        h.quatern = [0.0, 0.0, 1.0, 9.0, 9.0, 9.0];
        h.srow = [
            [-0.5, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 2.0],
            [0.0, 0.0, 2.0, 3.0],
        ];
        let vals: Vec<i16> = (0..12).map(|i| i * -1000 + 3).collect();
        let mut f = h.nifti1();
        f.extend(le_or_be(vals.iter().map(|v| v.to_le_bytes()), true));
        let v = parse(&gzip(&f)).unwrap();
        assert_eq!(v.spacing, [0.5, 1.0, 2.0]);
        assert_eq!(v.origin, [1.0, 2.0, 3.0]);
        assert_eq!(
            v.direction,
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(v.scalars, Scalars::I16(vals.clone()));

        // A sheared sform sets only the origin.
        h.srow[0][1] = 0.3;
        let mut f = h.nifti1();
        f.extend(le_or_be(vals.iter().map(|v| v.to_le_bytes()), true));
        let v = parse(&gzip(&f)).unwrap();
        assert_eq!(v.origin, [1.0, 2.0, 3.0]);
        assert_eq!(v.direction, ferrovol_core::IDENTITY_DIRECTION);
    }

    #[test]
    fn readers_nifti_scaling() {
        let vals: Vec<i16> = (0..12).map(|i| i * 10 - 20).collect();
        let data = le_or_be(vals.iter().map(|v| v.to_le_bytes()), false);
        let mut h = Hdr::new(4);
        h.slope = 2.0;
        h.inter = -1.0;
        let mut f = h.nifti1();
        f.extend(&data);
        let v = parse(&f).unwrap();
        assert_eq!(
            v.scalars,
            Scalars::F32(vals.iter().map(|&x| x as f32 * 2.0 - 1.0).collect())
        );

        // slope 1 / inter 0 and slope 0 keep the stored type.
        for (slope, inter) in [(1.0, 0.0), (0.0, 5.0)] {
            h.slope = slope;
            h.inter = inter;
            let mut f = h.nifti1();
            f.extend(&data);
            let v = parse(&f).unwrap();
            assert_eq!(v.scalars, Scalars::I16(vals.clone()));
        }

        // float64 data stays float64.
        let mut h = Hdr::new(64);
        h.slope = 0.5;
        let d: Vec<f64> = (0..12).map(|i| i as f64).collect();
        let mut f = h.nifti1();
        f.extend(le_or_be(d.iter().map(|v| v.to_le_bytes()), false));
        let v = parse(&f).unwrap();
        assert_eq!(v.scalars, Scalars::F64(d.iter().map(|x| x * 0.5).collect()));
    }

    #[test]
    fn readers_nifti_rgb_and_vector_components() {
        let rgb: Vec<u8> = (0..36).collect();
        let mut f = Hdr::new(128).nifti1();
        f.extend(&rgb);
        let v = parse(&f).unwrap();
        assert_eq!(v.components, 3);
        assert_eq!(v.scalars, Scalars::U8(rgb));

        // dim[5] = 2: two planar float32 volumes become 2 interleaved components.
        let mut h = Hdr::new(16);
        h.dim = [5, 3, 2, 2, 1, 2, 1, 1];
        let planar: Vec<f32> = (0..24).map(|i| i as f32).collect();
        let mut f = h.nifti1();
        f.extend(le_or_be(planar.iter().map(|v| v.to_le_bytes()), false));
        let v = parse(&f).unwrap();
        assert_eq!(v.components, 2);
        let want: Vec<f32> = (0..12).flat_map(|p| [p as f32, (p + 12) as f32]).collect();
        assert_eq!(v.scalars, Scalars::F32(want));
    }

    #[test]
    fn readers_nifti2_uint16() {
        let mut h = Hdr::new(512);
        h.sform_code = 1;
        h.srow = [
            [0.5, 0.0, 0.0, -1.0],
            [0.0, 1.0, 0.0, -2.0],
            [0.0, 0.0, 2.0, -3.0],
        ];
        let vals: Vec<u16> = (0..12).map(|i| 60000 - i * 7).collect();
        let mut f = h.nifti2();
        f.extend(le_or_be(vals.iter().map(|v| v.to_le_bytes()), false));
        let v = parse(&f).unwrap();
        assert_geometry(&v, [3, 2, 2], [0.5, 1.0, 2.0], [-1.0, -2.0, -3.0]);
        assert_eq!(v.scalars, Scalars::U16(vals.clone()));

        h.be = true;
        let mut f = h.nifti2();
        f.extend(le_or_be(vals.iter().map(|v| v.to_le_bytes()), true));
        let v = parse(&gzip(&f)).unwrap();
        assert_eq!(v.scalars, Scalars::U16(vals));
    }

    #[test]
    fn readers_nifti_errors() {
        let with = |h: &Hdr, data: &[u8]| {
            let mut f = h.nifti1();
            f.extend(data);
            f
        };
        let twelve = [1u8; 12];
        let mut cases: Vec<(&str, Vec<u8>, &str)> = vec![
            (
                "trunc.nii",
                with(&Hdr::new(2), &twelve[..5]),
                "truncated NIfTI voxel data: expected 12 bytes, found 5",
            ),
            (
                "hdr.nii",
                Hdr::new(2).nifti1()[..100].to_vec(),
                "truncated NIfTI header: expected 348 bytes, found 100",
            ),
            ("tiny.nii", vec![1, 2], "truncated NIfTI header"),
            ("notnii.nii", vec![7; 400], "not a NIfTI file"),
            (
                "i64.nii",
                with(&Hdr::new(1024), &[0; 96]),
                "unsupported scalar type 'int64",
            ),
            ("cplx.nii", with(&Hdr::new(32), &[0; 96]), "complex64"),
            (
                "nan.nii",
                with(&Hdr::new(16), &[0, 0, 0xc0, 0x7f].repeat(12)),
                "NaN",
            ),
            (
                "trunc.nii.gz",
                gzip(&with(&Hdr::new(2), &twelve[..5])),
                "truncated NIfTI voxel data",
            ),
        ];
        let mut h = Hdr::new(2);
        h.dim = [4, 3, 2, 2, 3, 1, 1, 1];
        cases.push(("ts.nii", with(&h, &[0; 36]), "4D series of 3 volumes"));
        let mut h = Hdr::new(2);
        h.pixdim[2] = 0.0;
        cases.push(("zero.nii", with(&h, &twelve), "spacing along y is 0"));
        let mut h = Hdr::new(2);
        h.pixdim[3] = -2.0;
        cases.push(("neg.nii", with(&h, &twelve), "spacing along z is -2"));
        let mut h = Hdr::new(2);
        h.magic = b"ni1\0";
        cases.push(("pair.nii", with(&h, &twelve), ".hdr/.img"));
        let mut h = Hdr::new(2);
        h.dim[0] = 0;
        cases.push(("dim0.nii", with(&h, &twelve), "dim[0]"));
        let mut h = Hdr::new(2);
        h.dim[2] = -4;
        cases.push(("dimneg.nii", with(&h, &twelve), "dim[2] is -4"));
        let mut h = Hdr::new(2);
        h.dim = [5, 3, 2, 2, 1, 5, 1, 1];
        cases.push(("vec5.nii", with(&h, &[0; 60]), "5 components"));
        let mut gz = gzip(&with(&Hdr::new(2), &twelve));
        let n = gz.len();
        gz[n / 2] ^= 0xff;
        gz.truncate(n - 6);
        cases.push(("bad.nii.gz", gz, "gzip"));
        check_errors(parse, &cases);
    }

    /// 10^12 voxels of float64 (8 TB) in a few bytes: an error, not an allocation.
    #[test]
    fn readers_nifti_absurd_size_fails_before_allocating() {
        let mut h = Hdr::new(64);
        h.dim = [3, 10_000, 10_000, 10_000, 1, 1, 1, 1];
        let mut f = h.nifti2();
        f.extend([0; 16]);
        let cases = [
            ("nii", f.clone(), "expected 8000000000000 bytes, found 16"),
            ("nii.gz", gzip(&f), "expected 8000000000000 bytes, found 16"),
        ];
        check_errors(parse, &cases);
    }

    #[test]
    fn readers_nifti_never_panics_on_damaged_files() {
        let mut h = Hdr::new(4);
        h.sform_code = 1;
        h.srow = [
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 2.0],
            [0.0, 0.0, 1.0, 3.0],
        ];
        let mut f = h.nifti1();
        f.extend([3u8; 24]);
        never_panics(parse, &f, &[0x00, 0xff, 0x7f, 0x80]);
    }
}
