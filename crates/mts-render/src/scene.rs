//! A scene the host drives: several models, each with many instances at
//! the host's own transforms, added, moved and removed at will, drawn at
//! levels of detail chosen by screen-space error and shared between
//! instances.
//!
//! **LoD choice.** Each visible instance gets the coarsest LoD whose
//! recorded error ([`mts::lod_for_screen_error`]), scaled by the instance's
//! largest axis scale and projected at the nearest depth of its bounding
//! sphere, covers at most the host's pixel threshold: the core's rule, with
//! the camera's [`mts::Projection`] ([`Camera::projection`]).
//!
//! **Shared extraction.** A model's LoDs are grouped in buckets: bucket
//! `b` is the finest LoD with at most `T × (1 − s)^b` triangles (`T` the
//! full count, `s` the spacing, [`DEFAULT_BUCKET_SPACING`]). An instance
//! draws the coarsest bucket at least as fine as its LoD, so its error
//! stays within the threshold and it draws at most about `1 / (1 − s)`
//! times the triangles its LoD has. Every instance in a bucket draws the
//! same index buffer, extracted once when the bucket is first needed and
//! kept while instances use it (then for [`KEEP_UPDATES`] more updates, so
//! an instance hovering at a boundary does not extract it again and
//! again). One [`Extractor`] per model walks from bucket to bucket: a new
//! bucket is extracted coherently from the last one, not from scratch, and
//! its compact strips (or, on a backend that ignores primitive restart,
//! [`StripMode::Stitched`], the strips stitched with degenerate triangles)
//! are copied into the bucket's own buffer.
//!
//! **Drawing.** The visible instances' transforms are written each update
//! into one instance buffer, grouped by (model, bucket); each group is one
//! instanced `draw_indexed`.
//!
//! **Culling.** A BVH over the instances' bounds (obvhs) answers the
//! frustum test. It is rebuilt (O(n log n)) at the next update after
//! instances were added or removed, and refitted (O(n): leaves' boxes
//! recomputed, then inner nodes) when instances only moved; after
//! [`REFITS_BEFORE_REBUILD`] refits in a row it is rebuilt, since refitted
//! boxes of instances that moved far apart grow loose.
//!
//! **Memory.** An instance holds its transform, bounds, scale, bucket and
//! LoD (plus its share of the BVH and the per-update lists); the GPU holds
//! the live buckets' index buffers, one instance buffer and each model's
//! vertices. See [`InstancedScene::memory`]. A model's slots go when its
//! last instance is removed, and the lists and the instance buffer at the
//! first update with no instance, so an emptied scene holds what a new one
//! with the same models does. The ground, the layout and the camera of
//! `mts render --scene` live in the CLI.
//!
//! **Hierarchies.** Beside models, a scene holds view-dependent
//! hierarchies ([`InstancedScene::add_hierarchy`]): each uploads its
//! vertices once; each of its instances keeps its own cut
//! ([`ViewDependent`]) and its own index buffer mirroring the cut's arena,
//! as [`crate::HierarchyRenderer`] does. An update tests each hierarchy
//! instance's bounding sphere against the frustum (a linear test: they
//! are few and large), selects the visible ones' cuts for the eye and the
//! frustum carried into model space ([`crate::hierarchy::instance_view`]),
//! writes their dirty ranges (restart path) or their stitched arenas, and
//! places their transforms after the models' groups in the instance
//! buffer; each is one `draw_indexed` of one instance. A culled instance's
//! cut is kept as it was, and follows the camera again when it is seen.

use super::camera::Camera;
use super::gpu::StripMode;
use super::strip_renderer::{write_index_range, RendererConfig, StripRenderer, INSTANCE_BYTES};
use crate::hierarchy::{instance_view, vertex_renderer, ArenaIndices, HierarchyFrame};
use crate::texture::Appearance;
use glam::{Mat4, Vec3, Vec4};
use mts::hierarchy::{Hierarchy, ViewDependent};
use mts::model::Extractor;
use mts::strip::encode::stitch_restart_buffer;
use mts::{Error, MtsModel, Result};
use std::ops::Range;

/// The default of [`InstancedScene::set_bucket_spacing`]: each bucket has
/// about 10% fewer triangles than the next finer one.
pub const DEFAULT_BUCKET_SPACING: f32 = 0.1;

/// The default pixel threshold of the LoD choice.
pub const DEFAULT_PIXEL_ERROR: f32 = 1.0;

/// Updates a bucket no instance uses is kept before its buffer is freed.
pub const KEEP_UPDATES: u32 = 30;

/// Refits of the instance BVH in a row before it is rebuilt.
pub const REFITS_BEFORE_REBUILD: u32 = 64;

/// Most instances an [`InstancedScene`] holds, over all its models.
pub const MAX_INSTANCES: usize = 1 << 22;

/// Most hierarchy instances an [`InstancedScene`] holds, over all its
/// hierarchies (each keeps its own cut, O(groups) bytes, and index
/// buffer).
pub const MAX_HIERARCHY_INSTANCES: usize = 1 << 12;

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

/// A hierarchy added to a scene ([`InstancedScene::add_hierarchy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HierarchyId(u32);

/// An instance of a hierarchy in a scene: valid until it is removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct HierarchyInstanceId {
    hierarchy: u32,
    slot: u32,
}

impl HierarchyInstanceId {
    /// The hierarchy this is an instance of.
    #[must_use]
    pub fn hierarchy(self) -> HierarchyId {
        HierarchyId(self.hierarchy)
    }
}

/// What one [`InstancedScene::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameStats {
    /// Instances inside the view frustum (drawn), of models and of
    /// hierarchies.
    pub visible: usize,
    /// Triangles the visible instances draw (their buckets' counts; a
    /// hierarchy instance's cut, culled parts left out).
    pub triangles: usize,
    /// Triangles the visible instances would draw at full detail.
    pub triangles_full_detail: usize,
    /// Indices the draws read (restarts, or stitching, included).
    pub indices_drawn: usize,
    /// Visible instances whose bucket changed (or that were not drawn in
    /// the previous update); hierarchy instances whose drawn cut changed.
    pub lod_changes: usize,
    /// Buckets extracted by this update.
    pub extractions: usize,
    /// Buckets whose buffers were freed by this update.
    pub evictions: usize,
    /// Instanced draws recorded ((model, bucket) groups, and one per
    /// visible hierarchy instance).
    pub draws: usize,
    /// Bytes written to the GPU (bucket indices, hierarchy instances'
    /// indices and instance transforms).
    pub upload_bytes: usize,
    /// Whether the instance BVH was rebuilt, refitted or kept.
    pub bvh: BvhUpdate,
}

