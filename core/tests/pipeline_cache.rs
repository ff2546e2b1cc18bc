//! The persistent pipeline cache (FERROVOL_CACHE_DIR) on a real device: written after a
//! frame compiles its pipeline, a damaged file ignored and replaced, none when it is off.
//! One test, because the folder is the process's environment.

use ferrovol_core::*;
use std::path::Path;
mod common;

fn draw_a_frame() {
    let mut r = common::gpu::new_renderer();
    let vol = synth::wavelet(synth::wavelet_extent(9));
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::ramp([40.0, 260.0], 0.5))
        .unwrap();
    let img = r
        .render_image(&View::fit(vol.bounds(), 16, 16), &RenderParams::default())
        .unwrap();
    assert!(img.rgba.iter().any(|&c| c > 0), "the frame drew nothing");
}

fn cache_files(dir: &Path) -> Vec<std::path::PathBuf> {
    std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default()
}

#[test]
fn cache_file_written_damage_ignored_off_means_none() {
    let dir = std::env::temp_dir().join(format!("ferrovol-cache-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::env::set_var("FERROVOL_CACHE_DIR", &dir);
    let vulkan = common::gpu::context().info.backend == "Vulkan";

    draw_a_frame();
    let files = cache_files(&dir);
    println!("after a frame: {files:?}");
    if !vulkan {
        assert!(files.is_empty(), "only Vulkan keeps a pipeline cache");
        return;
    }
    assert_eq!(files.len(), 1, "one file, no temporary left: {files:?}");
    let file = &files[0];
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        name.starts_with("wgpu_pipeline_cache_vulkan_")
            && name.ends_with(&format!("-ferrovol-{}.bin", env!("CARGO_PKG_VERSION"))),
        "{name}"
    );
    let whole = std::fs::read(file).unwrap();
    assert!(whole.starts_with(b"FVPCACHE"), "{:?}", &whole[..8]);

    // A damaged file: the next run draws as before and leaves a whole file again.
    let mut damaged = whole.clone();
    let last = damaged.len() - 1;
    damaged[last] ^= 0xff;
    std::fs::write(file, &damaged).unwrap();
    draw_a_frame();
    std::fs::write(file, b"not a cache").unwrap();
    draw_a_frame();
    assert_eq!(cache_files(&dir).len(), 1);
    assert!(std::fs::read(file).unwrap().starts_with(b"FVPCACHE"));

    // Off: nothing is written.
    std::fs::remove_dir_all(&dir).unwrap();
    std::env::set_var("FERROVOL_CACHE_DIR", "off");
    draw_a_frame();
    assert!(!dir.exists(), "FERROVOL_CACHE_DIR=off wrote {dir:?}");
}
