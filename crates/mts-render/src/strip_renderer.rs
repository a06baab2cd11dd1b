//! [`StripRenderer`]: one mesh's vertices on the GPU, one index buffer that
//! holds either strips or a triangle list, and the draw of it into a
//! caller's render pass.
//!
//! Strips are drawn with `TriangleStrip` topology and primitive restart
//! (`strip_index_format` set), triangle lists with `TriangleList`; both
//! pipelines share the shader (`shaders/mesh.wgsl`), the vertex layout, the
//! camera uniform, back-face culling and CCW front faces, so every method
//! goes through one code path and a winding error shows as a hole. Indices
//! are `u16` when every vertex index fits below the `u16` restart value.
//!
//! One vertex layout serves every mesh, with or without properties:
//! position and normal (`f32`), UV (`f32`), linear colour (`Unorm16x4`),
//! 40 bytes a vertex where position and normal alone took 24. Chosen over a
//! second vertex stream and pipeline for meshes with properties because
//! one pipeline keeps strips, lists, the scene and the oracle images on one
//! code path; the cost is 16 bytes a vertex on meshes without properties.
//! `Unorm16` keeps linear colours within 1/65535 (8 bits would band the
//! darks) at half the bytes of `f32`.

use super::camera::{Camera, Shading};
use super::gpu::StripMode;
use super::texture::{self, Appearance};
use glam::Vec3;
use mts::mesh::Properties;
use mts::model::Extractor;
use mts::strip::encode::{stitch_restart_buffer, RESTART_U16, RESTART_U32};
use mts::{Error, Result};
use std::ops::Range;

/// Formats and strip mode of a [`StripRenderer`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RendererConfig {
    /// Format of the colour attachment the caller's pass draws into.
    pub color_format: wgpu::TextureFormat,
    /// Format of its depth attachment, if any (depth test `Less`, writes on).
    pub depth_format: Option<wgpu::TextureFormat>,
    /// How strips are sent (see [`StripMode::for_backend`] to choose it
    /// from the adapter).
    pub strip_mode: StripMode,
}

/// What one upload sent to the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Upload {
    /// Bytes written with `queue.write_buffer`.
    pub bytes: usize,
    /// `write_buffer` calls (one per dirty range on the restart path).
    pub writes: usize,
}

/// What the index buffer holds now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Content {
    Strips,
    List,
}

/// Camera uniform as the shader reads it (`Camera` in `mesh.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CameraUniform {
    view_proj: [[f32; 4]; 4],
    light_dir: [f32; 4],
    colour: [f32; 4],
    /// x: 1 to sample the texture, y: 1 to use the vertex colours.
    material: [f32; 4],
}

/// Surface colour of a new [`StripRenderer`] (linear RGB, a warm light
/// grey).
pub const DEFAULT_COLOUR: Vec3 = Vec3::new(0.85, 0.78, 0.65);

/// Bytes of one instance transform (a column-major `mat4x4<f32>`), the
/// stride of vertex buffer slot 1.
pub const INSTANCE_BYTES: u64 = 64;

/// Bytes of one vertex in the vertex buffer (see the module docs).
pub const VERTEX_BYTES: usize = std::mem::size_of::<Vertex>();

/// Interleaved vertex: position, normal, UV, colour (40 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    /// `v` up (v = 0 is the image's bottom row); zero without UVs.
    uv: [f32; 2],
    /// Linear RGBA, `Unorm16x4`; white without colours.
    colour: [u16; 4],
}