/// One instanced draw of the last [`InstancedScene::update`]: a (model,
/// bucket) group ([`InstancedScene::draw_groups`]), for hosts and tests
/// that check what the GPU is given.
#[derive(Debug, Clone)]
pub struct DrawGroup<'a> {
    /// The model drawn.
    pub model: ModelId,
    /// The bucket's LoD.
    pub lod: usize,
    /// Indices [`InstancedScene::draw`] reads from `indices`: the compact
    /// strips of `lod` (stitched on [`StripMode::Stitched`]); a group of 0
    /// is not drawn.
    pub index_count: u32,
    /// The bucket's index buffer (restart `0xFFFF` or `u32::MAX`; a `u16`
    /// buffer of an odd count ends with one more restart). It can be
    /// copied from.
    pub indices: &'a wgpu::Buffer,
    /// The format of `indices` (the model renderer's).
    pub index_format: wgpu::IndexFormat,
    /// The group's transforms in [`InstancedScene::instance_buffer`], in
    /// [`INSTANCE_BYTES`] entries: the visible instances of the model that
    /// draw this bucket, ascending by id.
    pub instances: Range<u32>,
}

/// What an update did to the instance BVH.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BvhUpdate {
    /// Nothing moved.
    #[default]
    Kept,
    /// Instances moved: boxes refitted.
    Refitted,
    /// Instances were added or removed (or refits ran long): built anew.
    Rebuilt,
}

/// Where a scene's memory goes ([`InstancedScene::memory`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SceneMemory {
    /// Instances.
    pub instances: usize,
    /// CPU bytes that grow with the instances: the instance records, the
    /// BVH and the per-update lists (capacities, not lengths).
    pub cpu_instance_bytes: usize,
    /// CPU bytes per model, shared by its instances: the walking
    /// extractor and the bucket table.
    pub cpu_shared_bytes: usize,
    /// GPU bytes of the live buckets' index buffers (and the hierarchy
    /// instances').
    pub gpu_index_bytes: usize,
    /// GPU bytes of the instance buffer.
    pub gpu_instance_bytes: usize,
    /// GPU bytes of the models' vertex buffers.
    pub gpu_vertex_bytes: usize,
    /// Live bucket buffers (and hierarchy instances' index buffers).
    pub buffers: usize,
}

impl SceneMemory {
    /// [`SceneMemory::cpu_instance_bytes`] per instance (0 for none).
    #[must_use]
    pub fn cpu_bytes_per_instance(&self) -> usize {
        self.cpu_instance_bytes
            .checked_div(self.instances)
            .unwrap_or(0)
    }

    /// GPU bytes beyond the vertices: bucket indices and transforms.
    #[must_use]
    pub fn gpu_bytes(&self) -> usize {
        self.gpu_index_bytes + self.gpu_instance_bytes
    }
}

/// A bounding sphere, world space.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bound {
    centre: Vec3,
    radius: f32,
}

/// "None" for an instance's bucket, and the mark of a free slot.
const NONE: u32 = u32::MAX;

/// One placed copy of a model: what it costs per instance.
#[derive(Debug, Clone, Copy)]
struct Instance {
    transform: Mat4,
    bound: Bound,
    /// Largest axis scale of `transform`.
    scale: f32,
    /// Bucket drawn in the last update ([`NONE`]: not drawn).
    bucket: u32,
    /// LoD the error asked for in the last update.
    lod: u32,
    /// Whether the slot holds an instance.
    live: bool,
}

/// A group of LoDs drawn as one: its LoD and, while live, its buffer.
#[derive(Debug)]
struct Bucket {
    lod: u32,
    triangles: u32,
    buffer: Option<wgpu::Buffer>,
    /// Indices the buffer holds.
    len: u32,
    /// Instances drawing it in the current update.
    users: u32,
    /// Updates since it was last used.
    idle: u32,
    /// First transform of its group in the instance buffer, and how many
    /// are placed so far (this update).
    first: u32,
    placed: u32,
}

/// A model with its renderer, its buckets and its instances.
#[derive(Debug)]
struct ModelEntry<'m> {
    model: &'m MtsModel,
    renderer: StripRenderer,
    /// The model's bounding sphere in model space.
    local: Bound,
    /// The input's bounding-box diagonal (the unit of the errors).
    diagonal: f32,
    /// Walks from bucket to bucket.
    cursor: Extractor<'m>,
    buckets: Vec<Bucket>,
    slots: Vec<Instance>,
    free: Vec<u32>,
}

/// A hierarchy with its vertices and its instances.
#[derive(Debug)]
struct HierarchyEntry<'m> {
    h: &'m Hierarchy,
    /// The vertices (its own index buffer unused).
    renderer: StripRenderer,
    local: Bound,
    slots: Vec<Option<HierarchyInstance<'m>>>,
    free: Vec<u32>,
}

/// One placed copy of a hierarchy: its own cut and index buffer.
#[derive(Debug)]
struct HierarchyInstance<'m> {
    transform: Mat4,
    bound: Bound,
    view: ViewDependent<'m>,
    arena: ArenaIndices,
    /// What its last update (while visible) did.
    last: HierarchyFrame,
    /// Its transform's entry in the instance buffer this update; [`NONE`]
    /// when culled.
    entry: u32,
}

