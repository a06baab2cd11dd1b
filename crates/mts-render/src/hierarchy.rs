//! [`HierarchyRenderer`]: a view-dependent [`Hierarchy`] drawn as one
//! strip-restart draw of its [`ViewDependent`] arena, kept up to date
//! camera after camera by writing only what changed.
//!
//! **Vertices.** The hierarchy's input vertices are uploaded once, with
//! their properties and texture, by a [`StripRenderer`]
//! ([`StripRenderer::with_properties`]: the one vertex layout, shader and
//! pipelines of every other draw; normals from the input's triangles, the
//! level-0 clusters', where the properties have none). Every cut indexes
//! them, so a LoD change never touches the vertex buffer.
//!
//! **Indices.** The renderer keeps its own index buffer mirroring
//! [`ViewDependent::buffer`] (input vertex numbers, slots padded with
//! restarts). On the restart path an update writes the arena's dirty
//! ranges and, when the arena grew past what the buffer mirrored, the new
//! tail (the arena's contract: what lies past the old length is restarts
//! except where dirty, so the separators of slots appended at the end are
//! not in the dirty ranges), sorted and merged across gaps of at most
//! [`MERGE_GAP`] indices; the draw reads the arena's whole length. The
//! buffer grows to 1.5 times what is needed when the arena outgrows it
//! (then the arena is written whole) and never shrinks. On the stitched
//! path (GL, which ignores primitive restart) the arena is re-encoded
//! without restarts ([`stitch_restart_buffer`]) and written whole at
//! every update.
//!
//! **Camera.** [`HierarchyRenderer::update`] reads the eye from the
//! camera's view-projection matrix ([`camera_eye`]) and, when culling, the
//! frustum ([`Frustum::from_view_projection`]); the cut does not depend on
//! culling, so culling cannot open a crack in what is seen.

use crate::camera::Camera;
use crate::gpu::StripMode;
use crate::strip_renderer::{check_size, write_index_range, RendererConfig, StripRenderer, Upload};
use crate::texture::Appearance;
use glam::{DMat3, DVec3, Mat4, Vec3};
use mts::hierarchy::{FrameUpdate, Frustum, Hierarchy, View, ViewDependent, NO_GROUP};
use mts::strip::encode::stitch_restart_buffer;
use mts::{Error, Result};
use std::ops::Range;

/// Unchanged indices between two ranges to write that are written with
/// them (one `write_buffer` instead of two).
pub const MERGE_GAP: usize = 32;

/// What one [`HierarchyRenderer::update`] did, and what is drawn now.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HierarchyFrame {
    /// What the [`ViewDependent`] update did (groups and clusters drawn,
    /// entered, left, strips walked, indices written into the arena).
    pub update: FrameUpdate,
    /// Triangles drawn (culled groups and clusters left out).
    pub triangles: usize,
    /// Indices of the drawn strips without the arena's padding
    /// ([`ViewDependent::indices_sent`]).
    pub indices_sent: usize,
    /// Indices the draw makes the GPU read: the whole arena, padding and
    /// restarts included (restart path), or the stitched strips.
    pub indices_drawn: usize,
    /// What this update wrote to the index buffer.
    pub upload: Upload,
    /// GPU bytes of the vertex and index buffers.
    pub gpu_bytes: usize,
    /// CPU bytes of the [`ViewDependent`] ([`ViewDependent::memory_bytes`]).
    pub cpu_bytes: usize,
}

/// The eye of a view-projection matrix, world units: the point whose clip
/// `x`, `y` and `w` are 0 (solved in `f64`). An orthographic matrix (clip
/// `w` constant) has its eye at infinity: the centre of its near plane is
/// returned instead (its pixels per unit do not depend on the distance).
///
/// Cost: O(1).
#[must_use]
pub fn camera_eye(view_proj: Mat4) -> Vec3 {
    let m = view_proj.as_dmat4();
    let (r0, r1, r3) = (m.row(0), m.row(1), m.row(3));
    if r3.truncate() != DVec3::ZERO {
        let a = DMat3::from_cols(r0.truncate(), r1.truncate(), r3.truncate()).transpose();
        let det = a.determinant();
        if det != 0.0 && det.is_finite() {
            let eye = a.inverse() * -DVec3::new(r0.w, r1.w, r3.w);
            if eye.is_finite() {
                return eye.as_vec3();
            }
        }
    }
    view_proj.inverse().project_point3(Vec3::ZERO)
}

