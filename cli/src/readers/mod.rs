//! Volume file readers: VTK XML ImageData (`.vti`), NIfTI-1/2 (`.nii`, `.nii.gz`),
//! MetaImage (`.mha`, `.mhd`) and NRRD (`.nrrd`, `.nhdr`).
//!
//! Every reader keeps the scalar type stored in the file (no conversion to float, except
//! NIfTI data with a non-trivial `scl_slope`/`scl_inter`), returns a validated
//! [`VolumeData`], and reports every problem as a [`ReadError`] whose message names the
//! file, the problem and what to do about it. Nothing in a file's content can make a
//! reader panic: all sizes are checked (with overflow checks) before data is touched.

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};

use ferrovol_core::{ScalarType, Scalars, VolumeData};

mod metaimage;
mod nifti;
mod nrrd;
mod vti;

/// File name endings `read_volume` understands.
pub const SUPPORTED_EXTENSIONS: &[&str] =
    &[".vti", ".nii", ".nii.gz", ".mha", ".mhd", ".nrrd", ".nhdr"];

/// Why a volume file could not be read. Every message starts with the file's path.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{}: cannot read the file: {error} (check that the path is right and the file is readable)", .path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },

    /// The file name ends in none of [`SUPPORTED_EXTENSIONS`].
    #[error(
        "{}: unknown volume file type; ferrovol reads {} (convert the volume to one of these, e.g. with ParaView, 3D Slicer or SimpleITK)",
        .path.display(),
        SUPPORTED_EXTENSIONS.join(", ")
    )]
    UnknownFormat { path: PathBuf },

    /// The header is malformed, incomplete or inconsistent.
    #[error("{}: bad {format} header: {message}", .path.display())]
    BadHeader {
        path: PathBuf,
        format: &'static str,
        message: String,
    },

    /// The scalar type is not one ferrovol renders.
    #[error(
        "{}: unsupported scalar type '{type_name}'; ferrovol reads {supported} (convert the data to one of these, e.g. to 32-bit integers or floats)",
        .path.display()
    )]
    UnsupportedType {
        path: PathBuf,
        type_name: String,
        supported: &'static str,
    },

    /// A valid file that uses a feature these readers do not implement.
    #[error("{}: not supported: {message}", .path.display())]
    Unsupported { path: PathBuf, message: String },

    /// The data section is shorter than the header says.
    #[error(
        "{}: truncated {what}: expected {expected} bytes, found {found} (the file is incomplete; copy or export it again)",
        .path.display()
    )]
    Truncated {
        path: PathBuf,
        what: String,
        expected: u64,
        found: u64,
    },

    /// The data section is damaged: bad base64, a broken zlib/gzip stream, a number
    /// that does not parse, a count that does not match the header.
    #[error("{}: corrupt {what}: {message}", .path.display())]
    CorruptData {
        path: PathBuf,
        what: String,
        message: String,
    },

    /// The file was read but describes a volume ferrovol cannot render (core validation).
    #[error("{}: {error} (fix the file's header or data, or export it again)", .path.display())]
    InvalidVolume {
        path: PathBuf,
        error: ferrovol_core::Error,
    },
}

impl ReadError {
    /// A malformed header of `format` in `path`.
    pub fn bad_header(path: &Path, format: &'static str, message: impl Into<String>) -> ReadError {
        ReadError::BadHeader {
            path: path.to_path_buf(),
            format,
            message: message.into(),
        }
    }

