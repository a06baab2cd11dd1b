//! `mts bench view-dependent`: detail per region along a fixed flight, for
//! every method that varies its resolution within one object — the strip
//! hierarchy (`mts::hierarchy`), meshoptimizer's cluster LoD
//! (`mts::peers::clusterlod`), the cluster tree's variable resolution
//! (section 7 of its paper) — and the per-object MTS model, all with the
//! same cameras and the same pixel threshold.
//!
//! **The flight** ([`flight`]): a mesh whose bounding box is flat along `y`
//! (a terrain: `y` extent under a quarter of the largest) is flown over
//! low, from one corner to the opposite one, looking ahead and down; any
//! other mesh is circled once and a half while the eye closes in from 2.2
//! to 0.8 bounding radii of its centre.
//!
//! **Per frame and method**: triangles drawn (the selected cut, no
//! culling, so that the methods compare by their LoD choice alone; the
//! hierarchy's row adds what survives frustum culling), indices sent per
//! triangle (3 for lists), the milliseconds of selection and update
//! (hierarchy: [`mts::hierarchy::ViewDependent::update`]; cluster LoD: its
//! cut and the gathered triangle list; cluster tree: its
//! `view_dependent`; MTS: the LoD choice and the coherent extractor's
//! walk), cracks, popping and the triangles that changed.
//!
//! - **Cracks**: edges taken by point (vertices at the same position are
//!   one point, so a torn seam is a crack too) drawn a different number of
//!   times in each direction, unless both points lie on the input's
//!   boundary.
//! - **Popping**: the largest distance, in pixels at its depth, from a
//!   vertex drawn in one frame but not the next to the surface the next
//!   frame draws, and the same backwards: how far the drawn surface jumps
//!   where it changed. (Measured first against the changed triangles
//!   alone, it reported 27 px on the terrain where a contraction removed a
//!   vertical sliver with its whole fan: nothing replaces such a vertex,
//!   the surface around it stays.)
//! - **Image error** (with an adapter, on [`COMPARED_FRAMES`] frames): the
//!   method's frame against the full-detail frame drawn 4 × 4 times denser
//!   and box-filtered, over the full-detail frame at one sample per pixel
//!   ([`mts_render::image_error`]), pooled over those frames.

use crate::args::MeshSource;
use crate::bench::results::{ViewDependentRow, ViewDependentRun};
use crate::commands::render::Size;
use crate::stdout::outln;
use anyhow::{Context, Result};
use clap::Args;
use glam::Vec3;
use mts::hierarchy::{self, Frustum, HierarchyOptions, View, ViewDependent};
use mts::mesh::Mesh;
use mts::peers::clusterlod::ClusterLod;
use mts::screen_error::{nearest_distance, Projection};
use mts::{Extractor, LodSource};
use mts_render::headless::HeadlessTarget;
use mts_render::image_error::{ImageError, ReferenceTarget};
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
use std::collections::HashMap;
use std::time::Instant;

/// Frames of the flight compared with full detail, at `(k + 0.5) / n`.
pub const COMPARED_FRAMES: usize = 3;

#[derive(Args)]
pub struct BenchViewDependentArgs {
    /// The mesh (OBJ, PLY, glTF) or `--generated NAME:SIZE`; without
    /// either, `terrain:1M`.
    #[command(flatten)]
    source: MeshSource,
    /// The screen-space errors allowed, in pixels: a row per method each.
    #[arg(long, value_delimiter = ',', default_value = "1",
          value_parser = crate::args::pixel_error)]
    pixel_error: Vec<f32>,
    /// Frames along the flight (2 to 10,000): the default crosses it in
    /// five seconds at 60 Hz.
    #[arg(long, default_value_t = 300, allow_negative_numbers = true,
          value_parser = crate::args::count_in::<2, 10_000>)]
    frames: usize,
    /// Image size in pixels (the viewport the thresholds refer to).
    #[arg(long, default_value = "640x360")]
    size: Size,
    /// The hierarchy's triangles per cluster, at most.
    #[arg(long, default_value_t = HierarchyOptions::default().cluster_triangles,
          value_parser = crate::args::count_in::<8, 4096>)]
    cluster_triangles: usize,
    /// The hierarchy's clusters per group, at most.
    #[arg(long, default_value_t = HierarchyOptions::default().group_clusters,
          value_parser = crate::args::count_in::<2, 64>)]
    group_clusters: usize,
    /// The band slack of the hierarchy's group models (see `mts build
    /// --band-slack`).
    #[arg(long, default_value_t = HierarchyOptions::default().pipeline.build.band_slack,
          value_parser = crate::args::band_slack)]
    band_slack: f64,
    /// Skip the image error (no adapter is opened).
    #[arg(long)]
    no_images: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// What [`measure`] flies: the input, the thresholds, the flight's frames
