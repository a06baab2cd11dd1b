//! `mts render` and `mts view` of a glTF file of several parts
//! ([`mts::mesh::io::parse_gltf_parts`]: a part per triangle primitive of
//! each mesh, with its own texture or material colour): each part is built
//! into a model of its own and drawn in an [`InstancedScene`], one instance
//! per node that holds its mesh, each instance at the coarsest LoD within
//! the pixel threshold, the camera framing every instance. A file of one
//! part takes the one-model path of the commands (its LoD flags, methods
//! and baselines); `mts build` merges the parts into one model.
//!
//! **Mirrored instances.** The renderer culls back faces, and a node
//! matrix with a negative determinant turns the part's counter-clockwise
//! triangles clockwise on the screen: such instances draw a second model
//! of the part with every triangle's winding reversed (and, where the file
//! has no normals, the normals of the unreversed triangles, which the
//! instance's matrix mirrors back outwards). It costs a second build of
//! that part only when the file mirrors it.
//!
//! **Properties.** The parts' normals, texture coordinates, colours
//! (times the material's base-colour factor) and textures are read from
//! the file, as every command keeps them by default; `--positions-only`
//! drops them (each part is then drawn in the renderer's default colour,
//! still a model of its own).

use anyhow::{Context, Result};
use glam::{Mat4, Vec3};
use mts::mesh::io::{gltf_part_count, parse_gltf_parts, Format, GltfPart, LoadOptions};
use mts::mesh::{CleanOptions, Mesh};
use mts::model::{try_build_from_mesh, PipelineOptions};
use mts::MtsModel;
use mts_render::{Appearance, Camera, InstanceId, InstancedScene, RendererConfig};
use std::path::Path;

/// One model of a glTF scene: a part (or its mirror image), built, and the
/// transforms of its instances.
pub struct SceneModel {
    /// The part's mesh index in the file.
    pub mesh: usize,
    /// The part's primitive index in its mesh.
    pub primitive: usize,
    /// The mesh's name in the file, when it has one.
    pub name: Option<String>,
    /// Whether the triangles were reversed for mirroring transforms (see
    /// the module docs).
    pub mirrored: bool,
    /// The model of the part's mesh, cleaned with the command's options.
    pub model: MtsModel,
    /// Model-to-world matrices of its instances, in scene order; every one
    /// mirrors when `mirrored`, none does otherwise.
    pub transforms: Vec<Mat4>,
}

impl SceneModel {
    /// `mesh 0 "wheel" primitive 1`, and ` (mirrored)` when it is.
    pub fn label(&self) -> String {
        let name = self
            .name
            .as_ref()
            .map_or_else(String::new, |n| format!(" {n:?}"));
        let mirrored = if self.mirrored { " (mirrored)" } else { "" };
        format!(
            "mesh {}{name} primitive {}{mirrored}",
            self.mesh, self.primitive
        )
    }
}

/// The parts of a glTF file, built into models.
pub struct GltfScene {
    /// The file, as the command line spells it.
    pub name: String,
    /// Parts the file has ([`gltf_part_count`]).
    pub part_count: usize,
    /// The models to draw, parts in the order of their first instance (a
    /// mirrored model right after its part's unmirrored one); parts
    /// without a triangle left after cleaning are left out, with a
    /// warning.
    pub models: Vec<SceneModel>,
}

impl GltfScene {
    /// The scene of `path` when it is a glTF file of more than one part;
    /// `None` for any other file (an `.mts` model, OBJ, PLY, a glTF of one
    /// part), which the commands read as one model. `options` gives the
    /// weld, the triangle limit (over every instance) and whether the
    /// parts keep their properties.
    ///
    /// # Errors
    /// When the file cannot be read or parsed, or a part cannot be
    /// cleaned or built (for a reason other than having no triangle).
    ///
    /// Cost: the file is read whole (and read again by the one-model path
    /// when this returns `None`); the part count reads its JSON only; each
    /// part is built once (twice when mirrored), whatever its instances.
    pub fn load_if_several(path: &Path, options: LoadOptions) -> Result<Option<GltfScene>> {
        let bytes = mts::mesh::io::read_file(path)?;
        if !matches!(Format::detect(path, &bytes), Ok(Format::Gltf)) {
            return Ok(None);
        }
        let part_count = gltf_part_count(&bytes, path).context("cannot load the mesh")?;
        if part_count <= 1 {
            return Ok(None);
        }
        let parts = parse_gltf_parts(&bytes, path, options.max_triangles)
            .context("cannot load the mesh")?;
        let name = path.display().to_string();
        let mut models = Vec::with_capacity(parts.len());
        for mut part in parts {
            if !options.properties {
                part.raw.properties = mts::mesh::Properties::default();
            }
            models.extend(build_part(&name, part, options.clean)?);
        }
        if models.is_empty() {
            anyhow::bail!("{name}: no part of the scene has a triangle to draw");
        }
        Ok(Some(GltfScene {
            name,
            part_count,
            models,
        }))
    }

