//! Bricked volumes, streaming, device memory, out of memory and device loss through the C
//! ABI.

use super::*;

type Residency = unsafe extern "C" fn(H, *mut ferrovol::FvResidency) -> FvStatus;

/// An n³ u8 volume of `value(x, y, z)`, x fastest.
fn cube_u8(n: usize, value: impl Fn(usize, usize, usize) -> u8) -> Vec<u8> {
    (0..n * n * n)
        .map(|i| value(i % n, (i / n) % n, i / (n * n)))
        .collect()
}

/// A session whose renderer bricks volumes (fv_renderer_set_max_brick_points), and
/// fv_renderer_residency.
fn bricked_session(lib: &Lib, max_brick_points: u32) -> (Session<'_>, Residency) {
    let s = Session::new(lib);
    let set_bricks =
        lib.f::<unsafe extern "C" fn(H, u32) -> FvStatus>("fv_renderer_set_max_brick_points");
    // SAFETY: a valid handle.
    unsafe { lib.ok(set_bricks(s.r, max_brick_points)) };
    (s, *lib.f::<Residency>("fv_renderer_residency"))
}

/// A bricked volume keeps only the bricks something visible lies in, reports it through
/// fv_renderer_residency, and keeps rendering after the caller frees its FvVolume (the
/// renderer shares the data it reads bricks from).
#[test]
fn bricked_volume_residency_outlives_the_volume() {
    let lib = Lib::open();
    let n = 24usize;
    // a bright ball in one corner of a dark volume
    let data = cube_u8(n, |x, y, z| {
        let r2 = (x as f32 - 5.0).powi(2) + (y as f32 - 5.0).powi(2) + (z as f32 - 5.0).powi(2);
        if r2 < 16.0 {
            200
        } else {
            0
        }
    });
    let (mut s, residency) = bricked_session(&lib, 10);
    // SAFETY: a valid handle; the residency out-pointer is checked for NULL.
    unsafe { lib.expect(residency(s.r, null_mut()), Null, "residency") };
    s.set_volume([24, 24, 24], FvScalarType::U8, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 100.0, 0.0, 255.0, 1.0],
    );
    s.set_camera(&camera([11.5, 11.5, 80.0], [11.5; 3], [1.0, 200.0]));
    let before = s.frame(32, 32).to_vec();
    assert!(before.chunks(4).any(|p| p[3] > 100), "the ball is drawn");
    let mut res = ferrovol::FvResidency::default();
    // SAFETY: valid handles; the volume is freed once and forgotten by the session.
    unsafe {
        lib.ok(residency(s.r, &mut res));
        lib.f::<Free>("fv_volume_free")(s.volume);
    }
    s.volume = null_mut();
    let after = s.frame(32, 32).to_vec();
    println!(
        "{} of {} bricks resident ({} uploaded), pool {} bytes, dense {} bytes",
        res.resident, res.bricks, res.brick_uploads, res.pool_bytes, res.dense_bytes
    );
    assert!(res.bricks >= 8);
    assert!(
        res.resident >= 1 && res.resident * 3 <= res.bricks,
        "{res:?}"
    );
    assert_eq!(res.brick_uploads, res.resident);
    assert_eq!(res.dense_bytes, (n * n * n) as u64);
    assert_eq!(before, after, "the renderer still has the data");
}

