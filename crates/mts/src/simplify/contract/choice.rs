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
        // Drop the triangles that died around `v` while it stayed.
        self.fans.retain(v, |t| self.tris[t as usize][0] != DEAD);
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
    /// once each, in fan order.
    pub(super) fn partners_into(&mut self, v: u32, out: &mut Vec<u32>) {
        let epoch = self.next_epoch();
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
        if let Some(partners) = self.partners.get(v as usize) {
            for &w in partners {
                if !self.removed[w as usize] && self.mark[w as usize] != epoch {
                    self.mark[w as usize] = epoch;
                    out.push(w);
                }
            }
        }
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
        /// larger ones cost every occurrence.
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
