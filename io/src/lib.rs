//! ferrovol-io: the file formats around ferrovol's renderer.
//!
//! Volume readers for VTK XML ImageData (`.vti`), NIfTI-1/2 (`.nii`, `.nii.gz`),
//! MetaImage (`.mha`, `.mhd` + data file) and NRRD (`.nrrd`, `.nhdr` + data file), a
//! mesh reader for VTK XML UnstructuredGrid (`.vtu`, [`vtu`]), the JSON
//! transfer-function format ([`transfer`]), and image files: environment maps in,
//! rendered frames out ([`image`]).
//!
//! Meshes are not volumes: [`read_unstructured`] (and [`vtu::parse`]) return a validated
//! [`ferrovol_core::UnstructuredVolume`], not a [`VolumeData`], so `.vtu` is not a
//! [`Format`] and [`read_volume`] refuses it with a message that names
//! [`read_unstructured`]. The VTK XML machinery (DataArray encodings, appended data,
//! zlib blocks) is shared by the `.vti` and `.vtu` readers.
//!
//! Every reader has a byte-slice API beside the path API: [`read_volume`] reads a file
//! and its detached data file from disk; [`Format::parse`] (or each format module's
//! `parse`) takes the file's bytes and, for the formats whose header may name a separate
//! data file, a function that returns that file's bytes, so that volumes can be read from
//! memory, archives or the network without a filesystem.
//!
//! Every reader keeps the scalar type stored in the file (no conversion to float, except
//! NIfTI data with a non-trivial `scl_slope`/`scl_inter`), returns a validated
//! [`VolumeData`] (or mesh), and reports every problem as a [`ReadError`] whose message names the
//! file (when there is one), the field or section that was wrong and what to do about
//! it. Nothing in a file's content can make a reader panic, and no reader allocates more
//! than its input can fill: sizes are checked (with overflow checks) against the data
//! actually present before anything is allocated for them, so a header that claims
//! 10^12 voxels fails with an error, not with an out-of-memory abort. Compressed binary
//! data is inflated only up to the size the header gives. tests/allocation.rs measures
//! this for every reader and encoding, and every reader is fuzzed (docs/FUZZING.md).

use std::path::{Path, PathBuf};

use ferrovol_core::{UnstructuredVolume, VolumeData};

mod base64;
mod decode;
mod error;
pub mod image;
pub mod metaimage;
pub mod nifti;
pub mod nrrd;
mod raw;
pub mod transfer;
pub mod vti;
mod vtkxml;
pub mod vtu;

pub use error::{Problem, ReadError};
pub use raw::RawFileSource;

/// File name endings [`read_volume`] understands.
pub const SUPPORTED_EXTENSIONS: &[&str] =
    &[".vti", ".nii", ".nii.gz", ".mha", ".mhd", ".nrrd", ".nhdr"];

/// A volume file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// VTK XML ImageData, `.vti`.
    Vti,
    /// NIfTI-1 or NIfTI-2 in one file, `.nii`, or gzip-compressed, `.nii.gz`.
    Nifti,
    /// MetaImage, `.mha` (data in the same file) or `.mhd` (usually a separate data file).
    MetaImage,
    /// NRRD, `.nrrd` (data attached) or `.nhdr` (a separate data file).
    Nrrd,
}

impl Format {
    /// The format a file name's ending (case-insensitive, one of [`SUPPORTED_EXTENSIONS`])
    /// stands for.
    pub fn from_path(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        let ends = |exts: &[&str]| exts.iter().any(|e| name.ends_with(e));
        if ends(&[".vti"]) {
            Some(Format::Vti)
        } else if ends(&[".nii", ".nii.gz"]) {
            Some(Format::Nifti)
        } else if ends(&[".mha", ".mhd"]) {
            Some(Format::MetaImage)
        } else if ends(&[".nrrd", ".nhdr"]) {
            Some(Format::Nrrd)
        } else {
            None
        }
    }

