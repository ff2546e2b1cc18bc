//! Builds C and C++ programs against the committed headers alone (-Wall -Wextra -Werror
//! -pedantic), links them with the built libferrovol and runs them.

use std::path::{Path, PathBuf};
use std::process::Command;

/// target/<profile>/, where cargo put libferrovol.so next to this test's deps/ folder.
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf()
}

fn build(source: &str, compiler: &str, std: &str, extra: &[&str]) -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = lib_dir();
    assert!(
        lib.join("libferrovol.so").exists(),
        "{} missing: build it with `cargo build -p ferrovol-ffi` (make test does; `cargo test` \
         builds only the rlib)",
        lib.join("libferrovol.so").display()
    );
    let tmp = std::env::temp_dir().join(format!("ferrovol-ffi-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let exe = tmp.join(Path::new(source).file_stem().unwrap());
    let out = Command::new(compiler)
        .arg(format!("-std={std}"))
        .args(["-Wall", "-Wextra", "-Werror", "-pedantic", "-O1"])
        .arg("-I")
        .arg(manifest.join("include"))
        .arg(manifest.join("tests/c").join(source))
        .arg("-o")
        .arg(&exe)
        .arg(format!("-L{}", lib.display()))
        .arg("-lferrovol")
        .args(extra)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .output()
        .unwrap_or_else(|e| panic!("running {compiler}: {e}"));
    assert!(
        out.status.success(),
        "{compiler} {source} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

/// Runs `exe` (with a PNG path argument when `png` is set) and returns its exit code and
/// stdout; with `png`, checks that a non-trivial PNG was written.
fn run(exe: &Path, png: bool) -> (i32, String) {
    let out_png = exe.with_extension("png");
    let mut cmd = Command::new(exe);
    if png {
        cmd.arg(&out_png);
    }
    let run = cmd.output().expect("run the program");
    let stdout = String::from_utf8_lossy(&run.stdout).to_string();
    println!("{stdout}{}", String::from_utf8_lossy(&run.stderr));
    let code = run.status.code().unwrap_or(-1);
    if png && code == 0 {
        let len = std::fs::metadata(&out_png).map(|m| m.len()).unwrap_or(0);
        assert!(len > 1000, "{} is {len} bytes", out_png.display());
    }
    (code, stdout)
}

#[test]
fn c_program_renders_the_demo_volume() {
    let exe = build("render_demo.c", "cc", "c11", &["-lm"]);
    // The program itself fails when fewer than 10% of the pixels have opacity.
    let (code, out) = run(&exe, true);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("pixels with opacity"), "{out}");
}

#[test]
fn cpp_raii_wrapper_renders_and_throws() {
    let exe = build("raii_demo.cpp", "c++", "c++17", &[]);
    let (code, out) = run(&exe, true);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("FV_STATUS_INVALID_ARGUMENT: blend_mode 42"),
        "{out}"
    );
    assert!(out.contains("four intermixed volumes refused"), "{out}");
    assert!(
        out.contains("dangling index refused: FV_STATUS_INVALID_ARGUMENT: invalid volume: cell 0"),
        "{out}"
    );
}

/// Handles shared between threads as the header allows (one context and volume, a renderer
/// per thread, frames read concurrently, renderers moved): 4 threads × 32 frames, each
/// identical to the single-threaded reference. scripts/sanitize.sh runs it under
/// ThreadSanitizer and AddressSanitizer.
#[test]
fn threads_share_context_and_volume_as_the_header_allows() {
    let exe = build("thread_stress.c", "cc", "c11", &["-pthread"]);
    let mut cmd = Command::new(&exe);
    let run = cmd.arg("32").output().expect("run thread_stress");
    let out = String::from_utf8_lossy(&run.stdout);
    println!("{out}{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(run.status.code(), Some(0), "{out}");
    assert!(
        out.contains("4 threads x 32 rounds: 132 frames identical to the reference"),
        "{out}"
    );
}

/// The zero-copy path, for real: Mesa's llvmpipe (GL) imports lavapipe's (Vulkan) memory.
/// Exit code 77 means this machine has no such interop, which on the machines ferrovol is
/// built and tested on is a failure, not a skip.
#[test]
fn opengl_imports_the_shared_frame_exactly() {
    let exe = build("shared_gl.c", "cc", "c11", &["-lEGL", "-lGL"]);
    let (code, out) = run(&exe, false);
    assert_eq!(code, 0, "shared_gl exited {code}:\n{out}");
    assert!(out.contains(" 0 differ from the readback"), "{out}");
}
