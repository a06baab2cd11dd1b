//! A scene the host drives: several models, each with many instances at
//! the host's own transforms, added, moved and removed at will; each
//! instance gets its LoD from its projected size and its own coherence
//! cache, and instances are culled against the view frustum through a BVH
//! over their bounds (obvhs), rebuilt at the next update after instances
//! were added, moved or removed (O(n log n); a frame without changes keeps
//! it).
//!
//! Per model: one [`StripRenderer`] (vertices, pipelines, camera), one
//! index buffer holding a region per instance slot as long as the model's
//! widest band (the extractor's `active_range` of any band fits), and one
//! per-instance transform buffer. Within a band a LoD change uploads the
//! instance's dirty ranges into its region; a band change uploads the new
//! band's active range whole. Buffers grow by doubling; after a growth
//! every region is written again. Each visible instance is one
//! `draw_indexed` of its region with its transform.
//!
//! On a backend that ignores primitive restart ([`StripMode::Stitched`],
//! wgpu's GL) each region holds the instance's runs stitched with
//! degenerate triangles, rewritten whole when its LoD changes.
//!
//! Memory: every instance holds its extractor's slot buffer (4 bytes per
//! slot index of the widest band) and a GPU region; see
//! [`InstancedScene::bytes_per_instance`]. The ground, the grid layout and
//! the demo camera of `mts render --scene` live in the CLI.

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

/// Most instances an [`InstancedScene`] holds, over all its models.
pub const MAX_INSTANCES: usize = 1 << 20;

/// Most bytes of per-instance coherence caches an [`InstancedScene`]
/// holds (2 GiB).
pub const MAX_CACHE_BYTES: usize = 2 << 30;

/// A model added to a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ModelId(u32);

/// An instance in a scene: valid until it is removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct InstanceId {
    model: u32,
    slot: u32,
}

impl InstanceId {
    /// The model this is an instance of.
    #[must_use]
    pub fn model(self) -> ModelId {
        ModelId(self.model)
    }
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
    /// Bytes written to the index buffers.
    pub upload_bytes: usize,
}

/// A bounding sphere, world space.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bound {
    centre: Vec3,
    radius: f32,
}

/// One placed copy of a model.
#[derive(Debug)]
struct Slot<'m> {
    transform: Mat4,
    bound: Bound,
    extractor: Extractor<'m>,
    /// What its region holds now: the active range (restart) or the
    /// stitched length (from 0).
    held: Range<usize>,
    /// Whether its region holds what `held` says (false after a growth).
    written: bool,
}

/// A model with its renderer, its buffers and its instances' slots.
#[derive(Debug)]
struct ModelEntry<'m> {
    model: &'m MtsModel,
    renderer: StripRenderer,
    /// The model's bounding sphere in model space.
    local: Bound,
    /// Indices per instance region (even).
    region: usize,
    /// CPU bytes of one instance's extractor.
    cpu_per_instance: usize,
    /// Slots the buffers hold.
    capacity: usize,
    index_buffer: wgpu::Buffer,
    instance_buffer: wgpu::Buffer,
    slots: Vec<Option<Slot<'m>>>,
    free: Vec<u32>,
    /// Slots whose transform is not uploaded yet.
    moved: Vec<u32>,
}

/// Several models, each with instances the host places (see the module
/// docs).
#[derive(Debug)]
pub struct InstancedScene<'m> {
    config: RendererConfig,
    models: Vec<ModelEntry<'m>>,
    live: usize,
    cpu_bytes: usize,
    /// Instances in the BVH's order, and the BVH over their bounds; stale
    /// while `dirty`.
    order: Vec<InstanceId>,
    bounds: Vec<Bound>,
    bvh_nodes: Vec<obvhs::bvh2::node::Bvh2Node>,
    bvh_leaves: Vec<u32>,
    dirty: bool,
    stack: Vec<u32>,
    candidates: Vec<u32>,
    /// Visible instances of the last update, ascending.
    visible: Vec<InstanceId>,
    scratch: Vec<u16>,
    stitch_scratch: Vec<u32>,
    transform_scratch: Vec<f32>,
}

