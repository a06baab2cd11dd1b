//! Error quadrics (Garland and Heckbert, "Surface Simplification Using
//! Quadric Error Metrics", SIGGRAPH 1997, sections 5 and 6).
//!
//! A quadric is the symmetric 4×4 matrix `Σ wᵢ pᵢ pᵢᵀ` of weighted planes
//! `pᵢ = (n, d)` with `n·x + d = 0`; evaluated at a point it gives the
//! weighted sum of squared distances to those planes. Sums are in `f64`: the
//! `d²` terms of a mesh far from the origin cancel badly in `f32`.

use glam::{DVec3, Vec3};

/// A weighted sum of squared plane distances.
///
/// Stores the ten distinct coefficients of the symmetric matrix and the
/// total weight (the area for face planes), so that [`Quadric::mean_error`] can turn
/// a cost into a distance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quadric {
    /// a², ab, ac, ad, b², bc, bd, c², cd, d² — the upper triangle row by row.
    m: [f64; 10],
    /// Sum of the weights of the planes added.
    weight: f64,
}

impl Quadric {
    /// The quadric of the plane through `point` with unit normal `normal`,
    /// scaled by `weight`.
    #[must_use]
    pub fn plane(normal: DVec3, point: DVec3, weight: f64) -> Quadric {
        let [a, b, c] = normal.to_array();
        let d = -normal.dot(point);
        let w = weight;
        Quadric {
            m: [
                w * a * a,
                w * a * b,
                w * a * c,
                w * a * d,
                w * b * b,
                w * b * c,
                w * b * d,
                w * c * c,
                w * c * d,
                w * d * d,
            ],
            weight,
        }
    }

    /// The area-weighted quadric of a triangle's plane, or `None` for a
    /// triangle of zero area (it has no plane).
    #[must_use]
    pub fn triangle(p0: Vec3, p1: Vec3, p2: Vec3) -> Option<Quadric> {
        let (p0, p1, p2) = (p0.as_dvec3(), p1.as_dvec3(), p2.as_dvec3());
        let cross = (p1 - p0).cross(p2 - p0);
        let double_area = cross.length();
        (double_area > 0.0).then(|| Quadric::plane(cross / double_area, p0, 0.5 * double_area))
    }

    /// Weighted sum of squared distances from `p` to the planes. Never
    /// negative (rounding is clamped).
    #[must_use]
    #[inline]
    pub fn evaluate(&self, p: DVec3) -> f64 {
        let m = &self.m;
        let [x, y, z] = p.to_array();
        let v = m[0] * x * x
            + 2.0 * m[1] * x * y
            + 2.0 * m[2] * x * z
            + 2.0 * m[3] * x
            + m[4] * y * y
            + 2.0 * m[5] * y * z
            + 2.0 * m[6] * y
            + m[7] * z * z
            + 2.0 * m[8] * z
            + m[9];
        v.max(0.0)
    }

    /// This quadric with every plane's weight multiplied by `factor`.
    #[must_use]
    pub fn scaled(mut self, factor: f64) -> Quadric {
        for a in &mut self.m {
            *a *= factor;
        }
        self.weight *= factor;
        self
    }

    /// This quadric with its weight set to zero: its error adds to a sum
    /// without diluting the mean of [`Quadric::evaluate`]` / weight`.
    #[must_use]
    pub fn without_weight(mut self) -> Quadric {
        self.weight = 0.0;
        self
    }

    /// Asks the cache for every line of this quadric (88 bytes span two or
    /// three lines; loads 48 bytes apart reach each of them).
    #[inline]
    pub(crate) fn prefetch(&self) {
        super::prefetch(&self.m[0]);
        super::prefetch(&self.m[6]);
        super::prefetch(&self.weight);
    }

    /// Sum of the weights of the planes in this quadric.
    #[must_use]
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Mean squared plane distance at `p`: [`Quadric::evaluate`] divided by
    /// the weight (0 for an empty quadric). The contraction cost.
    #[must_use]
    #[inline]
    pub fn mean_error(&self, p: DVec3) -> f64 {
        if self.weight > 0.0 {
            self.evaluate(p) / self.weight
        } else {
            0.0
        }
    }

    /// The point that minimises the quadric, when the 3×3 system is well
    /// conditioned (section 4 of the paper); `None` when the planes do not
    /// pin a point down (flat or cylindrical neighbourhoods), in which case
    /// the caller falls back to a candidate point.
    #[must_use]
    pub fn minimizer(&self) -> Option<DVec3> {
        let m = &self.m;
        let a = glam::DMat3::from_cols(
            DVec3::new(m[0], m[1], m[2]),
            DVec3::new(m[1], m[4], m[5]),
            DVec3::new(m[2], m[5], m[7]),
        );
        let det = a.determinant();
        // Relative to the cube of the largest diagonal term: below 1e-9 the
        // solution moves by more than the model's size for rounding-level
        // changes of the planes (tuned on the bunny: 1e-6 rejected useful
        // corners, 1e-12 let points fly off along creases).
        let scale = m[0].max(m[4]).max(m[7]);
        if scale <= 0.0 || det.abs() <= 1e-9 * scale * scale * scale {
            return None;
        }
        let p = a.inverse() * -DVec3::new(m[3], m[6], m[8]);
        p.is_finite().then_some(p)
    }
}