/// and viewport, whether images are compared, the hierarchy's settings.
pub struct FlightSpec<'a> {
    pub mesh: &'a Mesh,
    /// The input's name, as the run reports it.
    pub name: &'a str,
    /// The screen-space errors allowed, in pixels: a row per method each.
    pub pixel_errors: &'a [f32],
    /// Frames along the flight (at least 2).
    pub frames: usize,
    /// The viewport the thresholds refer to, in pixels.
    pub width: u32,
    pub height: u32,
    /// Compare images with full detail (opens an adapter).
    pub images: bool,
    pub options: HierarchyOptions,
}

/// The eye and the point it looks at, `t` in 0..=1 along the flight over
/// the box `lo..hi`; and whether the flight is the terrain's.
pub fn flight(lo: Vec3, hi: Vec3, t: f32) -> (Vec3, Vec3, bool) {
    let extent = hi - lo;
    let largest = extent.max_element().max(f32::MIN_POSITIVE);
    let centre = 0.5 * (lo + hi);
    if extent.y < 0.25 * largest {
        // Low over the terrain, corner to corner, looking ahead and down.
        let from = Vec3::new(lo.x + 0.05 * extent.x, 0.0, lo.z + 0.05 * extent.z);
        let to = Vec3::new(hi.x - 0.05 * extent.x, 0.0, hi.z - 0.25 * extent.z);
        let ground = from.lerp(to, t);
        let eye = Vec3::new(ground.x, hi.y + 0.06 * largest, ground.z);
        let ahead = (to - from).normalize_or(Vec3::X);
        let target = eye + 0.4 * largest * ahead - Vec3::new(0.0, 0.12 * largest, 0.0);
        (eye, target, true)
    } else {
        let radius = 0.5 * extent.length();
        let angle = t * 3.0 * std::f32::consts::PI;
        let distance = radius * (2.2 - 1.4 * t);
        let eye = centre
            + Vec3::new(
                distance * angle.cos(),
                0.2 * radius * (2.0 * angle).sin(),
                distance * angle.sin(),
            );
        (eye, centre, false)
    }
}

/// The flight's camera at `t`.
pub(crate) fn camera_at(lo: Vec3, hi: Vec3, t: f32, aspect: f32) -> (Camera, Vec3) {
    let (eye, target, _) = flight(lo, hi, t);
    let scale = (hi - lo).length().max(f32::MIN_POSITIVE);
    (
        Camera::looking(eye, target, aspect, 1e-3 * scale, 10.0 * scale),
        eye,
    )
}

/// FxHash's multiply-and-rotate: the edge maps take millions of keys a
/// frame on the large inputs, where SipHash's resistance to chosen keys
/// buys nothing and costs most of the time.
#[derive(Default, Clone, Copy)]
struct FastHasher(u64);

impl FastHasher {
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl std::hash::Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u32(&mut self, x: u32) {
        self.add(u64::from(x));
    }

    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

type FastMap<K, V> = HashMap<K, V, std::hash::BuildHasherDefault<FastHasher>>;

/// Points of `positions` (vertices at one position are one point).
fn points_of(positions: &[Vec3]) -> Vec<u32> {
    let mut first: FastMap<[u32; 3], u32> =
        FastMap::with_capacity_and_hasher(positions.len(), Default::default());
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first
                .entry(p.to_array().map(f32::to_bits))
                .or_insert(i as u32)
        })
        .collect()
}

