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

/// Runs `ferrovol render ARGS --out PNG` (PNG a temp file named after `name`) and
/// checks that it succeeded; returns the PNG's path, stdout and stderr.
fn render_ok(name: &str, args: &[&str]) -> (std::path::PathBuf, String, String) {
    let out = std::env::temp_dir().join(format!("ferrovol-cli-test-{name}.png"));
    let path = out.to_str().expect("utf-8 temp path");
    let all: Vec<&str> = ["render"]
        .iter()
        .chain(args)
        .chain(&["--out", path])
        .copied()
        .collect();
    let (code, stdout, err) = ferrovol(&all);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains(path), "{stdout}");
    (out, stdout, err)
}

#[test]
fn bad_input_fails_with_a_message() {
    let iso = "--demo marschner-lobb --mode iso --size 16x16 --iso 0.5";
    let pt = "--demo sphere --mode pathtrace --size 8x8";
    // (flags, more flags, words the message must hold)
    let cases = [
        ("", "/no/such/volume.vti", "/no/such/volume.vti"),
        ("", "--size 0x10", "each side must be 1 to 16384"),
        ("--size 8x8", "--tf no-such-preset", "neither a preset"),
        ("--size 8x8", "--sample-distance 0", "sample distance 0"),
        (iso, "--iso abc", "not a finite number"),
        (iso, "--iso 0.5:0", "(0, 1]"),
        (iso, "--iso 0.5:1.5", "(0, 1]"),
        (iso, "--iso 0.5:1:2,0,0", "[0, 1]"),
        (iso, "--env /no/such/sky.hdr", "/no/such/sky.hdr"),
        (iso, "--env sky.txt", "unsupported file type"),
        (iso, "--env-cube a.png,b.png", "six"),
        (iso, "--env-up w", "x, y, z"),
        (iso, "--view-up up", "x, y, z"),
        (iso, "--view-up z", "parallel"),
        (iso, "--specular-samples 0", "specular samples"),
        (iso, "--ao 0", "ambient-occlusion"),
        (iso, "--layers 9", "layers"),
        (iso, "--shininess -1", "non-negative"),
        (iso, "--fresnel 2", "Fresnel"),
        (
            iso,
            "--scatter-inside traced --scatter-samples 0",
            "scattering directions",
        ),
        (
            iso,
            "--scatter-inside preview --absorption -1",
            "absorption",
        ),
        (iso, "--scatter-inside sometimes", "invalid value"),
        (pt, "--g 1.5", "anisotropy"),
        (pt, "--spp 0", "spp"),
        (pt, "--env-light -1", "environment light"),
        (pt, "--budget 8", "PxS"),
        (pt, "--budget 0x8", "at least 1"),
        (pt, "--budget 8x8 --spp 4", "cannot be used with"),
        (pt, "--psi -1", "gradient threshold"),
        (pt, "--psi 1 --blend-k 2", "cannot be used with"),
        (pt, "--blend-k inf", "stochastic blend"),
        (pt, "--roughness 0", "roughness"),
        (pt, "--bsdf-fresnel 2", "Fresnel"),
        (pt, "--transmission 1.5", "transmission"),
        (pt, "--cone-angle 90", "cone angle"),
        (pt, "--scatter sometimes", "invalid value"),
    ];
    for (base, args, words) in cases {
        let mut all = vec!["render"];
        all.extend(base.split_whitespace().chain(args.split_whitespace()));
        all.extend(["--out", "/tmp/ferrovol-cli-never.png"]);
        let (code, _, err) = ferrovol(&all);
        println!("{args}: exit {code}: {}", err.lines().next().unwrap_or(""));
        assert_ne!(code, 0, "{args}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(err.contains(words), "{args}: '{err}' lacks '{words}'");
    }
}

#[test]
fn demo_render_writes_a_picture_of_the_volume() {
    let args = ["--demo", "marschner-lobb", "--shade", "--size", "96x80"];
    let (out, _, _) = render_ok("demo", &args);
    let img = image::open(&out).expect("a PNG").to_rgb8();
    assert_eq!(img.dimensions(), (96, 80));
    // The volume covers the middle of the picture and leaves the black background around it.
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    let corner = img.get_pixel(0, 0).0;
    println!("lit pixels {lit} of {}, corner {corner:?}", 96 * 80);
    assert!(lit > 96 * 80 / 10, "only {lit} lit pixels");
    assert_eq!(corner, [0, 0, 0]);
}

/// Interactive frames past the memory budget: `--preview-level --repeat` says how many of
/// them drew a coarser level's bricks where fine ones were missing, and never streams.
#[test]
fn preview_frames_over_the_budget_report_their_stand_ins() {
    let args = [
        "--demo-size",
        "64",
        "--size",
        "64x64",
        "--gpu-memory",
        "1",
        "--brick",
        "24",
        "--preview-level",
        "--repeat",
        "3",
    ];
    let (out, stdout, _) = render_ok("preview", &args);
    println!("{stdout}");
    assert!(
        stdout.contains("3 of 3 frame(s) drew a coarser level's bricks"),
        "{stdout}"
    );
    assert!(
        !stdout.contains("streamed pass"),
        "a preview does not stream"
    );
    let img = image::open(&out).expect("a PNG").to_rgb8();
    assert!(img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count() > 64 * 64 / 10);
}

#[test]
fn iso_render_of_nested_surfaces_with_ao() {
    let iso = ["--demo", "marschner-lobb", "--mode", "iso", "--iso", "0.7"];
    let args = [
        "--iso",
        "0.3:0.4:1,0.6,0.5",
        "--ao",
        "8",
        "--env-background",
        "--size",
        "64x64",
    ];
    let (out, _, _) = render_ok("iso", &[&iso[..], &args].concat());
    let img = image::open(&out).expect("a PNG").to_rgb8();
    // the environment fills the background: no black pixel is left
    let black = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    println!("black pixels: {black}");
    assert_eq!(black, 0);
    // light scattered between the surfaces, traced
    let args = [
        "--iso",
        "0.3",
        "--scatter-inside",
        "traced",
        "--scatter-samples",
        "4",
    ];
    render_ok(
        "iso",
        &[&iso[..], &args, &["--absorption", "0.5", "--size", "32x32"]].concat(),
    );
}

#[test]
fn pathtrace_render_accumulates_paths() {
    let pt = [
        "--demo",
        "marschner-lobb",
        "--mode",
        "pathtrace",
        "--size",
        "24x24",
    ];
    let (out, _, err) = render_ok(
        "pathtrace",
        &[&pt[..], &["--spp", "70", "--g", "0.3"]].concat(),
    );
    // 64 paths in the first frame, 6 in the second: one accumulation, not a restart
    assert!(err.contains("70 paths per pixel"), "{err}");
    let img = image::open(&out).expect("a PNG").to_rgba8();
    let lit = img.pixels().filter(|p| p.0[3] > 0).count();
    println!("{lit} of {} pixels met the medium", 24 * 24);
    assert!(lit > 100);
    // The hybrid model, scattering at surfaces only, with a 2x4 ray budget.
    let args = [
        "--budget",
        "2x4",
        "--psi",
        "0.5",
        "--scatter",
        "iso",
        "--transmission",
        "0.5",
    ];
    let (_, _, err) = render_ok("pathtrace", &[&pt[..], &args].concat());
    assert!(err.contains("8 paths per pixel"), "{err}");
}

/// The house (a hexahedron with a pyramid roof) as an ASCII VTK XML UnstructuredGrid.
const HOUSE_VTU: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="9" NumberOfCells="2">
      <PointData Scalars="height">
        <DataArray type="Float32" Name="height" format="ascii">0 0 0 0 1 1 1 1 2</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 0  1 0 0  1 1 0  0 1 0  0 0 1  1 0 1  1 1 1  0 1 1  0.5 0.5 2
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3 4 5 6 7 4 5 6 7 8</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">8 13</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">12 14</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;

#[test]
fn a_vtu_mesh_renders_is_described_and_refuses_what_meshes_do_not_draw() {
    let vtu = std::env::temp_dir().join("ferrovol-cli-test-house.vtu");
    std::fs::write(&vtu, HOUSE_VTU).unwrap();
    let path = vtu.to_str().unwrap();
    let (png, stdout, _) = render_ok("house", &[path, "--mode", "mip", "--size", "32x32"]);
    assert!(stdout.contains("9 points, 2 cells"), "{stdout}");
    let img = image::open(&png).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    assert!(lit > 100, "{lit} pixels drawn");
    // path traced: the thin medium (two cells deep) scatters the sky dimly where the
    // maximum intensity projection drew
    let (png, _, _) = render_ok(
        "house-pathtrace",
        &[
            path,
            "--mode",
            "pathtrace",
            "--spp",
            "32",
            "--size",
            "32x32",
        ],
    );
    let img = image::open(&png).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 4)).count();
    assert!(lit > 60, "path traced: {lit} pixels drawn");
    let (code, out, _) = ferrovol(&["info", path]);
    assert_eq!(code, 0);
    assert!(
        out.contains("1 VTK_HEXAHEDRON (12)") && out.contains("tetrahedra: 14"),
        "{out}"
    );
    // the isosurface height 0.5 (the cube's middle) and 1.5 (inside the roof)
    let (png, _, _) = render_ok(
        "house-iso",
        &[
            path, "--mode", "iso", "--iso", "0.5", "--iso", "1.5", "--size", "32x32",
        ],
    );
    let img = image::open(&png).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    assert!(lit > 100, "isosurfaces: {lit} pixels drawn");
    let (code, _, err) = ferrovol(&["render", path, "--mode", "slice", "--size", "8x8"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("unstructured volumes are drawn in the composite"),
        "{err}"
    );
}