/// Several models, each with instances the host places, and hierarchies
/// with theirs (see the module docs).
///
/// # Example
///
/// One model placed near and far: each instance is drawn at the coarsest
/// LoD whose error covers at most one pixel, so the far one draws fewer
/// triangles. It needs a graphics adapter (Mesa's lavapipe draws it
/// without a GPU); without one it is skipped with a message, as the
/// renderer's tests are, unless `MTS_REQUIRE` names `gpu` (as in CI),
/// where it fails.
///
/// ```
/// use glam::{Mat4, Vec3};
/// use mts::mesh::generate::Generated;
/// use mts::model::{try_build_from_mesh, PipelineOptions};
/// use mts_render::{Camera, Gpu, HeadlessTarget, InstancedScene, RendererConfig};
///
/// # fn main() -> Result<(), mts::Error> {
/// let mesh = "torus:4k".parse::<Generated>()?.build();
/// let (model, _, _) = try_build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {})?;
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
/// let mut scene = InstancedScene::new(&RendererConfig::headless(gpu.report().strip_mode));
/// let torus = scene.add_model(device, queue, &model)?;
/// let d = mesh.diagonal(); // model units
/// let near = scene.add_instance(torus, Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0 * d)))?;
/// let far = scene.add_instance(torus, Mat4::from_translation(Vec3::new(d, 0.0, -40.0 * d)))?;
/// let camera = Camera::looking(Vec3::ZERO, Vec3::NEG_Z, target.aspect(), 0.1 * d, 100.0 * d);
/// // Once per frame: cull, choose LoDs (1 pixel over 480), extract what
/// // is newly needed, then draw into any render pass.
/// let stats = scene.update(device, queue, &camera, 480.0, 1.0)?;
/// let image = target.render_image(device, queue, |pass| scene.draw(pass))?;
/// assert_eq!(stats.visible, 2);
/// assert!(scene.lod_of(near) < scene.lod_of(far), "the far instance is coarser");
/// assert!(stats.triangles < 2 * mesh.triangle_count());
/// assert!(image.foreground_pixels() > 0);
/// # Ok(())
/// # }
/// ```
pub struct InstancedScene<'m> {
    config: RendererConfig,
    spacing: f32,
    models: Vec<ModelEntry<'m>>,
    live: usize,
    hierarchies: Vec<HierarchyEntry<'m>>,
    hierarchy_live: usize,
    /// Instances in the BVH's order, and the BVH over their bounds.
    order: Vec<InstanceId>,
    bvh: Option<obvhs::bvh2::Bvh2>,
    /// Instances were added or removed / moved since the BVH was made.
    rebuild: bool,
    refit: bool,
    refits: u32,
    stack: Vec<u32>,
    candidates: Vec<u32>,
    /// Visible instances of the last update, ascending, and of the one
    /// before (kept to reuse its allocation and to see who left the view).
    visible: Vec<InstanceId>,
    previous: Vec<InstanceId>,
    instance_buffer: Option<wgpu::Buffer>,
    instance_capacity: usize,
    compact: Vec<u32>,
    stitched: Vec<u32>,
    scratch: Vec<u16>,
}

impl std::fmt::Debug for InstancedScene<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InstancedScene")
            .field("models", &self.models.len())
            .field("instances", &self.live)
            .field("hierarchies", &self.hierarchies.len())
            .field("hierarchy_instances", &self.hierarchy_live)
            .field("visible", &self.visible.len())
            .field("bvh_nodes", &self.bvh.as_ref().map_or(0, |b| b.nodes.len()))
            .finish_non_exhaustive()
    }
}

