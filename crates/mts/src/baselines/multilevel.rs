//! Progressive multilevel mesh after Guéziec, Taubin, Horn and Lazarus,
//! "A framework for streaming geometry in VRML" (IEEE Computer Graphics
//! and Applications, 1999), sections "Vertex representatives", "Progressive multilevel mesh", "Low memory
//! footprint" and "Geomorphs".
//!
//! Vertices and triangles are sorted by level (`baselines/levels.rs`: one level
//! per contraction, so the paper's level `l` is our LoD `l`), each removed
//! vertex stores one representative (an older vertex), and LoD `k` uses
//! vertices `0..n_k` (`n_k = n - k` without seams) and the triangles of level `>= k`, a
//! prefix of the triangle array. A LoD change rebuilds the path-compressed
//! representatives (*pc-rep*) of the vertices at or above `n_k` on a
//! temporary array (O(k)), then rewrites the triangle prefix through it
//! (O(T_k)), never visiting the LoDs in between.
//!
//! Decisions where the paper leaves room:
//! - **Indices are 16-bit when the mesh has at most 65,536 vertices**, as
//!   the paper's byte count assumes compact indices; 32-bit otherwise.
//! - **No per-level table is stored.** With one level per contraction a
//!   table of `n_l` and triangle counts would cost 4 bytes per vertex and
//!   break the paper's 1.1 bound; `n_k = n - k` is implicit, and the
//!   triangle count of a LoD is found by binary search over the sorted
//!   triangles (degenerate ones come last), following the forest as the
//!   paper's Figure 5 does. On a mesh with seams a contraction moves a
//!   point's several vertices (its level holds them all, as the paper's
//!   levels hold several vertices), so `n_k` is no longer implicit and the
//!   vertex count of each LoD is stored (4 bytes per LoD, only then).
//! - **Properties ride with the vertices**, in level order (the paper
//!   carries texture coordinates and colours through its levels the same
//!   way): a vertex is drawn with its own values at every LoD, and the
//!   byte counts include them.

use super::levels::Levels;
use crate::error::ensure;
use crate::error::Result;
use crate::lod::{LodSource, Topology};
use crate::mesh::{is_degenerate, Mesh, Properties};
use crate::simplify::Collapses;
use glam::Vec3;
use std::ops::Range;

/// Index array stored at the narrowest width the vertex count allows.
#[derive(Debug, Clone, PartialEq)]
enum Indices {
    U16(Vec<u16>),
    U32(Vec<u32>),
}

impl Indices {
    fn new(values: impl Iterator<Item = u32>, wide: bool) -> Indices {
        if wide {
            Indices::U32(values.collect())
        } else {
            Indices::U16(values.map(|v| v as u16).collect())
        }
    }

    #[inline]
    fn get(&self, i: usize) -> u32 {
        match self {
            Indices::U16(v) => u32::from(v[i]),
            Indices::U32(v) => v[i],
        }
    }

    fn bytes(&self) -> usize {
        match self {
            Indices::U16(v) => 2 * v.len(),
            Indices::U32(v) => 4 * v.len(),
        }
    }
}

/// Gap (in indices) below which two changed stretches of the output are
/// reported as one dirty range: an upload of a few unchanged indices costs
/// less than another `write_buffer` call.
const DIRTY_GAP: usize = 8;

/// A progressive multilevel mesh and its working output.
///
/// Invariants (checked by [`MultilevelMesh::validate`]): every
/// representative of vertex `v` is below `v`; triangles are non-degenerate
/// at LoD 0 and sorted so that the triangles alive at any LoD are a prefix.
#[derive(Debug, Clone)]
pub struct MultilevelMesh {
    /// Positions in level order.
    positions: Vec<Vec3>,
    /// Normals, UVs and colours in level order (no position ids).
    properties: Properties,
    /// Vertices at each LoD when some level holds several (a mesh with
    /// seams); empty when each holds one (then `n_k = n - k`).
    present: Vec<u32>,
    /// Level index -> input vertex (for [`LodSource::triangles`]; not part
    /// of the structure the paper counts).
    order: Vec<u32>,
    /// Vertices never removed (`n - max_lod`).
    roots: usize,
    /// Three indices per triangle, in level order, finest-level vertices.
    triangles: Indices,
    /// Representative of vertex `roots + j` at entry `j`.
    representatives: Indices,
    /// Temporary pc-rep array of the current LoD (entries `n_k..n` valid).
    pc: Vec<u32>,
    /// The output triangle list (capacity for LoD 0).
    out: Vec<u32>,
    alive: usize,
    lod: Option<usize>,
    dirty: Vec<Range<usize>>,
}