    /// Parses a volume file of this format from its bytes. `data_file` is called with the
    /// name a MetaImage or NRRD header gives its detached data file (as written there,
    /// usually relative to the header's folder) and returns that file's bytes; pass
    /// [`no_data_file`] where there is none. Errors in the detached file's content name it
    /// as the header does ([`ReadError::file`]); other errors name no file.
    pub fn parse(
        self,
        bytes: &[u8],
        data_file: impl FnOnce(&str) -> Result<Vec<u8>, ReadError>,
    ) -> Result<VolumeData, ReadError> {
        match self {
            Format::Vti => vti::parse(bytes),
            Format::Nifti => nifti::parse(bytes),
            Format::MetaImage => metaimage::parse(bytes, data_file),
            Format::Nrrd => nrrd::parse(bytes, data_file),
        }
    }
}

/// The `data_file` argument for bytes that have no detached data file at hand: a header
/// that names one fails with [`ReadError::NoDataFile`].
pub fn no_data_file(name: &str) -> Result<Vec<u8>, ReadError> {
    Err(ReadError::NoDataFile {
        name: name.to_string(),
    })
}

/// Reads a volume file, choosing the reader by the file name's extension
/// (case-insensitive): `.vti`, `.nii`, `.nii.gz`, `.mha`, `.mhd`, `.nrrd`, `.nhdr`. A
/// detached data file is read relative to the header's folder. Every error message starts
/// with the path of the file it is about. The result has passed [`VolumeData::validate`].
pub fn read_volume(path: &Path) -> Result<VolumeData, ReadError> {
    if is_vtu(path) {
        return Err(ReadError::unsupported(
            "this is an unstructured grid (.vtu), not a volume: read it with read_unstructured",
        )
        .in_file(path));
    }
    let format = Format::from_path(path).ok_or_else(|| ReadError::UnknownFormat {
        path: path.to_path_buf(),
    })?;
    let bytes = read_file(path)?;
    format
        .parse(&bytes, |name| read_file(&data_file_path(path, name)))
        .map_err(|e| {
            e.located(|file| {
                file.map_or_else(|| path.to_path_buf(), |name| data_file_path(path, name))
            })
        })
}

/// Whether a file name ends in `.vtu` (case-insensitive).
fn is_vtu(path: &Path) -> bool {
    path.file_name()
        .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase().ends_with(".vtu"))
}

/// Reads a VTK XML UnstructuredGrid file (`.vtu`, [`vtu`]) into a validated mesh. Every
/// error message starts with the path.
pub fn read_unstructured(path: &Path) -> Result<UnstructuredVolume, ReadError> {
    let bytes = read_file(path)?;
    vtu::parse(&bytes).map_err(|e| e.in_file(path))
}

/// Opens a volume file as [`read_volume`] reads it, but leaves uncompressed binary data
/// where it is: a NRRD (`encoding: raw`, no `line skip`) or MetaImage (`BinaryData`, not
/// `CompressedData`) volume, its data detached or attached, or a `.vti` whose array is raw
/// appended data without a compressor (its XML part within the first MiB), comes back with
/// [`ferrovol_core::Scalars::Source`] scalars ([`RawFileSource`]) that read runs of values
/// with positioned reads as the renderer needs them, so it never holds the whole volume.
/// Other files (other formats, encodings and compressions) are read into memory by
/// [`read_volume`]. A data file shorter than its header says is an error here, as there.
///
/// NaN and infinite values in float data read in place are not found here (that would
/// read the whole file); the upload finds them (see [`ferrovol_core::Scalars`]).
pub fn open_volume(path: &Path) -> Result<VolumeData, ReadError> {
    let raw = match Format::from_path(path) {
        Some(Format::Nrrd) => header_prefix(path).map(|h| nrrd::raw_data(&h)),
        Some(Format::MetaImage) => header_prefix(path).map(|h| metaimage::raw_data(&h)),
        Some(Format::Vti) => header_prefix(path).map(|h| vti::raw_data(&h)),
        _ => None,
    };
    // A header the in-place reader cannot use (or an error in it) goes to read_volume,
    // which reports errors as it always does.
    match raw {
        Some(Ok(Some(raw))) => {
            let data_path = match &raw.file {
                Some(name) => data_file_path(path, name),
                None => path.to_path_buf(),
            };
            raw.open(&data_path)
        }
        _ => read_volume(path),
    }
}

