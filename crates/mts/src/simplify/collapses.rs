//! The recorded contraction sequence that defines every level of detail.
//!
//! LoD `k` is the mesh after the first `k` contractions (`../shared/DESIGN.md`,
//! "Level-of-detail numbering"). Vertices are never moved: a contraction
//! makes one vertex the *representative* of another, and triangles keep
//! their original indices, read through the representatives of the LoD.
//! The representatives form a forest (Kalvin-style "vertex representatives"
//! of the progressive multilevel meshes paper, section "Vertex
//! representatives"); [`Collapses::representatives`] path-compresses it for
//! one LoD into the paper's *pc-rep* array.
//!
//! On a mesh with seams ([`crate::mesh::Properties::position_ids`]) one
//! step contracts a point: every vertex of the removed point that live
//! triangles still use moves onto the kept point's vertex on the same side
//! of the seam, all at that LoD. The step's [`Collapse`] holds the first
//! move and [`Collapses::moves`] all of them; the others are the step's
//! *companions*.

use crate::error::ensure;
use crate::mesh::{is_degenerate, Mesh};
use glam::Vec3;

/// One contraction: `removed` is replaced by `kept` from then on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collapse {
    /// The vertex that leaves the mesh.
    pub removed: u32,
    /// The vertex that represents it from this step on. In optimal-placement
    /// sequences it is the other endpoint, and both endpoints are replaced
    /// by the vertex this step creates ([`Collapses::target`]).
    pub kept: u32,
    /// Error of the mesh after this step, relative to the bounding-box
    /// diagonal of the input: the running maximum over the contractions so
    /// far of the root-mean-square quadric distance and, with endpoint
    /// placement, the forward distance, so every input vertex the removed
    /// vertex stood for (itself included) lies within it of the kept
    /// vertex's triangles right after the step. Non-decreasing along the
    /// sequence.
    pub error: f32,
}

/// The ordered contraction sequence with its LoD tables.
///
/// Invariants (checked by [`Collapses::validate`]): a vertex is removed at
/// most once and never used as `kept` after its removal (companion moves
/// included); companions exist only with endpoint placement; the
/// triangle-count
/// table has `max_lod() + 1` non-increasing entries starting at the input's
/// triangle count; errors are finite and non-decreasing; the forest links
/// agree with the steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Collapses {
    /// Vertices of the input mesh.
    pub(crate) vertex_count: usize,
    /// The steps, LoD `k` applies `steps[..k]`.
    pub(crate) steps: Vec<Collapse>,
    /// Triangles (not degenerate) at each LoD, `max_lod + 1` entries.
    pub(crate) triangle_counts: Vec<u32>,
    /// Optimal-placement mode: the position of the vertex created by each
    /// step (one per step); empty when contractions keep an endpoint.
    pub(crate) appended: Vec<Vec3>,
    /// Companion moves `(removed, kept)` of every step, in step order, and
    /// where each step's start (`max_lod() + 1` offsets); both empty when
    /// no step has one.
    pub(crate) companions: Vec<(u32, u32)>,
    pub(crate) companion_start: Vec<u32>,
    /// Forest: for each vertex (input and appended) its representative once
    /// it is removed, and the LoD from which that link holds (`u32::MAX`
    /// for a vertex never removed).
    pub(crate) parent: Vec<u32>,
    pub(crate) parent_from_lod: Vec<u32>,
}

impl Collapses {
    /// Builds the sequence from its steps, computing the forest and checking
    /// the invariants; `triangle_counts[k]` is the triangle count at LoD `k`.
    ///
    /// # Panics
    /// In debug builds, if the steps break an invariant listed on
    /// [`Collapses`] (a bug in the caller, not bad input).
    #[must_use]
    pub(crate) fn new(
        vertex_count: usize,
        steps: Vec<Collapse>,
        triangle_counts: Vec<u32>,
        appended: Vec<Vec3>,
    ) -> Collapses {
        Collapses::with_companions(vertex_count, steps, triangle_counts, appended, Vec::new())
    }

