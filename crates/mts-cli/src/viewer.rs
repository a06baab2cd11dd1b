//! `mts view`: a window (winit) with an orbit camera around one model, the
//! demo layout ([`DemoScene`]) of an `InstancedScene`, the parts of a
//! glTF scene ([`GltfScene`]) in one, or a view-dependent hierarchy
//! ([`HierarchyRenderer`], its cut chosen again every frame and culled to
//! the view), drawn by the same renderer as everything else.
//!
//! Controls: drag with the left button (or the arrow keys) to orbit, `W`/`S`
//! to move closer or farther; the mouse wheel, `Up`/`Down` or `+`/`-`
//! change the LoD continuously (10% of the triangles per step); `A` toggles
//! the automatic mode, which picks the coarsest LoD whose error projects
//! within one pixel ([`mts::lod_for_screen_error`]); in a scene `F` flies
//! along the demo's path and back to orbiting; `Escape` quits. On a
//! hierarchy the wheel and keys change the pixel threshold of the cut
//! (10% per step; `A` goes back to one pixel), `W` comes as near as a
//! tenth of the bounding radius (down onto a terrain, up to a scan), and
//! `F` flies a circle low over the bounds, looking ahead and down. The
//! title shows triangles, indices sent, the last extraction's (or
//! hierarchy update's) microseconds and frames per second.

use crate::demo_scene::DemoScene;
use crate::gltf_scene::GltfScene;
use crate::stdout::warnln;
use glam::Vec3;
use mts::hierarchy::{Hierarchy, ViewDependent};
use mts::model::{Extractor, Prefix};
use mts::{Error, MtsModel, Result};
use mts_render::camera::Camera;
use mts_render::gpu::AdapterReport;
use mts_render::scene::DEFAULT_PIXEL_ERROR;
use mts_render::strip_renderer::{RendererConfig, StripRenderer};
use mts_render::{FrameStats, HierarchyRenderer, InstancedScene};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Depth format of the viewer's window.
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// LoD change per wheel notch or key press: this factor of the triangles.
const LOD_STEP: f64 = 1.1;
/// Seconds between title updates.
const TITLE_PERIOD: f64 = 0.5;
/// Seconds of one flight along the scene's path (`F`).
const FLIGHT_SECONDS: f32 = 40.0;
/// Nearest orbit distance in bounding radii: outside a model's sphere,
/// down to the surface of a hierarchy.
const NEAREST_ORBIT: f32 = 1.05;
const NEAREST_HIERARCHY_ORBIT: f32 = 0.1;

/// What the viewer shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewerContent {
    /// The model alone, with its properties (and the checker texture
    /// instead of its own when `checker` is set).
    Model {
        /// Show the checker texture.
        checker: bool,
    },
    /// `count` instances of it on a ground plane (with the checker
    /// texture when `checker` is set).
    Scene {
        /// Instances.
        count: usize,
        /// Show the checker texture.
        checker: bool,
    },
}

/// What a viewer session did, for a closing line.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewerReport {
    /// The adapter that drew.
    pub adapter: AdapterReport,
    /// Frames presented.
    pub frames: u64,
    /// Seconds from the first frame to the last.
    pub seconds: f64,
    /// The last window title (triangles, indices, extraction, fps).
    pub last_status: String,
}

/// Opens a window on `model` and runs until it is closed, or until
/// `max_frames` frames were presented when given (for scripted runs).
///
/// # Errors
/// [`Error::Gpu`] when no window, surface, adapter or device can be
/// created (no display, or no adapter that can present to it), and the
/// errors of [`StripRenderer::for_model`] and [`DemoScene::new`].
pub fn run(
    model: &MtsModel,
    others: &[&MtsModel],
    content: ViewerContent,
    title: &str,
    max_frames: Option<u64>,
) -> Result<ViewerReport> {
    let shown = Shown::Model {
        model,
        others,
        content,
    };
    run_app(shown, title, max_frames)
}

/// [`run`] on the parts of a glTF scene, each instance at the coarsest LoD
/// within [`DEFAULT_PIXEL_ERROR`], with the checker texture instead of
/// their own when `checker` is set.
///
/// # Errors
/// As [`run`], and those of [`GltfScene::scene`].
pub fn run_gltf(
    scene: &GltfScene,
    checker: bool,
    title: &str,
    max_frames: Option<u64>,
) -> Result<ViewerReport> {
    run_app(Shown::Gltf { scene, checker }, title, max_frames)
}