/// The edge `a -> b` between points: its key (the smaller point first)
/// and its direction (+1 from the smaller).
fn edge_key(a: u32, b: u32) -> (u64, i32) {
    if a < b {
        ((u64::from(a) << 32) | u64::from(b), 1)
    } else {
        ((u64::from(b) << 32) | u64::from(a), -1)
    }
}

/// The points of an edge key.
fn edge_points(key: u64) -> (usize, usize) {
    ((key >> 32) as usize, (key & 0xffff_ffff) as usize)
}

/// The crack edges of the triangles drawn (see the module documentation),
/// kept as triangles come and go: per edge taken by point, the times it
/// is drawn in one direction less the other, and how many such balances
/// are not zero away from the input's boundary. A frame's count costs its
/// changed triangles, not all it draws.
struct Cracks<'p> {
    /// A vertex's point, and the input's boundary points.
    point: &'p [u32],
    boundary: &'p [bool],
    balance: FastMap<u64, i32>,
    count: usize,
}

impl<'p> Cracks<'p> {
    fn new(point: &'p [u32], boundary: &'p [bool]) -> Cracks<'p> {
        Cracks {
            point,
            boundary,
            balance: FastMap::default(),
            count: 0,
        }
    }

    /// Counts `t` drawn once more (`sign` 1) or once less (-1).
    fn add(&mut self, t: &[u32; 3], sign: i32) {
        for i in 0..3 {
            let (a, b) = (
                self.point[t[i] as usize],
                self.point[t[(i + 1) % 3] as usize],
            );
            if a == b {
                continue;
            }
            let (key, d) = edge_key(a, b);
            let balance = self.balance.entry(key).or_insert(0);
            let old = *balance;
            *balance += sign * d;
            let (p, q) = edge_points(key);
            if self.boundary[p] && self.boundary[q] {
                continue;
            }
            match (old != 0, *balance != 0) {
                (false, true) => self.count += 1,
                (true, false) => self.count -= 1,
                _ => {}
            }
        }
    }
}

/// The input's boundary points: ends of edges (by point) not paired.
fn boundary_points(triangles: &[[u32; 3]], point: &[u32]) -> Vec<bool> {
    let mut balance: FastMap<u64, i32> = FastMap::default();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (point[t[i] as usize], point[t[(i + 1) % 3] as usize]);
            if a != b {
                let (key, d) = edge_key(a, b);
                *balance.entry(key).or_insert(0) += d;
            }
        }
    }
    let mut out = vec![false; point.len()];
    for (&key, &d) in &balance {
        if d != 0 {
            let (a, b) = edge_points(key);
            out[a] = true;
            out[b] = true;
        }
    }
    out
}

/// Walks two frames' triangles (sorted canonically) together, telling
/// `f` each triangle gone (-1) and come (+1); returns the larger of the
/// two counts, the triangles that changed.
fn diff(before: &[[u32; 3]], after: &[[u32; 3]], mut f: impl FnMut(&[u32; 3], i32)) -> usize {
    let (mut gone, mut came) = (0usize, 0usize);
    let (mut i, mut j) = (0, 0);
    while i < before.len() || j < after.len() {
        match (before.get(i), after.get(j)) {
            (Some(a), Some(b)) if a == b => {
                i += 1;
                j += 1;
            }
            (Some(a), Some(b)) if a < b => {
                f(a, -1);
                gone += 1;
                i += 1;
            }
            (Some(a), None) => {
                f(a, -1);
                gone += 1;
                i += 1;
            }
            (_, Some(b)) => {
                f(b, 1);
                came += 1;
                j += 1;
            }
            (None, None) => break,
        }
    }
    gone.max(came)
}

/// A frame's triangles (sorted canonically) and, once one direction of
/// [`one_way`] needed it, the BVH of their surface, kept for the next
/// frame's other direction.
struct Drawn {
    sorted: Vec<[u32; 3]>,
    bvh: Option<mts::distance::bvh::TriangleBvh>,
}