    /// A feature of a valid file that these readers do not implement.
    pub fn unsupported(path: &Path, message: impl Into<String>) -> ReadError {
        ReadError::Unsupported {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Reads a volume file, choosing the reader by the file name's extension
/// (case-insensitive): `.vti`, `.nii`, `.nii.gz`, `.mha`, `.mhd`, `.nrrd`, `.nhdr`.
/// The result has passed [`VolumeData::validate`].
pub fn read_volume(path: &Path) -> Result<VolumeData, ReadError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let volume = if name.ends_with(".vti") {
        vti::read(path)?
    } else if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        self::nifti::read(path)?
    } else if name.ends_with(".mha") || name.ends_with(".mhd") {
        metaimage::read(path)?
    } else if name.ends_with(".nrrd") || name.ends_with(".nhdr") {
        nrrd::read(path)?
    } else {
        return Err(ReadError::UnknownFormat {
            path: path.to_path_buf(),
        });
    };
    volume
        .validate()
        .map_err(|error| ReadError::InvalidVolume {
            path: path.to_path_buf(),
            error,
        })?;
    Ok(volume)
}

// ---------------------------------------------------------------------------------------
// Helpers shared by the readers.

/// Reads a whole file.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, ReadError> {
    std::fs::read(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// `dims[0] * dims[1] * … * components` as a `usize`, and the byte size of that many
/// values of `ty`, with overflow checks. Also checks that every dimension fits `u32`
/// (what [`VolumeData`] stores).
pub(crate) fn value_count(
    path: &Path,
    format: &'static str,
    dims: &[u64],
    components: u64,
    ty: ScalarType,
) -> Result<(usize, usize), ReadError> {
    let bad = |message: String| ReadError::BadHeader {
        path: path.to_path_buf(),
        format,
        message,
    };
    for &d in dims {
        if d == 0 {
            return Err(bad(format!(
                "dimensions {dims:?} contain 0; every dimension must be at least 1"
            )));
        }
        if d > u32::MAX as u64 {
            return Err(bad(format!(
                "dimension {d} is larger than {} (the largest ferrovol accepts)",
                u32::MAX
            )));
        }
    }
    let too_big = || {
        bad(format!(
            "dimensions {dims:?} with {components} component(s) of {} hold more values than this machine can address",
            ty.name()
        ))
    };
    let mut n: usize = 1;
    for &d in dims.iter().chain(std::iter::once(&components)) {
        let d = usize::try_from(d).map_err(|_| too_big())?;
        n = n.checked_mul(d).ok_or_else(too_big)?;
    }
    let bytes = n.checked_mul(ty.size_bytes()).ok_or_else(too_big)?;
    Ok((n, bytes))
}

/// Converts `bytes` (whose length must be a multiple of the type's size; extra bytes are
/// ignored) into scalars of `ty`.
pub(crate) fn decode_binary(bytes: &[u8], ty: ScalarType, big_endian: bool) -> Scalars {
    macro_rules! conv {
        ($t:ty, $n:expr) => {
            bytes
                .chunks_exact($n)
                .map(|c| {
                    let mut a = [0u8; $n];
                    a.copy_from_slice(c);
                    if big_endian {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }
                })
                .collect()
        };
    }
    match ty {
        ScalarType::U8 => Scalars::U8(bytes.to_vec()),
        ScalarType::I8 => Scalars::I8(bytes.iter().map(|&b| b as i8).collect()),
        ScalarType::U16 => Scalars::U16(conv!(u16, 2)),
        ScalarType::I16 => Scalars::I16(conv!(i16, 2)),
        ScalarType::U32 => Scalars::U32(conv!(u32, 4)),
        ScalarType::I32 => Scalars::I32(conv!(i32, 4)),
        ScalarType::F32 => Scalars::F32(conv!(f32, 4)),
        ScalarType::F64 => Scalars::F64(conv!(f64, 8)),
    }
}

/// Parses exactly `count` whitespace-separated numbers of type `ty` from `text`.
/// `what` names the data section in error messages.
pub(crate) fn parse_ascii(
    path: &Path,
    what: &str,
    text: &str,
    ty: ScalarType,
    count: usize,
) -> Result<Scalars, ReadError> {
    fn parse_all<T: std::str::FromStr>(
        path: &Path,
        what: &str,
        text: &str,
        ty: ScalarType,
        count: usize,
    ) -> Result<Vec<T>, ReadError> {
        let corrupt = |message: String| ReadError::CorruptData {
            path: path.to_path_buf(),
            what: what.to_string(),
            message,
        };
        // Cap the up-front reservation: `count` comes from the header.
        let mut out = Vec::with_capacity(count.min(text.len() / 2 + 1));
        for (i, token) in text.split_ascii_whitespace().enumerate() {
            if i >= count {
                return Err(corrupt(format!(
                    "more than the {count} values the header's dimensions call for (check the dimensions in the header)"
                )));
            }
            let v = token.parse::<T>().map_err(|_| {
                corrupt(format!(
                    "value #{} '{}' is not a valid {} number (fix or re-export the data)",
                    i + 1,
                    token.chars().take(40).collect::<String>(),
                    ty.name()
                ))
            })?;
            out.push(v);
        }
        if out.len() != count {
            return Err(corrupt(format!(
                "found {} values, expected {count} (the data is incomplete or the header's dimensions are wrong)",
                out.len()
            )));
        }
        Ok(out)
    }
    Ok(match ty {
        ScalarType::U8 => Scalars::U8(parse_all(path, what, text, ty, count)?),
        ScalarType::I8 => Scalars::I8(parse_all(path, what, text, ty, count)?),
        ScalarType::U16 => Scalars::U16(parse_all(path, what, text, ty, count)?),
        ScalarType::I16 => Scalars::I16(parse_all(path, what, text, ty, count)?),
        ScalarType::U32 => Scalars::U32(parse_all(path, what, text, ty, count)?),
        ScalarType::I32 => Scalars::I32(parse_all(path, what, text, ty, count)?),
        ScalarType::F32 => Scalars::F32(parse_all(path, what, text, ty, count)?),
        ScalarType::F64 => Scalars::F64(parse_all(path, what, text, ty, count)?),
    })
}

/// Decompresses `data` (zlib or gzip, detected by the gzip magic) and returns at most
/// `limit + 1` bytes: enough for the caller to tell "too short", "exact" and "too long"
/// apart without inflating a hostile stream without bound.
pub(crate) fn inflate(
    path: &Path,
    what: &str,
    data: &[u8],
    limit: usize,
) -> Result<Vec<u8>, ReadError> {
    let mut out = Vec::new();
    let cap = (limit as u64).saturating_add(1);
    let result = if data.starts_with(&[0x1f, 0x8b]) {
        flate2::read::MultiGzDecoder::new(data)
            .take(cap)
            .read_to_end(&mut out)
    } else {
        flate2::read::ZlibDecoder::new(data)
            .take(cap)
            .read_to_end(&mut out)
    };
    result.map_err(|e| ReadError::CorruptData {
        path: path.to_path_buf(),
        what: what.to_string(),
        message: format!(
            "decompression failed after {} bytes: {e} (the compressed data is damaged or truncated; export the file again)",
            out.len()
        ),
    })?;
    Ok(out)
}

/// Returns the first `needed` bytes of `data`, after decompressing it (zlib or gzip) if
/// `compressed`; a short section is a [`ReadError::Truncated`]. Bytes after the needed
/// ones are ignored.
pub(crate) fn take_data<'a>(
    path: &Path,
    what: &str,
    data: &'a [u8],
    compressed: bool,
    needed: usize,
) -> Result<Cow<'a, [u8]>, ReadError> {
    match compressed {
        false => match data.get(..needed) {
            Some(d) => Ok(Cow::Borrowed(d)),
            None => Err(ReadError::Truncated {
                path: path.to_path_buf(),
                what: what.to_string(),
                expected: needed as u64,
                found: data.len() as u64,
            }),
        },
        true => {
            let mut out = inflate(path, what, data, needed)?;
            if out.len() < needed {
                return Err(ReadError::Truncated {
                    path: path.to_path_buf(),
                    what: format!("{what} (after decompression)"),
                    expected: needed as u64,
                    found: out.len() as u64,
                });
            }
            out.truncate(needed);
            Ok(Cow::Owned(out))
        }
    }
}

