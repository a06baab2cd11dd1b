//! The demo layout of `mts render --scene`, `mts view --scene` and the
//! bench's scene rows: `count` instances of one or more models on a square
//! grid on a ground plane, and two cameras: one above a corner looking
//! across the field, and a path that flies through it. The renderer's
//! [`InstancedScene`] knows nothing of it: a host places its own
//! instances.

use crate::stdout::warnln;
use glam::{Mat4, Vec3};
use mts::{MtsModel, Result};
use mts_render::{Camera, FrameStats, InstanceId, InstancedScene, RendererConfig, StripRenderer};

/// Linear RGB of the ground plane (a muted green-grey, apart from the
/// models' colour).
pub const GROUND_COLOUR: Vec3 = Vec3::new(0.22, 0.27, 0.22);

/// Grid spacing in model radii (every instance is scaled to radius 1).
const SPACING: f32 = 5.0;

/// `count` instances of some models on a ground plane.
pub struct DemoScene<'m> {
    pub scene: InstancedScene<'m>,
    pub instances: Vec<InstanceId>,
    ground: StripRenderer,
    /// Extent of the field: min and max corner on the ground.
    field: (Vec3, Vec3),
}

impl<'m> DemoScene<'m> {
    /// Places `count` instances of `models` (taken in turn, drawn with
    /// `appearance`) on a square
    /// grid on the plane y = 0, each scaled to a bounding radius of 1,
    /// resting on the plane and turned about +y by a fixed pseudo-random
    /// angle, [`SPACING`] radii apart, with a ground quad under them.
    ///
    /// # Errors
    /// As [`InstancedScene::add_model_with`] and
    /// [`InstancedScene::add_instance`]; no models or no instances.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        models: &[&'m MtsModel],
        count: usize,
        appearance: &mts_render::Appearance,
    ) -> Result<DemoScene<'m>> {
        if count == 0 || models.is_empty() {
            return Err(mts::Error::InvalidArgument(
                "a scene needs models and instances".into(),
            ));
        }
        let mut scene = InstancedScene::new(config);
        // Per model: its id, its scale to radius 1, and the lift that
        // rests its lowest point on the plane.
        let mut placed = Vec::with_capacity(models.len());
        for model in models {
            let id = scene.add_model_with(device, queue, model, appearance)?;
            for w in scene.warnings(id) {
                warnln!("{w}");
            }
            let (min, max) = mts::mesh::bounds_of(model.positions()).unwrap_or_default();
            let radius = mts::mesh::diagonal_of(min, max) * 0.5;
            let centre = (min + max) * 0.5;
            // Scaled to radius 1 where f32 can say it: a model of one
            // point, or one whose scaled centre would overflow, is placed
            // as it is.
            let scale = (1.0 / radius) as f32;
            let scale = if radius > 0.0 && (centre.abs().max_element() * scale).is_finite() {
                scale
            } else {
                1.0
            };
            placed.push((id, scale, centre, min.y));
        }
        let side = (count as f64).sqrt().ceil() as usize;
        let mut instances = Vec::with_capacity(count);
        for i in 0..count {
            let (id, scale, centre, low) = placed[i % placed.len()];
            let (gx, gz) = ((i % side) as f32, (i / side) as f32);
            let angle = std::f32::consts::TAU * hash01(i as u32);
            let at = Vec3::new(gx * SPACING, (centre.y - low) * scale, gz * SPACING);
            let transform = Mat4::from_translation(at)
                * Mat4::from_rotation_y(angle)
                * Mat4::from_scale(Vec3::splat(scale))
                * Mat4::from_translation(-centre);
            instances.push(scene.add_instance(id, transform)?);
        }
        let far = (side.max(1) - 1) as f32 * SPACING;
        let margin = 1.5 * SPACING;
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
        Ok(DemoScene {
            scene,
            instances,
            ground,
            field,
        })
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

    /// The camera `t` (0 to 1) of the way along the fly-through: from the
    /// field's corner towards its centre, three radii above the ground
    /// (just over the instances), weaving gently and looking ahead and a
    /// little down, so that instances pass from the far distance to right
    /// beside the eye. The path has the same shape at every field size.
    #[must_use]
    pub fn path_camera(&self, t: f32, aspect: f32) -> Camera {
        let (a, b) = self.field;
        let diagonal = b - a;
        let along = diagonal.normalize_or_zero();
        let across = Vec3::new(-along.z, 0.0, along.x);
        let length = 0.5 * diagonal.length();
        let weave = (t * std::f32::consts::TAU).sin() * 0.1 * length.min(200.0);
        let eye = a + along * (t * length) + across * weave + Vec3::Y * 3.0;
        let ahead = eye + along * 20.0 + across * weave * 0.2 - Vec3::Y * 2.0;
        Camera::looking(eye, ahead, aspect, 0.05, 2.0 * diagonal.length().max(1.0))
    }

    /// The scene's update ([`InstancedScene::update`]) and the ground's
    /// camera.
    ///
    /// # Errors
    /// As [`InstancedScene::update`].
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        viewport_height: f32,
        pixel_error: f32,
    ) -> Result<FrameStats> {
        self.ground.set_camera(queue, camera);
        self.scene
            .update(device, queue, camera, viewport_height, pixel_error)
    }

    /// The ground, then the instances.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.ground.draw(pass);
        self.scene.draw(pass);
    }
}

/// The models of `--scene-with`: each mesh file loaded and built with the
/// default options, named by its path.
///
/// # Errors
/// When a file cannot be loaded.
pub fn load_models(paths: &[std::path::PathBuf]) -> anyhow::Result<Vec<(String, MtsModel)>> {
    use anyhow::Context;
    paths
        .iter()
        .map(|p| {
            let (mesh, _) = mts::mesh::io::load(p, Default::default())
                .with_context(|| format!("cannot load {}", p.display()))?;
            let (model, _, _) =
                mts::model::build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
            Ok((p.display().to_string(), model))
        })
        .collect()
}

/// A fixed pseudo-random number in 0..1 from `i` (integer hash).
fn hash01(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    (x >> 8) as f32 / (1u32 << 24) as f32
}