impl<'m> InstancedScene<'m> {
    /// An empty scene whose models will be drawn with `config` (its strip
    /// mode decides restart or stitching).
    #[must_use]
    pub fn new(config: &RendererConfig) -> InstancedScene<'m> {
        InstancedScene {
            config: *config,
            spacing: DEFAULT_BUCKET_SPACING,
            models: Vec::new(),
            live: 0,
            hierarchies: Vec::new(),
            hierarchy_live: 0,
            order: Vec::new(),
            bvh: None,
            rebuild: false,
            refit: false,
            refits: 0,
            stack: Vec::new(),
            candidates: Vec::new(),
            visible: Vec::new(),
            previous: Vec::new(),
            instance_buffer: None,
            instance_capacity: 0,
            compact: Vec::new(),
            stitched: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Sets the bucket spacing `s` (see the module docs) for the models
    /// added from now on: 0.01 to 0.9; wider buckets hold fewer buffers and
    /// draw more triangles.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] outside 0.01..=0.9.
    pub fn set_bucket_spacing(&mut self, spacing: f32) -> Result<()> {
        if !(0.01..=0.9).contains(&spacing) {
            return Err(Error::InvalidArgument(format!(
                "bucket spacing {spacing} is outside 0.01..=0.9"
            )));
        }
        self.spacing = spacing;
        Ok(())
    }

    /// Adds `model`: its vertices (and their properties and texture, as
    /// [`StripRenderer::for_model_with`]) are uploaded once, its instances
    /// share them and its buckets.
    ///
    /// # Errors
    /// [`Error::Gpu`] or [`Error::InvalidArgument`] as
    /// [`StripRenderer::for_model_with`].
    ///
    /// Cost: the vertex upload, and O(buckets × log LoDs) for the bucket
    /// table; nothing is extracted until an instance needs it.
    pub fn add_model(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &'m MtsModel,
    ) -> Result<ModelId> {
        self.add_model_with(device, queue, model, &Appearance::default())
    }

    /// [`InstancedScene::add_model`] drawn with `appearance` (e.g. the
    /// checker texture over the model's UVs; what cannot be drawn is in
    /// [`InstancedScene::warnings`]).
    ///
    /// # Errors
    /// As [`InstancedScene::add_model`].
    pub fn add_model_with(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &'m MtsModel,
        appearance: &Appearance,
    ) -> Result<ModelId> {
        if self.models.len() >= u32::MAX as usize {
            return Err(Error::InvalidArgument("too many models".into()));
        }
        let renderer =
            StripRenderer::for_model_with(device, queue, &self.config, model, appearance)?;
        let (min, max) = mts::mesh::bounds_of(model.positions()).unwrap_or_default();
        // A model wider than f32 can say (coordinates near f32::MAX) gets
        // the largest finite bound, so that a transform that scales it down
        // still places it.
        let diagonal = (mts::mesh::diagonal_of(min, max) as f32).min(f32::MAX);
        let radius = (diagonal * 0.5).max(f32::MIN_POSITIVE);
        self.models.push(ModelEntry {
            model,
            renderer,
            local: Bound {
                centre: (min + max) * 0.5,
                radius,
            },
            diagonal,
            cursor: Extractor::new(model),
            buckets: buckets(model, self.spacing),
            slots: Vec::new(),
            free: Vec::new(),
        });
        Ok(ModelId(self.models.len() as u32 - 1))
    }

    /// Adds an instance of `model` at `transform` (model to world). It is
    /// drawn from the next [`InstancedScene::update`] on.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a model not of this scene, past
    /// [`MAX_INSTANCES`], or for a transform whose bounds are not finite.
    ///
    /// Cost: O(1); the BVH is rebuilt at the next update.
    pub fn add_instance(&mut self, model: ModelId, transform: Mat4) -> Result<InstanceId> {
        if self.live >= MAX_INSTANCES {
            return Err(Error::InvalidArgument(format!(
                "a scene holds at most {MAX_INSTANCES} instances"
            )));
        }
        let entry = self
            .models
            .get_mut(model.0 as usize)
            .ok_or_else(|| Error::InvalidArgument(format!("no model {model:?}")))?;
        let (bound, scale) = place(entry.local, transform)?;
        let instance = Instance {
            transform,
            bound,
            scale,
            bucket: NONE,
            lod: 0,
            live: true,
        };
        let slot = match entry.free.pop() {
            Some(i) => {
                entry.slots[i as usize] = instance;
                i
            }
            None => {
                entry.slots.push(instance);
                entry.slots.len() as u32 - 1
            }
        };
        self.live += 1;
        self.rebuild = true;
        Ok(InstanceId {
            model: model.0,
            slot,
        })
    }

    /// Moves instance `id` to `transform`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for an instance that was removed or a
    /// transform whose bounds are not finite.
    ///
    /// Cost: O(1); the BVH is refitted at the next update.
    pub fn set_transform(&mut self, id: InstanceId, transform: Mat4) -> Result<()> {
        let entry = self
            .models
            .get_mut(id.model as usize)
            .ok_or_else(|| Error::InvalidArgument(format!("no instance {id:?}")))?;
        let local = entry.local;
        let slot = entry
            .slots
            .get_mut(id.slot as usize)
            .filter(|s| s.live)
            .ok_or_else(|| Error::InvalidArgument(format!("no instance {id:?}")))?;
        (slot.bound, slot.scale) = place(local, transform)?;
        slot.transform = transform;
        self.refit = true;
        Ok(())
    }

    /// Removes instance `id` (its slot is reused by a later instance).
    /// Returns whether it was there.
    pub fn remove_instance(&mut self, id: InstanceId) -> bool {
        let Some(entry) = self.models.get_mut(id.model as usize) else {
            return false;
        };
        let Some(slot) = entry.slots.get_mut(id.slot as usize) else {
            return false;
        };
        if !slot.live {
            return false;
        }
        slot.live = false;
        slot.bucket = NONE;
        entry.free.push(id.slot);
        if entry.free.len() == entry.slots.len() {
            // The model's last instance: its slots are given back (a
            // removed id then finds no slot).
            entry.slots = Vec::new();
            entry.free = Vec::new();
        }
        self.live -= 1;
        self.rebuild = true;
        true
    }

    /// Instances in the scene, over all models (hierarchy instances:
    /// [`InstancedScene::hierarchy_instance_count`]).
    #[must_use]
    pub fn instance_count(&self) -> usize {
        self.live
    }

    /// Adds the view-dependent hierarchy `h`: its vertices (and their
    /// properties and texture, as [`crate::HierarchyRenderer::new`]) are
    /// uploaded once and shared by its instances, each of which keeps its
    /// own cut (see the module docs).
    ///
    /// # Errors
    /// As [`crate::HierarchyRenderer::with_appearance`].
    ///
    /// Cost: the vertex upload; nothing is selected until an update.
    pub fn add_hierarchy(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        h: &'m Hierarchy,
    ) -> Result<HierarchyId> {
        self.add_hierarchy_with(device, queue, h, &Appearance::default())
    }

    /// [`InstancedScene::add_hierarchy`] drawn with `appearance`.
    ///
    /// # Errors
    /// As [`InstancedScene::add_hierarchy`].
    pub fn add_hierarchy_with(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        h: &'m Hierarchy,
        appearance: &Appearance,
    ) -> Result<HierarchyId> {
        if self.hierarchies.len() >= u32::MAX as usize {
            return Err(Error::InvalidArgument("too many hierarchies".into()));
        }
        let renderer = vertex_renderer(device, queue, &self.config, h, appearance)?;
        let (min, max) = mts::mesh::bounds_of(h.positions()).unwrap_or_default();
        let diagonal = (mts::mesh::diagonal_of(min, max) as f32).min(f32::MAX);
        self.hierarchies.push(HierarchyEntry {
            h,
            renderer,
            local: Bound {
                centre: (min + max) * 0.5,
                radius: (diagonal * 0.5).max(f32::MIN_POSITIVE),
            },
            slots: Vec::new(),
            free: Vec::new(),
        });
        Ok(HierarchyId(self.hierarchies.len() as u32 - 1))
    }

    /// Adds an instance of hierarchy `id` at `transform` (model to world;
    /// a rotation, translation and uniform scale keep the pixel threshold
    /// exact, a non-uniform scale tightens it, see
    /// [`crate::hierarchy::instance_view`]). It is drawn from the next
    /// [`InstancedScene::update`] on.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a hierarchy not of this scene, past
    /// [`MAX_HIERARCHY_INSTANCES`], or for a transform that is not
    /// invertible or whose bounds are not finite.
    ///
    /// Cost: O(groups + clusters) for the instance's cut tables.
    pub fn add_hierarchy_instance(
        &mut self,
        id: HierarchyId,
        transform: Mat4,
    ) -> Result<HierarchyInstanceId> {
        if self.hierarchy_live >= MAX_HIERARCHY_INSTANCES {
            return Err(Error::InvalidArgument(format!(
                "a scene holds at most {MAX_HIERARCHY_INSTANCES} hierarchy instances"
            )));
        }
        let entry = self
            .hierarchies
            .get_mut(id.0 as usize)
            .ok_or_else(|| Error::InvalidArgument(format!("no hierarchy {id:?}")))?;
        let bound = place_hierarchy(entry.local, transform)?;
        let instance = HierarchyInstance {
            transform,
            bound,
            view: ViewDependent::new(entry.h),
            arena: ArenaIndices::default(),
            last: HierarchyFrame::default(),
            entry: NONE,
        };
        let slot = match entry.free.pop() {
            Some(i) => {
                entry.slots[i as usize] = Some(instance);
                i
            }
            None => {
                entry.slots.push(Some(instance));
                entry.slots.len() as u32 - 1
            }
        };
        self.hierarchy_live += 1;
        Ok(HierarchyInstanceId {
            hierarchy: id.0,
            slot,
        })
    }

    /// Moves hierarchy instance `id` to `transform`; its cut follows at
    /// the next update (coherently: only what changed is walked).
    ///
    /// # Errors
    /// As [`InstancedScene::add_hierarchy_instance`], and for an instance
    /// that was removed.
    pub fn set_hierarchy_transform(
        &mut self,
        id: HierarchyInstanceId,
        transform: Mat4,
    ) -> Result<()> {
        let entry = self
            .hierarchies
            .get_mut(id.hierarchy as usize)
            .ok_or_else(|| Error::InvalidArgument(format!("no instance {id:?}")))?;
        let local = entry.local;
        let instance = entry
            .slots
            .get_mut(id.slot as usize)
            .and_then(Option::as_mut)
            .ok_or_else(|| Error::InvalidArgument(format!("no instance {id:?}")))?;
        instance.bound = place_hierarchy(local, transform)?;
        instance.transform = transform;
        Ok(())
    }

    /// Removes hierarchy instance `id` (its cut and index buffer go; its
    /// slot is reused). Returns whether it was there.
    pub fn remove_hierarchy_instance(&mut self, id: HierarchyInstanceId) -> bool {
        let Some(entry) = self.hierarchies.get_mut(id.hierarchy as usize) else {
            return false;
        };
        let Some(slot) = entry.slots.get_mut(id.slot as usize) else {
            return false;
        };
        if slot.take().is_none() {
            return false;
        }
        entry.free.push(id.slot);
        if entry.free.len() == entry.slots.len() {
            entry.slots = Vec::new();
            entry.free = Vec::new();
        }
        self.hierarchy_live -= 1;
        true
    }

    /// Hierarchy instances in the scene, over all hierarchies.
    #[must_use]
    pub fn hierarchy_instance_count(&self) -> usize {
        self.hierarchy_live
    }

    /// What the last update did for hierarchy instance `id` and what it
    /// draws (as [`crate::HierarchyRenderer::update`] reports it; its
    /// `gpu_bytes` are its index buffer's); `None` when that update culled
    /// it whole, or it is removed.
    #[must_use]
    pub fn hierarchy_frame(&self, id: HierarchyInstanceId) -> Option<HierarchyFrame> {
        let instance = self
            .hierarchies
            .get(id.hierarchy as usize)?
            .slots
            .get(id.slot as usize)?
            .as_ref()?;
        (instance.entry != NONE).then_some(instance.last)
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

    /// The instanced draws of the last update, in the order
    /// [`InstancedScene::draw`] records them (models as added, buckets
    /// finest first). Cost: O(buckets of all models); no allocation.
    pub fn draw_groups(&self) -> impl Iterator<Item = DrawGroup<'_>> + '_ {
        self.models.iter().enumerate().flat_map(|(m, entry)| {
            entry.buckets.iter().filter_map(move |b| {
                let indices = b.buffer.as_ref().filter(|_| b.users > 0)?;
                Some(DrawGroup {
                    model: ModelId(m as u32),
                    lod: b.lod as usize,
                    index_count: b.len,
                    indices,
                    index_format: entry.renderer.index_format(),
                    instances: b.first..b.first + b.users,
                })
            })
        })
    }

    /// The visible instances' transforms of the last update (column-major
    /// `f32` 4 × 4, [`INSTANCE_BYTES`] each, grouped as
    /// [`InstancedScene::draw_groups`] says); `None` before the first
    /// update with a visible instance. It can be copied from.
    #[must_use]
    pub fn instance_buffer(&self) -> Option<&wgpu::Buffer> {
        self.instance_buffer.as_ref()
    }

    /// The LoD instance `id` drew in the last update (its bucket's), `None`
    /// when it was not drawn or is removed.
    #[must_use]
    pub fn lod_of(&self, id: InstanceId) -> Option<usize> {
        let slot = self.slot(id)?;
        let b = self.models[id.model as usize]
            .buckets
            .get(slot.bucket as usize)?;
        Some(b.lod as usize)
    }

    /// The LoD the screen-space error asked for instance `id` in the last
    /// update (its bucket is at least as fine), `None` as
    /// [`InstancedScene::lod_of`].
    #[must_use]
    pub fn wanted_lod_of(&self, id: InstanceId) -> Option<usize> {
        let slot = self.slot(id)?;
        (slot.bucket != NONE).then_some(slot.lod as usize)
    }

    /// What the renderer of `model` could not draw (a missing or corrupt
    /// texture), as [`StripRenderer::warnings`].
    #[must_use]
    pub fn warnings(&self, model: ModelId) -> &[String] {
        self.models
            .get(model.0 as usize)
            .map_or(&[], |e| e.renderer.warnings())
    }

    /// Width and height of the base-colour texture `model` is drawn with,
    /// `None` when it is drawn untextured (or is not of this scene), as
    /// [`StripRenderer::texture_size`].
    #[must_use]
    pub fn texture_size(&self, model: ModelId) -> Option<(u32, u32)> {
        self.models.get(model.0 as usize)?.renderer.texture_size()
    }

    /// Where the scene's memory goes now.
    #[must_use]
    pub fn memory(&self) -> SceneMemory {
        let mut m = SceneMemory {
            instances: self.live,
            ..SceneMemory::default()
        };
        for entry in &self.models {
            // Slots (live or free) and the free list.
            m.cpu_instance_bytes += entry.slots.capacity() * std::mem::size_of::<Instance>()
                + entry.free.capacity() * 4;
            m.cpu_shared_bytes += entry.cursor.memory_bytes()
                + entry.buckets.capacity() * std::mem::size_of::<Bucket>();
            m.gpu_vertex_bytes += entry.renderer.vertex_count() * crate::VERTEX_BYTES;
            for b in &entry.buckets {
                if let Some(buffer) = &b.buffer {
                    m.gpu_index_bytes += buffer.size() as usize;
                    m.buffers += 1;
                }
            }
        }
        m.cpu_instance_bytes += self.order.capacity() * std::mem::size_of::<InstanceId>()
            + self.candidates.capacity() * 4
            + self.stack.capacity() * 4
            + (self.visible.capacity() + self.previous.capacity())
                * std::mem::size_of::<InstanceId>();
        if let Some(bvh) = &self.bvh {
            m.cpu_instance_bytes += bvh.nodes.capacity()
                * std::mem::size_of::<obvhs::bvh2::node::Bvh2Node>()
                + bvh.primitive_indices.capacity() * 4
                + bvh.primitives_to_nodes.capacity() * 4
                + bvh.parents.capacity() * 4;
        }
        for entry in &self.hierarchies {
            m.cpu_instance_bytes += entry.slots.capacity()
                * std::mem::size_of::<Option<HierarchyInstance<'_>>>()
                + entry.free.capacity() * 4;
            m.gpu_vertex_bytes += entry.renderer.vertex_count() * crate::VERTEX_BYTES;
            for instance in entry.slots.iter().flatten() {
                m.cpu_instance_bytes += instance.view.memory_bytes();
                let bytes = instance.arena.gpu_bytes();
                m.gpu_index_bytes += bytes;
                m.buffers += usize::from(bytes > 0);
            }
        }
        m.gpu_instance_bytes = self
            .instance_buffer
            .as_ref()
            .map_or(0, |b| b.size() as usize);
        m
    }

    fn slot(&self, id: InstanceId) -> Option<&Instance> {
        self.models
            .get(id.model as usize)?
            .slots
            .get(id.slot as usize)
            .filter(|s| s.live)
    }

    /// Culls the instances against `camera`'s frustum, gives each visible
    /// instance its LoD by screen-space error (`pixel_error` pixels at a
    /// viewport `viewport_height` pixels high) and its bucket, extracts
    /// the buckets that became needed, frees those unused for
    /// [`KEEP_UPDATES`] updates, and writes the visible instances'
    /// transforms grouped by bucket. Also writes the camera.
    ///
    /// # Errors
    /// [`Error::Gpu`] when a buffer would pass the device's
    /// `max_buffer_size`.
    ///
    /// Cost: O(visible · log instances) for culling, O(visible · log LoDs)
    /// for the LoD choice, the coherent walks between the buckets
    /// extracted, O(visible) for the transforms; plus O(n log n) for the
    /// BVH after instances were added or removed, O(n) after they moved.
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        viewport_height: f32,
        pixel_error: f32,
    ) -> Result<FrameStats> {
        let mut stats = FrameStats::default();
        for entry in &mut self.models {
            entry.renderer.set_camera(queue, camera);
        }
        for entry in &mut self.hierarchies {
            entry.renderer.set_camera(queue, camera);
        }
        stats.bvh = self.update_bvh();
        let planes = frustum_planes(camera.view_proj);
        {
            let (order, models) = (&self.order, &self.models);
            cull(
                self.bvh.as_ref(),
                |p| {
                    let id = order[p as usize];
                    models[id.model as usize].slots[id.slot as usize].bound
                },
                &planes,
                &mut self.stack,
                &mut self.candidates,
            );
        }
        // Last update's buckets, to count changes; then this update's.
        for entry in &mut self.models {
            for b in &mut entry.buckets {
                b.users = 0;
                b.placed = 0;
            }
        }
        let projection = camera.projection(viewport_height);
        std::mem::swap(&mut self.visible, &mut self.previous);
        self.visible.clear();
        self.visible
            .extend(self.candidates.iter().map(|&i| self.order[i as usize]));
        self.visible.sort_unstable();
        for &id in &self.previous {
            if self.visible.binary_search(&id).is_err() {
                if let Some(s) = self.models[id.model as usize]
                    .slots
                    .get_mut(id.slot as usize)
                {
                    s.bucket = NONE;
                }
            }
        }
        for &id in &self.visible {
            let entry = &mut self.models[id.model as usize];
            let slot = &mut entry.slots[id.slot as usize];
            // The bound's nearest depth: the instance's nearest point is no
            // nearer (infinite pixels per unit, full detail, at 0).
            let nearest = (camera.depth_of(slot.bound.centre) - slot.bound.radius).max(0.0);
            let lod = mts::lod_for_screen_error(
                entry.model.collapses(),
                entry.diagonal,
                slot.scale,
                projection.pixels_per_unit(nearest),
                pixel_error,
            );
            // The coarsest bucket at least as fine as `lod`.
            let bucket = entry.buckets.partition_point(|b| b.lod as usize <= lod) - 1;
            if slot.bucket != bucket as u32 {
                stats.lod_changes += 1;
            }
            slot.bucket = bucket as u32;
            slot.lod = lod as u32;
            let b = &mut entry.buckets[bucket];
            b.users += 1;
            stats.triangles += b.triangles as usize;
            stats.triangles_full_detail += entry.model.triangle_count(0);
        }
        // Extract what is newly needed (finer to coarser, each from the
        // last), free what has been idle too long, and lay out the groups.
        let stitched = self.config.strip_mode == StripMode::Stitched;
        let mut groups = 0u32;
        for entry in &mut self.models {
            let format = entry.renderer.index_format();
            for b in &mut entry.buckets {
                if b.users == 0 {
                    b.idle = b.idle.saturating_add(1);
                    if b.buffer.is_some() && b.idle > KEEP_UPDATES {
                        b.buffer = None;
                        stats.evictions += 1;
                    }
                    continue;
                }
                b.idle = 0;
                b.first = groups;
                groups += b.users;
                stats.draws += 1;
                if b.buffer.is_some() {
                    stats.indices_drawn += b.users as usize * b.len as usize;
                    continue;
                }
                entry.cursor.set_lod(b.lod as usize);
                entry.cursor.write_compact(&mut self.compact);
                let indices = if stitched {
                    stitch_restart_buffer(&self.compact, &mut self.stitched);
                    &self.stitched
                } else {
                    &self.compact
                };
                b.len = indices.len() as u32;
                let (buffer, bytes) =
                    index_buffer(device, queue, format, indices, &mut self.scratch)?;
                b.buffer = Some(buffer);
                stats.upload_bytes += bytes;
                stats.extractions += 1;
                stats.indices_drawn += b.users as usize * b.len as usize;
            }
        }
        stats.visible = self.visible.len();
        // Hierarchy instances: each seen one's cut follows the camera in
        // its model space; transforms after the models' groups.
        let mut entries = groups;
        for entry in &mut self.hierarchies {
            let format = entry.renderer.index_format();
            for instance in entry.slots.iter_mut().flatten() {
                instance.entry = NONE;
                let b = instance.bound;
                if !sphere_in_frustum(&planes, b.centre, b.radius) {
                    continue;
                }
                // Checked when placed: the transform is invertible.
                let Some(view) = instance_view(
                    camera,
                    instance.transform,
                    viewport_height,
                    pixel_error,
                    true,
                ) else {
                    continue;
                };
                let update = instance.view.update(&view);
                let upload = instance.arena.update(
                    device,
                    queue,
                    format,
                    self.config.strip_mode,
                    instance.view.buffer(),
                    instance.view.dirty_ranges(),
                )?;
                instance.last = HierarchyFrame {
                    update,
                    triangles: instance.view.triangle_count(),
                    indices_sent: instance.view.indices_sent(),
                    indices_drawn: instance.arena.indices_drawn(),
                    upload,
                    gpu_bytes: instance.arena.gpu_bytes(),
                    cpu_bytes: instance.view.memory_bytes(),
                };
                instance.entry = entries;
                entries += 1;
                let changed = update.groups_entered
                    + update.groups_left
                    + update.groups_changed
                    + update.clusters_entered
                    + update.clusters_left;
                stats.visible += 1;
                stats.lod_changes += usize::from(changed > 0);
                stats.triangles += instance.last.triangles;
                stats.triangles_full_detail += entry.h.triangle_count();
                stats.indices_drawn += instance.last.indices_drawn;
                stats.upload_bytes += upload.bytes;
                stats.draws += usize::from(instance.last.indices_drawn > 0);
            }
        }
        stats.upload_bytes += self.write_transforms(device, queue, entries as usize)?;
        if self.live == 0 && self.hierarchy_live == 0 {
            // Emptied: the per-update lists and the instance buffer are
            // given back, as a new scene has none.
            self.order = Vec::new();
            self.stack = Vec::new();
            self.candidates = Vec::new();
            self.visible = Vec::new();
            self.previous = Vec::new();
            self.instance_buffer = None;
            self.instance_capacity = 0;
        }
        Ok(stats)
    }

    /// Writes the visible instances' transforms, each at its bucket's
    /// group, and the visible hierarchy instances' at their entries; grows
    /// the instance buffer (doubling) when needed. Returns the bytes
    /// written.
    fn write_transforms(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        count: usize,
    ) -> Result<usize> {
        if count == 0 {
            return Ok(0);
        }
        if count > self.instance_capacity {
            let capacity = count.next_power_of_two();
            let bytes = capacity as u64 * INSTANCE_BYTES;
            let max = device.limits().max_buffer_size;
            if bytes > max {
                return Err(Error::Gpu(format!(
                    "{count} visible instances need a {bytes}-byte instance buffer, above the \
                     device's max_buffer_size {max}"
                )));
            }
            self.instance_buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mts scene instances"),
                size: bytes,
                // COPY_SRC: readable by hosts and tests (`instance_buffer`).
                usage: wgpu::BufferUsages::VERTEX
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }));
            self.instance_capacity = capacity;
        }
        let buffer = self.instance_buffer.as_ref().expect("made above");
        let size = count as u64 * INSTANCE_BYTES;
        let Some(mut view) =
            queue.write_buffer_with(buffer, 0, wgpu::BufferSize::new(size).expect("count > 0"))
        else {
            return Err(Error::Gpu(
                "cannot map the instance buffer for writing".into(),
            ));
        };
        for &id in &self.visible {
            let entry = &mut self.models[id.model as usize];
            let slot = &entry.slots[id.slot as usize];
            let b = &mut entry.buckets[slot.bucket as usize];
            let at = (b.first + b.placed) as usize * INSTANCE_BYTES as usize;
            b.placed += 1;
            view.slice(at..at + INSTANCE_BYTES as usize)
                .copy_from_slice(bytemuck::cast_slice(&slot.transform.to_cols_array()));
        }
        for instance in self
            .hierarchies
            .iter()
            .flat_map(|e| e.slots.iter().flatten())
        {
            if instance.entry == NONE {
                continue;
            }
            let at = instance.entry as usize * INSTANCE_BYTES as usize;
            view.slice(at..at + INSTANCE_BYTES as usize)
                .copy_from_slice(bytemuck::cast_slice(&instance.transform.to_cols_array()));
        }
        Ok(size as usize)
    }

    /// Records one instanced draw per (model, bucket) with visible
    /// instances into `pass`, then one draw per visible hierarchy
    /// instance.
    ///
    /// Cost: three binds per model or hierarchy with visible instances
    /// plus one `draw_indexed` per group or hierarchy instance.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        let Some(instances) = &self.instance_buffer else {
            return;
        };
        for entry in &self.models {
            let mut bound = false;
            for b in &entry.buckets {
                let (Some(buffer), true) = (&b.buffer, b.users > 0) else {
                    continue;
                };
                if b.len == 0 {
                    continue;
                }
                if !bound {
                    entry.renderer.bind(pass, true);
                    pass.set_vertex_buffer(1, instances.slice(..));
                    bound = true;
                }
                pass.set_index_buffer(buffer.slice(..), entry.renderer.index_format());
                pass.draw_indexed(0..b.len, 0, b.first..b.first + b.users);
            }
        }
        for entry in &self.hierarchies {
            let mut bound = false;
            for instance in entry.slots.iter().flatten() {
                if instance.entry == NONE || instance.arena.indices_drawn() == 0 {
                    continue;
                }
                if !bound {
                    entry.renderer.bind(pass, true);
                    pass.set_vertex_buffer(1, instances.slice(..));
                    bound = true;
                }
                let e = instance.entry;
                instance
                    .arena
                    .draw(pass, entry.renderer.index_format(), e..e + 1);
            }
        }
    }

    /// Rebuilds the BVH after instances were added or removed (or after
    /// [`REFITS_BEFORE_REBUILD`] refits), refits it after they moved.
    fn update_bvh(&mut self) -> BvhUpdate {
        if self.rebuild || (self.refit && self.refits >= REFITS_BEFORE_REBUILD) {
            self.order.clear();
            let mut boxes = Vec::with_capacity(self.live);
            for (m, entry) in self.models.iter().enumerate() {
                for (s, slot) in entry.slots.iter().enumerate() {
                    if slot.live {
                        self.order.push(InstanceId {
                            model: m as u32,
                            slot: s as u32,
                        });
                        boxes.push(aabb(slot.bound));
                    }
                }
            }
            self.bvh = (!boxes.is_empty()).then(|| build_bvh(&boxes));
            (self.rebuild, self.refit, self.refits) = (false, false, 0);
            return BvhUpdate::Rebuilt;
        }
        if !self.refit {
            return BvhUpdate::Kept;
        }
        self.refit = false;
        self.refits += 1;
        if let Some(bvh) = &mut self.bvh {
            let (order, models) = (&self.order, &self.models);
            refit(bvh, |p| {
                let id = order[p as usize];
                models[id.model as usize].slots[id.slot as usize].bound
            });
        }
        BvhUpdate::Refitted
    }
}

