//! The camera [`crate::StripRenderer`] draws with, and a default one
//! that frames a bounding box.
//!
//! Conventions: right-handed world, wgpu clip space (depth 0..1), +y up.

use glam::camera::rh::proj::directx::perspective;
use glam::camera::rh::view::look_at_mat4;
use glam::{Mat4, Vec3};

/// A view-projection matrix, the direction of the one light and the
/// shading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// World to clip space (wgpu: x, y in -1..1, depth 0..1).
    pub view_proj: Mat4,
    /// Unit direction from the surface towards the light, world space.
    pub light_dir: Vec3,
    /// Lit, or one flat colour.
    pub shading: Shading,
}

/// How fragments are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// Lambert lighting from the interpolated vertex normals.
    #[default]
    Lit,
    /// The base colour everywhere: an image of coverage alone, which does
    /// not depend on how the rasteriser interpolates (see `tests/render.rs`
    /// for why that matters when comparing strips with lists).
    Unlit,
}

/// Vertical field of view of [`Camera::framing`], radians (40°).
pub const FRAMING_FOV_Y: f32 = 40.0 * std::f32::consts::PI / 180.0;

impl Camera {
    /// A perspective camera that sees the whole box `min..max` from the
    /// front-right and above (direction (0.8, 0.5, 1.3) from the centre),
    /// with the box's bounding sphere just inside the narrower field of
    /// view, and a light from over the viewer's left shoulder.
    ///
    /// `aspect` is width / height. A degenerate box (a point) is framed as
    /// a unit sphere. Cost: O(1).
    #[must_use]
    pub fn framing(min: Vec3, max: Vec3, aspect: f32) -> Camera {
        let centre = (min + max) * 0.5;
        let mut radius = (max - min).length() * 0.5;
        if !(radius.is_finite() && radius > 0.0) {
            radius = 1.0;
        }
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let half_y = FRAMING_FOV_Y * 0.5;
        let half_x = (half_y.tan() * aspect).atan();
        // 5% margin around the sphere.
        let distance = 1.05 * radius / half_y.min(half_x).sin();
        let dir = Vec3::new(0.8, 0.5, 1.3).normalize();
        let eye = centre + dir * distance;
        let view = look_at_mat4(eye, centre, Vec3::Y);
        let near = (distance - radius * 1.1).max(distance * 1e-3);
        let far = distance + radius * 1.1;
        // wgpu's clip space is Direct3D's: depth 0..1, y up.
        let proj = perspective(FRAMING_FOV_Y, aspect, near, far);
        let light_dir = (dir + Vec3::new(-0.6, 0.8, 0.0)).normalize();
        Camera {
            view_proj: proj * view,
            light_dir,
            shading: Shading::Lit,
        }
    }

    /// A perspective camera at `eye` looking at `target` (+y up, vertical
    /// field of view [`FRAMING_FOV_Y`]), depth range `near..far` in world
    /// units, lit from over the viewer's left shoulder. Cost: O(1).
    #[must_use]
    pub fn looking(eye: Vec3, target: Vec3, aspect: f32, near: f32, far: f32) -> Camera {
        let view = look_at_mat4(eye, target, Vec3::Y);
        let proj = perspective(FRAMING_FOV_Y, aspect, near, far);
        let dir = (eye - target).normalize_or(Vec3::Z);
        Camera {
            view_proj: proj * view,
            light_dir: (dir + Vec3::new(-0.6, 0.8, 0.0)).normalize_or(Vec3::Y),
            shading: Shading::Lit,
        }
    }

    /// [`Camera::framing`] of the bounding box of `positions` (a unit
    /// sphere at the origin when there are none). Cost: O(positions).
    #[must_use]
    pub fn framing_points(positions: &[Vec3], aspect: f32) -> Camera {
        let (min, max) = mts::mesh::bounds_of(positions).unwrap_or_default();
        Camera::framing(min, max, aspect)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framed_box_corners_are_inside_the_view() {
        let (min, max) = (Vec3::new(-1.0, 2.0, -3.0), Vec3::new(4.0, 3.0, 1.0));
        for aspect in [0.5, 1.0, 2.0] {
            let c = Camera::framing(min, max, aspect);
            for i in 0..8 {
                let p = Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                );
                let q = c.view_proj.project_point3(p);
                assert!(q.x.abs() < 1.0 && q.y.abs() < 1.0, "{aspect} {p} -> {q}");
                assert!(q.z > 0.0 && q.z < 1.0, "{aspect} {p} -> {q}");
            }
        }
    }
}
