//! Each vertex's choice: its cheapest allowed target, queued as one key
//! per vertex, asked again when its neighbourhood changes, refusals
//! remembered until then (see the module docs of [`super`], "One queue entry
//! per vertex", "A refused target is remembered").

use super::*;

impl<P: Place> Contractor<P> {
    /// Every vertex's first choice, one refresh per vertex in vertex
    /// order.
    pub(super) fn choose_each(&mut self) {
        for v in 0..self.removed.len() as u32 {
            self.refresh(v);
        }
    }

    /// Recomputes `v`'s cheapest contraction and queues it when it changed
    /// (the old entry then goes stale).
    pub(super) fn refresh(&mut self, v: u32) {
        // Drop the triangles that died around `v` while it stayed (a wide
        // fan's current star says none did).
        if self.fans.get(v).len() > WIDE {
            let tris = &self.tris;
            self.stars
                .update(v, &mut self.fans, tris, |t| tris[t as usize][0] != DEAD);
        } else {
            self.fans.retain(v, |t| self.tris[t as usize][0] != DEAD);
        }
        if self.is_locked(v) {
            return;
        }
        let new = P::best(self, v).map_or((f32::INFINITY, NONE), |(c, w)| (c as f32, w));
        let old = self.queued[v as usize];
        if new.0 != old.0 || new.1 != old.1 {
            self.queue(v, new.0, new.1);
        }
    }

    /// Makes `v → target` at `cost` the vertex's one current entry (none
    /// for [`NONE`]). A key is pushed only when `cost` is below every key
    /// `v` has in the queue; otherwise the lowest one pops first and is
    /// pushed again at the then queued cost (see [`Contractor::heap`]).
    /// Keys are not told apart by target: equal keys pop together and the
    /// first stands for the current choice.
    pub(super) fn queue(&mut self, v: u32, cost: f32, target: u32) {
        if self.is_locked(v) {
            // A locked vertex is never removed: it has no entry.
            return;
        }
        self.queued[v as usize] = (cost, target);
        let bits = cost_bits(cost);
        if target != NONE && bits < self.floor[v as usize] {
            self.floor[v as usize] = bits;
            self.heap.push(key(cost, v));
        }
    }

    /// Forgets what the guards refused `v`, so that it chooses among all
    /// its targets again.
    pub(super) fn forget_refusals(&mut self, v: u32) {
        self.refusals.forget(v);
    }

    /// Queues `v → w` if it is cheaper than `v`'s queued contraction.
    pub(super) fn offer(&mut self, v: u32, w: u32) {
        let cost = P::pair_cost(self, v, w) as f32;
        let (old_cost, old_target) = self.queued[v as usize];
        if old_target != w && (cost < old_cost || (cost == old_cost && w < old_target)) {
            self.queue(v, cost, w);
        }
    }

    /// Forgets every refusal and queues every live vertex again.
    pub(super) fn requeue_all(&mut self) {
        for v in 0..self.removed.len() as u32 {
            self.forget_refusals(v);
            if !self.removed[v as usize] {
                self.queued[v as usize] = (f32::NAN, NONE);
                self.floor[v as usize] = NO_KEY;
                self.refresh(v);
            }
        }
    }

    /// Appends every current neighbour and virtual partner of `v` to `out`,
    /// once each, in fan order (from `v`'s star when it is current).
    pub(super) fn partners_into(&mut self, v: u32, out: &mut Vec<u32>) {
        let epoch = self.next_epoch();
        if let Some(star) = self.stars.get(v) {
            for &w in star.neighbours() {
                self.mark[w as usize] = epoch;
                out.push(w);
            }
        } else {
            for &t in self.fans.get(v) {
                let tri = self.tris[t as usize];
                if tri[0] == DEAD {
                    continue;
                }
                for w in tri {
                    if w != v && self.mark[w as usize] != epoch {
                        self.mark[w as usize] = epoch;
                        out.push(w);
                    }
                }
            }
        }
        if let Some(partners) = self.partners.get(v as usize) {
            for &w in partners {
                if !self.removed[w as usize] && self.mark[w as usize] != epoch {
                    self.mark[w as usize] = epoch;
                    out.push(w);
                }
            }
        }
    }