/// Draws one mesh's strips or triangle lists into a caller's render pass.
///
/// Built from the caller's device and queue; it owns its buffers and
/// pipelines and nothing else. The index buffer keeps the layout of
/// [`Extractor::buffer`] on the restart path, so after a LoD change only
/// [`Extractor::dirty_ranges`] are written ([`StripRenderer::update_strips`]).
///
/// Invariants: `index_buffer` holds `index_capacity` indices of
/// `index_format`, at least `draw.end`; on the restart path, after a strip
/// upload its first `uploaded_len` indices equal the extractor's buffer.
#[derive(Debug)]
pub struct StripRenderer {
    config: RendererConfig,
    vertex_buffer: wgpu::Buffer,
    vertex_count: usize,
    /// The vertices as last uploaded (for position-only updates).
    vertices: Vec<Vertex>,
    /// Linear RGB surface colour, written with the camera.
    colour: Vec3,
    /// The shader's `material` flags: texture, vertex colours.
    material: [f32; 4],
    /// Size of the base-colour texture drawn; `None` when untextured.
    texture_size: Option<(u32, u32)>,
    /// Why a texture or property is not drawn, one sentence each.
    warnings: Vec<String>,
    /// One identity transform: what [`StripRenderer::draw`] binds to slot 1.
    identity_instance: wgpu::Buffer,
    uniform_buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    strip_pipeline: wgpu::RenderPipeline,
    list_pipeline: wgpu::RenderPipeline,
    index_format: wgpu::IndexFormat,
    index_buffer: Option<wgpu::Buffer>,
    index_capacity: usize,
    content: Content,
    /// Length of the extractor buffer last uploaded whole (restart path);
    /// `None` after any other upload, so that dirty ranges are not applied
    /// over another layout.
    uploaded_len: Option<usize>,
    draw: Range<u32>,
    scratch_u16: Vec<u16>,
    scratch_u32: Vec<u32>,
}

