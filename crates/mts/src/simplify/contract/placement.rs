//! Where the survivor of a contraction goes, chosen once per run: the
//! [`Place`] strategy the contractor is generic over. Everything that
//! differs between the two placements of [`crate::simplify::Placement`]
//! lives here, with the state only one of them keeps; the loop, the guards
//! and the queue are shared.
//!
//! - [`Endpoint`] moves the removed vertex onto the kept one (the default:
//!   every LoD's vertices are input vertices, so the strips and the
//!   extractor index one vertex buffer). It keeps per vertex the input
//!   positions it stands for, for the tie-break and the distances.
//! - [`Optimal`] moves both onto the merged quadric's best point, a new
//!   vertex appended after the input's; the kept vertex moves too, so the
//!   guards look at its fan as well.
//!
//! The contractor is monomorphised per strategy ([`super::simplify`]
//! matches the option once), so the hot loop has no branch on it.

use super::*;

/// A placement strategy: what [`Contractor`] asks where it differs.
pub(super) trait Place: Sized + Sync {
    /// Whether the kept vertex moves too, so its fan needs the guards'
    /// checks as the removed one's does.
    const MOVES_KEPT: bool;

    /// The strategy's state for `mesh`, given the face quadrics (before
    /// border planes are added).
    fn new(mesh: &Mesh, quadrics: &[Quadric]) -> Self;

    /// Position of created vertex `i` (0 for the first one appended).
    fn created(&self, i: usize) -> DVec3;

    /// Every vertex's first choice, queued in vertex order.
    fn choose_all(c: &mut Contractor<Self>);

    /// The cheapest target of `v` no guard refused yet: `(cost, target)`.
    fn best(c: &mut Contractor<Self>, v: u32) -> Option<(f64, u32)>;

    /// Cost of contracting `v` with `w`.
    fn pair_cost(c: &Contractor<Self>, v: u32, w: u32) -> f64;

    /// Where the surviving vertex of `a → b` goes.
    fn target(c: &Contractor<Self>, a: u32, b: u32) -> DVec3;

    /// The distances measured when a choice pops, after the guards passed:
    /// `(forward, wait)`, where a `wait` above the queued cost puts the
    /// choice back at that cost.
    fn distances(c: &mut Contractor<Self>, a: u32, b: u32, cost: f32) -> (f64, f64);

    /// The error recorded for `a → b` (squared, in model units), before it
    /// enters the running maximum.
    fn recorded_error(c: &Contractor<Self>, a: u32, target: DVec3, cost: f32, forward: f64) -> f64;

    /// Joins `a`'s per-vertex state into the survivor's and returns the
    /// survivor: `b`, or a vertex created at `target`.
    fn merge(c: &mut Contractor<Self>, a: u32, b: u32, target: DVec3) -> u32;

    /// Asks for `v`'s strategy state ahead of its use.
    fn prefetch(&self, v: u32);

    /// The created vertices' positions, rounded for the output.
    fn into_created(self) -> Vec<Vec3>;
}

/// Endpoint placement: `a` moves onto `b`.
pub(super) struct Endpoint {
    /// The input positions each vertex stands for (its own and those
    /// contracted into it), for the tie-breaking term of
    /// [`Contractor::cost`].
    pub(super) anchors: Vec<PointSum>,
    /// The input vertices each vertex stands for, as circular lists:
    /// `members[v]` is `v`'s input position and the next vertex of its
    /// cycle. A vertex alone points to itself; moving `a` onto `b` joins
    /// their cycles by swapping the two links. The position sits beside
    /// the link so a walk loads one line per member.
    pub(super) members: Vec<(Vec3, u32)>,
    /// An upper bound on the distance from `v`'s input position to the
    /// input position of any member of its cycle (0 alone); moving `a`
    /// onto `b` raises `b`'s to `|a - b| + radius[a]` where larger (the
    /// triangle inequality, rounded up). [`Contractor::forward_error`]
    /// skips the walk over `a`'s members when no member can be farther
    /// from `b`'s fan than the distance already found.
    pub(super) radius: Vec<f64>,
}

impl Place for Endpoint {
    const MOVES_KEPT: bool = false;

    fn choose_all(c: &mut Contractor<Self>) {
        c.choose_all_in_parallel();
    }

    fn new(mesh: &Mesh, quadrics: &[Quadric]) -> Self {
        // Each vertex's anchor: its own position, weighted like its face
        // planes.
        let anchors = quadrics
            .iter()
            .zip(&mesh.positions)
            .map(|(q, p)| PointSum::point(p.as_dvec3(), q.weight()))
            .collect();
        let members = (0..mesh.vertex_count() as u32)
            .map(|v| (mesh.positions[v as usize], v))
            .collect();
        let radius = vec![0.0; mesh.vertex_count()];
        Endpoint {
            anchors,
            members,
            radius,
        }
    }

    fn created(&self, _: usize) -> DVec3 {
        unreachable!("endpoint placement creates no vertex")
    }

    #[inline]
    fn best(c: &mut Contractor<Self>, v: u32) -> Option<(f64, u32)> {
        if c.stars.get(v).is_some() {
            c.best_endpoint_wide(v)
        } else {
            c.best_endpoint(v)
        }
    }

