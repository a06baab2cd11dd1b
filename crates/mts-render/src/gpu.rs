//! Instance, adapter and device for headless rendering, and the adapter
//! report: which adapter and backend draw, and how strips reach them.
//!
//! The instance honours wgpu's environment variables (`WGPU_BACKEND`,
//! `WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF`), so `WGPU_BACKEND=gl` exercises
//! the stitched path on a machine whose Vulkan driver handles restart.

use mts::{Error, Result};
use std::fmt;

/// How strip index buffers reach the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StripMode {
    /// Runs joined by the restart value (`u32::MAX` or `u16::MAX`) and drawn
    /// with primitive restart: what the extractor emits, uploaded as is, so
    /// a LoD change uploads only its dirty ranges.
    Restart,
    /// Runs stitched into one with degenerate triangles (no restart values),
    /// for backends that ignore primitive restart. The active part of the
    /// buffer is re-encoded and uploaded whole on every change.
    Stitched,
}

impl StripMode {
    /// The mode that draws correctly on `backend`: [`StripMode::Stitched`]
    /// on GL (wgpu's GL backend ignores primitive restart), else
    /// [`StripMode::Restart`].
    #[must_use]
    pub fn for_backend(backend: wgpu::Backend) -> StripMode {
        if backend == wgpu::Backend::Gl {
            StripMode::Stitched
        } else {
            StripMode::Restart
        }
    }
}

impl fmt::Display for StripMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StripMode::Restart => "primitive restart",
            StripMode::Stitched => "degenerate stitching",
        })
    }
}

/// What draws: the adapter, its backend and the strip mode chosen for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdapterReport {
    /// The adapter's name, e.g. `llvmpipe (LLVM 19.1.7, 256 bits)`.
    pub name: String,
    /// The backend (Vulkan, GL, ...).
    pub backend: wgpu::Backend,
    /// Discrete, integrated, CPU (lavapipe), ...
    pub device_type: wgpu::DeviceType,
    /// Driver name and version, as the driver reports them (may be empty).
    pub driver: String,
    /// How strips are drawn on this adapter.
    pub strip_mode: StripMode,
}

impl AdapterReport {
    /// The report for an adapter described by `info`, with the strip mode
    /// [`StripMode::for_backend`] chooses.
    #[must_use]
    pub fn from_info(info: &wgpu::AdapterInfo) -> AdapterReport {
        let driver = [info.driver.as_str(), info.driver_info.as_str()]
            .iter()
            .filter(|s| !s.is_empty())
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        AdapterReport {
            name: info.name.clone(),
            backend: info.backend,
            device_type: info.device_type,
            driver,
            strip_mode: StripMode::for_backend(info.backend),
        }
    }
}

impl fmt::Display for AdapterReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({:?}, {:?}{}), strips by {}",
            self.name,
            self.backend,
            self.device_type,
            if self.driver.is_empty() {
                String::new()
            } else {
                format!(", {}", self.driver)
            },
            self.strip_mode
        )
    }
}

/// An adapter with its device and queue, for headless rendering (tests, the
/// `mts render` command, benches). Embedders with their own device use
/// [`crate::StripRenderer`] directly instead.
#[derive(Debug)]
pub struct Gpu {
    /// The instance the adapter came from.
    pub instance: wgpu::Instance,
    /// The adapter chosen.
    pub adapter: wgpu::Adapter,
    /// Its device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

impl Gpu {
    /// Opens the adapter that `WGPU_ADAPTER_NAME` names, or wgpu's default
    /// one (any backend `WGPU_BACKEND` allows; no surface), and a device with
    /// the downlevel default limits raised to the adapter's texture sizes,
    /// and the pipeline-statistics and timestamp queries where offered.
    ///
    /// # Errors
    /// [`Error::NoAdapter`] when no adapter exists (no GPU and no software
    /// Vulkan driver), [`Error::Gpu`] when the device cannot be created.
    ///
    /// Cost: blocks while the driver starts (tens of milliseconds on
    /// lavapipe, more on first use).
    pub fn new_headless() -> Result<Gpu> {
        Gpu::open(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
    }

    /// [`Gpu::new_headless`] restricted to `backends` (e.g.
    /// `wgpu::Backends::GL` to exercise the stitched path), whatever
    /// `WGPU_BACKEND` says.
    ///
    /// # Errors
    /// As [`Gpu::new_headless`].
    pub fn new_headless_on(backends: wgpu::Backends) -> Result<Gpu> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        descriptor.backends = backends;
        Gpu::open(descriptor)
    }

    fn open(descriptor: wgpu::InstanceDescriptor) -> Result<Gpu> {
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            &instance, None,
        ))
        .map_err(|e| Error::NoAdapter(e.to_string()))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("mts headless device"),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            // Only what the adapter has: `crate::stats` reads a missing
            // query as "not offered", never as a number.
            required_features: adapter.features()
                & (wgpu::Features::PIPELINE_STATISTICS_QUERY | wgpu::Features::TIMESTAMP_QUERY),
            ..wgpu::DeviceDescriptor::default()
        }))
        .map_err(|e| Error::Gpu(format!("cannot create a device: {e}")))?;
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
        })
    }

    /// The report on this adapter (strip mode chosen for its backend).
    #[must_use]
    pub fn report(&self) -> AdapterReport {
        AdapterReport::from_info(&self.adapter.get_info())
    }
}
