//! Many instances of one model on a ground plane, each with its own LoD
//! (from its projected size) and its own coherence cache, culled against
//! the view frustum through a BVH over their bounds (obvhs).
//!
//! Each instance owns an [`Extractor`] and a region of one shared index
//! buffer as long as the model's widest band (the extractor's
//! `active_range` of any band fits). Within a band a LoD change uploads the
//! instance's dirty ranges into its region; a band change uploads the new
//! band's active range whole (the extractor rewrote all of it anyway). The
//! instances share the vertex buffer, the strip pipeline and the camera of
//! one [`StripRenderer`]; their transforms sit in a per-instance vertex
//! buffer, and each visible instance is one `draw_indexed` of its region.
//!
//! Memory: every instance holds its extractor's slot buffer (4 bytes per
//! slot index of all bands) and a GPU region of the widest band; a model
//! of a few thousand triangles costs well under 1 MB per instance, the
//! 70K-triangle bunny several MB (see [`InstancedScene::bytes_per_instance`]).
//! On a backend that ignores primitive restart ([`StripMode::Stitched`],
//! wgpu's GL) each region holds the instance's runs stitched with
//! degenerate triangles, rewritten whole when its LoD changes.

use super::camera::Camera;
use super::gpu::StripMode;
use super::strip_renderer::{write_index_range, RendererConfig, StripRenderer, INSTANCE_BYTES};
use glam::{Mat4, Vec3, Vec4};
use mts::model::Extractor;
use mts::strip::encode::stitch_restart_buffer;
use mts::{Error, MtsModel, Result};
use std::ops::Range;

/// Projected pixels per triangle that [`InstancedScene::update`] aims at:
/// an instance whose bounding disc covers `A` pixels gets the finest LoD
/// with at most `A / PIXELS_PER_TRIANGLE` triangles. At 4 the silhouette of
/// a torus or bunny shows no facets at 1024 × 768 on lavapipe.
pub const PIXELS_PER_TRIANGLE: f32 = 4.0;

/// Linear RGB of the ground plane (a muted green-grey, apart from the
/// models' colour).
pub const GROUND_COLOUR: Vec3 = Vec3::new(0.22, 0.27, 0.22);

/// One placed copy of the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Model to world: a turn about +y, then a translation (no scale).
    pub transform: Mat4,
    /// Centre of the bounding sphere, world space.
    pub centre: Vec3,
    /// Radius of the bounding sphere (the model's bounding-box half
    /// diagonal).
    pub radius: f32,
}

/// What one [`InstancedScene::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameStats {
    /// Instances inside the view frustum (drawn).
    pub visible: usize,
    /// Triangles of the visible instances at their LoDs.
    pub triangles: usize,
    /// Indices a compact buffer of the visible instances holds (restarts
    /// included): what strips send.
    pub indices_sent: usize,
    /// Indices the draws read (slot padding included).
    pub indices_drawn: usize,
    /// Visible instances whose LoD changed.
    pub lod_changes: usize,
    /// Bytes written to the index buffer.
    pub upload_bytes: usize,
}

/// N instances of one model on a ground plane (see the module docs).
#[derive(Debug)]
pub struct InstancedScene<'m> {
    model: &'m MtsModel,
    renderer: StripRenderer,
    ground: StripRenderer,
    instances: Vec<Instance>,
    extractors: Vec<Extractor<'m>>,
    /// Per instance: the active range its region holds now.
    held: Vec<Range<usize>>,
    /// Indices per instance region (even).
    region: usize,
    index_buffer: wgpu::Buffer,
    instance_buffer: wgpu::Buffer,
    /// BVH over the instances' bounding boxes (obvhs, built once): its
    /// nodes and the instance indices its leaves point into.
    bvh_nodes: Vec<obvhs::bvh2::node::Bvh2Node>,
    bvh_instances: Vec<u32>,
    /// Traversal stack of [`InstancedScene::cull`].
    stack: Vec<u32>,
    /// Visible instances of the last update.
    visible: Vec<u32>,
    /// Extent of the field: min and max corner on the ground.
    field: (Vec3, Vec3),
    scratch: Vec<u16>,
    /// The backend ignores primitive restart: each instance's region holds
    /// its active range stitched with degenerate triangles, written whole
    /// on every LoD change.
    stitched: bool,
    stitch_scratch: Vec<u32>,
}