    #[inline]
    fn pair_cost(c: &Contractor<Self>, v: u32, w: u32) -> f64 {
        c.cost(v, w)
    }

    #[inline]
    fn target(c: &Contractor<Self>, _: u32, b: u32) -> DVec3 {
        c.p(b)
    }

    #[inline]
    fn distances(c: &mut Contractor<Self>, a: u32, b: u32, cost: f32) -> (f64, f64) {
        c.distances(a, b, cost)
    }

    /// The planes' part of the cost and the forward distance, without the
    /// tie-break.
    #[inline]
    fn recorded_error(c: &Contractor<Self>, a: u32, target: DVec3, _: f32, forward: f64) -> f64 {
        c.quadrics[a as usize].mean_error(target).max(forward)
    }

    #[inline]
    fn merge(c: &mut Contractor<Self>, a: u32, b: u32, _: DVec3) -> u32 {
        let this = &mut c.place;
        this.anchors[b as usize] = this.anchors[a as usize] + this.anchors[b as usize];
        let (after_a, after_b) = (this.members[a as usize].1, this.members[b as usize].1);
        this.members[a as usize].1 = after_b;
        this.members[b as usize].1 = after_a;
        let (pa, pb) = (this.members[a as usize].0, this.members[b as usize].0);
        let reach = (pa.as_dvec3() - pb.as_dvec3()).length() + this.radius[a as usize];
        // Rounded up, so that the bound stays above the true distance.
        let reach = reach * (1.0 + 1e-12);
        let r = &mut this.radius[b as usize];
        *r = r.max(reach);
        b
    }

    #[inline]
    fn prefetch(&self, v: u32) {
        self.anchors[v as usize].prefetch();
    }

    fn into_created(self) -> Vec<Vec3> {
        Vec::new()
    }
}

/// Optimal placement: `a` and `b` both move onto the merged quadric's best
/// point, a created vertex.
pub(super) struct Optimal {
    /// Positions of the created vertices (`f64`, after the input's; rounded
    /// to `f32` once, for the output, in [`Place::into_created`]).
    created: Vec<DVec3>,
}

impl Place for Optimal {
    const MOVES_KEPT: bool = true;

    fn choose_all(c: &mut Contractor<Self>) {
        c.choose_each();
    }

    fn new(_: &Mesh, _: &[Quadric]) -> Self {
        Optimal {
            created: Vec::new(),
        }
    }

    fn created(&self, i: usize) -> DVec3 {
        self.created[i]
    }

    fn best(c: &mut Contractor<Self>, v: u32) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        let mut around = std::mem::take(&mut c.around);
        around.clear();
        c.partners_into(v, &mut around);
        let refused = if c.refusals.is_empty(v) {
            None
        } else {
            Some(c.mark_refusals(v))
        };
        for &w in &around {
            if refused.is_some_and(|epoch| c.mark[w as usize] == epoch) {
                continue;
            }
            let cost = Self::pair_cost(c, v, w);
            if best.is_none_or(|(bc, bw)| cost < bc || (cost == bc && w < bw)) {
                best = Some((cost, w));
            }
        }
        c.around = around;
        best
    }

    fn pair_cost(c: &Contractor<Self>, v: u32, w: u32) -> f64 {
        let q = c.quadrics[v as usize] + c.quadrics[w as usize];
        let (p, cost) = if c.is_locked(w) {
            (c.p(w), q.mean_error(c.p(w)))
        } else {
            c.optimal_point(&q, v, w)
        };
        match &c.attributes {
            Some(a) => cost + a.cost_between(v, w, p, created::along(c.p(v), c.p(w), p)),
            None => cost,
        }
    }

    /// The locked endpoint's position when `b` is locked (`a` never is:
    /// it has no queue entry).
    fn target(c: &Contractor<Self>, a: u32, b: u32) -> DVec3 {
        if c.is_locked(b) {
            return c.p(b);
        }
        let q = c.quadrics[a as usize] + c.quadrics[b as usize];
        c.optimal_point(&q, a, b).0
    }

    /// None: the created vertex's cost is its error.
    fn distances(_: &mut Contractor<Self>, _: u32, _: u32, _: f32) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// The queue's cost, less the attribute cost where there is one (the
    /// recorded error is geometric).
    fn recorded_error(c: &Contractor<Self>, a: u32, target: DVec3, cost: f32, _: f64) -> f64 {
        match (&c.attributes, c.queued[a as usize].1) {
            (Some(_), b) if b != NONE => {
                (c.quadrics[a as usize] + c.quadrics[b as usize]).mean_error(target)
            }
            _ => f64::from(cost),
        }
    }

    /// A vertex created onto a locked one stands for it: it is locked too.
    fn merge(c: &mut Contractor<Self>, _: u32, b: u32, target: DVec3) -> u32 {
        c.place.created.push(target);
        let survivor = c.push_vertex();
        if c.is_locked(b) {
            c.locked[survivor as usize] = true;
        }
        survivor
    }

    fn prefetch(&self, _: u32) {}

    fn into_created(self) -> Vec<Vec3> {
        self.created.iter().map(|p| p.as_vec3()).collect()
    }
}
