//! Vertices and triangles of a contraction sequence sorted by level, the
//! common ground of the progressive mesh, the progressive multilevel mesh
//! and the cluster tree's runtime.
//!
//! After the progressive multilevel meshes paper (section "Progressive
//! multilevel mesh"): vertices and triangles are enumerated in order of
//! decreasing level, so every LoD is a prefix of both arrays. Here every
//! contraction is its own level (the LoD numbering of `../shared/DESIGN.md`
//! needs one level per step): the vertex removed by step `i` gets index
//! `n - 1 - i`, the vertices never removed come first in input order, and
//! a triangle's level is the LoD at which it becomes degenerate (its
//! *death*), triangles sorted by decreasing death, ties in input order.
//! LoD `k` then uses vertices `0..n - k` and the triangles whose death
//! exceeds `k`.

use crate::error::ensure;
use crate::error::{Error, Result};
use crate::mesh::{is_degenerate, Mesh};
use crate::simplify::Collapses;

/// A contraction sequence's vertices and triangles in level order.
///
/// Invariants (checked by [`Levels::validate`]): `order` and `rank` are
/// inverse permutations; `parent[v] < v` for every removed vertex
/// (`v >= roots`) and `parent[v] == v` below `roots`; `death` is
/// non-increasing; `alive[k]` counts the triangles whose death exceeds `k`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Levels {
    /// Level index -> input vertex.
    pub(crate) order: Vec<u32>,
    /// Input vertex -> level index.
    pub(crate) rank: Vec<u32>,
    /// Vertices never removed (`0..roots` in level numbering).
    pub(crate) roots: usize,
    /// Level numbering: the vertex that represents `v` once it is removed
    /// (the step's kept vertex); `v` itself for roots.
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
    /// (the baselines keep endpoints, as the MTS model does), moves several
    /// vertices per step (a mesh with seams: the baselines do not carry
    /// properties yet) or was not computed on `mesh`.
    pub(crate) fn new(mesh: &Mesh, collapses: &Collapses) -> Result<Levels> {
        if collapses.is_optimal_placement() {
            return Err(Error::InvalidArgument(
                "the baselines need an endpoint-placement contraction sequence".into(),
            ));
        }
        if collapses.has_companions() {
            return Err(Error::InvalidArgument(
                "the baselines do not carry vertex properties yet: a mesh with seams".into(),
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
        let mut rank = vec![u32::MAX; n];
        for (i, s) in steps.iter().enumerate() {
            rank[s.removed as usize] = (n - 1 - i) as u32;
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
        for s in steps {
            parent[rank[s.removed as usize] as usize] = rank[s.kept as usize];
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
        for (v, &p) in self.parent.iter().enumerate() {
            if v < self.roots {
                ensure!("Levels", p as usize == v, "root {v} has a parent");
            } else {
                ensure!(
                    "Levels",
                    (p as usize) < v,
                    "vertex {v}: parent {p} is not older"
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
    for (i, s) in collapses.steps().iter().enumerate() {
        let moved = std::mem::take(&mut holders[s.removed as usize]);
        for &t in &moved {
            let t = t as usize;
            if death[t] != never {
                continue;
            }
            for v in &mut current[t] {
                if *v == s.removed {
                    *v = s.kept;
                }
            }
            if is_degenerate(current[t]) {
                death[t] = i as u32 + 1;
            } else {
                holders[s.kept as usize].push(t as u32);
            }
        }
    }
    death
}