impl StripRenderer {
    /// Uploads `positions` with area-weighted vertex normals computed from
    /// `triangles` (the full-resolution mesh, so that the shading does not
    /// change with the LoD) and builds both pipelines: the surface in
    /// [`DEFAULT_COLOUR`], untextured. [`StripRenderer::with_properties`]
    /// with empty properties.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when there are no vertices, more than
    /// `u32::MAX - 1`, or a triangle indexes past them; [`Error::Gpu`] when
    /// the vertex buffer exceeds the device's `max_buffer_size`.
    ///
    /// Cost: O(vertices + triangles), one vertex upload, two pipelines.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
    ) -> Result<StripRenderer> {
        StripRenderer::with_properties(
            device,
            queue,
            config,
            positions,
            triangles,
            &Properties::default(),
            &Appearance::default(),
        )
    }

    /// [`StripRenderer::new`] drawing a mesh's vertex properties: its
    /// normals where present and non-zero (computed from `triangles`
    /// otherwise), its colours (white without), its UVs (zero without) and
    /// its base-colour texture, or the checker of
    /// [`Appearance::checker`]. A fragment's colour is surface colour ×
    /// texture × vertex colour × the Lambert shade; the surface colour
    /// starts white when a texture or vertex colours are drawn (so they
    /// show as authored), [`DEFAULT_COLOUR`] otherwise.
    ///
    /// The texture is decoded (PNG or JPEG), mipmapped on the CPU and
    /// uploaded as RGBA8 sRGB. A texture that cannot be drawn (missing or
    /// corrupt file, another format, a side above the device's
    /// `max_texture_dimension_2d`, no UVs) is not an error: the mesh is
    /// drawn untextured and [`StripRenderer::warnings`] says why, naming
    /// the image.
    ///
    /// # Errors
    /// As [`StripRenderer::new`], and [`Error::InvalidArgument`] when
    /// `properties` breaks an invariant of [`Properties::validate`] for
    /// `positions` (a stream of another length, a non-unit normal, a
    /// colour outside 0..=1).
    ///
    /// Cost: O(vertices + triangles + texels): the decode and the mip
    /// chain (4/3 of the image, in memory until uploaded) dominate for a
    /// textured mesh.
    pub fn with_properties(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        properties: &Properties,
        appearance: &Appearance,
    ) -> Result<StripRenderer> {
        if positions.is_empty() || positions.len() >= RESTART_U32 as usize {
            return Err(Error::InvalidArgument(format!(
                "the renderer needs 1 to {} vertices, got {}",
                RESTART_U32 - 1,
                positions.len()
            )));
        }
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= positions.len()))
        {
            return Err(Error::InvalidArgument(format!(
                "triangle {t} indexes past the {} vertices",
                positions.len()
            )));
        }
        properties
            .validate(positions)
            .map_err(|e| Error::InvalidArgument(format!("vertex properties: {e}")))?;
        let vertices = interleave(positions, triangles, properties);
        let vertex_bytes: &[u8] = bytemuck::cast_slice(&vertices);
        check_size(device, vertex_bytes.len(), "vertex buffer")?;
        let vertex_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts vertices"),
            size: vertex_bytes.len() as u64,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&vertex_buffer, 0, vertex_bytes);
        let mut warnings = Vec::new();
        let max_dimension = device.limits().max_texture_dimension_2d;
        let base = texture::base_colour(properties, appearance, max_dimension, &mut warnings);
        let texture_size = base.as_ref().map(|b| (b.width, b.height));
        let texture_view = match base {
            Some(base) => {
                texture::upload(device, queue, &texture::mip_chain(base), "mts base colour")
            }
            None => texture::upload(device, queue, &[texture::white()], "mts white"),
        };
        let sampler = texture::sampler(device);
        let colours = properties.colors.is_some();
        let material = [
            f32::from(u8::from(texture_size.is_some())),
            f32::from(u8::from(colours)),
            0.0,
            0.0,
        ];
        let colour = if texture_size.is_some() || colours {
            Vec3::ONE
        } else {
            DEFAULT_COLOUR
        };
        let identity_instance = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts identity instance"),
            size: INSTANCE_BYTES,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(
            &identity_instance,
            0,
            bytemuck::cast_slice(&glam::Mat4::IDENTITY.to_cols_array()),
        );
        let uniform_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts camera"),
            size: std::mem::size_of::<CameraUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mts camera and material layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mts camera and material"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&texture_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mts pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::include_wgsl!("../shaders/mesh.wgsl"));
        // Below the u16 restart value every index fits in 16 bits.
        let index_format = if positions.len() <= usize::from(RESTART_U16) {
            wgpu::IndexFormat::Uint16
        } else {
            wgpu::IndexFormat::Uint32
        };
        let pipeline = |topology, strip_index_format, label| {
            create_pipeline(
                device,
                &pipeline_layout,
                &shader,
                config,
                wgpu::PrimitiveState {
                    topology,
                    strip_index_format,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: Some(wgpu::Face::Back),
                    ..wgpu::PrimitiveState::default()
                },
                label,
            )
        };
        let strip_pipeline = pipeline(
            wgpu::PrimitiveTopology::TriangleStrip,
            Some(index_format),
            "mts strips",
        );
        let list_pipeline = pipeline(wgpu::PrimitiveTopology::TriangleList, None, "mts list");
        Ok(StripRenderer {
            config: *config,
            vertex_buffer,
            vertices,
            vertex_count: positions.len(),
            colour,
            material,
            texture_size,
            warnings,
            identity_instance,
            uniform_buffer,
            bind_group,
            strip_pipeline,
            list_pipeline,
            index_format,
            index_buffer: None,
            index_capacity: 0,
            content: Content::List,
            uploaded_len: None,
            draw: 0..0,
            scratch_u16: Vec::new(),
            scratch_u32: Vec::new(),
        })
    }

    /// [`StripRenderer::new`] for a model's vertices, with normals from its
    /// LoD-0 triangles.
    ///
    /// # Errors
    /// As [`StripRenderer::new`].
    pub fn for_model(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        model: &mts::MtsModel,
    ) -> Result<StripRenderer> {
        StripRenderer::for_model_with(device, queue, config, model, &Appearance::default())
    }

    /// [`StripRenderer::for_model`] drawing the model's properties
    /// ([`mts::MtsModel::properties`]: normals, colours, texture) as
    /// `appearance` asks. A model whose optimal placement created vertices
    /// has no properties for them and is drawn without its properties.
    ///
    /// # Errors
    /// As [`StripRenderer::with_properties`].
    pub fn for_model_with(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        model: &mts::MtsModel,
        appearance: &Appearance,
    ) -> Result<StripRenderer> {
        let triangles = model.base_strips().triangles();
        let positions = model.positions();
        let none = mts::mesh::Properties::default();
        let props = model.properties();
        let fits = props.is_empty() || props.validate(positions).is_ok();
        let props = if fits { props } else { &none };
        StripRenderer::with_properties(
            device, queue, config, positions, &triangles, props, appearance,
        )
    }

    /// [`StripRenderer::new`] for any [`mts::LodSource`]: its own vertices
    /// ([`mts::LodSource::positions`]), normals from its full mesh. Sets
    /// the source to LoD 0 to read that mesh and leaves it uploaded.
    ///
    /// # Errors
    /// As [`StripRenderer::new`] and [`StripRenderer::upload_source`].
    ///
    /// Cost: one LoD change of the source, O(vertices + triangles).
    pub fn for_source(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: &RendererConfig,
        source: &mut dyn mts::LodSource,
    ) -> Result<StripRenderer> {
        source.set_lod(0);
        let mut full = Vec::new();
        match source.topology() {
            mts::Topology::StripRestart => {
                mts::encoding::decode_restart_buffer(source.indices(), &mut full);
            }
            mts::Topology::TriangleList => {
                full.extend(source.indices().chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            }
        }
        let mut renderer = StripRenderer::new(device, queue, config, source.positions(), &full)?;
        renderer.upload_source(device, queue, source)?;
        Ok(renderer)
    }

    /// Why something of the properties is not drawn, one sentence each
    /// naming the image (e.g. `texture /a/b.png: cannot read it (...);
    /// drawn untextured`); empty when everything asked for is drawn.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Width and height of the base-colour texture drawn (level 0), or
    /// `None` when untextured.
    #[must_use]
    pub fn texture_size(&self) -> Option<(u32, u32)> {
        self.texture_size
    }

    /// The formats and strip mode it was built with.
    #[must_use]
    pub fn config(&self) -> &RendererConfig {
        &self.config
    }

    /// The strip mode in use.
    #[must_use]
    pub fn strip_mode(&self) -> StripMode {
        self.config.strip_mode
    }

    /// `Uint16` when the vertex count allows it, else `Uint32`.
    #[must_use]
    pub fn index_format(&self) -> wgpu::IndexFormat {
        self.index_format
    }

    /// Vertices uploaded.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Indices the next [`StripRenderer::draw`] makes the GPU read
    /// (restart values and slot padding included on the restart path).
    #[must_use]
    pub fn indices_drawn(&self) -> usize {
        (self.draw.end - self.draw.start) as usize
    }

    /// Sets the surface colour (linear RGB, each 0..1) that the next
    /// [`StripRenderer::set_camera`] writes; until then [`DEFAULT_COLOUR`],
    /// or white when textured or vertex-coloured
    /// ([`StripRenderer::with_properties`]).
    pub fn set_colour(&mut self, colour: Vec3) {
        self.colour = colour;
    }

    /// Writes `camera` (and the surface colour) into the uniform buffer. Like every
    /// `queue.write_buffer`, it takes effect at the next submission, so one
    /// camera holds per submission.
    pub fn set_camera(&self, queue: &wgpu::Queue, camera: &Camera) {
        let u = CameraUniform {
            view_proj: camera.view_proj.to_cols_array_2d(),
            light_dir: camera
                .light_dir
                .extend(match camera.shading {
                    Shading::Lit => 1.0,
                    Shading::Unlit => 0.0,
                })
                .to_array(),
            colour: self.colour.extend(1.0).to_array(),
            material: self.material,
        };
        queue.write_buffer(&self.uniform_buffer, 0, bytemuck::bytes_of(&u));
    }

    /// Uploads the extractor's whole current output (the first upload, or
    /// after switching content or extractor). Draws only
    /// [`Extractor::active_range`] on the restart path; on the stitched path
    /// the active range is re-encoded without restart values first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when the extractor's model has more
    /// vertices than this renderer; [`Error::Gpu`] when the index buffer
    /// would exceed the device's `max_buffer_size`.
    ///
    /// Cost: O(buffer) conversion (none for `u32` restart) and upload.
    pub fn upload_strips(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        extractor: &Extractor<'_>,
    ) -> Result<Upload> {
        self.check_vertices(extractor.model().positions().len())?;
        self.content = Content::Strips;
        match self.config.strip_mode {
            StripMode::Restart => {
                let buffer = extractor.buffer();
                let upload = self.write_indices(device, queue, buffer, 0..buffer.len())?;
                self.uploaded_len = Some(buffer.len());
                self.draw = to_u32_range(extractor.active_range());
                Ok(upload)
            }
            StripMode::Stitched => self.upload_stitched(device, queue, extractor),
        }
    }

    /// Uploads what the extractor's last `set_lod` changed: one
    /// `queue.write_buffer` per dirty range on the restart path (ranges
    /// widened to 4-byte boundaries with `u16` indices), the re-encoded
    /// active range on the stitched path. Falls back to
    /// [`StripRenderer::upload_strips`] when the buffer does not hold this
    /// extractor's layout yet (first call, or after a list upload).
    ///
    /// Precondition: the strips last uploaded came from the same extractor
    /// and every `set_lod` since has been followed by one call of this
    /// (dirty ranges only describe the last change).
    ///
    /// # Errors
    /// As [`StripRenderer::upload_strips`].
    ///
    /// Cost: O(dirty indices) on the restart path.
    pub fn update_strips(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        extractor: &Extractor<'_>,
    ) -> Result<Upload> {
        let buffer = extractor.buffer();
        if self.config.strip_mode == StripMode::Stitched
            || self.content != Content::Strips
            || self.uploaded_len != Some(buffer.len())
        {
            return self.upload_strips(device, queue, extractor);
        }
        let mut total = Upload::default();
        for range in extractor.dirty_ranges() {
            let u = self.write_indices(device, queue, buffer, range.clone())?;
            total.bytes += u.bytes;
            total.writes += u.writes;
        }
        self.draw = to_u32_range(extractor.active_range());
        Ok(total)
    }

    /// Uploads a restart-encoded strip buffer (runs joined by
    /// [`RESTART_U32`], e.g. [`mts::Strips::to_restart_u32`]) and draws
    /// all of it; stitched first on the stitched path.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when an index is not below the vertex
    /// count; [`Error::Gpu`] as [`StripRenderer::upload_strips`].
    ///
    /// Cost: O(indices).
    pub fn upload_strip_indices(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        indices: &[u32],
    ) -> Result<Upload> {
        self.check_indices(indices.iter().copied().filter(|&i| i != RESTART_U32))?;
        self.content = Content::Strips;
        self.uploaded_len = None;
        match self.config.strip_mode {
            StripMode::Restart => {
                let upload = self.write_indices(device, queue, indices, 0..indices.len())?;
                self.draw = 0..indices.len() as u32;
                Ok(upload)
            }
            StripMode::Stitched => {
                let mut stitched = std::mem::take(&mut self.scratch_u32);
                stitch_restart_buffer(indices, &mut stitched);
                let result = self.write_indices(device, queue, &stitched, 0..stitched.len());
                self.draw = 0..stitched.len() as u32;
                self.scratch_u32 = stitched;
                result
            }
        }
    }

    /// Uploads a triangle list (CCW front faces) and draws it with the list
    /// pipeline.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when an index is not below the vertex
    /// count; [`Error::Gpu`] as [`StripRenderer::upload_strips`].
    ///
    /// Cost: O(triangles).
    pub fn upload_list(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        triangles: &[[u32; 3]],
    ) -> Result<Upload> {
        let flat: &[u32] = bytemuck::cast_slice(triangles);
        self.check_indices(flat.iter().copied())?;
        self.content = Content::List;
        self.uploaded_len = None;
        let upload = self.write_indices(device, queue, flat, 0..flat.len())?;
        self.draw = 0..flat.len() as u32;
        Ok(upload)
    }

    /// Moves the first `positions.len()` vertices to `positions` (normals,
    /// UVs and colours kept), e.g. a geomorph's interpolated positions
    /// ([`mts::baselines::MultilevelMesh::geomorph`]) drawn with the finer
    /// LoD's triangles.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when there are more positions than
    /// vertices.
    ///
    /// Cost: O(positions) and one upload of that prefix.
    pub fn update_positions(&mut self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<()> {
        if positions.len() > self.vertices.len() {
            return Err(Error::InvalidArgument(format!(
                "{} positions for {} vertices",
                positions.len(),
                self.vertices.len()
            )));
        }
        for (v, p) in self.vertices.iter_mut().zip(positions) {
            v.position = p.to_array();
        }
        queue.write_buffer(
            &self.vertex_buffer,
            0,
            bytemuck::cast_slice(&self.vertices[..positions.len()]),
        );
        Ok(())
    }

    /// Uploads the current index buffer of any [`mts::LodSource`] (MTS or a
    /// baseline) whole, by its topology: strips through
    /// [`StripRenderer::upload_strip_indices`], a list through
    /// [`StripRenderer::upload_list`]. The renderer must hold the source's
    /// vertices ([`mts::LodSource::positions`]). For the MTS extractor,
    /// [`StripRenderer::update_strips`] uploads only the dirty ranges.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when a list's length is not a multiple of
    /// three or an index is past the vertices; [`Error::Gpu`] as the upload.
    ///
    /// Cost: O(indices).
    pub fn upload_source(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        source: &dyn mts::LodSource,
    ) -> Result<Upload> {
        match source.topology() {
            mts::Topology::StripRestart => {
                self.upload_strip_indices(device, queue, source.indices())
            }
            mts::Topology::TriangleList => {
                let triangles: &[[u32; 3]] =
                    bytemuck::try_cast_slice(source.indices()).map_err(|e| {
                        Error::InvalidArgument(format!(
                            "{}: a triangle list of {} indices ({e})",
                            source.name(),
                            source.indices().len()
                        ))
                    })?;
                self.upload_list(device, queue, triangles)
            }
        }
    }

    /// Records the draw of the current content into `pass` (which must have
    /// the colour and depth formats of the config). Draws nothing before
    /// the first upload.
    ///
    /// Cost: five commands; no allocation.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        let Some(index_buffer) = &self.index_buffer else {
            return;
        };
        if self.draw.is_empty() {
            return;
        }
        self.bind_single(pass, self.content == Content::Strips);
        pass.set_index_buffer(index_buffer.slice(..), self.index_format);
        pass.draw_indexed(self.draw.clone(), 0, 0..1);
    }

    /// [`StripRenderer::bind`] with the identity transform as the one
    /// instance (slot 1): the caller binds indices and draws one instance,
    /// as [`crate::hierarchy::HierarchyRenderer`] does with its own index
    /// buffer.
    pub(crate) fn bind_single(&self, pass: &mut wgpu::RenderPass<'_>, strips: bool) {
        self.bind(pass, strips);
        pass.set_vertex_buffer(1, self.identity_instance.slice(..));
    }

    /// GPU bytes of its vertex buffer and of its own index buffer (the
    /// texture, the camera uniform and the pipelines left out).
    #[must_use]
    pub fn gpu_bytes(&self) -> usize {
        self.vertex_count * VERTEX_BYTES + self.index_capacity * self.index_size()
    }

    /// Sets the strip (`strips`) or list pipeline, the camera and the
    /// vertices; the caller binds instances (slot 1) and indices, as
    /// [`crate::scene`] does for many instances of one mesh.
    pub(crate) fn bind(&self, pass: &mut wgpu::RenderPass<'_>, strips: bool) {
        pass.set_pipeline(if strips {
            &self.strip_pipeline
        } else {
            &self.list_pipeline
        });
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
    }

    fn upload_stitched(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        extractor: &Extractor<'_>,
    ) -> Result<Upload> {
        let mut stitched = std::mem::take(&mut self.scratch_u32);
        stitch_restart_buffer(&extractor.buffer()[extractor.active_range()], &mut stitched);
        let result = self.write_indices(device, queue, &stitched, 0..stitched.len());
        self.draw = 0..stitched.len() as u32;
        self.scratch_u32 = stitched;
        self.uploaded_len = None;
        result
    }

    fn check_vertices(&self, count: usize) -> Result<()> {
        if count > self.vertex_count {
            return Err(Error::InvalidArgument(format!(
                "the model has {count} vertices, the renderer {}",
                self.vertex_count
            )));
        }
        Ok(())
    }

    fn check_indices(&self, mut indices: impl Iterator<Item = u32>) -> Result<()> {
        match indices.find(|&i| i as usize >= self.vertex_count) {
            Some(i) => Err(Error::InvalidArgument(format!(
                "index {i} is not below the vertex count {}",
                self.vertex_count
            ))),
            None => Ok(()),
        }
    }

    /// Writes `source[range]` at the same index offset of the index buffer,
    /// (re)creating the buffer when `source.len()` does not fit. With `u16`
    /// indices the range is widened to even bounds so that the write is
    /// 4-byte aligned; indices past `source.len()` are written as restarts.
    fn write_indices(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        source: &[u32],
        range: Range<usize>,
    ) -> Result<Upload> {
        // Room for the whole source, rounded up to 4 bytes and never empty.
        let needed = (source.len() + 1) & !1;
        let needed = needed.max(2);
        if self.index_buffer.is_none() || self.index_capacity < needed {
            let bytes = needed * self.index_size();
            check_size(device, bytes, "index buffer")?;
            self.index_buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mts indices"),
                size: bytes as u64,
                usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
            self.index_capacity = needed;
        }
        let Some(buffer) = &self.index_buffer else {
            return Ok(Upload::default());
        };
        if range.is_empty() {
            return Ok(Upload::default());
        }
        let bytes = write_index_range(
            queue,
            buffer,
            self.index_format,
            source,
            range.clone(),
            range.start,
            &mut self.scratch_u16,
        );
        Ok(Upload { bytes, writes: 1 })
    }

    fn index_size(&self) -> usize {
        match self.index_format {
            wgpu::IndexFormat::Uint16 => 2,
            wgpu::IndexFormat::Uint32 => 4,
        }
    }
}

