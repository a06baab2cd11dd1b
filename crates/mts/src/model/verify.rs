//! Checks a model against the invariant every test leans on
//! (`docs/design.md`, "The invariant"): at each LoD the oriented
//! triangles drawn from the extracted strips are exactly those of the naive
//! replay of the contraction sequence, and coherent extraction is
//! byte-identical to extraction from scratch. On a model with seams
//! (position ids) it also checks that no contraction tears one: once a
//! point is contracted away, none of its vertices is drawn (every one
//! moved with it). Drawn vertices are input vertices, so the drawn
//! triangles' properties are the oracle's whenever their indices are. The
//! LoD → triangle table is checked against the replay's count too.
//!
//! Checking every LoD of a 70K-triangle model naively would cost
//! O(LoDs × triangles) for the oracle alone. Both sides are kept
//! incrementally instead:
//! - the oracle replays the contractions between two checked LoDs on a
//!   triangle list with per-vertex incidence lists (a contraction visits
//!   only the triangles around the vertices it moves);
//! - the strips' triangles are updated from the coherent extractor's dirty
//!   ranges (the runs they held before, kept in a shadow copy, go out; the
//!   runs they hold now come in);
//! - a map from oriented triangle (canonical rotation) to the difference
//!   "drawn − oracle" counts how many entries are non-zero; the LoD passes
//!   when none is.
//!
//! The from-scratch extractor walks its whole band at each checked LoD, and
//! the two buffers are compared where either one changed (they are equal
//! before, so equal everywhere after). Cost per checked LoD: O(changes +
//! the current band's size).

use super::{Extractor, MtsModel};
use crate::mesh::{is_degenerate, Mesh};
use crate::strip::canonical_triangle;
use std::collections::HashMap;
use std::ops::Range;

/// What [`verify`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VerifyReport {
    /// LoDs checked.
    pub lods_checked: usize,
    /// LoDs where the strips' triangles differ from the oracle's, or the
    /// coherent buffer from the from-scratch buffer.
    pub mismatches: usize,
    /// The first failing LoD and what failed there.
    pub first_mismatch: Option<(usize, String)>,
}

/// The LoDs to check: every one, or `n` spread evenly from 0 to `max_lod`
/// (both ends included).
#[must_use]
pub fn spread_lods(max_lod: usize, n: Option<usize>) -> Vec<usize> {
    match n {
        None => (0..=max_lod).collect(),
        Some(0) => Vec::new(),
        Some(1) => vec![0],
        Some(n) => {
            let mut lods: Vec<usize> = (0..n)
                .map(|i| ((i as f64 / (n - 1) as f64) * max_lod as f64).round() as usize)
                .collect();
            lods.dedup();
            lods
        }
    }
}

