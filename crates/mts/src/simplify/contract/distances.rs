//! The distances a popped choice waits on: forward (the moved vertex's
//! input positions to the new fan), backward (the new fan's centroids to
//! the old fans) and border (new border midpoints), each measured against
//! triangles as prisms (see the module docs of [`super`]).

use super::*;

/// A triangle prepared for [`over_within`]: corners, unit normal (zero
/// when degenerate) and the inward normals of its edges' planes through
/// the normal, so a point over the triangle's interior is found by dot
/// products alone.
pub(super) struct Prism {
    pub(super) corners: [DVec3; 3],
    pub(super) normal: DVec3,
    pub(super) sides: [DVec3; 3],
}

impl Prism {
    fn new(corners: [DVec3; 3]) -> Prism {
        let normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        let sides = [0, 1, 2].map(|i| normal.cross(corners[(i + 1) % 3] - corners[i]));
        Prism {
            corners,
            normal,
            sides,
        }
    }

    /// Squared distance from `p` to the triangle's plane where `p` lies
    /// over the triangle (the exact squared distance then), else `None`.
    fn over(&self, p: DVec3) -> Option<f64> {
        if self.normal == DVec3::ZERO {
            return None;
        }
        let inside = (0..3).all(|i| (p - self.corners[i]).dot(self.sides[i]) >= 0.0);
        inside.then(|| {
            let plane = (p - self.corners[0]).dot(self.normal);
            plane * plane
        })
    }

    fn distance2(&self, p: DVec3) -> f64 {
        let [x, y, z] = self.corners;
        (closest_on_triangle_f64(p, x, y, z) - p).length_squared()
    }
}

/// Squared distance from `p` to the nearest of `triangles` by the exact
/// closest-point test, or to the first one found within `within` (the
/// caller only asks whether it is farther); infinite when there are none.
/// For a point [`over_within`] did not settle: near an edge or a corner,
/// or farther than `within`.
pub(super) fn exact_within(triangles: &[Prism], p: DVec3, within: f64) -> f64 {
    let mut nearest = f64::INFINITY;
    for t in triangles {
        nearest = nearest.min(t.distance2(p));
        if nearest <= within {
            break;
        }
    }
    nearest
}

/// Whether `p` lies over one of `triangles` within `within` of its plane
/// (then within `within` of the surface): four dot products a triangle,
/// which settle most members of a fan.
pub(super) fn over_within(triangles: &[Prism], p: DVec3, within: f64) -> bool {
    triangles
        .iter()
        .any(|t| t.over(p).is_some_and(|d| d <= within))
}

