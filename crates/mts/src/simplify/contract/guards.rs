//! The guards of a contraction: flips against the current and the input
//! normals, the fin and link rules, the border rule (see the module docs of
//! [`super`], "Flips", "Fins", "Borders").

use super::*;

/// The kinds of the edges at a vertex ([`Contractor::edges_at`]).
pub(super) struct Edges {
    /// Some edge has other than two triangles: the merge test checks every
    /// common neighbour, and [`Contractor::border_error`] is measured.
    pub(super) border: bool,
    /// Some edge has one triangle, or four or more: the vertex leaves only
    /// along such an edge (or one of three).
    ///
    /// An edge of three triangles (three sheets meeting, or a fin on a
    /// sheet) does not count. meshoptimizer sees both directions of such an
    /// edge and treats its vertices as interior; tied to the edge, a vertex
    /// on beetle's 47 such edges could only slide along them, and the
    /// junctions stayed where the input has them. Free, the vertex may move
    /// into one of the sheets (the junction moves with it: the merge test
    /// keeps every edge within the input's most crowded). Over 6 vertex
    /// orders × 40 rows: beetle 10% median 1.11 → 1.04 and 1% 4.62 → 2.85
    /// (2.56 in the file's order), no other row moves (the geometric mean
    /// of the medians 0.746 → 0.736). Such a vertex still takes the merge
    /// test at every common neighbour (when this was measured it bounded
    /// each merged edge by the two it joined); without it (the interior
    /// vertex's link test alone) beetle 10% read 0.94, but a merged edge
    /// could then exceed the input's most crowded. Freeing edges of four or
    /// more too (meshoptimizer's view again) took bunny_res3 and bunny_res4
    /// at 1% to 1.75 and 1.61: their crowded edges are coincident triangle
    /// pairs of opposite winding, not fins.
    pub(super) slides: bool,
}

/// Why a guard refused a contraction.
pub(super) enum Reject {
    Flip,
    /// A fin, or the border rule.
    Topology,
}

/// A surviving triangle of a contraction, as [`Contractor::turn`] sees it.
#[derive(Clone, Copy)]
pub(super) struct Turn {
    /// The vertices after and before the moved one.
    pub(super) after: u32,
    pub(super) before: u32,
    /// Unnormalised normal before the move, and its length.
    pub(super) now: DVec3,
    pub(super) now_length: f64,
}

/// Whether one of the moved vertex's surviving triangles (`fan`, from
/// [`Contractor::turn`], normals before the move) is more than 15° from
/// their area-weighted mean normal ([`CREASE_COS`]). A flat fan's
/// replacements lie in its plane, so [`Contractor::backward_error`] is
/// skipped there. A fan whose normals cancel out counts as creased.
pub(super) fn creased(fan: &[Turn]) -> bool {
    let sum = fan.iter().fold(DVec3::ZERO, |s, t| s + t.now);
    let length = sum.length();
    length == 0.0
        || fan
            .iter()
            .any(|t| t.now.dot(sum) < CREASE_COS * t.now_length * length)
}