impl std::ops::Add for Quadric {
    type Output = Quadric;
    fn add(mut self, rhs: Quadric) -> Quadric {
        self += rhs;
        self
    }
}

impl std::ops::AddAssign for Quadric {
    fn add_assign(&mut self, rhs: Quadric) {
        for (a, b) in self.m.iter_mut().zip(rhs.m) {
            *a += b;
        }
        self.weight += rhs.weight;
    }
}

/// A weighted sum of squared distances to points, `Σ wᵢ |x − aᵢ|²`, kept
/// as `(Σ wᵢ, Σ wᵢ aᵢ, Σ wᵢ |aᵢ|²)` (40 bytes; sums add like quadrics).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PointSum {
    weight: f64,
    sum: DVec3,
    squares: f64,
}

impl PointSum {
    /// The squared distance to `point`, scaled by `weight`.
    #[must_use]
    pub fn point(point: DVec3, weight: f64) -> PointSum {
        PointSum {
            weight,
            sum: point * weight,
            squares: weight * point.length_squared(),
        }
    }

    /// Asks the cache for the sum (it may straddle two lines).
    #[inline]
    pub(crate) fn prefetch(&self) {
        super::prefetch(&self.weight);
        super::prefetch(&self.squares);
    }

    /// The points' weighted mean `m` and `c`, the mean of their squared
    /// lengths: [`PointSum::mean_error`] at `x` is [`PointSum::spread`]`(x,
    /// m, c)`, one division for many evaluations. `None` without weight.
    #[must_use]
    #[inline]
    pub fn centre(&self) -> Option<(DVec3, f64)> {
        (self.weight > 0.0).then(|| {
            let inv = 1.0 / self.weight;
            (self.sum * inv, self.squares * inv)
        })
    }

    /// `|x|² − 2 x·m + c` for the `(m, c)` of [`PointSum::centre`]
    /// (rounding is clamped).
    #[must_use]
    #[inline]
    pub fn spread(x: DVec3, mean: DVec3, squares: f64) -> f64 {
        (x.length_squared() - 2.0 * x.dot(mean) + squares).max(0.0)
    }

    /// The weighted mean squared distance from `x` to the points (zero
    /// without weight), by [`PointSum::centre`] and [`PointSum::spread`]:
    /// callers that evaluate one sum at many points get the same values.
    #[must_use]
    #[inline]
    pub fn mean_error(&self, x: DVec3) -> f64 {
        self.centre()
            .map_or(0.0, |(mean, squares)| PointSum::spread(x, mean, squares))
    }
}

impl std::ops::Add for PointSum {
    type Output = PointSum;
    fn add(self, rhs: PointSum) -> PointSum {
        PointSum {
            weight: self.weight + rhs.weight,
            sum: self.sum + rhs.sum,
            squares: self.squares + rhs.squares,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_distance_is_squared_and_weighted() {
        let q = Quadric::plane(DVec3::Z, DVec3::new(0.0, 0.0, 1.0), 2.0);
        assert!((q.evaluate(DVec3::new(5.0, -3.0, 4.0)) - 2.0 * 9.0).abs() < 1e-12);
        assert_eq!(q.evaluate(DVec3::new(7.0, 1.0, 1.0)), 0.0);
        assert!((q.mean_error(DVec3::new(5.0, -3.0, 4.0)) - 9.0).abs() < 1e-12);
    }

    #[test]
    fn triangle_weight_is_its_area() {
        let q = Quadric::triangle(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        )
        .unwrap();
        assert!((q.weight() - 3.0).abs() < 1e-12);
        assert!(Quadric::triangle(Vec3::ZERO, Vec3::X, Vec3::X * 2.0).is_none());
    }

    #[test]
    fn point_sums_measure_mean_squared_distance() {
        let s = PointSum::point(DVec3::ZERO, 1.0) + PointSum::point(DVec3::new(2.0, 0.0, 0.0), 3.0);
        // (1 · 1 + 3 · 1) / 4 at the midpoint, (1 · 4 + 0) / 4 at the second.
        assert!((s.mean_error(DVec3::X) - 1.0).abs() < 1e-12);
        assert!((s.mean_error(DVec3::new(2.0, 0.0, 0.0)) - 1.0).abs() < 1e-12);
        assert!(
            (s.mean_error(DVec3::new(1.5, 1.0, 0.0)) - (3.25 + 3.0 * 1.25) / 4.0).abs() < 1e-12
        );
        assert_eq!(PointSum::default().mean_error(DVec3::ONE), 0.0);
        let (m, c) = s.centre().unwrap();
        let x = DVec3::new(1.5, 1.0, 0.0);
        assert_eq!(PointSum::spread(x, m, c), s.mean_error(x));
    }

    #[test]
    fn three_planes_meet_at_the_minimizer() {
        let corner = DVec3::new(1.0, 2.0, 3.0);
        let q = Quadric::plane(DVec3::X, corner, 1.0)
            + Quadric::plane(DVec3::Y, corner, 1.0)
            + Quadric::plane(DVec3::Z, corner, 1.0);
        let p = q.minimizer().unwrap();
        assert!((p - corner).length() < 1e-9);
        // Two planes leave a line of minimizers: no unique point.
        let line = Quadric::plane(DVec3::X, corner, 1.0) + Quadric::plane(DVec3::Y, corner, 1.0);
        assert!(line.minimizer().is_none());
    }
}
