//! The persistent pipeline cache: what the driver compiled, kept on disk between runs
//! (wgpu's `PipelineCache`, where the backend has one: Vulkan).
//!
//! * **Where.** `$FERROVOL_CACHE_DIR`, else `$XDG_CACHE_HOME/ferrovol`, else
//!   `~/.cache/ferrovol`; `FERROVOL_CACHE_DIR=off` turns the cache off. One file per driver
//!   and ferrovol version: wgpu's key for the adapter (backend, vendor, device), then
//!   `-ferrovol-<version>.bin`.
//! * **What.** ferrovol's header (magic, data length, FNV-1a hash of the data), then the
//!   data wgpu gives (its own header names the wgpu version, driver and device).
//! * **A stale or corrupt file** (short, a hash that does not match, or data wgpu refuses
//!   because another driver, device or wgpu wrote it) is ignored with a warning in the log,
//!   and the next save replaces it. Nothing fails because of the cache: a directory that
//!   cannot be written only loses the saves.
//! * **Saves** follow each newly compiled pipeline and write a temporary file that is then
//!   renamed, so processes sharing the directory each leave a whole file.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

const MAGIC: &[u8; 8] = b"FVPCACHE";
const HEADER: usize = 8 + 8 + 8;

/// FNV-1a, 64 bits: enough to tell a damaged file from the one written.
fn fnv1a(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The data of a cache file, if it is whole.
fn unwrap_file(bytes: &[u8]) -> Option<&[u8]> {
    let (header, data) = (bytes.get(..HEADER)?, bytes.get(HEADER..)?);
    let word = |i: usize| u64::from_le_bytes(header[i..i + 8].try_into().unwrap_or_default());
    (header[..8] == MAGIC[..] && word(8) == data.len() as u64 && word(16) == fnv1a(data))
        .then_some(data)
}

/// `data` as a cache file.
fn wrap_file(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(data.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(data).to_le_bytes());
    out.extend_from_slice(data);
    out
}

/// The cache folder the environment names, if the cache is on.
fn folder() -> Option<PathBuf> {
    match std::env::var_os("FERROVOL_CACHE_DIR") {
        Some(d) if d == "off" || d.is_empty() => None,
        Some(d) => Some(PathBuf::from(d)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .filter(|d| !d.is_empty())
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache")))
            .map(|d| d.join("ferrovol")),
    }
}

/// A device's pipeline cache and the file it is kept in.
pub(crate) struct DiskCache {
    pub(crate) cache: wgpu::PipelineCache,
    path: PathBuf,
    /// Saves in flight from this process, one at a time.
    saving: Mutex<()>,
}

impl DiskCache {
    /// The cache of `device` (made on `adapter`), filled from its file when that is whole
    /// and this driver's; `None` where the backend keeps no pipeline cache, the device was
    /// made without [`wgpu::Features::PIPELINE_CACHE`], or the cache is off.
    pub(crate) fn open(device: &wgpu::Device, adapter: &wgpu::AdapterInfo) -> Option<DiskCache> {
        if !device.features().contains(wgpu::Features::PIPELINE_CACHE) {
            return None;
        }
        let key = wgpu::util::pipeline_cache_key(adapter)?;
        let path = folder()?.join(format!("{key}-ferrovol-{}.bin", env!("CARGO_PKG_VERSION")));
        let bytes = std::fs::read(&path).ok();
        let data = bytes.as_deref().and_then(|b| {
            let data = unwrap_file(b);
            if data.is_none() {
                log::warn!("ignoring the damaged pipeline cache {}", path.display());
            }
            data
        });
        // SAFETY: `data` is what `PipelineCache::get_data` gave an earlier run, as the file's
        // hash shows; wgpu checks that it comes from this adapter and wgpu version, and with
        // `fallback` starts empty where it does not.
        let cache = unsafe {
            device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("ferrovol pipelines"),
                data,
                fallback: true,
            })
        };
        Some(DiskCache {
            cache,
            path,
            saving: Mutex::new(()),
        })
    }

    /// Writes the cache to its file (after new pipelines were compiled into it).
    pub(crate) fn save(&self) {
        let Some(data) = self.cache.get_data() else {
            return;
        };
        let _one_at_a_time = self.saving.lock().unwrap_or_else(|e| e.into_inner());
        let tmp = self
            .path
            .with_extension(format!("{}.tmp", std::process::id()));
        let written = self
            .path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| std::fs::write(&tmp, wrap_file(&data)))
            .and_then(|()| std::fs::rename(&tmp, &self.path));
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            log::warn!(
                "could not save the pipeline cache {}: {e}",
                self.path.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_reads_back_whole_and_any_damage_is_seen() {
        let data: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
        let file = wrap_file(&data);
        assert_eq!(unwrap_file(&file), Some(&data[..]));
        assert_eq!(unwrap_file(&wrap_file(&[])), Some(&[][..]));
        assert_eq!(unwrap_file(&file[..file.len() - 1]), None, "truncated");
        assert_eq!(unwrap_file(&file[..10]), None, "shorter than the header");
        let mut longer = file.clone();
        longer.push(0);
        assert_eq!(unwrap_file(&longer), None, "extended");
        for at in [0, 9, 17, HEADER, file.len() - 1] {
            let mut bad = file.clone();
            bad[at] ^= 0x20;
            assert_eq!(unwrap_file(&bad), None, "byte {at} flipped");
        }
    }
}
