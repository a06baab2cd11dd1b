//! Progressive mesh after Hoppe, "Progressive Meshes" (SIGGRAPH 1996),
//! sections 3 (the representation: a base mesh and vertex splits) and 5
//! (the compact encoding), built from the same contraction sequence as the
//! MTS model.
//!
//! The base mesh is LoD `max_lod`; split `i` undoes contraction `i`. With
//! vertices and triangles in level order (`baselines/levels.rs`) the triangle
//! list of every LoD is a prefix of one maintained `u32` list: split `i`
//! appends the faces contraction `i` removed (they occupy list positions
//! `alive(i + 1)..alive(i)`) and moves the corners that contraction `i`
//! redirected from the removed vertex `r = n - 1 - i` to the kept one back
//! to `r`; a collapse does the reverse and shortens the prefix. Hoppe's
//! record names the split vertex, its two wing neighbours and the new
//! vertex's position; ours names the kept vertex, the new faces and the
//! redirected corners explicitly, which also handles the non-manifold
//! contractions the QEM sequence allows (a decision recorded in
//! `ARCHITECTURE.md`).
//!
//! On a mesh with seams a contraction moves several vertices (the removed
//! vertex and its companions, `baselines/levels.rs`): split `i` then
//! brings back all of them, vertices `present(i + 1)..present(i)`, each
//! from its own target, and the per-LoD vertex counts are stored (without
//! companions they are `n - k` and cost nothing). The property streams ride
//! with the vertices in level order: a LoD change rewrites indices only.

use super::bits::{width_for, BitReader, BitWriter};
use super::levels::Levels;
use super::props;
use crate::error::ensure;
use crate::error::Result;
use crate::lod::{LodSource, Topology};
use crate::mesh::{is_degenerate, Mesh, Properties};
use crate::simplify::Collapses;
use glam::Vec3;
use std::ops::Range;

/// Magic bytes of the progressive mesh file.
pub const MAGIC: &[u8; 8] = b"MTSPM\0\0\x01";
/// Magic bytes of the file of a mesh with properties or companion moves
/// (a superset of [`MAGIC`]'s format; meshes without either keep the
/// first format byte for byte).
pub const MAGIC_V2: &[u8; 8] = b"MTSPM\0\0\x02";

/// A progressive mesh with its maintained triangle list.
///
/// Invariants (checked by [`ProgressiveMesh::validate`]): `alive` is
/// non-increasing with `faces.len()` at LoD 0; `present` is empty or
/// decreasing from `n`, one entry per LoD; the targets of step `i`'s
/// vertices (`present(i + 1)..present(i)`, `n - 1 - i` alone without
/// companions) are below `present(i + 1)` and distinct; each face of step
/// `i` contains one of its vertices and that vertex's target; corners of
/// step `i` lie in the first `alive(i + 1)` triangles; the property streams
/// have one value per vertex; `list[..3 * alive(lod)]` is the mesh at the
/// current LoD.
#[derive(Debug, Clone)]
pub struct ProgressiveMesh {
    /// Positions in level order (vertex `v` is present at LoD `k` when
    /// `v < present(k)`).
    pub(crate) positions: Vec<Vec3>,
    /// Normals, UVs and colours in level order (no position ids).
    pub(crate) properties: Properties,
    /// Level index -> input vertex.
    pub(crate) order: Vec<u32>,
    /// Triangles at each LoD.
    pub(crate) alive: Vec<u32>,
    /// Vertices at each LoD when some step moves several; empty when each
    /// moves one (then LoD `k` has `n - k`).
    pub(crate) present: Vec<u32>,
    /// The target of each removed vertex: entry `v - roots` for vertex `v`
    /// (without companions, entry `max_lod - 1 - i` is step `i`'s kept
    /// vertex).
    pub(crate) parent: Vec<u32>,
    /// Every triangle in level order with its vertices at the last LoD it
    /// is alive (the base mesh first, then the faces of each split).
    pub(crate) faces: Vec<[u32; 3]>,
    /// Step `i`'s corners are `corners[corner_start[i]..corner_start[i + 1]]`:
    /// list positions (`3 * triangle + corner`), ascending.
    pub(crate) corner_start: Vec<u32>,
    pub(crate) corners: Vec<u32>,
    /// The maintained triangle list (capacity for LoD 0).
    list: Vec<u32>,
    lod: Option<usize>,
    /// List state's LoD (`lod`, or 0 before the first `set_lod`).
    state: usize,
    dirty: Vec<Range<usize>>,
    /// Scratch for the positions one change writes (sized for the worst).
    written: Vec<u32>,
}

