//! Adapter discovery and device creation (issue 3, SPEC 7 `talus info`).
//!
//! talus uses wgpu's Vulkan backend (what lavapipe, Mesa's software driver used in CI,
//! and the NVIDIA/AMD/Intel drivers of Linux workstations share: the tested one), and
//! where they exist Metal (macOS) and DX12 (Windows without a Vulkan driver), compiled
//! in on those systems only and not tested by this project's machines yet.

use std::fmt::Write as _;

/// Which path a run uses (`--backend`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendChoice {
    /// A GPU adapter when one exists, else the CPU path with a notice.
    Auto,
    Cpu,
    Gpu,
}

/// Storage buffers bound at once by the largest pipeline layout: the spring table and
/// `shaders/common.wgsl`'s bindings, and for `plan_rebuild` the indirect dispatch
/// arguments (`kernels::GROUP2_STORAGE`).
pub const STORAGE_BUFFERS_NEEDED: u32 = super::kernels::GROUP0_STORAGE
    + super::kernels::GROUP1_STORAGE
    + super::kernels::GROUP2_STORAGE;
/// Every buffer bound at once by the largest kernel: the storage buffers and the uniform
/// Params.
pub const BUFFERS_NEEDED: u32 = STORAGE_BUFFERS_NEEDED + 1;

/// The variable that sets [`wait_limit`], in seconds.
pub const WAIT_LIMIT_VAR: &str = "TALUS_GPU_TIMEOUT";

/// How long one wait for the device may take: `TALUS_GPU_TIMEOUT` seconds, by default
/// 300 (a submission of 64 steps of the largest scene lavapipe holds takes about 30 s
/// there; on a hardware GPU milliseconds). A value that is not a positive number of
/// seconds is ignored with the default.
pub fn wait_limit() -> std::time::Duration {
    wait_limit_from(std::env::var(WAIT_LIMIT_VAR).ok().as_deref())
}

/// [`wait_limit`] from the variable's value.
fn wait_limit_from(value: Option<&str>) -> std::time::Duration {
    let seconds = value
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| *s > 0.0 && *s < 1e9)
        .unwrap_or(300.0);
    std::time::Duration::from_secs_f64(seconds)
}

#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    #[error(
        "no GPU adapter found (talus needs a Vulkan, Metal or DX12 driver; on a Linux \
         machine without a GPU, install Mesa's software driver: apt-get install \
         mesa-vulkan-drivers libvulkan1)"
    )]
    NoAdapter,
    #[error("the GPU adapter {name} cannot run talus: {reason}")]
    Unsuitable { name: String, reason: String },
    #[error("could not open the GPU device {name}: {reason}")]
    Open { name: String, reason: String },
    #[error("the scene is too large for the GPU adapter {name}: {reason}")]
    TooLarge { name: String, reason: String },
}

/// The backends talus asks wgpu for (each compiled in only where it applies).
const BACKENDS: wgpu::Backends = wgpu::Backends::VULKAN
    .union(wgpu::Backends::METAL)
    .union(wgpu::Backends::DX12);

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = BACKENDS;
    // wgpu checks every indirect dispatch's arguments against the limits with a compute
    // pass of its own, one more dispatch and barrier per indirect dispatch. talus's only
    // indirect arguments are the rebuild stages' (shaders/plan.wgsl): the host's own
    // workgroup counts, checked against the limits at the upload, or zero.
    desc.flags
        .remove(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL);
    wgpu::Instance::new(desc)
}

/// All adapters of those backends.
pub fn adapters() -> Vec<wgpu::Adapter> {
    pollster::block_on(instance().enumerate_adapters(BACKENDS))
}

/// Why an adapter cannot be used, if it cannot.
fn unsuitable(adapter: &wgpu::Adapter) -> Option<String> {
    let l = adapter.limits();
    if l.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_NEEDED {
        return Some(format!(
            "it allows {} storage buffers per shader stage, talus needs {}",
            l.max_storage_buffers_per_shader_stage, STORAGE_BUFFERS_NEEDED
        ));
    }
    if l.max_buffers_and_acceleration_structures_per_shader_stage < BUFFERS_NEEDED {
        return Some(format!(
            "it allows {} buffers per shader stage, talus needs {}",
            l.max_buffers_and_acceleration_structures_per_shader_stage, BUFFERS_NEEDED
        ));
    }
    None
}