/// The buckets of `model` at `spacing` (see the module docs): LoDs
/// ascending, each distinct, the first LoD 0.
fn buckets(model: &MtsModel, spacing: f32) -> Vec<Bucket> {
    let full = model.triangle_count(0) as f64;
    let mut out: Vec<Bucket> = Vec::new();
    let mut budget = full;
    loop {
        let lod = model.lod_for_triangles(budget.floor() as usize) as u32;
        if out.last().is_none_or(|b| b.lod < lod) {
            out.push(Bucket {
                lod,
                triangles: model.triangle_count(lod as usize) as u32,
                buffer: None,
                len: 0,
                users: 0,
                idle: 0,
                first: 0,
                placed: 0,
            });
        }
        if lod as usize == model.max_lod() || budget < 1.0 {
            break;
        }
        budget *= 1.0 - f64::from(spacing);
    }
    out
}

/// A new index buffer holding `indices` (restart value `u32::MAX`) in
/// `format`, and the bytes written (4-byte aligned: a `u16` buffer of an
/// odd count ends with a restart).
fn index_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    format: wgpu::IndexFormat,
    indices: &[u32],
    scratch: &mut Vec<u16>,
) -> Result<(wgpu::Buffer, usize)> {
    let size = match format {
        wgpu::IndexFormat::Uint16 => 2 * ((indices.len() as u64 + 1) & !1),
        wgpu::IndexFormat::Uint32 => 4 * indices.len() as u64,
    }
    .max(4);
    let max = device.limits().max_buffer_size;
    if size > max {
        return Err(Error::Gpu(format!(
            "a {size}-byte index buffer is above the device's max_buffer_size {max}"
        )));
    }
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mts scene bucket"),
        size,
        // COPY_SRC: readable by hosts and tests (`draw_groups`).
        usage: wgpu::BufferUsages::INDEX
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let bytes = if indices.is_empty() {
        0
    } else {
        write_index_range(
            queue,
            &buffer,
            format,
            indices,
            0..indices.len(),
            0,
            scratch,
        )
    };
    Ok((buffer, bytes))
}