/// The largest distance in pixels from a point that `from` draws and `to`
/// does not to the surface `to` draws (its BVH built into `to.bvh` when
/// first needed). The whole surface: a vertex may leave with its whole
/// fan (a sliver that degenerates), and then nothing replaces it but the
/// surface around. Popping between two frames is the larger of both
/// directions.
fn one_way(
    from: &[[u32; 3]],
    to: &mut Drawn,
    positions: &[Vec3],
    point: &[u32],
    eye: Vec3,
    projection: &Projection,
) -> f64 {
    let mut used = vec![false; positions.len()];
    for t in &to.sorted {
        for &v in t {
            used[point[v as usize] as usize] = true;
        }
    }
    let mut left = Vec::new();
    for t in from {
        for &v in t {
            let p = point[v as usize] as usize;
            if !used[p] {
                used[p] = true;
                left.push(v);
            }
        }
    }
    if left.is_empty() || to.sorted.is_empty() {
        return 0.0;
    }
    let bvh = to.bvh.get_or_insert_with(|| {
        mts::distance::bvh::TriangleBvh::new(
            to.sorted
                .iter()
                .map(|t| t.map(|v| positions[v as usize]))
                .collect(),
        )
    });
    let mut worst = 0f64;
    for v in left {
        let at = positions[v as usize];
        if let Some((_, squared)) = bvh.closest(at) {
            let ppu = projection.pixels_per_unit(at.distance(eye));
            worst = worst.max(f64::from(squared).sqrt() * f64::from(ppu));
        }
    }
    worst
}

/// The median and the 99th percentile of `v`.
fn median_p99(mut v: Vec<f64>) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    v.sort_by(f64::total_cmp);
    let at = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    (at(0.5), at(0.99))
}

/// One frame of one method: what it draws and what it cost.
struct Frame {
    /// Whether anything drawn changed since the method's previous frame
    /// (when not, the quality figures of that frame stand).
    changed: bool,
    triangles: Vec<[u32; 3]>,
    indices: usize,
    update_ms: f64,
    index_buffer_len: usize,
    visible: Option<usize>,
}

/// A method's state along the flight.
enum Method<'a> {
    Hierarchy {
        h: &'a hierarchy::Hierarchy,
        vd: Box<ViewDependent<'a>>,
        culled: Box<ViewDependent<'a>>,
    },
    ClusterLod {
        lod: &'a ClusterLod,
        cut: mts::peers::clusterlod::Cut,
        list: Vec<[u32; 3]>,
    },
    ClusterTree {
        tree: &'a mts::baselines::ClusterTree,
        /// The previous frame's triangles.
        last: Vec<[u32; 3]>,
    },
    Mts {
        model: &'a mts::MtsModel,
        extractor: Box<Extractor<'a>>,
        centre: Vec3,
        radius: f32,
        diagonal: f32,
    },
}

