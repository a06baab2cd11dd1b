//! The MTS model: one labelled graph per triangle strip (section 3.1 of the
//! MTS paper, "Data structure"), stored as flat arrays.
//!
//! Strip `s` owns the nodes `strip_nodes[s]..strip_nodes[s + 1]` and the
//! beginnings `strip_begins[s]..strip_begins[s + 1]`. A node (the paper's
//! `ColumnNode`) names one vertex; its arcs (`RowNode`s) are
//! `node_arcs[n]..node_arcs[n + 1]`, each with a target and a label `res`:
//! the arc may be walked at every LoD up to and including `res`. A node's
//! arcs are valid over consecutive, disjoint LoD intervals in the order
//! they are stored, so at LoD `L` the valid arc is the first whose label is
//! at least `L` (the paper's Fig. 5 prints the comparison the wrong way
//! round; its text, "arcs having a label greater or equal to the requested
//! LoD", is what is meant).
//!
//! The paper's special nodes become arc targets: an arc to [`END`] ends the
//! strip (−3); an arc whose target carries [`RESTART`] ends the current run
//! and starts the next one at the target (−2, and −1 when the target names
//! the same vertex: a node per occurrence needs no separate marker for it).
//!
//! Decisions where the paper leaves room (see `build.rs` for the
//! construction and its proofs):
//! - **A node is one occurrence of a vertex in the strip**, not the vertex:
//!   a vertex that a strip visits twice (a swap does that) gets two nodes,
//!   so every node has at most one valid arc at any LoD and the walk never
//!   has to choose between two arcs with the same label.
//! - **Arcs go forward**: nodes are numbered in strip order, so every
//!   target is a later node. The walk therefore ends after at most as many
//!   steps as the strip has nodes, even on a corrupt model.

mod build;
mod extract;
pub mod format;
mod pipeline;
pub mod sequence;
mod verify;

pub use build::{
    build, build_with_progress, can_build, BuildOptions, DEFAULT_BAND_SLACK, MIN_BAND_DROP,
    MIN_BAND_SLACK,
};
pub use extract::{Extractor, Update};
pub use pipeline::{build_from_mesh, PipelineOptions, PipelineTimings};
pub use verify::{spread_lods, verify, VerifyReport};

use glam::Vec3;

/// Arc target meaning "the strip ends here" (the paper's −3).
pub const END: u32 = u32::MAX;
/// Flag on an arc target: end the current run before the target, which
/// starts the next one (the paper's −2, or −1 when the target repeats the
/// vertex the run ended on).
pub const RESTART: u32 = 1 << 31;
/// Mask of the node index in an arc target.
pub const NODE_MASK: u32 = RESTART - 1;

/// A multiresolution triangle strip model: every strip's labelled graph, the
/// vertices they index and the LoD → triangle count table.
///
/// Invariants (checked by [`MtsModel::validate`], which the loader runs):
/// offsets are non-decreasing and in range; every node's vertex is below the
/// vertex count; every arc target is [`END`] or a later node of the same
/// strip (optionally with [`RESTART`]); labels are at most `max_lod` and
/// strictly increasing along a node's arcs and along a strip's beginnings,
/// and a strip's last beginning has label `max_lod`. The LoD → triangle
/// table is the contraction sequence's.
#[derive(Debug, Clone, PartialEq)]
pub struct MtsModel {
    pub(crate) positions: Vec<Vec3>,
    /// The input vertices' properties (normals, UVs, colours, texture,
    /// position ids); empty for a mesh of positions only. A LoD draws
    /// input vertices (endpoint placement), so they serve every LoD.
    pub(crate) properties: crate::mesh::Properties,
    pub(crate) strip_nodes: Vec<u32>,
    pub(crate) strip_begins: Vec<u32>,
    /// Per beginning: the first node (global index) or [`END`] for "the
    /// strip draws nothing at these LoDs".
    pub(crate) begin_node: Vec<u32>,
    pub(crate) begin_res: Vec<u32>,
    pub(crate) node_vertex: Vec<u32>,
    pub(crate) node_arcs: Vec<u32>,
    /// Per arc: target node (global index) with optional [`RESTART`], or
    /// [`END`].
    pub(crate) arc_target: Vec<u32>,
    pub(crate) arc_res: Vec<u32>,
    /// First LoD of each band, and each band's strips
    /// (`band_strips[b]..band_strips[b + 1]`).
    pub(crate) band_lod: Vec<u32>,
    pub(crate) band_strips: Vec<u32>,
    /// What the model was built from; the `.mts` file stores this and the
    /// loader builds the graphs again (see [`format`]).
    pub(crate) recipe: Recipe,
}

/// The inputs of [`build`]: enough to build the same model again.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Recipe {
    pub(crate) strips: crate::strip::Strips,
    pub(crate) collapses: crate::simplify::Collapses,
    pub(crate) options: BuildOptions,
}