    /// Marks the targets refused to `v` with a fresh epoch, which it
    /// returns: a question per target instead of a walk of the list (a
    /// vertex of a dense mesh is refused hundreds of targets).
    pub(super) fn mark_refusals(&mut self, v: u32) -> u32 {
        let epoch = self.next_epoch();
        let mark = &mut self.mark;
        self.refusals.for_each(v, |w| mark[w as usize] = epoch);
        epoch
    }

    pub(super) fn next_epoch(&mut self) -> u32 {
        self.epoch = self.epoch.wrapping_add(2);
        if self.epoch < 2 {
            self.mark.fill(0);
            self.epoch = 2;
        }
        self.epoch
    }
}

impl Contractor<Endpoint> {
    /// [`Place::best`] in endpoint mode, the hot path: `v`'s quadric is
    /// loaded once, and each neighbour is costed about once. Around `v` a
    /// neighbour that follows `v` in one triangle precedes it in the next
    /// one, so only followers are costed, plus the predecessors that follow
    /// `v` nowhere (across a border edge). The set of targets is that of
    /// all neighbours, so the choice is the same (ties go to the lower
    /// index either way); it halves the cost evaluations of an interior
    /// vertex.
    pub(super) fn best_endpoint(&self, v: u32) -> Option<(f64, u32)> {
        /// Fans up to this many triangles are deduplicated on the stack;
        /// larger ones cost every occurrence (or each neighbour once, from
        /// a current star: [`Contractor::best_endpoint_wide`]).
        const FAN: usize = 24;
        let q = &self.quadrics[v as usize];
        let (centre, squares) = self.place.anchors[v as usize]
            .centre()
            .unwrap_or((DVec3::ZERO, 0.0));
        let refused = !self.refusals.is_empty(v);
        let mut best: Option<(f64, u32)> = None;
        let mut consider = |w: u32| {
            if refused && self.refusals.contains(v, w) {
                return;
            }
            // The tie-break term of `cost`, its centre computed once.
            let p = self.p(w);
            let mut cost = q.mean_error(p) + TIE_BREAK * PointSum::spread(p, centre, squares);
            if let Some(a) = &self.attributes {
                cost += a.cost(v, w, p);
            }
            if best.is_none_or(|(bc, bw)| cost < bc || (cost == bc && w < bw)) {
                best = Some((cost, w));
            }
        };
        let around = self.fans.get(v);
        if around.len() <= FAN {
            let mut next = [0u32; FAN];
            let mut prev = [0u32; FAN];
            let mut k = 0;
            for &t in around {
                let tri = self.tris[t as usize];
                if tri[0] == DEAD {
                    continue;
                }
                let i = usize::from(tri[1] == v) + 2 * usize::from(tri[2] == v);
                next[k] = tri[(i + 1) % 3];
                prev[k] = tri[(i + 2) % 3];
                k += 1;
            }
            for &w in &next[..k] {
                consider(w);
            }
            for &w in &prev[..k] {
                if !next[..k].contains(&w) {
                    consider(w);
                }
            }
        } else {
            for &t in around {
                let tri = self.tris[t as usize];
                if tri[0] == DEAD {
                    continue;
                }
                for w in tri {
                    if w != v {
                        consider(w);
                    }
                }
            }
        }
        if let Some(partners) = self.partners.get(v as usize) {
            for &w in partners {
                if !self.removed[w as usize] {
                    consider(w);
                }
            }
        }
        best
    }

    /// [`Contractor::cost`] of `v → w` with `v`'s quadric `q` and the
    /// centre of its anchor (the tie-break's, computed once per choice), as
    /// [`Contractor::best_endpoint`] computes it (there written out: its
    /// closure compiled to more instructions calling this).
    #[inline(always)]
    fn endpoint_cost(&self, q: &Quadric, centre: DVec3, squares: f64, v: u32, w: u32) -> f64 {
        let p = self.p(w);
        let mut cost = q.mean_error(p) + TIE_BREAK * PointSum::spread(p, centre, squares);
        if let Some(a) = &self.attributes {
            cost += a.cost(v, w, p);
        }
        cost
    }

