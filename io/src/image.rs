//! Image files around the renderer: environment maps in (equirectangular `.hdr`, `.exr`,
//! `.png`, `.jpg`, or six cube faces) and rendered frames out (PNG over a background).
//!
//! Like the volume readers, each reader has a byte-slice form ([`parse_environment`]) beside
//! the path form ([`read_environment`], [`read_environment_cube`]). Values are taken as
//! linear radiance as they come: LDR images are not sRGB-decoded (the renderer's output is
//! not encoded either); negative and non-finite texels become 0.

use std::path::Path;

use ferrovol_core::{Environment, Image, FACE_NAMES};

/// File name endings (case-insensitive) the environment readers take.
pub const ENVIRONMENT_EXTENSIONS: &[&str] = &["hdr", "exr", "png", "jpg", "jpeg"];

/// Why an image file could not be read or written. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file name ends in none of [`ENVIRONMENT_EXTENSIONS`].
    #[error("environment map '{path}': unsupported file type '{extension}'; give an .hdr, .exr, .png or .jpg image")]
    UnknownFormat { path: String, extension: String },
    /// The file could not be opened.
    #[error("environment map '{path}' cannot be opened: {message}; check the path")]
    Open { path: String, message: String },
    /// The bytes are not an image of the format the name says.
    #[error("environment map '{path}' is not a readable image: {message}")]
    Decode { path: String, message: String },
    /// The image decodes but its shape is not what the source needs.
    #[error("{0}")]
    Shape(String),
    /// The pixels make no valid environment.
    #[error("environment map '{path}': {error}")]
    Environment {
        path: String,
        error: ferrovol_core::Error,
    },
    /// An image could not be written.
    #[error("could not write image '{path}': {message}")]
    Write { path: String, message: String },
}

/// An image's size and its texels as linear RGB.
struct Texels {
    width: u32,
    height: u32,
    rgb: Vec<[f32; 3]>,
}

fn format_of(path: &Path) -> Result<::image::ImageFormat, ImageError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "hdr" => Ok(::image::ImageFormat::Hdr),
        "exr" => Ok(::image::ImageFormat::OpenExr),
        "png" => Ok(::image::ImageFormat::Png),
        "jpg" | "jpeg" => Ok(::image::ImageFormat::Jpeg),
        _ => Err(ImageError::UnknownFormat {
            path: path.display().to_string(),
            extension,
        }),
    }
}

/// Decodes an image whose name says `format`; the content's own signature wins where it
/// says otherwise.
fn decode(bytes: &[u8], format: ::image::ImageFormat, name: &str) -> Result<Texels, ImageError> {
    let bad = |e: &dyn std::fmt::Display| ImageError::Decode {
        path: name.to_string(),
        message: e.to_string(),
    };
    let img = ::image::ImageReader::with_format(std::io::Cursor::new(bytes), format)
        .with_guessed_format()
        .map_err(|e| bad(&e))?
        .decode()
        .map_err(|e| bad(&e))?;
    let rgb = img.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let rgb = rgb
        .pixels()
        .map(|p| p.0.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 }))
        .collect();
    Ok(Texels { width, height, rgb })
}

fn read(path: &Path) -> Result<Texels, ImageError> {
    let format = format_of(path)?;
    let bytes = std::fs::read(path).map_err(|e| ImageError::Open {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    decode(&bytes, format, &path.display().to_string())
}

fn equirect(t: Texels, name: &str) -> Result<Environment, ImageError> {
    if t.width != 2 * t.height {
        return Err(ImageError::Shape(format!(
            "environment map '{name}' is {}x{}: an equirectangular map must be exactly twice as \
             wide as high (for six cube faces use read_environment_cube)",
            t.width, t.height
        )));
    }
    Environment::from_equirect(t.width, t.height, t.rgb).map_err(|error| ImageError::Environment {
        path: name.to_string(),
        error,
    })
}

/// Reads an equirectangular environment map: `.hdr` (Radiance RGBE), `.exr` (OpenEXR) or
/// `.png`/`.jpg`, twice as wide as high.
pub fn read_environment(path: &Path) -> Result<Environment, ImageError> {
    let t = read(path)?;
    equirect(t, &path.display().to_string())
}

/// [`read_environment`] from the file's bytes; `name` is the file's name, whose ending
/// gives the format and which the messages name.
pub fn parse_environment(bytes: &[u8], name: &str) -> Result<Environment, ImageError> {
    let t = decode(bytes, format_of(Path::new(name))?, name)?;
    equirect(t, name)
}

/// Reads six square cube faces of one size, in the order +X, −X, +Y, −Y, +Z, −Z.
pub fn read_environment_cube(paths: &[&Path; 6]) -> Result<Environment, ImageError> {
    let mut faces = Vec::with_capacity(6);
    let mut size = 0;
    for (i, p) in paths.iter().enumerate() {
        let t = read(p)?;
        if t.width != t.height || (i > 0 && t.width != size) {
            return Err(ImageError::Shape(format!(
                "cube face {} '{}' is {}x{}: the six faces must be square and of one size{}",
                FACE_NAMES[i],
                p.display(),
                t.width,
                t.height,
                if i > 0 {
                    format!(" ({size}x{size} like the first)")
                } else {
                    String::new()
                }
            )));
        }
        size = t.width;
        faces.push(t.rgb);
    }
    Environment::from_cube(size, faces).map_err(|error| ImageError::Environment {
        path: paths[0].display().to_string(),
        error,
    })
}

/// A frame composited over an opaque `background` colour (linear, 0 to 1): RGB8, rows top
/// to bottom.
pub fn over_background(img: &Image, background: [f32; 3]) -> Vec<u8> {
    img.rgba
        .chunks_exact(4)
        .flat_map(|p| {
            let a = p[3] as f32 / 255.0;
            [0, 1, 2].map(|c| {
                let v = p[c] as f32 + (1.0 - a) * background[c] * 255.0;
                v.round().clamp(0.0, 255.0) as u8
            })
        })
        .collect()
}

/// Writes a frame as a PNG, composited over an opaque background colour.
pub fn write_png(img: &Image, path: &Path, background: [f32; 3]) -> Result<(), ImageError> {
    ::image::save_buffer(
        path,
        &over_background(img, background),
        img.width,
        img.height,
        ::image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| ImageError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