/// The world-space bound of a hierarchy instance (as [`place`]), once its
/// transform is known to be invertible with every axis scale above 0 (the
/// cut is selected in model space).
fn place_hierarchy(local: Bound, transform: Mat4) -> Result<Bound> {
    let (bound, _) = place(local, transform)?;
    let invertible = [transform.x_axis, transform.y_axis, transform.z_axis]
        .iter()
        .all(|c| c.truncate().length() > 0.0)
        && transform.inverse().is_finite()
        && transform.determinant() != 0.0;
    if !invertible {
        return Err(Error::InvalidArgument(format!(
            "a hierarchy instance's transform must be invertible: {transform}"
        )));
    }
    Ok(bound)
}

/// The box around a bound.
fn aabb(b: Bound) -> obvhs::aabb::Aabb {
    let r = Vec3::splat(b.radius);
    obvhs::aabb::Aabb::new((b.centre - r).into(), (b.centre + r).into())
}

/// The world-space bound of a model's `local` bound under `transform`, and
/// the transform's largest axis scale (which bounds a uniform or
/// non-uniform scale).
fn place(local: Bound, transform: Mat4) -> Result<(Bound, f32)> {
    // A column of tiny (denormal) or huge entries has a square that
    // underflows or overflows in f32: its length is then taken in f64.
    let scale = [transform.x_axis, transform.y_axis, transform.z_axis]
        .iter()
        .map(|c| match c.truncate().length() {
            l if l == 0.0 || l.is_infinite() => c.truncate().as_dvec3().length() as f32,
            l => l,
        })
        .fold(0.0f32, f32::max);
    let bound = Bound {
        centre: transform.transform_point3(local.centre),
        radius: local.radius * scale,
    };
    if !(bound.centre.is_finite() && bound.radius.is_finite() && scale > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "an instance's bounds are not finite in f32, or its scale is 0 (centre {}, radius {})",
            bound.centre, bound.radius
        )));
    }
    Ok((bound, scale))
}

