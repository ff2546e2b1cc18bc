//! Volumes whose scalars are a [`ScalarSource`] (read in runs, never held whole) render
//! byte for byte as the same values in memory, as one brick and as many bricks, for float32
//! and uint16 storage; a source's NaN and its read failures are errors of the upload.

use crate::common::gpu::{renderer, set_bricked};
use crate::common::scenes::{component_transfer, oblique, shaded};
use ferrovol_core::*;
use std::sync::Arc;

/// The values of `v` in memory, in its scalar type (float32 or uint16).
fn in_memory(v: &VolumeData) -> VolumeData {
    let mut all = vec![0.0; v.scalars.len()];
    v.scalars.read_run(0, &mut all).unwrap();
    let scalars = match v.scalars.scalar_type() {
        ScalarType::F32 => Scalars::F32(all.iter().map(|&x| x as f32).collect()),
        ScalarType::U16 => Scalars::U16(all.iter().map(|&x| x as u16).collect()),
        t => panic!("no in-memory copy for {t:?}"),
    };
    VolumeData {
        scalars,
        ..v.clone()
    }
}

/// A transfer function over `v`'s range, partly transparent, so rays cross every brick.
fn transfer(v: &VolumeData) -> TransferFunction {
    let [lo, hi] = v.range(0);
    let at = |f: f64| lo + (hi - lo) * f;
    TransferFunction::single(component_transfer(
        &[
            (at(0.0), [0.2, 0.3, 0.9]),
            (at(0.5), [0.9, 0.6, 0.2]),
            (at(1.0), [1.0, 1.0, 0.9]),
        ],
        &[(at(0.3), 0.0), (at(0.6), 0.3), (at(1.0), 0.8)],
        2.0,
    ))
}

#[test]
fn a_source_renders_as_its_values_in_memory() {
    let mut r = renderer();
    for ty in [ScalarType::F32, ScalarType::U16] {
        let source = synth::wavelet_generated(synth::wavelet_extent(26), ty).unwrap();
        assert!(source.scalars.source().is_some());
        let memory = in_memory(&source);
        r.set_transfer_function(&transfer(&memory)).unwrap();
        let view = oblique(&memory, 64);
        let mut images = Vec::new();
        for vol in [&memory, &source] {
            r.set_volume(vol).unwrap();
            assert_eq!(r.brick_count(), 1);
            let one = r.render_image(&view, &shaded()).unwrap();
            set_bricked(&mut r, vol, 12);
            assert!(r.brick_count() >= 8, "{} bricks", r.brick_count());
            let bricked = r.render_image(&view, &shaded()).unwrap();
            images.push((one, bricked));
        }
        let (m, s) = (&images[0], &images[1]);
        let covered = m.0.rgba.chunks(4).filter(|p| p[3] > 0).count();
        println!("{ty:?}: {covered} pixels covered");
        assert!(covered > 64 * 64 / 10, "{ty:?}: the image shows nothing");
        assert!(m.0.rgba == s.0.rgba, "{ty:?}: one brick differs");
        assert!(m.1.rgba == s.1.rgba, "{ty:?}: bricked differs");
    }
}

/// A source that fails after `ok` values, or gives NaN at value `nan`.
#[derive(Debug)]
struct Faulty {
    len: usize,
    ok: usize,
    nan: usize,
}

impl ScalarSource for Faulty {
    fn scalar_type(&self) -> ScalarType {
        ScalarType::F32
    }
    fn len(&self) -> usize {
        self.len
    }
    fn read(&self, start: usize, out: &mut [f64]) -> std::io::Result<()> {
        if start + out.len() > self.ok {
            return Err(std::io::Error::other("the disk went away"));
        }
        for (i, o) in (start..).zip(out.iter_mut()) {
            *o = if i == self.nan { f64::NAN } else { i as f64 };
        }
        Ok(())
    }
}

#[test]
fn source_errors_are_upload_errors() {
    let mut r = renderer();
    let dims = [8, 8, 8];
    let faulty = |ok, nan| {
        let s = Faulty { len: 512, ok, nan };
        VolumeData::new(dims, 1, Scalars::Source(Arc::new(s))).unwrap()
    };
    let e = r.set_volume(&faulty(512, 300)).unwrap_err().to_string();
    assert!(e.contains("(4, 5, 4)") && e.contains("NaN"), "{e}");
    let e = r
        .set_volume(&faulty(200, usize::MAX))
        .unwrap_err()
        .to_string();
    assert!(e.contains("the disk went away"), "{e}");
    r.set_volume(&faulty(512, usize::MAX)).unwrap();
}