impl<'m> InstancedScene<'m> {
    /// An empty scene whose models will be drawn with `config` (its strip
    /// mode decides restart or stitching).
    #[must_use]
    pub fn new(config: &RendererConfig) -> InstancedScene<'m> {
        InstancedScene {
            config: *config,
            models: Vec::new(),
            live: 0,
            cpu_bytes: 0,
            order: Vec::new(),
            bounds: Vec::new(),
            bvh_nodes: Vec::new(),
            bvh_leaves: Vec::new(),
            dirty: false,
            stack: Vec::new(),
            candidates: Vec::new(),
            visible: Vec::new(),
            scratch: Vec::new(),
            stitch_scratch: Vec::new(),
            transform_scratch: Vec::new(),
        }
    }

    /// Adds `model`: its vertices are uploaded once, its instances share
    /// them.
    ///
    /// # Errors
    /// [`Error::Gpu`] or [`Error::InvalidArgument`] as
    /// [`StripRenderer::for_model`].
    ///
    /// Cost: the vertex upload and one walk per band (the widest band's
    /// span).
    pub fn add_model(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &'m MtsModel,
    ) -> Result<ModelId> {
        let renderer = StripRenderer::for_model(device, queue, &self.config, model)?;
        let (min, max) = mts::mesh::bounds_of(model.positions()).unwrap_or_default();
        let radius = ((mts::mesh::diagonal_of(min, max) * 0.5) as f32).max(f32::MIN_POSITIVE);
        let mut probe = Extractor::new(model);
        let cpu_per_instance = 4 * probe.buffer().len();
        let widest = (0..model.band_count())
            .map(|b| {
                probe.set_lod(model.band_first_lod(b));
                probe.active_range().len()
            })
            .max()
            .unwrap_or(0);
        // Stitching turns each restart into at most three repeated indices
        // and runs hold at least four entries with their restart, so twice
        // the widest active range holds any stitched one (and the padding
        // index a 16-bit write may add).
        let region = if self.config.strip_mode == StripMode::Stitched {
            2 * widest + 4
        } else {
            ((widest + 1) & !1).max(2)
        };
        let (index_buffer, instance_buffer) = buffers(device, &renderer, region, 1)?;
        self.models.push(ModelEntry {
            model,
            renderer,
            local: Bound {
                centre: (min + max) * 0.5,
                radius,
            },
            region,
            cpu_per_instance,
            capacity: 1,
            index_buffer,
            instance_buffer,
            slots: Vec::new(),
            free: Vec::new(),
            moved: Vec::new(),
        });
        Ok(ModelId(self.models.len() as u32 - 1))
    }

    /// Adds an instance of `model` at `transform` (model to world: a
    /// rotation, a translation and a uniform scale). It is drawn from the
    /// next [`InstancedScene::update`] on.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] past [`MAX_INSTANCES`] or
    /// [`MAX_CACHE_BYTES`], or for a transform whose bounds are not finite.
    ///
    /// Cost: one extractor (O(strips)); no GPU work until the update.
    pub fn add_instance(&mut self, model: ModelId, transform: Mat4) -> Result<InstanceId> {
        let entry = &mut self.models[model.0 as usize];
        if self.live >= MAX_INSTANCES {
            return Err(Error::InvalidArgument(format!(
                "a scene holds at most {MAX_INSTANCES} instances"
            )));
        }
        if self.cpu_bytes + entry.cpu_per_instance > MAX_CACHE_BYTES {
            return Err(Error::InvalidArgument(format!(
                "another instance would take the coherence caches past {MAX_CACHE_BYTES} bytes \
                 ({} each)",
                entry.cpu_per_instance
            )));
        }
        let bound = place(entry.local, transform)?;
        let slot = Slot {
            transform,
            bound,
            extractor: Extractor::new(entry.model),
            held: 0..0,
            written: false,
        };
        let index = match entry.free.pop() {
            Some(i) => {
                entry.slots[i as usize] = Some(slot);
                i
            }
            None => {
                entry.slots.push(Some(slot));
                entry.slots.len() as u32 - 1
            }
        };
        entry.moved.push(index);
        self.live += 1;
        self.cpu_bytes += entry.cpu_per_instance;
        self.dirty = true;
        Ok(InstanceId {
            model: model.0,
            slot: index,
        })
    }

    /// Moves instance `id` to `transform`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for an instance that was removed or a
    /// transform whose bounds are not finite.
    pub fn set_transform(&mut self, id: InstanceId, transform: Mat4) -> Result<()> {
        let entry = &mut self.models[id.model as usize];
        let local = entry.local;
        let slot = entry
            .slots
            .get_mut(id.slot as usize)
            .and_then(Option::as_mut)
            .ok_or_else(|| Error::InvalidArgument(format!("no instance {id:?}")))?;
        slot.bound = place(local, transform)?;
        slot.transform = transform;
        entry.moved.push(id.slot);
        self.dirty = true;
        Ok(())
    }

    /// Removes instance `id` (its slot is reused by a later instance).
    /// Returns whether it was there.
    pub fn remove_instance(&mut self, id: InstanceId) -> bool {
        let entry = &mut self.models[id.model as usize];
        let Some(slot) = entry.slots.get_mut(id.slot as usize) else {
            return false;
        };
        if slot.take().is_none() {
            return false;
        }
        entry.free.push(id.slot);
        self.live -= 1;
        self.cpu_bytes -= entry.cpu_per_instance;
        self.dirty = true;
        true
    }

    /// Instances in the scene, over all models.
    #[must_use]
    pub fn instance_count(&self) -> usize {
        self.live
    }

    /// The bounding sphere (centre, radius) of instance `id` in world
    /// space, `None` once removed.
    #[must_use]
    pub fn bounds_of(&self, id: InstanceId) -> Option<(Vec3, f32)> {
        let slot = self.slot(id)?;
        Some((slot.bound.centre, slot.bound.radius))
    }

    /// Instances the last update found visible, ascending.
    #[must_use]
    pub fn visible(&self) -> &[InstanceId] {
        &self.visible
    }

    /// The LoD instance `id` holds now (`None` before it was first seen,
    /// or once removed).
    #[must_use]
    pub fn lod_of(&self, id: InstanceId) -> Option<usize> {
        self.slot(id)?.extractor.lod()
    }

    /// Bytes an instance of `model` costs: its extractor's slot buffer
    /// (CPU) and its index region (GPU).
    #[must_use]
    pub fn bytes_per_instance(&self, model: ModelId) -> (usize, usize) {
        let entry = &self.models[model.0 as usize];
        (
            entry.cpu_per_instance,
            index_size(&entry.renderer) as usize * entry.region,
        )
    }

    fn slot(&self, id: InstanceId) -> Option<&Slot<'m>> {
        self.models
            .get(id.model as usize)?
            .slots
            .get(id.slot as usize)?
            .as_ref()
    }

    /// Culls the instances against `camera`'s frustum (a BVH over their
    /// bounding boxes, then each candidate's sphere; the BVH is rebuilt
    /// first when instances changed), gives each visible instance the
    /// finest LoD with at most its projected disc area (in pixels of a
    /// viewport `viewport_height` pixels high) divided by
    /// [`PIXELS_PER_TRIANGLE`] triangles, extracts it through its own
    /// coherence cache and uploads what changed: transforms of moved
    /// instances, index ranges of changed LoDs. Instances out of view keep
    /// their LoD and cost nothing. Also writes the camera.
    ///
    /// # Errors
    /// [`Error::Gpu`] when a model's buffers would pass the device's
    /// `max_buffer_size` as they grow.
    ///
    /// Cost: O(visible · log instances) for culling, plus the extraction and
    /// upload of the instances whose LoD changed, plus O(n log n) for the
    /// BVH after a change of instances.
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        viewport_height: f32,
    ) -> Result<FrameStats> {
        for entry in &mut self.models {
            entry.renderer.set_camera(queue, camera);
            grow(device, entry)?;
            upload_transforms(queue, entry, &mut self.transform_scratch);
        }
        if self.dirty {
            self.rebuild_bvh();
        }
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
            &self.bvh_leaves,
            &self.bounds,
            &planes,
            &mut self.stack,
            &mut self.candidates,
        );
        self.visible.clear();
        self.visible
            .extend(self.candidates.iter().map(|&i| self.order[i as usize]));
        self.visible.sort_unstable();
        let stitched = self.config.strip_mode == StripMode::Stitched;
        for &id in &self.visible {
            let entry = &mut self.models[id.model as usize];
            let (format, region, model) =
                (entry.renderer.index_format(), entry.region, entry.model);
            let slot = entry.slots[id.slot as usize]
                .as_mut()
                .expect("visible instances are live");
            let depth = row_w
                .dot(slot.bound.centre.extend(1.0))
                .max(slot.bound.radius);
            let r_px = slot.bound.radius * px_per_unit / depth;
            let budget = (std::f32::consts::PI * r_px * r_px / PIXELS_PER_TRIANGLE) as usize;
            let lod = model.lod_for_triangles(budget.max(1));
            let ex = &mut slot.extractor;
            let changed = ex.lod() != Some(lod);
            if changed {
                ex.set_lod(lod);
                stats.lod_changes += 1;
            }
            let base = id.slot as usize * region;
            if stitched && (changed || !slot.written) {
                stitch_restart_buffer(&ex.buffer()[ex.active_range()], &mut self.stitch_scratch);
                let n = self.stitch_scratch.len();
                slot.held = 0..n;
                if n > 0 {
                    stats.upload_bytes += write_index_range(
                        queue,
                        &entry.index_buffer,
                        format,
                        &self.stitch_scratch,
                        0..n,
                        base,
                        &mut self.scratch,
                    );
                }
            } else if changed || !slot.written {
                if !slot.written {
                    slot.held = 0..0;
                }
                stats.upload_bytes += upload_instance(
                    queue,
                    &entry.index_buffer,
                    format,
                    base,
                    ex,
                    &mut slot.held,
                    &mut self.scratch,
                );
            }
            slot.written = true;
            stats.triangles += model.triangle_count(lod);
            stats.indices_sent += if stitched {
                slot.held.len()
            } else {
                ex.indices_sent()
            };
            stats.indices_drawn += slot.held.len();
        }
        stats.visible = self.visible.len();
        Ok(stats)
    }

    /// Records one draw per visible instance into `pass`, model by model.
    ///
    /// Cost: three binds per model with visible instances plus one
    /// `draw_indexed` per visible instance.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        let mut bound = u32::MAX;
        for &id in &self.visible {
            let entry = &self.models[id.model as usize];
            let Some(slot) = &entry.slots[id.slot as usize] else {
                continue;
            };
            if slot.held.is_empty() {
                continue;
            }
            if bound != id.model {
                entry.renderer.bind(pass, true);
                pass.set_vertex_buffer(1, entry.instance_buffer.slice(..));
                pass.set_index_buffer(entry.index_buffer.slice(..), entry.renderer.index_format());
                bound = id.model;
            }
            let base = id.slot as usize * entry.region;
            pass.draw_indexed(
                base as u32..(base + slot.held.len()) as u32,
                0,
                id.slot..id.slot + 1,
            );
        }
    }

    /// The live instances and their bounds, and a BVH over them.
    fn rebuild_bvh(&mut self) {
        self.order.clear();
        self.bounds.clear();
        for (m, entry) in self.models.iter().enumerate() {
            for (s, slot) in entry.slots.iter().enumerate() {
                if let Some(slot) = slot {
                    self.order.push(InstanceId {
                        model: m as u32,
                        slot: s as u32,
                    });
                    self.bounds.push(slot.bound);
                }
            }
        }
        (self.bvh_nodes, self.bvh_leaves) = bvh_over(&self.bounds);
        self.dirty = false;
    }
}