impl Contractor<Endpoint> {
    /// Squared distance from `a`'s input position to the nearest triangle
    /// of its fan once `a` is moved onto `b`, or of `b`'s when none of
    /// `a`'s survives (zero when neither has one); or, where larger than
    /// both that and `limit`, the largest squared distance from an input
    /// vertex contracted into `a` earlier (its [`Endpoint::members`]) to
    /// `b`'s fan after the move.
    ///
    /// The quadric cost measures how far `b` lies from `a`'s planes, the
    /// mean over everything `a` stands for: a vertex at the tip of a thin
    /// feature, or one whose mean is diluted by a large flat patch it
    /// absorbed, can look cheap while the surface leaves it behind.
    /// Raising the cost to this distance when it is larger (see
    /// [`Contractor::run`]; the quadric cost is then a lower bound, and a
    /// raised choice waits in the queue at the larger cost) took the geometric
    /// mean of the 40 Hausdorff ratios to meshoptimizer's from 0.898 to
    /// 0.851 and the rows above 1.15 × from 5 to 4: homer at 1% 1.23 →
    /// 1.02, ogre at 10% 1.19 → 1.06, beetle at 1% 2.77 → 2.07, but
    /// bunny_compact at 1% 0.87 → 1.16 and bunny_res4 at 1% 1.22 → 2.16.
    /// The distance weighted by 0.5 or 2 measured worse (0.861 and
    /// 0.905), and so did choosing among all of `a`'s targets by the
    /// larger cost at each pop (0.864). Cost: about 10% of the sequence's
    /// time (bunny 98 → 108 ms in alternating runs).
    ///
    /// The members: `a`'s own input position is one of the points the
    /// surface must stay near; every input vertex contracted into `a`
    /// before is another, and a move can leave one of those behind while
    /// `a`'s own stays close (the tip of a feature absorbed two steps
    /// earlier). With them measured as well, over 6 vertex orders of the 40
    /// rows the geometric mean of the median ratios to meshoptimizer's
    /// Hausdorff went 0.796 → 0.746 (bunny_res4 at 1% 2.25 → 0.78, cow at
    /// 10% 0.66 → 0.42, bunny at 1% 0.63 → 0.57; teapot at 10% 0.89 →
    /// 1.02). Only a member farther than the largest distance so far and
    /// `limit` needs an exact distance: each scan stops at the first
    /// triangle within them ([`over_within`], then [`exact_within`]).
    /// [`Contractor::distances`] passes the planes' mean error as `limit`,
    /// the rest of what the step records, so the recorded error covers
    /// every member. Measured and not kept: checking only the first 8
    /// members (0.764, fandisk at 1% 1.70) and only at creased fans (0.781,
    /// bunny_res4 at 1% 2.32), and skipping interior fans flat within 5°
    /// (0.745; the 1M icosphere 2.6 → 2.24 s, the bunny unchanged). Cost:
    /// the bunny's sequence about 103 → 130 ms, the 1M icosphere's 1.85 →
    /// 2.6 s in alternating runs (18% of the bunny's checks and 25% of the
    /// icosphere's are raised by a member and pop twice; callgrind on the
    /// bunny 898M → 1088M instructions).
    pub(super) fn forward_error(&mut self, a: u32, b: u32, limit: f64) -> f64 {
        let (pa, pb) = (self.p(a), self.p(b));
        let moved = self.nearest_around(pa, a, b, pb, 0.0);
        // Every triangle of `a` dies (an ear, or a vertex between two
        // borders): the surface left is `b`'s.
        let nearest = if moved.is_finite() {
            moved
        } else {
            self.nearest_around(pa, b, a, pb, 0.0)
        };
        let nearest = if nearest.is_finite() { nearest } else { 0.0 };
        if self.place.members[a as usize].1 == a {
            return nearest;
        }
        // Every triangle of `b`'s fan after the move has `b` as a corner,
        // so no member lies farther from it than from `b`, at most
        // `|a - b| + radius[a]` (the triangle inequality, with a margin
        // far above the rounding of either side): when that is within what
        // is already found, no member can raise it, and the walk, which
        // would change nothing, is skipped. Without this a mesh whose
        // vertices all sit on one point (every member at distance 0, but
        // every triangle degenerate, so each member took a full scan)
        // walked all of them at every step: torus:20k so made took 9.7 s
        // to simplify, torus:40k over a minute.
        let bound = (pa - pb).length() + self.place.radius[a as usize];
        if bound * bound * (1.0 + 1e-6) <= nearest.max(limit) {
            return nearest;
        }
        // `b`'s fan after the move: `a`'s triangles without `b` (moved),
        // which settle most members by dot products, and `b`'s without
        // `a`, added for the first member they do not settle (the full
        // scan then covers both). Bunny: 2% fewer instructions than
        // preparing both up front; the sequence is the same.
        let mut after = std::mem::take(&mut self.after);
        after.clear();
        after.extend(self.corners_around(a, b, pb).map(Prism::new));
        let moved = after.len();
        let mut worst = nearest.max(limit);
        let mut member_farther = false;
        let mut u = self.place.members[a as usize].1;
        while u != a {
            let (p, next) = self.place.members[u as usize];
            prefetch(&self.place.members[next as usize]);
            let p = p.as_dvec3();
            u = next;
            // Within `worst` of `b`, a corner of every triangle scanned.
            if (p - pb).length_squared() * (1.0 + 1e-9) <= worst {
                continue;
            }
            if over_within(&after[..moved], p, worst) {
                continue;
            }
            if after.len() == moved {
                after.extend(self.corners_around(b, a, pb).map(Prism::new));
            }
            if over_within(&after[moved..], p, worst) {
                continue;
            }
            let d = exact_within(&after, p, worst);
            if d > worst && d.is_finite() {
                worst = d;
                member_farther = true;
            }
        }
        self.after = after;
        if member_farther {
            worst
        } else {
            nearest
        }
    }

