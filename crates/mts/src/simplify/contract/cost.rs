//! What a contraction costs and where the survivor goes: the quadric cost
//! of moving a vertex onto another, the tie-break, and the optimal point
//! (which of them a contraction uses is the [`Place`] strategy's choice).

use super::*;

impl Contractor<Endpoint> {
    /// Cost of moving `removed` onto `kept` (endpoint placement): the mean
    /// squared distance from the kept position to the removed vertex's
    /// planes. Only the removed vertex's quadric counts, since the kept one
    /// does not move (meshoptimizer ranks the same way; the sum of both,
    /// Garland and Heckbert's cost, measured 1.26 against 1.00 times
    /// meshoptimizer's Hausdorff on `ogre` at 10%), and the mean (not the
    /// area-weighted sum) keeps large flat regions from looking expensive.
    ///
    /// Plus [`TIE_BREAK`] times the mean squared distance from the kept
    /// position to the input positions `removed` stands for. Without it, in
    /// flat regions (every plane cost zero up to rounding) the choice fell
    /// to rounding and vertex order, and one vertex could absorb a whole
    /// flat patch; its quadric's mean was then so diluted by the patch's
    /// planes that moving it off a crease looked free (fandisk at 10%:
    /// Hausdorff 1.51 × meshoptimizer's). meshoptimizer adds the same kind
    /// of term (a point quadric of weight 1e-7 of the face weights). The
    /// recorded error leaves it out ([`Contractor::contract`]).
    pub(super) fn cost(&self, removed: u32, kept: u32) -> f64 {
        let p = self.p(kept);
        let mut cost = self.quadrics[removed as usize].mean_error(p)
            + TIE_BREAK * self.place.anchors[removed as usize].mean_error(p);
        if let Some(a) = &self.attributes {
            cost += a.cost(removed, kept, p);
        }
        cost
    }
}

impl<P: Place> Contractor<P> {
    /// The quadric's minimiser, or the best of the endpoints and midpoint.
    pub(super) fn optimal_point(&self, q: &Quadric, a: u32, b: u32) -> (DVec3, f64) {
        let (pa, pb) = (self.p(a), self.p(b));
        let mut best = (pb, q.mean_error(pb));
        for p in [pa, 0.5 * (pa + pb)].into_iter().chain(q.minimizer()) {
            let cost = q.mean_error(p);
            if cost < best.1 {
                best = (p, cost);
            }
        }
        best
    }
}
