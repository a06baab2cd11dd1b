//! Properties of the vertices optimal placement creates on a mesh with
//! properties.
//!
//! A step contracting points `a` and `b` to `p` creates one vertex per
//! seam pair `(va, vb)` (`seams.rs`). Its properties are interpolated from
//! the nearest point of the old surface along the contracted edge: the
//! pair's two vertices' values weighted by where `p` projects on segment
//! `a`–`b` (clamped to it), normals renormalised, colours clamped to
//! 0..=1, texture coordinates left as they are.
//!
//! Chosen over the attribute quadric's minimiser at `p` (Hoppe 1999,
//! closed form in the split quadrics of `attributes.rs`) because
//! - the value is a convex combination of the two it replaces, so it never
//!   leaves their range: no texture coordinate off its chart and no colour
//!   out of gamut, where the minimiser extrapolates every gathered
//!   triangle's linear function to `p`, which is far from most of them at
//!   coarse levels;
//! - it exists for every stream, whereas the attribute quadrics hold only
//!   the channels whose [`crate::simplify::AttributeWeights`] is positive;
//! - it depends only on the pair, so a seam's sides (different pairs of
//!   the same step) stay exactly as far apart as they were.
//!
//! The cost ([`super::attributes::Attributes::cost_between`]) measures this
//! same value against both vertices' quadrics.

use super::*;
use crate::mesh::Properties;

/// Where `p` projects on segment `pa`–`pb`, from 0 at `pa` to 1 at `pb`
/// (0.5 for a segment of zero length).
pub(super) fn along(pa: DVec3, pb: DVec3, p: DVec3) -> f64 {
    let e = pb - pa;
    let l2 = e.length_squared();
    if l2 > 0.0 {
        ((p - pa).dot(e) / l2).clamp(0.0, 1.0)
    } else {
        0.5
    }
}

/// Appends to every stream of `props` the value `t` of the way from vertex
/// `va`'s to `vb`'s (see the module docs).
pub(super) fn push_interpolated(props: &mut Properties, va: u32, vb: u32, t: f64) {
    let t = t as f32;
    let (a, b) = (va as usize, vb as usize);
    if let Some(n) = &mut props.normals {
        let v = n[a].lerp(n[b], t).normalize_or_zero();
        n.push(v);
    }
    if let Some(uv) = &mut props.uvs {
        let v = uv[a].lerp(uv[b], t);
        uv.push(v);
    }
    if let Some(c) = &mut props.colors {
        let v = c[a].lerp(c[b], t).clamp(glam::Vec4::ZERO, glam::Vec4::ONE);
        c.push(v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec4};

    #[test]
    fn values_follow_the_projection_on_the_edge() {
        let (pa, pb) = (DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(along(pa, pb, DVec3::new(0.5, 3.0, -1.0)), 0.25);
        assert_eq!(along(pa, pb, DVec3::new(-1.0, 0.0, 0.0)), 0.0);
        assert_eq!(along(pa, pb, DVec3::new(9.0, 0.0, 0.0)), 1.0);
        assert_eq!(along(pa, pa, pb), 0.5);

        let mut p = Properties {
            normals: Some(vec![Vec3::X, Vec3::Y]),
            uvs: Some(vec![Vec2::new(0.0, 1.0), Vec2::new(2.0, -1.0)]),
            colors: Some(vec![Vec4::ZERO, Vec4::ONE]),
            ..Default::default()
        };
        push_interpolated(&mut p, 0, 1, 0.25);
        assert_eq!(p.uvs.as_ref().unwrap()[2], Vec2::new(0.5, 0.5));
        assert_eq!(p.colors.as_ref().unwrap()[2], Vec4::splat(0.25));
        let n = p.normals.as_ref().unwrap()[2];
        assert!((n.length() - 1.0).abs() < 1e-6, "{n}");
        assert!((n - Vec3::new(0.75, 0.25, 0.0).normalize()).length() < 1e-6);
        // Opposite normals cancel: no normal (zero), never NaN.
        let mut q = Properties {
            normals: Some(vec![Vec3::Z, -Vec3::Z]),
            ..Default::default()
        };
        push_interpolated(&mut q, 0, 1, 0.5);
        assert_eq!(q.normals.unwrap()[2], Vec3::ZERO);
        assert!(p.validate(&[Vec3::ZERO; 3]).is_ok());
    }
}