/// Checks `model` at `lods` (ascending; values past `max_lod` are clamped)
/// against the replay of its contraction sequence on `mesh`, and coherent
/// against from-scratch extraction; see the module documentation.
///
/// `mesh` must be the mesh the model was built from (its vertices; its
/// triangles in any order, e.g. [`MtsModel::mesh`]).
///
/// # Panics
/// If `mesh` has another vertex count than the model's contraction
/// sequence, or `lods` is not ascending.
#[must_use]
pub fn verify(model: &MtsModel, mesh: &Mesh, lods: &[usize]) -> VerifyReport {
    assert!(
        lods.windows(2).all(|w| w[0] <= w[1]),
        "LoDs to verify must be ascending"
    );
    let mut oracle = Oracle::new(model, mesh);
    let mut coherent = Extractor::new(model);
    let mut scratch = Extractor::new(model);
    let mut shadow = coherent.buffer().to_vec();
    let mut tally = Tally::default();
    for t in &oracle.current {
        if !is_degenerate(*t) {
            tally.add(*t, -1);
        }
    }
    let mut report = VerifyReport {
        lods_checked: 0,
        mismatches: 0,
        first_mismatch: None,
    };
    let mut decoded = Vec::new();
    let mut runs: Vec<Range<usize>> = Vec::new();
    for &lod in lods {
        let lod = lod.min(model.max_lod());
        oracle.advance(lod, &mut tally);
        coherent.set_lod(lod);
        // A dirty range may start inside a run (a strip re-walked from one
        // of its segments): widen each to whole runs, which the two
        // buffers share outside the ranges, before decoding.
        runs.clear();
        for r in coherent.dirty_ranges() {
            let r = whole_runs(coherent.buffer(), r.clone());
            match runs.last_mut() {
                Some(last) if last.end >= r.start => last.end = last.end.max(r.end),
                _ => runs.push(r),
            }
        }
        for r in &runs {
            decode_range(&shadow, r.clone(), &mut decoded);
            for t in decoded.drain(..) {
                tally.add(t, -1);
            }
            decode_range(coherent.buffer(), r.clone(), &mut decoded);
            for t in decoded.drain(..) {
                tally.add(t, 1);
            }
            shadow[r.clone()].copy_from_slice(&coherent.buffer()[r.clone()]);
        }
        scratch.set_lod_from_scratch(lod);
        let mut problem = None;
        if let Some((step, w)) = oracle.torn {
            problem = Some(format!(
                "a seam is torn: contraction {step} moved its point without vertex {w}, still drawn"
            ));
        } else if oracle.alive != model.triangle_count(lod) {
            problem = Some(format!(
                "the LoD table says {} triangles, the replay has {}",
                model.triangle_count(lod),
                oracle.alive
            ));
        } else if tally.nonzero != 0 {
            problem = Some(format!(
                "the strips draw {} oriented triangles in other numbers than the replay",
                tally.nonzero
            ));
        } else if let Some(i) = first_difference(&coherent, &scratch) {
            problem = Some(format!(
                "coherent and from-scratch buffers differ at index {i}"
            ));
        } else if coherent.overflows() != 0 {
            problem = Some(format!("{} strip walks overflowed", coherent.overflows()));
        }
        report.lods_checked += 1;
        if let Some(p) = problem {
            report.mismatches += 1;
            if report.first_mismatch.is_none() {
                report.first_mismatch = Some((lod, p));
            }
        }
    }
    report
}

/// First index where the two buffers differ, looked for where either
/// extractor wrote last.
fn first_difference(a: &Extractor<'_>, b: &Extractor<'_>) -> Option<usize> {
    let (x, y) = (a.buffer(), b.buffer());
    a.dirty_ranges()
        .iter()
        .chain(b.dirty_ranges())
        .filter_map(|r| {
            r.clone()
                .zip(&x[r.clone()])
                .zip(&y[r.clone()])
                .find(|((_, p), q)| p != q)
                .map(|((i, _), _)| i)
        })
        .min()
}

/// The oriented triangles of `buffer[range]`, runs split at restarts.
/// `range` widened to the runs it touches: back to just after a restart
/// (or the buffer's start), on to a restart (or the buffer's end).
fn whole_runs(buffer: &[u32], range: Range<usize>) -> Range<usize> {
    use crate::strip::encode::RESTART_U32;
    let mut lo = range.start;
    while lo > 0 && buffer[lo - 1] != RESTART_U32 {
        lo -= 1;
    }
    let mut hi = range.end;
    while hi < buffer.len() && buffer[hi] != RESTART_U32 {
        hi += 1;
    }
    lo..hi
}

fn decode_range(buffer: &[u32], range: Range<usize>, out: &mut Vec<[u32; 3]>) {
    crate::encoding::decode_restart_buffer(&buffer[range], out);
}

/// Per oriented triangle (canonical rotation), drawn minus expected.
#[derive(Default)]
struct Tally {
    count: HashMap<[u32; 3], i64>,
    nonzero: usize,
}