/// [`run`] on a view-dependent hierarchy: its cut for the camera within
/// [`DEFAULT_PIXEL_ERROR`] (or the threshold the wheel sets), culled to the
/// view, updated every frame ([`HierarchyRenderer::update`]), with the
/// checker texture instead of its own when `checker` is set.
///
/// # Errors
/// As [`run`], and those of [`HierarchyRenderer::with_appearance`].
pub fn run_hierarchy(
    h: &Hierarchy,
    checker: bool,
    title: &str,
    max_frames: Option<u64>,
) -> Result<ViewerReport> {
    run_app(Shown::Hierarchy { h, checker }, title, max_frames)
}

/// A file arriving: each prefix that opens more LoDs than the one shown,
/// then the whole model, as they arrive ([`run_streamed`]).
pub struct Arrivals {
    /// The prefixes, in order, opened on another thread.
    pub receiver: std::sync::mpsc::Receiver<Result<Prefix>>,
    /// The whole model's triangles at LoD 0 (shares are of these).
    pub full_triangles: usize,
    /// The file's bytes.
    pub file_bytes: u64,
}

/// What a streamed view shows now and receives next.
struct Stream {
    arrivals: Arrivals,
    checker: bool,
    first_lod: usize,
    bytes_used: usize,
    whole: bool,
}

/// [`run`] on a model as its file arrives: `first` (a prefix of the
/// file, [`MtsModel::from_prefix`]) is shown, then each prefix
/// `arrivals` delivers replaces it (new buffers, the same camera), until
/// the whole model. The manual share is of the whole model's triangles.
/// The models shown are kept until the process ends (the viewer's window
/// holds them by reference; a few coarse models and the whole one).
///
/// # Errors
/// As [`run`], and a prefix that fails to open.
pub fn run_streamed(
    first: Prefix,
    arrivals: Arrivals,
    checker: bool,
    title: &str,
    max_frames: Option<u64>,
) -> Result<ViewerReport> {
    let stream = Stream {
        arrivals,
        checker,
        first_lod: first.first_lod,
        bytes_used: first.bytes_used,
        whole: first.is_whole(),
    };
    let model: &'static MtsModel = Box::leak(Box::new(first.model));
    let shown = Shown::Model {
        model,
        others: &[],
        content: ViewerContent::Model { checker },
    };
    run_app_streamed(shown, title, max_frames, Some(stream))
}

fn run_app(shown: Shown<'_>, title: &str, max_frames: Option<u64>) -> Result<ViewerReport> {
    run_app_streamed(shown, title, max_frames, None)
}

fn run_app_streamed(
    shown: Shown<'_>,
    title: &str,
    max_frames: Option<u64>,
    stream: Option<Stream>,
) -> Result<ViewerReport> {
    let event_loop = EventLoop::new().map_err(|e| Error::Gpu(format!("no event loop: {e}")))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        shown,
        title: title.to_owned(),
        max_frames,
        state: None,
        error: None,
        stream,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::Gpu(format!("event loop: {e}")))?;
    if let Some(e) = app.error {
        return Err(e);
    }
    let state = app
        .state
        .ok_or_else(|| Error::Gpu("the window never opened".into()))?;
    Ok(ViewerReport {
        adapter: state.report,
        frames: state.total_frames,
        seconds: state.started.elapsed().as_secs_f64(),
        last_status: state.status,
    })
}

/// What the window shows, before it opens.
#[derive(Clone, Copy)]
enum Shown<'m> {
    Model {
        model: &'m MtsModel,
        /// More models of the scene (instances taken in turn with
        /// `model`).
        others: &'m [&'m MtsModel],
        content: ViewerContent,
    },
    Gltf {
        scene: &'m GltfScene,
        checker: bool,
    },
    Hierarchy {
        h: &'m Hierarchy,
        checker: bool,
    },
}

struct App<'m> {
    shown: Shown<'m>,
    title: String,
    max_frames: Option<u64>,
    state: Option<State<'m>>,
    error: Option<Error>,
    /// A streamed model's arrivals, until the window opens.
    stream: Option<Stream>,
}

