//! Vertices and triangles of a contraction sequence sorted by level, the
//! common ground of the progressive mesh, the progressive multilevel mesh
//! and the cluster tree's runtime.
//!
//! After the progressive multilevel meshes paper (section "Progressive
//! multilevel mesh"): vertices and triangles are enumerated in order of
//! decreasing level, so every LoD is a prefix of both arrays. Here every
//! contraction is its own level (the LoD numbering of `docs/design.md`
//! needs one level per step): the vertices step `i` moves (its removed
//! vertex, then its companions on a mesh with seams, in
//! [`Collapses::moves`] order) get the consecutive indices
//! `present[i + 1]..present[i]`, the vertices never removed come first in
//! input order, and a triangle's level is the LoD at which it becomes
//! degenerate (its *death*), triangles sorted by decreasing death, ties in
//! input order. LoD `k` then uses vertices `0..present[k]` and the
//! triangles whose death exceeds `k`. Without companions `present[k] = n -
//! k`, the vertex removed by step `i` is `n - 1 - i`, and the baselines
//! keep no table.
//!
//! A step's moves must have distinct targets (the simplifier's seam rules
//! refuse a contraction that would pair two vertices with one): then a
//! triangle dies at step `i` exactly when it holds a moved vertex and that
//! vertex's target, and a split finds the vertex a corner returns to from
//! the corner's target.

use crate::error::ensure;
use crate::error::{Error, Result};
use crate::mesh::{is_degenerate, Mesh, Properties};
use crate::simplify::Collapses;

/// A contraction sequence's vertices and triangles in level order.
///
/// Invariants (checked by [`Levels::validate`]): `order` and `rank` are
/// inverse permutations; `present` is non-increasing from `n` to `roots`;
/// the vertices of step `i` (`present[i + 1]..present[i]`) have parents
/// below `present[i + 1]`, distinct within the step, and `parent[v] == v`
/// below `roots`; `death` is non-increasing; `alive[k]` counts the
/// triangles whose death exceeds `k`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Levels {
    /// Level index -> input vertex.
    pub(crate) order: Vec<u32>,
    /// Input vertex -> level index.
    pub(crate) rank: Vec<u32>,
    /// Vertices never removed (`0..roots` in level numbering).
    pub(crate) roots: usize,
    /// Vertices present at each LoD (`max_lod + 1` entries): LoD `k` uses
    /// `0..present[k]`.
    pub(crate) present: Vec<u32>,
    /// Level numbering: the vertex that represents `v` once it is removed
    /// (the target of its move); `v` itself for roots.
    pub(crate) parent: Vec<u32>,
    /// Triangles in level order, their input corners in level numbering.
    pub(crate) triangles: Vec<[u32; 3]>,
    /// Input index of each sorted triangle.
    pub(crate) source: Vec<u32>,
    /// First LoD at which each sorted triangle is degenerate
    /// (`max_lod + 1` for one that never is).
    pub(crate) death: Vec<u32>,
    /// Triangles alive at each LoD (`max_lod + 1` entries).
    pub(crate) alive: Vec<u32>,
}

impl Levels {
    /// Sorts `mesh` by the levels of `collapses`. O(V + T log T) plus the
    /// replay (each corner moves once per removal of its representative).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when `collapses` uses optimal placement
    /// (the baselines keep endpoints, as the MTS model does), moves two
    /// vertices of one step onto the same vertex, or was not computed on
    /// `mesh`.
    pub(crate) fn new(mesh: &Mesh, collapses: &Collapses) -> Result<Levels> {
        if collapses.is_optimal_placement() {
            return Err(Error::InvalidArgument(
                "the baselines need an endpoint-placement contraction sequence".into(),
            ));
        }
        let n = mesh.vertex_count();
        if collapses.vertex_count() != n {
            return Err(Error::InvalidArgument(format!(
                "contraction sequence of {} vertices used with a mesh of {n}",
                collapses.vertex_count()
            )));
        }
        let steps = collapses.steps();
        let max_lod = steps.len();
        let mut moved = 0usize;
        let mut present = Vec::with_capacity(max_lod + 1);
        present.push(n as u32);
        for i in 0..max_lod {
            moved += collapses.moves(i).count();
            present.push((n - moved) as u32);
        }
        let mut rank = vec![u32::MAX; n];
        for i in 0..max_lod {
            for (j, (from, to)) in collapses.moves(i).enumerate() {
                if collapses.moves(i).take(j).any(|(_, t)| t == to) {
                    return Err(Error::InvalidArgument(format!(
                        "step {i} moves two vertices onto vertex {to}: the baselines need one \
                         vertex per target"
                    )));
                }
                rank[from as usize] = present[i + 1] + j as u32;
            }
        }
        let mut order = vec![0u32; n];
        let mut next = 0u32;
        for v in 0..n {
            if rank[v] == u32::MAX {
                rank[v] = next;
                next += 1;
            }
            order[rank[v] as usize] = v as u32;
        }
        let roots = next as usize;
        let mut parent: Vec<u32> = (0..n as u32).collect();
        for i in 0..max_lod {
            for (from, to) in collapses.moves(i) {
                parent[rank[from as usize] as usize] = rank[to as usize];
            }
        }
        let death = deaths(mesh, collapses);
        let mut by_death: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
        by_death.sort_by_key(|&t| std::cmp::Reverse(death[t as usize]));
        let triangles = by_death
            .iter()
            .map(|&t| mesh.triangles[t as usize].map(|v| rank[v as usize]))
            .collect();
        let death: Vec<u32> = by_death.iter().map(|&t| death[t as usize]).collect();
        let alive = (0..=max_lod as u32)
            .map(|k| death.partition_point(|&d| d > k) as u32)
            .collect();
        let levels = Levels {
            order,
            rank,
            roots,
            present,
            parent,
            triangles,
            source: by_death,
            death,
            alive,
        };
        if cfg!(debug_assertions) {
            assert_eq!(levels.validate(), Ok(()));
            assert_eq!(levels.alive, collapses.triangle_counts(), "alive table");
        }
        Ok(levels)
    }