impl MultilevelMesh {
    /// Builds the multilevel mesh of `collapses` over `mesh`.
    /// O(V + T log T) plus a replay of the sequence.
    ///
    /// # Errors
    /// [`crate::Error::InvalidArgument`] when `collapses` uses optimal
    /// placement, moves two vertices of a step onto one, or belongs to
    /// another mesh.
    pub fn new(mesh: &Mesh, collapses: &Collapses) -> Result<MultilevelMesh> {
        let levels = Levels::new(mesh, collapses)?;
        let n = levels.order.len();
        let wide = n > 1 << 16;
        let triangles = Indices::new(levels.triangles.iter().flatten().copied(), wide);
        let representatives = Indices::new(levels.parent[levels.roots..].iter().copied(), wide);
        let t = levels.triangles.len();
        let m = MultilevelMesh {
            positions: levels
                .order
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect(),
            properties: levels.properties(mesh),
            present: if levels.has_companions() {
                levels.present.clone()
            } else {
                Vec::new()
            },
            order: levels.order,
            roots: levels.roots,
            triangles,
            representatives,
            pc: (0..n as u32).collect(),
            out: vec![0; 3 * t],
            alive: 0,
            lod: None,
            dirty: Vec::with_capacity(3 * t / (DIRTY_GAP + 1) + 2),
        };
        debug_assert_eq!(m.validate(), Ok(()));
        Ok(m)
    }

    /// Number of triangles.
    fn total_triangles(&self) -> usize {
        self.out.len() / 3
    }

    /// The property streams in the order of [`LodSource::positions`],
    /// uploaded once for every LoD.
    #[must_use]
    pub fn properties(&self) -> &Properties {
        &self.properties
    }

    /// `n_k`: the vertices of LoD `lod` are `0..n_k`.
    fn present(&self, lod: usize) -> usize {
        match self.present.get(lod) {
            Some(&p) => p as usize,
            None => self.positions.len() - lod,
        }
    }

    /// Representative of `v` among the vertices below `n_k`, following the
    /// forest (no path compression). O(depth).
    fn root_below(&self, mut v: u32, n_k: u32) -> u32 {
        while v >= n_k {
            v = self.representatives.get(v as usize - self.roots);
        }
        v
    }

    /// Fills `self.pc[n_k..n]` with the path-compressed representatives of
    /// LoD `lod`: each entry reads its representative's final entry, which
    /// is older and therefore already resolved. O(lod).
    fn compress(&mut self, lod: usize) {
        let n = self.positions.len();
        let n_k = self.present(lod);
        for v in n_k..n {
            let r = self.representatives.get(v - self.roots);
            self.pc[v] = if (r as usize) < n_k {
                r
            } else {
                self.pc[r as usize]
            };
        }
    }

    #[inline]
    fn pc_of(&self, v: u32, n_k: usize) -> u32 {
        if (v as usize) < n_k {
            v
        } else {
            self.pc[v as usize]
        }
    }

    /// Triangle `t` read through the current pc-rep.
    #[inline]
    fn mapped(&self, t: usize, n_k: usize) -> [u32; 3] {
        [0, 1, 2].map(|c| self.pc_of(self.triangles.get(3 * t + c), n_k))
    }

    /// Positions of a geomorph between LoD `fine` and the coarser LoD
    /// `coarse`, for `t` in 0..=1 (0 draws LoD `coarse`'s shape, 1 LoD
    /// `fine`'s), written to `out` (cleared first): one position per vertex
    /// of LoD `fine` (`n - fine` entries), to draw with LoD `fine`'s
    /// triangles. Each vertex moves linearly from its representative at
    /// `coarse` to its own position (the paper's "Geomorphs"). O(V) by
    /// following the forest; allocates only when `out` is too small.
    ///
    /// # Errors
    /// [`crate::Error::InvalidArgument`] when `fine > coarse`, `coarse`
    /// exceeds `max_lod` or `t` is outside 0..=1.
    pub fn geomorph(&self, fine: usize, coarse: usize, t: f32, out: &mut Vec<Vec3>) -> Result<()> {
        if fine > coarse || coarse > self.max_lod() || !(0.0..=1.0).contains(&t) {
            return Err(crate::Error::InvalidArgument(format!(
                "geomorph from LoD {fine} to {coarse} at t = {t} (LoDs 0..={}, fine <= coarse, t in 0..=1)",
                self.max_lod()
            )));
        }
        let n_coarse = self.present(coarse) as u32;
        out.clear();
        out.extend((0..self.present(fine) as u32).map(|v| {
            let from = self.positions[self.root_below(v, n_coarse) as usize];
            from.lerp(self.positions[v as usize], t)
        }));
        Ok(())
    }

