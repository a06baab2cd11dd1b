//! Greedy quadric-error pair contraction (Garland and Heckbert, "Surface
//! Simplification Using Quadric Error Metrics", SIGGRAPH 1997), recorded
//! step by step as [`Collapses`].
//!
//! Decisions where the paper leaves room (measurements in
//! `ARCHITECTURE.md`, "Simplification"):
//! - **Costs after meshoptimizer**: moving `a` onto `b` costs the *mean*
//!   squared distance from `b` to `a`'s accumulated planes (see
//!   [`Contractor::cost`]); face planes weigh `sqrt(area)`. The recorded
//!   error is the square root of that cost relative to the bounding-box
//!   diagonal, as a running maximum so it never decreases.
//! - **Ties broken by distance**: the queue's cost adds `3e-6` times the
//!   mean squared distance to the input positions the moved vertex stands
//!   for ([`TIE_BREAK`]), so flat regions contract toward near neighbours
//!   instead of draining into one vertex; the recorded error leaves it out.
//! - **The surface must stay near the moved vertex**: when a choice
//!   pops, the distance from the moved vertex's input position to the
//!   triangles that replace its fan is measured, and where it exceeds the
//!   queue's cost the choice waits at that cost
//!   ([`Contractor::forward_error`]); the recorded error includes it.
//! - **The surface must stay near the old one**: where the moved
//!   vertex's fan is creased, the centroids of the triangles that replace
//!   it are measured against the old fans of both endpoints, and a choice
//!   whose weighted distance exceeds the queue's cost waits at it
//!   ([`Contractor::backward_error`]); where it was on a border, so are
//!   the midpoints of the new border edges ([`Contractor::border_error`]).
//! - **One queue entry per vertex**: its cheapest allowed target. The
//!   queue (`queue.rs`) holds 8-byte `(cost, vertex)` keys; the vertex's
//!   current cost and target live beside it. A cost that rises pushes
//!   nothing: the older, lower key pops first and is pushed again at the
//!   current cost, so the pop order is that of an exact priority queue.
//!   After `a → b` the survivor and `a`'s neighbours choose again; `b`'s
//!   other neighbours keep their choice.
//! - **A refused target is remembered per vertex** until its
//!   neighbourhood changes, and the vertex picks its next best. Validity
//!   can also change farther away, so when the queue runs dry every refusal
//!   is forgotten and every vertex queued again; the sequence ends after a
//!   round with no contraction.
//! - **Flips are judged against both the current and the original normal**
//!   of every moved triangle (75° at most against each): a series of small
//!   turns could otherwise fold a triangle over, and every LoD must keep
//!   the input's orientation. Two moved triangles that end up facing each
//!   other (a spike) are not refused: the distance checks above measure
//!   them (a fold guard did before those existed; removed, see
//!   `ARCHITECTURE.md`).
//! - **Fins**: a contraction is rejected when the edge it makes from a
//!   vertex adjacent to both endpoints would hold more triangles than the
//!   input's most crowded edge, or than two (so a manifold input stays
//!   manifold along its edges); for an interior vertex, when any common
//!   neighbour but the two apexes of the edge would merge (the link
//!   condition). This is weaker than the link condition where borders meet:
//!   two border edges may merge into one manifold edge, which closes a hole
//!   or a notch. The link condition keeps the topology, so small open
//!   models kept every hole to the end (teapot at 1%: Hausdorff 2.25 ×
//!   meshoptimizer's, 0.46 with this rule; bunny_res3 2.78 → 1.03). Two
//!   triangles may end up on the same three vertices (a tetrahedral pocket
//!   or a fin folds flat); the next contraction on the doubled sheet
//!   removes both, so a closed part can vanish and the sequence may end
//!   with no triangle, as meshoptimizer's does (refused, beetle's fins
//!   stood to its floor: 1% at 2.33 × meshoptimizer's Hausdorff, 0.53
//!   allowed).
//! - **Borders**: every edge without an orientation-consistent neighbour
//!   (see [`TriangleAdjacency`]) adds a plane through it, perpendicular to
//!   its triangle, to both endpoints' quadrics (weight `boundary_weight ×
//!   length`, plus the triangle's own plane counted in the error but not
//!   in the mean's weight); a vertex on an edge of one triangle, or of
//!   four or more, leaves only along such an edge (or one of three).

use super::collapses::{Collapse, Collapses};
use super::fans::Fans;
use super::pairs::virtual_pairs;
use super::prefetch;
use super::quadric::{PointSum, Quadric};
use super::queue::{cost_bits, key, Queue};
use super::refusals::Refusals;
use super::{Placement, Simplification, SimplifyOptions, Stop, StopReason};
use crate::distance::bvh::closest_on_triangle_f64;
use crate::mesh::Mesh;
#[cfg(doc)]
use crate::mesh::TriangleAdjacency;
use glam::{DVec3, Vec3};

/// Computes the whole contraction sequence of `mesh`.
///
/// Runs until no valid pair or no triangle remains (or until
/// [`SimplifyOptions::stop_at_triangles`]), and says where and why it
/// stopped in [`Simplification::stop`]. Cost: O((V + T) log T) for
/// bounded valences; memory under 200 bytes per triangle at peak (197 for
/// the whole `mts simplify` process on a 1M-triangle icosphere).
///
/// # Panics
/// If `mesh` breaks the [`Mesh`] invariants (check with
/// [`Mesh::validate`] first; loaders and generators guarantee them).
///
/// Coordinates far from 1 (beyond 2^±40, e.g. 1e20 or 1e-25) are simplified
/// in a frame scaled by a power of two ([`crate::mesh::power_of_two_scale`]):
/// the queue's `f32` costs are squared distances and would overflow or
/// vanish in model units. The scaling is exact, errors are relative to the
/// diagonal, and created vertices are scaled back exactly, so the result is
/// the sequence of the true coordinates; ordinary models are not scaled.
#[must_use]
pub fn simplify(mesh: &Mesh, options: &SimplifyOptions) -> Simplification {
    let scale = crate::mesh::power_of_two_scale(&mesh.positions);
    if scale != 1.0 {
        let scaled = Mesh {
            positions: mesh
                .positions
                .iter()
                .map(|p| (p.as_dvec3() * scale).as_vec3())
                .collect(),
            triangles: mesh.triangles.clone(),
        };
        let mut result = simplify(&scaled, options);
        for p in &mut result.collapses.appended {
            *p = (p.as_dvec3() / scale).as_vec3();
        }
        return result;
    }
    let mut c = Contractor::new(mesh, options);
    c.run(options.stop_at_triangles);
    c.finish()
}

/// Below this many vertices per thread the first choices are made on one
/// thread (a spawn costs tens of microseconds).
const PARALLEL_MIN_VERTICES: usize = 20_000;

/// A triangle that died, in [`Contractor::tris`].
const DEAD: u32 = u32::MAX;

/// No key in [`Contractor::floor`].
const NO_KEY: u32 = u32::MAX;

/// "No target" in [`Contractor::queued`].
const NONE: u32 = u32::MAX;