/// The first bytes of a file, enough for any header: the whole file up to 1 MiB. `None`
/// if it cannot be read (read_volume reports that).
fn header_prefix(path: &Path) -> Option<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(1 << 20)
        .read_to_end(&mut bytes)
        .ok()?;
    Some(bytes)
}

/// Where a header at `header` finds the data file it calls `name`: relative to the
/// header's folder (an absolute `name` stays as it is).
fn data_file_path(header: &Path, name: impl AsRef<Path>) -> PathBuf {
    match header.parent() {
        Some(dir) => dir.join(name),
        None => name.as_ref().to_path_buf(),
    }
}

/// Reads a whole file.
fn read_file(path: &Path) -> Result<Vec<u8>, ReadError> {
    std::fs::read(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })
}

#[cfg(test)]
mod test_util {
    use ferrovol_core::{UnstructuredVolume, VolumeData};

    use crate::ReadError;

    /// What a reader returns: a volume or a mesh, which validates.
    pub trait Valid: std::fmt::Debug {
        fn check(&self);
    }
    impl Valid for VolumeData {
        fn check(&self) {
            self.validate().unwrap();
        }
    }
    impl Valid for UnstructuredVolume {
        fn check(&self) {
            self.validate().unwrap();
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
    pub fn msg<T: std::fmt::Debug>(r: Result<T, ReadError>) -> String {
        match r {
            Ok(v) => panic!("expected an error, got {v:?}"),
            Err(e) => e.to_string(),
        }
    }

    /// Checks a volume's dimensions, spacing and origin.
    pub fn assert_geometry(v: &VolumeData, dims: [u32; 3], spacing: [f64; 3], origin: [f64; 3]) {
        assert_eq!((v.dims, v.spacing, v.origin), (dims, spacing, origin));
    }

    /// Checks that parsing each case's bytes fails with a message containing the case's
    /// words.
    pub fn check_errors<T: Valid>(
        parse: impl Fn(&[u8]) -> Result<T, ReadError>,
        cases: &[(&str, Vec<u8>, &str)],
    ) {
        for (name, bytes, want) in cases {
            let m = msg(parse(bytes));
            println!("{name}: {m}");
            assert!(m.contains(want), "{name}: wanted {want:?} in {m}");
        }
    }

    /// Parses every prefix of `file` and `file` with each byte replaced by each of
    /// `replacements`: every parse must return an error or a valid volume, never panic.
    pub fn never_panics<T: Valid>(
        parse: impl Fn(&[u8]) -> Result<T, ReadError>,
        file: &[u8],
        replacements: &[u8],
    ) {
        for cut in 0..file.len() {
            let _ = parse(&file[..cut]);
        }
        let mut f = file.to_vec();
        for i in 0..f.len() {
            let keep = f[i];
            for &x in replacements {
                f[i] = x;
                if let Ok(v) = parse(&f) {
                    v.check();
                }
            }
            f[i] = keep;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::*;
    use super::*;

    #[test]
    fn unknown_extension_lists_supported() {
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
    fn formats_by_extension() {
        for (name, want) in [
            ("a.vti", Some(Format::Vti)),
            ("A.NII", Some(Format::Nifti)),
            ("b.nii.gz", Some(Format::Nifti)),
            ("c.mha", Some(Format::MetaImage)),
            ("c.MHD", Some(Format::MetaImage)),
            ("d.nrrd", Some(Format::Nrrd)),
            ("d.nhdr", Some(Format::Nrrd)),
            ("e.gz", None),
            ("vti", None),
        ] {
            assert_eq!(Format::from_path(Path::new(name)), want, "{name}");
        }
    }

    #[test]
    fn data_file_is_relative_to_the_header() {
        assert_eq!(
            data_file_path(Path::new("/a/b/h.nhdr"), "sub/d.raw"),
            Path::new("/a/b/sub/d.raw")
        );
        assert_eq!(
            data_file_path(Path::new("h.mhd"), "d.raw"),
            Path::new("d.raw")
        );
        assert_eq!(
            data_file_path(Path::new("/a/h.mhd"), "/elsewhere/d.raw"),
            Path::new("/elsewhere/d.raw")
        );
    }
}
