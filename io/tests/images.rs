//! Image files: environment maps read (with what is wrong said), the maps' radiance as the
//! renderer sees it, and frames written as PNG.

use std::path::Path;

use ferrovol_core::{Context, Environment, EnvironmentSource, Image, Renderer};
use ferrovol_io::image::{
    over_background, parse_environment, read_environment, read_environment_cube, write_png,
};

mod common;
use common::TempDir;

/// The error's message, checked for each of `words`.
fn error_with<T, E: std::fmt::Display>(res: Result<T, E>, words: &[&str]) -> String {
    let e = match res {
        Ok(_) => panic!("accepted, an error was expected ({words:?})"),
        Err(e) => e.to_string(),
    };
    println!("{e}");
    for w in words {
        assert!(e.contains(w), "'{e}' lacks '{w}'");
    }
    e
}

fn solid_png(path: &Path, w: u32, h: u32, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(w, h, image::Rgb(rgb))
        .save(path)
        .unwrap();
}

#[test]
fn environment_files_say_what_is_wrong() {
    let dir = TempDir::new("env-errors");
    error_with(
        read_environment(&dir.path("missing.hdr")),
        &["missing.hdr", "cannot be opened"],
    );
    error_with(
        read_environment(&dir.path("sky.txt")),
        &["unsupported file type 'txt'"],
    );
    let corrupt = dir.path("corrupt.png");
    std::fs::write(&corrupt, b"not a png at all").unwrap();
    error_with(
        read_environment(&corrupt),
        &["corrupt.png", "not a readable image"],
    );
    let square = dir.path("square.png");
    solid_png(&square, 8, 8, [10, 20, 30]);
    error_with(read_environment(&square), &["8x8", "twice as wide"]);
    let small = dir.path("small.png");
    solid_png(&small, 4, 4, [10, 20, 30]);
    let faces = [&square, &square, &square, &small, &square, &square].map(|p| p.as_path());
    error_with(
        read_environment_cube(&faces),
        &["cube face -Y", "4x4", "one size"],
    );
    error_with(
        parse_environment(b"not a png at all", "memory.png"),
        &["memory.png", "not a readable image"],
    );
}

/// The texels an equirectangular environment holds.
fn texels(env: &Environment) -> &[[f32; 3]] {
    match &env.source {
        EnvironmentSource::Equirect { texels, .. } => texels,
        other => panic!("an equirectangular source was expected, got {other:?}"),
    }
}

#[test]
fn environment_maps_keep_their_radiance() {
    let dir = TempDir::new("env-values");
    let mut r = Renderer::new(Context::new().expect("a device")).unwrap();
    // constant maps in each format: the texels and the irradiance are the constant
    let c = [0.25f32, 0.5, 2.0];
    let hdr = dir.path("constant.hdr");
    image::Rgb32FImage::from_pixel(64, 32, image::Rgb(c))
        .save(&hdr)
        .unwrap();
    let exr = dir.path("constant.exr");
    image::Rgb32FImage::from_pixel(64, 32, image::Rgb(c))
        .save(&exr)
        .unwrap();
    let png = dir.path("constant.png");
    solid_png(&png, 64, 32, [51, 102, 255]);
    for (path, want) in [(&hdr, c), (&exr, c), (&png, [0.2, 0.4, 1.0])] {
        let env = read_environment(path).unwrap();
        let from_bytes =
            parse_environment(&std::fs::read(path).unwrap(), &path.display().to_string()).unwrap();
        assert_eq!(
            texels(&env),
            texels(&from_bytes),
            "path and byte APIs agree"
        );
        r.set_environment(&env).unwrap();
        let irr = r.read_irradiance().unwrap();
        let worst = irr
            .faces
            .iter()
            .flatten()
            .flat_map(|t| (0..3).map(move |k| ((t[k] - want[k]) / want[k]).abs()))
            .fold(0.0f32, f32::max);
        println!(
            "{}: irradiance within {worst:.2e} of {want:?}",
            path.display()
        );
        // RGBE keeps 8 mantissa bits per texel (0.4%); half floats 0.05%
        assert!(worst < 0.01);
    }
    // six faces from files
    let small = dir.path("small.png");
    solid_png(&small, 4, 4, [10, 20, 30]);
    let faces = [&small; 6].map(|p| p.as_path());
    let env = read_environment_cube(&faces).unwrap();
    r.set_environment(&env).unwrap();
    let t = r.read_irradiance().unwrap().faces[0][0];
    println!("cube of 4x4 faces: irradiance {t:?}");
    assert!((t[2] - 30.0 / 255.0).abs() < 1e-3);
}

#[test]
fn frames_are_written_over_their_background() {
    let dir = TempDir::new("png");
    // premultiplied: opaque red, half-transparent green, empty
    let img = Image {
        width: 3,
        height: 1,
        rgba: vec![255, 0, 0, 255, 0, 128, 0, 128, 0, 0, 0, 0],
        depth: vec![0.5, 0.5, 1.0],
    };
    let bg = [0.0, 0.0, 1.0];
    let want = [255u8, 0, 0, 0, 128, 127, 0, 0, 255];
    assert_eq!(over_background(&img, bg), want);
    let out = dir.path("frame.png");
    write_png(&img, &out, bg).unwrap();
    let back = image::open(&out).unwrap().to_rgb8();
    assert_eq!(back.dimensions(), (3, 1));
    assert_eq!(back.as_raw().as_slice(), want);
    error_with(
        write_png(&img, &dir.path("no/such/folder/frame.png"), bg),
        &["could not write image", "frame.png"],
    );
}
