//! `run_wgsl_fn`: runs single WGSL functions of `shaders/` on the device, one thread per
//! input, so that tests can hold them against their Rust twins on random inputs (issue
//! 14 item 7).

use talus::gpu::layout::Params;
use wgpu::util::DeviceExt;

pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
pub const POSITION: &str = include_str!("../../shaders/position.wgsl");
pub const ORIENTATION: &str = include_str!("../../shaders/orientation.wgsl");
pub const LAWS: &str = include_str!("../../shaders/laws.wgsl");

/// Runs `body` once per item of `input` (`n_in` words of four u32 per item) after the
/// WGSL `parts` (e.g. common.wgsl and laws.wgsl), with `params` bound as the kernels'
/// uniform, and returns `n_out` words per item. In `body`, `k` is the item,
/// `wgsl_arg(k, m)` its m-th input word and `wgsl_put(k, m, v)` writes its m-th output
/// word; floats travel as their bits (`bitcast`). None when there is no adapter (and
/// the GPU is not required).
pub fn run_wgsl_fn(
    test: &str,
    parts: &[&str],
    params: &Params,
    (n_in, n_out): (usize, usize),
    body: &str,
    input: &[[u32; 4]],
) -> Option<Vec<[u32; 4]>> {
    assert_eq!(input.len() % n_in, 0, "whole items");
    let items = input.len() / n_in;
    let gpu = super::gpu(test)?;
    // The kernels' bindings, as every module declares them (src/gpu/bindings.rs).
    let mut source = parts.join("\n") + &talus::gpu::bindings::declarations("wgsl_fn", |_| true);
    // The harness's buffers go in group 1 beside the spring table, at bindings no kernel
    // uses; the layout is derived from what the entry point uses.
    source += &format!(
        "
@group(1) @binding(100) var<storage, read> wgsl_in: array<vec4<u32>>;
@group(1) @binding(101) var<storage, read_write> wgsl_out: array<vec4<u32>>;
const WGSL_N_IN: u32 = {n_in}u;
const WGSL_N_OUT: u32 = {n_out}u;
fn wgsl_arg(k: u32, m: u32) -> vec4<u32> {{ return wgsl_in[k * WGSL_N_IN + m]; }}
fn wgsl_put(k: u32, m: u32, v: vec4<u32>) {{ wgsl_out[k * WGSL_N_OUT + m] = v; }}
@compute @workgroup_size(64)
fn wgsl_main(@builtin(global_invocation_id) gid: vec3<u32>) {{
    let k = gid.x;
    if (k >= arrayLength(&wgsl_in) / WGSL_N_IN) {{ return; }}
    _ = params.dt;
    {body}
}}
"
    );
    let dev = &gpu.device;
    let module = dev.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(test),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = dev.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(test),
        layout: None,
        module: &module,
        entry_point: Some("wgsl_main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let uniform = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("params"),
        contents: bytemuck::bytes_of(params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let input_buf = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("wgsl_in"),
        contents: bytemuck::cast_slice(input),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (items * n_out * 16) as u64;
    let output = dev.create_buffer(&wgpu::BufferDescriptor {
        label: Some("wgsl_out"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = dev.create_buffer(&wgpu::BufferDescriptor {
        label: Some("staging"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group0 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let group1 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 100,
                resource: input_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 101,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut enc = dev.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group0, &[]);
        pass.set_bind_group(1, &group1, &[]);
        pass.dispatch_workgroups((items as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &staging, 0, bytes);
    gpu.queue.submit([enc.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    dev.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let view = staging.slice(..).get_mapped_range().expect("mapped");
    Some(bytemuck::cast_slice(&view).to_vec())
}

/// Four f32 as the words `run_wgsl_fn` takes.
pub fn word(v: [f64; 4]) -> [u32; 4] {
    v.map(|x| (x as f32).to_bits())
}

/// A word back as four f32 (in f64).
pub fn floats(w: [u32; 4]) -> [f64; 4] {
    w.map(|x| f32::from_bits(x) as f64)
}