/// Most instances an [`InstancedScene`] takes.
pub const MAX_INSTANCES: usize = 1 << 20;

/// Most bytes of per-instance coherence caches an [`InstancedScene`]
/// holds (2 GiB).
pub const MAX_CACHE_BYTES: usize = 2 << 30;

impl<'m> InstancedScene<'m> {
    /// Places `count` instances of `model` on a square grid on the plane
    /// y = 0 (each resting on it, turned about +y by a fixed pseudo-random
    /// angle), spaced 2.5 model diameters apart, with a ground quad under
    /// them.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a `count` outside 1..=[`MAX_INSTANCES`],
    /// caches above [`MAX_CACHE_BYTES`] or a model too large for the field
    /// in `f32`; [`Error::Gpu`] when the index buffer (`count` × the widest
    /// band) exceeds the device's `max_buffer_size`. Nothing large is
    /// allocated before these checks.
    ///
    /// Cost: one extractor per instance (O(strips) each), no extraction.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        model: &'m MtsModel,
        count: usize,
    ) -> Result<InstancedScene<'m>> {
        if count == 0 || count > MAX_INSTANCES {
            return Err(Error::InvalidArgument(format!(
                "a scene holds 1 to {MAX_INSTANCES} instances, not {count}"
            )));
        }
        // Per instance: the extractor's slot buffer on the CPU; refused
        // before anything is allocated.
        let cpu_per_instance = 4 * Extractor::new(model).buffer().len();
        let cpu = cpu_per_instance.saturating_mul(count);
        if cpu > MAX_CACHE_BYTES {
            return Err(Error::InvalidArgument(format!(
                "{count} instances would hold {cpu} bytes of coherence caches ({cpu_per_instance} \
                 each), above {MAX_CACHE_BYTES}; use fewer instances"
            )));
        }
        let stitched = config.strip_mode == StripMode::Stitched;
        let (min, max) = mts::mesh::bounds_of(model.positions()).unwrap_or_default();
        let radius = ((mts::mesh::diagonal_of(min, max) * 0.5) as f32).max(f32::MIN_POSITIVE);
        let spacing = 5.0 * radius;
        let side = (count as f64).sqrt().ceil() as usize;
        if !(spacing * (side as f32 + 3.0) + max.abs().max_element()).is_finite() {
            return Err(Error::InvalidArgument(format!(
                "a model {radius:e} units across does not fit a field of {count} instances in \
                 f32 coordinates"
            )));
        }
        let renderer = StripRenderer::for_model(device, queue, config, model)?;
        let mut instances = Vec::with_capacity(count);
        let local_centre = (min + max) * 0.5;
        for i in 0..count {
            let (gx, gz) = ((i % side) as f32, (i / side) as f32);
            let angle = std::f32::consts::TAU * hash01(i as u32);
            // Rest on the plane: the lowest point of the box at y = 0.
            let at = Vec3::new(gx * spacing, -min.y, gz * spacing);
            let transform = Mat4::from_translation(at) * Mat4::from_rotation_y(angle);
            instances.push(Instance {
                transform,
                centre: transform.transform_point3(local_centre),
                radius,
            });
        }
        let far = (side.max(1) - 1) as f32 * spacing;
        let margin = 1.5 * spacing;
        let field = (
            Vec3::new(-margin, 0.0, -margin),
            Vec3::new(far + margin, 0.0, far + margin),
        );
        let (a, b) = field;
        let ground_positions = [
            Vec3::new(a.x, 0.0, a.z),
            Vec3::new(b.x, 0.0, a.z),
            Vec3::new(b.x, 0.0, b.z),
            Vec3::new(a.x, 0.0, b.z),
        ];
        // Counter-clockwise seen from above (+y).
        let ground_triangles = [[0, 2, 1], [0, 3, 2]];
        let mut ground =
            StripRenderer::new(device, queue, config, &ground_positions, &ground_triangles)?;
        ground.upload_list(device, queue, &ground_triangles)?;
        ground.set_colour(GROUND_COLOUR);

        // The widest band's span: the active range at each band's first
        // LoD (one walk per band, on a scratch extractor).
        let mut probe = Extractor::new(model);
        let widest = (0..model.band_count())
            .map(|b| {
                probe.set_lod(model.band_first_lod(b));
                probe.active_range().len()
            })
            .max()
            .unwrap_or(0);
        drop(probe);
        // Stitching turns each restart into at most three repeated indices
        // and runs hold at least four entries with their restart, so twice
        // the widest active range holds any stitched one (and the padding
        // index a 16-bit write may add).
        let region = if stitched {
            2 * widest + 4
        } else {
            (widest + 1) & !1
        };
        let index_size = match renderer.index_format() {
            wgpu::IndexFormat::Uint16 => 2,
            wgpu::IndexFormat::Uint32 => 4,
        };
        let bytes = (count as u64)
            .saturating_mul(region.max(2) as u64)
            .saturating_mul(index_size);
        let max = device.limits().max_buffer_size;
        if bytes > max {
            return Err(Error::Gpu(format!(
                "{count} instances need a {bytes}-byte index buffer, above the device's \
                 max_buffer_size {max}; use fewer instances or a smaller model"
            )));
        }
        let extractors: Vec<Extractor<'m>> = (0..count).map(|_| Extractor::new(model)).collect();
        let index_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts scene indices"),
            size: bytes,
            usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let transforms: Vec<f32> = instances
            .iter()
            .flat_map(|i| i.transform.to_cols_array())
            .collect();
        let instance_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts scene instances"),
            size: count as u64 * INSTANCE_BYTES,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&instance_buffer, 0, bytemuck::cast_slice(&transforms));
        let bvh = instance_bvh(&instances);
        Ok(InstancedScene {
            stitched,
            stitch_scratch: Vec::new(),
            model,
            renderer,
            ground,
            instances,
            held: vec![0..0; count],
            extractors,
            region,
            index_buffer,
            instance_buffer,
            bvh_nodes: bvh.nodes,
            bvh_instances: bvh.primitive_indices,
            stack: Vec::new(),
            visible: Vec::with_capacity(count),
            field,
            scratch: Vec::new(),
        })
    }

    /// The instances, in placement order.
    #[must_use]
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Indices of the instances the last update found visible, ascending.
    #[must_use]
    pub fn visible(&self) -> &[u32] {
        &self.visible
    }

    /// The LoD instance `i` holds now (`None` before it was first seen).
    #[must_use]
    pub fn lod_of(&self, i: usize) -> Option<usize> {
        self.extractors[i].lod()
    }

    /// Bytes each instance costs: its extractor's slot buffer (CPU) and
    /// its index region (GPU).
    #[must_use]
    pub fn bytes_per_instance(&self) -> (usize, usize) {
        let index_size = match self.renderer.index_format() {
            wgpu::IndexFormat::Uint16 => 2,
            wgpu::IndexFormat::Uint32 => 4,
        };
        (
            4 * self.extractors[0].buffer().len(),
            index_size * self.region,
        )
    }

    /// A camera above one corner of the field looking across it, so that
    /// instances range from near (fine LoDs) to far (coarse ones) and some
    /// fall outside the view. `aspect` is width / height.
    #[must_use]
    pub fn overview_camera(&self, aspect: f32) -> Camera {
        let (a, b) = self.field;
        let size = (b - a).length();
        let eye = Vec3::new(a.x, 0.05 * size, a.z) + Vec3::new(0.08, 0.0, 0.08) * size;
        let target = a + (b - a) * Vec3::new(0.55, 0.0, 0.45);
        Camera::looking(eye, target, aspect, 0.01 * size, 2.0 * size)
    }

    /// Culls the instances against `camera`'s frustum (a BVH over their
    /// bounding boxes, then each candidate's sphere), gives each visible
    /// instance the finest LoD with at most its projected disc area (in
    /// pixels of a viewport `viewport_height` pixels high) divided by
    /// [`PIXELS_PER_TRIANGLE`] triangles, extracts it through its own
    /// coherence cache and uploads what changed. Instances out of view keep
    /// their LoD and cost nothing. Also writes the camera.
    ///
    /// Cost: O(visible · log instances) for culling, plus the extraction and
    /// upload of the instances whose LoD changed.
    pub fn update(
        &mut self,
        queue: &wgpu::Queue,
        camera: &Camera,
        viewport_height: f32,
    ) -> FrameStats {
        self.renderer.set_camera(queue, camera);
        self.ground.set_camera(queue, camera);
        let planes = frustum_planes(camera.view_proj);
        // Pixels per world unit at view depth 1: the projection's y scale
        // (the length of the matrix's second row, the view being a
        // rotation) times half the viewport.
        let row_y = camera.view_proj.row(1).truncate().length();
        let row_w = camera.view_proj.row(3);
        let px_per_unit = row_y * 0.5 * viewport_height;
        let mut stats = FrameStats::default();
        cull(
            &self.bvh_nodes,
            &self.bvh_instances,
            &self.instances,
            &planes,
            &mut self.stack,
            &mut self.visible,
        );
        for &i in &self.visible {
            let (i, inst) = (i as usize, &self.instances[i as usize]);
            let depth = row_w.dot(inst.centre.extend(1.0)).max(inst.radius);
            let r_px = inst.radius * px_per_unit / depth;
            let budget = (std::f32::consts::PI * r_px * r_px / PIXELS_PER_TRIANGLE) as usize;
            let lod = self.model.lod_for_triangles(budget.max(1));
            let ex = &mut self.extractors[i];
            if ex.lod() != Some(lod) && self.stitched {
                ex.set_lod(lod);
                stats.lod_changes += 1;
                stitch_restart_buffer(&ex.buffer()[ex.active_range()], &mut self.stitch_scratch);
                let n = self.stitch_scratch.len();
                self.held[i] = 0..n;
                if n > 0 {
                    stats.upload_bytes += write_index_range(
                        queue,
                        &self.index_buffer,
                        self.renderer.index_format(),
                        &self.stitch_scratch,
                        0..n,
                        i * self.region,
                        &mut self.scratch,
                    );
                }
            } else if ex.lod() != Some(lod) {
                ex.set_lod(lod);
                stats.lod_changes += 1;
                stats.upload_bytes += upload_instance(
                    queue,
                    &self.index_buffer,
                    self.renderer.index_format(),
                    i * self.region,
                    ex,
                    &mut self.held[i],
                    &mut self.scratch,
                );
            }
            stats.triangles += self.model.triangle_count(lod);
            stats.indices_sent += if self.stitched {
                self.held[i].len()
            } else {
                ex.indices_sent()
            };
            stats.indices_drawn += self.held[i].len();
        }
        stats.visible = self.visible.len();
        stats
    }

    /// Records the ground and one draw per visible instance into `pass`.
    ///
    /// Cost: two binds plus one `draw_indexed` per visible instance.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.ground.draw(pass);
        if self.visible.is_empty() {
            return;
        }
        self.renderer.bind(pass, true);
        pass.set_vertex_buffer(1, self.instance_buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), self.renderer.index_format());
        for &i in &self.visible {
            let held = &self.held[i as usize];
            if held.is_empty() {
                continue;
            }
            let base = i as usize * self.region;
            pass.draw_indexed(base as u32..(base + held.len()) as u32, 0, i..i + 1);
        }
    }
}