/// Sizes of a model, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelStats {
    /// Strips (each one labelled graph).
    pub strips: usize,
    /// Graph nodes (vertex occurrences).
    pub nodes: usize,
    /// Graph arcs.
    pub arcs: usize,
    /// Entries of the strip-beginning lists.
    pub begins: usize,
    /// Bytes of the in-memory arrays.
    pub memory_bytes: usize,
}

impl MtsModel {
    /// Number of strips.
    #[must_use]
    pub fn strip_count(&self) -> usize {
        self.strip_nodes.len().saturating_sub(1)
    }

    /// Number of contractions; LoDs run from 0 to `max_lod()`.
    #[must_use]
    pub fn max_lod(&self) -> usize {
        self.recipe.collapses.max_lod()
    }

    /// The vertices the strips index (input vertices, then those created
    /// by optimal placement).
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Triangles drawn at `lod` (clamped to `max_lod()`).
    #[must_use]
    pub fn triangle_count(&self, lod: usize) -> usize {
        self.recipe
            .collapses
            .triangle_count(lod.min(self.max_lod()))
    }

    /// The monotone LoD → triangle count table.
    #[must_use]
    pub fn triangle_counts(&self) -> &[u32] {
        self.recipe.collapses.triangle_counts()
    }

    /// The finest LoD with at most `budget` triangles (see
    /// [`crate::Collapses::lod_for_triangles`]).
    #[must_use]
    pub fn lod_for_triangles(&self, budget: usize) -> usize {
        self.recipe.collapses.lod_for_triangles(budget)
    }

    /// The LoD for `ratio` of the full triangle count (see
    /// [`crate::Collapses::lod_for_ratio`]).
    #[must_use]
    pub fn lod_for_ratio(&self, ratio: f64) -> usize {
        self.recipe.collapses.lod_for_ratio(ratio)
    }

    /// The contraction sequence the model was built from.
    #[must_use]
    pub fn collapses(&self) -> &crate::simplify::Collapses {
        &self.recipe.collapses
    }

    /// The strips of LoD 0 the model was built from.
    #[must_use]
    pub fn base_strips(&self) -> &crate::strip::Strips {
        &self.recipe.strips
    }

    /// The options the model was built with.
    #[must_use]
    pub fn build_options(&self) -> &BuildOptions {
        &self.recipe.options
    }

    /// The full-resolution mesh: the input vertices and the triangles of
    /// the LoD-0 strips (in strip order).
    #[must_use]
    pub fn mesh(&self) -> crate::Mesh {
        crate::Mesh {
            positions: self.positions[..self.recipe.collapses.vertex_count()].to_vec(),
            triangles: self.recipe.strips.triangles(),
            properties: self.properties.clone(),
        }
    }

    /// The input vertices' properties, uploaded once for every LoD.
    #[must_use]
    pub fn properties(&self) -> &crate::mesh::Properties {
        &self.properties
    }

    /// Number of bands (strip sets stripified afresh at a LoD).
    #[must_use]
    pub fn band_count(&self) -> usize {
        self.band_lod.len()
    }

    /// The band that draws `lod`.
    #[must_use]
    pub fn band_of(&self, lod: usize) -> usize {
        self.band_lod
            .partition_point(|&b| b as usize <= lod)
            .saturating_sub(1)
    }

    /// First LoD of band `b`.
    #[must_use]
    pub fn band_first_lod(&self, b: usize) -> usize {
        self.band_lod[b] as usize
    }

    /// The strips of band `b`.
    #[must_use]
    pub fn band_strips(&self, b: usize) -> std::ops::Range<usize> {
        self.band_strips[b] as usize..self.band_strips[b + 1] as usize
    }

    /// Node, arc and byte counts.
    #[must_use]
    pub fn stats(&self) -> ModelStats {
        let words = self.strip_nodes.len()
            + self.strip_begins.len()
            + self.begin_node.len()
            + self.begin_res.len()
            + self.node_vertex.len()
            + self.node_arcs.len()
            + self.arc_target.len()
            + self.arc_res.len()
            + self.band_lod.len()
            + self.band_strips.len();
        ModelStats {
            strips: self.strip_count(),
            nodes: self.node_vertex.len(),
            arcs: self.arc_target.len(),
            begins: self.begin_node.len(),
            memory_bytes: 4 * words
                + 12 * self.positions.len()
                + self.properties.bytes_per_vertex() * self.recipe.collapses.vertex_count()
                + 4 * self.properties.position_ids.len(),
        }
    }