/// Writes `source[range]` (restart values [`RESTART_U32`]) into `buffer`
/// of `format` starting at index `dest`, and returns the bytes written.
/// With `u16` the write is widened to even index bounds (4-byte aligned):
/// one index before when `dest` is odd and one after when the count is odd,
/// both with their current values from `source` (a restart past its end),
/// so the buffer keeps mirroring `source`; the caller makes sure `source`
/// has the index before and `buffer` room for the one after.
pub(crate) fn write_index_range(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    format: wgpu::IndexFormat,
    source: &[u32],
    range: Range<usize>,
    dest: usize,
    scratch: &mut Vec<u16>,
) -> usize {
    match format {
        wgpu::IndexFormat::Uint32 => {
            let data: &[u8] = bytemuck::cast_slice(&source[range]);
            queue.write_buffer(buffer, (dest * 4) as u64, data);
            data.len()
        }
        wgpu::IndexFormat::Uint16 => {
            let lead = dest & 1;
            let count = (range.len() + lead + 1) & !1;
            let first = range.start - lead;
            scratch.clear();
            scratch.extend((first..first + count).map(|i| match source.get(i) {
                Some(&v) if v != RESTART_U32 => v as u16,
                _ => RESTART_U16,
            }));
            let data: &[u8] = bytemuck::cast_slice(scratch);
            queue.write_buffer(buffer, ((dest - lead) * 2) as u64, data);
            data.len()
        }
    }
}