    /// [`Contractor::best_endpoint`] of a vertex whose star is current:
    /// the first target no guard refused in the star's ranking of its
    /// neighbours by `(cost, index)`, which is their minimum. The ranking
    /// is made once per star (a vertex of a dense mesh chooses again after
    /// each of hundreds of refusals, and costing every neighbour each time
    /// was most of its sequence's time). O(valence + refusals) per choice,
    /// O(valence · log valence) per star; where the scan cost O(fan ·
    /// refusals).
    ///
    /// Costs that change while the star stays current (attribute costs,
    /// which read the target's state, and virtual partners, which come and
    /// go without a triangle changing) are costed per choice instead, each
    /// distinct neighbour once ([`Contractor::best_among`]), and so are
    /// NaN costs, which have no rank.
    pub(super) fn best_endpoint_wide(&mut self, v: u32) -> Option<(f64, u32)> {
        let refused = if self.refusals.is_empty(v) {
            None
        } else {
            Some(self.mark_refusals(v))
        };
        let is_refused = |c: &Self, w: u32| refused.is_some_and(|e| c.mark[w as usize] == e);
        if self.attributes.is_some() || !self.partners.is_empty() {
            return self.best_among(v, is_refused);
        }
        if !self.stars.current(v).ranked {
            let q = &self.quadrics[v as usize];
            let (centre, squares) = self.place.anchors[v as usize]
                .centre()
                .unwrap_or((DVec3::ZERO, 0.0));
            let mut ranking = std::mem::take(&mut self.stars.current_mut(v).ranking);
            ranking.clear();
            for &w in self.stars.current(v).neighbours() {
                ranking.push((self.endpoint_cost(q, centre, squares, v, w), w));
            }
            if ranking.iter().any(|(cost, _)| cost.is_nan()) {
                ranking.clear();
            } else {
                // As the scan compares: -0 and 0 tie, and go by index.
                ranking.sort_unstable_by(|x, y| {
                    x.0.partial_cmp(&y.0)
                        .unwrap_or(std::cmp::Ordering::Equal)
                        .then(x.1.cmp(&y.1))
                });
            }
            let star = self.stars.current_mut(v);
            (star.ranking, star.ranked) = (ranking, true);
        }
        let star = self.stars.current(v);
        if star.ranking.is_empty() && !star.neighbours().is_empty() {
            return self.best_among(v, is_refused);
        }
        star.ranking
            .iter()
            .find(|&&(_, w)| !is_refused(self, w))
            .copied()
    }

    /// The cheapest of `v`'s star's neighbours and its live virtual
    /// partners for which `refused` fails, ties to the lower index, each
    /// costed in the order a scan of the fan meets it (so a NaN cost
    /// decides as it does in [`Contractor::best_endpoint`]).
    fn best_among(&self, v: u32, refused: impl Fn(&Self, u32) -> bool) -> Option<(f64, u32)> {
        let q = &self.quadrics[v as usize];
        let (centre, squares) = self.place.anchors[v as usize]
            .centre()
            .unwrap_or((DVec3::ZERO, 0.0));
        let mut best: Option<(f64, u32)> = None;
        let partners = self.partners.get(v as usize).map_or(&[][..], Vec::as_slice);
        let live_partners = partners.iter().filter(|&&w| !self.removed[w as usize]);
        for &w in self
            .stars
            .current(v)
            .neighbours()
            .iter()
            .chain(live_partners)
        {
            if refused(self, w) {
                continue;
            }
            let cost = self.endpoint_cost(q, centre, squares, v, w);
            if best.is_none_or(|(bc, bw)| cost < bc || (cost == bc && w < bw)) {
                best = Some((cost, w));
            }
        }
        best
    }

    /// Every vertex's first choice. In endpoint mode the choices only read
    /// the contractor, so they are made on all cores and queued in vertex
    /// order afterwards (the same queue as one refresh per vertex).
    pub(super) fn choose_all_in_parallel(&mut self) {
        let n = self.removed.len();
        let threads = std::thread::available_parallelism()
            .map_or(1, std::num::NonZeroUsize::get)
            .min(n / PARALLEL_MIN_VERTICES + 1);
        if threads < 2 {
            self.choose_each();
            return;
        }
        let mut choices = vec![(f32::INFINITY, NONE); n];
        let chunk = n.div_ceil(threads);
        let this = &*self;
        std::thread::scope(|scope| {
            for (i, part) in choices.chunks_mut(chunk).enumerate() {
                scope.spawn(move || {
                    for (j, c) in part.iter_mut().enumerate() {
                        let v = (i * chunk + j) as u32;
                        if let Some((cost, w)) = this.best_endpoint(v) {
                            *c = (cost as f32, w);
                        }
                    }
                });
            }
        });
        for (v, (cost, w)) in choices.into_iter().enumerate() {
            self.queue(v as u32, cost, w);
        }
    }
}