    /// The distances a popped choice `a → b` at queue cost `cost` must stay
    /// within (endpoint placement, after [`Contractor::check`] passed):
    /// `(forward, wait)`, the forward distance for the recorded error and
    /// the largest of the distances, at which the choice waits where it
    /// exceeds `cost`. The moved vertex's input position must stay near
    /// the triangles that replace its fan ([`Contractor::forward_error`]);
    /// where the fan is creased, those triangles must stay near the old
    /// surface ([`Contractor::backward_error`]; a flat fan's replacements
    /// lie in its plane), and where `a` is on a border, so must its new
    /// border edges ([`Contractor::border_error`]). Each later check stops
    /// early once it is within the largest so far.
    pub(super) fn distances(&mut self, a: u32, b: u32, cost: f32) -> (f64, f64) {
        // Members are measured exactly above the planes' mean error, the
        // rest of what the step records, so the recorded error covers each.
        let planes = self.quadrics[a as usize].mean_error(self.p(b));
        let forward = self.forward_error(a, b, planes);
        let mut wait = forward;
        if creased(&self.fan) {
            let limit = f64::from(cost).max(wait) * (1.0 + 1e-4);
            if let Some(backward) = self.backward_error(a, b, limit) {
                wait = wait.max(backward);
            }
        }
        if self.fan_on_border {
            let limit = f64::from(cost).max(wait) * (1.0 + 1e-4);
            if let Some(border) = self.border_error(a, b, limit) {
                wait = wait.max(border);
            }
        }
        (forward, wait)
    }
}

impl<P: Place> Contractor<P> {
    /// [`BACKWARD_WEIGHT`] times the largest squared distance from the
    /// centroid of a triangle that replaces `a`'s fan (moving `a` onto
    /// `b`) to the old surface, the live triangles around `a` and `b`
    /// before the move; `None` when every centroid is within `limit` of
    /// it. Reads the surviving triangles [`Contractor::check`] left in
    /// `self.fan`.
    ///
    /// The quadric cost and the forward distance look from the input
    /// towards the new surface; where a fan is creased the new triangles
    /// can cut across the old surface while every vertex stays near it
    /// (beetle at 10%: one contraction took the Hausdorff distance from
    /// 0.0108 to 0.0188 while its recorded error was 0.0093, the far
    /// point on a new triangle). Measured over 6 vertex orders of each of
    /// the 40 rows (`examples/order_spread.rs`), the geometric mean of the
    /// median ratios to meshoptimizer's Hausdorff went 0.865 → 0.826 and
    /// the rows with some order above 1.15 × 10 → 6; in the files' own
    /// orders 0.855 → 0.821 and 4 → 3 rows above. Ungated (every fan) it
    /// gave 0.809 and 6 rows at about 65% more time: nearly every choice is
    /// then raised once and pops twice. See [`CREASE_COS`] for the gate.
    ///
    /// Early exit: each centroid is tested first against the triangle it
    /// came from, and a scan stops at the first triangle within `limit`;
    /// only a centroid farther than `limit` from all of them costs a full
    /// scan, and its distance is then exact.
    pub(super) fn backward_error(&self, a: u32, b: u32, limit: f64) -> Option<f64> {
        let within = limit / BACKWARD_WEIGHT;
        let (pa, pb) = (self.p(a), self.p(b));
        let mut worst: Option<f64> = None;
        for turn in &self.fan {
            let (y, z) = (self.p(turn.after), self.p(turn.before));
            let centroid = (pb + y + z) / 3.0;
            if (closest_on_triangle_f64(centroid, pa, y, z) - centroid).length_squared() <= within {
                continue;
            }
            let nearest = self.nearest_old(centroid, a, b, within);
            if nearest > within {
                let error = BACKWARD_WEIGHT * nearest;
                worst = Some(worst.map_or(error, |w: f64| w.max(error)));
            }
        }
        worst
    }

