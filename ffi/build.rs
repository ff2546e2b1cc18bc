//! Generates the C header with cbindgen into OUT_DIR (the header check test compares it with
//! the committed include/ferrovol.h); FERROVOL_UPDATE_HEADER=1 rewrites the committed one.

fn main() {
    let crate_dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let out_dir = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    println!("cargo:rerun-if-env-changed=FERROVOL_UPDATE_HEADER");
    let config = cbindgen::Config::from_file(format!("{crate_dir}/cbindgen.toml"))
        .expect("ffi/cbindgen.toml is valid");
    let bindings = cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen could not parse ffi/src");
    bindings.write_to_file(format!("{out_dir}/ferrovol.h"));
    if std::env::var_os("FERROVOL_UPDATE_HEADER").is_some() {
        bindings.write_to_file(format!("{crate_dir}/include/ferrovol.h"));
    }
}
