//! The recorded contraction sequence that defines every level of detail.
//!
//! LoD `k` is the mesh after the first `k` contractions (`docs/design.md`,
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
//!
//! With optimal placement a step creates one vertex per pair it moves
//! (its [`Collapse`] and each companion): both vertices of the pair move
//! onto it, so a seamed point becomes one new point with as many vertices
//! as the pair had sides. The created vertices follow the input's in step
//! order, and [`Collapses::created_properties`] holds their properties.

use crate::error::ensure;
use crate::mesh::{is_degenerate, Mesh, Properties};
use glam::Vec3;

/// One contraction: `removed` is replaced by `kept` from then on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collapse {
    /// The vertex that leaves the mesh.
    pub removed: u32,
    /// The vertex that represents it from this step on. In optimal-placement
    /// sequences it is the other endpoint, and both endpoints are replaced
    /// by the first vertex this step creates ([`Collapses::target`]).
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
/// included); with optimal placement there is one created vertex per pair
/// moved (a step and each companion), all of one step at one position, each
/// created after the vertices its step moves, and their properties (when
/// present) one per created vertex, finite, normals unit or zero, colours in
/// 0..=1; the triangle-count table has `max_lod() + 1` non-increasing
/// entries starting at the input's triangle count; errors are finite and
/// non-decreasing; the forest links agree with the steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Collapses {
    /// Vertices of the input mesh.
    pub(crate) vertex_count: usize,
    /// The steps, LoD `k` applies `steps[..k]`.
    pub(crate) steps: Vec<Collapse>,
    /// Triangles (not degenerate) at each LoD, `max_lod + 1` entries.
    pub(crate) triangle_counts: Vec<u32>,
    /// Optimal-placement mode: the position of each created vertex, in
    /// step order (one per pair a step moves, see
    /// [`Collapses::created_start`]); empty when contractions keep an
    /// endpoint.
    pub(crate) appended: Vec<Vec3>,
    /// Properties of the created vertices (streams only, one entry per
    /// entry of `appended`); empty when the input has none.
    pub(crate) created_properties: Properties,
    /// Companion moves `(removed, kept)` of every step, in step order, and
    /// where each step's start (`max_lod() + 1` offsets); both empty when
    /// no step has one.
    pub(crate) companions: Vec<(u32, u32)>,
    pub(crate) companion_start: Vec<u32>,
    /// Optimal placement: the first created vertex of each step, less
    /// `vertex_count` (`max_lod() + 1` offsets, so step `i` creates
    /// `created_start[i + 1] - created_start[i]` vertices); empty otherwise.
    pub(crate) created_start: Vec<u32>,
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
        Collapses::with_created_properties(
            vertex_count,
            steps,
            triangle_counts,
            appended,
            companions,
            Properties::default(),
        )
    }

    /// [`Collapses::with_companions`] with the properties of the created
    /// vertices (optimal placement on a mesh with properties; streams only,
    /// one entry per created vertex). In optimal placement each step
    /// creates one vertex per pair it moves, so `appended` then holds
    /// `steps.len()` plus the companions' count.
    #[must_use]
    pub(crate) fn with_created_properties(
        vertex_count: usize,
        steps: Vec<Collapse>,
        triangle_counts: Vec<u32>,
        appended: Vec<Vec3>,
        companions: Vec<Vec<(u32, u32)>>,
        created_properties: Properties,
    ) -> Collapses {
        let (mut flat, mut companion_start) = (Vec::new(), Vec::new());
        if companions.iter().any(|c| !c.is_empty()) {
            companion_start.push(0);
            for i in 0..steps.len() {
                flat.extend(companions.get(i).into_iter().flatten().copied());
                companion_start.push(flat.len() as u32);
            }
        }
        let optimal = !appended.is_empty();
        let created_start: Vec<u32> = if optimal {
            (0..=steps.len())
                .map(|i| i as u32 + companion_start.get(i).copied().unwrap_or(0))
                .collect()
        } else {
            Vec::new()
        };
        let total = vertex_count + appended.len();
        let mut parent: Vec<u32> = (0..total as u32).collect();
        let mut parent_from_lod = vec![u32::MAX; total];
        for (i, s) in steps.iter().enumerate() {
            let lod = i as u32 + 1;
            let step_companions = match companion_start.get(i..i + 2) {
                Some(w) => &flat[w[0] as usize..w[1] as usize],
                None => &[],
            };
            let pairs = std::iter::once((s.removed, s.kept)).chain(step_companions.iter().copied());
            for (j, (r, k)) in pairs.enumerate() {
                if optimal {
                    // Out of range for a broken table: `validate` reports it.
                    let c = (vertex_count + created_start[i] as usize + j).min(total - 1) as u32;
                    for v in [r, k] {
                        if let Some(slot) = parent.get_mut(v as usize) {
                            *slot = c;
                            parent_from_lod[v as usize] = lod;
                        }
                    }
                } else if let Some(slot) = parent.get_mut(r as usize) {
                    *slot = k;
                    parent_from_lod[r as usize] = lod;
                }
            }
        }
        let c = Collapses {
            vertex_count,
            steps,
            triangle_counts,
            appended,
            created_properties,
            companions: flat,
            companion_start,
            created_start,
            parent,
            parent_from_lod,
        };
        debug_assert_eq!(c.validate(), Ok(()));
        c
    }

    /// The vertex that replaces step `i`'s endpoints: `kept`, or in
    /// optimal-placement mode the first vertex the step creates
    /// (`vertex_count() + i` when no step has companions).
    #[must_use]
    pub fn target(&self, i: usize) -> u32 {
        if self.appended.is_empty() {
            self.steps[i].kept
        } else {
            (self.vertex_count + self.created_start[i] as usize) as u32
        }
    }

    /// The vertices step `i` creates (empty with endpoint placement): the
    /// `j`-th replaces the step's `j`-th pair (its [`Collapse`], then its
    /// companions).
    #[must_use]
    pub fn created(&self, i: usize) -> std::ops::Range<u32> {
        match self.created_start.get(i..i + 2) {
            Some(w) => {
                let n = self.vertex_count as u32;
                n + w[0]..n + w[1]
            }
            None => 0..0,
        }
    }

    /// The pairs step `i` moves: its [`Collapse`] as `(removed, kept)`,
    /// then its companions.
    fn pairs(&self, i: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        let s = self.steps[i];
        let companions = match self.companion_start.get(i..i + 2) {
            Some(w) => &self.companions[w[0] as usize..w[1] as usize],
            None => &[],
        };
        std::iter::once((s.removed, s.kept)).chain(companions.iter().copied())
    }

    /// The companion pairs of step `i` (the other sides of the contracted
    /// points at seams), as `(removed, kept)`.
    pub(crate) fn companions(&self, i: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.pairs(i).skip(1)
    }

    /// Every vertex move of step `i` as `(from, to)`: `removed → kept` and
    /// its companions, or in optimal placement both vertices of each pair
    /// onto the vertex created for it. A LoD change applies all of them at
    /// once.
    pub fn moves(&self, i: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        let first = self.is_optimal_placement().then(|| self.target(i));
        self.pairs(i).enumerate().flat_map(move |(j, (r, k))| {
            let both = match first {
                Some(c) => [Some((r, c + j as u32)), Some((k, c + j as u32))],
                None => [Some((r, k)), None],
            };
            both.into_iter().flatten()
        })
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
    /// `vertex_count() + i` is `appended()[i]`, created by the step whose
    /// [`Collapses::created`] holds it); empty otherwise.
    #[must_use]
    pub fn appended(&self) -> &[Vec3] {
        &self.appended
    }

    /// Properties of the created vertices (one entry per
    /// [`Collapses::appended`] in each stream); empty when the input has
    /// none or placement keeps endpoints.
    #[must_use]
    pub fn created_properties(&self) -> &Properties {
        &self.created_properties
    }

    /// Properties of every vertex, the input's then the created ones, with
    /// position ids (the created vertices of one step share a new point)
    /// when the input has them; `None` when the input has properties the
    /// created vertices lack (a sequence computed without them).
    ///
    /// # Panics
    /// If `mesh` is not the mesh the sequence was computed from.
    #[must_use]
    pub fn properties(&self, mesh: &Mesh) -> Option<Properties> {
        assert_eq!(
            mesh.vertex_count(),
            self.vertex_count,
            "Collapses used with another mesh"
        );
        let p = &mesh.properties;
        if self.appended.is_empty() {
            return Some(p.clone());
        }
        let c = &self.created_properties;
        if p.normals.is_some() != c.normals.is_some()
            || p.uvs.is_some() != c.uvs.is_some()
            || p.colors.is_some() != c.colors.is_some()
        {
            return None;
        }
        fn join<T: Copy>(a: &Option<Vec<T>>, b: &Option<Vec<T>>) -> Option<Vec<T>> {
            Some(a.as_ref()?.iter().chain(b.as_ref()?).copied().collect())
        }
        let position_ids = if p.position_ids.is_empty() {
            Vec::new()
        } else {
            let points = p.position_ids.iter().max().map_or(0, |&m| m + 1);
            let mut ids = p.position_ids.clone();
            for i in 0..self.max_lod() {
                ids.extend(self.created(i).map(|_| points + i as u32));
            }
            ids
        };
        Some(Properties {
            normals: join(&p.normals, &c.normals),
            uvs: join(&p.uvs, &c.uvs),
            colors: join(&p.colors, &c.colors),
            position_ids,
            texture: p.texture.clone(),
        })
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
    /// with unreferenced vertices dropped (order kept), with their
    /// properties ([`Collapses::properties`]; none when the created vertices
    /// lack the input's), for export and error measurement.
    #[must_use]
    pub fn mesh_at(&self, mesh: &Mesh, lod: usize) -> Mesh {
        let triangles = self.triangles_at(mesh, lod);
        let all: Vec<Vec3> = mesh
            .positions
            .iter()
            .chain(&self.appended)
            .copied()
            .collect();
        Mesh::level(&all, &triangles, &self.properties(mesh).unwrap_or_default())
    }

    /// Checks the invariants listed on [`Collapses`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        let total = self.vertex_count + self.appended.len();
        let optimal = self.is_optimal_placement();
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
            self.companion_start.is_empty()
                || (self.companion_start.len() == self.steps.len() + 1
                    && self.companion_start[0] == 0
                    && self.companion_start.windows(2).all(|w| w[0] <= w[1])
                    && *self.companion_start.last().unwrap() as usize == self.companions.len()),
            "companion table"
        );
        if optimal {
            // One created vertex per pair moved, in step order.
            let expected = (0..=self.steps.len())
                .map(|i| i as u32 + self.companion_start.get(i).copied().unwrap_or(0));
            ensure!(
                "Collapses",
                self.created_start.len() == self.steps.len() + 1
                    && self.created_start.iter().copied().eq(expected)
                    && self.appended.len() == self.steps.len() + self.companions.len(),
                "{} created vertices for {} steps and {} companions",
                self.appended.len(),
                self.steps.len(),
                self.companions.len()
            );
        } else {
            ensure!(
                "Collapses",
                self.created_start.is_empty(),
                "created-vertex table without optimal placement"
            );
        }
        let p = &self.created_properties;
        ensure!(
            "Collapses",
            p.position_ids.is_empty() && p.texture.is_none(),
            "created vertices' properties hold position ids or a texture"
        );
        if !p.is_empty() {
            if let Err(why) = p.validate(&self.appended) {
                ensure!("Collapses", false, "created vertices' properties: {why}");
            }
        }
        let mut removed_at = vec![u32::MAX; total];
        let mut last_error = 0.0f32;
        for (i, s) in self.steps.iter().enumerate() {
            let created = self.created(i);
            for (j, (r, k)) in self.pairs(i).enumerate() {
                let (r, k) = (r as usize, k as usize);
                let what = if j == 0 { "step" } else { "companion" };
                ensure!(
                    "Collapses",
                    r < total && k < total && r != k,
                    "step {i}: bad {what} {r} -> {k}"
                );
                ensure!(
                    "Collapses",
                    removed_at[r] == u32::MAX && removed_at[k] == u32::MAX,
                    "step {i}: {what} {r} -> {k} uses a removed vertex"
                );
                removed_at[r] = i as u32;
                if optimal {
                    let c = created.start + j as u32;
                    ensure!(
                        "Collapses",
                        r.max(k) < created.start as usize,
                        "step {i}: uses a vertex created later"
                    );
                    ensure!(
                        "Collapses",
                        self.appended[c as usize - self.vertex_count]
                            == self.appended[created.start as usize - self.vertex_count],
                        "step {i}: created vertices at different positions"
                    );
                    removed_at[k] = i as u32;
                    ensure!(
                        "Collapses",
                        self.parent[r] == c && self.parent[k] == c,
                        "step {i}: forest links of {what} {r} -> {k}"
                    );
                } else {
                    ensure!(
                        "Collapses",
                        self.parent[r] == k as u32,
                        "step {i}: forest link of {what} {r} -> {k}"
                    );
                }
            }
            ensure!(
                "Collapses",
                s.error.is_finite() && s.error >= last_error,
                "step {i}: error decreases"
            );
            last_error = s.error;
        }
        Ok(())
    }
}