/// Splits text into lines at `\n`, stripping a trailing `\r`; returns (line, offset of
/// the byte after the line's end).
pub(crate) fn next_line(bytes: &[u8], start: usize) -> Option<(&[u8], usize)> {
    let rest = bytes.get(start..)?;
    if rest.is_empty() {
        return None;
    }
    let (line, next) = match rest.iter().position(|&b| b == b'\n') {
        Some(i) => (&rest[..i], start + i + 1),
        None => (rest, bytes.len()),
    };
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    Some((line, next))
}

/// Normalizes the columns of `m` (row-major; column `j` is the world direction of index
/// axis `j`). Returns the column lengths and the normalized matrix, or `None` if a column
/// is zero or not finite.
pub(crate) fn normalize_columns(m: [[f64; 3]; 3]) -> Option<([f64; 3], [[f64; 3]; 3])> {
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
pub(crate) fn is_orthonormal(m: &[[f64; 3]; 3]) -> bool {
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

/// Parses whitespace-separated floats, exactly `n` of them.
pub(crate) fn parse_floats(text: &str, n: usize) -> Option<Vec<f64>> {
    let v: Vec<f64> = text
        .split_ascii_whitespace()
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()?;
    (v.len() == n).then_some(v)
}

#[cfg(test)]
pub(crate) mod test_util {
    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh directory under the system temp dir, removed on drop.
    pub struct TempDir(PathBuf);

    impl TempDir {
        pub fn new(tag: &str) -> TempDir {
            static COUNTER: AtomicUsize = AtomicUsize::new(0);
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let dir = std::env::temp_dir()
                .join(format!("ferrovol-readers-{}-{tag}-{n}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            TempDir(dir)
        }
        pub fn path(&self) -> &Path {
            &self.0
        }
        /// Writes `bytes` to `name` in the directory and returns the full path.
        pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
            let p = self.0.join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    pub fn zlib(data: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(data).unwrap();
        e.finish().unwrap()
    }

    pub fn gzip(data: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(data).unwrap();
        e.finish().unwrap()
    }

    /// The message of an error, for `contains` checks.
    pub fn msg<T: std::fmt::Debug>(r: Result<T, super::ReadError>) -> String {
        match r {
            Ok(v) => panic!("expected an error, got {v:?}"),
            Err(e) => e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::*;
    use super::*;

    #[test]
    fn readers_unknown_extension_lists_supported() {
        let m = msg(read_volume(Path::new("/tmp/some/volume.xyz")));
        assert!(
            m.starts_with("/tmp/some/volume.xyz: unknown volume file type"),
            "{m}"
        );
        for ext in SUPPORTED_EXTENSIONS {
            assert!(m.contains(ext), "{m}");
        }
    }

    #[test]
    fn readers_missing_file_names_path() {
        for name in [
            "nothere.vti",
            "nothere.nii",
            "nothere.nii.gz",
            "nothere.mha",
            "nothere.nrrd",
        ] {
            let dir = TempDir::new("missing");
            let p = dir.path().join(name);
            let m = msg(read_volume(&p));
            assert!(
                m.contains(name) && m.contains("cannot read the file"),
                "{m}"
            );
        }
    }

    #[test]
    fn readers_value_count_overflow() {
        let p = Path::new("x.nrrd");
        let e = value_count(p, "NRRD", &[u32::MAX as u64; 3], 4, ScalarType::F64);
        if usize::BITS == 64 {
            assert!(msg(e).contains("more values than"));
        }
        assert!(
            msg(value_count(p, "NRRD", &[1 << 33, 1, 1], 1, ScalarType::U8)).contains("larger")
        );
        assert!(msg(value_count(p, "NRRD", &[4, 0, 1], 1, ScalarType::U8)).contains("at least 1"));
        assert_eq!(
            value_count(p, "NRRD", &[2, 3, 4], 2, ScalarType::U16).unwrap(),
            (48, 96)
        );
    }

    #[test]
    fn readers_decode_binary_endianness() {
        let b = [0x01, 0x02, 0x03, 0x04];
        assert_eq!(
            decode_binary(&b, ScalarType::U16, false),
            Scalars::U16(vec![0x0201, 0x0403])
        );
        assert_eq!(
            decode_binary(&b, ScalarType::U16, true),
            Scalars::U16(vec![0x0102, 0x0304])
        );
        assert_eq!(
            decode_binary(&1.5f32.to_be_bytes(), ScalarType::F32, true),
            Scalars::F32(vec![1.5])
        );
    }

    #[test]
    fn readers_parse_ascii_errors() {
        let p = Path::new("a.vti");
        assert_eq!(
            parse_ascii(p, "x", " 1 2\n3 ", ScalarType::I8, 3).unwrap(),
            Scalars::I8(vec![1, 2, 3])
        );
        assert!(msg(parse_ascii(p, "x", "1 2", ScalarType::I8, 3))
            .contains("found 2 values, expected 3"));
        assert!(msg(parse_ascii(p, "x", "1 2 3 4", ScalarType::I8, 3)).contains("more than"));
        assert!(msg(parse_ascii(p, "x", "1 300 3", ScalarType::U8, 3)).contains("'300'"));
    }
}
