//! Adapter and device: chosen through wgpu's environment conventions, with the adapter's own
//! storage-buffer limits (a scene's BVH can exceed the 128 MiB default binding) and its timestamp
//! queries where it has them.

use super::GpuError;

/// Which timestamps the device can take (none, around compute passes only, or anywhere in a
/// command encoder, which also times the copies).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Timestamps {
    /// No timestamp queries: kernel and transfer times are unknown.
    None,
    /// At the start and end of compute passes: the kernel's time.
    Pass,
    /// Anywhere in an encoder: the upload copy, the kernel and the readback copy.
    Encoder,
}

/// A device, its queue and the bind group layout of the casting kernels.
pub(super) struct Gpu {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) pipeline_layout: wgpu::PipelineLayout,
    pub(super) layout: wgpu::BindGroupLayout,
    /// The timestamps this device takes.
    pub(super) timestamps: Timestamps,
    /// Nanoseconds per timestamp tick.
    pub(super) timestamp_period_ns: f64,
    /// Largest storage binding, bytes.
    pub(super) max_binding_bytes: u64,
    /// Adapter name, backend and type.
    pub(super) description: String,
    /// The first error the device reported outside a call's results (out of memory, a validation
    /// error, the device lost), if any: every result since may be wrong.
    pub(super) fault: std::sync::Arc<std::sync::Mutex<Option<String>>>,
}

impl Gpu {
    /// Records `message` as the device's fault unless one is recorded already.
    pub(super) fn record_fault(fault: &std::sync::Mutex<Option<String>>, message: String) {
        let mut f = fault.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        f.get_or_insert(message);
    }

    /// The device's fault, if any (see [`Gpu::fault`]).
    pub(super) fn fault(&self) -> Option<String> {
        self.fault.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone()
    }
}

/// The process's one wgpu instance, made on first use and never dropped.
///
/// Dropping the last instance unloads the Vulkan loader and with it the driver (`dlclose`); on
/// NVIDIA's driver a thread of its own can still be running then, and the process crashed at exit
/// (SIGSEGV after its output was complete, about one run in ten on an H200 with driver 580: the
/// crashing thread's code was unmapped while the main thread was in `munmap`; see also
/// gfx-rs/wgpu#8365). A static is never dropped, so the driver stays loaded until the process ends.
fn instance() -> &'static wgpu::Instance {
    static INSTANCE: std::sync::OnceLock<wgpu::Instance> = std::sync::OnceLock::new();
    INSTANCE.get_or_init(|| wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env()))
}

/// The adapter wgpu's environment variables choose: `WGPU_ADAPTER_NAME` (a case-insensitive
/// substring of the name) among the adapters of `WGPU_BACKEND`, else the default request.
fn adapter() -> Result<wgpu::Adapter, GpuError> {
    let instance = instance();
    if let Ok(name) = std::env::var("WGPU_ADAPTER_NAME") {
        let want = name.to_lowercase();
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
        let all = pollster::block_on(instance.enumerate_adapters(backends));
        let names: Vec<String> = all.iter().map(|a| a.get_info().name).collect();
        return all
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&want))
            .ok_or_else(|| GpuError::NoAdapter(format!("WGPU_ADAPTER_NAME `{name}` matches none of {names:?}")));
    }
    let options = wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::from_env().unwrap_or(wgpu::PowerPreference::HighPerformance),
        ..Default::default()
    };
    pollster::block_on(instance.request_adapter(&options)).map_err(|e| GpuError::NoAdapter(e.to_string()))
}

/// "name (backend, device type)" of the adapter wgpu's environment variables choose.
pub fn adapter_description() -> Result<String, GpuError> {
    Ok(describe(&adapter()?.get_info()))
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}

impl Gpu {
    /// Opens the device (with timestamp queries where the adapter has them); the shader and its
    /// pipelines are made per scene ([`super::scene::SceneBuffers`]), whose BVH layout picks the
    /// traversal and whose split into bindings sets its constants.
    pub(super) fn new() -> Result<Self, GpuError> {
        let adapter = adapter()?;
        let info = adapter.get_info();
        let description = describe(&info);
        let limits = adapter.limits();
        let has = adapter.features();
        let timestamps =
            if has.contains(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS) {
                Timestamps::Encoder
            } else if has.contains(wgpu::Features::TIMESTAMP_QUERY) {
                Timestamps::Pass
            } else {
                Timestamps::None
            };
        let required_features = match timestamps {
            Timestamps::Encoder => wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
            Timestamps::Pass => wgpu::Features::TIMESTAMP_QUERY,
            Timestamps::None => wgpu::Features::empty(),
        };
        let desc = wgpu::DeviceDescriptor {
            label: Some("groundtruth caster"),
            required_limits: limits.clone(),
            required_features,
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(|e| GpuError::Device { adapter: info.name.clone(), reason: e.to_string() })?;
        let storage = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("caster"),
            entries: &[
                storage(0, true),
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, true),
                storage(5, true),
                storage(6, true),
                storage(7, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 8,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("caster"),
            bind_group_layouts: &[Some(&layout)],
            ..Default::default()
        });
        // Errors are recorded, not panics (wgpu's default): the caster reports them to its caller.
        let fault = std::sync::Arc::new(std::sync::Mutex::new(None));
        let name = info.name.clone();
        let on_error = std::sync::Arc::clone(&fault);
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            let kind = match &e {
                wgpu::Error::OutOfMemory { .. } => "ran out of memory",
                _ => "reported an error",
            };
            Self::record_fault(&on_error, format!("the GPU `{name}` {kind}: {e}"));
        }));
        let (name, on_lost) = (info.name.clone(), std::sync::Arc::clone(&fault));
        device.set_device_lost_callback(move |reason, message| {
            Self::record_fault(&on_lost, format!("the GPU `{name}` was lost ({reason:?}): {message}"));
        });
        let max_binding_bytes = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let timestamp_period_ns = f64::from(queue.get_timestamp_period());
        Ok(Self {
            device,
            queue,
            pipeline_layout,
            layout,
            timestamps,
            timestamp_period_ns,
            max_binding_bytes,
            description,
            fault,
        })
    }
}