/// Uploads what `ex`'s last `set_lod` changed into the region at `base`,
/// which holds `held` (an active range) now: the dirty ranges inside the
/// active range when it did not move, else the whole new active range.
/// Returns the bytes written.
fn upload_instance(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    format: wgpu::IndexFormat,
    base: usize,
    ex: &Extractor<'_>,
    held: &mut Range<usize>,
    scratch: &mut Vec<u16>,
) -> usize {
    let active = ex.active_range();
    let source = ex.buffer();
    if active != *held {
        *held = active.clone();
        if active.is_empty() {
            return 0;
        }
        return write_index_range(queue, buffer, format, source, active.clone(), base, scratch);
    }
    let mut bytes = 0;
    for r in ex.dirty_ranges() {
        let (start, end) = (r.start.max(active.start), r.end.min(active.end));
        if start < end {
            let dest = base + (start - active.start);
            bytes += write_index_range(queue, buffer, format, source, start..end, dest, scratch);
        }
    }
    bytes
}

/// A fixed pseudo-random number in 0..1 from `i` (integer hash).
fn hash01(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// The six planes (`n · p + d >= 0` inside) of a view-projection matrix
/// with depth 0..1 (Gribb and Hartmann, "Fast extraction of viewing frustum
/// planes from the world-view-projection matrix", 2001), normalised.
fn frustum_planes(m: Mat4) -> [Vec4; 6] {
    let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| {
        let len = p.truncate().length();
        if len > 0.0 {
            p / len
        } else {
            p
        }
    })
}

