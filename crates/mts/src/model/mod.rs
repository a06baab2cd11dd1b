//! The MTS model: one labelled graph per triangle strip (section 3.1 of the
//! MTS paper, "Data structure"), stored as flat arrays of compact records.
//!
//! Strip `s` owns the records `strip_records[s]..strip_records[s + 1]` and
//! the beginnings `strip_begins[s]..strip_begins[s + 1]`. A node (the
//! paper's `ColumnNode`) names one vertex; its arcs (`RowNode`s) are
//! consecutive records (`records.rs` gives the layout), each with a target
//! and a label `res`: the arc may be walked at every LoD up to and
//! including `res`. A node's arcs are valid over consecutive, disjoint LoD
//! intervals in the order they are stored, so at LoD `L` the valid arc is
//! the first whose label is at least `L` (the paper's Fig. 5 prints the
//! comparison the wrong way round; its text, "arcs having a label greater
//! or equal to the requested LoD", is what is meant).
//!
//! The paper's special nodes become arc targets: an arc to the end ends the
//! strip (−3); an arc with a break ends the current run and starts the next
//! one at the target (−2, and −1 when the target names the same vertex: a
//! node per occurrence needs no separate marker for it).
//!
//! Decisions where the paper leaves room (see `build.rs` for the
//! construction and its proofs):
//! - **A node is one occurrence of a vertex in the strip**, not the vertex:
//!   a vertex that a strip visits twice (a swap does that) gets two nodes,
//!   so every node has at most one valid arc at any LoD and the walk never
//!   has to choose between two arcs with the same label.
//! - **Arcs go forward**: nodes are stored in strip order, so every target
//!   is a later record. The walk therefore ends after at most as many
//!   steps as the strip has records, even on a corrupt model.

mod build;
pub mod compress;
mod digest;
mod extract;
pub mod format;
pub mod lifetimes;
mod pipeline;
pub mod prefix;
pub(crate) mod records;
pub mod requests;
mod segments;
mod verify;

pub use build::{
    build, build_with_progress, can_build, BuildOptions, DEFAULT_BAND_SLACK, MIN_BAND_DROP,
    MIN_BAND_SLACK,
};
pub use extract::{Extractor, Update};
pub use pipeline::{build_from_mesh, try_build_from_mesh, PipelineOptions, PipelineTimings};
pub use prefix::{
    bytes_for_lod, chunk_index, Chunk, Prefix, DEFAULT_PREFIX_SHARES, STREAMED_VERSION,
};
pub use verify::{spread_lods, verify, VerifyReport};

use glam::Vec3;
use records::{Narrow, Word};

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
/// vertex count; every arc target is the end or a later node of the same
/// strip; labels are at most `max_lod` and strictly increasing along a
/// node's arcs and along a strip's beginnings, and a strip's last beginning
/// has label `max_lod`; a strip's slot size is the length of its walk at
/// its band's first LoD.
/// The LoD → triangle table is the contraction sequence's.
///
/// # Example
///
/// ```
/// use mts::mesh::generate::Generated;
/// use mts::model::{build_from_mesh, PipelineOptions};
/// use mts::MtsModel;
///
/// let mesh = "torus:2k".parse::<Generated>()?.build();
/// let (model, _, _) = build_from_mesh(&mesh, &PipelineOptions::default(), &mut |_, _| {});
/// // LoD 0 is the full mesh; each LoD one contraction more, never more triangles.
/// assert_eq!(model.triangle_count(0), mesh.triangle_count());
/// assert!(model.triangle_counts().windows(2).all(|w| w[0] >= w[1]));
/// // The finest LoD with at most a quarter of the triangles.
/// let lod = model.lod_for_ratio(0.25);
/// assert!(model.triangle_count(lod) <= mesh.triangle_count() / 4);
/// // Saved ready to walk and loaded back (checked against its recipe): the same model.
/// let loaded = MtsModel::from_bytes(&model.to_bytes(), std::path::Path::new("torus.mts"))?;
/// assert_eq!(loaded, model);
/// assert_eq!(model.validate(), Ok(()));
/// # Ok::<(), mts::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MtsModel {
    pub(crate) positions: Vec<Vec3>,
    /// The input vertices' properties (normals, UVs, colours, texture,
    /// position ids); empty for a mesh of positions only. A LoD draws
    /// input vertices (endpoint placement), so they serve every LoD.
    pub(crate) properties: crate::mesh::Properties,
    /// Per strip, its first record (one more entry than strips).
    pub(crate) strip_records: Vec<u32>,
    pub(crate) strip_begins: Vec<u32>,
    /// Per beginning: the first node's record or [`END`] for "the strip
    /// draws nothing at these LoDs".
    pub(crate) begin_node: Vec<u32>,
    pub(crate) begin_res: Vec<u32>,
    /// Per record ([`records`]): the node's vertex, the arc's label
    /// relative to the band's first LoD, and its code.
    pub(crate) rec_vertex: records::Narrow,
    pub(crate) rec_label: records::Narrow,
    pub(crate) rec_code: Vec<u8>,
    /// (record, target record) of the arcs that jump [`records::FAR`]
    /// records or more, by record.
    pub(crate) far: Vec<(u32, u32)>,
    /// Per strip, the indices its sequence takes at its band's first LoD
    /// (the longest it gets, see `build.rs`, "Monotone"): the extractor's
    /// slot sizes, so that it need not walk every strip to start.
    pub(crate) slot_size: Vec<u32>,
    /// First LoD of each band, and each band's strips
    /// (`band_strips[b]..band_strips[b + 1]`).
    pub(crate) band_lod: Vec<u32>,
    pub(crate) band_strips: Vec<u32>,
    /// What the model was built from (the `.mts` file stores it beside
    /// the graphs, for `verify` and for building again; see [`format`]).
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
    /// Records (one per arc, one per node without arcs; `records.rs`).
    pub records: usize,
    /// Entries of the strip-beginning lists.
    pub begins: usize,
    /// Bytes of the in-memory arrays.
    pub memory_bytes: usize,
}