/// The [`View`] a [`ViewDependent`] update takes for `camera` on a
/// viewport `viewport_height` pixels high: its projection
/// ([`Camera::projection`]), its eye ([`camera_eye`]), the threshold, and
/// its frustum when `cull` is set.
#[must_use]
pub fn camera_view(
    camera: &Camera,
    viewport_height: f32,
    pixel_threshold: f32,
    cull: bool,
) -> View {
    View {
        projection: camera.projection(viewport_height),
        eye: camera_eye(camera.view_proj),
        pixel_threshold,
        frustum: cull.then(|| Frustum::from_view_projection(camera.view_proj)),
    }
}

/// [`camera_view`] for an instance of a hierarchy placed at `transform`
/// (model to world): the eye and the frustum in model space, and the
/// threshold scaled by the transform's smallest over largest axis scale,
/// so that a non-uniform scale cannot push an error past the threshold (a
/// rotation, translation and uniform scale keep the threshold: errors and
/// distances scale alike). `None` when `transform` is not invertible.
#[must_use]
pub fn instance_view(
    camera: &Camera,
    transform: Mat4,
    viewport_height: f32,
    pixel_threshold: f32,
    cull: bool,
) -> Option<View> {
    let inverse = transform.inverse();
    let scales =
        [transform.x_axis, transform.y_axis, transform.z_axis].map(|c| c.truncate().length());
    let (lo, hi) = scales.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &s| {
        (lo.min(s), hi.max(s))
    });
    if !(inverse.is_finite() && lo > 0.0 && hi.is_finite()) {
        return None;
    }
    let eye = inverse.transform_point3(camera_eye(camera.view_proj));
    let model_view_proj = camera.view_proj * transform;
    Some(View {
        projection: camera.projection(viewport_height),
        eye,
        pixel_threshold: pixel_threshold * (lo / hi),
        frustum: cull.then(|| Frustum::from_view_projection(model_view_proj)),
    })
}

/// A renderer over `h`'s input vertices (see the module docs): its
/// properties and texture as `appearance` asks, normals from the level-0
/// clusters' triangles where the properties have none.
pub(crate) fn vertex_renderer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    config: &RendererConfig,
    h: &Hierarchy,
    appearance: &Appearance,
) -> Result<StripRenderer> {
    let properties = h.properties();
    let has_normals = properties
        .normals
        .as_ref()
        .is_some_and(|n| !n.contains(&Vec3::ZERO));
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    if !has_normals {
        triangles.reserve(h.triangle_count());
        for (c, cluster) in h.clusters().iter().enumerate() {
            if cluster.producer == NO_GROUP {
                triangles.extend(h.cluster_triangles(c));
            }
        }
    }
    StripRenderer::with_properties(
        device,
        queue,
        config,
        h.positions(),
        &triangles,
        properties,
        appearance,
    )
}

/// Room for `len` indices in a buffer: an even count (4-byte aligned
/// `u16` writes), never empty.
fn room(len: usize) -> usize {
    ((len + 1) & !1).max(2)
}

/// An index buffer mirroring a [`ViewDependent`] arena (see the module
/// docs): [`HierarchyRenderer`]'s, and one per hierarchy instance of
/// [`crate::InstancedScene`].
///
/// Invariants: `buffer` holds `capacity` indices (even) when present; on
/// the restart path, `mirrored == Some(n)` means its first `n` indices
/// equal the arena as last written.
#[derive(Debug, Default)]
pub(crate) struct ArenaIndices {
    buffer: Option<wgpu::Buffer>,
    capacity: usize,
    mirrored: Option<usize>,
    /// Indices the draw reads.
    draw: u32,
    ranges: Vec<Range<usize>>,
    stitched: Vec<u32>,
    scratch: Vec<u16>,
}