impl ProgressiveMesh {
    /// Builds the base mesh and the vertex splits of `collapses` over
    /// `mesh`, the list holding LoD 0. O(V + T log T) plus a replay of the
    /// sequence.
    ///
    /// # Errors
    /// [`crate::Error::InvalidArgument`] when `collapses` uses optimal placement,
    /// moves two vertices of a step onto one, or belongs to another mesh.
    pub fn new(mesh: &Mesh, collapses: &Collapses) -> Result<ProgressiveMesh> {
        let levels = Levels::new(mesh, collapses)?;
        Ok(ProgressiveMesh::from_levels(mesh, &levels))
    }

    pub(crate) fn from_levels(mesh: &Mesh, levels: &Levels) -> ProgressiveMesh {
        let n = levels.order.len();
        let max_lod = levels.max_lod();
        let alive = levels.alive.clone();
        let mut list: Vec<u32> = levels.triangles.iter().flatten().copied().collect();
        let mut holders: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (p, &v) in list.iter().enumerate() {
            holders[v as usize].push(p as u32);
        }
        let mut faces = vec![[0u32; 3]; levels.triangles.len()];
        let mut corner_start = Vec::with_capacity(max_lod + 1);
        let mut corners = Vec::new();
        corner_start.push(0);
        for i in 0..max_lod {
            let (after, before) = (alive[i + 1] as usize, alive[i] as usize);
            for (t, face) in faces.iter_mut().enumerate().take(before).skip(after) {
                *face = [list[3 * t], list[3 * t + 1], list[3 * t + 2]];
            }
            let first = corners.len();
            for r in levels.present[i + 1] as usize..levels.present[i] as usize {
                let k = levels.parent[r];
                for p in std::mem::take(&mut holders[r]) {
                    if (p as usize) / 3 < after {
                        list[p as usize] = k;
                        corners.push(p);
                        holders[k as usize].push(p);
                    }
                }
            }
            corners[first..].sort_unstable();
            corner_start.push(corners.len() as u32);
        }
        let base = alive[max_lod] as usize;
        for (t, face) in faces.iter_mut().enumerate().take(base) {
            *face = [list[3 * t], list[3 * t + 1], list[3 * t + 2]];
        }
        let positions = levels
            .order
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        let present = if levels.has_companions() {
            levels.present.clone()
        } else {
            Vec::new()
        };
        ProgressiveMesh::assemble(
            positions,
            levels.properties(mesh),
            levels.order.clone(),
            alive,
            present,
            levels.parent[levels.roots..].to_vec(),
            faces,
            corner_start,
            corners,
            levels.triangles.iter().flatten().copied().collect(),
        )
    }

    /// Sets up the working state around the stored records, `list` holding
    /// LoD 0.
    #[allow(clippy::too_many_arguments)]
    fn assemble(
        positions: Vec<Vec3>,
        properties: Properties,
        order: Vec<u32>,
        alive: Vec<u32>,
        present: Vec<u32>,
        parent: Vec<u32>,
        faces: Vec<[u32; 3]>,
        corner_start: Vec<u32>,
        corners: Vec<u32>,
        list: Vec<u32>,
    ) -> ProgressiveMesh {
        let written = Vec::with_capacity(corners.len());
        let pm = ProgressiveMesh {
            positions,
            properties,
            order,
            alive,
            present,
            parent,
            faces,
            corner_start,
            dirty: Vec::with_capacity(corners.len() + 1),
            corners,
            list,
            lod: None,
            state: 0,
            written,
        };
        debug_assert_eq!(pm.validate(), Ok(()));
        pm
    }