/// A BVH over the bounding boxes of `bounds`: its nodes and the indices
/// into `bounds` its leaves point to (both empty for no bound). O(n log n).
fn bvh_over(bounds: &[Bound]) -> (Vec<obvhs::bvh2::node::Bvh2Node>, Vec<u32>) {
    if bounds.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let boxes: Vec<obvhs::aabb::Aabb> = bounds
        .iter()
        .map(|b| {
            let r = Vec3::splat(b.radius);
            obvhs::aabb::Aabb::new((b.centre - r).into(), (b.centre + r).into())
        })
        .collect();
    let mut build_time = std::time::Duration::ZERO;
    let bvh = obvhs::bvh2::builder::build_bvh2(
        &boxes,
        obvhs::BvhBuildParams::fast_build(),
        &mut build_time,
    );
    (bvh.nodes, bvh.primitive_indices)
}

/// The world-space bound of a model's `local` bound under `transform`
/// (the largest axis scale bounds a uniform or non-uniform scale).
fn place(local: Bound, transform: Mat4) -> Result<Bound> {
    let scale = [transform.x_axis, transform.y_axis, transform.z_axis]
        .iter()
        .map(|c| c.truncate().length())
        .fold(0.0f32, f32::max);
    let bound = Bound {
        centre: transform.transform_point3(local.centre),
        radius: local.radius * scale,
    };
    if !(bound.centre.is_finite() && bound.radius.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "an instance's bounds are not finite in f32 (centre {}, radius {})",
            bound.centre, bound.radius
        )));
    }
    Ok(bound)
}

