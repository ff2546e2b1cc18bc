//! Raw data read in place: a [`ScalarSource`] over uncompressed binary values in a file,
//! read with positioned reads as the renderer asks for runs of them, so that a volume
//! larger than memory renders (see [`crate::open_volume`]).

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use ferrovol_core::{ScalarSource, ScalarType, Scalars, VolumeData};

use crate::decode::{Geometry, Layout};
use crate::ReadError;

/// Where a header says its raw data starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RawStart {
    /// At this byte offset.
    At(u64),
    /// At the end of the file (NRRD `byte skip: -1`, MetaImage `HeaderSize = -1`).
    FromEnd,
}

/// Uncompressed binary data as a header describes it.
pub(crate) struct RawData {
    pub format: &'static str,
    pub layout: Layout,
    pub geometry: Geometry,
    pub big_endian: bool,
    /// The detached data file as the header names it (relative to the header's folder);
    /// `None`: the header's own file.
    pub file: Option<String>,
    pub start: RawStart,
}

impl RawData {
    /// The volume whose scalars read the data from `path` (the file the data is in) in
    /// place. Errors: the file cannot be opened, or is shorter than the header says.
    pub fn open(self, path: &Path) -> Result<VolumeData, ReadError> {
        let io = |error| ReadError::Io {
            path: path.to_path_buf(),
            error,
        };
        let file = File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let nbytes = self.layout.nbytes as u64;
        // As the in-memory readers count: the bytes needed against those from the start.
        let truncated = |found: u64| {
            ReadError::truncated(
                format!("{} data", self.format),
                nbytes as usize,
                found as usize,
            )
            .in_file(path)
        };
        let offset = match self.start {
            RawStart::At(o) => o,
            RawStart::FromEnd => len.checked_sub(nbytes).ok_or_else(|| truncated(len))?,
        };
        if len.saturating_sub(offset) < nbytes {
            return Err(truncated(len.saturating_sub(offset)));
        }
        let source = RawFileSource {
            path: path.to_path_buf(),
            file,
            offset,
            ty: self.layout.ty,
            count: self.layout.count,
            big_endian: self.big_endian,
        };
        self.layout
            .volume(self.geometry, Scalars::Source(Arc::new(source)))
    }
}

/// Values of one scalar type stored contiguously from `offset` in a file.
pub struct RawFileSource {
    path: PathBuf,
    file: File,
    offset: u64,
    ty: ScalarType,
    count: usize,
    big_endian: bool,
}

impl std::fmt::Debug for RawFileSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ({} {} {}-endian values from byte {})",
            self.path.display(),
            self.count,
            self.ty.name(),
            if self.big_endian { "big" } else { "little" },
            self.offset
        )
    }
}

/// Runs longer than this are read in pieces (bounded buffer).
const MAX_READ_BYTES: usize = 4 << 20;

impl ScalarSource for RawFileSource {
    fn scalar_type(&self) -> ScalarType {
        self.ty
    }

    fn len(&self) -> usize {
        self.count
    }

    fn read(&self, start: usize, out: &mut [f64]) -> std::io::Result<()> {
        let size = self.ty.size_bytes();
        let per_read = (MAX_READ_BYTES / size).max(1);
        let mut bytes = vec![0u8; out.len().min(per_read) * size];
        let mut first = start;
        for chunk in out.chunks_mut(per_read) {
            let buf = &mut bytes[..chunk.len() * size];
            self.file
                .read_exact_at(buf, self.offset + (first * size) as u64)?;
            convert(buf, self.ty, self.big_endian, chunk);
            first += chunk.len();
        }
        Ok(())
    }
}

/// Converts the values of `ty` in `bytes` into `out`.
fn convert(bytes: &[u8], ty: ScalarType, big_endian: bool, out: &mut [f64]) {
    macro_rules! conv {
        ($t:ty, $n:expr) => {
            for (o, c) in out.iter_mut().zip(bytes.chunks_exact($n)) {
                let a: [u8; $n] = c.try_into().expect("chunks of $n");
                *o = if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                } as f64;
            }
        };
    }
    match ty {
        ScalarType::U8 => conv!(u8, 1),
        ScalarType::I8 => conv!(i8, 1),
        ScalarType::U16 => conv!(u16, 2),
        ScalarType::I16 => conv!(i16, 2),
        ScalarType::U32 => conv!(u32, 4),
        ScalarType::I32 => conv!(i32, 4),
        ScalarType::F32 => conv!(f32, 4),
        ScalarType::F64 => conv!(f64, 8),
    }
}