impl Method<'_> {
    fn name(&self) -> &'static str {
        match self {
            Method::Hierarchy { .. } => "mts_hierarchy",
            Method::ClusterLod { .. } => "clusterlod",
            Method::ClusterTree { .. } => "cluster_tree",
            Method::Mts { .. } => "mts",
        }
    }

    fn positions(&self) -> &[Vec3] {
        match self {
            Method::Hierarchy { h, .. } => h.positions(),
            Method::ClusterLod { lod, .. } => lod.positions(),
            Method::ClusterTree { tree, .. } => tree.positions(),
            Method::Mts { model, .. } => model.positions(),
        }
    }

    /// Selects and extracts for one camera: only the timed part.
    fn frame(&mut self, camera: &Camera, eye: Vec3, height: f32, px: f32) -> Frame {
        let projection = camera.projection(height);
        match self {
            Method::Hierarchy { vd, culled, .. } => {
                let view = View {
                    projection,
                    eye,
                    pixel_threshold: px,
                    frustum: None,
                };
                let t = Instant::now();
                let u = vd.update(&view);
                let update_ms = t.elapsed().as_secs_f64() * 1e3;
                let changed = u.indices_written > 0;
                culled.update(&View {
                    frustum: Some(Frustum::from_view_projection(camera.view_proj)),
                    ..view
                });
                Frame {
                    changed,
                    triangles: vd.triangles(),
                    indices: vd.indices_sent(),
                    update_ms,
                    index_buffer_len: vd.buffer().len(),
                    visible: Some(culled.triangle_count()),
                }
            }
            Method::ClusterLod { lod, cut, list } => {
                let before = cut.clusters.clone();
                let t = Instant::now();
                lod.cut_into(eye, projection, px, cut);
                list.clear();
                list.extend_from_slice(&cut.triangles);
                let update_ms = t.elapsed().as_secs_f64() * 1e3;
                Frame {
                    changed: before != cut.clusters,
                    triangles: list.clone(),
                    indices: 3 * list.len(),
                    update_ms,
                    index_buffer_len: 3 * list.len(),
                    visible: None,
                }
            }
            Method::ClusterTree { tree, last } => {
                // Its threshold is an angle: a size seen at `px` pixels
                // from a unit distance.
                let threshold = px / projection.pixels_per_unit(1.0);
                let t = Instant::now();
                let triangles = tree.view_dependent(eye, threshold);
                let update_ms = t.elapsed().as_secs_f64() * 1e3;
                let changed = *last != triangles;
                last.clone_from(&triangles);
                Frame {
                    changed,
                    indices: 3 * triangles.len(),
                    index_buffer_len: 3 * triangles.len(),
                    triangles,
                    update_ms,
                    visible: None,
                }
            }
            Method::Mts {
                model,
                extractor,
                centre,
                radius,
                diagonal,
            } => {
                let t = Instant::now();
                let ppu = projection.pixels_per_unit(nearest_distance(eye, *centre, *radius));
                let lod = mts::lod_for_screen_error(model.collapses(), *diagonal, 1.0, ppu, px);
                let before = extractor.lod();
                extractor.set_lod(lod);
                let update_ms = t.elapsed().as_secs_f64() * 1e3;
                Frame {
                    changed: before != Some(lod),
                    triangles: extractor.triangles(),
                    indices: extractor.indices_sent(),
                    update_ms,
                    index_buffer_len: extractor.buffer().len(),
                    visible: None,
                }
            }
        }
    }
}

/// What was built once per input, for every threshold.
struct Built {
    hierarchy: hierarchy::Hierarchy,
    hierarchy_ms: f64,
    clusterlod: ClusterLod,
    clusterlod_ms: f64,
    tree: mts::baselines::ClusterTree,
    tree_ms: f64,
    model: mts::MtsModel,
    model_ms: f64,
}

fn build_all(
    mesh: &Mesh,
    options: &HierarchyOptions,
    say: &dyn Fn(&str) -> Result<()>,
) -> Result<Built> {
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    say("the strip hierarchy")?;
    let t = Instant::now();
    let hierarchy = hierarchy::build(mesh, options)?;
    let hierarchy_ms = ms(t);
    say("meshoptimizer's cluster LoD")?;
    if let Some(why) = mts::peers::meshopt::refusal(mesh) {
        anyhow::bail!("meshoptimizer cannot take this mesh: {why}");
    }
    let t = Instant::now();
    let clusterlod = ClusterLod::build(mesh)?;
    let clusterlod_ms = ms(t);
    say("the cluster tree")?;
    let t = Instant::now();
    let tree = mts::baselines::ClusterTree::new(mesh)?;
    let tree_ms = ms(t);
    say("the per-object MTS model")?;
    let t = Instant::now();
    let (model, _, _) = crate::commands::build::build_with_bar(mesh, &Default::default())?;
    let model_ms = ms(t);
    Ok(Built {
        hierarchy,
        hierarchy_ms,
        clusterlod,
        clusterlod_ms,
        tree,
        tree_ms,
        model,
        model_ms,
    })
}