    /// [`Collapses::new`] with companion moves: `companions[i]` are step
    /// `i`'s moves besides its [`Collapse`] (an empty list for none, or no
    /// list at all).
    #[must_use]
    pub(crate) fn with_companions(
        vertex_count: usize,
        steps: Vec<Collapse>,
        triangle_counts: Vec<u32>,
        appended: Vec<Vec3>,
        companions: Vec<Vec<(u32, u32)>>,
    ) -> Collapses {
        let (mut flat, mut companion_start) = (Vec::new(), Vec::new());
        if companions.iter().any(|c| !c.is_empty()) {
            companion_start.push(0);
            for i in 0..steps.len() {
                flat.extend(companions.get(i).into_iter().flatten().copied());
                companion_start.push(flat.len() as u32);
            }
        }
        let total = vertex_count + appended.len();
        let mut parent: Vec<u32> = (0..total as u32).collect();
        let mut parent_from_lod = vec![u32::MAX; total];
        let optimal = !appended.is_empty();
        for (i, s) in steps.iter().enumerate() {
            let lod = i as u32 + 1;
            let target = if optimal {
                (vertex_count + i) as u32
            } else {
                s.kept
            };
            parent[s.removed as usize] = target;
            parent_from_lod[s.removed as usize] = lod;
            if let Some(w) = companion_start.get(i..i + 2) {
                for &(r, k) in &flat[w[0] as usize..w[1] as usize] {
                    parent[r as usize] = k;
                    parent_from_lod[r as usize] = lod;
                }
            }
            if optimal {
                parent[s.kept as usize] = target;
                parent_from_lod[s.kept as usize] = lod;
            }
        }
        let c = Collapses {
            vertex_count,
            steps,
            triangle_counts,
            appended,
            companions: flat,
            companion_start,
            parent,
            parent_from_lod,
        };
        debug_assert_eq!(c.validate(), Ok(()));
        c
    }

    /// The vertex that replaces step `i`'s endpoints: `kept`, or in
    /// optimal-placement mode the vertex the step creates
    /// (`vertex_count() + i`).
    #[must_use]
    pub fn target(&self, i: usize) -> u32 {
        if self.appended.is_empty() {
            self.steps[i].kept
        } else {
            (self.vertex_count + i) as u32
        }
    }

    /// Every vertex move of step `i` as `(from, to)`: `removed → kept` and
    /// its companions, or in optimal placement both endpoints onto the
    /// created vertex. A LoD change applies all of them at once.
    pub fn moves(&self, i: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        let s = self.steps[i];
        let target = self.target(i);
        let kept = self.is_optimal_placement().then_some((s.kept, target));
        let companions = match self.companion_start.get(i..i + 2) {
            Some(w) => &self.companions[w[0] as usize..w[1] as usize],
            None => &[],
        };
        std::iter::once((s.removed, target))
            .chain(kept)
            .chain(companions.iter().copied())
    }

    /// Whether any step moves more than one vertex of a point (the mesh
    /// has seams).
    #[must_use]
    pub fn has_companions(&self) -> bool {
        !self.companions.is_empty()
    }

    /// Whether contractions create new vertices at the quadric's optimum
    /// instead of keeping an endpoint.
    #[must_use]
    pub fn is_optimal_placement(&self) -> bool {
        !self.appended.is_empty()
    }

    /// Number of contractions; LoDs run from 0 (input) to `max_lod()`.
    #[must_use]
    pub fn max_lod(&self) -> usize {
        self.steps.len()
    }

    /// The steps in order.
    #[must_use]
    pub fn steps(&self) -> &[Collapse] {
        &self.steps
    }

    /// Vertices of the input mesh.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Positions of the vertices created by optimal placement (vertex
    /// `vertex_count() + i` is created by step `i`); empty otherwise.
    #[must_use]
    pub fn appended(&self) -> &[Vec3] {
        &self.appended
    }

    /// Triangle count at LoD `lod` (degenerate triangles not counted).
    ///
    /// # Panics
    /// If `lod > max_lod()`.
    #[must_use]
    pub fn triangle_count(&self, lod: usize) -> usize {
        self.triangle_counts[lod] as usize
    }