/// Preference order: a discrete GPU, then an integrated one, then anything else (a
/// software rasteriser such as lavapipe last).
fn rank(info: &wgpu::AdapterInfo) -> u32 {
    match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// The adapter a GPU run would use: the best-ranked suitable one.
pub fn choose_adapter() -> Result<wgpu::Adapter, DeviceError> {
    let all = adapters();
    if all.is_empty() {
        return Err(DeviceError::NoAdapter);
    }
    let mut usable: Vec<_> = all.iter().filter(|a| unsuitable(a).is_none()).collect();
    usable.sort_by_key(|a| rank(&a.get_info()));
    match usable.first() {
        Some(a) => Ok((*a).clone()),
        None => {
            let a = &all[0];
            Err(DeviceError::Unsuitable {
                name: a.get_info().name,
                reason: unsuitable(a).unwrap_or_default(),
            })
        }
    }
}

/// An open device with the limits talus asked for.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// The first error the device reported (lost, out of memory, a failed readback):
    /// wgpu's default handler would panic; talus notes it here and the run stops with it
    /// at its next check (`GpuSimulation::failure`; issue 16 item 8).
    pub failure: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// Timestamp queries inside compute passes were granted (`GpuSimulation::profile`).
    pub timestamps: bool,
}

impl Gpu {
    pub fn open() -> Result<Self, DeviceError> {
        let adapter = choose_adapter()?;
        let info = adapter.get_info();
        let have = adapter.limits();
        // Ask for the adapter's own buffer and dispatch limits: scenes of 10⁵–10⁶
        // particles need more than WebGPU's defaults.
        let limits = wgpu::Limits {
            max_storage_buffers_per_shader_stage: STORAGE_BUFFERS_NEEDED,
            max_buffers_and_acceleration_structures_per_shader_stage: BUFFERS_NEEDED,
            max_storage_buffer_binding_size: have.max_storage_buffer_binding_size,
            max_buffer_size: have.max_buffer_size,
            max_compute_workgroups_per_dimension: have.max_compute_workgroups_per_dimension,
            ..wgpu::Limits::downlevel_defaults()
        };
        // Timestamps between kernels (`talus bench --kernels`), where the adapter has them.
        let timing =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES;
        let timestamps = adapter.features().contains(timing);
        let desc = wgpu::DeviceDescriptor {
            label: Some("talus"),
            required_features: if timestamps {
                timing
            } else {
                wgpu::Features::empty()
            },
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&desc)).map_err(|e| DeviceError::Open {
                name: info.name.clone(),
                reason: e.to_string(),
            })?;
        let failure: std::sync::Arc<std::sync::Mutex<Option<String>>> = Default::default();
        let slot = failure.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            note(&slot, e.to_string())
        }));
        let slot = failure.clone();
        device.set_device_lost_callback(move |why, message| {
            note(&slot, format!("the device was lost ({why:?}): {message}"))
        });
        Ok(Self {
            device,
            queue,
            info,
            limits,
            failure,
            timestamps,
        })
    }

    /// Notes a failure of the device (the first one is kept).
    pub fn note_failure(&self, reason: String) {
        note(&self.failure, reason)
    }

    /// Waits until `submission` (None: everything submitted) is done, at most
    /// [`wait_limit`]: a hung device stops the run with this error instead of hanging it
    /// (issue 38).
    pub fn wait(&self, submission: Option<wgpu::SubmissionIndex>) -> Result<(), String> {
        let limit = wait_limit();
        let polled = self.device.poll(wgpu::PollType::Wait {
            submission_index: submission,
            timeout: Some(limit),
        });
        match polled {
            Ok(_) => Ok(()),
            Err(wgpu::PollError::Timeout) => Err(format!(
                "the device did not finish its work within {} s (set {WAIT_LIMIT_VAR} to wait \
                 longer): it may be hung",
                limit.as_secs_f64()
            )),
            Err(e) => Err(format!("the device was lost: {e}")),
        }
    }

    /// The first failure the device reported, if any.
    pub fn failure(&self) -> Option<String> {
        self.failure
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }

    /// The most bytes one buffer may hold and be bound.
    pub fn binding_limit(&self) -> u64 {
        binding_limit(&self.limits)
    }
}

