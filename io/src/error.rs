//! [`ReadError`]: everything that can be wrong with a file ferrovol-io reads.

use std::path::{Path, PathBuf};

use crate::SUPPORTED_EXTENSIONS;

/// Why a file could not be read. Messages of errors about a file's content start with the
/// file's path when it is known ([`ReadError::file`]): [`crate::read_volume`] names the
/// file it read; the byte-slice parsers name only a detached data file (as its header
/// writes it), and a caller that knows the file's name adds it with
/// [`ReadError::in_file`].
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

    /// The header names a detached data file, but the bytes were parsed without one
    /// ([`crate::no_data_file`]).
    #[error("the header's data is in the separate file {name:?}, which was not given (read the header with read_volume from its folder, or parse it with a function that returns the data file's bytes)")]
    NoDataFile { name: String },

    /// What is wrong with a file's content, and the file when it is known.
    #[error("{}{problem}", at(.file))]
    Content {
        file: Option<PathBuf>,
        problem: Problem,
    },
}

/// What can be wrong with a file's content.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// The header is malformed, incomplete or inconsistent.
    #[error("bad {format} header: {message}")]
    BadHeader {
        format: &'static str,
        message: String,
    },

    /// The scalar type is not one ferrovol renders.
    #[error(
        "unsupported scalar type '{type_name}'; ferrovol reads {supported} (convert the data to one of these, e.g. to 32-bit integers or floats)"
    )]
    UnsupportedType {
        type_name: String,
        supported: &'static str,
    },

    /// A valid file that uses a feature these readers do not implement.
    #[error("not supported: {message}")]
    Unsupported { message: String },

    /// The data section is shorter than the header says.
    #[error(
        "truncated {what}: expected {expected} bytes, found {found} (the file is incomplete; copy or export it again)"
    )]
    Truncated {
        what: String,
        expected: u64,
        found: u64,
    },

    /// The data section is damaged: bad base64, a broken zlib/gzip stream, a number
    /// that does not parse, a count that does not match the header.
    #[error("corrupt {what}: {message}")]
    CorruptData { what: String, message: String },

    /// The file was read but describes a volume ferrovol cannot render (core validation).
    #[error("{0} (fix the file's header or data, or export it again)")]
    InvalidVolume(ferrovol_core::Error),

    /// A transfer-function file ([`crate::transfer`]) is not valid JSON or does not
    /// describe a transfer function; the message names the field.
    #[error("{0}")]
    TransferFunction(String),
}

impl From<Problem> for ReadError {
    /// The problem in a file not named (yet).
    fn from(problem: Problem) -> ReadError {
        ReadError::Content {
            file: None,
            problem,
        }
    }
}

/// `"path: "` before a message about a known file, nothing otherwise.
fn at(file: &Option<PathBuf>) -> String {
    file.as_ref()
        .map_or_else(String::new, |f| format!("{}: ", f.display()))
}

impl ReadError {
    /// A malformed header of `format`.
    pub(crate) fn bad_header(format: &'static str, message: impl Into<String>) -> ReadError {
        Problem::BadHeader {
            format,
            message: message.into(),
        }
        .into()
    }

    /// A scalar type (named `type_name` in the file) that ferrovol does not render;
    /// `supported` lists the format's names of those it does.
    pub(crate) fn unsupported_type(type_name: &str, supported: &'static str) -> ReadError {
        Problem::UnsupportedType {
            type_name: type_name.to_string(),
            supported,
        }
        .into()
    }

    /// A feature of a valid file that these readers do not implement.
    pub(crate) fn unsupported(message: impl Into<String>) -> ReadError {
        Problem::Unsupported {
            message: message.into(),
        }
        .into()
    }

    /// A data section of `found` bytes where `expected` were needed.
    pub(crate) fn truncated(what: impl Into<String>, expected: usize, found: usize) -> ReadError {
        Problem::Truncated {
            what: what.into(),
            expected: expected as u64,
            found: found as u64,
        }
        .into()
    }

    /// A damaged data section.
    pub(crate) fn corrupt(what: impl Into<String>, message: impl Into<String>) -> ReadError {
        Problem::CorruptData {
            what: what.into(),
            message: message.into(),
        }
        .into()
    }

    /// The file this error is about, when it is known.
    pub fn file(&self) -> Option<&Path> {
        match self {
            ReadError::Io { path, .. } | ReadError::UnknownFormat { path } => Some(path),
            ReadError::NoDataFile { .. } => None,
            ReadError::Content { file, .. } => file.as_deref(),
        }
    }

    /// Names `path` as the file this error is about, unless the error names one already
    /// (a detached data file).
    pub fn in_file(self, path: &Path) -> ReadError {
        self.located(|file| file.unwrap_or(path).to_path_buf())
    }

    /// Replaces the file an error about a file's content names (or does not name) with
    /// `locate` of it; errors that carry their own path keep it.
    pub(crate) fn located(mut self, locate: impl FnOnce(Option<&Path>) -> PathBuf) -> ReadError {
        if let ReadError::Content { file, .. } = &mut self {
            *file = Some(locate(file.as_deref()));
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_start_with_the_file_when_known() {
        let e = ReadError::bad_header("NRRD", "no 'sizes' field");
        assert_eq!(e.to_string(), "bad NRRD header: no 'sizes' field");
        assert_eq!(e.file(), None);
        let e = e.in_file(Path::new("dir/a.nrrd"));
        assert_eq!(
            e.to_string(),
            "dir/a.nrrd: bad NRRD header: no 'sizes' field"
        );
        // A file named already (a detached data file) stays.
        let e = ReadError::truncated("NRRD data", 24, 10)
            .located(|_| PathBuf::from("d.raw"))
            .in_file(Path::new("a.nhdr"));
        assert_eq!(e.file(), Some(Path::new("d.raw")));
        assert!(e
            .to_string()
            .starts_with("d.raw: truncated NRRD data: expected 24 bytes, found 10"));
    }
}