impl ArenaIndices {
    /// Brings the buffer to `arena`, which changed since the last call
    /// only in `dirty` and past the length it had then.
    pub(crate) fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::IndexFormat,
        mode: StripMode,
        arena: &[u32],
        dirty: &[Range<usize>],
    ) -> Result<Upload> {
        if mode == StripMode::Stitched {
            let mut stitched = std::mem::take(&mut self.stitched);
            stitch_restart_buffer(arena, &mut stitched);
            let upload = self.write_whole(device, queue, format, &stitched);
            self.stitched = stitched;
            self.mirrored = None;
            return upload;
        }
        let len = arena.len();
        // Taken: an error below leaves the next call to write the whole.
        let previous = self
            .mirrored
            .take()
            .filter(|_| self.buffer.is_some() && room(len) <= self.capacity);
        let Some(previous) = previous else {
            let upload = self.write_whole(device, queue, format, arena)?;
            self.mirrored = Some(len);
            return Ok(upload);
        };
        self.ranges.clear();
        self.ranges.extend(
            dirty
                .iter()
                .map(|r| r.start.min(len)..r.end.min(len))
                .filter(|r| !r.is_empty()),
        );
        if len > previous {
            self.ranges.push(previous..len);
        }
        self.ranges.sort_unstable_by_key(|r| r.start);
        let mut merged = 0;
        for i in 0..self.ranges.len() {
            let r = self.ranges[i].clone();
            if merged > 0 && r.start <= self.ranges[merged - 1].end + MERGE_GAP {
                let last = &mut self.ranges[merged - 1];
                last.end = last.end.max(r.end);
            } else {
                self.ranges[merged] = r;
                merged += 1;
            }
        }
        self.ranges.truncate(merged);
        let mut upload = Upload::default();
        if let Some(buffer) = &self.buffer {
            for r in &self.ranges {
                upload.bytes += write_index_range(
                    queue,
                    buffer,
                    format,
                    arena,
                    r.clone(),
                    r.start,
                    &mut self.scratch,
                );
                upload.writes += 1;
            }
        }
        self.mirrored = Some(len);
        self.draw = len as u32;
        Ok(upload)
    }

    /// Writes `indices` whole from index 0 (growing the buffer first when
    /// they do not fit) and draws all of them.
    fn write_whole(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::IndexFormat,
        indices: &[u32],
    ) -> Result<Upload> {
        self.reserve(device, format, indices.len())?;
        self.draw = indices.len() as u32;
        let Some(buffer) = &self.buffer else {
            return Ok(Upload::default());
        };
        if indices.is_empty() {
            return Ok(Upload::default());
        }
        let bytes = write_index_range(
            queue,
            buffer,
            format,
            indices,
            0..indices.len(),
            0,
            &mut self.scratch,
        );
        Ok(Upload { bytes, writes: 1 })
    }

    /// Room for `len` indices: when they do not fit, a new buffer with 1.5
    /// times the room (the room alone where that passes the device's
    /// `max_buffer_size`); its content is then undefined.
    fn reserve(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::IndexFormat,
        len: usize,
    ) -> Result<()> {
        let needed = room(len);
        if self.buffer.is_some() && needed <= self.capacity {
            return Ok(());
        }
        let size = index_size(format);
        let mut capacity = room(needed + needed / 2);
        if (capacity * size) as u64 > device.limits().max_buffer_size {
            capacity = needed;
        }
        check_size(device, capacity * size, "hierarchy index buffer")?;
        self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts hierarchy indices"),
            size: (capacity * size) as u64,
            // COPY_SRC: readable by hosts and tests.
            usage: wgpu::BufferUsages::INDEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        }));
        self.capacity = capacity;
        self.mirrored = None;
        Ok(())
    }

    /// Records the draw of the arena as `instances` of slot 1 (bound by
    /// the caller with the vertices and the strip pipeline).
    pub(crate) fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        format: wgpu::IndexFormat,
        instances: Range<u32>,
    ) {
        let Some(buffer) = &self.buffer else {
            return;
        };
        if self.draw == 0 {
            return;
        }
        pass.set_index_buffer(buffer.slice(..), format);
        pass.draw_indexed(0..self.draw, 0, instances);
    }

    /// Indices the draw reads.
    pub(crate) fn indices_drawn(&self) -> usize {
        self.draw as usize
    }

    /// GPU bytes of the buffer.
    pub(crate) fn gpu_bytes(&self) -> usize {
        self.buffer.as_ref().map_or(0, |b| b.size() as usize)
    }

    /// The buffer, once written.
    pub(crate) fn buffer(&self) -> Option<&wgpu::Buffer> {
        self.buffer.as_ref()
    }
}

