//! VTK UnstructuredGrid (`.vtu`): every encoding (ascii, base64 binary, appended raw or
//! base64, zlib-compressed), several pieces, and the mesh validation behind them.
fn main() {
    ferrovol_fuzz::fuzz(|input| ferrovol_fuzz::check_mesh(&ferrovol_io::vtu::parse(input)));
}
