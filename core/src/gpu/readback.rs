//! Copies of GPU textures and buffers to the CPU: those a caller asks for (tests, G-buffer
//! and environment inspection, the output image), each waiting for the device, and the
//! [`ReadbackRing`] that frames read their own results through, one frame late, without
//! waiting.

use super::buffers::buffer;
use super::Context;
use crate::error::{Error, Result};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

/// A ring slot's buffer holds nothing the ring still has to read.
const FREE: u8 = 0;
/// A copy into the slot is encoded, not submitted yet.
const RECORDED: u8 = 1;
/// Submitted and asked to map: the device has not finished it.
const PENDING: u8 = 2;
/// Mapped: the copy is there to read.
const READY: u8 = 3;

/// One staging buffer of a [`ReadbackRing`].
struct RingSlot {
    buffer: wgpu::Buffer,
    /// FREE, RECORDED, PENDING or READY; the map callback moves PENDING on.
    state: Arc<AtomicU8>,
    /// The recording's place in the ring's order (the newest ready copy wins).
    order: u64,
    /// What the recorder said the copy stands for (e.g. the work it measured).
    tag: u64,
}

/// Results a frame copies out for the host to read at a later frame, without waiting for the
/// device: a few staging buffers, each free, recorded (the copy encoded in the frame's
/// commands), pending (submitted and asked to map) or ready (mapped). A frame records into a
/// free slot ([`ReadbackRing::record`]), marks it submitted after its submission
/// ([`ReadbackRing::submitted`]); a later frame takes the newest copy the device has
/// finished ([`ReadbackRing::take_latest`], which only polls). With every slot in flight a
/// frame records nothing: its results are skipped, never waited for.
pub(crate) struct ReadbackRing {
    slots: Vec<RingSlot>,
    /// Recordings so far.
    recorded: u64,
}

impl ReadbackRing {
    /// `count` staging buffers of `size` bytes.
    pub(crate) fn new(ctx: &Context, label: &str, size: u64, count: usize) -> ReadbackRing {
        let slots = (0..count)
            .map(|_| RingSlot {
                buffer: buffer(
                    ctx,
                    label,
                    size,
                    wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                ),
                state: Arc::new(AtomicU8::new(FREE)),
                order: 0,
                tag: 0,
            })
            .collect();
        ReadbackRing { slots, recorded: 0 }
    }

    /// Takes a free slot for a copy the caller encodes into its buffer
    /// ([`ReadbackRing::buffer`]); None while every slot is in flight. A recording never
    /// submitted (its frame failed) is forgotten by the next.
    pub(crate) fn record(&mut self) -> Option<usize> {
        for s in &self.slots {
            // (compare_exchange: a map callback may be moving a pending slot meanwhile)
            let _ = s
                .state
                .compare_exchange(RECORDED, FREE, Ordering::AcqRel, Ordering::Acquire);
        }
        let i = self
            .slots
            .iter()
            .position(|s| s.state.load(Ordering::Acquire) == FREE)?;
        self.recorded += 1;
        let slot = &mut self.slots[i];
        slot.state.store(RECORDED, Ordering::Release);
        slot.order = self.recorded;
        Some(i)
    }

    /// The staging buffer of `slot` (COPY_DST).
    pub(crate) fn buffer(&self, slot: usize) -> &wgpu::Buffer {
        &self.slots[slot].buffer
    }

    /// After the submission holding the copy into `slot`, which stands for `tag` (e.g. the
    /// work it measured): the buffer maps once the device has finished it.
    pub(crate) fn submitted(&mut self, slot: usize, tag: u64) {
        let s = &mut self.slots[slot];
        if s.state.load(Ordering::Acquire) != RECORDED {
            return;
        }
        s.tag = tag;
        s.state.store(PENDING, Ordering::Release);
        let state = s.state.clone();
        s.buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { READY } else { FREE }, Ordering::Release);
        });
    }

    /// The newest copy that has come back since the last call, with its tag (None if none
    /// has); older ones are dropped. Copies come back in the device's map callbacks, which
    /// run when the device is polled ([`Context::poll`]) or waited for: this never waits.
    pub(crate) fn take_latest(&mut self) -> Option<(u64, Vec<u8>)> {
        let mut latest: Option<(u64, u64, Vec<u8>)> = None;
        for s in &self.slots {
            if s.state.load(Ordering::Acquire) != READY {
                continue;
            }
            if latest.as_ref().is_none_or(|(order, _, _)| s.order > *order) {
                // (a slot maps whole: its range is there to read)
                if let Ok(view) = s.buffer.slice(..).get_mapped_range() {
                    latest = Some((s.order, s.tag, view.to_vec()));
                }
            }
            s.buffer.unmap();
            s.state.store(FREE, Ordering::Release);
        }
        latest.map(|(_, tag, bytes)| (tag, bytes))
    }
}

/// Copies one mip level / array layer of a texture to the CPU (rows tightly packed).
pub(crate) fn read_texture_layer(
    ctx: &Context,
    tex: &wgpu::Texture,
    mip: u32,
    layer: u32,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let w = (tex.width() >> mip).max(1);
    let h = (tex.height() >> mip).max(1);
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buf = buffer(
        ctx,
        "readback",
        padded as u64 * h as u64,
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: tex,
            mip_level: mip,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    ctx.submit([enc.finish()]);
    let bytes = map_read(ctx, &buf)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for y in 0..h as usize {
        out.extend_from_slice(&bytes[y * padded as usize..y * padded as usize + row as usize]);
    }
    Ok(out)
}

/// Copies a storage buffer to the CPU.
pub(crate) fn read_buffer(ctx: &Context, src: &wgpu::Buffer) -> Result<Vec<u8>> {
    let buf = buffer(
        ctx,
        "readback",
        src.size(),
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(src, 0, &buf, 0, src.size());
    ctx.submit([enc.finish()]);
    map_read(ctx, &buf)
}

fn map_read(ctx: &Context, buf: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buf.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle()?;
    rx.recv()
        .map_err(|_| Error::Gpu("readback never completed".into()))?
        .map_err(|e| Error::Gpu(format!("mapping the readback buffer: {e}")))?;
    let out = buf
        .slice(..)
        .get_mapped_range()
        .map_err(|e| Error::Gpu(format!("{e:?}")))?
        .to_vec();
    buf.unmap();
    Ok(out)
}
