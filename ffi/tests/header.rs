//! The committed header is what cbindgen generates now, and its version macros agree with
//! Cargo.toml and the library.

use std::ffi::CStr;

const FRESH: &str = include_str!(concat!(env!("OUT_DIR"), "/ferrovol.h"));
const COMMITTED: &str = include_str!("../include/ferrovol.h");

#[test]
fn committed_header_matches_a_fresh_generation() {
    assert!(
        FRESH == COMMITTED,
        "ffi/include/ferrovol.h is stale: regenerate it with \
         `FERROVOL_UPDATE_HEADER=1 cargo build -p ferrovol-ffi` and commit it"
    );
}

fn header_macro(name: &str) -> u32 {
    let line = COMMITTED
        .lines()
        .find(|l| l.starts_with(&format!("#define {name} ")))
        .unwrap_or_else(|| panic!("{name} not in the header"));
    line.split_whitespace().nth(2).unwrap().parse().unwrap()
}

#[test]
fn version_macros_agree_with_cargo_and_the_library() {
    let cargo = [
        env!("CARGO_PKG_VERSION_MAJOR"),
        env!("CARGO_PKG_VERSION_MINOR"),
        env!("CARGO_PKG_VERSION_PATCH"),
    ]
    .map(|v| v.parse::<u32>().unwrap());
    let header = ["FV_VERSION_MAJOR", "FV_VERSION_MINOR", "FV_VERSION_PATCH"].map(header_macro);
    assert_eq!(header, cargo, "header version vs Cargo.toml");
    // SAFETY: fv_version returns a static NUL-terminated string.
    let runtime = unsafe { CStr::from_ptr(ferrovol::fv_version()) }
        .to_str()
        .unwrap();
    assert_eq!(runtime, env!("CARGO_PKG_VERSION"));
    assert_eq!(ferrovol::fv_version_major(), cargo[0]);
    println!("header {header:?}, Cargo.toml {cargo:?}, fv_version() {runtime}");
}
