//! Headless device selection: a hardware adapter when one exists, else the software Vulkan
//! driver (Mesa's lavapipe), else a typed error that says how to install one.

use std::fmt;

use super::pass_timer::PassTimer;

/// Where the frames are computed: the adapter wgpu chose and why.
#[derive(Clone, Debug, PartialEq)]
pub struct AdapterReport {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    /// True when the adapter is a CPU (software) rasterizer such as lavapipe.
    pub is_software: bool,
}

impl AdapterReport {
    pub fn of(info: &wgpu::AdapterInfo) -> Self {
        Self {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
            is_software: info.device_type == wgpu::DeviceType::Cpu,
        }
    }
}

impl fmt::Display for AdapterReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}, {}, driver {})",
            self.name, self.backend, self.device_type, self.driver
        )
    }
}

#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    #[error(
        "no GPU adapter found (looked at: {looked_at}); install a Vulkan driver — on a machine \
         without a GPU, Mesa's software driver lavapipe: `apt-get install mesa-vulkan-drivers \
         libvulkan1` (Debian/Ubuntu) or `dnf install mesa-vulkan-drivers` (Fedora)"
    )]
    NoAdapter { looked_at: String },
    #[error("adapter {adapter} refused a device: {source}")]
    RequestDevice {
        adapter: String,
        #[source]
        source: wgpu::RequestDeviceError,
    },
}

/// A device and queue with the features the passes use: one the runtime requested
/// ([`Self::new_headless`], [`Self::for_adapter`]: the one place it asks for a device), or one a
/// host application made and lends ([`Self::from_device`]).
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub report: AdapterReport,
    /// `Rgba32Float` can be a blended render target (else the passes use `Rgba16Float`).
    pub float32_blendable: bool,
    /// `Rgba32Float` / `R32Float` textures can be sampled with linear filtering (an exported
    /// LUT in float, `bake --export ktx2 --export-format float`).
    pub float32_filterable: bool,
    /// GPU time per pass, on adapters with timestamp queries.
    pub pass_timer: Option<PassTimer>,
    /// Whether a timed section may wait for the GPU to finish its work (the headless commands
    /// measure each pass that way). A host's device never waits inside a frame: its sections
    /// record only the CPU time of encoding.
    pub waits_to_time: bool,
}

impl GpuContext {
    /// A headless device: hardware first (discrete, integrated, virtual), the software
    /// rasterizer last.
    pub fn new_headless() -> Result<Self, DeviceError> {
        pollster::block_on(Self::new_headless_async(None))
    }

    /// [`Self::new_headless`] held to `limits` instead of the adapter's own: what a browser
    /// grants a page (`wgpu::Limits::default()` is WebGPU's), on this machine's device.
    pub fn new_headless_limited(limits: wgpu::Limits) -> Result<Self, DeviceError> {
        pollster::block_on(Self::new_headless_async(Some(limits)))
    }