/// Weight of the tie-breaking term of [`Contractor::cost`] (the mean
/// squared distance to the input positions a vertex stands for) against
/// the planes' mean squared distance. Moving a vertex by `d` then costs as
/// much as a plane `0.0017 d` away: it decides between targets that the
/// planes rate alike and almost nowhere else. Rows above 1.15 ×
/// meshoptimizer's Hausdorff (of 40: every model at 10% and 1%): 7 without
/// it, 6 at 1e-7 and 1e-6, 5 at 3e-6, 6 at 1e-5 and 3e-5, 7 at 1e-4; the
/// response is not smooth (at 1% of small models any change of order
/// moves the end state), so the weight is the best of that sweep.
/// Measured again with the members' forward distance, the 15° crease gate
/// and boundary weight 15 (6 orders, geometric mean of the median ratios):
/// 1e-6 → 0.706, 3e-6 → 0.698, 1e-5 → 0.709 (ogre at 1% 1.24 in its
/// file's order).
const TIE_BREAK: f64 = 3e-6;

/// Weight of the backward distance ([`Contractor::backward_error`]): the
/// squared distance from a moved triangle's centroid to the old surface,
/// times 4 (the centroid sees a third of the moved corner's displacement,
/// the worst point of the triangle more). Weights 1, 2, 3, 5 and 8
/// measured worse on the 40 rows of the README table (0.817–0.918 against
/// 0.794 as the geometric mean of the ratios, ungated). Measured again
/// with the members' forward distance and boundary weight 15 (6 orders,
/// geometric mean of the medians): 2 → 0.766, 4 → 0.719, 8 → 0.765.
const BACKWARD_WEIGHT: f64 = 4.0;

/// A fan is creased when one of its triangles' normals is more than 15°
/// from the fan's area-weighted mean normal ([`creased`]); only then is
/// the backward distance measured. Over 6 vertex orders of the 40 rows
/// (geometric mean of the median ratios to meshoptimizer's Hausdorff;
/// rows with some order above 1.15 ×; instructions of the bunny's whole
/// sequence): ungated 0.809, 6 rows, about 65% more time; 10° 0.805, 5
/// rows, 16% more instructions (and beetle at 10% 1.34 → 1.45); 20°
/// 0.826, 6 rows, 5% more instructions, kept for the bunny's 150 ms
/// budget (the sequence was at 125 ms). Measured again with the members'
/// forward distance, the three-triangle rule and boundary weight 15: 30°
/// 0.778, 20° 0.719, 15° 0.698, 10° 0.710 (files' orders 0.768, 0.727,
/// 0.707, 0.700; over 10 orders 20° 0.722, 15° 0.708); 15° costs about
/// 4% more instructions than 20° on the bunny, 10° about 13%.
const CREASE_COS: f64 = 0.966;

/// Weight of the border distance ([`Contractor::border_error`]): the
/// squared distance from the midpoint of a new border edge to the old
/// surface, as it is (0.5 measured worse: alligator at 1% kept a median
/// of 1.01 and a worst order of 1.49 × meshoptimizer's Hausdorff).
/// Measured again with the members' forward distance and boundary weight
/// 15 (6 orders, geometric mean of the medians): 0.5 → 0.728, 1 →
/// 0.719, 2 → 0.718, 4 → 0.748, 8 → 0.776.
const BORDER_WEIGHT: f64 = 1.0;

/// The kinds of the edges at a vertex ([`Contractor::edges_at`]).
struct Edges {
    /// Some edge has other than two triangles: the merge test checks every
    /// common neighbour, and [`Contractor::border_error`] is measured.
    border: bool,
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
    slides: bool,
}

/// Why a guard refused a contraction.
enum Reject {
    Flip,
    /// A fin, or the border rule.
    Topology,
}

struct Contractor {
    placement: Placement,
    diagonal: f64,
    /// Positions, `f64`; optimal mode appends one per contraction.
    /// Input positions as loaded (`f32`, half the cache footprint; widened
    /// exactly on use, see [`Contractor::p`]).
    pos: Vec<Vec3>,
    /// Positions of the vertices optimal mode appends (`f64`, after `pos`).
    appended_pos: Vec<DVec3>,
    quadrics: Vec<Quadric>,
    /// The input positions each vertex stands for (its own and those
    /// contracted into it), for the tie-breaking term of
    /// [`Contractor::cost`]; empty in optimal placement, which does not
    /// use them.
    anchors: Vec<PointSum>,
    /// The input vertices each vertex stands for, as circular lists:
    /// `members[v]` is `v`'s input position and the next vertex of its
    /// cycle. A vertex alone points to itself; moving `a` onto `b` joins
    /// their cycles by swapping the two links. The position sits beside
    /// the link so a walk loads one line per member. Empty in optimal
    /// placement, which does not use them.
    members: Vec<(Vec3, u32)>,
    /// Scratch list of the triangles around the survivor after a move, for
    /// [`Contractor::forward_error`].
    after: Vec<Prism>,
    /// Current triangles (input triangles with contracted vertices
    /// substituted); `[DEAD; 3]` once a contraction left them without three
    /// distinct vertices (no separate flag to load).
    tris: Vec<[u32; 3]>,
    /// Unnormalised `f32` normal (edge cross product) of each input
    /// triangle, zero for a zero-area one; see [`Contractor::input_normal`].
    normals0: Vec<Vec3>,
    /// Triangles around each vertex; may hold dead ones until the vertex is
    /// next contracted or chooses again.
    fans: Fans,
    /// Virtual partners of each vertex (empty unless enabled).
    partners: Vec<Vec<u32>>,
    removed: Vec<bool>,
    /// Scratch list of the moved triangles in [`Contractor::check`].
    fan: Vec<Turn>,
    /// Whether the vertex [`Contractor::check`] last looked at is on a
    /// border (an edge with other than two triangles).
    fan_on_border: bool,
    /// Scratch marks per vertex, compared with `epoch`.
    mark: Vec<u32>,
    epoch: u32,
    /// `(cost, vertex)` keys. A vertex's choice is current when a key with
    /// its queued cost pops; a key below it is pushed again at that cost
    /// (costs mostly rise, so most updates push nothing), one above it is
    /// stale. Invariant: every queued vertex has a key at or below its
    /// queued cost.
    heap: Queue,
    /// The (cost, target) of each vertex's current queue entry.
    queued: Vec<(f32, u32)>,
    /// `cost_bits` of the lowest key of each vertex known to be in `heap`
    /// ([`NO_KEY`] when none may be).
    floor: Vec<u32>,
    /// Targets a guard refused for each vertex since its neighbourhood last
    /// changed.
    refusals: Refusals,
    /// Scratch vertex list (neighbours of a survivor).
    ring: Vec<u32>,
    /// Scratch vertex list (a vertex's partners, in [`Contractor::best`]
    /// in optimal mode and for the survivor in [`Contractor::contract`]).
    around: Vec<u32>,
    /// Output.
    steps: Vec<Collapse>,
    triangle_counts: Vec<u32>,
    appended: Vec<Vec3>,
    triangles_now: u32,
    max_error: f32,
    stop: Option<Stop>,
    input_vertices: usize,
    /// Scratch (vertex, count) list for [`Contractor::edges_at`].
    scratch: Vec<(u32, u32)>,
    /// Scratch list of the common neighbours [`Contractor::check`] has
    /// looked at.
    checked: Vec<u32>,
    /// Triangles on the input's most crowded edge, at least 2: no merge
    /// may make an edge hold more ([`Contractor::merge_keeps_manifold`]).
    crowding: usize,
}