    /// Instances over every model.
    pub fn instance_count(&self) -> usize {
        self.models.iter().map(|m| m.transforms.len()).sum()
    }

    /// The world-space box around every instance (each model's box under
    /// each of its transforms).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for m in &self.models {
            let (a, b) = mts::mesh::bounds_of(m.model.positions()).unwrap_or_default();
            for t in &m.transforms {
                for corner in 0..8 {
                    let p = Vec3::select(
                        glam::BVec3::new(corner & 1 != 0, corner & 2 != 0, corner & 4 != 0),
                        b,
                        a,
                    );
                    let q = t.transform_point3(p);
                    lo = lo.min(q);
                    hi = hi.max(q);
                }
            }
        }
        (lo, hi)
    }

    /// The camera that frames every instance ([`Camera::framing`] of
    /// [`GltfScene::bounds`]).
    pub fn camera(&self, aspect: f32) -> Camera {
        let (lo, hi) = self.bounds();
        Camera::framing(lo, hi, aspect)
    }

    /// The instanced scene of every model with its instances, drawn with
    /// `appearance`, and the instances of each model in the order of its
    /// transforms; what a model's renderer cannot draw (a texture that
    /// does not decode) is printed as a warning naming the part.
    ///
    /// # Errors
    /// As [`InstancedScene::add_model_with`], and
    /// [`mts::Error::InvalidArgument`] naming the part for an instance
    /// whose bounds are not finite in `f32`.
    pub fn scene<'m>(
        &'m self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        appearance: &Appearance,
    ) -> mts::Result<(InstancedScene<'m>, Vec<Vec<InstanceId>>)> {
        let mut scene = InstancedScene::new(config);
        let mut instances = Vec::with_capacity(self.models.len());
        for m in &self.models {
            let id = scene.add_model_with(device, queue, &m.model, appearance)?;
            for w in scene.warnings(id) {
                crate::stdout::warnln!("{}: {}: {w}", self.name, m.label());
            }
            let mut placed = Vec::with_capacity(m.transforms.len());
            for &t in &m.transforms {
                placed.push(scene.add_instance(id, t).map_err(|e| {
                    mts::Error::InvalidArgument(format!(
                        "{}: an instance of {}: {e}",
                        self.name,
                        m.label()
                    ))
                })?);
            }
            instances.push(placed);
        }
        Ok((scene, instances))
    }
}

/// The models of `part`: one for its transforms that keep orientation,
/// one (triangles reversed) for those that mirror; none, with a warning,
/// when cleaning leaves no triangle.
fn build_part(file: &str, part: GltfPart, clean: CleanOptions) -> Result<Vec<SceneModel>> {
    let what = format!("{file} mesh {} primitive {}", part.mesh, part.primitive);
    let (mesh, _) = match mts::mesh::clean(part.raw, clean, &what) {
        Ok(cleaned) => cleaned,
        Err(mts::Error::InvalidMesh { message, .. }) => {
            crate::stdout::warnln!("{what}: not drawn: {message}");
            return Ok(Vec::new());
        }
        Err(e) => return Err(e.into()),
    };
    let (mirroring, keeping): (Vec<Mat4>, Vec<Mat4>) = part
        .transforms
        .iter()
        .map(|t| t.as_mat4())
        .partition(|t| t.determinant() < 0.0);
    let mut out = Vec::with_capacity(2);
    for (transforms, mirrored) in [(keeping, false), (mirroring, true)] {
        if transforms.is_empty() {
            continue;
        }
        let built = if mirrored { &mirror(&mesh) } else { &mesh };
        let (model, _, _) = try_build_from_mesh(built, &PipelineOptions::default(), &mut |_, _| {})
            .with_context(|| format!("{what}: cannot build its model"))?;
        out.push(SceneModel {
            mesh: part.mesh,
            primitive: part.primitive,
            name: part.name.clone(),
            mirrored,
            model,
            transforms,
        });
    }
    Ok(out)
}

/// `mesh` with every triangle's winding reversed, for mirroring
/// transforms; normals kept, or computed from the unreversed triangles
/// when it has none (the reversed ones would point them inwards).
fn mirror(mesh: &Mesh) -> Mesh {
    let mut out = mesh.clone();
    if out.properties.normals.is_none() {
        out.properties.normals = Some(mts_render::vertex_normals(&mesh.positions, &mesh.triangles));
    }
    for t in &mut out.triangles {
        t.swap(1, 2);
    }
    out
}