/// Fills `visible` (ascending) with the instances whose bounding sphere
/// meets the frustum: the BVH's boxes prune whole groups, each leaf's
/// instances are tested by their spheres, so the result is the linear
/// sphere test's.
fn cull(
    nodes: &[obvhs::bvh2::node::Bvh2Node],
    leaves: &[u32],
    instances: &[Instance],
    planes: &[Vec4; 6],
    stack: &mut Vec<u32>,
    visible: &mut Vec<u32>,
) {
    visible.clear();
    stack.clear();
    if nodes.is_empty() {
        return;
    }
    stack.push(0);
    while let Some(n) = stack.pop() {
        let node = &nodes[n as usize];
        let aabb = node.aabb();
        if !box_in_frustum(planes, aabb.min.into(), aabb.max.into()) {
            continue;
        }
        if node.is_leaf() {
            let first = node.first_index as usize;
            for &p in &leaves[first..first + node.prim_count as usize] {
                let inst = &instances[p as usize];
                if sphere_in_frustum(planes, inst.centre, inst.radius) {
                    visible.push(p);
                }
            }
        } else {
            stack.push(node.first_index);
            stack.push(node.first_index + 1);
        }
    }
    visible.sort_unstable();
}

/// Whether a box may meet the frustum: for each plane, the box corner
/// farthest along its normal is inside (conservative: a box near a
/// frustum corner may pass without meeting it).
fn box_in_frustum(planes: &[Vec4; 6], min: Vec3, max: Vec3) -> bool {
    planes.iter().all(|p| {
        let n = p.truncate();
        let corner = Vec3::select(n.cmpge(Vec3::ZERO), max, min);
        n.dot(corner) + p.w >= 0.0
    })
}