impl Tally {
    fn add(&mut self, t: [u32; 3], delta: i64) {
        let c = self.count.entry(canonical_triangle(t)).or_insert(0);
        let was = *c != 0;
        *c += delta;
        match (was, *c != 0) {
            (false, true) => self.nonzero += 1,
            (true, false) => self.nonzero -= 1,
            _ => {}
        }
    }
}

/// The naive replay kept incrementally: every input triangle with its
/// current vertices, and per vertex the triangles that name it.
struct Oracle<'m> {
    model: &'m MtsModel,
    lod: usize,
    current: Vec<[u32; 3]>,
    /// Triangles of `current` that are not degenerate.
    alive: usize,
    incident: Vec<Vec<u32>>,
    /// On a model with seams: the vertices of each point (CSR over the
    /// position ids), to see that a contraction leaves none of the removed
    /// point's vertices drawn.
    point_start: Vec<u32>,
    point_vertices: Vec<u32>,
    /// The first step that left a vertex of its removed point drawn (a
    /// torn seam: that point's other vertices moved away), and the vertex.
    torn: Option<(usize, u32)>,
}

impl<'m> Oracle<'m> {
    fn new(model: &'m MtsModel, mesh: &Mesh) -> Oracle<'m> {
        let collapses = model.collapses();
        assert_eq!(
            mesh.vertex_count(),
            collapses.vertex_count(),
            "mesh of another model"
        );
        let vertices = collapses.vertex_count() + collapses.appended().len();
        let mut incident = vec![Vec::new(); vertices];
        for (i, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                incident[v as usize].push(i as u32);
            }
        }
        let (point_start, point_vertices) = points(&model.properties().position_ids);
        Oracle {
            model,
            lod: 0,
            current: mesh.triangles.clone(),
            alive: mesh
                .triangles
                .iter()
                .filter(|&&t| !is_degenerate(t))
                .count(),
            incident,
            point_start,
            point_vertices,
            torn: None,
        }
    }

    /// Whether a vertex of the point that step `step` removed is still
    /// drawn after the step's moves: the seam was torn.
    fn check_seam(&mut self, step: usize) {
        let removed = self.model.collapses().steps()[step].removed as usize;
        let Some(&point) = self.model.properties().position_ids.get(removed) else {
            return;
        };
        let p = point as usize;
        let vertices =
            &self.point_vertices[self.point_start[p] as usize..self.point_start[p + 1] as usize];
        for &w in vertices {
            let drawn = self.incident[w as usize].iter().any(|&ti| {
                let t = self.current[ti as usize];
                !is_degenerate(t) && t.contains(&w)
            });
            if drawn && self.torn.is_none() {
                self.torn = Some((step, w));
            }
        }
    }

    /// Applies contractions up to `lod`, moving each changed triangle's
    /// contribution in `tally`.
    fn advance(&mut self, lod: usize, tally: &mut Tally) {
        let collapses = self.model.collapses();
        while self.lod < lod {
            for (from, to) in collapses.moves(self.lod) {
                self.move_vertex(from, to, tally);
            }
            if !self.point_vertices.is_empty() {
                self.check_seam(self.lod);
            }
            self.lod += 1;
        }
    }

    fn move_vertex(&mut self, from: u32, to: u32, tally: &mut Tally) {
        if from == to {
            return;
        }
        let list = std::mem::take(&mut self.incident[from as usize]);
        let mut keep = Vec::with_capacity(list.len());
        for ti in list {
            let t = &mut self.current[ti as usize];
            if is_degenerate(*t) || !t.contains(&from) {
                continue;
            }
            tally.add(*t, 1);
            for v in t.iter_mut() {
                if *v == from {
                    *v = to;
                }
            }
            if is_degenerate(*t) {
                self.alive -= 1;
            } else {
                tally.add(*t, -1);
                keep.push(ti);
            }
        }
        self.incident[to as usize].extend(keep);
    }
}