impl MtsModel {
    /// Number of strips.
    #[must_use]
    pub fn strip_count(&self) -> usize {
        self.strip_records.len().saturating_sub(1)
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
        let records = self.rec_code.len();
        let no_arc = self
            .rec_code
            .iter()
            .filter(|&&c| c == records::NO_ARC)
            .count();
        let later = self
            .rec_code
            .iter()
            .filter(|&&c| c & records::MORE != 0)
            .count();
        let words = self.strip_records.len()
            + self.strip_begins.len()
            + self.begin_node.len()
            + self.begin_res.len()
            + 2 * self.far.len()
            + self.slot_size.len()
            + self.band_lod.len()
            + self.band_strips.len();
        ModelStats {
            strips: self.strip_count(),
            nodes: records - later,
            arcs: records - no_arc,
            records,
            begins: self.begin_node.len(),
            memory_bytes: 4 * words
                + self.rec_vertex.bytes()
                + self.rec_label.bytes()
                + records
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

    /// The records of strip `s`.
    pub(crate) fn records_of(&self, s: usize) -> std::ops::Range<usize> {
        self.strip_records[s] as usize..self.strip_records[s + 1] as usize
    }

    /// Whether record `r` of a strip whose records start at `first` starts
    /// a node (is not a later arc of the node before it).
    pub(crate) fn starts_node(&self, r: usize, first: usize) -> bool {
        r == first || self.rec_code[r - 1] & records::MORE == 0
    }

    /// The first LoD of each strip's band.
    pub(crate) fn strip_births(&self) -> Vec<u32> {
        let mut births = vec![0; self.strip_count()];
        for b in 0..self.band_count() {
            for s in self.band_strips(b) {
                births[s] = self.band_lod[b];
            }
        }
        births
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
        let key = digest::TriangleKey::random();
        self.check_parts(&key, &vec![Vec::new(); self.band_count()])
            .map(drop)
            .map_err(|message| crate::Invalid {
                structure: "MtsModel",
                message,
            })
    }

    /// [`MtsModel::validate`], and that the model draws what its recipe
    /// replays, with its LoD table's triangle counts, at LoD 0 and at one
    /// LoD drawn at random: what loading a ready `.mts` checks (the
    /// decision, its cost and what it leaves to trust: `model/digest.rs`).
    ///
    /// # Errors
    /// [`crate::Invalid`] naming the first broken invariant, or the band
    /// (or LoD) where the model and its recipe disagree.
    ///
    /// Cost: [`MtsModel::validate`]'s, a hash of the triangles of the two
    /// sampled LoDs on each side, one more walk of one band's strips, and
    /// the recipe's triangles mapped to the drawn LoD (on a second
    /// thread).
    pub fn validate_against_recipe(&self) -> std::result::Result<(), crate::Invalid> {
        let key = digest::TriangleKey::random();
        let samples = key.samples(&self.band_lod, self.max_lod() as u32);
        let flat: Vec<u32> = samples.iter().flatten().copied().collect();
        let (walked, replayed) = std::thread::scope(|scope| {
            let replay = scope.spawn(|| digest::replay_digests(self, &key, &flat));
            let walked = self.check_parts(&key, &samples);
            let replayed = replay
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e));
            (walked, replayed)
        });
        let invalid = |message| crate::Invalid {
            structure: "MtsModel",
            message,
        };
        let (walked, replayed) = (walked.map_err(invalid)?, replayed.map_err(invalid)?);
        let mut replayed = replayed.iter();
        for (b, (lods, walked)) in samples.iter().zip(&walked).enumerate() {
            for (lod, (w, r)) in lods.iter().zip(walked.iter().zip(replayed.by_ref())) {
                if w != r {
                    return Err(invalid(format!(
                        "band {b}: its strips draw {} triangles at LoD {lod}, {} the \
                         recipe's replay has",
                        w.count,
                        if w.count == r.count {
                            "other triangles than"
                        } else {
                            "not as many as"
                        }
                    )));
                }
            }
        }
        Ok(())
    }

