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

    /// How this camera turns world units into pixels on a viewport
    /// `viewport_height` pixels high, for the core's screen-space error
    /// rule ([`mts::lod_for_screen_error`], [`mts::Projection`]): read
    /// from [`Camera::view_proj`], whose view part must be a rotation and
    /// translation (as [`Camera::looking`] and [`Camera::framing`] make).
    /// A perspective matrix (a clip `w` that depends on the point) gives
    /// [`mts::Projection::Perspective`] with the field of view whose
    /// half-angle's cotangent is the projection's `y` scale (the length of
    /// the matrix's second row); otherwise the matrix is orthographic and
    /// shows `2 / y scale` world units over the viewport's height.
    ///
    /// Cost: O(1).
    #[must_use]
    pub fn projection(&self, viewport_height: f32) -> mts::Projection {
        let y_scale = self.view_proj.row(1).truncate().length();
        if self.view_proj.row(3).truncate() == Vec3::ZERO {
            mts::Projection::Orthographic {
                view_height: 2.0 / y_scale,
                viewport_height,
            }
        } else {
            mts::Projection::Perspective {
                fov_y: 2.0 * (1.0 / y_scale).atan(),
                viewport_height,
            }
        }
    }

    /// Depth of `point` in front of the eye along the view axis, world
    /// units (the clip `w` of a perspective camera; 1 for an orthographic
    /// one, whose pixels per unit do not depend on it).
    #[must_use]
    pub fn depth_of(&self, point: Vec3) -> f32 {
        self.view_proj.row(3).dot(point.extend(1.0))
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

    /// The projection read back from the matrix has the field of view it
    /// was made with, and a world unit face-on at depth `d` covers the
    /// pixels the matrix maps it to.
    #[test]
    fn projection_is_read_back_from_the_matrix() {
        let c = Camera::looking(Vec3::new(1.0, 2.0, 9.0), Vec3::ZERO, 1.5, 0.1, 100.0);
        let mts::Projection::Perspective {
            fov_y,
            viewport_height,
        } = c.projection(600.0)
        else {
            panic!("a perspective camera");
        };
        assert!((fov_y - FRAMING_FOV_Y).abs() < 1e-6, "{fov_y}");
        assert_eq!(viewport_height, 600.0);
        let eye = Vec3::new(1.0, 2.0, 9.0);
        let forward = -eye.normalize();
        let up = forward.cross(Vec3::Y).cross(forward).normalize();
        let at = eye + forward * 7.0;
        assert!((c.depth_of(at) - 7.0).abs() < 1e-4);
        let ndc = |p: Vec3| c.view_proj.project_point3(p).y;
        let pixels = (ndc(at + up) - ndc(at)) * 0.5 * 600.0;
        let ppu = c.projection(600.0).pixels_per_unit(7.0);
        assert!((pixels - ppu).abs() < 1e-3 * ppu, "{pixels} {ppu}");
        let ortho = Camera {
            view_proj: glam::camera::rh::proj::directx::orthographic(
                -4.0, 4.0, -2.5, 2.5, 0.0, 10.0,
            ),
            ..c
        };
        assert_eq!(ortho.projection(500.0).pixels_per_unit(3.0), 100.0);
    }

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