/// The brick pool follows what a frame needs: a transfer function that shows a corner of
/// the volume after one that shows all of it shrinks the pool the residency reports, the
/// needed bricks copied on the device (no upload); showing all again grows it back.
#[test]
fn brick_pool_shrinks_to_what_is_shown() {
    let lib = Lib::open();
    let n = 24usize;
    let data = cube_u8(n, |x, y, z| ((x + y + z) * 255 / (3 * (n - 1))) as u8);
    let (mut s, residency) = bricked_session(&lib, 8);
    s.set_volume([24, 24, 24], FvScalarType::U8, &data);
    s.set_camera(&camera([11.5, 11.5, 80.0], [11.5; 3], [1.0, 200.0]));
    let white = [0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0];
    let mut seen = Vec::new();
    for from in [1.0, 235.0, 1.0] {
        s.set_transfer_function(&white, &[0.0, 0.0, from, 0.0, 255.0, 0.8]);
        assert!(s.frame(32, 32).chunks(4).any(|p| p[3] > 20), "drawn");
        let mut res = ferrovol::FvResidency::default();
        // SAFETY: valid handles.
        unsafe { lib.ok(residency(s.r, &mut res)) };
        println!(
            "opacity from {from}: {} of {} bricks resident, pool {} bytes, {} uploaded",
            res.resident, res.bricks, res.pool_bytes, res.brick_uploads
        );
        seen.push(res);
    }
    let (all, corner, again) = (seen[0], seen[1], seen[2]);
    assert!(
        2 * corner.pool_bytes <= all.pool_bytes,
        "showing a corner shrinks the pool: {corner:?} after {all:?}"
    );
    assert!(corner.resident < all.resident);
    assert_eq!(
        corner.brick_uploads, all.brick_uploads,
        "the corner's bricks were resident: copied, not uploaded"
    );
    assert_eq!(again.pool_bytes, all.pool_bytes, "and grows back");
}

/// Progress of a streamed frame: a memory budget under what a frame needs makes ray casting
/// stream the bricks in several passes, and the callback hears of each one in order.
#[test]
fn streamed_frames_report_progress() {
    unsafe extern "C" fn record(user: *mut c_void, done: u32, total: u32) {
        // SAFETY: `user` is the test's Vec, alive for the whole render.
        unsafe { (*(user as *mut Vec<(u32, u32)>)).push((done, total)) };
    }
    let lib = Lib::open();
    let n = 32usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    let budget = lib.f::<unsafe extern "C" fn(H, u64) -> FvStatus>("fv_renderer_set_memory_budget");
    let progress = lib
        .f::<unsafe extern "C" fn(H, ferrovol::FvProgressFn, *mut c_void) -> FvStatus>(
            "fv_renderer_set_progress",
        );
    let mut calls: Vec<(u32, u32)> = Vec::new();
    // SAFETY: a valid handle; `calls` outlives every frame rendered with the callback.
    unsafe {
        lib.ok(budget(s.r, (n * n * n) as u64)); // a quarter of the float32 volume
        lib.ok(progress(
            s.r,
            Some(record),
            (&mut calls as *mut Vec<(u32, u32)>).cast(),
        ));
    }
    s.set_volume([32, 32, 32], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 31.0, 1.0, 1.0, 1.0],
        &[0.0, 0.1, 31.0, 0.5],
    );
    s.set_camera(&camera([15.5, 15.5, 100.0], [15.5; 3], [1.0, 300.0]));
    let streamed = s.frame(32, 32).to_vec();
    // SAFETY: a valid handle; NULL turns the callback off.
    unsafe { lib.ok(progress(s.r, None, null_mut())) };
    println!("progress calls: {calls:?}");
    let total = calls.last().map_or(0, |c| c.1);
    assert!(total >= 2, "the frame was streamed: {calls:?}");
    assert_eq!(
        calls,
        (1..=total).map(|d| (d, total)).collect::<Vec<_>>(),
        "one call per pass, in order"
    );
    assert!(streamed.chunks(4).any(|p| p[3] > 50), "drawn");
}

