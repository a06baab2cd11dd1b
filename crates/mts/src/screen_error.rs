//! Level of detail by screen-space error: the coarsest LoD whose recorded
//! geometric error, projected where the instance comes nearest to the
//! camera, stays within a pixel threshold.
//!
//! The error of LoD `k` is [`Collapses::error`] (the running maximum over
//! the first `k` contractions, so it never decreases with `k`) times the
//! input's bounding-box diagonal: a distance in model units. An instance
//! scales it by the largest axis scale of its transform, and a perspective
//! projection shrinks it by the distance from the eye to the instance's
//! nearest point (its bounding sphere's, so the bound is conservative: no
//! point of the instance is nearer). The LoD is found by a binary search
//! over the monotone table, O(log LoDs), with no allocation.
//!
//! The recorded error is what the simplifier measured (quadric distance
//! and the distance of the removed input vertices to the new surface),
//! not a Hausdorff distance: it can miss a deviation between samples, so
//! the threshold is a target rather than a guarantee; the scene benchmark
//! measures the resulting image difference.

use crate::lod::LodSource;
use crate::simplify::Collapses;
use glam::Vec3;

/// How model units become pixels on the screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// A perspective camera: `fov_y` radians of vertical field of view
    /// over `viewport_height` pixels.
    Perspective {
        /// Vertical field of view in radians (0 to π, exclusive).
        fov_y: f32,
        /// Height of the viewport in pixels.
        viewport_height: f32,
    },
    /// An orthographic camera showing `view_height` world units over
    /// `viewport_height` pixels, whatever the distance.
    Orthographic {
        /// World units the viewport spans vertically.
        view_height: f32,
        /// Height of the viewport in pixels.
        viewport_height: f32,
    },
}

impl Projection {
    /// Pixels that one world unit, seen face-on at `distance` from the eye,
    /// covers on the screen. Infinite for a perspective camera at distance
    /// 0 or less (the eye inside the bounds), and 0 for a projection whose
    /// parameters are not positive and finite (nothing can be seen).
    #[must_use]
    pub fn pixels_per_unit(&self, distance: f32) -> f32 {
        match *self {
            Projection::Perspective {
                fov_y,
                viewport_height,
            } => {
                let valid = fov_y > 0.0
                    && fov_y < std::f32::consts::PI
                    && viewport_height > 0.0
                    && viewport_height.is_finite();
                if !valid {
                    return 0.0;
                }
                if distance.is_nan() || distance <= 0.0 {
                    return f32::INFINITY;
                }
                viewport_height / (2.0 * distance * (0.5 * fov_y).tan())
            }
            Projection::Orthographic {
                view_height,
                viewport_height,
            } => {
                let valid = view_height > 0.0
                    && view_height.is_finite()
                    && viewport_height > 0.0
                    && viewport_height.is_finite();
                if valid {
                    viewport_height / view_height
                } else {
                    0.0
                }
            }
        }
    }
}

/// Distance from `eye` to the nearest point of the sphere at `centre` with
/// `radius` (0 when the eye is inside it). It stands for the depth of that
/// point: off the view axis the depth is shorter (at the edge of a 60°
/// field of view by cos 30°), so there an error projects up to 15% larger
/// than computed; the threshold absorbs it rather than every instance
/// paying for a per-view computation.
#[must_use]
pub fn nearest_distance(eye: Vec3, centre: Vec3, radius: f32) -> f32 {
    (eye.distance(centre) - radius).max(0.0)
}