    /// Vertices of the full mesh.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The property streams in the order of [`LodSource::positions`],
    /// uploaded once for every LoD.
    #[must_use]
    pub fn properties(&self) -> &Properties {
        &self.properties
    }

    /// Corners of step `i`.
    pub(crate) fn corners_of(&self, i: usize) -> Range<usize> {
        self.corner_start[i] as usize..self.corner_start[i + 1] as usize
    }

    /// Vertices present at LoD `k` (`0..present(k)`).
    pub(crate) fn present(&self, k: usize) -> usize {
        match self.present.get(k) {
            Some(&p) => p as usize,
            None => self.positions.len() - k,
        }
    }

    /// Vertices no step removes.
    pub(crate) fn roots(&self) -> usize {
        self.positions.len() - self.parent.len()
    }

    /// The vertices step `i` removes (`n - 1 - i` alone without companions).
    pub(crate) fn step_vertices(&self, i: usize) -> Range<usize> {
        self.present(i + 1)..self.present(i)
    }

    /// The target of removed vertex `v`.
    pub(crate) fn parent_of(&self, v: usize) -> u32 {
        self.parent[v - self.roots()]
    }

    /// The vertex of step `i` whose target is `k` (the one a corner holding
    /// `k` returns to when the step is undone).
    fn moved_onto(&self, i: usize, k: u32) -> u32 {
        let vs = self.step_vertices(i);
        if vs.len() == 1 {
            return vs.start as u32;
        }
        vs.clone()
            .find(|&v| self.parent_of(v) == k)
            .expect("a corner of step i holds one of its targets") as u32
    }

    /// Moves the list from its current LoD to `target`, applying collapses
    /// (coarser) or splits (finer) one by one; records written positions.
    fn apply(&mut self, target: usize) {
        self.written.clear();
        let cur = self.state;
        if target > cur {
            for i in cur..target {
                for c in self.corners_of(i) {
                    let p = self.corners[c] as usize;
                    self.list[p] = self.parent_of(self.list[p] as usize);
                    self.written.push(p as u32);
                }
            }
        } else {
            for i in (target..cur).rev() {
                for c in self.corners_of(i) {
                    let p = self.corners[c] as usize;
                    self.list[p] = self.moved_onto(i, self.list[p]);
                    self.written.push(p as u32);
                }
                let (after, before) = (self.alive[i + 1] as usize, self.alive[i] as usize);
                for t in after..before {
                    self.list[3 * t..3 * t + 3].copy_from_slice(&self.faces[t]);
                }
            }
        }
        self.state = target;
    }