    /// The structure checks; returns, per band, the digest of the
    /// triangles its strips draw at each of its `samples` (LoDs of the band,
    /// ascending), hashed with `key`.
    fn check_parts(
        &self,
        key: &digest::TriangleKey,
        samples: &[Vec<u32>],
    ) -> Result<Vec<Vec<digest::Digest>>, String> {
        let max_lod = self.max_lod() as u32;
        let records = self.rec_code.len();
        check_offsets("strip record", &self.strip_records, records)?;
        check_offsets("strip beginning", &self.strip_begins, self.begin_node.len())?;
        if self.strip_records.len() != self.strip_begins.len() {
            return Err("record and beginning offsets disagree on the strip count".into());
        }
        if self.rec_vertex.len() != records || self.rec_label.len() != records {
            return Err("record arrays differ in length".into());
        }
        if self.begin_res.len() != self.begin_node.len() {
            return Err("label arrays do not match their targets".into());
        }
        if self.slot_size.len() != self.strip_count() {
            return Err("slot sizes do not match the strip count".into());
        }
        if records >= NODE_MASK as usize {
            return Err("too many records".into());
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
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {v} is not finite"));
        }
        if self.far.windows(2).any(|w| w[1].0 <= w[0].0) {
            return Err("far arcs are not sorted by record".into());
        }
        // The strips, in chunks of about equal records checked on all
        // cores (the loader's main cost); the first error in strip order
        // is reported.
        let births = self.strip_births();
        let threads = std::thread::available_parallelism()
            .map_or(1, std::num::NonZeroUsize::get)
            .min(1 + records / 200_000);
        let mut cuts = vec![0];
        for t in 1..threads {
            let at = (records * t / threads) as u32;
            cuts.push(
                self.strip_records
                    .partition_point(|&r| r < at)
                    .min(self.strip_count()),
            );
        }
        cuts.push(self.strip_count());
        if samples.len() != self.band_count() {
            return Err("band tables disagree".into());
        }
        type Checked = Result<(usize, Vec<Vec<digest::Digest>>), String>;
        let results: Vec<Checked> = if threads == 1 {
            vec![self.check_strips(0..self.strip_count(), &births, key, samples)]
        } else {
            std::thread::scope(|scope| {
                let handles: Vec<_> = cuts
                    .windows(2)
                    .map(|w| {
                        let (range, births) = (w[0]..w[1], &births);
                        scope.spawn(move || self.check_strips(range, births, key, samples))
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                    .collect()
            })
        };
        let mut far_arcs = 0;
        let mut digests: Vec<Vec<digest::Digest>> = samples
            .iter()
            .map(|l| vec![digest::Digest::default(); l.len()])
            .collect();
        for r in results {
            let (far, chunk) = r?;
            far_arcs += far;
            for (band, c) in digests.iter_mut().zip(chunk) {
                for (d, c) in band.iter_mut().zip(c) {
                    d.merge(c);
                }
            }
        }
        if far_arcs != self.far.len() {
            return Err("the far table names a record whose arc is not far".into());
        }
        Ok(digests)
    }

    /// Checks strips `strips` (beginnings, records, slot sizes); returns
    /// how many far arcs they hold, and per band the digest of the
    /// triangles they draw at each of the band's `samples`.
    fn check_strips(
        &self,
        strips: std::ops::Range<usize>,
        births: &[u32],
        key: &digest::TriangleKey,
        samples: &[Vec<u32>],
    ) -> Result<(usize, Vec<Vec<digest::Digest>>), String> {
        let mut digests: Vec<Vec<digest::Digest>> = samples
            .iter()
            .map(|l| vec![digest::Digest::default(); l.len()])
            .collect();
        let max_lod = self.max_lod() as u32;
        let vertices = self.positions.len() as u32;
        let first_record = self.strip_records[strips.start];
        let far_start = self.far.partition_point(|&(r, _)| r < first_record);
        let mut far = self.far[far_start..].iter();
        let mut scratch = Vec::new();
        for s in strips {
            let recs = self.records_of(s);
            let (first, birth) = (recs.start, births[s]);
            let node_in_strip = |t: usize| recs.contains(&t) && self.starts_node(t, first);
            let begins = self.begins_of(s);
            if begins.is_empty() {
                return Err(format!("strip {s} has no beginning"));
            }
            for b in begins.clone() {
                let n = self.begin_node[b];
                if n != END && !node_in_strip(n as usize) {
                    return Err(format!(
                        "strip {s} beginning {b} names record {n} outside the strip or inside a node"
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
            let ranges = Ranges {
                recs: recs.clone(),
                birth,
                max_lod,
                vertices,
            };
            records::with_widths!(&self.rec_vertex, &self.rec_label, |v, l| {
                check_records(&ranges, v, l, &self.rec_code, &mut far)
            })
            .map_err(|e| format!("strip {s} {e}"))?;
            // The slot: the strip's walk at its band's first LoD has
            // exactly the stored length (a longer one would be cut in its
            // slot). A node emits its vertex and at most one break.
            scratch.resize(2 * recs.len() + 1, 0);
            let w = extract::walk(self, s, birth, birth, &mut scratch);
            if w.len != self.slot_size[s] {
                return Err(format!(
                    "strip {s}: slot of {} indices, its walk at LoD {birth} takes {}",
                    self.slot_size[s], w.len
                ));
            }
            let band = self
                .band_strips
                .partition_point(|&first| first as usize <= s)
                - 1;
            for (&lod, d) in samples[band].iter().zip(&mut digests[band]) {
                let len = if lod == birth {
                    w.len
                } else {
                    let at = extract::walk(self, s, birth, lod, &mut scratch);
                    if at.overflow || at.len > self.slot_size[s] {
                        return Err(format!(
                            "strip {s}: its walk at LoD {lod} overflows its slot of {}",
                            self.slot_size[s]
                        ));
                    }
                    at.len
                };
                d.merge(key.digest_of_runs(&scratch[..len as usize]));
            }
        }
        Ok((self.far.len() - far_start - far.len(), digests))
    }
}

/// What [`check_records`] checks one strip's records against.
struct Ranges {
    recs: std::ops::Range<usize>,
    birth: u32,
    max_lod: u32,
    vertices: u32,
}

/// Checks one strip's records (see [`MtsModel`]'s invariants): vertices
/// in range, arcs to later nodes of the strip, labels increasing along a
/// node and within the LoDs; `far` is consumed in record order.
fn check_records<V: Word, L: Word>(
    strip: &Ranges,
    vertex: &[V],
    label: &[L],
    code: &[u8],
    far: &mut std::slice::Iter<'_, (u32, u32)>,
) -> Result<(), String> {
    use records::{BREAK, DISTANCE, FAR, MORE, NO_ARC};
    let Ranges {
        recs,
        birth,
        max_lod,
        vertices,
    } = strip;
    let (first, end) = (recs.start, recs.end);
    let (code, vertex, label) = (&code[..end], &vertex[..end], &label[..end]);
    let label_limit = max_lod - birth;
    let mut previous_label = 0;
    // Whether record `r` starts a node: the record before has no MORE.
    let mut node_start = true;
    for r in first..end {
        let c = code[r];
        let l = label[r].get();
        if node_start && vertex[r].get() >= *vertices {
            return Err(format!(
                "record {r} names vertex {} of {vertices}",
                vertex[r].get()
            ));
        }
        // A node's later records hold vertex 0 (the coded file stores the
        // node starts' only, so a model that loads is one it writes).
        if !node_start && vertex[r].get() != 0 {
            return Err(format!(
                "record {r}, a node's later arc, names vertex {}",
                vertex[r].get()
            ));
        }
        if c == NO_ARC {
            if !node_start {
                return Err(format!("record {r}: a node's later arc has no target"));
            }
            continue;
        }
        if l > label_limit {
            return Err(format!(
                "record {r}: label {l} past LoD {birth} is beyond LoD {max_lod}"
            ));
        }
        if !node_start && l <= previous_label {
            return Err(format!("record {r}: labels do not increase"));
        }
        previous_label = l;
        let target = match c & DISTANCE {
            0 if c & BREAK != 0 => {
                return Err(format!("record {r}: a break to the strip's end"));
            }
            0 => None,
            FAR => match far.next() {
                Some(&(at, t)) if at as usize == r => Some(t as usize),
                _ => return Err(format!("record {r}: far arc missing from the far table")),
            },
            d => Some(r + usize::from(d)),
        };
        if let Some(t) = target {
            if t <= r || t >= end || code[t - 1] & MORE != 0 {
                return Err(format!(
                    "record {r}: target {t} is not a later node of the strip"
                ));
            }
        }
        node_start = c & MORE == 0;
    }
    if !node_start {
        return Err(format!("record {}: the strip ends inside a node", end - 1));
    }
    Ok(())
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