fn index_size(renderer: &StripRenderer) -> u64 {
    match renderer.index_format() {
        wgpu::IndexFormat::Uint16 => 2,
        wgpu::IndexFormat::Uint32 => 4,
    }
}

/// An index buffer of `slots` regions of `region` indices and a transform
/// buffer of `slots` instances.
fn buffers(
    device: &wgpu::Device,
    renderer: &StripRenderer,
    region: usize,
    slots: usize,
) -> Result<(wgpu::Buffer, wgpu::Buffer)> {
    let bytes = (slots as u64)
        .saturating_mul(region as u64)
        .saturating_mul(index_size(renderer));
    let max = device.limits().max_buffer_size;
    if bytes > max {
        return Err(Error::Gpu(format!(
            "{slots} instances need a {bytes}-byte index buffer, above the device's \
             max_buffer_size {max}; use fewer instances or a smaller model"
        )));
    }
    let index_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mts scene indices"),
        size: bytes,
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let instance_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mts scene instances"),
        size: slots as u64 * INSTANCE_BYTES,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    Ok((index_buffer, instance_buffer))
}

/// Uploads the transforms of `entry`'s moved slots: each run of
/// consecutive slots in one write (a host moving every instance each frame
/// sends one buffer, not one write per instance), each slot once however
/// often it moved. Clears the list.
fn upload_transforms(queue: &wgpu::Queue, entry: &mut ModelEntry<'_>, scratch: &mut Vec<f32>) {
    let moved = &mut entry.moved;
    moved.sort_unstable();
    moved.dedup();
    let mut i = 0;
    while i < moved.len() {
        let first = moved[i];
        scratch.clear();
        let mut next = first;
        while i < moved.len() && moved[i] == next {
            let m = entry.slots[next as usize]
                .as_ref()
                .map_or(Mat4::ZERO, |slot| slot.transform);
            scratch.extend_from_slice(&m.to_cols_array());
            next += 1;
            i += 1;
        }
        queue.write_buffer(
            &entry.instance_buffer,
            u64::from(first) * INSTANCE_BYTES,
            bytemuck::cast_slice(scratch),
        );
    }
    moved.clear();
}

