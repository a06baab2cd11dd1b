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

mod attributes;
mod choice;
mod cost;
mod created;
mod distances;
mod guards;
mod placement;
mod seams;

use distances::Prism;
use guards::{border_slots, creased, most_crowded_edge, Reject, Turn};
use placement::{Endpoint, Optimal, Place};

use super::collapses::{Collapse, Collapses};
use super::fans::{Fans, Stars, WIDE};
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
/// bounded valences; where fans hold thousands of triangles over a few
/// hundred neighbours (a dense non-manifold mesh) O(T log T) and
/// O(valence) per refused candidate (`fans.rs`, stars); memory under 200
/// bytes per triangle at peak (197 for the whole `mts simplify` process on
/// a 1M-triangle icosphere).
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
    simplify_locked(mesh, options, &[])
}

/// [`simplify`] with some vertices locked in place: `locked` is empty (no
/// lock: the very sequence [`simplify`] makes) or holds one flag per vertex
/// of `mesh`. A locked vertex is never removed: with endpoint placement a
/// contraction `u → v` of a locked `u` is never made (`v` may be locked);
/// with optimal placement a contraction onto a locked vertex puts the
/// created vertex exactly at its position (and locks it), and one of two
/// locked vertices is never made. On a mesh with seams a point is locked
/// when any of its vertices is. Used to simplify a part of a mesh whose
/// border must still meet its neighbours' (`crate::hierarchy`).
///
/// Cost: as [`simplify`], plus O(vertices) for the flags.
///
/// # Panics
/// As [`simplify`], and if `locked` is neither empty nor one flag per
/// vertex.
#[must_use]
pub fn simplify_locked(mesh: &Mesh, options: &SimplifyOptions, locked: &[bool]) -> Simplification {
    assert!(
        locked.is_empty() || locked.len() == mesh.vertex_count(),
        "simplify_locked: {} lock flags for {} vertices",
        locked.len(),
        mesh.vertex_count()
    );
    // No flag set is no lock: the unlocked loop, bit for bit.
    let locked = if locked.contains(&true) { locked } else { &[] };
    let scale = crate::mesh::power_of_two_scale(&mesh.positions);
    if scale != 1.0 {
        let scaled = Mesh {
            positions: crate::mesh::scaled_positions(&mesh.positions, scale),
            triangles: mesh.triangles.clone(),
            properties: mesh.properties.clone(),
        };
        let mut result = simplify_locked(&scaled, options, locked);
        for p in &mut result.collapses.appended {
            *p = (p.as_dvec3() / scale).as_vec3();
        }
        return result;
    }
    let with_properties = !mesh.properties.is_empty();
    match options.placement {
        Placement::Endpoint if with_properties => {
            contract_points::<Endpoint>(mesh, options, locked)
        }
        Placement::Endpoint => contract::<Endpoint>(mesh, options, locked),
        Placement::Optimal if with_properties => contract_points::<Optimal>(mesh, options, locked),
        Placement::Optimal => contract::<Optimal>(mesh, options, locked),
    }
}

/// The whole sequence with placement `P`.
fn contract<P: Place>(mesh: &Mesh, options: &SimplifyOptions, locked: &[bool]) -> Simplification {
    let mut c = Contractor::<P>::new_with(mesh, options, |c| c.locked = locked.to_vec());
    c.run(options.stop_at_triangles);
    c.finish()
}

