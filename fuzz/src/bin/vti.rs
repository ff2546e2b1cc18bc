//! VTK ImageData (`.vti`): every encoding (ascii, base64 binary, appended raw or base64,
//! zlib-compressed) comes through the one byte-slice parser.
fn main() {
    ferrovol_fuzz::fuzz(|input| {
        ferrovol_fuzz::check_volume(
            &ferrovol_io::Format::Vti.parse(input, ferrovol_io::no_data_file),
        )
    });
}