/// The coarsest LoD of `collapses` whose error, in model units
/// (`diagonal` is the input's bounding-box diagonal, the unit of
/// [`Collapses::error`]) times `scale` (the instance's largest axis scale),
/// covers at most `pixel_threshold` pixels at `pixels_per_unit` (from
/// [`Projection::pixels_per_unit`] at the instance's nearest distance).
///
/// LoD 0 when even the first contraction's error is too large, and also
/// when the threshold or the scale is not a finite number above 0 (no
/// error is allowed, or the input is not understood: full detail is the
/// safe answer). With 0 pixels per unit (nothing visible) the coarsest
/// LoD. O(log LoDs).
///
/// # Example
///
/// ```
/// use mts::mesh::generate::Generated;
/// use mts::{lod_for_screen_error, simplify, Projection, SimplifyOptions};
///
/// let mesh = "torus:4k".parse::<Generated>()?.build();
/// let collapses = simplify(&mesh, &SimplifyOptions::default()).collapses;
/// let camera = Projection::Perspective { fov_y: 60f32.to_radians(), viewport_height: 1080.0 };
/// // At most one pixel of error, the instance at scale 1 seen from `distance`.
/// let lod_at = |distance: f32| {
///     let pixels_per_unit = camera.pixels_per_unit(distance);
///     lod_for_screen_error(&collapses, mesh.diagonal(), 1.0, pixels_per_unit, 1.0)
/// };
/// let (near, far) = (lod_at(2.0), lod_at(200.0));
/// assert!(near < far && far <= collapses.max_lod());
/// let pixels = |lod: usize, distance: f32| {
///     f64::from(collapses.error(lod))
///         * f64::from(mesh.diagonal())
///         * f64::from(camera.pixels_per_unit(distance))
/// };
/// // The coarsest LoD within the threshold: one more contraction exceeds it.
/// assert!(pixels(near, 2.0) <= 1.0 && pixels(near + 1, 2.0) > 1.0);
/// # Ok::<(), mts::Error>(())
/// ```
#[must_use]
pub fn lod_for_screen_error(
    collapses: &Collapses,
    diagonal: f32,
    scale: f32,
    pixels_per_unit: f32,
    pixel_threshold: f32,
) -> usize {
    relative_error_limit(diagonal, scale, pixels_per_unit, pixel_threshold)
        .map_or(0, |limit| coarsest_within(collapses, limit))
}

/// The largest relative error (a [`Collapses::error`]) that
/// [`lod_for_screen_error`] allows, `None` when its arguments ask for full
/// detail.
pub(crate) fn relative_error_limit(
    diagonal: f32,
    scale: f32,
    pixels_per_unit: f32,
    pixel_threshold: f32,
) -> Option<f64> {
    let sane = |x: f32| x.is_finite() && x > 0.0;
    let diagonal_ok = diagonal.is_finite() && diagonal >= 0.0;
    if !sane(pixel_threshold) || !sane(scale) || !diagonal_ok || pixels_per_unit.is_nan() {
        return None;
    }
    // Largest allowed error relative to the diagonal: error × diagonal ×
    // scale × pixels_per_unit <= threshold.
    let per_relative = f64::from(diagonal) * f64::from(scale) * f64::from(pixels_per_unit);
    Some(if per_relative == 0.0 {
        f64::INFINITY
    } else {
        f64::from(pixel_threshold) / per_relative
    })
}

/// [`lod_for_screen_error`] for any [`LodSource`] built from `collapses`:
/// every source numbers its LoDs by the contractions of the sequence it
/// was built from (`docs/design.md`, "Level-of-detail numbering"), so the
/// sequence's error table answers for it too; the LoD is clamped to the
/// source's `max_lod`.
/// Discrete LoDs draw the coarsest stored level with at least the LoD's
/// triangle count, simplified by meshoptimizer: at least as many
/// triangles, with meshoptimizer's error rather than the sequence's.
#[must_use]
pub fn lod_for_screen_error_of(
    source: &dyn LodSource,
    collapses: &Collapses,
    diagonal: f32,
    scale: f32,
    pixels_per_unit: f32,
    pixel_threshold: f32,
) -> usize {
    lod_for_screen_error(collapses, diagonal, scale, pixels_per_unit, pixel_threshold)
        .min(source.max_lod())
}