    async fn new_headless_async(limits: Option<wgpu::Limits>) -> Result<Self, DeviceError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        // Vulkan, Metal, DX12: every pass needs compute and storage buffers, which the GL
        // backend lacks. WGPU_BACKEND overrides.
        desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let instance = wgpu::Instance::new(desc);
        let adapter = Self::preferred_adapter(&instance).await?;
        Self::for_adapter(adapter, limits).await
    }

    /// The adapter [`Self::new_headless`] would choose on `instance`: hardware first (discrete,
    /// integrated, virtual), the software rasterizer last. An application that presents to a
    /// window asks on the instance its surface comes from, then [`Self::for_adapter`].
    pub async fn preferred_adapter(
        instance: &wgpu::Instance,
    ) -> Result<wgpu::Adapter, DeviceError> {
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        let looked_at = if adapters.is_empty() {
            "no Vulkan, Metal or DX12 adapters".to_string()
        } else {
            adapters
                .iter()
                .map(|a| a.get_info().name)
                .collect::<Vec<_>>()
                .join(", ")
        };
        let adapter = match adapters
            .into_iter()
            .min_by_key(|a| preference_rank(a.get_info().device_type))
        {
            Some(a) => a,
            None => instance
                .request_adapter(&wgpu::RequestAdapterOptions {
                    force_fallback_adapter: true,
                    ..Default::default()
                })
                .await
                .map_err(|_| DeviceError::NoAdapter { looked_at })?,
        };
        Ok(adapter)
    }

    /// A device on `adapter` with the features the passes use: `limits` (a web page asks for
    /// WebGPU's defaults), or the adapter's own. Timestamps are read back by blocking, which a
    /// browser cannot do: there the passes go untimed.
    pub async fn for_adapter(
        adapter: wgpu::Adapter,
        limits: Option<wgpu::Limits>,
    ) -> Result<Self, DeviceError> {
        let report = AdapterReport::of(&adapter.get_info());
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("strandlight"),
                required_features: Self::wanted_features(adapter.features()),
                required_limits: limits.unwrap_or_else(|| adapter.limits()),
                ..Default::default()
            })
            .await
            .map_err(|source| DeviceError::RequestDevice {
                adapter: report.to_string(),
                source,
            })?;
        let pass_timer = PassTimer::new(&device, &queue);
        Ok(Self {
            pass_timer,
            waits_to_time: true,
            ..Self::from_device(device, queue)
        }
        .with_report(report))
    }

    /// The features the passes use where `offered` has them: blendable and filterable f32
    /// targets, and timestamps outside a browser (which cannot wait to read them).
    pub fn wanted_features(offered: wgpu::Features) -> wgpu::Features {
        let mut wanted = wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::FLOAT32_FILTERABLE;
        if !cfg!(target_arch = "wasm32") {
            wanted |= wgpu::Features::TIMESTAMP_QUERY;
        }
        offered & wanted
    }

    /// A context on a device a host application created: the runtime requests no device of its
    /// own and never waits for the GPU inside a frame (its passes go untimed). It uses what the
    /// device was created with; ask for [`Self::wanted_features`] of the adapter to get f32
    /// render targets and filtering, else the passes fall back to f16.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let features = device.features();
        Self {
            report: AdapterReport::of(&device.adapter_info()),
            float32_blendable: features.contains(wgpu::Features::FLOAT32_BLENDABLE),
            float32_filterable: features.contains(wgpu::Features::FLOAT32_FILTERABLE),
            pass_timer: None,
            waits_to_time: false,
            device,
            queue,
        }
    }

    fn with_report(self, report: AdapterReport) -> Self {
        Self { report, ..self }
    }

    /// The HDR colour format of render targets.
    pub fn hdr_format(&self) -> wgpu::TextureFormat {
        if self.float32_blendable {
            wgpu::TextureFormat::Rgba32Float
        } else {
            wgpu::TextureFormat::Rgba16Float
        }
    }

    /// Blocks until all submitted work has finished.
    pub fn wait_idle(&self) {
        // A lost device surfaces as an error in the following map/readback; nothing to do here.
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// Lower is preferred: hardware first, the CPU rasterizer last.
fn preference_rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CI installs lavapipe, so a missing adapter is a broken install: fail, with the hint.
    #[test]
    fn a_headless_device_exists() {
        let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "adapter: {} (software: {}, Rgba32Float blendable: {})",
            gpu.report, gpu.report.is_software, gpu.float32_blendable
        );
        assert!(!gpu.report.name.is_empty());
    }

    #[test]
    fn hardware_is_preferred_over_the_software_rasterizer() {
        assert!(
            preference_rank(wgpu::DeviceType::DiscreteGpu) < preference_rank(wgpu::DeviceType::Cpu)
        );
        assert!(
            preference_rank(wgpu::DeviceType::IntegratedGpu)
                < preference_rank(wgpu::DeviceType::Cpu)
        );
    }

    #[test]
    fn the_no_adapter_error_says_how_to_install_lavapipe() {
        let text = DeviceError::NoAdapter {
            looked_at: "no Vulkan adapters".into(),
        }
        .to_string();
        assert!(text.contains("mesa-vulkan-drivers"), "{text}");
    }
}