/// The vertex buffer's contents: `positions` with the normals of
/// `properties` where present and non-zero, else area-weighted ones from
/// `triangles`; UVs (zero without); colours rounded to 16 bits (white
/// without). Precondition: `properties` is valid for `positions`.
///
/// Cost: O(vertices + triangles); the computed normals are skipped when
/// every vertex has its own.
fn interleave(positions: &[Vec3], triangles: &[[u32; 3]], properties: &Properties) -> Vec<Vertex> {
    let given = properties.normals.as_deref();
    let computed = match given {
        Some(normals) if !normals.contains(&Vec3::ZERO) => Vec::new(),
        _ => super::vertex_normals(positions, triangles),
    };
    let unorm16 = |c: f32| (c.clamp(0.0, 1.0) * 65535.0).round() as u16;
    positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            let normal = match given.map(|n| n[v]) {
                Some(n) if n != Vec3::ZERO => n,
                _ => computed[v],
            };
            let uv = properties
                .uvs
                .as_ref()
                .map_or([0.0; 2], |t| t[v].to_array());
            let colour = properties
                .colors
                .as_ref()
                .map_or([u16::MAX; 4], |c| c[v].to_array().map(unorm16));
            Vertex {
                position: p.to_array(),
                normal: normal.to_array(),
                uv,
                colour,
            }
        })
        .collect()
}