    /// Bytes of the raw input mesh with 32-bit indices: 12 per vertex
    /// (three `f32`) plus its properties' bytes
    /// ([`crate::mesh::Properties::bytes_per_vertex`]), and 12 per triangle
    /// (three `u32`). The reference of the `.mts` size target and of
    /// `mts build --json`'s `raw_bytes`.
    #[must_use]
    pub fn raw_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.recipe.collapses.vertex_count()
            + 12 * self.triangle_count(0)
    }

    /// Bytes of the raw input mesh with 16-bit indices: 12 per vertex and 6
    /// per triangle, the reference of the cluster-tree paper's Table 2.
    #[must_use]
    pub fn raw_bytes_u16(&self) -> usize {
        12 * self.recipe.collapses.vertex_count() + 6 * self.triangle_count(0)
    }

    /// The nodes of strip `s`.
    pub(crate) fn nodes_of(&self, s: usize) -> std::ops::Range<usize> {
        self.strip_nodes[s] as usize..self.strip_nodes[s + 1] as usize
    }

    /// The beginnings of strip `s`.
    pub(crate) fn begins_of(&self, s: usize) -> std::ops::Range<usize> {
        self.strip_begins[s] as usize..self.strip_begins[s + 1] as usize
    }

    /// Checks the invariants listed on [`MtsModel`].
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken one (strip, node or arc).
    pub fn validate(&self) -> std::result::Result<(), crate::Invalid> {
        self.check_parts().map_err(|message| crate::Invalid {
            structure: "MtsModel",
            message,
        })
    }

    fn check_parts(&self) -> Result<(), String> {
        let max_lod = self.max_lod() as u32;
        check_offsets("strip node", &self.strip_nodes, self.node_vertex.len())?;
        check_offsets("strip beginning", &self.strip_begins, self.begin_node.len())?;
        check_offsets("node arc", &self.node_arcs, self.arc_target.len())?;
        if self.strip_nodes.len() != self.strip_begins.len() {
            return Err("node and beginning offsets disagree on the strip count".into());
        }
        if self.node_arcs.len() != self.node_vertex.len() + 1 {
            return Err("arc offsets do not match the node count".into());
        }
        if self.begin_res.len() != self.begin_node.len()
            || self.arc_res.len() != self.arc_target.len()
        {
            return Err("label arrays do not match their targets".into());
        }
        if self.node_vertex.len() >= NODE_MASK as usize {
            return Err("too many nodes".into());
        }
        if self.band_lod.first() != Some(&0) || self.band_lod.windows(2).any(|w| w[1] <= w[0]) {
            return Err("band LoDs do not start at 0 and increase".into());
        }
        if self.band_lod.last().is_some_and(|&l| l > max_lod) {
            return Err("band beyond the last LoD".into());
        }
        check_offsets("band strip", &self.band_strips, self.strip_count())?;
        if self.band_strips.len() != self.band_lod.len() + 1 {
            return Err("band tables disagree".into());
        }
        let vertices = self.positions.len() as u32;
        if let Some(n) = self.node_vertex.iter().position(|&v| v >= vertices) {
            return Err(format!(
                "node {n} names vertex {} of {vertices}",
                self.node_vertex[n]
            ));
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {v} is not finite"));
        }
        for s in 0..self.strip_count() {
            let nodes = self.nodes_of(s);
            let in_strip = |t: u32| t == END || (nodes.contains(&((t & NODE_MASK) as usize)));
            let begins = self.begins_of(s);
            if begins.is_empty() {
                return Err(format!("strip {s} has no beginning"));
            }
            for b in begins.clone() {
                if !in_strip(self.begin_node[b])
                    || (self.begin_node[b] != END && self.begin_node[b] & RESTART != 0)
                {
                    return Err(format!(
                        "strip {s} beginning {b} names node {:#x} outside the strip",
                        self.begin_node[b]
                    ));
                }
            }
            check_labels(&self.begin_res[begins.clone()], max_lod)
                .map_err(|e| format!("strip {s} beginnings: {e}"))?;
            if self.begin_res[begins.end - 1] != max_lod {
                return Err(format!(
                    "strip {s}: last beginning is not labelled {max_lod}"
                ));
            }
            for n in nodes.clone() {
                let arcs = self.node_arcs[n] as usize..self.node_arcs[n + 1] as usize;
                for a in arcs.clone() {
                    let t = self.arc_target[a];
                    if !in_strip(t) || (t != END && (t & NODE_MASK) as usize <= n) {
                        return Err(format!("strip {s} node {n} arc {a}: target {t:#x} is not a later node of the strip"));
                    }
                }
                check_labels(&self.arc_res[arcs], max_lod)
                    .map_err(|e| format!("strip {s} node {n}: {e}"))?;
            }
        }
        Ok(())
    }
}

fn check_offsets(what: &str, offsets: &[u32], len: usize) -> Result<(), String> {
    if offsets.first() != Some(&0) {
        return Err(format!("{what} offsets do not start at 0"));
    }
    if let Some(i) = offsets.windows(2).position(|w| w[1] < w[0]) {
        return Err(format!("{what} offsets decrease at {}", i + 1));
    }
    if offsets.last().map(|&o| o as usize) != Some(len) {
        return Err(format!("{what} offsets do not end at {len}"));
    }
    Ok(())
}

fn check_labels(labels: &[u32], max_lod: u32) -> Result<(), String> {
    if let Some(i) = labels.windows(2).position(|w| w[1] <= w[0]) {
        return Err(format!("labels do not increase at {}", i + 1));
    }
    if let Some(&l) = labels.iter().find(|&&l| l > max_lod) {
        return Err(format!("label {l} beyond LoD {max_lod}"));
    }
    Ok(())
}