/// The coarsest LoD whose relative error is at most `limit` (binary search
/// over the non-decreasing errors; LoD 0's is 0).
pub(crate) fn coarsest_within(collapses: &Collapses, limit: f64) -> usize {
    let (mut lo, mut hi) = (0, collapses.max_lod());
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if f64::from(collapses.error(mid)) <= limit {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::Generated;
    use crate::simplify::{simplify, SimplifyOptions};

    fn torus() -> (Collapses, f32) {
        let mesh = "torus:4k".parse::<Generated>().unwrap().build();
        let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
        (c, mesh.diagonal())
    }

    #[test]
    fn the_chosen_lod_is_the_coarsest_within_the_threshold() {
        let (c, diagonal) = torus();
        let projection = Projection::Perspective {
            fov_y: 60f32.to_radians(),
            viewport_height: 1080.0,
        };
        let mut last = 0;
        for distance in [0.5f32, 1.0, 2.0, 5.0, 20.0, 100.0, 1000.0] {
            let ppu = projection.pixels_per_unit(distance);
            let lod = lod_for_screen_error(&c, diagonal, 1.0, ppu, 1.0);
            let pixels =
                |lod: usize| f64::from(c.error(lod)) * f64::from(diagonal) * f64::from(ppu);
            assert!(pixels(lod) <= 1.0 + 1e-9, "{distance}: {}", pixels(lod));
            if lod < c.max_lod() {
                assert!(
                    pixels(lod + 1) > 1.0,
                    "{distance}: LoD {lod} is not the coarsest"
                );
            }
            // Farther never asks for more detail.
            assert!(lod >= last, "{distance}: {lod} < {last}");
            last = lod;
        }
        // Far enough, the coarsest; near enough, full detail.
        let far = lod_for_screen_error(&c, diagonal, 1.0, projection.pixels_per_unit(1e7), 1.0);
        assert_eq!(far, c.max_lod());
        let inside = lod_for_screen_error(&c, diagonal, 1.0, projection.pixels_per_unit(0.0), 1.0);
        assert_eq!(c.error(inside), 0.0);
        assert!(inside == c.max_lod() || c.error(inside + 1) > 0.0);
    }

    #[test]
    fn a_larger_instance_or_a_tighter_threshold_asks_for_more_detail() {
        let (c, diagonal) = torus();
        let ppu = 50.0;
        let base = lod_for_screen_error(&c, diagonal, 1.0, ppu, 1.0);
        assert!(base > 0 && base < c.max_lod(), "{base} of {}", c.max_lod());
        assert!(lod_for_screen_error(&c, diagonal, 4.0, ppu, 1.0) < base);
        assert!(lod_for_screen_error(&c, diagonal, 1.0, ppu, 0.25) < base);
        assert!(lod_for_screen_error(&c, diagonal, 1.0, ppu, 4.0) > base);
        // Scaling the instance by 2 is halving the threshold.
        assert_eq!(
            lod_for_screen_error(&c, diagonal, 2.0, ppu, 1.0),
            lod_for_screen_error(&c, diagonal, 1.0, ppu, 0.5)
        );
    }

    #[test]
    fn nonsense_asks_for_full_detail_and_nothing_visible_for_the_coarsest() {
        let (c, diagonal) = torus();
        for (scale, ppu, threshold) in [
            (1.0, 10.0, f32::NAN),
            (1.0, 10.0, -1.0),
            (1.0, 10.0, 0.0),
            (f32::NAN, 10.0, 1.0),
            (0.0, 10.0, 1.0),
            (f32::INFINITY, 10.0, 1.0),
            (1.0, f32::NAN, 1.0),
        ] {
            assert_eq!(lod_for_screen_error(&c, diagonal, scale, ppu, threshold), 0);
        }
        assert_eq!(
            lod_for_screen_error(&c, diagonal, 1.0, 0.0, 1.0),
            c.max_lod()
        );
        let broken = Projection::Perspective {
            fov_y: f32::NAN,
            viewport_height: 100.0,
        };
        assert_eq!(broken.pixels_per_unit(3.0), 0.0);
    }

    #[test]
    fn a_baseline_built_from_the_sequence_gets_the_same_lod() {
        let mesh = "torus:4k".parse::<Generated>().unwrap().build();
        let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
        let pm = crate::baselines::ProgressiveMesh::new(&mesh, &c).unwrap();
        for ppu in [1.0f32, 20.0, 200.0, 5000.0] {
            let lod = lod_for_screen_error(&c, mesh.diagonal(), 1.0, ppu, 1.0);
            assert_eq!(
                lod_for_screen_error_of(&pm, &c, mesh.diagonal(), 1.0, ppu, 1.0),
                lod
            );
            assert_eq!(pm.triangle_count(lod), c.triangle_count(lod));
        }
    }

    #[test]
    fn projections_convert_units_to_pixels() {
        let p = Projection::Perspective {
            fov_y: 90f32.to_radians(),
            viewport_height: 1000.0,
        };
        // At distance 1 with a 90° field of view the screen spans 2 units.
        assert!((p.pixels_per_unit(1.0) - 500.0).abs() < 1e-3);
        assert!((p.pixels_per_unit(10.0) - 50.0).abs() < 1e-3);
        assert_eq!(p.pixels_per_unit(0.0), f32::INFINITY);
        let o = Projection::Orthographic {
            view_height: 4.0,
            viewport_height: 800.0,
        };
        assert_eq!(o.pixels_per_unit(1.0), 200.0);
        assert_eq!(o.pixels_per_unit(1e9), 200.0);
        assert_eq!(
            nearest_distance(Vec3::ZERO, Vec3::new(3.0, 4.0, 0.0), 1.0),
            4.0
        );
        assert_eq!(nearest_distance(Vec3::ZERO, Vec3::X, 2.0), 0.0);
    }
}