fn to_u32_range(r: Range<usize>) -> Range<u32> {
    r.start as u32..r.end as u32
}

/// [`Error::Gpu`] when a buffer of `bytes` exceeds the device's
/// `max_buffer_size`.
pub(crate) fn check_size(device: &wgpu::Device, bytes: usize, what: &str) -> Result<()> {
    let max = device.limits().max_buffer_size;
    if bytes as u64 > max {
        return Err(Error::Gpu(format!(
            "{what} of {bytes} bytes exceeds the device's max_buffer_size {max}"
        )));
    }
    Ok(())
}

fn create_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    config: &RendererConfig,
    primitive: wgpu::PrimitiveState,
    label: &str,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            buffers: &[
                Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![
                        0 => Float32x3, 1 => Float32x3, 6 => Float32x2, 7 => Unorm16x4
                    ],
                }),
                Some(wgpu::VertexBufferLayout {
                    array_stride: INSTANCE_BYTES,
                    step_mode: wgpu::VertexStepMode::Instance,
                    attributes: &wgpu::vertex_attr_array![
                        2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4
                    ],
                }),
            ],
        },
        primitive,
        depth_stencil: config.depth_format.map(|format| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: config.color_format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec4};

    #[test]
    fn vertices_take_given_normals_and_fill_in_the_rest() {
        // 3---2
        // | / |   z = 0, CCW from +z: computed normals are +z
        // 0---1
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let t = [[0, 1, 2], [0, 2, 3]];
        let plain = interleave(&p, &t, &Properties::default());
        assert_eq!(VERTEX_BYTES, 40);
        assert!(plain
            .iter()
            .all(|v| v.normal == [0.0, 0.0, 1.0] && v.uv == [0.0; 2] && v.colour == [u16::MAX; 4]));
        // A zero normal is "none": that vertex alone gets the computed one.
        let properties = Properties {
            normals: Some(vec![Vec3::X, Vec3::ZERO, Vec3::Y, Vec3::NEG_Z]),
            uvs: Some(vec![Vec2::new(0.5, 2.0); 4]),
            colors: Some(vec![Vec4::new(0.0, 0.5, 1.0, 0.25); 4]),
            ..Properties::default()
        };
        let v = interleave(&p, &t, &properties);
        let normals: Vec<[f32; 3]> = v.iter().map(|v| v.normal).collect();
        assert_eq!(
            normals,
            [
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, -1.0]
            ]
        );
        assert_eq!(v[3].uv, [0.5, 2.0]);
        // 0.5 * 65535 = 32767.5 rounds up; 0.25 * 65535 = 16383.75.
        assert_eq!(v[3].colour, [0, 32768, 65535, 16384]);
    }
}