/// For each triangle, bit `slot` set when [`is_border`] holds for that
/// edge slot. Works vertex by vertex on a local copy of the corners (the
/// triangles around `a` read once, not once per slot).
pub(super) fn border_slots(tris: &[[u32; 3]], fans: &Fans) -> Vec<u8> {
    const LOCAL: usize = 32;
    let mut out = vec![0u8; tris.len()];
    let mut holders: Vec<(u32, u32, u8)> = Vec::new();
    let mut opposite: Vec<u32> = Vec::new();
    for a in 0..fans.vertex_count() as u32 {
        let around = fans.get(a);
        if around.len() > LOCAL {
            // Sorted instead of scanned per corner: linearithmic in the
            // fan (a 100,000-triangle fan took seconds by the scan), the
            // holders of each `b` matched against the opposite run of `b`
            // in one merge.
            holders.clear();
            opposite.clear();
            for &t in around {
                let tri = tris[t as usize];
                let k = tri.iter().position(|&w| w == a).unwrap_or(0);
                holders.push((tri[(k + 1) % 3], t, k as u8));
                opposite.push(tri[(k + 2) % 3]);
            }
            holders.sort_unstable();
            opposite.sort_unstable();
            let (mut rank, mut count, mut at) = (0, 0, 0);
            for (i, &(b, t, k)) in holders.iter().enumerate() {
                if i > 0 && holders[i - 1].0 == b {
                    rank += 1;
                } else {
                    rank = 0;
                    while opposite.get(at).is_some_and(|&x| x < b) {
                        at += 1;
                    }
                    count = opposite[at..].iter().take_while(|&&x| x == b).count();
                }
                if rank >= count {
                    out[t as usize] |= 1 << k;
                }
            }
            continue;
        }
        // Corners around `a`: the vertex after and before it, and its slot.
        let (mut next, mut prev, mut slot) = ([0u32; LOCAL], [0u32; LOCAL], [0u8; LOCAL]);
        for (i, &t) in around.iter().enumerate() {
            let tri = tris[t as usize];
            let k = tri.iter().position(|&w| w == a).unwrap_or(0);
            (next[i], prev[i], slot[i]) = (tri[(k + 1) % 3], tri[(k + 2) % 3], k as u8);
        }
        let k = around.len();
        for i in 0..k {
            let b = next[i];
            // `around` is in increasing triangle order: earlier holders of
            // (a, b) come first.
            let rank = next[..i].iter().filter(|&&x| x == b).count();
            let opposite = prev[..k].iter().filter(|&&x| x == b).count();
            if rank >= opposite {
                out[around[i] as usize] |= 1 << slot[i];
            }
        }
    }
    out
}

/// Whether the directed edge `(a, b)` of triangle `t` has no
/// orientation-consistent neighbour as [`TriangleAdjacency`] pairs them (the
/// `r`-th holder of `(a, b)` with the `r`-th holder of `(b, a)`, in triangle
/// order), read from the triangles `around_a` of `a` (in increasing order)
/// without building the whole adjacency.
#[cfg(test)]
pub(super) fn is_border(tris: &[[u32; 3]], around_a: &[u32], t: u32, a: u32, b: u32) -> bool {
    let (mut rank, mut opposite) = (0u32, 0u32);
    for &u in around_a {
        let tri = tris[u as usize];
        let k = tri.iter().position(|&w| w == a).unwrap_or(0);
        if tri[(k + 1) % 3] == b && u < t {
            rank += 1;
        } else if tri[(k + 2) % 3] == b {
            opposite += 1;
        }
    }
    rank >= opposite
}

/// Triangles on the most crowded edge of `tris` (0 when there is none):
/// around each vertex `a`, how often each later neighbour `x > a` appears
/// among its triangles' corners (once per triangle on edge `(a, x)`),
/// tallied in one word per vertex that holds the `a` it counts for.
/// Cost: O(triangles).
pub(super) fn most_crowded_edge(tris: &[[u32; 3]], fans: &Fans) -> usize {
    let n = fans.vertex_count();
    let mut tally = vec![u64::MAX; n];
    let mut most = 0;
    for a in 0..n as u32 {
        let stamp = u64::from(a) << 32;
        for &t in fans.get(a) {
            for x in tris[t as usize] {
                if x > a {
                    let entry = &mut tally[x as usize];
                    *entry = if *entry >> 32 == u64::from(a) {
                        *entry + 1
                    } else {
                        stamp | 1
                    };
                    most = most.max(*entry as u32);
                }
            }
        }
    }
    most as usize
}