/// The GPU side of the image error: the target, the reference per compared
/// frame, and the full-detail frame at one sample per pixel.
struct Images {
    gpu: Gpu,
    config: RendererConfig,
    target: HeadlessTarget,
    /// Per compared frame: (flight position, full-detail image, reference).
    frames: Vec<(
        f32,
        mts_render::headless::Image,
        mts_render::image_error::Reference,
    )>,
}

impl Images {
    fn new(mesh: &Mesh, lo: Vec3, hi: Vec3, (width, height): (u32, u32)) -> Result<Images> {
        let gpu = Gpu::new_headless()?;
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let (d, q) = (&gpu.device, &gpu.queue);
        let target = HeadlessTarget::new(d, width, height)?;
        let mut full = StripRenderer::new(d, q, &config, &mesh.positions, &mesh.triangles)?;
        full.upload_list(d, q, &mesh.triangles)?;
        let reference_target = ReferenceTarget::new(d, width, height)?;
        let mut frames = Vec::new();
        for k in 0..COMPARED_FRAMES {
            let at = (k as f32 + 0.5) / COMPARED_FRAMES as f32;
            let (camera, _) = camera_at(lo, hi, at, target.aspect());
            full.set_camera(q, &camera);
            let image = target.render_image(d, q, |pass| full.draw(pass))?;
            let reference = reference_target.render(&camera, |tile_camera, tile| {
                full.set_camera(q, tile_camera);
                tile.render_image(d, q, |pass| full.draw(pass))
            })?;
            frames.push((at, image, reference));
        }
        Ok(Images {
            gpu,
            config,
            target,
            frames,
        })
    }

    /// The image-error ratio of `method` at `px` over the compared frames.
    /// `full` is the method's full-detail triangles: the normals of every
    /// frame are computed from them, as for the reference.
    fn ratio(
        &self,
        method: &mut Method<'_>,
        full: &[[u32; 3]],
        px: f32,
        lo: Vec3,
        hi: Vec3,
    ) -> Result<Option<f64>> {
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        let mut renderer = StripRenderer::new(d, q, &self.config, method.positions(), full)?;
        let height = self.target.size().1 as f32;
        let mut error = ImageError::default();
        for (at, full, reference) in &self.frames {
            let (camera, eye) = camera_at(lo, hi, *at, self.target.aspect());
            let frame = method.frame(&camera, eye, height, px);
            renderer.upload_list(d, q, &frame.triangles)?;
            renderer.set_camera(q, &camera);
            let image = self.target.render_image(d, q, |pass| renderer.draw(pass))?;
            error.add(reference, full, &image)?;
        }
        Ok(error.ratio())
    }
}