/// Path tracing past the memory budget traces a coarser level, and fv_renderer_residency
/// says which: 2 fine points per point for a budget of a quarter of the volume; a ray-cast
/// frame after it draws the volume itself again; a preview frame of ray casting reports the
/// bricks it read from a coarser level's stand-ins, and a still frame none.
#[test]
fn path_tracing_past_the_budget_reports_its_level() {
    let lib = Lib::open();
    let n = 32usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    let mut s = Session::new(&lib);
    let budget = lib.f::<unsafe extern "C" fn(H, u64) -> FvStatus>("fv_renderer_set_memory_budget");
    let residency = lib.f::<Residency>("fv_renderer_residency");
    let read = |s: &Session| {
        let mut res = ferrovol::FvResidency::default();
        // SAFETY: a valid handle and out-pointer.
        unsafe { lib.ok(residency(s.r, &mut res)) };
        res
    };
    // SAFETY: a valid handle.
    unsafe { lib.ok(budget(s.r, (n * n * n) as u64)) }; // a quarter of the float32 volume
    s.set_volume([32, 32, 32], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 0.9, 0.8, 0.7, 31.0, 0.9, 0.8, 0.7],
        &[0.0, 0.0, 31.0, 0.5],
    );
    s.set_camera(&camera([15.5, 15.5, 100.0], [15.5; 3], [1.0, 300.0]));
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::PathTrace as u32;
    s.set_params(&p);
    let traced = s.frame(24, 24).to_vec();
    let res = read(&s);
    println!("path traced past the budget: {res:?}");
    assert!(traced.chunks(4).any(|p| p[3] > 20), "drawn");
    assert_eq!((res.level, res.level_dims), (2, [17; 3]));
    assert!(
        res.pool_bytes <= (n * n * n) as u64,
        "within the budget: {res:?}"
    );
    p.blend_mode = FvBlendMode::Composite as u32;
    s.set_params(&p);
    s.frame(24, 24);
    let res = read(&s);
    assert_eq!((res.level, res.level_dims), (1, [32; 3]), "{res:?}");
    assert_eq!(res.stand_ins, 0, "{res:?}");
    p.preview_level = true;
    s.set_params(&p);
    let preview = s.frame(24, 24).to_vec();
    let res = read(&s);
    println!("a preview past the budget: {res:?}");
    assert!(preview.chunks(4).any(|p| p[3] > 20), "drawn");
    assert!(res.stand_ins > 0 && res.level == 1, "{res:?}");
}

/// The device-memory tests' scene on `s`: a 16³ f32 ramp along x (0 to 15), then
/// [`small_scene_view`].
fn small_scene(s: &mut Session) {
    let n = 16usize;
    let data: Vec<f32> = (0..n * n * n).map(|i| (i % n) as f32).collect();
    s.set_volume([16, 16, 16], FvScalarType::F32, &data);
    small_scene_view(s);
}

/// A session showing [`small_scene`] and its 24 × 24 frame, checked to show the volume.
fn small_scene_session(lib: &Lib) -> (Session<'_>, Vec<u8>) {
    let mut s = Session::new(lib);
    small_scene(&mut s);
    let frame = s.frame(24, 24).to_vec();
    assert!(frame.chunks(4).any(|p| p[3] > 100), "the volume is drawn");
    (s, frame)
}

/// White to orange over the ramp, opacity rising to 1, seen from +z: what a renderer made
/// again for `small_scene`'s volume needs to draw it the same.
fn small_scene_view(s: &mut Session) {
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 15.0, 1.0, 0.5, 0.0],
        &[0.0, 0.0, 15.0, 1.0],
    );
    s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
}