    /// Number of contractions.
    pub(crate) fn max_lod(&self) -> usize {
        self.alive.len() - 1
    }

    /// Whether some step moves more than one vertex (then the baselines
    /// store [`Levels::present`]; otherwise it is `n - k`).
    pub(crate) fn has_companions(&self) -> bool {
        self.present.len() != self.order.len() - self.roots + 1
    }

    /// `mesh`'s properties in level order (position ids dropped: the
    /// baselines draw vertices and need no points).
    pub(crate) fn properties(&self, mesh: &Mesh) -> Properties {
        let mut p = mesh.properties.gather(&self.order);
        p.position_ids = Vec::new();
        p
    }

    /// Checks the invariants listed on [`Levels`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant.
    pub(crate) fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        for (i, &v) in self.order.iter().enumerate() {
            ensure!(
                "Levels",
                self.rank[v as usize] as usize == i,
                "order and rank"
            );
        }
        ensure!(
            "Levels",
            self.present.first() == Some(&(self.order.len() as u32))
                && self.present.last() == Some(&(self.roots as u32))
                && self.present.windows(2).all(|w| w[0] > w[1])
                && self.present.len() == self.alive.len(),
            "present table"
        );
        for v in 0..self.roots {
            ensure!(
                "Levels",
                self.parent[v] as usize == v,
                "root {v} has a parent"
            );
        }
        for (i, w) in self.present.windows(2).enumerate() {
            let step = &self.parent[w[1] as usize..w[0] as usize];
            for (j, &p) in step.iter().enumerate() {
                ensure!(
                    "Levels",
                    p < w[1] && !step[..j].contains(&p),
                    "step {i}: parent {p} of vertex {} is not older or not unique",
                    w[1] as usize + j
                );
            }
        }
        ensure!(
            "Levels",
            self.death.windows(2).all(|w| w[0] >= w[1]),
            "death order"
        );
        for (k, &a) in self.alive.iter().enumerate() {
            ensure!(
                "Levels",
                a as usize == self.death.partition_point(|&d| d as usize > k),
                "alive at {k}"
            );
        }
        Ok(())
    }
}

/// First LoD at which each input triangle is degenerate (`max_lod + 1` if
/// never): a forward replay on per-vertex corner lists.
fn deaths(mesh: &Mesh, collapses: &Collapses) -> Vec<u32> {
    let never = collapses.max_lod() as u32 + 1;
    let mut death = vec![never; mesh.triangle_count()];
    let mut current: Vec<[u32; 3]> = mesh.triangles.clone();
    let mut holders: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertex_count()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            holders[v as usize].push(t as u32);
        }
    }
    for i in 0..collapses.max_lod() {
        // All moves of the step first, then the deaths: a triangle two
        // moves touch is judged once both are applied.
        let mut touched = Vec::new();
        for (from, to) in collapses.moves(i) {
            for t in std::mem::take(&mut holders[from as usize]) {
                if death[t as usize] != never {
                    continue;
                }
                for v in &mut current[t as usize] {
                    if *v == from {
                        *v = to;
                    }
                }
                holders[to as usize].push(t);
                touched.push(t);
            }
        }
        for t in touched {
            if death[t as usize] == never && is_degenerate(current[t as usize]) {
                death[t as usize] = i as u32 + 1;
            }
        }
    }
    death
}