/// The whole sequence of a mesh with properties, contracted point by point
/// (`seams.rs`; every vertex its own point when none is split), with the
/// attribute quadrics in the cost (`attributes.rs`). With optimal placement
/// each step creates one vertex per seam pair, with interpolated
/// properties (`created.rs`).
fn contract_points<P: Place>(
    mesh: &Mesh,
    options: &SimplifyOptions,
    locked: &[bool],
) -> Simplification {
    let identity: Vec<u32>;
    let ids = if mesh.properties.position_ids.is_empty() {
        identity = (0..mesh.vertex_count() as u32).collect();
        &identity
    } else {
        &mesh.properties.position_ids
    };
    let points = ids.iter().max().map_or(0, |&m| m as usize + 1);
    let mut positions = vec![Vec3::ZERO; points];
    for (v, &id) in ids.iter().enumerate() {
        positions[id as usize] = mesh.positions[v];
    }
    let point_mesh = Mesh {
        positions,
        triangles: mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| ids[v as usize]))
            .collect(),
        properties: Default::default(),
    };
    let mut c = Contractor::<P>::new_with(&point_mesh, options, |c| {
        if !locked.is_empty() {
            c.locked = vec![false; points];
            for (v, &id) in ids.iter().enumerate() {
                c.locked[id as usize] |= locked[v];
            }
        }
        c.corners.clone_from(&mesh.triangles);
        c.output_vertices = mesh.vertex_count();
        if P::MOVES_KEPT {
            c.properties = Some(crate::mesh::Properties {
                position_ids: Vec::new(),
                texture: None,
                ..mesh.properties.clone()
            });
        }
        c.attributes =
            attributes::Attributes::new(mesh, ids, points, options.attribute_weights, c.diagonal);
    });
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

struct Contractor<P> {
    /// The placement strategy and its state.
    place: P,
    /// On a mesh with seams (`seams.rs`), the vertex at each corner of each
    /// triangle (the triangles of `tris` are over points); empty otherwise.
    corners: Vec<[u32; 3]>,
    /// Scratch pairs (vertex of `a`, vertex of `b`) of
    /// [`Contractor::seam_map`].
    seam_pairs: Vec<(u32, u32)>,
    /// Each step's moves besides its [`Collapse`] (seams only).
    companions: Vec<Vec<(u32, u32)>>,
    /// Attribute quadrics of the vertices (a mesh with properties only).
    attributes: Option<attributes::Attributes>,
    /// Optimal placement on a mesh with properties: the property streams
    /// of every vertex, the input's then the created ones (`created.rs`).
    properties: Option<crate::mesh::Properties>,
    /// Scratch `(old vertex, created vertex)` moves of a step in optimal
    /// placement on a mesh with properties.
    corner_moves: Vec<(u32, u32)>,
    /// Output vertices created so far (optimal placement on a mesh with
    /// properties; one per step otherwise, not counted here).
    created_count: usize,
    /// Vertices of the output sequence: the input's, or on a mesh with
    /// seams its vertices (not its points).
    output_vertices: usize,
    diagonal: f64,
    /// Input positions as loaded (`f32`, half the cache footprint; widened
    /// exactly on use, see [`Contractor::p`]). Created vertices (optimal
    /// placement) follow them, held by [`Contractor::place`].
    pos: Vec<Vec3>,
    quadrics: Vec<Quadric>,
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
    /// The neighbours of wide fans (`fans.rs`), current until a triangle
    /// of the fan changes ([`Contractor::contract`] marks them).
    stars: Stars,
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
    /// Scratch vertex list (a vertex's partners, in [`Optimal`]'s
    /// [`Place::best`] and for the survivor in [`Contractor::contract`]).
    around: Vec<u32>,
    /// Output.
    steps: Vec<Collapse>,
    triangle_counts: Vec<u32>,
    triangles_now: u32,
    max_error: f32,
    stop: Option<Stop>,
    /// Scratch (vertex, count) list for [`Contractor::edges_at`].
    scratch: Vec<(u32, u32)>,
    /// Scratch list of the common neighbours [`Contractor::check`] has
    /// looked at.
    checked: Vec<u32>,
    /// Triangles on the input's most crowded edge, at least 2: no merge
    /// may make an edge hold more ([`Contractor::merge_keeps_manifold`]).
    crowding: usize,
    /// Per vertex, whether it is locked ([`simplify_locked`]): it never
    /// chooses a target, so it is never the removed end of a contraction.
    /// Empty when nothing is locked.
    locked: Vec<bool>,
}