fn index_size(format: wgpu::IndexFormat) -> usize {
    match format {
        wgpu::IndexFormat::Uint16 => 2,
        wgpu::IndexFormat::Uint32 => 4,
    }
}

/// Draws a [`Hierarchy`] view-dependently (see the module docs).
///
/// Built from the caller's device and queue and a hierarchy; the
/// [`ViewDependent`] that chooses the cut belongs to the caller (it
/// borrows the hierarchy) and is passed to every
/// [`HierarchyRenderer::update`].
///
/// # Example
///
/// A terrain drawn from a camera near its corner, the cut within one
/// pixel, culled to the view. It needs a graphics adapter (Mesa's lavapipe
/// draws it without a GPU); without one it is skipped with a message,
/// unless `MTS_REQUIRE` names `gpu` (as in CI), where it fails.
///
/// ```
/// use glam::Vec3;
/// use mts::hierarchy::{self, HierarchyOptions, ViewDependent};
/// use mts::mesh::generate::Generated;
/// use mts_render::{Camera, Gpu, HeadlessTarget, HierarchyRenderer, RendererConfig};
///
/// # fn main() -> Result<(), mts::Error> {
/// let mesh = "terrain:8k".parse::<Generated>()?.build();
/// let h = hierarchy::build(&mesh, &HierarchyOptions::default())?;
/// # if let Err(mts::Error::NoAdapter(why)) = Gpu::new_headless() {
/// #     let required = std::env::var("MTS_REQUIRE")
/// #         .is_ok_and(|v| v.split(',').any(|w| w.trim() == "gpu"));
/// #     assert!(!required, "MTS_REQUIRE names gpu: no adapter ({why})");
/// #     eprintln!("skipped: no graphics adapter ({why})");
/// #     return Ok(());
/// # }
/// let gpu = Gpu::new_headless()?;
/// let (device, queue) = (&gpu.device, &gpu.queue);
/// let target = HeadlessTarget::new(device, 640, 480)?;
/// let config = RendererConfig::headless(gpu.report().strip_mode);
/// let mut renderer = HierarchyRenderer::new(device, queue, &config, &h)?;
/// let mut view = ViewDependent::new(&h);
/// let camera = Camera::looking(Vec3::new(-1.2, 0.6, -1.2), Vec3::ZERO, target.aspect(), 0.01, 10.0);
/// // Once per frame: select the cut, write what changed, draw.
/// let frame = renderer.update(device, queue, &mut view, &camera, 480.0, 1.0, true)?;
/// let image = target.render_image(device, queue, |pass| renderer.draw(pass))?;
/// assert!(frame.triangles > 0 && frame.triangles < h.triangle_count());
/// assert!(image.foreground_pixels() > 0);
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct HierarchyRenderer {
    /// The vertices, properties, texture, pipelines and camera; its own
    /// index buffer is not drawn by [`HierarchyRenderer::draw`].
    vertices: StripRenderer,
    arena: ArenaIndices,
    last: HierarchyFrame,
}

