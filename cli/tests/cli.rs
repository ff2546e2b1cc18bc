//! The `ferrovol` command as a user runs it: exit codes, messages, and a real render.

use std::process::Command;

fn ferrovol(args: &[&str]) -> (i32, String, String) {
    let xdg = std::env::temp_dir().join("ferrovol-cli-test-xdg");
    let _ = std::fs::create_dir_all(&xdg);
    let out = Command::new(env!("CARGO_BIN_EXE_ferrovol"))
        .args(args)
        .env("XDG_RUNTIME_DIR", &xdg)
        .output()
        .expect("the ferrovol binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn missing_file_names_the_file_and_fails() {
    let (code, _, err) = ferrovol(&["render", "/no/such/volume.vti", "--out", "/tmp/never.png"]);
    println!("exit {code}: {err}");
    assert_ne!(code, 0);
    assert!(err.contains("/no/such/volume.vti"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bad_parameters_fail_with_a_message() {
    for args in [
        vec!["render", "--size", "0x10"],
        vec!["render", "--tf", "no-such-preset"],
        vec!["render", "--sample-distance", "0"],
    ] {
        let (code, _, err) = ferrovol(&args);
        println!(
            "{args:?}: exit {code}: {}",
            err.lines().next().unwrap_or("")
        );
        assert_ne!(code, 0, "{args:?}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!err.trim().is_empty());
    }
}

#[test]
fn demo_render_writes_a_picture_of_the_volume() {
    let out = std::env::temp_dir().join("ferrovol-cli-test-demo.png");
    let path = out.to_str().expect("utf-8 temp path");
    let (code, stdout, err) = ferrovol(&[
        "render",
        "--demo",
        "marschner-lobb",
        "--shade",
        "--size",
        "96x80",
        "--out",
        path,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains(path), "{stdout}");
    let img = image::open(&out).expect("a PNG").to_rgb8();
    assert_eq!(img.dimensions(), (96, 80));
    // The volume covers the middle of the picture and leaves the black background around it.
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    let corner = img.get_pixel(0, 0).0;
    println!("lit pixels {lit} of {}, corner {corner:?}", 96 * 80);
    assert!(lit > 96 * 80 / 10, "only {lit} lit pixels");
    assert_eq!(corner, [0, 0, 0]);
}

#[test]
fn iso_flags_reject_bad_values_with_a_message() {
    for (args, words) in [
        (vec!["--iso", "abc"], "not a finite number"),
        (vec!["--iso", "0.5:0"], "(0, 1]"),
        (vec!["--iso", "0.5:1.5"], "(0, 1]"),
        (vec!["--iso", "0.5:1:2,0,0"], "[0, 1]"),
        (
            vec!["--iso", "0.5", "--env", "/no/such/sky.hdr"],
            "/no/such/sky.hdr",
        ),
        (
            vec!["--iso", "0.5", "--env", "sky.txt"],
            "unsupported file type",
        ),
        (vec!["--iso", "0.5", "--env-cube", "a.png,b.png"], "six"),
        (vec!["--iso", "0.5", "--env-up", "w"], "x, y, z"),
        (vec!["--iso", "0.5", "--view-up", "up"], "x, y, z"),
        (vec!["--iso", "0.5", "--view-up", "z"], "parallel"),
        (
            vec!["--iso", "0.5", "--specular-samples", "0"],
            "specular samples",
        ),
        (vec!["--iso", "0.5", "--ao", "0"], "ambient-occlusion"),
        (vec!["--iso", "0.5", "--layers", "9"], "layers"),
        (vec!["--iso", "0.5", "--shininess", "-1"], "non-negative"),
        (vec!["--iso", "0.5", "--fresnel", "2"], "Fresnel"),
        (
            vec![
                "--iso",
                "0.5",
                "--scatter-inside",
                "traced",
                "--scatter-samples",
                "0",
            ],
            "scattering directions",
        ),
        (
            vec![
                "--iso",
                "0.5",
                "--scatter-inside",
                "preview",
                "--absorption",
                "-1",
            ],
            "absorption",
        ),
        (
            vec!["--iso", "0.5", "--scatter-inside", "sometimes"],
            "invalid value",
        ),
    ] {
        let mut all = vec!["render", "--demo", "marschner-lobb", "--mode", "iso"];
        all.extend(&args);
        all.extend(["--size", "16x16", "--out", "/tmp/ferrovol-cli-never.png"]);
        let (code, _, err) = ferrovol(&all);
        println!(
            "{args:?}: exit {code}: {}",
            err.lines().next().unwrap_or("")
        );
        assert_ne!(code, 0, "{args:?}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(err.contains(words), "{args:?}: '{err}' lacks '{words}'");
    }
}

#[test]
fn iso_render_of_nested_surfaces_with_ao() {
    let out = std::env::temp_dir().join("ferrovol-cli-test-iso.png");
    let path = out.to_str().expect("utf-8 temp path");
    let (code, stdout, err) = ferrovol(&[
        "render",
        "--demo",
        "marschner-lobb",
        "--mode",
        "iso",
        "--iso",
        "0.7",
        "--iso",
        "0.3:0.4:1,0.6,0.5",
        "--ao",
        "8",
        "--env-background",
        "--size",
        "64x64",
        "--out",
        path,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains(path), "{stdout}");
    let img = image::open(&out).expect("a PNG").to_rgb8();
    // the environment fills the background: no black pixel is left
    let black = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    println!("black pixels: {black}");
    assert_eq!(black, 0);
    // light scattered between the surfaces, traced
    let (code, _, err) = ferrovol(&[
        "render",
        "--demo",
        "marschner-lobb",
        "--mode",
        "iso",
        "--iso",
        "0.7",
        "--iso",
        "0.3",
        "--scatter-inside",
        "traced",
        "--scatter-samples",
        "4",
        "--absorption",
        "0.5",
        "--size",
        "32x32",
        "--out",
        path,
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn pathtrace_render_and_bad_settings() {
    let out = std::env::temp_dir().join("ferrovol-cli-test-pathtrace.png");
    let path = out.to_str().expect("utf-8 temp path");
    let (code, _, err) = ferrovol(&[
        "render",
        "--demo",
        "marschner-lobb",
        "--mode",
        "pathtrace",
        "--spp",
        "70",
        "--g",
        "0.3",
        "--size",
        "24x24",
        "--out",
        path,
    ]);
    assert_eq!(code, 0, "{err}");
    // 64 paths in the first frame, 6 in the second: one accumulation, not a restart
    assert!(err.contains("70 paths per pixel"), "{err}");
    let img = image::open(&out).expect("a PNG").to_rgba8();
    let lit = img.pixels().filter(|p| p.0[3] > 0).count();
    println!("{lit} of {} pixels met the medium", 24 * 24);
    assert!(lit > 100);
    // The hybrid model, scattering at surfaces only, with a 2x4 ray budget.
    let (code, _, err) = ferrovol(&[
        "render",
        "--demo",
        "marschner-lobb",
        "--mode",
        "pathtrace",
        "--budget",
        "2x4",
        "--psi",
        "0.5",
        "--scatter",
        "iso",
        "--transmission",
        "0.5",
        "--size",
        "24x24",
        "--out",
        path,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("8 paths per pixel"), "{err}");
    for (args, words) in [
        (vec!["--g", "1.5"], "anisotropy"),
        (vec!["--spp", "0"], "spp"),
        (vec!["--env-light", "-1"], "environment light"),
        (vec!["--budget", "8"], "PxS"),
        (vec!["--budget", "0x8"], "at least 1"),
        (vec!["--budget", "8x8", "--spp", "4"], "cannot be used with"),
        (vec!["--psi", "-1"], "gradient threshold"),
        (vec!["--psi", "1", "--blend-k", "2"], "cannot be used with"),
        (vec!["--blend-k", "inf"], "stochastic blend"),
        (vec!["--roughness", "0"], "roughness"),
        (vec!["--bsdf-fresnel", "2"], "Fresnel"),
        (vec!["--transmission", "1.5"], "transmission"),
        (vec!["--cone-angle", "90"], "cone angle"),
        (vec!["--scatter", "sometimes"], "invalid value"),
    ] {
        let mut all = vec!["render", "--demo", "sphere", "--mode", "pathtrace"];
        all.extend(&args);
        all.extend(["--size", "8x8", "--out", "/tmp/ferrovol-cli-never.png"]);
        let (code, _, err) = ferrovol(&all);
        println!(
            "{args:?}: exit {code}: {}",
            err.lines().next().unwrap_or("")
        );
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(words), "{args:?}: '{err}' lacks '{words}'");
    }
}