    /// [`BORDER_WEIGHT`] times the largest squared distance from the
    /// midpoint of a new border edge `(x, b)`, where `(a, x)` was a border
    /// edge of one triangle, to the old surface around `a` and `b`; `None`
    /// when every midpoint is within `limit`. Reads `self.fan` as
    /// [`Contractor::backward_error`] does.
    ///
    /// A border vertex that slides along its border onto `b` makes its
    /// other border neighbour `x` the start of a new border edge to `b`.
    /// Where the border turned inwards at `a` (a notch), that edge cuts
    /// across area the input does not cover, which no plane of a quadric
    /// sees when the fan is flat (alligator at 1%: one contraction took
    /// the Hausdorff distance from 0.0042 to 0.0115 with a recorded error
    /// of 0.0033). Over 6 vertex orders of the 40 rows: alligator at 1%
    /// median 1.49 → 0.79 × meshoptimizer's Hausdorff, geometric mean of
    /// the medians 0.826 → 0.811, rows with some order above 1.15 × 6 → 5;
    /// in the files' orders 0.821 → 0.813. Only border vertices pay for it.
    pub(super) fn border_error(&self, a: u32, b: u32, limit: f64) -> Option<f64> {
        let within = limit / BORDER_WEIGHT;
        let pb = self.p(b);
        let mut worst: Option<f64> = None;
        for turn in &self.fan {
            for x in [turn.after, turn.before] {
                if x == b || self.triangles_on(a, x) != 1 {
                    continue;
                }
                let midpoint = 0.5 * (pb + self.p(x));
                let nearest = self.nearest_old(midpoint, a, b, within);
                if nearest > within {
                    let error = BORDER_WEIGHT * nearest;
                    worst = Some(worst.map_or(error, |w: f64| w.max(error)));
                }
            }
        }
        worst
    }

    /// Squared distance from `p` to the nearest live triangle around `a`
    /// or `b` as they are before `a` moves, or the first one found within
    /// `within` (the callers only ask whether it is farther).
    pub(super) fn nearest_old(&self, p: DVec3, a: u32, b: u32, within: f64) -> f64 {
        let around_a = self.nearest_around(p, a, NONE, self.p(a), within);
        if around_a <= within {
            return around_a;
        }
        around_a.min(self.nearest_around(p, b, NONE, self.p(b), within))
    }

    /// Live triangles around `a` on edge `(a, x)` (`a`'s list holds every
    /// triangle on the edge); from `a`'s star when it is current.
    pub(super) fn triangles_on(&self, a: u32, x: u32) -> usize {
        if let Some(star) = self.stars.get(a) {
            return star.count(x);
        }
        self.fans
            .get(a)
            .iter()
            .filter(|&&t| {
                let tri = self.tris[t as usize];
                tri[0] != DEAD && tri.contains(&x)
            })
            .count()
    }

    /// Squared distance from `p` to the nearest live triangle around `v`
    /// that does not contain `without` ([`NONE`] for none: no live
    /// triangle holds it), with `v` placed at `at` (infinite when there is
    /// none); the first one found within `within` ends the scan (0 for the
    /// exact minimum).
    pub(super) fn nearest_around(
        &self,
        p: DVec3,
        v: u32,
        without: u32,
        at: DVec3,
        within: f64,
    ) -> f64 {
        let mut nearest = f64::INFINITY;
        for [x, y, z] in self.corners_around(v, without, at) {
            nearest = nearest.min((closest_on_triangle_f64(p, x, y, z) - p).length_squared());
            if nearest <= within {
                break;
            }
        }
        nearest
    }

    /// Corners of the live triangles around `v` that do not contain
    /// `without` ([`NONE`] for none), with `v` placed at `at`: `v`'s fan
    /// after a move, for [`Contractor::nearest_around`] and the member
    /// walk's [`Prism`]s.
    pub(super) fn corners_around(
        &self,
        v: u32,
        without: u32,
        at: DVec3,
    ) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.fans.get(v).iter().filter_map(move |&t| {
            let tri = self.tris[t as usize];
            (tri[0] != DEAD && !tri.contains(&without))
                .then(|| tri.map(|w| if w == v { at } else { self.p(w) }))
        })
    }
}