    /// Bytes of the multilevel mesh as the paper counts them: positions
    /// (12 per vertex) and their property values, triangles and
    /// representatives at the stored index width, and the per-LoD vertex
    /// counts when stored. Excludes the temporary pc-rep, the output
    /// buffer and the map back to input numbering.
    #[must_use]
    pub fn structure_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.positions.len()
            + self.triangles.bytes()
            + self.representatives.bytes()
            + 4 * self.present.len()
    }

    /// The raw mesh the paper compares with: 12 bytes per vertex and its
    /// property values, and three indices per triangle at the same width
    /// as [`Self::structure_bytes`] uses (2 bytes up to 65,536 vertices).
    #[must_use]
    pub fn raw_bytes(&self) -> usize {
        let width = match self.triangles {
            Indices::U16(_) => 2,
            Indices::U32(_) => 4,
        };
        (12 + self.properties.bytes_per_vertex()) * self.positions.len()
            + 3 * width * self.total_triangles()
    }

    /// Checks the invariants listed on [`MultilevelMesh`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        let n = self.positions.len();
        for j in 0..n - self.roots {
            let v = self.roots + j;
            ensure!(
                "MultilevelMesh",
                (self.representatives.get(j) as usize) < v,
                "vertex {v}: representative not older"
            );
        }
        ensure!(
            "MultilevelMesh",
            self.present.is_empty()
                || (self.present[0] as usize == n
                    && *self.present.last().unwrap() as usize == self.roots
                    && self.present.windows(2).all(|w| w[0] > w[1])),
            "present table"
        );
        ensure!(
            "MultilevelMesh",
            self.properties.check_counts(n).is_ok(),
            "property streams"
        );
        for k in [0, self.max_lod() / 2, self.max_lod()] {
            let n_k = self.present(k) as u32;
            let alive = self.count_at(k);
            for t in 0..self.total_triangles() {
                let tri = [0, 1, 2].map(|c| self.root_below(self.triangles.get(3 * t + c), n_k));
                ensure!(
                    "MultilevelMesh",
                    is_degenerate(tri) == (t >= alive),
                    "LoD {k}: triangle {t} out of level order"
                );
            }
        }
        Ok(())
    }

    /// Triangles alive at `lod` by binary search with the forest. O(log T
    /// × depth).
    fn count_at(&self, lod: usize) -> usize {
        let n_k = self.present(lod) as u32;
        let (mut lo, mut hi) = (0, self.total_triangles());
        while lo < hi {
            let mid = (lo + hi) / 2;
            let tri = [0, 1, 2].map(|c| self.root_below(self.triangles.get(3 * mid + c), n_k));
            if is_degenerate(tri) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    }
}

impl LodSource for MultilevelMesh {
    fn name(&self) -> &'static str {
        "multilevel"
    }

    fn max_lod(&self) -> usize {
        if self.present.is_empty() {
            self.positions.len() - self.roots
        } else {
            self.present.len() - 1
        }
    }

    /// O(log T × forest depth): the paper's walk toward the roots.
    fn triangle_count(&self, lod: usize) -> usize {
        self.count_at(lod.min(self.max_lod()))
    }

    fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    fn properties(&self) -> &Properties {
        &self.properties
    }

    fn topology(&self) -> Topology {
        Topology::TriangleList
    }

    /// Rebuilds the pc-rep of `lod` and rewrites the triangle prefix,
    /// writing only indices that change: O(lod + T_lod), allocation-free.
    fn set_lod(&mut self, lod: usize) -> usize {
        let lod = lod.min(self.max_lod());
        let n_k = self.present(lod);
        self.compress(lod);
        let (mut lo, mut hi) = (0, self.total_triangles());
        while lo < hi {
            let mid = (lo + hi) / 2;
            if is_degenerate(self.mapped(mid, n_k)) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        let alive = lo;
        self.dirty.clear();
        let first = self.lod.is_none();
        for t in 0..alive {
            let tri = self.mapped(t, n_k);
            for (c, &v) in tri.iter().enumerate() {
                let i = 3 * t + c;
                if first || self.out[i] != v || t >= self.alive {
                    self.out[i] = v;
                    match self.dirty.last_mut() {
                        Some(last) if i <= last.end + DIRTY_GAP => last.end = i + 1,
                        _ => self.dirty.push(i..i + 1),
                    }
                }
            }
        }
        self.alive = alive;
        self.lod = Some(lod);
        lod
    }

    fn lod(&self) -> Option<usize> {
        self.lod
    }

    fn indices(&self) -> &[u32] {
        &self.out[..3 * self.alive]
    }

    fn dirty_ranges(&self) -> &[Range<usize>] {
        &self.dirty
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes()
            + 4 * (self.order.len() + self.pc.len() + self.out.len())
            + 16 * self.dirty.capacity()
    }

    /// The paper's file (Figure 6) holds the same arrays: the structure's
    /// bytes plus a count per level, which with one level per contraction
    /// is implicit (one vertex each) or, with seams, the stored table; so
    /// the structure's size.
    fn file_bytes(&self) -> usize {
        self.structure_bytes()
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        self.indices()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]].map(|v| self.order[v as usize]))
            .collect()
    }
}