/// Runs the flight for every method and threshold; `say` is told what is
/// being built.
///
/// # Errors
/// Building, an empty mesh or fewer than 2 frames, or the adapter when
/// images are asked for.
pub fn measure(
    spec: &FlightSpec<'_>,
    say: &dyn Fn(&str) -> Result<()>,
) -> Result<ViewDependentRun> {
    let mesh = spec.mesh;
    anyhow::ensure!(spec.frames >= 2, "a flight needs 2 frames at least");
    let (lo, hi) = mts::mesh::bounds_of(&mesh.positions).context("the mesh has no vertices")?;
    let built = build_all(mesh, &spec.options, say)?;
    let images = if spec.images {
        Some(Images::new(mesh, lo, hi, (spec.width, spec.height))?)
    } else {
        None
    };
    let raw_bytes = built.model.raw_bytes();
    let (width, height) = (spec.width, spec.height);
    let aspect = width as f32 / height as f32;
    let (_, _, terrain) = flight(lo, hi, 0.0);
    let mut rows = Vec::new();
    for &px in spec.pixel_errors {
        let centre = 0.5 * (lo + hi);
        let radius = 0.5 * lo.distance(hi);
        let mut methods = vec![
            Method::Hierarchy {
                h: &built.hierarchy,
                vd: Box::new(ViewDependent::new(&built.hierarchy)),
                culled: Box::new(ViewDependent::new(&built.hierarchy)),
            },
            Method::ClusterLod {
                lod: &built.clusterlod,
                cut: Default::default(),
                list: Vec::new(),
            },
            Method::ClusterTree {
                tree: &built.tree,
                last: Vec::new(),
            },
            Method::Mts {
                model: &built.model,
                extractor: Box::new(Extractor::new(&built.model)),
                centre,
                radius,
                diagonal: mesh.diagonal(),
            },
        ];
        for method in &mut methods {
            let positions = method.positions().to_vec();
            let point = points_of(&positions);
            let full: Vec<[u32; 3]> = match method {
                Method::ClusterTree { tree, .. } => tree.view_dependent(lo, 0.0),
                _ => mesh.triangles.clone(),
            };
            let boundary = boundary_points(&full, &point);
            let mut cracks = Cracks::new(&point, &boundary);
            let mut frames = Vec::with_capacity(spec.frames);
            let mut previous: Option<Drawn> = None;
            let (mut pops, mut changed) = (Vec::new(), Vec::new());
            let (mut cracked, mut last_cracks, mut buffer_max) = (0usize, 0usize, 0usize);
            let (mut drawn, mut visible, mut ipt) = (Vec::new(), Vec::new(), Vec::new());
            // One untimed frame at the start (extractors made, caches warm).
            let (camera, eye) = camera_at(lo, hi, 0.0, aspect);
            method.frame(&camera, eye, height as f32, px);
            for i in 0..spec.frames {
                let t = i as f32 / (spec.frames - 1) as f32;
                let (camera, eye) = camera_at(lo, hi, t, aspect);
                let frame = method.frame(&camera, eye, height as f32, px);
                if frame.changed || previous.is_none() {
                    let mut now = Drawn {
                        sorted: mts::strip::sorted_canonical(&frame.triangles),
                        bvh: None,
                    };
                    if let Some(mut before) = previous.take() {
                        let change = diff(&before.sorted, &now.sorted, |t, sign| {
                            cracks.add(t, sign);
                        });
                        let projection = camera.projection(height as f32);
                        let pop = one_way(
                            &before.sorted,
                            &mut now,
                            &positions,
                            &point,
                            eye,
                            &projection,
                        )
                        .max(one_way(
                            &now.sorted,
                            &mut before,
                            &positions,
                            &point,
                            eye,
                            &projection,
                        ));
                        pops.push(pop);
                        changed.push(change as f64);
                    } else {
                        for t in &now.sorted {
                            cracks.add(t, 1);
                        }
                    }
                    last_cracks = cracks.count;
                    previous = Some(now);
                } else if previous.is_some() {
                    pops.push(0.0);
                    changed.push(0.0);
                }
                cracked += last_cracks;
                buffer_max = buffer_max.max(frame.index_buffer_len);
                drawn.push(frame.triangles.len() as f64);
                if let Some(v) = frame.visible {
                    visible.push(v as f64);
                }
                ipt.push(if frame.triangles.is_empty() {
                    0.0
                } else {
                    frame.indices as f64 / frame.triangles.len() as f64
                });
                frames.push(frame.update_ms);
            }
            let (update_ms_median, update_ms_p99) = median_p99(frames);
            let pops_max = pops.iter().copied().fold(0.0, f64::max);
            let image_error_ratio = match &images {
                Some(images) => images.ratio(method, &full, px, lo, hi)?,
                None => None,
            };
            let (memory_bytes, build_ms) = match method {
                Method::Hierarchy { h, vd, .. } => {
                    (h.memory_bytes() + vd.memory_bytes(), built.hierarchy_ms)
                }
                Method::ClusterLod { lod, .. } => (lod.memory_bytes(), built.clusterlod_ms),
                Method::ClusterTree { tree, .. } => (tree.memory_bytes(), built.tree_ms),
                Method::Mts {
                    model, extractor, ..
                } => (
                    model.stats().memory_bytes + extractor.memory_bytes(),
                    built.model_ms,
                ),
            };
            rows.push(ViewDependentRow {
                method: method.name().to_owned(),
                pixel_threshold: f64::from(px),
                triangles_drawn_median: median_p99(drawn.clone()).0,
                triangles_drawn_max: drawn.iter().copied().fold(0.0, f64::max) as u64,
                triangles_full_detail: mesh.triangle_count() as u64,
                triangles_visible_median: (!visible.is_empty()).then(|| median_p99(visible).0),
                indices_per_triangle: median_p99(ipt.clone()).0,
                indices_per_triangle_max: ipt.iter().copied().fold(0.0, f64::max),
                update_ms_median,
                update_ms_p99,
                cracks: cracked as u64,
                popping_px_max: pops_max,
                popping_px_median: median_p99(pops).0,
                triangles_changed_median: median_p99(changed).0,
                memory_bytes: memory_bytes as u64,
                raw_bytes: raw_bytes as u64,
                gpu_bytes: (mts_render::VERTEX_BYTES * positions.len() + 4 * buffer_max) as u64,
                build_ms,
                image_error_ratio,
            });
        }
    }
    Ok(ViewDependentRun {
        input: spec.name.to_owned(),
        triangles_full_detail: mesh.triangle_count() as u64,
        vertices: mesh.vertex_count() as u64,
        raw_bytes: raw_bytes as u64,
        flight: if terrain { "over" } else { "around" }.to_owned(),
        frames: spec.frames as u64,
        width,
        height,
        adapter: images.as_ref().map(|i| i.gpu.report().name),
        methods: rows,
    })
}

