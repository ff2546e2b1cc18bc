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

fn build_and_run(source: &str, compiler: &str, std: &str, extra: &[&str]) -> String {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = lib_dir();
    assert!(
        lib.join("libferrovol.so").exists(),
        "{} missing: build the ffi crate first",
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
    let png = tmp.join(format!("{source}.png"));
    let run = Command::new(&exe)
        .arg(&png)
        .output()
        .expect("run the program");
    let stdout = String::from_utf8_lossy(&run.stdout).to_string();
    println!("{stdout}");
    assert!(
        run.status.success(),
        "{source} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let len = std::fs::metadata(&png).map(|m| m.len()).unwrap_or(0);
    assert!(len > 1000, "{} is {len} bytes", png.display());
    stdout
}

#[test]
fn c_program_renders_the_demo_volume() {
    let out = build_and_run("render_demo.c", "cc", "c11", &["-lm"]);
    // The program itself fails when fewer than 10% of the pixels have opacity.
    assert!(out.contains("pixels with opacity"), "{out}");
}

#[test]
fn cpp_raii_wrapper_renders_and_throws() {
    let out = build_and_run("raii_demo.cpp", "c++", "c++17", &[]);
    assert!(
        out.contains("FV_STATUS_INVALID_ARGUMENT: blend_mode 42"),
        "{out}"
    );
}