impl Contractor {
    fn new(mesh: &Mesh, options: &SimplifyOptions) -> Contractor {
        let n = mesh.vertex_count();
        let pos = mesh.positions.clone();
        let tris = mesh.triangles.clone();
        for t in &tris {
            assert!(
                t.iter().all(|&v| (v as usize) < n) && !crate::mesh::is_degenerate(*t),
                "simplify needs a valid mesh (see Mesh::validate)"
            );
        }
        let mut quadrics = vec![Quadric::default(); n];
        let mut normals0 = Vec::with_capacity(tris.len());
        for t in &tris {
            let [p0, p1, p2] = t.map(|v| mesh.positions[v as usize]);
            let normal = match Quadric::triangle(p0, p1, p2) {
                Some(q) => {
                    // Weight sqrt(area) instead of area, so that the error
                    // grows linearly with size; after meshoptimizer, which
                    // found it keeps silhouettes (measured here: Hausdorff
                    // at 10% on lucy 0.0036 against 0.0044 with area).
                    let q = q.scaled(1.0 / q.weight().sqrt());
                    for &v in t {
                        quadrics[v as usize] += q;
                    }
                    (p1 - p0).cross(p2 - p0)
                }
                None => Vec3::ZERO,
            };
            normals0.push(normal);
        }
        // Each vertex's anchor: its own position, weighted like its face
        // planes (before border planes are added).
        let anchors = if options.placement == Placement::Endpoint {
            quadrics
                .iter()
                .zip(&mesh.positions)
                .map(|(q, p)| PointSum::point(p.as_dvec3(), q.weight()))
                .collect()
        } else {
            Vec::new()
        };
        let members = if options.placement == Placement::Endpoint {
            (0..n as u32)
                .map(|v| (mesh.positions[v as usize], v))
                .collect()
        } else {
            Vec::new()
        };
        let fans = Fans::new(n, &tris);
        let crowding = most_crowded_edge(&tris, &fans).max(2);
        if options.boundary_weight > 0.0 {
            let borders = border_slots(&tris, &fans);
            for (t, tri) in tris.iter().enumerate() {
                for slot in 0..3 {
                    if borders[t] & (1 << slot) == 0 {
                        continue;
                    }
                    let (a, b) = (tri[slot], tri[(slot + 1) % 3]);
                    let (pa, pb) = (pos[a as usize].as_dvec3(), pos[b as usize].as_dvec3());
                    let edge = pb - pa;
                    let normal = edge
                        .cross(normals0[t].as_dvec3().normalize_or_zero())
                        .normalize_or_zero();
                    if normal == DVec3::ZERO {
                        continue;
                    }
                    // Length, to match the sqrt(area) of face planes.
                    let w = options.boundary_weight;
                    let mut q = Quadric::plane(normal, pa, w * edge.length());
                    // The triangle's own plane, equally weighted but not
                    // counted in the weight: otherwise the heavy edge plane
                    // dilutes the mean and a border vertex slides along a
                    // straight border across a curved surface (beetle at
                    // 10%: Hausdorff 0.048 against meshoptimizer's 0.020).
                    if let Some(face) = Quadric::triangle(
                        mesh.positions[a as usize],
                        mesh.positions[b as usize],
                        mesh.positions[tri[(slot + 2) % 3] as usize],
                    ) {
                        let face = face.scaled(w / face.weight().sqrt());
                        q += face.without_weight();
                    }
                    quadrics[a as usize] += q;
                    quadrics[b as usize] += q;
                }
            }
        }
        let diagonal = mesh.diagonal_f64().max(f64::MIN_POSITIVE);
        let mut partners = Vec::new();
        if let Some(d) = options.pair_distance {
            let pairs = virtual_pairs(&mesh.positions, &fans, &tris, d * mesh.diagonal());
            if !pairs.is_empty() {
                partners = vec![Vec::new(); n];
                for (a, b) in pairs {
                    partners[a as usize].push(b);
                    partners[b as usize].push(a);
                }
            }
        }
        let triangles_now = tris.len() as u32;
        let mut c = Contractor {
            placement: options.placement,
            diagonal,
            pos,
            quadrics,
            anchors,
            members,
            after: Vec::new(),
            tris,
            normals0,
            appended_pos: Vec::new(),
            fans,
            partners,
            removed: vec![false; n],
            fan: Vec::new(),
            fan_on_border: false,
            mark: vec![0; n],
            epoch: 0,
            heap: Queue::with_capacity(2 * n),
            queued: vec![(f32::NAN, NONE); n],
            floor: vec![NO_KEY; n],
            refusals: Refusals::new(n),
            ring: Vec::new(),
            around: Vec::new(),
            steps: Vec::new(),
            triangle_counts: vec![triangles_now],
            appended: Vec::new(),
            triangles_now,
            max_error: 0.0,
            stop: None,
            input_vertices: n,
            scratch: Vec::new(),
            checked: Vec::new(),
            crowding,
        };
        c.choose_all();
        c
    }

    /// Asks for the triangles around `v` ahead of the loops over them.
    #[inline]
    fn prefetch_ring(&self, v: u32) {
        for &t in self.fans.get(v) {
            prefetch(&self.tris[t as usize]);
        }
    }

    /// Position of vertex `v` in `f64` (input positions widen exactly).
    #[inline]
    fn p(&self, v: u32) -> DVec3 {
        match self.pos.get(v as usize) {
            Some(p) => p.as_dvec3(),
            None => self.appended_pos[v as usize - self.pos.len()],
        }
    }

    /// Unit normal of input triangle `t` (zero for a zero-area one),
    /// normalised in `f64` as when it was stored that way.
    #[inline]
    fn input_normal(&self, t: u32) -> DVec3 {
        self.normals0[t as usize].as_dvec3().normalize_or_zero()
    }