pub fn bench_view_dependent(args: &BenchViewDependentArgs) -> Result<()> {
    let (name, mesh, _) = if args.source.mesh.is_none() && args.source.generated.is_none() {
        args.source.load_generated(
            "terrain:1M"
                .parse()
                .map_err(|e| anyhow::anyhow!("terrain:1M: {e}"))?,
        )?
    } else {
        args.source.load()?
    };
    let mut options = HierarchyOptions {
        cluster_triangles: args.cluster_triangles,
        group_clusters: args.group_clusters,
        ..HierarchyOptions::default()
    };
    options.pipeline.build.band_slack = args.band_slack;
    let spec = FlightSpec {
        mesh: &mesh,
        name: &name,
        pixel_errors: &args.pixel_error,
        frames: args.frames,
        width: args.size.0,
        height: args.size.1,
        images: !args.no_images,
        options,
    };
    let say = |what: &str| -> Result<()> {
        if !args.json {
            outln!("building {what}…")?;
        }
        Ok(())
    };
    let report = measure(&spec, &say)?;
    if args.json {
        return outln!("{}", serde_json::to_string(&report)?);
    }
    outln!(
        "{name}: {} triangles, {} frames {} it, {}x{} pixels{}",
        report.triangles_full_detail,
        report.frames,
        if report.flight == "over" {
            "flying over"
        } else {
            "circling"
        },
        report.width,
        report.height,
        report
            .adapter
            .as_ref()
            .map_or(String::new(), |a| format!(", images on {a}"))
    )?;
    outln!(
        "{:>14} {:>4} {:>10} {:>6} {:>8} {:>8} {:>6} {:>7} {:>8} {:>8} {:>8}",
        "method",
        "px",
        "triangles",
        "ind/tr",
        "upd ms",
        "p99 ms",
        "cracks",
        "pop px",
        "mem/raw",
        "build s",
        "img err"
    )?;
    for r in &report.methods {
        outln!(
            "{:>14} {:>4} {:>10.0} {:>6.2} {:>8.3} {:>8.3} {:>6} {:>7.2} {:>8.2} {:>8.1} {:>8}",
            r.method,
            r.pixel_threshold,
            r.triangles_drawn_median,
            r.indices_per_triangle,
            r.update_ms_median,
            r.update_ms_p99,
            r.cracks,
            r.popping_px_max,
            r.memory_bytes as f64 / r.raw_bytes as f64,
            r.build_ms / 1e3,
            r.image_error_ratio
                .map_or("—".into(), |x| format!("{x:.2}"))
        )?;
    }
    Ok(())
}