impl<P: Place> Contractor<P> {
    /// The guards of the module docs for contracting `a` into `b` placed at
    /// `target`. Allocation-free (once the stars' buffers have grown);
    /// O(valence(a) · valence(b)) at worst, the topology rules of wide fans
    /// from their stars ([`Contractor::topology_wide`]).
    pub(super) fn check(&mut self, a: u32, b: u32, target: DVec3) -> Result<(), Reject> {
        if self.fans.get(a).len() > WIDE || self.fans.get(b).len() > WIDE {
            self.topology_wide(a, b)?;
        } else {
            self.topology(a, b)?;
        }
        // Triangles of `a` that survive: no flipped normal (their turns are
        // kept for the distance checks).
        //
        // A surviving triangle may land on the three vertices of one of
        // `b`'s (most often its other two corners are the apexes of edge
        // (a, b): a tetrahedral pocket, a closed part folded flat, or a fin
        // folding onto its sheet). The pair is a doubled sheet where the
        // surface is, and the next contraction on it removes both; the
        // topology rules' merge test still bounds every edge. Refusing it
        // (as a link condition would) kept beetle's fins standing: at its
        // floor of 81 triangles 31 edges still held three (meshoptimizer's
        // 81 keep 3), and its 1% row read 2.33 × meshoptimizer's Hausdorff
        // (median of 6 vertex orders). Allowed, with the crowding bound of
        // the merge test: 0.53, the last two rows above 1.15 × pass, the
        // geometric mean of the 40 rows' medians 0.698 → 0.684 (see
        // ARCHITECTURE.md).
        let mut fan = std::mem::take(&mut self.fan);
        fan.clear();
        let mut verdict = Ok(());
        for &t in self.fans.get(a) {
            let tri = self.tris[t as usize];
            if self.tris[t as usize][0] == DEAD || tri.contains(&b) {
                continue;
            }
            let Some(turn) = self.turn(t, a, target) else {
                verdict = Err(Reject::Flip);
                break;
            };
            fan.push(turn);
        }
        self.fan = fan;
        verdict?;
        if P::MOVES_KEPT {
            for &t in self.fans.get(b) {
                let tri = self.tris[t as usize];
                if self.tris[t as usize][0] != DEAD && !tri.contains(&a) && self.flips(t, b, target)
                {
                    return Err(Reject::Flip);
                }
            }
        }
        if !self.corners.is_empty() && !self.seam_map(a, b) {
            return Err(Reject::Topology);
        }
        Ok(())
    }

    /// The topology rules of [`Contractor::check`] (the border rule, fins
    /// and the link condition) for contracting `a` into `b`; sets
    /// [`Contractor::fan_on_border`]. O(valence(a) · valence(b)) at worst.
    pub(super) fn topology(&mut self, a: u32, b: u32) -> Result<(), Reject> {
        for &t in self.fans.get(a) {
            prefetch(&self.tris[t as usize]);
            prefetch(&self.normals0[t as usize]);
        }
        self.prefetch_ring(b);
        // Topology rule, after meshoptimizer's vertex kinds: an interior
        // vertex goes anywhere; a vertex on a border (an edge of one
        // triangle) or on an edge of four or more leaves only along such
        // an edge, so the border keeps its shape and two borders are never
        // pinched together. An edge of three triangles (a fin on a sheet)
        // does not tie its vertices to it; the merge test below still
        // bounds every edge. (Locking vertices where borders touch or fins
        // meet, as meshoptimizer does, measured worse: bunny_res3 stuck at
        // 512 triangles. See `Edges::slides` for the edges of three.)
        let (a_edges, ab_triangles) = self.edges_at(a, b);
        self.fan_on_border = a_edges.border;
        if a_edges.slides && ab_triangles == 2 {
            return Err(Reject::Topology);
        }
        if P::MOVES_KEPT {
            let (b_edges, _) = self.edges_at(b, a);
            if b_edges.slides && ab_triangles == 2 {
                return Err(Reject::Topology);
            }
        }
        let epoch = self.next_epoch();
        let apex = epoch + 1;
        // Mark a's neighbours (and ask for their positions, which the flip
        // test reads).
        for &t in self.fans.get(a) {
            if self.tris[t as usize][0] != DEAD {
                for w in self.tris[t as usize] {
                    self.mark[w as usize] = epoch;
                    if let Some(p) = self.pos.get(w as usize) {
                        prefetch(p);
                    }
                }
            }
        }
        // Apexes of the triangles on edge (a, b): the only allowed common
        // neighbours.
        for &t in self.fans.get(b) {
            let tri = self.tris[t as usize];
            if self.tris[t as usize][0] != DEAD && tri.contains(&a) {
                for w in tri {
                    if w != a && w != b {
                        self.mark[w as usize] = apex;
                    }
                }
            }
        }
        // Every common neighbour `w` merges edges (a, w) and (b, w) into
        // one: refused when that edge would hold more triangles than the
        // input's most crowded edge, or than two. Where two border edges
        // merge (two borders zipped into one manifold edge) it is allowed;
        // the link condition, which refuses every common neighbour but the
        // apexes, ended small models early (see ARCHITECTURE.md).
        let mut checked = std::mem::take(&mut self.checked);
        checked.clear();
        for &t in self.fans.get(b) {
            let tri = self.tris[t as usize];
            if tri[0] == DEAD || tri.contains(&a) {
                continue;
            }
            for w in tri {
                let m = self.mark[w as usize];
                if w == b || (m != epoch && m != apex) {
                    continue;
                }
                // Every edge of an interior `a` holds two triangles: an
                // apex's merged edge then holds at most what `(b, w)` did,
                // any other common neighbour's at least three, refused
                // even where the input's most crowded edge would allow it
                // (the link condition; the merge test alone took
                // bunny_res3 at 1% from 0.44 to 1.02 × meshoptimizer's
                // Hausdorff, median of 6 vertex orders, worst 1.69).
                if !a_edges.border {
                    if m == epoch {
                        self.checked = checked;
                        return Err(Reject::Topology);
                    }
                    continue;
                }
                if checked.contains(&w) {
                    continue;
                }
                checked.push(w);
                if !self.merge_keeps_manifold(a, b, w) {
                    self.checked = checked;
                    return Err(Reject::Topology);
                }
            }
        }
        self.checked = checked;
        Ok(())
    }