impl<P: Place> Contractor<P> {
    #[cfg(test)]
    fn new(mesh: &Mesh, options: &SimplifyOptions) -> Contractor<P> {
        Self::new_with(mesh, options, |_| {})
    }

    /// [`Contractor::new`] with `setup` run before the first choices.
    fn new_with(
        mesh: &Mesh,
        options: &SimplifyOptions,
        setup: impl FnOnce(&mut Contractor<P>),
    ) -> Contractor<P> {
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
        let place = P::new(mesh, &quadrics);
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
            place,
            corners: Vec::new(),
            seam_pairs: Vec::new(),
            companions: Vec::new(),
            attributes: None,
            properties: None,
            corner_moves: Vec::new(),
            created_count: 0,
            output_vertices: n,
            diagonal,
            pos,
            quadrics,
            after: Vec::new(),
            tris,
            normals0,
            fans,
            stars: Stars::new(n),
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
            triangles_now,
            max_error: 0.0,
            stop: None,
            scratch: Vec::new(),
            checked: Vec::new(),
            crowding,
            locked: Vec::new(),
        };
        setup(&mut c);
        P::choose_all(&mut c);
        c
    }

    /// Asks for the triangles around `v` ahead of the loops over them (not
    /// for a wide fan: its questions go to its star).
    #[inline]
    fn prefetch_ring(&self, v: u32) {
        let around = self.fans.get(v);
        if around.len() > WIDE {
            return;
        }
        for &t in around {
            prefetch(&self.tris[t as usize]);
        }
    }

    /// Whether `v` is locked ([`Contractor::locked`]).
    #[inline]
    fn is_locked(&self, v: u32) -> bool {
        self.locked.get(v as usize).copied().unwrap_or(false)
    }

    /// Position of vertex `v` in `f64` (input positions widen exactly).
    #[inline]
    fn p(&self, v: u32) -> DVec3 {
        match self.pos.get(v as usize) {
            Some(p) => p.as_dvec3(),
            None => self.place.created(v as usize - self.pos.len()),
        }
    }

    /// Unit normal of input triangle `t` (zero for a zero-area one),
    /// normalised in `f64` as when it was stored that way.
    #[inline]
    fn input_normal(&self, t: u32) -> DVec3 {
        self.normals0[t as usize].as_dvec3().normalize_or_zero()
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
            self.place.prefetch(a);
            self.fans.prefetch_span(b);
            if self.removed[b as usize] {
                // The target went away without `a` being next to its
                // survivor (their shared triangles died with it).
                self.refresh(a);
                continue;
            }
            let target = P::target(self, a, b);
            match self.check(a, b, target) {
                Ok(()) => {
                    // The queue's cost is a lower bound (after the guards:
                    // their loads of the fan serve the distances too).
                    let (forward, wait) = P::distances(self, a, b, cost);
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
        // Every triangle that changes below is around `a` (and in optimal
        // mode around `b`, whose neighbours are marked once the survivor's
        // fan is known).
        if !self.stars.is_empty() {
            self.stars.invalidate(a);
            for &w in &ring {
                self.stars.invalidate(w);
            }
        }
        let error = P::recorded_error(self, a, target, cost, forward);
        let q = self.quadrics[a as usize] + self.quadrics[b as usize];
        let t = created::along(self.p(a), self.p(b), target);
        let survivor = P::merge(self, a, b, target);
        self.quadrics[survivor as usize] = q;
        // Optimal placement on a mesh with properties: each seam pair's
        // vertices move onto a vertex created for the pair.
        let create = survivor != b && !self.corners.is_empty();
        let first_created = if create {
            let first = self.output_vertices + self.created_count;
            self.corner_moves.clear();
            for (j, &(va, vb)) in self.seam_pairs.iter().enumerate() {
                let c = (first + j) as u32;
                self.corner_moves.extend([(va, c), (vb, c)]);
            }
            first
        } else {
            0
        };
        // The survivor's list: b's live triangles without `a`, then `a`'s
        // live ones (which never contain `b`), in b's block when it has room.
        let mut dead = 0u32;
        let tris = &mut self.tris;
        let (corners, moves) = (&mut self.corners, &self.corner_moves);
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
            for (slot, w) in tri.iter_mut().enumerate() {
                if *w == b {
                    *w = survivor;
                    if create {
                        let c = &mut corners[t as usize][slot];
                        *c = Self::seam_target(moves, *c);
                    }
                }
            }
            true
        });
        if survivor != b {
            self.fans.move_into(b, survivor, |_| true);
            self.removed[b as usize] = true;
        }
        let (corners, pairs) = if create {
            (&mut self.corners, &self.corner_moves)
        } else {
            (&mut self.corners, &self.seam_pairs)
        };
        self.fans.move_into(a, survivor, |t| {
            let tri = &mut tris[t as usize];
            if tri[0] == DEAD {
                return false;
            }
            for (slot, w) in tri.iter_mut().enumerate() {
                if *w == a {
                    *w = survivor;
                    if let Some(c) = corners.get_mut(t as usize) {
                        c[slot] = Self::seam_target(pairs, c[slot]);
                    }
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
        if create {
            let pairs = self.seam_pairs.len();
            if let Some(props) = &mut self.properties {
                for &(va, vb) in &self.seam_pairs {
                    created::push_interpolated(props, va, vb, t);
                }
            }
            if let Some(attributes) = &mut self.attributes {
                let props = self
                    .properties
                    .as_ref()
                    .expect("optimal placement keeps properties");
                for (j, &(va, vb)) in self.seam_pairs.iter().enumerate() {
                    attributes.create((first_created + j) as u32, va, vb, props);
                }
                attributes.push_point((0..pairs).map(|j| (first_created + j) as u32));
            }
            self.created_count += pairs;
        } else if let Some(attributes) = &mut self.attributes {
            for &(wa, wb) in &self.seam_pairs {
                attributes.merge(wa, wb);
            }
        }
        let (removed, kept) = if self.corners.is_empty() {
            (a, b)
        } else {
            // The step's first move; the others are its companions.
            self.companions.push(self.seam_pairs[1..].to_vec());
            self.seam_pairs[0]
        };
        self.steps.push(Collapse {
            removed,
            kept,
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
        if everyone && !self.stars.is_empty() {
            for &w in &around {
                self.stars.invalidate(w);
            }
        }
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
            self.place.prefetch(v);
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

    /// Adds a vertex with no triangles, quadric or choice yet (a
    /// placement that creates one calls it) and returns it.
    fn push_vertex(&mut self) -> u32 {
        let c = self.removed.len() as u32;
        self.quadrics.push(Quadric::default());
        self.fans.push_vertex();
        self.stars.push_vertex();
        self.removed.push(false);
        self.mark.push(0);
        self.queued.push((f32::NAN, NONE));
        self.floor.push(NO_KEY);
        self.refusals.push_vertex();
        if !self.partners.is_empty() {
            self.partners.push(Vec::new());
        }
        if !self.locked.is_empty() {
            self.locked.push(false);
        }
        c
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
        let mut created = self.place.into_created();
        let mut created_properties = crate::mesh::Properties::default();
        if !self.corners.is_empty() && !created.is_empty() {
            // One created vertex per pair of each step, at the step's point.
            created = created
                .iter()
                .zip(&self.companions)
                .flat_map(|(&p, c)| std::iter::repeat_n(p, 1 + c.len()))
                .collect();
        }
        if let Some(mut p) = self.properties {
            let n = self.output_vertices;
            created_properties.normals = p.normals.as_mut().map(|s| s.split_off(n));
            created_properties.uvs = p.uvs.as_mut().map(|s| s.split_off(n));
            created_properties.colors = p.colors.as_mut().map(|s| s.split_off(n));
        }
        let collapses = Collapses::with_created_properties(
            self.output_vertices,
            self.steps,
            self.triangle_counts,
            created,
            self.companions,
            created_properties,
        );
        Simplification { collapses, stop }
    }
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
    use super::guards::is_border;
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

    /// Wide fans (sorted, not scanned) pair as the adjacency does too: a
    /// dense mesh with a hub, and 40 copies of one triangle beside 25
    /// reversed ones.
    #[test]
    fn border_slots_of_wide_fans_match_the_adjacency() {
        let mut mesh = dense_with_hub(64, 1000, 3);
        mesh.triangles.extend([[5, 6, 7]; 40]);
        mesh.triangles.extend([[5, 7, 6]; 25]);
        let adjacency = TriangleAdjacency::new(&mesh);
        let around = Fans::new(mesh.positions.len(), &mesh.triangles);
        assert!((0..64).all(|v| around.get(v).len() > 32));
        let slots = border_slots(&mesh.triangles, &around);
        let mut borders = 0;
        for (t, (bits, neighbours)) in slots.iter().zip(&adjacency.neighbours).enumerate() {
            for (slot, &n) in neighbours.iter().enumerate() {
                let border = n == NO_NEIGHBOUR;
                assert_eq!(border, bits & (1 << slot) != 0, "{t} {slot}");
                borders += usize::from(border);
            }
        }
        assert_eq!(borders, 1817);
    }

    /// The fan of apex 0 over the ring 1, 2, 3, 4 at `positions`, with
    /// the move of 0 onto 1 checked: it passes the guards and leaves two
    /// creased triangles in `fan`.
    fn apex_0_onto_1(positions: [Vec3; 5]) -> (Mesh, Contractor<Endpoint>) {
        let mesh = Mesh {
            positions: positions.to_vec(),
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
            properties: Default::default(),
        };
        let mut c = Contractor::<Endpoint>::new(&mesh, &SimplifyOptions::default());
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
        let mut c = Contractor::<Endpoint>::new(&flat, &SimplifyOptions::default());
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
            properties: Default::default(),
        };
        let mut c = Contractor::<Endpoint>::new(&mesh, &SimplifyOptions::default());
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
        let mut c = Contractor::<Endpoint>::new(&filled, &SimplifyOptions::default());
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
            properties: Default::default(),
        };
        let mut c = Contractor::<Endpoint>::new(&mesh, &SimplifyOptions::default());
        let (p0, p1) = (c.p(0), c.p(1));
        assert!(c.check(0, 1, p1).is_ok());
        let alone = c.forward_error(0, 1, 0.0);
        assert_eq!(c.place.members[0].1, 0, "0 stands for itself alone");

        assert!(c.check(4, 0, p0).is_ok());
        c.contract(4, 0, p0, 0.0, 0.0);
        assert_eq!(c.triangles_now, 2);
        let mut cycle = vec![0];
        while let next @ 1.. = c.place.members[*cycle.last().unwrap() as usize].1 {
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

    /// `triangles` distinct random triangles over `vertices` vertices in
    /// the unit cube (a fixed linear congruential sequence), and a hub:
    /// both windings of `(0, 1, k)` for every other vertex `k`. Every fan
    /// is wide and every pair of vertices a common neighbour; the hub's
    /// crowded edge lets merges pass the fin rule, so about half the
    /// vertices contract before no valid pair is left.
    fn dense_with_hub(vertices: u32, triangles: usize, seed: u64) -> Mesh {
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as u32
        };
        let positions = (0..vertices)
            .map(|_| Vec3::new(next() as f32, next() as f32, next() as f32) / 2f32.powi(31))
            .collect();
        let mut seen = std::collections::HashSet::new();
        let mut tris = Vec::new();
        while tris.len() < triangles {
            let t = [next() % vertices, next() % vertices, next() % vertices];
            let mut key = t;
            key.sort_unstable();
            if key[0] != key[1] && key[1] != key[2] && seen.insert(key) {
                tris.push(t);
            }
        }
        for k in 2..vertices {
            tris.extend([[0, 1, k], [1, 0, k]]);
        }
        Mesh {
            positions,
            triangles: tris,
            properties: Default::default(),
        }
    }

    /// Asserts that the stars answer what the scans of the fans answer:
    /// the topology verdict and the border flag of every pair of live
    /// vertices, and each vertex's choice as `choose` returns it (scan,
    /// star). Returns how many pairs pass.
    fn stars_agree_with_scans<P: Place>(
        c: &mut Contractor<P>,
        choose: impl Fn(&mut Contractor<P>, u32) -> (Option<(f64, u32)>, Option<(f64, u32)>),
    ) -> usize {
        let live: Vec<u32> = (0..c.removed.len() as u32)
            .filter(|&v| !c.removed[v as usize])
            .collect();
        let mut passed = 0;
        for &a in &live {
            let (scan, star) = choose(c, a);
            assert_eq!(scan, star, "choice of {a}");
            for &b in live.iter().filter(|&&b| b != a) {
                let scan = c.topology(a, b).is_ok();
                let border = c.fan_on_border;
                let star = c.topology_wide(a, b).is_ok();
                assert_eq!((scan, border), (star, c.fan_on_border), "{a} -> {b}");
                passed += usize::from(star);
            }
        }
        passed
    }

    /// The stars of a dense mesh give the scans' answers as built, partway
    /// and at the end of the sequence (a star left current across a change
    /// of its fan would show), in both placements.
    #[test]
    fn stars_answer_as_the_scans_do() {
        let mesh = dense_with_hub(64, 1000, 7);
        assert_eq!(mesh.triangle_count(), 1124);
        let mut seen = Vec::new();
        for stop in [Some(1124), Some(1090), None] {
            let options = SimplifyOptions {
                stop_at_triangles: stop,
                ..Default::default()
            };
            let mut c = Contractor::<Endpoint>::new(&mesh, &options);
            c.run(stop);
            let passed = stars_agree_with_scans(&mut c, |c, v| {
                c.refresh(v);
                let scan = c.best_endpoint(v);
                (scan, Endpoint::best(c, v))
            });
            assert!(!c.stars.is_empty());
            let mut c_optimal = Contractor::<Optimal>::new(&mesh, &options);
            c_optimal.run(stop);
            stars_agree_with_scans(&mut c_optimal, |_, _| (None, None));
            seen.push((c.steps.len(), passed, c_optimal.steps.len()));
        }
        // (endpoint steps, pairs passing the topology rules, optimal steps)
        assert_eq!(seen, [(0, 2968, 0), (15, 1836, 18), (32, 842, 44)]);
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
            properties: Default::default(),
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
            properties: Default::default(),
        }
    }

    #[test]
    fn a_vertex_where_three_sheets_meet_may_leave_the_line_four_may_not() {
        let three = sheets_on_a_line(&[Vec3::Y, Vec3::NEG_Y, Vec3::Z]);
        let mut c = Contractor::<Endpoint>::new(&three, &SimplifyOptions::default());
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
        let mut c = Contractor::<Endpoint>::new(&four, &SimplifyOptions::default());
        let (edges, on_01) = c.edges_at(0, 1);
        assert_eq!(on_01, 4);
        assert!(edges.border && edges.slides);
        assert!(matches!(c.check(0, 4, p4), Err(Reject::Topology)));
        assert!(c.check(0, 1, p1).is_ok());

        // A border vertex (an edge of one triangle) slides too.
        let one = sheets_on_a_line(&[Vec3::Y]);
        let mut c = Contractor::<Endpoint>::new(&one, &SimplifyOptions::default());
        assert!(c.edges_at(0, 1).0.slides);
        assert!(matches!(c.check(0, 4, p4), Err(Reject::Topology)));
    }
}
