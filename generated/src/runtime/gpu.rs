//! A headless wgpu device chosen from the environment, for tests, tools and examples.
//!
//! - `WGPU_BACKEND` (comma list: `vulkan`, `metal`, `dx12`, ...) restricts the backends
//!   (`wgpu::InstanceDescriptor::with_env`, i.e. `Backends::from_env`); CI sets `vulkan` to
//!   run on Mesa's lavapipe (see `scripts/setup-vulkan`).
//! - `WGPU_ADAPTER_NAME` picks an adapter by name substring, `WGPU_POWER_PREF` (`low`/`high`)
//!   the preference otherwise (`wgpu::util::initialize_adapter_from_env_or_default`).
//!
//! This crate enables wgpu's native backends only (Vulkan, Metal, DX12), not GLES or WebGPU.

use std::fmt;

/// Instance, adapter, device and queue of a headless wgpu context.
#[derive(Debug, Clone)]
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

/// Why no device could be made.
#[derive(Debug)]
pub enum GpuError {
    /// No adapter for the enabled backends (`WGPU_BACKEND`): no GPU, no driver, no ICD.
    NoAdapter(wgpu::RequestAdapterError),
    /// An adapter was found but refused the device.
    Device(wgpu::RequestDeviceError),
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let backends = std::env::var("WGPU_BACKEND").unwrap_or_else(|_| "all".into());
        match self {
            GpuError::NoAdapter(e) => write!(f, "no wgpu adapter (WGPU_BACKEND={backends}): {e}"),
            GpuError::Device(e) => write!(f, "wgpu adapter refused a device: {e}"),
        }
    }
}

impl std::error::Error for GpuError {}

/// A wgpu instance for the backends named by `WGPU_BACKEND` (all enabled ones if unset), with
/// the other `WGPU_*` instance settings from the environment too.
pub fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Adapter (from the environment, see the module documentation) and a device with default
/// limits and no optional features.
pub async fn headless(label: &str) -> Result<Gpu, GpuError> {
    headless_with(label, wgpu::Features::empty()).await
}

/// [`headless`], with those of the `optional` features the adapter offers (e.g.
/// `TIMESTAMP_QUERY` for GPU-side timing, `FLOAT32_FILTERABLE` for a linear sampler on a 32-bit
/// float LUT): `device.features()` says which were granted (one the adapter lacks is left out, not an error).
pub async fn headless_with(label: &str, optional: wgpu::Features) -> Result<Gpu, GpuError> {
    let instance = instance();
    let adapter = wgpu::util::initialize_adapter_from_env_or_default(&instance, None)
        .await
        .map_err(GpuError::NoAdapter)?;
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some(label),
            required_features: optional & adapter.features(),
            required_limits: wgpu::Limits::default().using_resolution(adapter.limits()),
            ..Default::default()
        })
        .await
        .map_err(GpuError::Device)?;
    Ok(Gpu { instance, adapter, device, queue })
}

/// One line about an adapter: name, backend, device type, driver and driver version.
pub fn describe(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?}, {:?}, driver {} {})",
        info.name,
        info.backend,
        info.device_type,
        if info.driver.is_empty() { "?" } else { &info.driver },
        info.driver_info
    )
}

/// A storage-buffer binding of a compute shader (read-only or read-write).
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute pipeline running `entry` of `module` with one bind group laid out as `entries`;
/// returns the group's layout (to create the bind group) and the pipeline.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> (wgpu::BindGroupLayout, wgpu::ComputePipeline) {
    let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&bgl)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    (bgl, pipeline)
}

/// Run `pipeline` with `bind_group` over `workgroups` × 1 × 1 workgroups, copy `output` into
/// `readback` (both of the size [`output_and_readback`] made them) and return its bytes.
pub fn dispatch_and_read(
    g: &Gpu,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    bind_group: &wgpu::BindGroup,
    workgroups: u32,
    output: &wgpu::Buffer,
    readback: &wgpu::Buffer,
) -> Vec<u8> {
    let mut encoder = g.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(workgroups, 1, 1);
    }
    encoder.copy_buffer_to_buffer(output, 0, readback, 0, output.size());
    g.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.slice(..).map_async(wgpu::MapMode::Read, move |r| tx.send(r).expect("the receiver waits"));
    g.device.poll(wgpu::PollType::wait_indefinitely()).expect("device poll");
    rx.recv().expect("the map callback ran").expect("map the readback buffer");
    let bytes = readback.slice(..).get_mapped_range().expect("mapped range").to_vec();
    readback.unmap();
    bytes
}

/// A storage buffer a shader writes `size` bytes to, and the mappable buffer to copy it into.
pub fn output_and_readback(device: &wgpu::Device, size: u64) -> (wgpu::Buffer, wgpu::Buffer) {
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("outputs"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (output, readback)
}