/// Everything that exists once the window does.
struct State<'m> {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    depth: wgpu::TextureView,
    report: AdapterReport,
    drawn: Drawn<'m>,
    orbit: Orbit,
    /// Share of the triangles asked for in manual mode (0..1].
    ratio: f64,
    /// A hierarchy's pixel threshold in manual mode.
    pixel_error: f32,
    /// In a scene, when set: flying along the demo's path since then
    /// (`F` toggles), instead of orbiting.
    flying: Option<Instant>,
    auto: bool,
    dragging: bool,
    last_cursor: Option<(f64, f64)>,
    extract_us: f64,
    /// Frames since the last title update, and that update's time.
    frames: u32,
    since: Instant,
    total_frames: u64,
    started: Instant,
    /// What the title shows (kept here: not every platform reads it back).
    status: String,
    renderer_config: RendererConfig,
    /// A model shown as its file arrives.
    stream: Option<Stream>,
}

// One value per window, never moved around: the size difference is moot.
#[allow(clippy::large_enum_variant)]
enum Drawn<'m> {
    Model {
        renderer: StripRenderer,
        extractor: Extractor<'m>,
    },
    Scene(DemoScene<'m>),
    /// The parts of a glTF scene.
    Parts(InstancedScene<'m>),
    /// A hierarchy, its cut kept by `view`; `bounds` of its vertices.
    Hierarchy {
        renderer: HierarchyRenderer,
        view: ViewDependent<'m>,
        bounds: (Vec3, Vec3),
    },
}

/// The flight over a hierarchy at `t` (0..1): a circle around the
/// bounds' centre at about half their width, a tenth of `radius` above
/// their top, looking one radian ahead along the circle and down to
/// their middle height.
fn hierarchy_flight(bounds: (Vec3, Vec3), radius: f32, t: f32, aspect: f32) -> Camera {
    let (lo, hi) = bounds;
    let centre = (lo + hi) * 0.5;
    let ring = 0.55 * (hi.x - lo.x).max(hi.z - lo.z) * 0.5;
    let at = |a: f32| {
        let (s, c) = a.sin_cos();
        Vec3::new(centre.x + ring * c, 0.0, centre.z + ring * s)
    };
    let a = std::f32::consts::TAU * t;
    let eye = at(a) + Vec3::Y * (hi.y + 0.1 * radius);
    let target = at(a + 1.0) + Vec3::Y * centre.y;
    Camera::looking(eye, target, aspect, 1e-3 * radius, 3.0 * radius)
}

/// Orbit camera around `centre`: yaw and pitch in radians, distance in
/// bounding-sphere radii.
#[derive(Debug, Clone, Copy)]
struct Orbit {
    centre: Vec3,
    radius: f32,
    yaw: f32,
    pitch: f32,
    distance: f32,
}

impl Orbit {
    fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.centre + Vec3::new(cp * sy, sp, cp * cy) * self.distance * self.radius
    }

    fn camera(&self, aspect: f32) -> Camera {
        let d = self.distance * self.radius;
        Camera::looking(
            self.eye(),
            self.centre,
            aspect,
            (d - 1.5 * self.radius).max(d * 1e-3),
            d + 1.5 * self.radius,
        )
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match State::new(event_loop, self.shown, &self.title) {
            Ok(mut state) => {
                state.stream = self.stream.take();
                self.state = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(state) = &mut self.state else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => state.resize(size.width, size.height),
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                state.auto = false;
                state.step_lod(notches);
            }
            WindowEvent::MouseInput {
                state: pressed,
                button: MouseButton::Left,
                ..
            } => {
                state.dragging = pressed == ElementState::Pressed;
                state.last_cursor = None;
            }
            WindowEvent::CursorMoved { position, .. } if state.dragging => {
                if let Some((x, y)) = state.last_cursor {
                    state.orbit.yaw -= ((position.x - x) * 0.01) as f32;
                    state.orbit.pitch =
                        (state.orbit.pitch + ((position.y - y) * 0.01) as f32).clamp(-1.5, 1.5);
                }
                state.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Named(NamedKey::ArrowUp) | Key::Character("+") => {
                        state.auto = false;
                        state.step_lod(1.0);
                    }
                    Key::Named(NamedKey::ArrowDown) | Key::Character("-") => {
                        state.auto = false;
                        state.step_lod(-1.0);
                    }
                    Key::Named(NamedKey::ArrowLeft) => state.orbit.yaw += 0.1,
                    Key::Named(NamedKey::ArrowRight) => state.orbit.yaw -= 0.1,
                    Key::Character("a" | "A") => state.auto = !state.auto,
                    Key::Character("f" | "F")
                        if matches!(state.drawn, Drawn::Scene(_) | Drawn::Hierarchy { .. }) =>
                    {
                        state.flying = match state.flying {
                            Some(_) => None,
                            None => Some(Instant::now()),
                        };
                    }
                    Key::Character("w" | "W") => {
                        let nearest = if matches!(state.drawn, Drawn::Hierarchy { .. }) {
                            NEAREST_HIERARCHY_ORBIT
                        } else {
                            NEAREST_ORBIT
                        };
                        state.orbit.distance = (state.orbit.distance / 1.1).max(nearest);
                    }
                    Key::Character("s" | "S") => state.orbit.distance *= 1.1,
                    _ => {}
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = state.frame() {
                    self.error = Some(e);
                    event_loop.exit();
                }
                if self.max_frames.is_some_and(|m| state.total_frames >= m) {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }
}

impl<'m> State<'m> {
    fn new(event_loop: &ActiveEventLoop, shown: Shown<'m>, title: &str) -> Result<State<'m>> {
        let gpu = |what: &str, e: &dyn std::fmt::Display| Error::Gpu(format!("{what}: {e}"));
        let window = Arc::new(
            event_loop
                .create_window(Window::default_attributes().with_title(title))
                .map_err(|e| gpu("cannot open a window", &e))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| gpu("cannot create a surface", &e))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..wgpu::RequestAdapterOptions::default()
        }))
        .map_err(|e| gpu("no adapter for this window", &e))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("mts viewer"),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..wgpu::DeviceDescriptor::default()
        }))
        .map_err(|e| gpu("cannot create a device", &e))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| Error::Gpu("the surface does not suit the adapter".into()))?;
        if let Some(&srgb) = surface
            .get_capabilities(&adapter)
            .formats
            .iter()
            .find(|f| f.is_srgb())
        {
            config.format = srgb;
        }
        surface.configure(&device, &config);
        let report = AdapterReport::from_info(&adapter.get_info());
        let renderer_config = RendererConfig {
            color_format: config.format,
            depth_format: Some(DEPTH_FORMAT),
            strip_mode: report.strip_mode,
        };
        let (drawn, centre, radius) = match shown {
            Shown::Hierarchy { h, checker } => {
                let appearance = mts_render::Appearance { checker };
                let renderer = HierarchyRenderer::with_appearance(
                    &device,
                    &queue,
                    &renderer_config,
                    h,
                    &appearance,
                )?;
                for w in renderer.warnings() {
                    warnln!("{w}");
                }
                let (lo, hi) = mts::mesh::bounds_of(h.positions()).unwrap_or_default();
                let drawn = Drawn::Hierarchy {
                    renderer,
                    view: ViewDependent::new(h),
                    bounds: (lo, hi),
                };
                (drawn, (lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6))
            }
            Shown::Gltf { scene, checker } => {
                let appearance = mts_render::Appearance { checker };
                let (parts, _) = scene.scene(&device, &queue, &renderer_config, &appearance)?;
                let (lo, hi) = scene.bounds();
                let radius = ((hi - lo).length() * 0.5).max(1e-6);
                (Drawn::Parts(parts), (lo + hi) * 0.5, radius)
            }
            Shown::Model {
                model,
                content: ViewerContent::Model { checker },
                ..
            } => {
                let appearance = mts_render::texture::Appearance { checker };
                let renderer = StripRenderer::for_model_with(
                    &device,
                    &queue,
                    &renderer_config,
                    model,
                    &appearance,
                )?;
                for w in renderer.warnings() {
                    warnln!("{w}");
                }
                let (lo, hi) = mts::mesh::bounds_of(model.positions()).unwrap_or_default();
                let drawn = Drawn::Model {
                    renderer,
                    extractor: Extractor::new(model),
                };
                (drawn, (lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6))
            }
            Shown::Model {
                model,
                others,
                content: ViewerContent::Scene { count, checker },
            } => {
                // Stitched on backends that ignore primitive restart.
                let scene = DemoScene::new(
                    &device,
                    &queue,
                    &renderer_config,
                    &std::iter::once(model)
                        .chain(others.iter().copied())
                        .collect::<Vec<_>>(),
                    count,
                    &mts_render::Appearance { checker },
                )?;
                let (lo, hi) = scene
                    .instances
                    .iter()
                    .filter_map(|&i| scene.scene.bounds_of(i))
                    .fold(
                        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                        |(lo, hi), (c, _)| (lo.min(c), hi.max(c)),
                    );
                let radius = ((hi - lo).length() * 0.5).max(1e-6);
                (Drawn::Scene(scene), (lo + hi) * 0.5, radius)
            }
        };
        let depth = depth_view(&device, config.width, config.height);
        Ok(State {
            window,
            surface,
            device,
            queue,
            config,
            depth,
            report,
            drawn,
            orbit: Orbit {
                centre,
                radius,
                yaw: 0.55,
                pitch: 0.35,
                distance: 3.0,
            },
            ratio: 1.0,
            pixel_error: DEFAULT_PIXEL_ERROR,
            flying: None,
            auto: !matches!(
                shown,
                Shown::Model {
                    content: ViewerContent::Model { .. },
                    ..
                }
            ),
            dragging: false,
            last_cursor: None,
            extract_us: 0.0,
            frames: 0,
            since: Instant::now(),
            total_frames: 0,
            started: Instant::now(),
            status: String::new(),
            renderer_config,
            stream: None,
        })
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&self.device, &self.config);
        self.depth = depth_view(&self.device, width, height);
    }

    /// Changes the manual LoD by `notches` steps (positive: finer): a
    /// share of the triangles, or a hierarchy's pixel threshold (from
    /// where the automatic mode left it).
    fn step_lod(&mut self, notches: f64) {
        self.ratio = (self.ratio * LOD_STEP.powf(notches)).clamp(1e-4, 1.0);
        let step = LOD_STEP.powf(-notches) as f32;
        self.pixel_error = (self.pixel_error * step).clamp(0.05, 1000.0);
    }

    /// The pixel threshold of a hierarchy's cut now.
    fn hierarchy_pixel_error(&self) -> f32 {
        if self.auto {
            DEFAULT_PIXEL_ERROR
        } else {
            self.pixel_error
        }
    }

    /// Triangles and indices drawn by a scene's update (started at
    /// `started`), which is timed as an extraction when a LoD changed; a
    /// failed update draws nothing this frame, with a warning.
    fn scene_counts(&mut self, stats: Result<FrameStats>, started: Instant) -> (usize, usize) {
        let stats = stats.unwrap_or_else(|e| {
            warnln!("scene update: {e}");
            FrameStats::default()
        });
        if stats.lod_changes > 0 {
            self.extract_us = started.elapsed().as_secs_f64() * 1e6;
        }
        (stats.triangles, stats.indices_drawn)
    }

    /// Shows the next prefix of a streamed file when one has arrived.
    fn take_arrival(&mut self) -> Result<()> {
        let Some(stream) = &mut self.stream else {
            return Ok(());
        };
        let Ok(arrived) = stream.arrivals.receiver.try_recv() else {
            return Ok(());
        };
        let prefix = arrived?;
        stream.first_lod = prefix.first_lod;
        stream.bytes_used = prefix.bytes_used;
        stream.whole = prefix.is_whole();
        let model: &'static MtsModel = Box::leak(Box::new(prefix.model));
        let appearance = mts_render::texture::Appearance {
            checker: stream.checker,
        };
        let renderer = StripRenderer::for_model_with(
            &self.device,
            &self.queue,
            &self.renderer_config,
            model,
            &appearance,
        )?;
        self.drawn = Drawn::Model {
            renderer,
            extractor: Extractor::new(model),
        };
        Ok(())
    }

    fn frame(&mut self) -> Result<()> {
        self.take_arrival()?;
        let (w, h) = (self.config.width, self.config.height);
        let aspect = w as f32 / h as f32;
        let camera = match (&self.drawn, self.flying) {
            (Drawn::Scene(scene), Some(since)) => {
                let t = (since.elapsed().as_secs_f32() / FLIGHT_SECONDS).fract();
                scene.path_camera(t, aspect)
            }
            (Drawn::Hierarchy { bounds, .. }, Some(since)) => {
                let t = (since.elapsed().as_secs_f32() / FLIGHT_SECONDS).fract();
                hierarchy_flight(*bounds, self.orbit.radius, t, aspect)
            }
            _ => self.orbit.camera(aspect),
        };
        let pixel_error = self.hierarchy_pixel_error();
        let t = Instant::now();
        let (triangles, indices) = match &mut self.drawn {
            Drawn::Hierarchy { renderer, view, .. } => {
                // Every frame: the cut follows the camera, culled to it.
                let frame = renderer.update(
                    &self.device,
                    &self.queue,
                    view,
                    &camera,
                    h as f32,
                    pixel_error,
                    true,
                )?;
                self.extract_us = t.elapsed().as_secs_f64() * 1e6;
                (frame.triangles, frame.indices_sent)
            }
            Drawn::Model {
                renderer,
                extractor,
            } => {
                let model = extractor.model();
                let lod = if self.auto {
                    // The model's nearest point is about one bounding
                    // radius nearer than the orbit's centre.
                    let nearest = (self.orbit.distance - 1.0).max(0.0) * self.orbit.radius;
                    mts::lod_for_screen_error(
                        model.collapses(),
                        2.0 * self.orbit.radius,
                        1.0,
                        camera.projection(h as f32).pixels_per_unit(nearest),
                        DEFAULT_PIXEL_ERROR,
                    )
                } else if let Some(stream) = &self.stream {
                    let full = stream.arrivals.full_triangles as f64;
                    model.lod_for_triangles((self.ratio * full).round() as usize)
                } else {
                    model.lod_for_ratio(self.ratio)
                };
                if extractor.lod() != Some(lod) {
                    extractor.set_lod(lod);
                    renderer.update_strips(&self.device, &self.queue, extractor)?;
                    self.extract_us = t.elapsed().as_secs_f64() * 1e6;
                }
                renderer.set_camera(&self.queue, &camera);
                (model.triangle_count(lod), extractor.indices_sent())
            }
            Drawn::Scene(scene) => {
                let stats = scene.update(
                    &self.device,
                    &self.queue,
                    &camera,
                    h as f32,
                    DEFAULT_PIXEL_ERROR,
                );
                self.scene_counts(stats, t)
            }
            Drawn::Parts(scene) => {
                let stats = scene.update(
                    &self.device,
                    &self.queue,
                    &camera,
                    h as f32,
                    DEFAULT_PIXEL_ERROR,
                );
                self.scene_counts(stats, t)
            }
        };
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let mut pass = mts_render::headless::begin_cleared_pass(
                &mut encoder,
                "mts viewer",
                &view,
                &self.depth,
            );
            match &self.drawn {
                Drawn::Model { renderer, .. } => renderer.draw(&mut pass),
                Drawn::Scene(scene) => scene.draw(&mut pass),
                Drawn::Parts(scene) => scene.draw(&mut pass),
                Drawn::Hierarchy { renderer, .. } => renderer.draw(&mut pass),
            }
        }
        self.queue.submit([encoder.finish()]);
        self.queue.present(frame);
        self.frames += 1;
        self.total_frames += 1;
        let elapsed = self.since.elapsed().as_secs_f64();
        if elapsed >= TITLE_PERIOD {
            let fps = f64::from(self.frames) / elapsed;
            let (note, work) = match &self.drawn {
                Drawn::Hierarchy { .. } => (
                    format!(
                        " (cut within {pixel_error:.2} px{})",
                        if self.auto { ", auto" } else { "" }
                    ),
                    "update",
                ),
                _ if self.auto => (" (auto)".to_owned(), "extraction"),
                _ => (String::new(), "extraction"),
            };
            let arrived = match &self.stream {
                Some(s) if s.whole => format!(", whole file of {} bytes", s.arrivals.file_bytes),
                Some(s) => format!(
                    ", first {} of {} bytes: LoDs {}..",
                    s.bytes_used, s.arrivals.file_bytes, s.first_lod
                ),
                None => String::new(),
            };
            self.status = format!(
                "mts view: {triangles} triangles{note}, {indices} indices sent, {work} {:.0} us, \
                 {fps:.0} fps ({}, {:?}){arrived}",
                self.extract_us, self.report.name, self.report.backend
            );
            self.window.set_title(&self.status);
            self.frames = 0;
            self.since = Instant::now();
        }
        Ok(())
    }
}

fn depth_view(device: &wgpu::Device, width: u32, height: u32) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("mts viewer depth"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flight over a terrain's bounds stays above them, inside their
    /// width, and looks ahead and down at ground it can see.
    #[test]
    fn the_hierarchy_flight_looks_down_at_the_bounds() {
        let bounds = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.3, 1.0));
        let radius = (bounds.1 - bounds.0).length() * 0.5;
        for i in 0..16 {
            let t = i as f32 / 16.0;
            let camera = hierarchy_flight(bounds, radius, t, 1.5);
            let eye = mts_render::hierarchy::camera_eye(camera.view_proj);
            assert!(eye.y > bounds.1.y, "{t}: {eye}");
            assert!(eye.x.abs() < 1.0 && eye.z.abs() < 1.0, "{t}: {eye}");
            // The middle of the view is ground below the eye.
            let ahead = camera
                .view_proj
                .inverse()
                .project_point3(Vec3::new(0.0, 0.0, 0.5));
            assert!(ahead.y < eye.y, "{t}: looks up to {ahead}");
        }
    }
}