    /// Appends every current neighbour and virtual partner of `v` to `out`,
    /// once each, in fan order.
    fn partners_into(&mut self, v: u32, out: &mut Vec<u32>) {
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

    fn next_epoch(&mut self) -> u32 {
        self.epoch = self.epoch.wrapping_add(2);
        if self.epoch < 2 {
            self.mark.fill(0);
            self.epoch = 2;
        }
        self.epoch
    }

    /// The cheapest target of `v` among its neighbours and virtual
    /// partners that no guard refused yet: `(cost, target)`.
    fn best(&mut self, v: u32) -> Option<(f64, u32)> {
        if self.placement == Placement::Endpoint {
            return self.best_endpoint(v);
        }
        let mut best: Option<(f64, u32)> = None;
        let mut around = std::mem::take(&mut self.around);
        around.clear();
        self.partners_into(v, &mut around);
        for &w in &around {
            if self.refusals.contains(v, w) {
                continue;
            }
            let cost = self.pair_cost(v, w);
            if best.is_none_or(|(bc, bw)| cost < bc || (cost == bc && w < bw)) {
                best = Some((cost, w));
            }
        }
        self.around = around;
        best
    }

    /// [`Contractor::best`] in endpoint mode, the hot path: `v`'s quadric is
    /// loaded once, and each neighbour is costed about once. Around `v` a
    /// neighbour that follows `v` in one triangle precedes it in the next
    /// one, so only followers are costed, plus the predecessors that follow
    /// `v` nowhere (across a border edge). The set of targets is that of
    /// all neighbours, so the choice is the same (ties go to the lower
    /// index either way); it halves the cost evaluations of an interior
    /// vertex.
    fn best_endpoint(&self, v: u32) -> Option<(f64, u32)> {
        /// Fans up to this many triangles are deduplicated on the stack;
        /// larger ones cost every occurrence.
        const FAN: usize = 24;
        let q = &self.quadrics[v as usize];
        let (centre, squares) = self.anchors[v as usize]
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
            let cost = q.mean_error(p) + TIE_BREAK * PointSum::spread(p, centre, squares);
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
    fn choose_all(&mut self) {
        let n = self.removed.len();
        let threads = std::thread::available_parallelism()
            .map_or(1, std::num::NonZeroUsize::get)
            .min(n / PARALLEL_MIN_VERTICES + 1);
        if self.placement != Placement::Endpoint || threads < 2 {
            for v in 0..n as u32 {
                self.refresh(v);
            }
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

    /// Recomputes `v`'s cheapest contraction and queues it when it changed
    /// (the old entry then goes stale).
    fn refresh(&mut self, v: u32) {
        // Drop the triangles that died around `v` while it stayed.
        self.fans.retain(v, |t| self.tris[t as usize][0] != DEAD);
        let new = self
            .best(v)
            .map_or((f32::INFINITY, NONE), |(c, w)| (c as f32, w));
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
    fn queue(&mut self, v: u32, cost: f32, target: u32) {
        self.queued[v as usize] = (cost, target);
        let bits = cost_bits(cost);
        if target != NONE && bits < self.floor[v as usize] {
            self.floor[v as usize] = bits;
            self.heap.push(key(cost, v));
        }
    }

    /// Forgets what the guards refused `v`, so that it chooses among all
    /// its targets again.
    fn forget_refusals(&mut self, v: u32) {
        self.refusals.forget(v);
    }

    /// Queues `v → w` if it is cheaper than `v`'s queued contraction.
    fn offer(&mut self, v: u32, w: u32) {
        let cost = self.pair_cost(v, w) as f32;
        let (old_cost, old_target) = self.queued[v as usize];
        if old_target != w && (cost < old_cost || (cost == old_cost && w < old_target)) {
            self.queue(v, cost, w);
        }
    }

    /// Squared distance from `a`'s input position to the nearest triangle
    /// of its fan once `a` is moved onto `b`, or of `b`'s when none of
    /// `a`'s survives (zero when neither has one); or, where larger than
    /// both that and `limit`, the largest squared distance from an input
    /// vertex contracted into `a` earlier (its [`Contractor::members`]) to
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
    fn forward_error(&mut self, a: u32, b: u32, limit: f64) -> f64 {
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
        if self.members[a as usize].1 == a {
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
        let mut u = self.members[a as usize].1;
        while u != a {
            let (p, next) = self.members[u as usize];
            prefetch(&self.members[next as usize]);
            let p = p.as_dvec3();
            u = next;
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
    fn distances(&mut self, a: u32, b: u32, cost: f32) -> (f64, f64) {
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
    fn backward_error(&self, a: u32, b: u32, limit: f64) -> Option<f64> {
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
    fn border_error(&self, a: u32, b: u32, limit: f64) -> Option<f64> {
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
    fn nearest_old(&self, p: DVec3, a: u32, b: u32, within: f64) -> f64 {
        let around_a = self.nearest_around(p, a, NONE, self.p(a), within);
        if around_a <= within {
            return around_a;
        }
        around_a.min(self.nearest_around(p, b, NONE, self.p(b), within))
    }

    /// Live triangles around `a` on edge `(a, x)` (`a`'s list holds every
    /// triangle on the edge).
    fn triangles_on(&self, a: u32, x: u32) -> usize {
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
    fn nearest_around(&self, p: DVec3, v: u32, without: u32, at: DVec3, within: f64) -> f64 {
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
    fn corners_around(
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

    /// Cost of contracting `v` with `w`: moving `v` onto `w`, or in optimal
    /// mode both onto the merged quadric's best point.
    fn pair_cost(&self, v: u32, w: u32) -> f64 {
        match self.placement {
            Placement::Endpoint => self.cost(v, w),
            Placement::Optimal => {
                let q = self.quadrics[v as usize] + self.quadrics[w as usize];
                self.optimal_point(&q, v, w).1
            }
        }
    }

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
    fn cost(&self, removed: u32, kept: u32) -> f64 {
        let p = self.p(kept);
        self.quadrics[removed as usize].mean_error(p)
            + TIE_BREAK * self.anchors[removed as usize].mean_error(p)
    }

    /// The quadric's minimiser, or the best of the endpoints and midpoint.
    fn optimal_point(&self, q: &Quadric, a: u32, b: u32) -> (DVec3, f64) {
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

    fn run(&mut self, stop_at: Option<usize>) {
        let mut round = RoundStats::default();
        let mut round_start = 0;
        loop {
            if stop_at.is_some_and(|t| self.triangles_now as usize <= t) {
                self.stop =
                    Some(self.stop_record(StopReason::TargetReached, RoundStats::default()));
                return;
            }
            if self.triangles_now == 0 {
                self.stop =
                    Some(self.stop_record(StopReason::NoTriangleLeft, RoundStats::default()));
                return;
            }
            let Some(k) = self.heap.pop() else {
                // A round ends. Refused pairs may have become valid since
                // (a guard looks at more than the two vertices' own
                // neighbourhoods); try everything again unless the round
                // changed nothing.
                if self.steps.len() == round_start || self.refusals.count() == 0 {
                    self.stop = Some(self.stop_record(StopReason::NoValidPair, round));
                    return;
                }
                self.requeue_all();
                round_start = self.steps.len();
                round = RoundStats::default();
                continue;
            };
            let a = k as u32;
            // The next key is most often the next contraction: ask for its
            // vertex's state while this one is handled.
            if let Some(next) = self.heap.peek() {
                let v = next as u32;
                prefetch(&self.queued[v as usize]);
                self.fans.prefetch_span(v);
            }
            // Other keys of `a` may remain, but none lower.
            self.floor[a as usize] = NO_KEY;
            let (cost, b) = self.queued[a as usize];
            if self.removed[a as usize] || b == NONE {
                continue;
            }
            let (popped, bits) = ((k >> 32) as u32, cost_bits(cost));
            if popped != bits {
                if popped < bits {
                    // The cost rose since this key: queue it where it is now.
                    self.floor[a as usize] = bits;
                    self.heap.push(key(cost, a));
                }
                continue;
            }
            self.quadrics[a as usize].prefetch();
            self.quadrics[b as usize].prefetch();
            if let Some(anchor) = self.anchors.get(a as usize) {
                anchor.prefetch();
            }
            self.fans.prefetch_span(b);
            if self.removed[b as usize] {
                // The target went away without `a` being next to its
                // survivor (their shared triangles died with it).
                self.refresh(a);
                continue;
            }
            let target = self.target_position(a, b);
            match self.check(a, b, target) {
                Ok(()) => {
                    // The queue's cost is a lower bound (after the guards:
                    // their loads of the fan serve the distances too).
                    let (forward, wait) = match self.placement {
                        Placement::Endpoint => self.distances(a, b, cost),
                        Placement::Optimal => (0.0, 0.0),
                    };
                    if wait as f32 > cost * (1.0 + 1e-4) {
                        let raised = wait as f32;
                        self.queued[a as usize] = (raised, b);
                        self.floor[a as usize] = cost_bits(raised);
                        self.heap.push(key(raised, a));
                        continue;
                    }
                    self.contract(a, b, target, cost, forward);
                }
                Err(why) => {
                    round.candidates += 1;
                    match why {
                        Reject::Flip => round.flip += 1,
                        Reject::Topology => round.topology += 1,
                    }
                    self.refusals.add(a, b);
                    self.refresh(a);
                }
            }
        }
    }

    /// Forgets every refusal and queues every live vertex again.
    fn requeue_all(&mut self) {
        for v in 0..self.removed.len() as u32 {
            self.forget_refusals(v);
            if !self.removed[v as usize] {
                self.queued[v as usize] = (f32::NAN, NONE);
                self.floor[v as usize] = NO_KEY;
                self.refresh(v);
            }
        }
    }

    /// Where the surviving vertex of `a → b` goes.
    fn target_position(&self, a: u32, b: u32) -> DVec3 {
        match self.placement {
            Placement::Endpoint => self.p(b),
            Placement::Optimal => {
                let q = self.quadrics[a as usize] + self.quadrics[b as usize];
                self.optimal_point(&q, a, b).0
            }
        }
    }

    /// The guards of the module docs for contracting `a` into `b` placed at
    /// `target`. Allocation-free; O(valence(a) · valence(b)) at worst.
    fn check(&mut self, a: u32, b: u32, target: DVec3) -> Result<(), Reject> {
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
        if self.placement == Placement::Optimal {
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
        // Triangles of `a` that survive: no flipped normal (their turns are
        // kept for the distance checks).
        //
        // A surviving triangle may land on the three vertices of one of
        // `b`'s (most often its other two corners are the apexes of edge
        // (a, b): a tetrahedral pocket, a closed part folded flat, or a fin
        // folding onto its sheet). The pair is a doubled sheet where the
        // surface is, and the next contraction on it removes both; the
        // merge test above still bounds every edge. Refusing it (as a link
        // condition would) kept beetle's fins standing: at its floor of 81
        // triangles 31 edges still held three (meshoptimizer's 81 keep 3),
        // and its 1% row read 2.33 × meshoptimizer's Hausdorff (median of 6
        // vertex orders). Allowed, with the crowding bound of the merge
        // test: 0.53, the last two rows above 1.15 × pass, the geometric
        // mean of the 40 rows' medians 0.698 → 0.684 (see ARCHITECTURE.md).
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
        if self.placement == Placement::Optimal {
            for &t in self.fans.get(b) {
                let tri = self.tris[t as usize];
                if self.tris[t as usize][0] != DEAD && !tri.contains(&a) && self.flips(t, b, target)
                {
                    return Err(Reject::Flip);
                }
            }
        }
        Ok(())
    }

    /// The kinds of the edges at `v` (live triangles only), and the number
    /// of live triangles on edge `(v, w)`.
    fn edges_at(&mut self, v: u32, w: u32) -> (Edges, usize) {
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
    fn merge_keeps_manifold(&self, a: u32, b: u32, w: u32) -> bool {
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
    fn flips(&self, t: u32, v: u32, p: DVec3) -> bool {
        self.turn(t, v, p).is_none()
    }

    /// Moving vertex `v` of triangle `t` to `p`: `None` when it flips (see
    /// [`Contractor::flips`]), else the triangle's normal before the move
    /// and the vertices after and before `v`.
    fn turn(&self, t: u32, v: u32, p: DVec3) -> Option<Turn> {
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

    /// Applies `a → b` (or both into a new vertex at `target`) and queues
    /// the pairs around the survivor again.
    fn contract(&mut self, a: u32, b: u32, target: DVec3, cost: f32, forward: f64) {
        // Who must choose again afterwards: in endpoint mode the survivor
        // and `a`'s neighbours (they lose `a` as a target); `b`'s other
        // neighbours keep their candidates and costs, so only those that a
        // guard refused something are asked again. In optimal mode every
        // neighbour sees a new vertex. Each is asked once: `b` is one of
        // `a`'s neighbours, and `b`'s refused neighbours that are also
        // `a`'s are not added again (a second refresh finds the same
        // choice; asking the survivor twice was a third of all refreshes).
        let mut ring = std::mem::take(&mut self.ring);
        ring.clear();
        self.partners_into(a, &mut ring);
        if !ring.contains(&b) {
            ring.push(b);
        }
        // The recorded error: the planes' part of the cost and the
        // forward distance, without the tie-break.
        let error = match self.placement {
            Placement::Endpoint => self.quadrics[a as usize].mean_error(target).max(forward),
            Placement::Optimal => f64::from(cost),
        };
        let q = self.quadrics[a as usize] + self.quadrics[b as usize];
        if self.placement == Placement::Endpoint {
            self.anchors[b as usize] = self.anchors[a as usize] + self.anchors[b as usize];
            let (after_a, after_b) = (self.members[a as usize].1, self.members[b as usize].1);
            self.members[a as usize].1 = after_b;
            self.members[b as usize].1 = after_a;
        }
        let survivor = match self.placement {
            Placement::Endpoint => b,
            Placement::Optimal => {
                let c = self.removed.len() as u32;
                self.appended_pos.push(target);
                self.quadrics.push(Quadric::default());
                self.fans.push_vertex();
                self.removed.push(false);
                self.mark.push(0);
                self.queued.push((f32::NAN, NONE));
                self.floor.push(NO_KEY);
                self.refusals.push_vertex();
                if !self.partners.is_empty() {
                    self.partners.push(Vec::new());
                }
                self.appended.push(target.as_vec3());
                c
            }
        };
        self.quadrics[survivor as usize] = q;
        // The survivor's list: b's live triangles without `a`, then `a`'s
        // live ones (which never contain `b`), in b's block when it has room.
        let mut dead = 0u32;
        let tris = &mut self.tris;
        self.fans.retain(b, |t| {
            let tri = &mut tris[t as usize];
            if tri[0] == DEAD {
                return false;
            }
            if tri.contains(&a) {
                *tri = [DEAD; 3];
                dead += 1;
                return false;
            }
            for w in tri.iter_mut() {
                if *w == b {
                    *w = survivor;
                }
            }
            true
        });
        if survivor != b {
            self.fans.move_into(b, survivor, |_| true);
            self.removed[b as usize] = true;
        }
        self.fans.move_into(a, survivor, |t| {
            let tri = &mut tris[t as usize];
            if tri[0] == DEAD {
                return false;
            }
            for w in tri.iter_mut() {
                if *w == a {
                    *w = survivor;
                }
            }
            true
        });
        if !self.partners.is_empty() {
            let mut list = std::mem::take(&mut self.partners[a as usize]);
            list.append(&mut self.partners[b as usize]);
            list.retain(|&w| w != a && w != b && !self.removed[w as usize]);
            list.sort_unstable();
            list.dedup();
            for &w in &list {
                // Partners of a gone vertex now pair with the survivor.
                let theirs = &mut self.partners[w as usize];
                for x in theirs.iter_mut() {
                    if *x == a || *x == b {
                        *x = survivor;
                    }
                }
            }
            self.partners[survivor as usize] = list;
        }
        self.removed[a as usize] = true;
        // Entries of removed vertices are skipped by `removed`; the
        // survivor is refreshed below, which replaces its entry only when
        // its choice changed (its key then stays current).
        for gone in [a, b] {
            if gone != survivor {
                self.forget_refusals(gone);
            }
        }
        self.triangles_now -= dead;
        let rms = error.max(0.0).sqrt() / self.diagonal;
        self.max_error = self.max_error.max(rms as f32);
        self.steps.push(Collapse {
            removed: a,
            kept: b,
            error: self.max_error,
        });
        self.triangle_counts.push(self.triangles_now);
        // The survivor's quadric changed; its neighbours lost `a` (and in
        // optimal mode `b`) as a target and gained the survivor, and what
        // the guards refused them may be allowed now.
        if survivor != b {
            ring.clear();
            ring.push(survivor);
        }
        let everyone = survivor != b;
        let mut around = std::mem::take(&mut self.around);
        around.clear();
        self.partners_into(survivor, &mut around);
        let from_a = ring.len();
        for &w in &around {
            if (everyone || !self.refusals.is_empty(w)) && !ring[..from_a].contains(&w) {
                ring.push(w);
            }
        }
        self.around = around;
        for &v in &ring {
            prefetch(&self.queued[v as usize]);
            prefetch(self.fans.get(v));
            self.quadrics[v as usize].prefetch();
            if let Some(anchor) = self.anchors.get(v as usize) {
                anchor.prefetch();
            }
        }
        for (i, &v) in ring.iter().enumerate() {
            if let Some(&next) = ring.get(i + 1) {
                self.prefetch_ring(next);
            }
            if self.removed[v as usize] {
                continue;
            }
            let (_, queued_target) = self.queued[v as usize];
            let full = v == survivor
                || everyone
                || queued_target == a
                || queued_target == NONE
                || !self.refusals.is_empty(v);
            if full {
                self.forget_refusals(v);
                self.refresh(v);
            } else {
                // Only the survivor is new among `v`'s targets, and no other
                // cost changed: compare it with the queued one.
                self.offer(v, survivor);
            }
        }
        self.ring = ring;
    }

    fn stop_record(&mut self, reason: StopReason, round: RoundStats) -> Stop {
        let epoch = self.next_epoch();
        let mut vertices = 0;
        for tri in &self.tris {
            if tri[0] != DEAD {
                for &w in tri {
                    if self.mark[w as usize] != epoch {
                        self.mark[w as usize] = epoch;
                        vertices += 1;
                    }
                }
            }
        }
        Stop {
            reason,
            lod: self.steps.len(),
            triangles: self.triangles_now as usize,
            vertices,
            candidates_left: round.candidates,
            rejected_flip: round.flip,
            rejected_topology: round.topology,
        }
    }

    fn finish(self) -> Simplification {
        let stop = self.stop.expect("run() records where it stopped");
        let collapses = Collapses::new(
            self.input_vertices,
            self.steps,
            self.triangle_counts,
            self.appended,
        );
        Simplification { collapses, stop }
    }
}

/// A surviving triangle of a contraction, as [`Contractor::turn`] sees it.
#[derive(Clone, Copy)]
struct Turn {
    /// The vertices after and before the moved one.
    after: u32,
    before: u32,
    /// Unnormalised normal before the move, and its length.
    now: DVec3,
    now_length: f64,
}

/// A triangle prepared for [`over_within`]: corners, unit normal (zero
/// when degenerate) and the inward normals of its edges' planes through
/// the normal, so a point over the triangle's interior is found by dot
/// products alone.
struct Prism {
    corners: [DVec3; 3],
    normal: DVec3,
    sides: [DVec3; 3],
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
fn exact_within(triangles: &[Prism], p: DVec3, within: f64) -> f64 {
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
fn over_within(triangles: &[Prism], p: DVec3, within: f64) -> bool {
    triangles
        .iter()
        .any(|t| t.over(p).is_some_and(|d| d <= within))
}

/// Whether one of the moved vertex's surviving triangles (`fan`, from
/// [`Contractor::turn`], normals before the move) is more than 15° from
/// their area-weighted mean normal ([`CREASE_COS`]). A flat fan's
/// replacements lie in its plane, so [`Contractor::backward_error`] is
/// skipped there. A fan whose normals cancel out counts as creased.
fn creased(fan: &[Turn]) -> bool {
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
fn border_slots(tris: &[[u32; 3]], fans: &Fans) -> Vec<u8> {
    const LOCAL: usize = 32;
    let mut out = vec![0u8; tris.len()];
    for a in 0..fans.vertex_count() as u32 {
        let around = fans.get(a);
        if around.len() > LOCAL {
            // Sorted instead of scanned per corner: linearithmic in the
            // fan (a 100,000-triangle fan took seconds by the scan).
            let mut holders: Vec<(u32, u32, u8)> = Vec::with_capacity(around.len());
            let mut opposite: Vec<u32> = Vec::with_capacity(around.len());
            for &t in around {
                let tri = tris[t as usize];
                let k = tri.iter().position(|&w| w == a).unwrap_or(0);
                holders.push((tri[(k + 1) % 3], t, k as u8));
                opposite.push(tri[(k + 2) % 3]);
            }
            holders.sort_unstable();
            opposite.sort_unstable();
            let mut rank = 0;
            for (i, &(b, t, k)) in holders.iter().enumerate() {
                rank = if i > 0 && holders[i - 1].0 == b {
                    rank + 1
                } else {
                    0
                };
                let count =
                    opposite.partition_point(|&x| x <= b) - opposite.partition_point(|&x| x < b);
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
fn is_border(tris: &[[u32; 3]], around_a: &[u32], t: u32, a: u32, b: u32) -> bool {
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
fn most_crowded_edge(tris: &[[u32; 3]], fans: &Fans) -> usize {
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

/// Rejections counted over one round of the queue.
#[derive(Default, Clone, Copy)]
struct RoundStats {
    candidates: usize,
    flip: usize,
    topology: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{TriangleAdjacency, NO_NEIGHBOUR};

    /// `is_border` marks exactly the edge slots without a neighbour in
    /// [`TriangleAdjacency`], fins and flipped triangles included.
    #[test]
    fn border_slots_match_the_adjacency() {
        let grid: crate::mesh::generate::Generated = "grid:200".parse().unwrap();
        let mut mesh = grid.build();
        // A fin (three triangles on one edge), a flipped triangle and a
        // lone one.
        let [a, b] = [mesh.triangles[0][0], mesh.triangles[0][1]];
        let extra = mesh.positions.len() as u32;
        mesh.positions.push(glam::Vec3::new(0.3, 0.3, 1.0));
        mesh.positions.push(glam::Vec3::new(0.5, 0.1, 2.0));
        let [x, y, z] = mesh.triangles[5];
        mesh.triangles.push([a, b, extra]);
        mesh.triangles.push([b, a, extra + 1]);
        mesh.triangles.push([y, x, extra + 1]);
        mesh.triangles.push([x, z, extra]);
        let adjacency = TriangleAdjacency::new(&mesh);
        let around = Fans::new(mesh.positions.len(), &mesh.triangles);
        let slots = border_slots(&mesh.triangles, &around);
        let mut borders = 0;
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for slot in 0..3 {
                let (a, b) = (tri[slot], tri[(slot + 1) % 3]);
                let border = is_border(&mesh.triangles, around.get(a), t as u32, a, b);
                assert_eq!(border, adjacency.neighbours[t][slot] == NO_NEIGHBOUR);
                assert_eq!(border, slots[t] & (1 << slot) != 0);
                borders += usize::from(border);
            }
        }
        assert!(borders > 10);
    }

    /// The fan of apex 0 over the ring 1, 2, 3, 4 at `positions`, with
    /// the move of 0 onto 1 checked: it passes the guards and leaves two
    /// creased triangles in `fan`.
    fn apex_0_onto_1(positions: [Vec3; 5]) -> (Mesh, Contractor) {
        let mesh = Mesh {
            positions: positions.to_vec(),
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
        };
        let mut c = Contractor::new(&mesh, &SimplifyOptions::default());
        let p1 = c.p(1);
        assert!(c.check(0, 1, p1).is_ok());
        assert_eq!(c.fan.len(), 2);
        assert!(creased(&c.fan));
        (mesh, c)
    }

    /// A fan of four triangles around vertex 0, seen from above (+z):
    ///
    /// ```text
    ///             3
    ///           / |
    ///   4 ---- 0  |        0 (0, 0, 0)      3 (1, 2, 0)
    ///    \     | \ |        1 (0, -1, -0.5)  4 (-1, 0, 2)
    ///      \   |  2        2 (0.5, -0.5, 0)
    ///        \ | /
    ///           1
    /// ```
    ///
    /// Moving 0 onto 1 turns (0, 2, 3) by 52° and (0, 3, 4) by 5°, which
    /// the flip guard allows, but leaves them facing each other across
    /// edge (1, 3): normals 113° apart, 66° before, a spike. No guard
    /// refuses it; the fan is creased, so the backward distance measures
    /// the new triangles against the old fans, and the move waits at that
    /// distance, far above its quadric cost.
    #[test]
    fn a_move_that_folds_two_neighbours_is_measured_not_refused() {
        let (mesh, c) = apex_0_onto_1([
            Vec3::ZERO,
            Vec3::new(0.0, -1.0, -0.5),
            Vec3::new(0.5, -0.5, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(-1.0, 0.0, 2.0),
        ]);
        let cost = c.cost(0, 1);
        let backward = c.backward_error(0, 1, cost).expect("the spike is measured");
        // Independently: the farthest centroid of the new triangles (1, 2,
        // 3) and (1, 3, 4) from the four old ones, weighted.
        let p = |v: usize| mesh.positions[v];
        let farthest = [[1, 2, 3], [1, 3, 4]]
            .iter()
            .map(|t: &[usize; 3]| {
                let centroid = (p(t[0]) + p(t[1]) + p(t[2])) / 3.0;
                mesh.triangles
                    .iter()
                    .map(|o| {
                        let q = crate::distance::bvh::closest_on_triangle(
                            centroid,
                            p(o[0] as usize),
                            p(o[1] as usize),
                            p(o[2] as usize),
                        );
                        f64::from(q.distance_squared(centroid))
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(
            (backward - BACKWARD_WEIGHT * farthest).abs() < 1e-6,
            "{backward} {farthest}"
        );
        assert!(backward > 1.5 * cost, "{backward} against {cost}");
    }

    /// An open square pyramid, apex 0 at height `h = 0.5` over the ring
    /// 1 (1, 0), 2 (0, 1), 3 (-1, 0), 4 (0, -1). Moving the apex onto 1
    /// flattens the two triangles that survive into the base plane; the
    /// centroid (0, 1/3, 0) of (1, 2, 3) lies below face (0, 2, 3), whose
    /// plane `-x + y + z/h = 1` is `(2/3) / sqrt(2 + 1/h²)` away, and the
    /// other centroid mirrors it. A flat fan is not creased.
    #[test]
    fn backward_distance_of_a_flattened_pyramid() {
        let (mesh, c) = apex_0_onto_1([
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
        ]);
        let d = (2.0 / 3.0) / (2.0f64 + 4.0).sqrt();
        let expected = BACKWARD_WEIGHT * d * d;
        let got = c.backward_error(0, 1, 0.0).unwrap();
        assert!((got - expected).abs() < 1e-9, "{got} != {expected}");
        // Within the limit: nothing to wait for.
        assert_eq!(c.backward_error(0, 1, expected * 1.001), None);

        let mut flat = mesh.clone();
        flat.positions[0].z = 0.0;
        let mut c = Contractor::new(&flat, &SimplifyOptions::default());
        let p1 = c.p(1);
        assert!(c.check(0, 1, p1).is_ok());
        assert!(!creased(&c.fan));
        assert_eq!(c.backward_error(0, 1, 0.0), None);
    }

    /// A flat fan around border vertex 0 at the origin covering three
    /// quadrants, 1 (1, 0), 2 (0, 1), 3 (-1, 0), 4 (0, -1): the quadrant
    /// x > 0, y < 0 is a notch. Sliding 0 along its border onto 1 makes
    /// (4, 1) a border edge across the notch; its midpoint (0.5, -0.5) is
    /// 0.5 from the old surface. With the notch filled, 0 is interior and
    /// no new edge is a border edge.
    #[test]
    fn a_new_border_edge_across_a_notch_is_measured() {
        let mesh = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]],
        };
        let mut c = Contractor::new(&mesh, &SimplifyOptions::default());
        let p1 = c.p(1);
        assert!(c.check(0, 1, p1).is_ok());
        assert!(c.fan_on_border);
        let got = c.border_error(0, 1, 0.0).unwrap();
        assert!((got - BORDER_WEIGHT * 0.25).abs() < 1e-12, "{got}");
        assert_eq!(c.border_error(0, 1, BORDER_WEIGHT * 0.25 * 1.001), None);
        // The flat fan is not creased: the backward distance is not asked.
        assert!(!creased(&c.fan));

        let mut filled = mesh.clone();
        filled.triangles.push([0, 4, 1]);
        let mut c = Contractor::new(&filled, &SimplifyOptions::default());
        assert!(c.check(0, 1, p1).is_ok());
        assert!(!c.fan_on_border);
        assert_eq!(c.border_error(0, 1, 0.0), None);
    }

    /// An open square pyramid, apex 4 at (0, 0, 1.5) over the ring 0 (1,
    /// 0, 0), 1 (0, 1, 0), 2 (-1, 0, 0), 3 (0, -1, 0). Moving the apex
    /// onto 0 flattens it into the square, and 0 then stands for 4 too.
    /// Sliding 0 along the border onto 1 leaves triangle (1, 2, 3): 0's
    /// own position is 1 from its edge (1, 3), squared 1; 4's is 1.5 above
    /// its point (0, 0, 0), squared 2.25, and that is the forward
    /// distance. Before the apex moved, 0 stood for itself alone.
    #[test]
    fn an_input_vertex_contracted_earlier_is_measured_too() {
        let mesh = Mesh {
            positions: vec![
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
                Vec3::new(0.0, 0.0, 1.5),
            ],
            triangles: vec![[4, 0, 1], [4, 1, 2], [4, 2, 3], [4, 3, 0]],
        };
        let mut c = Contractor::new(&mesh, &SimplifyOptions::default());
        let (p0, p1) = (c.p(0), c.p(1));
        assert!(c.check(0, 1, p1).is_ok());
        let alone = c.forward_error(0, 1, 0.0);
        assert_eq!(c.members[0].1, 0, "0 stands for itself alone");

        assert!(c.check(4, 0, p0).is_ok());
        c.contract(4, 0, p0, 0.0, 0.0);
        assert_eq!(c.triangles_now, 2);
        let mut cycle = vec![0];
        while let next @ 1.. = c.members[*cycle.last().unwrap() as usize].1 {
            cycle.push(next);
        }
        assert_eq!(cycle, [0, 4], "0's cycle holds 4 after the move");

        assert!(c.check(0, 1, p1).is_ok());
        let own = 1.0;
        let with_members = c.forward_error(0, 1, 0.0);
        assert!((with_members - 2.25).abs() < 1e-12, "{with_members}");
        // The pyramid's quadric cost does not see it: only the distance
        // makes the move wait.
        assert!(c.cost(0, 1) < with_members, "{}", c.cost(0, 1));
        // Within the limit a member decides nothing: the own distance.
        assert!((c.forward_error(0, 1, 2.3) - own).abs() < 1e-12);
        // Before the apex moved, the same move measured 0's own distance.
        assert!((alone - own).abs() < 1e-12, "{alone}");
    }

    #[test]
    fn the_most_crowded_edge_is_counted() {
        let most = |mesh: &Mesh| {
            most_crowded_edge(
                &mesh.triangles,
                &Fans::new(mesh.vertex_count(), &mesh.triangles),
            )
        };
        let tetrahedron = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        assert_eq!(most(&tetrahedron), 2);
        let one = Mesh {
            triangles: vec![[0, 1, 2]],
            ..tetrahedron.clone()
        };
        assert_eq!(most(&one), 1);
        let none = Mesh {
            triangles: Vec::new(),
            ..tetrahedron
        };
        assert_eq!(most(&none), 0);
        // Sheets meeting on the line through 1, 0, 2: each of its two
        // edges holds one triangle per sheet.
        let three = sheets_on_a_line(&[Vec3::Y, Vec3::Z, -Vec3::Y - Vec3::Z]);
        assert_eq!(most(&three), 3);
        let five = sheets_on_a_line(&[Vec3::Y, Vec3::Z, -Vec3::Y, -Vec3::Z, Vec3::ONE]);
        assert_eq!(most(&five), 5);
    }

    /// Strips of four triangles meeting along the line 1 (-1, 0,
    /// 0), 0 (0, 0, 0), 2 (1, 0, 0), each leaving it in its own direction
    /// `d` with the row `(-1, 0, 0) + d`, `d`, `(1, 0, 0) + d`: edges (0,
    /// 1) and (0, 2) hold one triangle per sheet.
    fn sheets_on_a_line(directions: &[Vec3]) -> Mesh {
        let mut positions = vec![Vec3::ZERO, Vec3::new(-1.0, 0.0, 0.0), Vec3::X];
        let mut triangles = Vec::new();
        for &d in directions {
            let row = positions.len() as u32;
            positions.extend([Vec3::new(-1.0, 0.0, 0.0) + d, d, Vec3::X + d]);
            let (r0, r1, r2) = (row, row + 1, row + 2);
            triangles.extend([[1, 0, r1], [1, r1, r0], [0, 2, r2], [0, r2, r1]]);
        }
        Mesh {
            positions,
            triangles,
        }
    }

    #[test]
    fn a_vertex_where_three_sheets_meet_may_leave_the_line_four_may_not() {
        let three = sheets_on_a_line(&[Vec3::Y, Vec3::NEG_Y, Vec3::Z]);
        let mut c = Contractor::new(&three, &SimplifyOptions::default());
        let (edges, on_01) = c.edges_at(0, 1);
        assert_eq!(on_01, 3);
        assert!(edges.border && !edges.slides);
        // Into the +y sheet, onto its middle vertex 4.
        let p4 = c.p(4);
        assert!(c.check(0, 4, p4).is_ok());
        assert!(c.fan_on_border);
        // Along the line as before.
        let p1 = c.p(1);
        assert!(c.check(0, 1, p1).is_ok());

        let four = sheets_on_a_line(&[Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z]);
        let mut c = Contractor::new(&four, &SimplifyOptions::default());
        let (edges, on_01) = c.edges_at(0, 1);
        assert_eq!(on_01, 4);
        assert!(edges.border && edges.slides);
        assert!(matches!(c.check(0, 4, p4), Err(Reject::Topology)));
        assert!(c.check(0, 1, p1).is_ok());

        // A border vertex (an edge of one triangle) slides too.
        let one = sheets_on_a_line(&[Vec3::Y]);
        let mut c = Contractor::new(&one, &SimplifyOptions::default());
        assert!(c.edges_at(0, 1).0.slides);
        assert!(matches!(c.check(0, 4, p4), Err(Reject::Topology)));
    }
}