/// Whether a sphere is at least partly inside every plane.
fn sphere_in_frustum(planes: &[Vec4; 6], centre: Vec3, radius: f32) -> bool {
    planes
        .iter()
        .all(|p| p.truncate().dot(centre) + p.w >= -radius)
}

/// A BVH over the instances' bounding boxes (their spheres' boxes), built
/// once: what the frustum culling walks. O(n log n).
fn instance_bvh(instances: &[Instance]) -> obvhs::bvh2::Bvh2 {
    let boxes: Vec<obvhs::aabb::Aabb> = instances
        .iter()
        .map(|i| {
            let r = Vec3::splat(i.radius);
            obvhs::aabb::Aabb::new((i.centre - r).into(), (i.centre + r).into())
        })
        .collect();
    let mut build_time = std::time::Duration::ZERO;
    obvhs::bvh2::builder::build_bvh2(&boxes, obvhs::BvhBuildParams::fast_build(), &mut build_time)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bvh_culling_equals_the_linear_test() {
        // 30 x 30 unit spheres on a grid with varying heights and radii.
        let instances: Vec<Instance> = (0..900)
            .map(|i| {
                let centre = Vec3::new(
                    (i % 30) as f32 * 3.0,
                    hash01(i) * 4.0,
                    (i / 30) as f32 * 3.0,
                );
                Instance {
                    transform: Mat4::from_translation(centre),
                    centre,
                    radius: 0.5 + hash01(i + 1000),
                }
            })
            .collect();
        let bvh = instance_bvh(&instances);
        let (mut stack, mut visible) = (Vec::new(), Vec::new());
        let mut seen = 0;
        for k in 0..20u32 {
            let eye = Vec3::new(
                hash01(k) * 90.0,
                2.0 + hash01(k + 50) * 20.0,
                hash01(k + 99) * 90.0,
            );
            let target = Vec3::new(hash01(k + 7) * 90.0, 0.0, hash01(k + 13) * 90.0);
            let cam = Camera::looking(eye, target, 1.5, 0.1, 60.0 + 40.0 * hash01(k + 3));
            let planes = frustum_planes(cam.view_proj);
            cull(
                &bvh.nodes,
                &bvh.primitive_indices,
                &instances,
                &planes,
                &mut stack,
                &mut visible,
            );
            let linear: Vec<u32> = (0..900u32)
                .filter(|&i| {
                    let inst = &instances[i as usize];
                    sphere_in_frustum(&planes, inst.centre, inst.radius)
                })
                .collect();
            assert_eq!(visible, linear, "camera {k}");
            seen += visible.len();
        }
        assert!(seen > 500, "the cameras see something ({seen})");
    }

    #[test]
    fn ground_faces_up() {
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let n = super::super::vertex_normals(&p, &[[0, 2, 1], [0, 3, 2]]);
        assert!(n.iter().all(|&n| n == Vec3::Y), "{n:?}");
    }

    #[test]
    fn frustum_keeps_what_it_sees() {
        let cam = Camera::looking(Vec3::ZERO, Vec3::NEG_Z, 1.0, 0.1, 100.0);
        let planes = frustum_planes(cam.view_proj);
        assert!(sphere_in_frustum(&planes, Vec3::new(0.0, 0.0, -10.0), 1.0));
        assert!(!sphere_in_frustum(&planes, Vec3::new(0.0, 0.0, 10.0), 1.0));
        assert!(!sphere_in_frustum(
            &planes,
            Vec3::new(0.0, 0.0, -200.0),
            1.0
        ));
        assert!(!sphere_in_frustum(
            &planes,
            Vec3::new(50.0, 0.0, -10.0),
            1.0
        ));
        // Straddling the left plane: kept.
        assert!(sphere_in_frustum(&planes, Vec3::new(-4.0, 0.0, -10.0), 1.0));
        let unit = Vec3::ONE;
        assert!(box_in_frustum(
            &planes,
            Vec3::new(0.0, 0.0, -10.0) - unit,
            Vec3::new(0.0, 0.0, -10.0) + unit
        ));
        assert!(!box_in_frustum(
            &planes,
            Vec3::new(0.0, 0.0, 10.0) - unit,
            Vec3::new(0.0, 0.0, 10.0) + unit
        ));
        assert!(!box_in_frustum(
            &planes,
            Vec3::new(50.0, 0.0, -10.0) - unit,
            Vec3::new(50.0, 0.0, -10.0) + unit
        ));
    }
}