    /// [`Contractor::topology`] read from the stars of `a` and `b` (built
    /// or kept current here): the same verdict in O(valence(a) +
    /// valence(b) + k) for the `k` triangles on edge `(a, b)`, whatever the
    /// widths of the fans. The scans cost each common neighbour a pass
    /// over both fans: a dense non-manifold mesh (every vertex in
    /// thousands of triangles, every pair of vertices a common neighbour)
    /// spent seconds per thousand triangles here.
    ///
    /// A common neighbour `w` takes the merge test where the scan meets it:
    /// on a triangle of `b` without `a`, i.e. where `b`'s triangles on `(b,
    /// w)` outnumber the `dying` ones on `(a, b, w)`.
    pub(super) fn topology_wide(&mut self, a: u32, b: u32) -> Result<(), Reject> {
        let tris = &self.tris;
        for v in [a, b] {
            self.stars
                .update(v, &mut self.fans, tris, |t| tris[t as usize][0] != DEAD);
        }
        let (sa, sb) = (self.stars.current(a), self.stars.current(b));
        // The apexes of edge (a, b), sorted: those of the triangles on (a,
        // b, w) are the run of `w`.
        let apexes = sa.thirds(b);
        self.fan_on_border = sa.border();
        if sa.slides() && apexes.len() == 2 {
            return Err(Reject::Topology);
        }
        if P::MOVES_KEPT && sb.slides() && apexes.len() == 2 {
            return Err(Reject::Topology);
        }
        let mut around_a = sa.edges().peekable();
        let mut apex = 0;
        for (w, on_bw) in sb.edges() {
            while around_a.next_if(|&(x, _)| x < w).is_some() {}
            let Some(&(x, on_aw)) = around_a.peek() else {
                break;
            };
            if x != w || w == a {
                continue;
            }
            while apexes.get(apex).is_some_and(|&x| x < w) {
                apex += 1;
            }
            let dying = apexes[apex..].iter().take_while(|&&x| x == w).count();
            let (on_aw, on_bw) = (on_aw.len(), on_bw.len());
            if on_bw == dying {
                continue;
            }
            let refused = if sa.border() {
                on_aw + on_bw - 2 * dying > self.crowding
            } else {
                dying == 0
            };
            if refused {
                return Err(Reject::Topology);
            }
        }
        Ok(())
    }