/// Grows `entry`'s buffers to hold all its slots (doubling); after a
/// growth every transform is uploaded and every region written again.
fn grow(device: &wgpu::Device, entry: &mut ModelEntry<'_>) -> Result<()> {
    let needed = entry.slots.len();
    if needed <= entry.capacity {
        return Ok(());
    }
    let capacity = needed.next_power_of_two();
    let (index_buffer, instance_buffer) = buffers(device, &entry.renderer, entry.region, capacity)?;
    entry.index_buffer = index_buffer;
    entry.instance_buffer = instance_buffer;
    entry.capacity = capacity;
    entry.moved.clear();
    for (i, slot) in entry.slots.iter_mut().enumerate() {
        if let Some(slot) = slot {
            slot.written = false;
            entry.moved.push(i as u32);
        }
    }
    Ok(())
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
    instances: &[Bound],
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed pseudo-random number in 0..1 from `i` (integer hash).
    fn hash01(i: u32) -> f32 {
        let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
        x ^= x >> 16;
        x = x.wrapping_mul(0x7FEB_352D);
        x ^= x >> 15;
        (x >> 8) as f32 / (1u32 << 24) as f32
    }

    #[test]
    fn bvh_culling_equals_the_linear_test() {
        // 30 x 30 unit spheres on a grid with varying heights and radii.
        let instances: Vec<Bound> = (0..900)
            .map(|i| {
                let centre = Vec3::new(
                    (i % 30) as f32 * 3.0,
                    hash01(i) * 4.0,
                    (i / 30) as f32 * 3.0,
                );
                Bound {
                    centre,
                    radius: 0.5 + hash01(i + 1000),
                }
            })
            .collect();
        let (nodes, leaves) = bvh_over(&instances);
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
                &nodes,
                &leaves,
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