    /// The monotone table LoD → triangle count (`max_lod() + 1` entries).
    #[must_use]
    pub fn triangle_counts(&self) -> &[u32] {
        &self.triangle_counts
    }

    /// The finest LoD with at most `budget` triangles; `max_lod()` when even
    /// the coarsest has more. O(log n).
    #[must_use]
    pub fn lod_for_triangles(&self, budget: usize) -> usize {
        // Non-increasing table: the first entry <= budget.
        let k = self
            .triangle_counts
            .partition_point(|&t| t as usize > budget);
        k.min(self.max_lod())
    }

    /// [`Collapses::lod_for_triangles`] for `ratio` of the input's triangles
    /// (rounded to the nearest count; ratios outside 0..=1 are clamped).
    #[must_use]
    pub fn lod_for_ratio(&self, ratio: f64) -> usize {
        let full = f64::from(self.triangle_counts[0]);
        let budget = (ratio.clamp(0.0, 1.0) * full).round() as usize;
        self.lod_for_triangles(budget)
    }

    /// Error after `lod` contractions (0 at LoD 0), relative to the input's
    /// bounding-box diagonal.
    #[must_use]
    pub fn error(&self, lod: usize) -> f32 {
        if lod == 0 {
            0.0
        } else {
            self.steps[lod - 1].error
        }
    }

    /// Representative of vertex `v` at LoD `lod`: follows the forest while
    /// its links are older than `lod`. O(depth of the forest).
    #[must_use]
    pub fn representative(&self, mut v: u32, lod: usize) -> u32 {
        while self.parent_from_lod[v as usize] as usize <= lod {
            v = self.parent[v as usize];
        }
        v
    }

    /// The path-compressed representative array (*pc-rep*) of LoD `lod`:
    /// entry `v` is the vertex drawn in place of `v`. O(vertices + lod):
    /// steps are resolved backwards, so every `kept` is final when read.
    #[must_use]
    pub fn representatives(&self, lod: usize) -> Vec<u32> {
        let mut rep = Vec::new();
        self.fill_representatives(lod, &mut rep);
        rep
    }

    /// [`Collapses::representatives`] into a caller's buffer (no allocation
    /// when it is already large enough).
    pub fn fill_representatives(&self, lod: usize, rep: &mut Vec<u32>) {
        let lod = lod.min(self.max_lod());
        rep.clear();
        rep.extend(0..self.parent.len() as u32);
        for i in (0..lod).rev() {
            for (from, to) in self.moves(i) {
                rep[from as usize] = rep[to as usize];
            }
        }
    }

    /// The naive replay, the oracle of every later test: each input triangle
    /// with its vertices replaced by their representatives at `lod`, in input
    /// order, degenerate ones dropped. Indices refer to the input's vertices
    /// (and appended ones in optimal mode). O(triangles + vertices).
    ///
    /// # Panics
    /// If `mesh` is not the mesh the sequence was computed from (vertex
    /// count differs) or `lod > max_lod()`.
    #[must_use]
    pub fn triangles_at(&self, mesh: &Mesh, lod: usize) -> Vec<[u32; 3]> {
        assert_eq!(
            mesh.vertex_count(),
            self.vertex_count,
            "Collapses used with another mesh"
        );
        assert!(lod <= self.max_lod(), "LoD {lod} beyond {}", self.max_lod());
        let rep = self.representatives(lod);
        mesh.triangles
            .iter()
            .map(|t| t.map(|v| rep[v as usize]))
            .filter(|t| !is_degenerate(*t))
            .collect()
    }

    /// The mesh at `lod` as a standalone [`Mesh`]: [`Collapses::triangles_at`]
    /// with unreferenced vertices dropped (order kept), for export and error
    /// measurement.
    #[must_use]
    pub fn mesh_at(&self, mesh: &Mesh, lod: usize) -> Mesh {
        let triangles = self.triangles_at(mesh, lod);
        let all: Vec<Vec3> = mesh
            .positions
            .iter()
            .chain(&self.appended)
            .copied()
            .collect();
        let (mut out, order) = compact(&all, &triangles);
        if self.appended.is_empty() {
            // Endpoint placement: every vertex is an input vertex, with its
            // input properties.
            out.properties = mesh.properties.gather(&order);
        }
        out
    }

