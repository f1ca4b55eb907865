//! Device time per kernel (`talus bench --kernels`, issue 14): a timestamp written after
//! every dispatch of a run of steps, and at the start of each batch's pass. A dispatch is
//! charged the time from the timestamp before it to its own, so what the device spends
//! between kernels (barriers, launching an empty indirect dispatch) is counted too, and
//! the kernels' times add up to the whole run on the device.
//!
//! Needs the adapter's timestamp queries inside compute passes (NVIDIA, AMD, Intel and
//! lavapipe under Vulkan have them; `Gpu::timestamps`); without them `profile` says so.

use super::*;
use std::collections::BTreeMap;

/// Timestamps one profiled run may write at most (wgpu's limit per query set).
const MAX_QUERIES: u32 = 4096;

/// The marks of a profiled run: its query set, and for each timestamp written the
/// kernel dispatched just before it (`None`: a pass starts).
pub(super) struct Recorder {
    set: wgpu::QuerySet,
    marks: Vec<Option<Kernel>>,
}

/// What a kernel cost in a profiled run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct KernelTime {
    /// The kernel (`Kernel`'s name: `ContactForcesOnly` is `contact_forces` without
    /// the outputs).
    pub kernel: String,
    pub dispatches_per_step: f64,
    /// Device time per step, from the timestamp before each of its dispatches to the
    /// one after.
    pub microseconds_per_step: f64,
}

/// The kernels of a profiled run, the costliest first.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct KernelTimes {
    pub steps: u64,
    /// Device time per step, all kernels together.
    pub microseconds_per_step: f64,
    pub kernels: Vec<KernelTime>,
}

impl GpuSimulation {
    /// Whether the adapter can time single kernels (`profile`).
    pub fn can_profile(&self) -> bool {
        self.gpu.timestamps
    }

    /// Advances `steps` steps (as `advance` does) with a timestamp after every dispatch,
    /// and returns each kernel's device time. `steps` is capped so that the timestamps
    /// fit one query set (about 200 steps).
    pub fn profile(&mut self, steps: u64) -> Result<KernelTimes, GpuError> {
        if !self.can_profile() {
            return Err(GpuError::Profile(format!(
                "{} has no timestamp queries inside compute passes",
                self.gpu.info.name
            )));
        }
        // Each step dispatches at most ~20 kernels, and each batch starts a pass.
        let per_step = (REBUILD_STAGES.len() + 8) as u64;
        let steps = steps.clamp(1, MAX_QUERIES as u64 / (per_step + 1));
        let set = self.gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("kernel times"),
            ty: wgpu::QueryType::Timestamp,
            count: MAX_QUERIES,
        });
        *self.recorder.borrow_mut() = Some(Recorder {
            set,
            marks: Vec::new(),
        });
        let advanced = self.advance(steps);
        let recorder = self.recorder.borrow_mut().take().expect("the recorder");
        advanced.map_err(|e| GpuError::Profile(format!("the profiled steps stopped: {e}")))?;
        let stamps = self.read_timestamps(&recorder)?;
        Ok(kernel_times(&recorder.marks, &stamps, steps))
    }

    /// Writes a timestamp at the start of a pass, when profiling.
    pub(super) fn mark_start(&self, pass: &mut wgpu::ComputePass) {
        self.mark(pass, None);
    }

    /// Writes a timestamp after kernel k's dispatch, when profiling.
    pub(super) fn mark_kernel(&self, pass: &mut wgpu::ComputePass, k: Kernel) {
        self.mark(pass, Some(k));
    }

    fn mark(&self, pass: &mut wgpu::ComputePass, k: Option<Kernel>) {
        if let Some(r) = self.recorder.borrow_mut().as_mut() {
            let index = r.marks.len() as u32;
            assert!(
                index < MAX_QUERIES,
                "more timestamps than one query set holds"
            );
            pass.write_timestamp(&r.set, index);
            r.marks.push(k);
        }
    }

    /// The timestamps written, in nanoseconds.
    fn read_timestamps(&self, r: &Recorder) -> Result<Vec<f64>, GpuError> {
        let n = r.marks.len() as u32;
        let bytes = n as u64 * 8;
        let resolved = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(&r.set, 0..n, &resolved, 0);
        self.gpu.queue.submit([enc.finish()]);
        let words: Vec<u64> = self.read_buffer(&resolved, 0, n as usize);
        if let Some(e) = self.failure() {
            return Err(e);
        }
        let period = self.gpu.queue.get_timestamp_period() as f64;
        Ok(words.iter().map(|&t| t as f64 * period).collect())
    }
}

/// Each kernel's share of the run: a dispatch takes the time since the timestamp before
/// it (a pass start begins the count afresh).
pub fn kernel_times(marks: &[Option<Kernel>], stamps_ns: &[f64], steps: u64) -> KernelTimes {
    let mut by_kernel: BTreeMap<String, (u64, f64)> = BTreeMap::new();
    for (w, m) in marks.windows(2).zip(stamps_ns.windows(2)) {
        if let Some(k) = w[1] {
            let e = by_kernel.entry(format!("{k:?}")).or_default();
            e.0 += 1;
            // Timestamps of some drivers may step back by a tick between kernels.
            e.1 += (m[1] - m[0]).max(0.0);
        }
    }
    let per = |x: f64| x / steps as f64;
    let mut kernels: Vec<KernelTime> = (by_kernel.into_iter())
        .map(|(kernel, (count, ns))| KernelTime {
            kernel,
            dispatches_per_step: per(count as f64),
            microseconds_per_step: per(ns) * 1e-3,
        })
        .collect();
    kernels.sort_by(|a, b| b.microseconds_per_step.total_cmp(&a.microseconds_per_step));
    KernelTimes {
        steps,
        microseconds_per_step: kernels.iter().map(|k| k.microseconds_per_step).sum(),
        kernels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dispatch_is_charged_the_time_since_the_mark_before_it() {
        let (p, c) = (Kernel::Predict, Kernel::Correct);
        // Two passes: the gap between them (20 → 100) is no kernel's.
        let marks = [None, Some(p), Some(c), None, Some(p), Some(c)];
        let stamps = [0.0, 3000.0, 10000.0, 100000.0, 102000.0, 110000.0];
        let t = kernel_times(&marks, &stamps, 2);
        assert_eq!(t.kernels[0].kernel, "Correct");
        assert_eq!(t.kernels[0].microseconds_per_step, 7.5);
        assert_eq!(t.kernels[1].kernel, "Predict");
        assert_eq!(t.kernels[1].microseconds_per_step, 2.5);
        assert_eq!(t.kernels[1].dispatches_per_step, 1.0);
        assert_eq!(t.microseconds_per_step, 10.0);
    }
}