    /// Checks the invariants listed on [`ProgressiveMesh`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant.
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        let n = self.positions.len();
        let max_lod = self.max_lod();
        ensure!(
            "ProgressiveMesh",
            self.present.is_empty()
                || (self.present.len() == max_lod + 1
                    && self.present[0] as usize == n
                    && self.present.windows(2).all(|w| w[0] > w[1])),
            "present table"
        );
        ensure!(
            "ProgressiveMesh",
            self.parent.len() <= n && self.present(max_lod) == self.roots(),
            "parent table length"
        );
        ensure!(
            "ProgressiveMesh",
            self.properties.check_counts(n).is_ok() && self.properties.position_ids.is_empty(),
            "property streams"
        );
        ensure!(
            "ProgressiveMesh",
            self.alive[0] as usize == self.faces.len(),
            "alive at LoD 0"
        );
        ensure!(
            "ProgressiveMesh",
            self.alive.windows(2).all(|w| w[0] >= w[1]),
            "alive increases"
        );
        ensure!(
            "ProgressiveMesh",
            self.corner_start.len() == max_lod + 1,
            "corner offsets"
        );
        ensure!(
            "ProgressiveMesh",
            self.list.len() == 3 * self.faces.len(),
            "list length"
        );
        for i in 0..max_lod {
            let vs = self.step_vertices(i);
            for r in vs.clone() {
                let k = self.parent_of(r);
                ensure!(
                    "ProgressiveMesh",
                    (k as usize) < vs.start && (vs.start..r).all(|s| self.parent_of(s) != k),
                    "step {i}: target {k} of {r} not older or not unique"
                );
            }
            for t in self.alive[i + 1]..self.alive[i] {
                let f = self.faces[t as usize];
                ensure!(
                    "ProgressiveMesh",
                    vs.clone()
                        .any(|r| f.contains(&(r as u32)) && f.contains(&self.parent_of(r))),
                    "step {i}: face {t} {f:?}"
                );
            }
            for c in self.corners_of(i) {
                ensure!(
                    "ProgressiveMesh",
                    self.corners[c] < 3 * self.alive[i + 1],
                    "step {i}: corner out of range"
                );
            }
        }
        let base = self.alive[max_lod] as usize;
        let roots = self.roots();
        ensure!(
            "ProgressiveMesh",
            self.faces[..base]
                .iter()
                .flatten()
                .all(|&v| (v as usize) < roots),
            "base mesh uses a removed vertex"
        );
        Ok(())
    }

    /// The compact file: header, positions in level order, the base mesh,
    /// then one record per split in refinement order: the kept vertex
    /// (`width_for(r)` bits, `r` the new vertex), the update bit list (one
    /// bit per triangle holding the kept vertex, in list order: whether its
    /// corner moves to `r`, as the cluster-tree stream does), and the new
    /// faces (Elias-gamma count; per face its third vertex and 3 bits
    /// placing `r` and the kept vertex, so rotations survive). Input
    /// numbering is not stored: a loaded mesh numbers vertices in level
    /// order. O(size + T).
    ///
    /// A mesh with properties or companion moves is written in the second
    /// format ([`MAGIC_V2`]): the header adds the root count and the
    /// property flags (`baselines/props.rs`), each position is followed by
    /// its property values, and a split record starts with the Elias-gamma
    /// count of its vertices less one, gives each vertex's target and
    /// update list in turn, and each face names which of them it holds
    /// (`width_for(m)` bits for `m` vertices, none for one); the third
    /// vertex is written with the new vertex skipped, so one-vertex records
    /// cost what they cost in the first format.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let n = self.positions.len();
        let max_lod = self.max_lod();
        let flags = props::flags(&self.properties);
        let v2 = !self.present.is_empty() || flags != 0;
        let mut w = BitWriter::default();
        for &b in if v2 { MAGIC_V2 } else { MAGIC } {
            w.put(u64::from(b), 8);
        }
        w.put(n as u64, 32);
        w.put(self.faces.len() as u64, 32);
        w.put(max_lod as u64, 32);
        let roots = self.roots();
        if v2 {
            w.put(roots as u64, 32);
            w.put(flags, 8);
        }
        for (v, p) in self.positions.iter().enumerate() {
            for x in p.to_array() {
                w.f32(x);
            }
            props::write(&mut w, &self.properties, v);
        }
        let base = self.alive[max_lod] as usize;
        w.put(base as u64, 32);
        let mut holders: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (j, f) in self.faces[..base].iter().enumerate() {
            for &v in f {
                w.put(u64::from(v), width_for(roots as u64));
                holders[v as usize].push(j as u32);
            }
        }
        // The list replayed coarse to fine (each face enters at its
        // coarsest state), and which step moves each corner.
        let mut list: Vec<u32> = self.faces.iter().flatten().copied().collect();
        let mut mark = vec![u32::MAX; list.len()];
        for i in (0..max_lod).rev() {
            let vs = self.step_vertices(i);
            if v2 {
                w.gamma((vs.len() - 1) as u64);
            }
            for c in self.corners_of(i) {
                mark[self.corners[c] as usize] = i as u32;
            }
            for r in vs.clone() {
                let k = self.parent_of(r);
                w.put(u64::from(k), width_for(vs.start as u64));
                for j in std::mem::take(&mut holders[k as usize]) {
                    // The triangle holds `k` once; that corner came from
                    // `r` exactly when step `i` moved it (targets are
                    // distinct).
                    let at = 3 * j as usize;
                    let c = list[at..at + 3].iter().position(|&x| x == k).unwrap_or(0);
                    let moves = mark[at + c] == i as u32;
                    w.bit(moves);
                    holders[if moves { r } else { k as usize }].push(j);
                }
            }
            for c in self.corners_of(i) {
                let p = self.corners[c] as usize;
                list[p] = self.moved_onto(i, list[p]);
            }
            let (after, before) = (self.alive[i + 1] as usize, self.alive[i] as usize);
            w.gamma((before - after) as u64);
            for (j, f) in self.faces.iter().enumerate().take(before).skip(after) {
                let (slot, r) = vs
                    .clone()
                    .enumerate()
                    .find(|&(_, r)| f.contains(&(r as u32)) && f.contains(&self.parent_of(r)))
                    .expect("a face of step i holds a vertex of the step and its target");
                let (r, k) = (r as u32, self.parent_of(r));
                let at = f.iter().position(|&v| v == r).unwrap_or(0);
                let k_next = f[(at + 1) % 3] == k;
                let third = f[if k_next { (at + 2) % 3 } else { (at + 1) % 3 }];
                w.put(slot as u64, width_for(vs.len() as u64));
                w.put(
                    u64::from(third - u32::from(third > r)),
                    width_for((vs.end - 1) as u64),
                );
                w.put(at as u64, 2);
                w.bit(k_next);
                for v in [r, k, third] {
                    holders[v as usize].push(j as u32);
                }
            }
        }
        w.finish()
    }

    /// Parses [`ProgressiveMesh::to_bytes`]'s formats, replaying every split
    /// to rebuild its corner list; `file` names the input in errors.
    /// Allocation is bounded by what the input's length can hold.
    /// O(size + T).
    ///
    /// # Errors
    /// [`crate::Error::Parse`] with the byte offset and record for a wrong magic,
    /// truncated input, an index out of range, a degenerate face, a bad
    /// property value, two vertices of a split with one target, counts
    /// that disagree, trailing bytes.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<ProgressiveMesh> {
        let mut r = BitReader::new(bytes, file);
        let mut v2 = false;
        for (at, &b) in MAGIC.iter().enumerate() {
            let got = r.get(8, "magic")?;
            if at == 7 && got == u64::from(MAGIC_V2[7]) {
                v2 = true;
            } else if got != u64::from(b) {
                return Err(r.error("magic", "not a progressive mesh file"));
            }
        }
        let n = r.get(32, "vertex count")? as usize;
        let t = r.get(32, "triangle count")? as usize;
        let max_lod = r.get(32, "split count")? as usize;
        if max_lod >= n.max(1) {
            return Err(r.error("split count", format!("{max_lod} splits for {n} vertices")));
        }
        let (roots, flags) = if v2 {
            let roots = r.get(32, "root count")? as usize;
            if roots == 0 || roots + max_lod > n {
                return Err(r.error(
                    "root count",
                    format!("{roots} roots with {max_lod} splits of {n} vertices"),
                ));
            }
            let flags = r.get(8, "property flags")?;
            if flags & !props::KNOWN_FLAGS != 0 {
                return Err(r.error("property flags", format!("unknown bits in {flags:#x}")));
            }
            (roots, flags)
        } else {
            (n - max_lod, 0)
        };
        // Each vertex costs 96 bits and its properties', each split at
        // least 1 (its face count), each triangle 3 bits or more.
        let vertex_bits = 96 + props::bits_per_vertex(flags);
        if (n as u64) * vertex_bits + max_lod as u64 > r.remaining() || 3 * t as u64 > r.remaining()
        {
            return Err(r.error("header", "counts exceed what the file can hold"));
        }
        let mut positions = Vec::with_capacity(n);
        let mut properties = props::empty(flags);
        for _ in 0..n {
            let p = [
                r.finite_f32("position")?,
                r.finite_f32("position")?,
                r.finite_f32("position")?,
            ];
            positions.push(Vec3::from_array(p));
            props::read(&mut r, flags, "vertex properties")?.push(&mut properties);
        }
        let base = r.get(32, "base triangle count")? as usize;
        if base > t {
            return Err(r.error("base triangle count", format!("{base} exceeds {t}")));
        }
        let mut faces: Vec<[u32; 3]> = Vec::with_capacity(t);
        let mut holders: Vec<Vec<u32>> = vec![Vec::new(); n];
        for j in 0..base {
            let f = [
                r.below(roots as u64, "base triangle")? as u32,
                r.below(roots as u64, "base triangle")? as u32,
                r.below(roots as u64, "base triangle")? as u32,
            ];
            if is_degenerate(f) {
                return Err(r.error("base triangle", format!("degenerate {f:?}")));
            }
            for v in f {
                holders[v as usize].push(j as u32);
            }
            faces.push(f);
        }
        // Replay coarse to fine on the list: the moved corners of each split.
        let mut list: Vec<u32> = faces.iter().flatten().copied().collect();
        let mut parent = vec![0u32; n - roots];
        let mut present = vec![0u32; max_lod + 1];
        present[max_lod] = roots as u32;
        let mut alive = vec![0u32; max_lod + 1];
        alive[max_lod] = base as u32;
        let mut corner_lists: Vec<(usize, usize)> = vec![(0, 0); max_lod];
        let mut corners_rev: Vec<u32> = Vec::new();
        for i in (0..max_lod).rev() {
            let lo = present[i + 1] as usize;
            let m = if v2 {
                r.gamma("split vertex count")? as usize + 1
            } else {
                1
            };
            // Every later split keeps at least one vertex of its own.
            if m > n - lo - i {
                return Err(r.error(
                    "split vertex count",
                    format!("{m} vertices from {lo} of {n} with {i} splits to come"),
                ));
            }
            let start = corners_rev.len();
            for v in lo..lo + m {
                let k = r.below(lo as u64, "split kept vertex")? as u32;
                if parent[lo - roots..v - roots].contains(&k) {
                    return Err(r.error(
                        "split kept vertex",
                        format!("two vertices of split {i} with target {k}"),
                    ));
                }
                parent[v - roots] = k;
                let candidates = std::mem::take(&mut holders[k as usize]);
                for j in candidates {
                    if r.bit("split update list")? {
                        let at = 3 * j as usize;
                        let c = list[at..at + 3].iter().position(|&x| x == k).unwrap_or(0);
                        list[at + c] = v as u32;
                        corners_rev.push((at + c) as u32);
                        holders[v].push(j);
                    } else {
                        holders[k as usize].push(j);
                    }
                }
            }
            present[i] = (lo + m) as u32;
            corner_lists[i] = (start, corners_rev.len());
            let face_count = r.gamma("split face count")? as usize;
            if faces.len() + face_count > t {
                return Err(r.error("split face count", format!("more than the {t} triangles")));
            }
            for _ in 0..face_count {
                let slot = r.below(m as u64, "split face")? as usize;
                let v = (lo + slot) as u32;
                let k = parent[v as usize - roots];
                let third = r.below((lo + m - 1) as u64, "split face")? as u32;
                let third = third + u32::from(third >= v);
                let at = r.get(2, "split face")? as usize;
                let k_next = r.bit("split face")?;
                if at > 2 || third == k {
                    return Err(
                        r.error("split face", format!("bad face: third {third}, slot {at}"))
                    );
                }
                let mut f = [0u32; 3];
                f[at] = v;
                f[(at + 1) % 3] = if k_next { k } else { third };
                f[(at + 2) % 3] = if k_next { third } else { k };
                let j = faces.len() as u32;
                for x in [v, k, third] {
                    holders[x as usize].push(j);
                }
                faces.push(f);
                list.extend_from_slice(&f);
            }
            alive[i] = faces.len() as u32;
        }
        r.finish("end")?;
        if present[0] as usize != n {
            return Err(r.error(
                "end",
                format!("{} vertices split, header says {n}", present[0]),
            ));
        }
        if faces.len() != t {
            return Err(r.error(
                "end",
                format!("{} triangles decoded, header says {t}", faces.len()),
            ));
        }
        let mut corner_start = Vec::with_capacity(max_lod + 1);
        let mut corners = Vec::with_capacity(corners_rev.len());
        corner_start.push(0);
        for &(a, b) in &corner_lists {
            corners.extend_from_slice(&corners_rev[a..b]);
            corner_start.push(corners.len() as u32);
        }
        if roots + max_lod == n {
            present = Vec::new();
        }
        let order = (0..n as u32).collect();
        Ok(ProgressiveMesh::assemble(
            positions,
            properties,
            order,
            alive,
            present,
            parent,
            faces,
            corner_start,
            corners,
            list,
        ))
    }

    /// Bytes of the records (structure), without the working list: the
    /// property streams included.
    #[must_use]
    pub fn structure_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.positions.len()
            + 4 * (self.order.len()
                + self.alive.len()
                + self.present.len()
                + self.parent.len()
                + self.corner_start.len()
                + self.corners.len())
            + 12 * self.faces.len()
    }
}