    /// Checks the invariants listed on [`Collapses`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        let total = self.vertex_count + self.appended.len();
        ensure!(
            "Collapses",
            self.triangle_counts.len() == self.steps.len() + 1,
            "table length"
        );
        ensure!(
            "Collapses",
            self.triangle_counts.windows(2).all(|w| w[0] >= w[1]),
            "triangle counts increase"
        );
        ensure!(
            "Collapses",
            self.appended.is_empty() || self.appended.len() == self.steps.len(),
            "self.appended.is_empty() || self.appended.len() == self.steps.len()"
        );
        ensure!(
            "Collapses",
            self.companion_start.is_empty()
                || (self.companion_start.len() == self.steps.len() + 1
                    && self.companion_start.windows(2).all(|w| w[0] <= w[1])
                    && *self.companion_start.last().unwrap() as usize == self.companions.len()),
            "companion table"
        );
        let mut removed_at = vec![u32::MAX; total];
        let mut last_error = 0.0f32;
        for (i, s) in self.steps.iter().enumerate() {
            let (r, k) = (s.removed as usize, s.kept as usize);
            ensure!(
                "Collapses",
                r < total && k < total && r != k,
                "step {i}: bad vertices {s:?}"
            );
            ensure!(
                "Collapses",
                removed_at[r] == u32::MAX,
                "step {i}: vertex {r} removed twice"
            );
            ensure!(
                "Collapses",
                removed_at[k] == u32::MAX,
                "step {i}: kept vertex {k} already removed"
            );
            removed_at[r] = i as u32;
            let target = self.target(i);
            ensure!(
                "Collapses",
                !self.is_optimal_placement() || (r.max(k) < target as usize),
                "step {i}: uses a vertex created later"
            );
            if self.is_optimal_placement() {
                removed_at[k] = i as u32;
                ensure!(
                    "Collapses",
                    self.parent[k] == target,
                    "step {i}: forest link of the kept endpoint"
                );
            }
            if let Some(w) = self.companion_start.get(i..i + 2) {
                ensure!(
                    "Collapses",
                    !self.is_optimal_placement(),
                    "step {i}: companions in optimal placement"
                );
                for &(cr, ck) in &self.companions[w[0] as usize..w[1] as usize] {
                    let (cr, ck) = (cr as usize, ck as usize);
                    ensure!(
                        "Collapses",
                        cr < total && ck < total && cr != ck,
                        "step {i}: bad companion {cr} -> {ck}"
                    );
                    ensure!(
                        "Collapses",
                        removed_at[cr] == u32::MAX && removed_at[ck] == u32::MAX,
                        "step {i}: companion {cr} -> {ck} uses a removed vertex"
                    );
                    removed_at[cr] = i as u32;
                    ensure!(
                        "Collapses",
                        self.parent[cr] == ck as u32,
                        "step {i}: forest link of a companion"
                    );
                }
            }
            ensure!(
                "Collapses",
                s.error.is_finite() && s.error >= last_error,
                "step {i}: error decreases"
            );
            last_error = s.error;
            ensure!(
                "Collapses",
                self.parent[r] == target,
                "step {i}: forest link"
            );
        }
        Ok(())
    }
}

/// `triangles` over `positions` with unreferenced vertices dropped, and
/// the old vertex of each new one.
fn compact(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Mesh, Vec<u32>) {
    let mut map = vec![u32::MAX; positions.len()];
    let mut out = Vec::new();
    let mut order = Vec::new();
    let triangles = triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut map[v as usize];
                if *slot == u32::MAX {
                    *slot = out.len() as u32;
                    out.push(positions[v as usize]);
                    order.push(v);
                }
                *slot
            })
        })
        .collect();
    (
        Mesh {
            positions: out,
            triangles,
            properties: Default::default(),
        },
        order,
    )
}