/// The vertices of each point of `ids` (position ids; empty for a mesh
/// without seams) as offsets and a list. O(vertices).
fn points(ids: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let Some(&most) = ids.iter().max() else {
        return (Vec::new(), Vec::new());
    };
    let mut start = vec![0u32; most as usize + 2];
    for &p in ids {
        start[p as usize + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = start.clone();
    let mut vertices = vec![0u32; ids.len()];
    for (v, &p) in ids.iter().enumerate() {
        vertices[fill[p as usize] as usize] = v as u32;
        fill[p as usize] += 1;
    }
    (start, vertices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::Generated;
    use crate::model::{build_from_mesh, PipelineOptions};

    fn torus_model() -> (MtsModel, Mesh) {
        let mesh: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
        let (model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
        (model, mesh)
    }

    #[test]
    fn a_sound_model_passes_at_every_lod() {
        let (model, mesh) = torus_model();
        let lods = spread_lods(model.max_lod(), None);
        let report = verify(&model, &mesh, &lods);
        assert_eq!(report.lods_checked, model.max_lod() + 1);
        assert_eq!(report.mismatches, 0, "{:?}", report.first_mismatch);
    }

    #[test]
    fn a_wrong_vertex_in_a_graph_is_caught() {
        let (mut model, mesh) = torus_model();
        // Node 5 names another vertex: the strips draw other triangles
        // from LoD 0 until that node leaves the strip.
        let v = model.rec_vertex.get(5);
        model
            .rec_vertex
            .set(5, (v + 1) % mesh.vertex_count() as u32);
        let report = verify(&model, &mesh, &spread_lods(model.max_lod(), Some(50)));
        assert_eq!(report.lods_checked, 50);
        assert!(report.mismatches >= 1);
        let (lod, what) = report.first_mismatch.unwrap();
        assert_eq!(lod, 0);
        assert!(what.contains("oriented triangles"), "{what}");
    }

    #[test]
    fn a_flipped_oracle_triangle_is_caught() {
        let (model, mut mesh) = torus_model();
        let t = &mut mesh.triangles[0];
        t.swap(0, 1);
        let report = verify(&model, &mesh, &[0]);
        assert_eq!(report.mismatches, 1);
    }

    #[test]
    fn a_torn_seam_is_caught() {
        let mesh = "torus:2k"
            .parse::<Generated>()
            .unwrap()
            .build_with_properties();
        let (mut model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
        let report = verify(&model, &model.mesh(), &spread_lods(model.max_lod(), None));
        assert_eq!(report.mismatches, 0, "{:?}", report.first_mismatch);
        // Drop the first companion move: that step moves its point but
        // leaves one of its vertices behind.
        let c = &mut model.recipe.collapses;
        let step = c
            .companion_start
            .windows(2)
            .position(|w| w[1] > w[0])
            .unwrap();
        let first = c.companion_start[step] as usize;
        c.companions.remove(first);
        for s in &mut c.companion_start[step + 1..] {
            *s -= 1;
        }
        let report = verify(&model, &model.mesh(), &spread_lods(model.max_lod(), None));
        assert!(report.mismatches >= 1);
        let (lod, what) = report.first_mismatch.unwrap();
        assert_eq!(lod, step + 1, "{what}");
        assert!(
            what.contains(&format!("seam is torn: contraction {step} ")),
            "{what}"
        );
    }

    #[test]
    fn points_list_each_point_s_vertices() {
        assert_eq!(points(&[]), (vec![], vec![]));
        assert_eq!(points(&[1, 0, 1, 2]), (vec![0, 1, 3, 4], vec![1, 0, 2, 3]));
    }

    #[test]
    fn spread_lods_include_both_ends_once() {
        assert_eq!(spread_lods(10, Some(3)), vec![0, 5, 10]);
        assert_eq!(spread_lods(2, Some(5)), vec![0, 1, 2]);
        assert_eq!(spread_lods(3, None), vec![0, 1, 2, 3]);
        assert_eq!(spread_lods(7, Some(1)), vec![0]);
    }
}
