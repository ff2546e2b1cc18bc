//! How long submissions take on the device, learnt without waiting for it: GPU timestamps
//! around a compute pass, resolved and copied into a [`ReadbackRing`] that a later frame
//! reads; on a device without timestamp queries, the time from the submission to the host's
//! first sight of its completion (`Queue::on_submitted_work_done`, whose callbacks run when
//! the device is polled), which is an upper bound.

use super::readback::ReadbackRing;
use super::Context;
use crate::error::Result;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Submissions that can be timed at once (with every one in flight, a submission goes
/// untimed).
const IN_FLIGHT: usize = 3;
/// Bytes between the slots of the resolve buffer (wgpu's resolve alignment).
const RESOLVE_STRIDE: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;

/// The timestamp queries: two per ring slot (the pass's start and end), resolved into one
/// buffer and copied from it into the ring.
struct Timestamps {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    ring: ReadbackRing,
    /// Nanoseconds per timestamp tick.
    period: f64,
}

/// A submission timed by its completion callback.
struct Observed {
    work: u64,
    submitted: Instant,
    done: Arc<Mutex<Option<Instant>>>,
}

/// The device time per unit of work of the newest submission measured, and its work, read a
/// frame or more after the submission: [`GpuTimer::pass_writes`] for the timed compute pass,
/// [`GpuTimer::resolve`] after it in the same encoder, [`GpuTimer::submitted`] after the
/// submission, [`GpuTimer::seconds_per_unit`] at a later frame.
pub(crate) struct GpuTimer {
    timestamps: Option<Timestamps>,
    observed: VecDeque<Observed>,
    /// The ring slot the encoder being recorded writes.
    recording: Option<usize>,
    /// The newest measurement: seconds per unit, units.
    latest: Option<(f64, u64)>,
    /// The measurements' running mean (seconds per unit; each new one weighs a quarter).
    mean: Option<f64>,
}

impl GpuTimer {
    /// Timestamps when the device has them (`DeviceInfo::timestamps`), else completion
    /// callbacks.
    pub(crate) fn new(ctx: &Context, timestamps: bool) -> GpuTimer {
        let timestamps = timestamps.then(|| Timestamps {
            queries: ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("submission timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * IN_FLIGHT as u32,
            }),
            resolve: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("resolved timestamps"),
                size: RESOLVE_STRIDE * IN_FLIGHT as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            ring: ReadbackRing::new(ctx, "timestamps readback", 16, IN_FLIGHT),
            period: ctx.queue.get_timestamp_period() as f64,
        });
        GpuTimer {
            timestamps,
            observed: VecDeque::new(),
            recording: None,
            latest: None,
            mean: None,
        }
    }

    /// The timestamp writes of the compute pass to time (None without timestamps, or with
    /// every slot in flight).
    pub(crate) fn pass_writes(&mut self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let ts = self.timestamps.as_mut()?;
        let slot = ts.ring.record()?;
        self.recording = Some(slot);
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &ts.queries,
            beginning_of_pass_write_index: Some(2 * slot as u32),
            end_of_pass_write_index: Some(2 * slot as u32 + 1),
        })
    }

    /// After the timed pass, in its encoder: the timestamps into the ring.
    pub(crate) fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        let (Some(ts), Some(slot)) = (self.timestamps.as_ref(), self.recording) else {
            return;
        };
        let at = RESOLVE_STRIDE * slot as u64;
        let first = 2 * slot as u32;
        enc.resolve_query_set(&ts.queries, first..first + 2, &ts.resolve, at);
        enc.copy_buffer_to_buffer(&ts.resolve, at, ts.ring.buffer(slot), 0, 16);
    }

    /// After the submission: it did `work` units (what [`GpuTimer::seconds_per_unit`]
    /// divides by).
    pub(crate) fn submitted(&mut self, ctx: &Context, work: u64) {
        match self.timestamps.as_mut() {
            Some(ts) => {
                if let Some(slot) = self.recording.take() {
                    ts.ring.submitted(slot, work);
                }
            }
            None => {
                if self.observed.len() == IN_FLIGHT {
                    return;
                }
                let done = Arc::new(Mutex::new(None));
                let seen = done.clone();
                ctx.queue.on_submitted_work_done(move || {
                    if let Ok(mut d) = seen.lock() {
                        *d = Some(Instant::now());
                    }
                });
                self.observed.push_back(Observed {
                    work,
                    submitted: Instant::now(),
                    done,
                });
            }
        }
    }

    /// Device seconds per unit of work that a budget should plan with, and the units of the
    /// newest timed submission that has come back (polling the device, never waiting), or
    /// of the one before if none has since; None before any. The rate is the newest
    /// measurement's or the running mean's, whichever is slower: one measurement that came
    /// out fast (lavapipe's vary by a factor of two from frame to frame) would otherwise
    /// send the next frames over their budget.
    pub(crate) fn seconds_per_unit(&mut self, ctx: &Context) -> Result<Option<(f64, u64)>> {
        ctx.poll("reading the device's timestamps")?;
        let rate = |seconds: f64, work: u64| (work > 0).then(|| (seconds / work as f64, work));
        let mut measured = Vec::new();
        match self.timestamps.as_mut() {
            Some(ts) => {
                if let Some((work, bytes)) = ts.ring.take_latest() {
                    let t: &[u64] = bytemuck::cast_slice(&bytes);
                    let ticks = t[1].saturating_sub(t[0]) as f64;
                    measured.extend(rate(ticks * ts.period * 1e-9, work));
                }
            }
            None => {
                while let Some(o) = self.observed.front() {
                    let done = *o.done.lock().unwrap_or_else(|e| e.into_inner());
                    let Some(done) = done else { break };
                    let seconds = done.duration_since(o.submitted).as_secs_f64();
                    measured.extend(rate(seconds, o.work));
                    self.observed.pop_front();
                }
            }
        }
        for (r, work) in measured {
            self.mean = Some(self.mean.map_or(r, |m| m + 0.25 * (r - m)));
            self.latest = Some((r, work));
        }
        Ok(self
            .latest
            .map(|(r, work)| (r.max(self.mean.unwrap_or(r)), work)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ways of timing measure a submission without waiting for it: after a wait
    /// (callbacks run), the next frame's reading has a positive time per unit.
    #[test]
    fn timers_measure_submissions_one_frame_late() {
        let Ok(ctx) = Context::new() else {
            eprintln!("no adapter: skipped");
            return;
        };
        let kinds = [true, false]
            .into_iter()
            .filter(|&t| !t || ctx.info.timestamps);
        for timestamps in kinds {
            let mut timer = GpuTimer::new(&ctx, timestamps);
            assert_eq!(timer.seconds_per_unit(&ctx).unwrap(), None);
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            let writes = timer.pass_writes();
            assert_eq!(writes.is_some(), timestamps);
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: writes,
            });
            timer.resolve(&mut enc);
            ctx.submit([enc.finish()]);
            timer.submitted(&ctx, 4);
            ctx.wait_idle().unwrap();
            let rate = timer.seconds_per_unit(&ctx).unwrap();
            println!("timestamps {timestamps}: {rate:?} s per unit");
            assert!(
                rate.is_some_and(|(r, work)| r >= 0.0 && r.is_finite() && work == 4),
                "{rate:?}"
            );
        }
    }
}