impl LodSource for ProgressiveMesh {
    fn name(&self) -> &'static str {
        "pm"
    }

    fn max_lod(&self) -> usize {
        self.alive.len() - 1
    }

    fn triangle_count(&self, lod: usize) -> usize {
        self.alive[lod.min(self.alive.len() - 1)] as usize
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

    /// Applies the splits or collapses between the current LoD and `lod`
    /// one by one: O(corners and faces they touch + their sort).
    fn set_lod(&mut self, lod: usize) -> usize {
        let lod = lod.min(self.alive.len() - 1);
        let first = self.lod.is_none();
        let before = self.alive[self.state] as usize;
        self.apply(lod);
        let after = self.alive[lod] as usize;
        self.dirty.clear();
        if first {
            if after > 0 {
                self.dirty.push(0..3 * after);
            }
        } else {
            self.written.sort_unstable();
            let faces = 3 * before..3 * after.max(before);
            for &p in &self.written {
                let p = p as usize;
                if faces.contains(&p) {
                    continue;
                }
                match self.dirty.last_mut() {
                    Some(last) if p < last.end => {}
                    Some(last) if last.end == p => last.end = p + 1,
                    _ => self.dirty.push(p..p + 1),
                }
            }
            if !faces.is_empty() {
                match self.dirty.last_mut() {
                    Some(last) if last.end == faces.start => last.end = faces.end,
                    _ => self.dirty.push(faces),
                }
            }
        }
        self.lod = Some(lod);
        lod
    }

    fn lod(&self) -> Option<usize> {
        self.lod
    }

    fn indices(&self) -> &[u32] {
        &self.list[..3 * self.alive[self.state] as usize]
    }

    fn dirty_ranges(&self) -> &[Range<usize>] {
        &self.dirty
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes()
            + 4 * (self.list.len() + self.written.capacity())
            + 16 * self.dirty.capacity()
    }

    fn file_bytes(&self) -> usize {
        self.to_bytes().len()
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        self.indices()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]].map(|v| self.order[v as usize]))
            .collect()
    }
}
