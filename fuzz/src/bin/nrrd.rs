//! NRRD: `.nrrd` with attached data (raw, gzip, ascii, hex) and `.nhdr` with a detached
//! data file (after the input's data-file mark, see `split_data_file`).
fn main() {
    ferrovol_fuzz::fuzz(|input| {
        ferrovol_fuzz::parse_with_data_file(ferrovol_io::Format::Nrrd, input, "fuzz.nrrd")
    });
}