/// A BVH over `boxes` (obvhs' fast build, up to 8 instances a leaf).
/// O(n log n).
fn build_bvh(boxes: &[obvhs::aabb::Aabb]) -> obvhs::bvh2::Bvh2 {
    let mut build_time = std::time::Duration::ZERO;
    obvhs::bvh2::builder::build_bvh2(boxes, obvhs::BvhBuildParams::fast_build(), &mut build_time)
}

/// Refits `bvh` to the primitives' current bounds: each leaf's box from
/// its primitives, then the inner nodes bottom-up. O(n).
fn refit(bvh: &mut obvhs::bvh2::Bvh2, bound: impl Fn(u32) -> Bound) {
    for n in 0..bvh.nodes.len() {
        let node = bvh.nodes[n];
        if !node.is_leaf() {
            continue;
        }
        let first = node.first_index as usize;
        let mut bounds = obvhs::aabb::Aabb::empty();
        for &p in &bvh.primitive_indices[first..first + node.prim_count as usize] {
            bounds = bounds.union(&aabb(bound(p)));
        }
        bvh.nodes[n].set_aabb(bounds);
    }
    bvh.refit_all();
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
    bvh: Option<&obvhs::bvh2::Bvh2>,
    bound: impl Fn(u32) -> Bound,
    planes: &[Vec4; 6],
    stack: &mut Vec<u32>,
    visible: &mut Vec<u32>,
) {
    visible.clear();
    stack.clear();
    let Some(bvh) = bvh.filter(|b| !b.nodes.is_empty()) else {
        return;
    };
    let (nodes, leaves) = (&bvh.nodes, &bvh.primitive_indices);
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
                let inst = bound(p);
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
        let boxes: Vec<_> = instances.iter().map(|&b| aabb(b)).collect();
        let mut bvh = build_bvh(&boxes);
        let (mut stack, mut visible) = (Vec::new(), Vec::new());
        let mut seen = 0;
        // The same after every instance moved and the BVH was refitted.
        let moved: Vec<Bound> = instances
            .iter()
            .enumerate()
            .map(|(i, b)| Bound {
                centre: b.centre
                    + Vec3::new(hash01(i as u32 + 7) * 9.0, 0.0, -hash01(i as u32) * 9.0),
                radius: b.radius * (0.5 + hash01(i as u32 + 3)),
            })
            .collect();
        for k in 0..40u32 {
            let instances = if k < 20 { &instances } else { &moved };
            if k == 20 {
                refit(&mut bvh, |p| moved[p as usize]);
            }
            let eye = Vec3::new(
                hash01(k) * 90.0,
                2.0 + hash01(k + 50) * 20.0,
                hash01(k + 99) * 90.0,
            );
            let target = Vec3::new(hash01(k + 7) * 90.0, 0.0, hash01(k + 13) * 90.0);
            let cam = Camera::looking(eye, target, 1.5, 0.1, 60.0 + 40.0 * hash01(k + 3));
            let planes = frustum_planes(cam.view_proj);
            cull(
                Some(&bvh),
                |p| instances[p as usize],
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
        assert!(seen > 1000, "the cameras see something ({seen})");
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

    #[test]
    fn buckets_are_a_geometric_series_of_triangle_counts() {
        use mts::mesh::generate::Generated;
        let mesh: mts::Mesh = "torus:20k".parse::<Generated>().unwrap().build();
        let (model, _, _) = mts::model::build_from_mesh(
            &mesh,
            &mts::model::PipelineOptions::default(),
            &mut |_, _| {},
        );
        let full = model.triangle_count(0) as f64;
        for spacing in [0.1f32, 0.3] {
            let b = buckets(&model, spacing);
            assert_eq!(b[0].lod, 0);
            assert_eq!(b.last().unwrap().lod as usize, model.max_lod());
            for (i, w) in b.windows(2).enumerate() {
                assert!(w[0].lod < w[1].lod);
                // Each bucket is the finest LoD within its budget: the
                // next finer LoD has more triangles than the budget that
                // chose it, so a step never drops far more than `spacing`.
                assert_eq!(
                    w[1].triangles as usize,
                    model.triangle_count(w[1].lod as usize)
                );
                let ratio = f64::from(w[1].triangles) / f64::from(w[0].triangles);
                assert!(ratio < 1.0, "{i}: {ratio}");
            }
            let sum: f64 = b.iter().map(|b| f64::from(b.triangles)).sum();
            // At most the geometric series' sum (plus the last buckets,
            // where LoDs are fewer than budgets).
            assert!(
                sum <= full / f64::from(spacing) + 1.0,
                "{spacing}: {sum} for {full}"
            );
            assert!(
                sum >= full / f64::from(spacing) * 0.8,
                "{spacing}: {sum} for {full}"
            );
        }
    }
}