/// The most bytes one buffer may hold and be bound under `limits`.
pub fn binding_limit(limits: &wgpu::Limits) -> u64 {
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
}

/// Whether tests must fail, rather than skip, when no adapter exists (CI sets it).
pub fn gpu_required() -> bool {
    std::env::var("TALUS_REQUIRE_GPU").is_ok_and(|v| v == "1")
}

/// The report printed by `talus info`.
pub fn describe() -> String {
    let mut s = String::new();
    let all = adapters();
    if all.is_empty() {
        let _ = writeln!(s, "GPU adapters (Vulkan, Metal, DX12): none found");
    } else {
        let _ = writeln!(s, "GPU adapters (Vulkan, Metal, DX12):");
    }
    for a in &all {
        let i = a.get_info();
        let l = a.limits();
        let _ = writeln!(s, "  - {} ({:?}, {:?})", i.name, i.backend, i.device_type);
        let _ = writeln!(s, "      driver: {} {}", i.driver, i.driver_info);
        let _ = writeln!(
            s,
            "      limits used: storage buffers per stage {}, storage binding {} MiB, \
             buffer {} MiB, workgroups per dimension {}",
            l.max_storage_buffers_per_shader_stage,
            l.max_storage_buffer_binding_size >> 20,
            l.max_buffer_size >> 20,
            l.max_compute_workgroups_per_dimension
        );
        let timing =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES;
        let _ = writeln!(
            s,
            "      features used: core WebGPU compute (f32, u32 atomics){}",
            if a.features().contains(timing) {
                "; timestamps inside passes (`talus bench --kernels`)"
            } else {
                "; no timestamps inside passes (`talus bench --kernels` unavailable)"
            }
        );
        let binding = binding_limit(&l);
        let largest: Vec<String> = (crate::gpu::footprint::largest_scenes(binding).iter())
            .map(|(what, n)| format!("{n} {what}"))
            .collect();
        let _ = writeln!(
            s,
            "      largest scene the GPU path holds here: {}",
            largest.join(", ")
        );
        if let Some(why) = unsuitable(a) {
            let _ = writeln!(s, "      unsuitable: {why}");
        }
    }
    let _ = match choose_adapter() {
        Ok(a) if a.get_info().device_type == wgpu::DeviceType::Cpu => writeln!(
            s,
            "--backend gpu would run on: {} (a software adapter)\n--backend auto would run on \
             the CPU reference path, which is faster than a software adapter",
            a.get_info().name
        ),
        Ok(a) => writeln!(
            s,
            "--backend auto or gpu would run on: {}",
            a.get_info().name
        ),
        Err(e) => writeln!(
            s,
            "--backend auto would run on the CPU reference path ({e});\n--backend gpu would fail"
        ),
    };
    s
}

fn note(slot: &std::sync::Mutex<Option<String>>, reason: String) {
    slot.lock()
        .unwrap_or_else(|p| p.into_inner())
        .get_or_insert(reason);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wait_limit_is_a_positive_number_of_seconds_or_the_default() {
        let secs = |v| wait_limit_from(v).as_secs_f64();
        assert_eq!(secs(None), 300.0);
        assert_eq!(secs(Some(" 60 ")), 60.0);
        assert_eq!(secs(Some("0.5")), 0.5);
        for bad in ["0", "-3", "inf", "NaN", "a minute", ""] {
            assert_eq!(secs(Some(bad)), 300.0, "{bad:?}");
        }
    }
}