/// The context's device memory counters: a renderer's frames allocate once (repeated
/// frames hold the same buffers and textures), and a renderer freed and made again holds no
/// more than the first one did.
#[test]
fn device_memory_stays_flat_over_frames_and_renderers() {
    type Memory = unsafe extern "C" fn(H, *mut ferrovol::FvDeviceMemory) -> FvStatus;
    let lib = Lib::open();
    let mut s = Session::new(&lib);
    let memory = lib.f::<Memory>("fv_context_device_memory");
    let read = |s: &Session| {
        let mut m = ferrovol::FvDeviceMemory::default();
        // SAFETY: a valid context and out-pointer.
        unsafe { lib.ok(memory(s.ctx, &mut m)) };
        m
    };
    // SAFETY: a NULL out-pointer is refused, not written.
    unsafe { lib.expect(memory(s.ctx, null_mut()), Null, "memory") };
    small_scene(&mut s);
    s.frame(24, 24);
    let first = read(&s);
    for _ in 0..5 {
        s.frame(24, 24);
    }
    let again = read(&s);
    println!("after one frame {first:?}\nafter six       {again:?}");
    assert!(first.texture_views > 0 && first.texture_bytes > 0 && first.buffers > 0);
    assert_eq!(
        (again.buffers, again.texture_views, again.bind_groups),
        (first.buffers, first.texture_views, first.bind_groups)
    );
    assert_eq!(
        (again.buffer_bytes, again.texture_bytes),
        (first.buffer_bytes, first.texture_bytes)
    );
    for _ in 0..3 {
        // SAFETY: the renderer came from fv_renderer_new and is replaced by a new one.
        unsafe {
            lib.f::<Free>("fv_renderer_free")(s.r);
            s.r = null_mut();
            lib.ok(lib.f::<NewRenderer>("fv_renderer_new")(s.ctx, &mut s.r));
            lib.ok(lib.f::<SetH>("fv_renderer_set_volume")(s.r, s.volume));
        }
        small_scene_view(&mut s);
        s.frame(24, 24);
        s.frame(24, 24);
    }
    let renewed = read(&s);
    println!("after three new renderers {renewed:?}");
    assert!(
        renewed.buffer_bytes + renewed.texture_bytes <= first.buffer_bytes + first.texture_bytes,
        "{renewed:?} holds more than {first:?}"
    );
}

/// Out of device memory (a cap set with fv_context_limit_device_memory, as a smaller device
/// would have): a frame that needs more memory returns FV_STATUS_OUT_OF_MEMORY naming the
/// sizes, the renderer stays usable, and without the cap it draws the same frame as before.
#[test]
fn out_of_memory_is_reported_and_the_renderer_recovers() {
    let lib = Lib::open();
    let (mut s, before) = small_scene_session(&lib);
    type Limit = unsafe extern "C" fn(H, u64) -> FvStatus;
    let limit = lib.f::<Limit>("fv_context_limit_device_memory");
    let render = lib.f::<Render>("fv_renderer_render");
    let mut memory = ferrovol::FvDeviceMemory::default();
    // SAFETY: valid handles and a live FvDeviceMemory.
    unsafe {
        lib.expect(limit(null_mut(), 1), Null, "ctx");
        lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvDeviceMemory) -> FvStatus>(
            "fv_context_device_memory",
        )(s.ctx, &mut memory);
        let held = memory.buffer_bytes + memory.texture_bytes;
        assert!(held > 0, "the frame holds device memory");
        assert_eq!(limit(s.ctx, held + 1024), FvStatus::Ok);
        lib.expect(
            render(s.r, 512, 512, null(), 0),
            FvStatus::OutOfMemory,
            "limited to",
        );
        assert_eq!(limit(s.ctx, 0), FvStatus::Ok);
    }
    assert_eq!(
        s.frame(24, 24),
        &before[..],
        "without the cap the renderer draws the same frame"
    );
}

/// A lost device (fv_context_lose_device, as a driver reset would): the renderer's next
/// frame returns FV_STATUS_DEVICE_LOST with a message saying what to do, and a new context
/// and renderer draw the same frame as before.
#[test]
fn device_loss_is_reported_and_a_new_context_draws() {
    let lib = Lib::open();
    let (s, before) = small_scene_session(&lib);
    let render = lib.f::<Render>("fv_renderer_render");
    // SAFETY: a valid context (NULL is ignored) and renderer.
    unsafe {
        lib.f::<unsafe extern "C" fn(H)>("fv_context_lose_device")(null_mut());
        lib.f::<unsafe extern "C" fn(H)>("fv_context_lose_device")(s.ctx);
        lib.expect(
            render(s.r, 24, 24, null(), 0),
            FvStatus::DeviceLost,
            "create a new context",
        );
    }
    drop(s);
    let (_fresh, after) = small_scene_session(&lib);
    assert_eq!(after, before, "a new context draws the same frame");
}