impl HierarchyRenderer {
    /// [`HierarchyRenderer::with_appearance`] with the default appearance
    /// (the hierarchy's own texture, if any).
    ///
    /// # Errors
    /// As [`HierarchyRenderer::with_appearance`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        h: &Hierarchy,
    ) -> Result<HierarchyRenderer> {
        HierarchyRenderer::with_appearance(device, queue, config, h, &Appearance::default())
    }

    /// Uploads `h`'s input vertices with their properties (normals,
    /// colours, UVs and texture, or the checker when `appearance` asks;
    /// what cannot be drawn is in [`HierarchyRenderer::warnings`]) and
    /// builds the pipelines. Nothing is drawn before the first
    /// [`HierarchyRenderer::update`].
    ///
    /// # Errors
    /// As [`StripRenderer::with_properties`] (no vertices, too many, a
    /// vertex buffer past the device's `max_buffer_size`).
    ///
    /// Cost: O(vertices + triangles) and the texture's decode, as
    /// [`StripRenderer::with_properties`].
    pub fn with_appearance(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        h: &Hierarchy,
        appearance: &Appearance,
    ) -> Result<HierarchyRenderer> {
        let vertices = vertex_renderer(device, queue, config, h, appearance)?;
        Ok(HierarchyRenderer {
            vertices,
            arena: ArenaIndices::default(),
            last: HierarchyFrame::default(),
        })
    }

    /// Selects `view`'s cut for `camera` on a viewport `viewport_height`
    /// pixels high at `pixel_threshold` pixels of projected error (culled
    /// to the camera's frustum when `cull` is set), writes what changed in
    /// its arena into the index buffer (see the module docs) and the camera
    /// into the uniform.
    ///
    /// Precondition: `view` is the same [`ViewDependent`] at every call
    /// (the dirty ranges describe its arena), updated only here (or through
    /// [`HierarchyRenderer::upload`] after each of the caller's own
    /// updates).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when `view`'s hierarchy has another
    /// vertex count than the renderer's; [`Error::Gpu`] when the index
    /// buffer would pass the device's `max_buffer_size`.
    ///
    /// Cost: the [`ViewDependent::update`], plus O(dirty indices) on the
    /// restart path or O(arena) on the stitched path.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view: &mut ViewDependent<'_>,
        camera: &Camera,
        viewport_height: f32,
        pixel_threshold: f32,
        cull: bool,
    ) -> Result<HierarchyFrame> {
        self.check(view)?;
        self.vertices.set_camera(queue, camera);
        let update = view.update(&camera_view(camera, viewport_height, pixel_threshold, cull));
        self.upload(device, queue, view, update)
    }

    /// Writes what the caller's own [`ViewDependent::update`] changed (for
    /// a [`View`] of its own making, e.g. [`instance_view`]); `update` is
    /// what it returned, reported back in the frame. Call it after every
    /// such update.
    ///
    /// # Errors
    /// As [`HierarchyRenderer::update`].
    pub fn upload(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view: &ViewDependent<'_>,
        update: FrameUpdate,
    ) -> Result<HierarchyFrame> {
        self.check(view)?;
        let upload = self.arena.update(
            device,
            queue,
            self.vertices.index_format(),
            self.vertices.strip_mode(),
            view.buffer(),
            view.dirty_ranges(),
        )?;
        self.last = HierarchyFrame {
            update,
            triangles: view.triangle_count(),
            indices_sent: view.indices_sent(),
            indices_drawn: self.arena.indices_drawn(),
            upload,
            gpu_bytes: self.gpu_bytes(),
            cpu_bytes: view.memory_bytes(),
        };
        Ok(self.last)
    }

    fn check(&self, view: &ViewDependent<'_>) -> Result<()> {
        let n = view.hierarchy().vertex_count();
        if n != self.vertices.vertex_count() {
            return Err(Error::InvalidArgument(format!(
                "the hierarchy has {n} vertices, the renderer {}",
                self.vertices.vertex_count()
            )));
        }
        Ok(())
    }

    /// Records the draw of the cut into `pass` (which must have the
    /// colour and depth formats of the config): one strip draw of the
    /// whole arena. Draws nothing before the first update.
    ///
    /// Cost: five commands; no allocation.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.arena.indices_drawn() == 0 {
            return;
        }
        self.vertices.bind_single(pass, true);
        self.arena.draw(pass, self.vertices.index_format(), 0..1);
    }

    /// Writes `camera` into the uniform (as [`StripRenderer::set_camera`];
    /// [`HierarchyRenderer::update`] does it too).
    pub fn set_camera(&self, queue: &wgpu::Queue, camera: &Camera) {
        self.vertices.set_camera(queue, camera);
    }

    /// Sets the surface colour the next camera write takes (as
    /// [`StripRenderer::set_colour`]).
    pub fn set_colour(&mut self, colour: Vec3) {
        self.vertices.set_colour(colour);
    }

    /// What the last update did and what is drawn.
    #[must_use]
    pub fn last_frame(&self) -> HierarchyFrame {
        self.last
    }

    /// Indices the next draw reads.
    #[must_use]
    pub fn indices_drawn(&self) -> usize {
        self.arena.indices_drawn()
    }

    /// GPU bytes of the vertex buffer and the arena's index buffer.
    #[must_use]
    pub fn gpu_bytes(&self) -> usize {
        self.vertices.gpu_bytes() + self.arena.gpu_bytes()
    }

    /// The index buffer the draw reads (its first
    /// [`HierarchyRenderer::indices_drawn`] indices, in
    /// [`HierarchyRenderer::index_format`]; restart `0xFFFF` or
    /// `u32::MAX`), `None` before the first update. It can be copied from.
    #[must_use]
    pub fn index_buffer(&self) -> Option<&wgpu::Buffer> {
        self.arena.buffer()
    }

    /// `Uint16` when the hierarchy's vertices allow it, else `Uint32`.
    #[must_use]
    pub fn index_format(&self) -> wgpu::IndexFormat {
        self.vertices.index_format()
    }

    /// The strip mode in use.
    #[must_use]
    pub fn strip_mode(&self) -> StripMode {
        self.vertices.strip_mode()
    }

    /// Why something of the properties is not drawn (as
    /// [`StripRenderer::warnings`]).
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        self.vertices.warnings()
    }

    /// Width and height of the base-colour texture drawn, `None` when
    /// untextured.
    #[must_use]
    pub fn texture_size(&self) -> Option<(u32, u32)> {
        self.vertices.texture_size()
    }

    /// The [`StripRenderer`] holding the vertices and pipelines. Its own
    /// index buffer is not the arena's: uploading a triangle list to it and
    /// drawing it ([`StripRenderer::upload_list`], [`StripRenderer::draw`])
    /// draws other triangles over the same vertices, e.g. a cut from
    /// scratch as the tests' oracle.
    #[must_use]
    pub fn strip_renderer(&self) -> &StripRenderer {
        &self.vertices
    }

    /// See [`HierarchyRenderer::strip_renderer`].
    pub fn strip_renderer_mut(&mut self) -> &mut StripRenderer {
        &mut self.vertices
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eye_is_read_back_from_the_matrix() {
        for (eye, target) in [
            (Vec3::new(1.0, 2.0, 9.0), Vec3::ZERO),
            (Vec3::new(-300.0, 40.0, 12.5), Vec3::new(-290.0, 0.0, 0.0)),
            (Vec3::new(0.1, -0.2, 0.05), Vec3::new(0.0, -0.2, 0.0)),
        ] {
            let c = Camera::looking(eye, target, 1.5, 0.01, 1000.0);
            let got = camera_eye(c.view_proj);
            assert!(
                got.distance(eye) <= 1e-4 * eye.length().max(1.0),
                "{eye} -> {got}"
            );
        }
        // Orthographic: the centre of the near plane.
        let ortho = glam::camera::rh::proj::directx::orthographic(-4.0, 4.0, -2.5, 2.5, 0.0, 10.0);
        assert_eq!(camera_eye(ortho), Vec3::ZERO);
    }

    #[test]
    fn an_instance_view_is_the_camera_seen_from_model_space() {
        let c = Camera::looking(Vec3::new(10.0, 5.0, 3.0), Vec3::ZERO, 1.0, 0.1, 100.0);
        let t = Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(1.0, 0.0, -2.0),
        );
        let v = instance_view(&c, t, 600.0, 1.0, true).unwrap();
        assert!(
            t.transform_point3(v.eye)
                .distance(Vec3::new(10.0, 5.0, 3.0))
                < 1e-4
        );
        assert!((v.pixel_threshold - 1.0).abs() < 1e-6);
        let f = v.frustum.unwrap();
        // The model-space point seen at the world origin is in view.
        assert!(f.may_see(t.inverse().transform_point3(Vec3::ZERO), 0.0));
        assert!(!f.may_see(
            t.inverse().transform_point3(Vec3::new(20.0, 10.0, 6.0)),
            0.0
        ));
        // A non-uniform scale tightens the threshold by its ratio.
        let squashed = Mat4::from_scale(Vec3::new(1.0, 0.25, 1.0));
        let v = instance_view(&c, squashed, 600.0, 2.0, false).unwrap();
        assert!((v.pixel_threshold - 0.5).abs() < 1e-6 && v.frustum.is_none());
        assert!(instance_view(&c, Mat4::ZERO, 600.0, 1.0, false).is_none());
    }
}