    /// The kinds of the edges at `v` (live triangles only), and the number
    /// of live triangles on edge `(v, w)`.
    pub(super) fn edges_at(&mut self, v: u32, w: u32) -> (Edges, usize) {
        let mut counts = std::mem::take(&mut self.scratch);
        counts.clear();
        for &t in self.fans.get(v) {
            if self.tris[t as usize][0] == DEAD {
                continue;
            }
            for x in self.tris[t as usize] {
                if x == v {
                    continue;
                }
                match counts.iter_mut().find(|(y, _)| *y == x) {
                    Some((_, c)) => *c += 1,
                    None => counts.push((x, 1)),
                }
            }
        }
        let edges = Edges {
            border: counts.iter().any(|&(_, c)| c != 2),
            slides: counts.iter().any(|&(_, c)| c != 2 && c != 3),
        };
        let on_edge = counts.iter().find(|(y, _)| *y == w).map_or(0, |&(_, c)| c);
        self.scratch = counts;
        (edges, on_edge as usize)
    }

    /// Whether contracting `a` into `b` leaves edge `(b, w)` with no more
    /// triangles than the input's most crowded edge, or two (the triangles
    /// on `(a, b, w)` die; the others of `(a, w)` join `(b, w)`). So no LoD
    /// has a more crowded edge than the input.
    ///
    /// On an input with edges of three triangles (beetle's fins) a merge
    /// may make a new one. Bounding each merged edge by the two it joins
    /// instead (no edge gains triangles), with doubled triangles allowed
    /// ([`Contractor::check`]), gave bunny_res4 at 1% 1.17 ×
    /// meshoptimizer's Hausdorff (median of 6 vertex orders; worst 1.18);
    /// the input's bound gives 1.05 (worst 1.06), bunny_res3 at 1% 0.58 →
    /// 0.44, beetle the same. On a manifold input both bounds are two.
    pub(super) fn merge_keeps_manifold(&self, a: u32, b: u32, w: u32) -> bool {
        let (mut on_aw, mut dying) = (0, 0);
        for &t in self.fans.get(a) {
            let tri = self.tris[t as usize];
            if tri[0] != DEAD && tri.contains(&w) {
                on_aw += 1;
                dying += usize::from(tri.contains(&b));
            }
        }
        let on_bw = self.triangles_on(b, w);
        on_aw + on_bw - 2 * dying <= self.crowding
    }

    /// Whether moving vertex `v` of triangle `t` to `p` turns its normal by
    /// 75° or more against its current or its input normal, or leaves it
    /// without area.
    pub(super) fn flips(&self, t: u32, v: u32, p: DVec3) -> bool {
        self.turn(t, v, p).is_none()
    }

    /// Moving vertex `v` of triangle `t` to `p`: `None` when it flips (see
    /// [`Contractor::flips`]), else the triangle's normal before the move
    /// and the vertices after and before `v`.
    pub(super) fn turn(&self, t: u32, v: u32, p: DVec3) -> Option<Turn> {
        let tri = self.tris[t as usize];
        let [p0, p1, p2] = tri.map(|w| self.p(w));
        let now = (p1 - p0).cross(p2 - p0);
        let [q0, q1, q2] = tri.map(|w| if w == v { p } else { self.p(w) });
        let next = (q1 - q0).cross(q2 - q0);
        let input = self.input_normal(t);
        // cos 75°: a pure 90° test lets a triangle fold over through a
        // series of near-90° turns (meshoptimizer makes the same choice).
        // The limit against the current normal at 70° or 80° instead
        // measured 0.719 and 0.710 against 0.698 (6 orders × 40 rows,
        // geometric mean of the median ratios, after the members' check).
        let next_length = next.length();
        let limit = 0.25 * next_length;
        let now_length = now.length();
        if (now != DVec3::ZERO && next.dot(now) <= limit * now_length)
            || (input != DVec3::ZERO && next.dot(input) <= limit)
        {
            return None;
        }
        let i = usize::from(tri[1] == v) + 2 * usize::from(tri[2] == v);
        Some(Turn {
            after: tri[(i + 1) % 3],
            before: tri[(i + 2) % 3],
            now,
            now_length,
        })
    }
}
