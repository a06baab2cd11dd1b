//! # mts-render — the wgpu renderer of mts: draws what the extractor emits
//!
//! It embeds into a host's own wgpu device, queue and render pass; the core
//! crate (`mts`) knows nothing of it.
//!
//! - [`gpu`]: instance, adapter and device for headless use, and the
//!   [`AdapterReport`] (adapter, backend, strip mode).
//! - [`strip_renderer`]: [`StripRenderer`], which embeds into a caller's own
//!   device, queue and render pass; strips with primitive restart (or
//!   degenerate stitching where the backend ignores restart) and triangle
//!   lists through one pipeline layout and one shader (`shaders/mesh.wgsl`);
//!   vertex normals, colours and UVs of a mesh's properties.
//! - [`texture`]: the base-colour texture ([`Appearance`]): decoded PNG or
//!   JPEG, or a checker; mipmapped on the CPU, RGBA8 sRGB.
//! - [`headless`]: render to a texture, read it back, write a PNG.
//! - [`image_error`]: how far a LoD frame is from the truth (the
//!   full-detail frame supersampled), in units of the full-detail frame's
//!   own error at one sample per pixel.
//! - [`camera`]: a default camera that frames a bounding box.
//! - [`stats`]: the adapter's own counts for a draw (vertex-shader,
//!   clipper and fragment invocations; GPU time), where it offers them.
//! - [`scene`]: many instances of one model, each with its own LoD and
//!   coherence cache, frustum-culled.
//! - [`hierarchy`]: [`HierarchyRenderer`], a view-dependent
//!   [`mts::hierarchy::Hierarchy`] drawn as one strip draw of its
//!   [`mts::hierarchy::ViewDependent`] arena, only the changed ranges
//!   written camera after camera.
//!
//! The interactive viewer (winit) lives in the `mts` command (`mts-cli`).

pub mod camera;
pub mod gpu;
pub mod headless;
pub mod hierarchy;
pub mod image_error;
pub mod scene;
pub mod stats;
pub mod strip_renderer;
pub mod texture;

pub use camera::{Camera, Shading};
pub use gpu::{AdapterReport, Gpu, StripMode};
pub use headless::{Difference, HeadlessTarget, Image};
pub use hierarchy::{HierarchyFrame, HierarchyRenderer};
pub use scene::{
    BvhUpdate, FrameStats, HierarchyId, HierarchyInstanceId, InstanceId, InstancedScene, ModelId,
    SceneMemory,
};
pub use stats::{DrawMeasurement, DrawQueries, PipelineCounts};
pub use strip_renderer::{RendererConfig, StripRenderer, Upload, VERTEX_BYTES};
pub use texture::Appearance;
/// The wgpu this renderer is built with, so that embedders use the same
/// version.
pub use wgpu;

use glam::Vec3;

/// Area-weighted vertex normals: each triangle adds its unnormalised face
/// normal (twice its area, CCW front) to its three vertices, then each sum
/// is normalised. A vertex in no triangle gets the zero vector (the shader
/// lights it as if it faced the light).
///
/// Triangles with an index out of range are skipped. Cost: O(vertices +
/// triangles), one allocation.
#[must_use]
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for &[a, b, c] in triangles {
        let (a, b, c) = (a as usize, b as usize, c as usize);
        if a.max(b).max(c) >= positions.len() {
            continue;
        }
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    for n in &mut normals {
        *n = n.normalize_or_zero();
    }
    normals
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_ccw_square_point_up() {
        // 3---2
        // | / |
        // 0---1   (z = 0, seen from +z: counter-clockwise)
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(5.0, 5.0, 5.0),
        ];
        let n = vertex_normals(&p, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(&n[..4], &[Vec3::Z; 4]);
        assert_eq!(n[4], Vec3::ZERO);
    }
}
