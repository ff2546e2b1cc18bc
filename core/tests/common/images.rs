//! Test images: PNGs in `target/test-images` for inspection, written here (with the `image`
//! crate) rather than by the renderer.

use ferrovol_core::Image;
use std::path::PathBuf;

/// `target/test-images`, created when missing.
pub fn dir() -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/test-images");
    std::fs::create_dir_all(&dir).expect("creating target/test-images");
    dir
}

/// Writes `NAME.png`: a `width` × `height` RGB image enlarged `zoom`× (nearest neighbour).
fn write(name: &str, width: u32, height: u32, zoom: u32, rgb: impl Fn(u32, u32) -> [u8; 3]) {
    image::RgbImage::from_fn(width * zoom, height * zoom, |x, y| {
        image::Rgb(rgb(x / zoom, y / zoom))
    })
    .save(dir().join(format!("{name}.png")))
    .expect("writing a test image");
}

/// Writes `NAME.png`: the premultiplied image over black.
pub fn save(img: &Image, name: &str) {
    write(name, img.width, img.height, 1, |x, y| rgb(img, x, y));
}

/// Writes `NAME.png` over black, enlarged (nearest) to about 256 px so that small test images
/// can be looked at.
pub fn save_enlarged(img: &Image, name: &str) {
    let zoom = (256 / img.width.max(img.height)).max(1);
    write(name, img.width, img.height, zoom, |x, y| rgb(img, x, y));
}

/// Writes `NAME.png` from 8-bit RGB bytes of a `size` × `size` image, enlarged `zoom`×.
pub fn save_rgb(bytes: &[u8], size: u32, zoom: u32, name: &str) {
    write(name, size, size, zoom, |x, y| {
        let i = 3 * (y * size + x) as usize;
        [bytes[i], bytes[i + 1], bytes[i + 2]]
    });
}

fn rgb(img: &Image, x: u32, y: u32) -> [u8; 3] {
    let i = 4 * (y * img.width + x) as usize;
    [img.rgba[i], img.rgba[i + 1], img.rgba[i + 2]]
}
