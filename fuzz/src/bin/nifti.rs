//! NIfTI-1 and NIfTI-2, plain (`.nii`) or gzip-compressed (`.nii.gz`): the parser tells
//! them apart by the gzip magic.
fn main() {
    ferrovol_fuzz::fuzz(|input| {
        ferrovol_fuzz::check_volume(
            &ferrovol_io::Format::Nifti.parse(input, ferrovol_io::no_data_file),
        )
    });
}
