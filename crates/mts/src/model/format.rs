//! The `.mts` file: a versioned little-endian binary format.
//!
//! **Decision (version 3): the file holds the model ready to walk, and the
//! recipe beside it.** Versions 1 and 2 stored only what the graphs are
//! built from (the LoD-0 strips, the contraction sequence, the build
//! options), so loading meant building again: about half a second for the
//! bunny. Version 3 adds the `MODL` section, the compact records of
//! `model/records.rs` as they lie in memory, so loading is one pass over
//! the bytes plus [`MtsModel::validate`]; the recipe stays for `mts verify`
//! and for building again, and is decoded but not built. Files of versions
//! 1 and 2 still load (built again).
//!
//! Layout (all integers little-endian):
//!
//! ```text
//! header   magic "MTSMODEL" | version u32 | section count u32 | file length u64 | checksum u64
//! section  tag [u8; 4] | payload length u64 | payload
//! ```
//!
//! The checksum is of every byte after the header: FNV-1a (64 bit) in
//! versions 1 and 2, its four-lane word form
//! ([`crate::checksum::fnv1a64_words`]) from version 3 on. Sections, in this
//! order:
//! - `META`: varints vertex count, appended vertex count, run count, strip
//!   index count, step count; then band slack (f64), the band stripifier's
//!   options (patches u8, min patch quads varint, two swap penalties as f32
//!   with NaN for none, join ends u8 with the cache-aware option as bit 1),
//!   optimal placement u8.
//! - `POSI`: `3 × f32` per vertex (input vertices, then appended ones).
//! - `STRP`: each run's length (varint), then every index as a zigzag
//!   varint of its difference from the previous index.
//! - `STEP`: per contraction: removed (varint), kept (varint), error (f32).
//!
//! Version 2 adds two sections after these, and is written only for a
//! model that needs them (a mesh with properties or seams); version 3
//! always has them, then `MODL`:
//! - `PROP`: flags u8 (1 normals, 2 texture coordinates, 4 colours, 8
//!   position ids, 16 texture), then per input vertex `3 × f32` normals,
//!   `2 × f32` UVs, `4 × f32` colours, a varint position id, as flagged;
//!   then the texture: kind u8 (0 a file path, 1 embedded), for a path its
//!   UTF-8 bytes (varint length first), for embedded the MIME type and the
//!   image bytes (each with a varint length).
//! - `CMPN`: per step, its number of companion moves (varint), then each
//!   move's removed and kept vertex (varints).
//! - `MODL`: varints strips, bands, beginnings, records, far arcs; the
//!   vertex and label widths (u8 each, 2 or 4); then as `u32` arrays the
//!   bands' first LoDs, the band → strip offsets, the strip → record and
//!   strip → beginning offsets, the slot sizes, the beginnings' records and
//!   labels; the records' vertices and labels (at their widths) and codes
//!   (u8); the far arcs (record, target as `u32` pairs); the LoD → triangle
//!   count table (`u32`, one more entry than steps).
//!
//! Every count is checked against the bytes that must hold it before
//! anything is allocated, so a corrupt file costs at most its own size.
//!
//! Version 4 holds a view-dependent hierarchy instead of a model, each of
//! its groups' models in the sections above ([`crate::hierarchy::format`]):
//! [`MtsModel::from_bytes`] says so when given one, and [`holds`] tells
//! the two kinds apart from the header.
//!
//! Version 5 ([`COMPRESSED_VERSION`], `mts build --prefixes none`) is version 3
//! with each section's payload coded with Zstandard, `MODL` in six
//! parts ([`super::compress`]): about a third of version 3's bytes (the
//! bunny: 2.1 MB against 7.2 MB, 1.71 × the raw mesh), decoded, then
//! checked as version 3 (the `MODL` head's counts against the decoded
//! parts' lengths instead of the section's). Its checksum is version 3's.
//!
//! Version 6 ([`super::prefix::STREAMED_VERSION`], what `mts build`
//! writes) is version 5 with `PRFX` chunks first, the recipes of coarse
//! LoDs, so that a prefix of the file opens ([`super::prefix`]).

use super::records::Narrow;
use super::{build, BuildOptions, MtsModel};
use crate::error::{Error, Place, Result};
use crate::mesh::Mesh;
use crate::simplify::{Collapse, Collapses};
use crate::strip::{StripifyOptions, Strips};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The file's first bytes.
pub const MAGIC: &[u8; 8] = b"MTSMODEL";
/// The version of the ready file with its arrays as they lie in memory
/// ([`MtsModel::to_bytes`]); this crate reads 1, 2 and
/// [`COMPRESSED_VERSION`] and [`super::prefix::STREAMED_VERSION`] too.
pub const VERSION: u32 = 3;
/// The version of a model file whose sections are coded
/// ([`MtsModel::to_compressed_bytes`], [`super::compress`]).
pub const COMPRESSED_VERSION: u32 = 5;
pub(crate) const HEADER_LEN: usize = 32;
pub(crate) const TAGS: [&[u8; 4]; 7] = [
    b"META", b"POSI", b"STRP", b"STEP", b"PROP", b"CMPN", b"MODL",
];
/// Sections of a version-1 file.
const V1_SECTIONS: usize = 4;

/// The sections a hierarchy's group leaves out: its vertices are the
/// input's (`hierarchy/format.rs`).
const VERTEX_TAGS: [&[u8; 4]; 2] = [b"POSI", b"PROP"];

/// Sections of a file of `version`.
pub(crate) fn section_count(version: u32) -> usize {
    match version {
        1 => V1_SECTIONS,
        2 => 6,
        _ => TAGS.len(),
    }
}

/// What an `.mts` file holds, by its version: a per-object model
/// (versions 1 to 3 and 5) or a view-dependent hierarchy (version 4,
/// [`crate::hierarchy::Hierarchy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holds {
    /// An [`MtsModel`] (versions 1 to [`VERSION`], and
    /// [`COMPRESSED_VERSION`]).
    Model,
    /// A [`crate::hierarchy::Hierarchy`] (version
    /// [`crate::hierarchy::format::VERSION`]).
    Hierarchy,
}

/// The version in the header of `.mts` bytes, or `None` when they do not
/// start with [`MAGIC`] and a version: what a reader of both kinds peeks at
/// before it chooses [`MtsModel::from_bytes`] or
/// [`crate::hierarchy::Hierarchy::from_bytes`] (see [`holds`]).
#[must_use]
pub fn file_version(bytes: &[u8]) -> Option<u32> {
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return None;
    }
    Some(u32::from_le_bytes([
        bytes[8], bytes[9], bytes[10], bytes[11],
    ]))
}

/// What `.mts` bytes hold, from their header's version; `None` when they
/// are not an `.mts` file of a known version (the loaders then say why).
#[must_use]
pub fn holds(bytes: &[u8]) -> Option<Holds> {
    match file_version(bytes)? {
        1..=VERSION | COMPRESSED_VERSION | super::prefix::STREAMED_VERSION => Some(Holds::Model),
        crate::hierarchy::format::VERSION | crate::hierarchy::format::CODED_VERSION => {
            Some(Holds::Hierarchy)
        }
        _ => None,
    }
}

/// Appends each section: tag, payload length (`u64`), payload.
pub(crate) fn put_sections<'t>(
    out: &mut Vec<u8>,
    sections: impl IntoIterator<Item = (&'t [u8; 4], Vec<u8>)>,
) {
    for (tag, payload) in sections {
        out.extend_from_slice(tag);
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&payload);
    }
}

/// The file: the header (magic, `version`, `sections`, length, checksum of
/// `body`: FNV-1a before version 3, its word form since) and `body`.
pub(crate) fn seal_body(version: u32, sections: usize, body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(sections as u32).to_le_bytes());
    out.extend_from_slice(&((HEADER_LEN + body.len()) as u64).to_le_bytes());
    out.extend_from_slice(&body_checksum(version, body).to_le_bytes());
    out.extend_from_slice(body);
    out
}

/// The checksum of a body of a file of `version`.
fn body_checksum(version: u32, body: &[u8]) -> u64 {
    if version < 3 {
        crate::checksum::fnv1a64(body)
    } else {
        crate::checksum::fnv1a64_words(body)
    }
}

impl MtsModel {
    /// The model as `.mts` bytes, ready to walk (version 3): what
    /// [`MtsModel::save`] writes.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        self.encode(true)
    }

    /// The model as `.mts` bytes of its recipe only (version 1, or 2 for a
    /// mesh with properties or seams): about a seventh of
    /// [`MtsModel::to_bytes`] on the bunny, but loading builds the graphs
    /// again (hundreds of milliseconds instead of a few).
    #[must_use]
    pub fn to_recipe_bytes(&self) -> Vec<u8> {
        self.encode(false)
    }

    /// The model as `.mts` bytes ready to walk, its sections coded with
    /// Zstandard at `level` (1 to 22; [`super::compress::DEFAULT_LEVEL`]
    /// in `mts build`): version [`COMPRESSED_VERSION`], about a third of
    /// [`MtsModel::to_bytes`] on the bunny, loaded in a few more
    /// milliseconds (see [`super::compress`]). [`MtsModel::from_bytes`]
    /// reads it.
    #[must_use]
    pub fn to_compressed_bytes(&self, level: i32) -> Vec<u8> {
        let mut body = Vec::new();
        let sections = self.coded_sections(level);
        let count = sections.len();
        put_sections(&mut body, sections);
        seal_body(COMPRESSED_VERSION, count, &body)
    }

    /// The sections of a version-5 file, coded at `level`.
    pub(crate) fn coded_sections(&self, level: i32) -> Vec<(&'static [u8; 4], Vec<u8>)> {
        let recipe = self.payloads(2);
        let payloads = super::compress::pack(&recipe, &self.model_parts(true), level);
        TAGS.iter().copied().zip(payloads).collect()
    }

    fn encode(&self, ready: bool) -> Vec<u8> {
        let version = if ready {
            VERSION
        } else if self.properties.is_empty() && !self.recipe.collapses.has_companions() {
            1
        } else {
            2
        };
        let payloads = self.payloads(version);
        let mut body = Vec::new();
        let sections = payloads.len();
        put_sections(&mut body, TAGS.iter().copied().zip(payloads));
        seal_body(version, sections, &body)
    }

    /// The payloads of the sections of a version-`version` file, in the
    /// order of [`TAGS`].
    fn payloads(&self, version: u32) -> Vec<Vec<u8>> {
        let r = &self.recipe;
        let c = &r.collapses;
        let mut meta = Vec::new();
        for n in [
            c.vertex_count(),
            c.appended().len(),
            r.strips.run_count(),
            r.strips.runs().map(<[u32]>::len).sum(),
            c.max_lod(),
        ] {
            put_varint(&mut meta, n as u64);
        }
        meta.extend_from_slice(&r.options.band_slack.to_le_bytes());
        let so = &r.options.stripify;
        meta.push(u8::from(so.patches));
        put_varint(&mut meta, so.min_patch_quads as u64);
        for p in so.swap_penalties {
            meta.extend_from_slice(&p.unwrap_or(f32::NAN).to_le_bytes());
        }
        meta.push(u8::from(so.join_ends) | u8::from(so.cache_aware) << 1);
        meta.push(u8::from(c.is_optimal_placement()));

        let mut posi = Vec::with_capacity(12 * self.positions.len());
        for p in &self.positions {
            for x in p.to_array() {
                posi.extend_from_slice(&x.to_le_bytes());
            }
        }
        let mut strp = Vec::new();
        for run in r.strips.runs() {
            put_varint(&mut strp, run.len() as u64);
        }
        let mut prev = 0i64;
        for run in r.strips.runs() {
            for &v in run {
                put_varint(&mut strp, zigzag(i64::from(v) - prev));
                prev = i64::from(v);
            }
        }
        let mut step = Vec::new();
        for s in c.steps() {
            put_varint(&mut step, u64::from(s.removed));
            put_varint(&mut step, u64::from(s.kept));
            step.extend_from_slice(&s.error.to_le_bytes());
        }

        let mut payloads = vec![meta, posi, strp, step];
        if version > 1 {
            payloads.push(properties_payload(&self.properties));
            let mut cmpn = Vec::new();
            for i in 0..c.max_lod() {
                let moves: Vec<(u32, u32)> = c.companions(i).collect();
                put_varint(&mut cmpn, moves.len() as u64);
                for (r, k) in moves {
                    put_varint(&mut cmpn, u64::from(r));
                    put_varint(&mut cmpn, u64::from(k));
                }
            }
            payloads.push(cmpn);
        }
        if version > 2 {
            payloads.push(self.model_payload());
        }
        payloads
    }

    /// The model's sections as a version-3 file has them, without `POSI`
    /// and `PROP` unless `own_vertices` (a hierarchy's group, whose
    /// vertices are the input's, gathered: `hierarchy/format.rs`).
    pub(crate) fn sections(&self, own_vertices: bool) -> Vec<(&'static [u8; 4], Vec<u8>)> {
        TAGS.iter()
            .copied()
            .zip(self.payloads(VERSION))
            .filter(|(tag, _)| own_vertices || !VERTEX_TAGS.contains(tag))
            .collect()
    }

    /// The `MODL` section.
    fn model_payload(&self) -> Vec<u8> {
        self.model_parts(false).concat()
    }

    /// The `MODL` section in six parts, whose concatenation is the
    /// section: the counts and widths; the `u32` arrays before the records;
    /// the records' vertices (with `node_vertices_only`, only those of the
    /// records that start a node, as version 5 codes them:
    /// [`super::compress`]); their labels; their codes; the far arcs and the
    /// LoD → triangle table.
    pub(crate) fn model_parts(&self, node_vertices_only: bool) -> [Vec<u8>; 6] {
        let mut head = Vec::with_capacity(32);
        for n in [
            self.strip_count(),
            self.band_count(),
            self.begin_node.len(),
            self.rec_code.len(),
            self.far.len(),
        ] {
            put_varint(&mut head, n as u64);
        }
        head.push(self.rec_vertex.width() as u8);
        head.push(self.rec_label.width() as u8);
        let words = |out: &mut Vec<u8>, v: &[u32]| {
            for x in v {
                out.extend_from_slice(&x.to_le_bytes());
            }
        };
        let mut tables =
            Vec::with_capacity(4 * (3 * self.strip_count() + 2 * self.begin_node.len() + 8));
        for v in [
            &self.band_lod,
            &self.band_strips,
            &self.strip_records,
            &self.strip_begins,
            &self.slot_size,
            &self.begin_node,
            &self.begin_res,
        ] {
            words(&mut tables, v);
        }
        let starts_node = |r: usize| r == 0 || self.rec_code[r - 1] & super::records::MORE == 0;
        let narrow = |n: &Narrow, only_nodes: bool| {
            let mut out = Vec::with_capacity(n.bytes());
            let keep = |r: usize| !only_nodes || starts_node(r);
            match n {
                Narrow::U16(v) => v
                    .iter()
                    .enumerate()
                    .filter(|&(r, _)| keep(r))
                    .for_each(|(_, x)| out.extend_from_slice(&x.to_le_bytes())),
                Narrow::U32(v) => v
                    .iter()
                    .enumerate()
                    .filter(|&(r, _)| keep(r))
                    .for_each(|(_, x)| out.extend_from_slice(&x.to_le_bytes())),
            }
            out
        };
        let vertices = narrow(&self.rec_vertex, node_vertices_only);
        let labels = narrow(&self.rec_label, false);
        let mut tail = Vec::with_capacity(8 * self.far.len() + 4 * (self.max_lod() + 1));
        for &(r, t) in &self.far {
            words(&mut tail, &[r, t]);
        }
        words(&mut tail, self.recipe.collapses.triangle_counts());
        [head, tables, vertices, labels, self.rec_code.clone(), tail]
    }

    /// Writes the model to `path`, ready to walk with its arrays uncoded
    /// (see [`MtsModel::to_bytes`]; [`MtsModel::to_compressed_bytes`] for
    /// the coded file), whole or not at all ([`crate::output`]).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::output::write_file(path, &self.to_bytes())
    }

    /// Reads a model from `path` (see [`MtsModel::from_bytes`]).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as
    /// [`MtsModel::from_bytes`].
    pub fn load(path: &Path) -> Result<MtsModel> {
        let bytes = crate::mesh::io::read_file(path)?;
        MtsModel::from_bytes(&bytes, path)
    }

    /// Parses `.mts` bytes, validates every count, index and label, and
    /// builds the model. `file` names the source in errors.
    ///
    /// # Errors
    /// [`Error::UnknownFormat`] for a wrong magic or version, [`Error::Parse`]
    /// naming the byte offset and section of the first problem otherwise
    /// (truncation, checksum, counts, indices, labels).
    pub fn from_bytes(bytes: &[u8], file: &Path) -> Result<MtsModel> {
        if matches!(
            file_version(bytes),
            Some(COMPRESSED_VERSION | super::prefix::STREAMED_VERSION)
        ) {
            return read_coded_model(bytes, file);
        }
        let sections = model_sections(bytes, file)?;
        read_model(sections, file, true)
    }
}

/// Reads a version-5 file ([`super::compress`]): its header, what its
/// parts may decode to, then the `MODL` arrays decoded on a second thread
/// (from as soon as the step count is known) while the recipe's sections
/// are decoded and parsed; then as version 3.
fn read_coded_model(bytes: &[u8], file: &Path) -> Result<MtsModel> {
    use super::compress::{check_expansion, only_part, unpack_recipe};
    let (version, mut top) = check_header(bytes, file, Holds::Model, section_count)?;
    // A version-6 file's chunks come first; the whole model does not need
    // them, but checks them once it is loaded.
    let chunks = if version == super::prefix::STREAMED_VERSION {
        skip_prefixes(&mut top, bytes)?
    } else {
        Vec::new()
    };
    let mut coded = split_sections(&mut top, &TAGS)?;
    top.finish()?;
    check_expansion(&coded, true, bytes.len())?;
    let Some(modl) = coded.pop() else {
        return Err(top.error("no MODL section"));
    };
    // The step count (META's fifth varint), bounded as `parse_model`
    // bounds it (6 bytes a step at least, of the decoded STEP section).
    let (r, meta) = only_part(&coded[0])?;
    let meta = meta.decode(&r)?;
    let mut m = Reader::new(&meta, 0, "META, decoded", file);
    for _ in 0..4 {
        m.varint()?;
    }
    let step_bytes = only_part(&coded[3])?.1.decoded_len();
    let steps = m.count("step count", step_bytes / 6)?;
    std::thread::scope(|scope| {
        let arrays_of = modl.clone();
        let arrays = scope.spawn(move || read_coded_arrays(arrays_of, steps));
        let recipe = unpack_recipe(coded)?;
        let mut readers: Vec<Reader<'_>> = recipe
            .iter()
            .zip(DECODED_NAMES)
            .map(|(d, name)| Reader::new(d, 0, name, file))
            .collect();
        readers.push(modl);
        let mut sections = sections_of(readers, file)?;
        sections.modl_coded = true;
        sections.arrays = Some(Box::new(move || {
            arrays
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e))
        }));
        read_model(sections, file, true)
    })
    .and_then(|model| {
        super::prefix::check_chunks(&chunks, file, &model)?;
        Ok(model)
    })
}

/// Steps `top` over a version-6 file's chunks (`PRFX` sections: the
/// header's section count less version 5's), each checked against the
/// bytes left, and returns them; `mts verify` opens them
/// ([`MtsModel::prefixes_of`]).
fn skip_prefixes<'a>(top: &mut Reader<'a>, bytes: &[u8]) -> Result<Vec<Reader<'a>>> {
    let declared = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
    let tags = vec![super::prefix::PREFIX_TAG; declared.saturating_sub(TAGS.len())];
    split_sections(top, &tags)
}

/// Decodes one model's sections and checks it: a recipe (no `MODL`) is
/// built and validated, a ready model checked against its recipe
/// ([`MtsModel::validate_against_recipe`]). With `threaded`, the `MODL`
/// arrays are read on a second thread while the recipe is parsed.
pub(crate) fn read_model(s: ModelSections<'_>, file: &Path, threaded: bool) -> Result<MtsModel> {
    let mut parsed = parse_model(s, threaded)?;
    let Some(arrays) = parsed.arrays.take() else {
        let model = build(
            &parsed.mesh,
            &parsed.strips,
            &parsed.collapses,
            &parsed.options,
        );
        debug_assert_eq!(model.properties, parsed.mesh.properties);
        model.validate().map_err(|e| {
            parse_error(
                file,
                0,
                "model",
                format!("built model is invalid: {}", e.message),
            )
        })?;
        return Ok(model);
    };
    let at = parsed.modl.as_ref().map_or(0, |m| m.base);
    let section = parsed.modl.as_ref().map_or("MODL", |m| m.section);
    let model = assemble(arrays?, parsed);
    model
        .validate_against_recipe()
        .map_err(|e| parse_error(file, at, section, e.message))?;
    Ok(model)
}

/// Rewrites the header's file length and checksum to match `bytes` (for
/// tests and fuzzing that alter a file's content on purpose, so that the
/// loader's checks past the checksum are reached). Does nothing to bytes
/// shorter than a header.
pub fn seal(bytes: &mut [u8]) {
    if bytes.len() < HEADER_LEN {
        return;
    }
    let len = bytes.len() as u64;
    bytes[16..24].copy_from_slice(&len.to_le_bytes());
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    let sum = body_checksum(version, &bytes[HEADER_LEN..]);
    bytes[24..32].copy_from_slice(&sum.to_le_bytes());
}

/// What a file holds, validated.
struct Parsed<'a> {
    /// Every vertex, appended ones too.
    positions: Vec<Vec3>,
    /// Version 3's `MODL` section, and its arrays (read on a second
    /// thread while the recipe is parsed).
    modl: Option<Reader<'a>>,
    arrays: Option<Result<Arrays>>,
    /// The input vertices with their properties, and (before version 3)
    /// the strips' triangles to build from.
    mesh: Mesh,
    strips: Strips,
    collapses: Collapses,
    options: BuildOptions,
}

pub(crate) fn parse_error(file: &Path, byte: usize, element: &str, message: String) -> Error {
    Error::Parse {
        file: file.to_owned(),
        place: Place {
            element: Some(element.to_owned()),
            ..Place::default()
        }
        .at_byte(byte as u64),
        message,
    }
}

/// A bounds-checked little-endian reader over one section.
#[derive(Clone)]
pub(crate) struct Reader<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) pos: usize,
    /// Offset of `bytes` in the file, for error places.
    pub(crate) base: usize,
    pub(crate) section: &'static str,
    pub(crate) file: PathBuf,
}

impl<'a> Reader<'a> {
    /// A reader over `bytes`, which start at byte `base` of `file`, named
    /// `section` in errors.
    pub(crate) fn new(
        bytes: &'a [u8],
        base: usize,
        section: &'static str,
        file: &Path,
    ) -> Reader<'a> {
        Reader {
            bytes,
            pos: 0,
            base,
            section,
            file: file.to_owned(),
        }
    }

    /// An error at the current position.
    #[cold]
    #[inline(never)]
    pub(crate) fn error(&self, message: impl Into<String>) -> Error {
        parse_error(
            &self.file,
            self.base + self.pos,
            self.section,
            message.into(),
        )
    }

    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    #[inline]
    pub(crate) fn take(&mut self, n: usize) -> Result<&[u8]> {
        if self.remaining() < n {
            return Err(self.error(format!(
                "truncated: {n} bytes needed, {} left",
                self.remaining()
            )));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    #[inline]
    pub(crate) fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    #[inline]
    pub(crate) fn f32(&mut self) -> Result<f32> {
        let b = self.take(4)?;
        Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub(crate) fn f64(&mut self) -> Result<f64> {
        let mut a = [0u8; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(f64::from_le_bytes(a))
    }

    /// `n` little-endian `u32`s.
    pub(crate) fn words(&mut self, n: usize) -> Result<Vec<u32>> {
        let bytes = self.take(
            n.checked_mul(4)
                .ok_or_else(|| self.error("count overflows"))?,
        )?;
        Ok(bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    }

    #[inline]
    pub(crate) fn varint(&mut self) -> Result<u64> {
        // Fast path: a one- or two-byte varint with its bytes present.
        if let [b0, rest @ ..] = &self.bytes[self.pos..] {
            if b0 & 0x80 == 0 {
                self.pos += 1;
                return Ok(u64::from(*b0));
            }
            if let Some(&b1) = rest.first() {
                if b1 & 0x80 == 0 {
                    self.pos += 2;
                    return Ok(u64::from(b0 & 0x7f) | u64::from(b1) << 7);
                }
            }
        }
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.u8()?;
            v |= u64::from(b & 0x7f) << shift;
            if b & 0x80 == 0 {
                if shift == 63 && b > 1 {
                    break;
                }
                return Ok(v);
            }
        }
        Err(self.error("varint longer than 64 bits"))
    }

    /// A varint that must be at most `max`, named `what` in errors.
    pub(crate) fn count(&mut self, what: &str, max: u64) -> Result<usize> {
        let at = self.pos;
        let v = self.varint()?;
        if v > max {
            self.pos = at;
            return Err(self.error(format!("{what} {v} exceeds {max}")));
        }
        Ok(v as usize)
    }

    pub(crate) fn finish(&self) -> Result<()> {
        if self.remaining() != 0 {
            return Err(self.error(format!(
                "{} unexpected bytes at the end of the section",
                self.remaining()
            )));
        }
        Ok(())
    }
}

/// Checks the header of `.mts` `bytes` that should hold `holds`: the
/// magic, a version of that kind (a file of the other kind is named as
/// such), the section count (`sections(version)`), the file length and
/// the checksum. Returns the version and a reader over the body.
pub(crate) fn check_header<'a>(
    bytes: &'a [u8],
    file: &Path,
    holds: Holds,
    sections: impl Fn(u32) -> usize,
) -> Result<(u32, Reader<'a>)> {
    if bytes.len() < HEADER_LEN || &bytes[..8] != MAGIC {
        return Err(Error::UnknownFormat {
            file: file.to_owned(),
            message: if bytes.len() < HEADER_LEN {
                format!(
                    "not an .mts file: {} bytes, shorter than the {HEADER_LEN}-byte header \
                     (byte 0 on)",
                    bytes.len()
                )
            } else {
                "not an .mts file: byte 0: magic \"MTSMODEL\" missing".into()
            },
        });
    }
    let u32_at =
        |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let u64_at = |o: usize| {
        let mut a = [0u8; 8];
        a.copy_from_slice(&bytes[o..o + 8]);
        u64::from_le_bytes(a)
    };
    let version = u32_at(8);
    let hierarchy = crate::hierarchy::format::VERSION;
    let coded_hierarchy = crate::hierarchy::format::CODED_VERSION;
    let wrong = match (holds, version) {
        (Holds::Model, 1..=VERSION | COMPRESSED_VERSION | super::prefix::STREAMED_VERSION) => None,
        (Holds::Hierarchy, v) if v == hierarchy || v == coded_hierarchy => None,
        (Holds::Model, v) if v == hierarchy || v == coded_hierarchy => Some(format!(
            "byte 8: .mts version {v} holds a view-dependent hierarchy (`mts build \
             --hierarchy`), not a per-object model: `mts info` and `mts verify` read it (in \
             the library: mts::hierarchy::Hierarchy::load)"
        )),
        (
            Holds::Hierarchy,
            v @ (1..=VERSION | COMPRESSED_VERSION | super::prefix::STREAMED_VERSION),
        ) => Some(format!(
            "byte 8: .mts version {v} holds a per-object model, not a view-dependent \
             hierarchy (version {hierarchy} or {coded_hierarchy}): `mts build --hierarchy` writes one (in the \
             library: mts::MtsModel::load reads this file)"
        )),
        (_, v) => Some(format!(
            "byte 8: .mts version {v}; this build reads versions 1 to {VERSION}, \
             {COMPRESSED_VERSION} and {} (a model) and {hierarchy} and {coded_hierarchy} (a \
             hierarchy)",
            super::prefix::STREAMED_VERSION
        )),
    };
    if let Some(message) = wrong {
        return Err(Error::UnknownFormat {
            file: file.to_owned(),
            message,
        });
    }
    let header = |byte, m: String| parse_error(file, byte, "header", m);
    let section_count = sections(version);
    let streamed = holds == Holds::Model && version == super::prefix::STREAMED_VERSION;
    let extra = (u32_at(12) as usize).saturating_sub(section_count);
    if u32_at(12) as usize != section_count
        && !(streamed && (1..=super::prefix::MAX_PREFIXES).contains(&extra))
    {
        return Err(header(
            12,
            format!(
                "{} sections, expected {section_count}{} in version {version}",
                u32_at(12),
                if streamed {
                    format!(" to {}", section_count + super::prefix::MAX_PREFIXES)
                } else {
                    String::new()
                }
            ),
        ));
    }
    if u64_at(16) != bytes.len() as u64 {
        return Err(header(
            16,
            format!(
                "file length {} but {} bytes present (truncated?)",
                u64_at(16),
                bytes.len()
            ),
        ));
    }
    let body = &bytes[HEADER_LEN..];
    let sum = body_checksum(version, body);
    if u64_at(24) != sum {
        return Err(header(
            24,
            format!("checksum {:#018x}, content gives {sum:#018x}", u64_at(24)),
        ));
    }
    Ok((
        version,
        Reader::new(body, HEADER_LEN, "section table", file),
    ))
}

/// Reads from `top` one section per tag of `tags`, in that order (tag,
/// `u64` length, payload), each checked against the bytes left: a reader
/// over each payload, named by its tag.
pub(crate) fn split_sections<'a>(
    top: &mut Reader<'a>,
    tags: &[&'static [u8; 4]],
) -> Result<Vec<Reader<'a>>> {
    let mut sections = Vec::with_capacity(tags.len().min(top.remaining() / 12));
    for (i, &tag) in tags.iter().enumerate() {
        let at = top.pos;
        let got = top.take(4)?.to_vec();
        if got != *tag {
            top.pos = at;
            return Err(top.error(format!(
                "section {i} is {:?}, expected {:?}",
                String::from_utf8_lossy(&got),
                String::from_utf8_lossy(tag)
            )));
        }
        let mut len = [0u8; 8];
        len.copy_from_slice(top.take(8)?);
        let len = u64::from_le_bytes(len);
        if len > top.remaining() as u64 {
            return Err(top.error(format!(
                "section length {len} exceeds the {} bytes left",
                top.remaining()
            )));
        }
        let start = top.pos;
        let bytes: &'a [u8] = &top.bytes[start..start + len as usize];
        top.pos += len as usize;
        let name = std::str::from_utf8(&tag[..]).unwrap_or("section");
        sections.push(Reader::new(bytes, top.base + start, name, &top.file));
    }
    Ok(sections)
}

/// One model's sections: `META`, `STRP`, `STEP`; `CMPN` from version 2 on
/// and `MODL` from version 3 on; its vertices from `POSI` and (from version
/// 2 on) `PROP`, or given (a hierarchy's group).
pub(crate) struct ModelSections<'a> {
    pub(crate) meta: Reader<'a>,
    pub(crate) vertices: Vertices<'a>,
    pub(crate) strp: Reader<'a>,
    pub(crate) step: Reader<'a>,
    pub(crate) cmpn: Option<Reader<'a>>,
    pub(crate) modl: Option<Reader<'a>>,
    /// Whether `modl` is coded (version 5, [`super::compress`]).
    pub(crate) modl_coded: bool,
    /// The arrays of `modl`, being read elsewhere: called once the recipe
    /// is parsed (version 5 starts them before the recipe is decoded).
    pub(crate) arrays: Option<ArraysJoin<'a>>,
}

/// What [`ModelSections::arrays`] holds.
pub(crate) type ArraysJoin<'a> = Box<dyn FnOnce() -> Result<Arrays> + 'a>;

/// Where a model's vertices come from.
pub(crate) enum Vertices<'a> {
    /// Its own `POSI` section (input vertices, then appended ones) and
    /// `PROP` section (none in version 1).
    Stored {
        posi: Reader<'a>,
        prop: Option<Reader<'a>>,
    },
    /// Given whole (no appended vertex): a hierarchy group's, gathered from
    /// the input's.
    Given {
        positions: Vec<Vec3>,
        properties: crate::mesh::Properties,
    },
}

/// The sections of a model file (versions 1 to 3), its header checked.
fn model_sections<'a>(bytes: &'a [u8], file: &Path) -> Result<ModelSections<'a>> {
    let (version, mut top) = check_header(bytes, file, Holds::Model, section_count)?;
    let sections = split_sections(&mut top, &TAGS[..section_count(version)])?;
    top.finish()?;
    sections_of(sections, file)
}

/// The names of a version-5 file's sections once decoded (an error's byte
/// is then an offset in the decoded section).
const DECODED_NAMES: [&str; 6] = [
    "META, decoded",
    "POSI, decoded",
    "STRP, decoded",
    "STEP, decoded",
    "PROP, decoded",
    "CMPN, decoded",
];

/// A model's sections from readers over them, in the order of [`TAGS`]
/// (the first four at least).
fn sections_of<'a>(mut sections: Vec<Reader<'a>>, file: &Path) -> Result<ModelSections<'a>> {
    let mut extra = sections.split_off(V1_SECTIONS).into_iter();
    let (prop, cmpn, modl) = (extra.next(), extra.next(), extra.next());
    let [meta, posi, strp, step]: [Reader; 4] = sections
        .try_into()
        .map_err(|_| parse_error(file, HEADER_LEN, "section table", "section count".into()))?;
    Ok(ModelSections {
        meta,
        vertices: Vertices::Stored { posi, prop },
        strp,
        step,
        cmpn,
        modl,
        modl_coded: false,
        arrays: None,
    })
}

/// Decodes and checks one model's sections (every count bounded by the
/// bytes of the section that holds it, every index by its range).
fn parse_model(s: ModelSections<'_>, threaded: bool) -> Result<Parsed<'_>> {
    let ModelSections {
        mut meta,
        vertices: source,
        mut strp,
        mut step,
        cmpn,
        modl,
        modl_coded,
        arrays: prefetched,
    } = s;
    // META: counts, each bounded by the bytes of the section that holds it.
    let (vertices, appended) = match &source {
        Vertices::Stored { posi, .. } => {
            let vertices = meta.count("vertex count", (posi.remaining() / 12) as u64)?;
            let appended = meta.count(
                "appended vertex count",
                (posi.remaining() / 12 - vertices) as u64,
            )?;
            if 12 * (vertices + appended) != posi.remaining() {
                return Err(posi.error(format!(
                    "{} bytes for {} vertices",
                    posi.remaining(),
                    vertices + appended
                )));
            }
            (vertices, appended)
        }
        Vertices::Given { positions, .. } => {
            let at = meta.pos;
            let vertices = meta.count("vertex count", positions.len() as u64)?;
            if vertices != positions.len() {
                meta.pos = at;
                return Err(meta.error(format!(
                    "{vertices} vertices, {} mapped to the input's",
                    positions.len()
                )));
            }
            (vertices, meta.count("appended vertex count", 0)?)
        }
    };
    let runs = meta.count("run count", (strp.remaining() / 4) as u64)?;
    let indices = meta.count("strip index count", strp.remaining() as u64)?;
    let steps = meta.count("step count", (step.remaining() / 6) as u64)?;
    let band_slack = meta.f64()?;
    if band_slack.is_nan() || band_slack < super::MIN_BAND_SLACK {
        return Err(meta.error(format!(
            "band slack {band_slack} is below {}",
            super::MIN_BAND_SLACK
        )));
    }
    let patches = flag(&mut meta, "patches")?;
    let min_patch_quads = meta.count("min patch quads", u64::from(u32::MAX))?;
    let mut swap_penalties = [None; 2];
    for p in &mut swap_penalties {
        let v = meta.f32()?;
        if v.is_infinite() {
            return Err(meta.error("infinite swap penalty"));
        }
        *p = (!v.is_nan()).then_some(v);
    }
    let (join_ends, cache_aware) = match meta.u8()? {
        b @ 0..=3 => (b & 1 != 0, b & 2 != 0),
        b => {
            meta.pos -= 1;
            return Err(meta.error(format!("join ends byte is {b}, not 0 to 3")));
        }
    };
    let optimal = flag(&mut meta, "optimal placement")?;
    meta.finish()?;
    if optimal != (appended > 0) && !(optimal && steps == 0) {
        return Err(meta.error(format!(
            "{appended} appended vertices with optimal placement {optimal}"
        )));
    }
    if optimal && appended != steps {
        return Err(meta.error(format!("{appended} appended vertices for {steps} steps")));
    }
    if vertices >= super::NODE_MASK as usize {
        return Err(meta.error(format!("{vertices} vertices is too many")));
    }

    // The model's arrays are read on a second thread while the recipe is
    // parsed (version 3), when `threaded`.
    // A coded section (version 5) is decoded there too.
    let arrays_reader = modl.clone();
    let arrays_of = move |m: Reader<'_>| {
        if modl_coded {
            read_coded_arrays(m, steps)
        } else {
            read_arrays(m, steps)
        }
    };
    std::thread::scope(|scope| {
        let (reading, inline) = if prefetched.is_some() {
            (None, None)
        } else if threaded {
            (
                arrays_reader.map(|m| scope.spawn(move || arrays_of(m))),
                None,
            )
        } else {
            (None, arrays_reader)
        };
        let rest = (move || -> Result<Parsed<'_>> {
            // POSI and PROP, or the given vertices.
            let (positions, prop, given_properties) = match source {
                Vertices::Stored { mut posi, prop } => {
                    let mut positions = Vec::with_capacity(vertices + appended);
                    for i in 0..vertices + appended {
                        let p = Vec3::new(posi.f32()?, posi.f32()?, posi.f32()?);
                        if !p.is_finite() {
                            posi.pos -= 12;
                            return Err(posi.error(format!("vertex {i} is not finite: {p}")));
                        }
                        positions.push(p);
                    }
                    posi.finish()?;
                    (positions, prop, None)
                }
                Vertices::Given {
                    positions,
                    properties,
                } => (positions, None, Some(properties)),
            };

            // STRP.
            let mut starts = Vec::with_capacity(runs + 1);
            starts.push(0u32);
            let mut total = 0usize;
            for r in 0..runs {
                let len = strp.count("run length", indices as u64)?;
                if len < 3 {
                    return Err(strp.error(format!("run {r} has {len} vertices")));
                }
                total += len;
                if total > indices {
                    return Err(strp.error(format!(
                        "runs hold more than the {indices} indices announced"
                    )));
                }
                starts.push(total as u32);
            }
            if total != indices {
                return Err(strp.error(format!("runs hold {total} indices, {indices} announced")));
            }
            let mut all = Vec::with_capacity(indices);
            let mut prev = 0i64;
            for i in 0..indices {
                let at = strp.pos;
                let v = prev + unzigzag(strp.varint()?);
                if v < 0 || v >= vertices as i64 {
                    strp.pos = at;
                    return Err(strp.error(format!(
                        "strip index {i} is {v}, vertices are 0..{vertices}"
                    )));
                }
                all.push(v as u32);
                prev = v;
            }
            strp.finish()?;
            let strips = Strips::from_runs(
                starts
                    .windows(2)
                    .map(|w| &all[w[0] as usize..w[1] as usize]),
                vertices as u32,
            )
            .map_err(|e| strp.error(e.to_string()))?;
            // A ready model needs no mesh to build from.
            let mut mesh = Mesh {
                positions: positions[..vertices].to_vec(),
                triangles: if modl.is_some() {
                    Vec::new()
                } else {
                    strips.triangles()
                },
                properties: Default::default(),
            };
            if let Some(mut prop) = prop {
                mesh.properties = read_properties(&mut prop, &mesh.positions)?;
            } else if let Some(properties) = given_properties {
                mesh.properties = properties;
            }
            if strips.triangle_count() == 0 {
                return Err(strp.error("the strips draw no triangle"));
            }

            // STEP: a valid sequence (each vertex removed once, never used after).
            let total_vertices = vertices + appended;
            let mut removed_at = vec![false; total_vertices];
            let mut list = Vec::with_capacity(steps);
            let mut last_error = 0.0f32;
            for i in 0..steps {
                let at = step.pos;
                let limit = if optimal { vertices + i } else { vertices };
                let removed = step.count("removed vertex", total_vertices as u64)?;
                let kept = step.count("kept vertex", total_vertices as u64)?;
                let error = step.f32()?;
                let problem = if removed >= limit || kept >= limit {
                    Some(format!(
                        "names a vertex not present at that step ({removed}, {kept})"
                    ))
                } else if removed == kept {
                    Some(format!("contracts vertex {removed} onto itself"))
                } else if removed_at[removed] || removed_at[kept] {
                    Some(format!("uses a removed vertex ({removed}, {kept})"))
                } else if !error.is_finite() || error < last_error {
                    Some(format!("error {error} is not finite or decreases"))
                } else {
                    None
                };
                if let Some(p) = problem {
                    step.pos = at;
                    return Err(step.error(format!("step {i} {p}")));
                }
                removed_at[removed] = true;
                if optimal {
                    removed_at[kept] = true;
                }
                last_error = error;
                list.push(Collapse {
                    removed: removed as u32,
                    kept: kept as u32,
                    error,
                });
            }
            step.finish()?;
            let companions = match cmpn {
                Some(mut r) => read_companions(&mut r, &list, vertices, optimal)?,
                None => Vec::new(),
            };
            let appended_positions = positions[vertices..].to_vec();
            // Version 3 stores the triangle counts with the model (read and
            // checked by `read_model`); earlier versions replay them.
            let counts = if let Some(m) = &modl {
                let lods = list.len() + 1;
                let triangles = strips.triangle_count() as u32;
                if modl_coded {
                    let tail = super::compress::modl_tail(m.clone())?;
                    let t = Reader::new(&tail, 0, "MODL tail, decoded", &m.file);
                    table_at_end(&t, lods, triangles)?
                } else {
                    table_at_end(m, lods, triangles)?
                }
            } else {
                replay_counts(&mesh, &list, optimal, &companions)
            };
            let collapses =
                Collapses::with_companions(vertices, list, counts, appended_positions, companions);
            Ok(Parsed {
                positions,
                modl,
                arrays: None,
                mesh,
                strips,
                collapses,
                options: BuildOptions {
                    band_slack,
                    stripify: StripifyOptions {
                        patches,
                        min_patch_quads,
                        swap_penalties,
                        join_ends,
                        cache_aware,
                    },
                },
            })
        })();
        let arrays = reading.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        rest.map(|mut p| {
            p.arrays = arrays
                .or_else(|| prefetched.map(|join| join()))
                .or_else(|| inline.map(arrays_of));
            p
        })
    })
}

/// The graph arrays of the `MODL` section, before they join the recipe.
pub(crate) struct Arrays {
    strip_records: Vec<u32>,
    strip_begins: Vec<u32>,
    begin_node: Vec<u32>,
    begin_res: Vec<u32>,
    rec_vertex: Narrow,
    rec_label: Narrow,
    rec_code: Vec<u8>,
    far: Vec<(u32, u32)>,
    slot_size: Vec<u32>,
    band_lod: Vec<u32>,
    band_strips: Vec<u32>,
}

/// Reads the `MODL` section's arrays for a model of `max_lod`
/// contractions. Every count is bounded by the bytes left before anything
/// is allocated; the structure is checked afterwards by
/// [`MtsModel::validate`].
fn read_arrays(mut r: Reader<'_>, max_lod: usize) -> Result<Arrays> {
    let head = read_head(&mut r, max_lod, None)?;
    let records = head.records;
    let mut narrow = |width: usize| -> Result<Narrow> {
        Ok(if width == 2 {
            Narrow::U16(
                r.take(2 * records)?
                    .chunks_exact(2)
                    .map(|b| u16::from_le_bytes([b[0], b[1]]))
                    .collect(),
            )
        } else {
            Narrow::U32(r.words(records)?)
        })
    };
    let rec_vertex = narrow(head.vertex_width)?;
    let rec_label = narrow(head.label_width)?;
    let rec_code = r.take(records)?.to_vec();
    let far = read_far(&mut r, head.far, max_lod)?;
    Ok(head.with_records(rec_vertex, rec_label, rec_code, far))
}

/// The arrays of a version-5 `MODL` section `m` (see [`super::compress`]):
/// the head decoded and checked first, then the codes, which say how many
/// records start a node; every other part's announced length is checked
/// against those counts before its array is allocated; the columns are
/// decoded straight into their arrays (the vertices on a second thread),
/// and the vertices of the records that start a node spread back over
/// every record (0 on a node's later records).
fn read_coded_arrays(mut m: Reader<'_>, max_lod: usize) -> Result<Arrays> {
    use super::compress::modl_parts;
    let parts = modl_parts(&mut m)?;
    let m = &m;
    let [counts, tables, vertices, labels, codes, tail] = &parts[..] else {
        return Err(m.error("part count"));
    };
    let mut head_bytes = counts.decode(m)?;
    head_bytes.extend_from_slice(&tables.decode(m)?);
    let mut h = Reader::new(&head_bytes, 0, "MODL head, decoded", &m.file);
    let head = read_head(
        &mut h,
        max_lod,
        Some((codes.decoded_len(), tail.decoded_len())),
    )?;
    let records = head.records;
    let (vw, lw) = (head.vertex_width, head.label_width);
    // The codes first: they say which records start a node, and so what
    // the vertices' part must hold, before the other arrays are allocated.
    let mut rec_code = vec![0u8; records];
    codes.decode_into(m, &mut rec_code, u8::from_le)?;
    let starts = match records {
        0 => 0,
        n => {
            1 + rec_code[..n - 1]
                .iter()
                .filter(|&&c| c & super::records::MORE == 0)
                .count()
        }
    };
    for (part, name, expected) in [
        (vertices, "vertices", vw * starts),
        (labels, "labels", lw * records),
    ] {
        if part.decoded_len() != expected as u64 {
            return Err(m.error(format!(
                "{name}: {} bytes announced, {expected} for {records} records of which \
                 {starts} start a node",
                part.decoded_len()
            )));
        }
    }
    /// Spreads the `starts` node vertices at the front of `v` over its
    /// records, backwards, so that a value moves to its record (never
    /// before its own index) before that index is written; a select, not a
    /// branch. `k` stays in range: it only falls below `v.len()` as node
    /// starts are met, and `starts` counts them all.
    fn spread<T: Copy + Default>(v: &mut [T], codes: &[u8], starts: usize) {
        let mut k = starts;
        for r in (0..v.len()).rev() {
            let s = r == 0 || codes[r - 1] & super::records::MORE == 0;
            k -= usize::from(s);
            let x = v[k.min(r)];
            v[r] = if s { x } else { T::default() };
        }
        debug_assert_eq!(k, 0);
    }
    let code = &rec_code;
    let (rec_vertex, rest) = std::thread::scope(|scope| {
        let vertex_part = scope.spawn(move || -> Result<Narrow> {
            Ok(if vw == 2 {
                let mut v = vec![0u16; records];
                vertices.decode_into(m, &mut v[..starts], u16::from_le)?;
                spread(&mut v, code, starts);
                Narrow::U16(v)
            } else {
                let mut v = vec![0u32; records];
                vertices.decode_into(m, &mut v[..starts], u32::from_le)?;
                spread(&mut v, code, starts);
                Narrow::U32(v)
            })
        });
        let rest = (|| -> Result<(Narrow, Vec<u8>)> {
            let rec_label = if lw == 2 {
                let mut v = vec![0u16; records];
                labels.decode_into(m, &mut v, u16::from_le)?;
                Narrow::U16(v)
            } else {
                let mut v = vec![0u32; records];
                labels.decode_into(m, &mut v, u32::from_le)?;
                Narrow::U32(v)
            };
            Ok((rec_label, tail.decode(m)?))
        })();
        let v = vertex_part
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (v, rest)
    });
    let (rec_vertex, (rec_label, tail)) = (rec_vertex?, rest?);
    let mut t = Reader::new(&tail, 0, "MODL tail, decoded", &m.file);
    let far = read_far(&mut t, head.far, max_lod)?;
    Ok(head.with_records(rec_vertex, rec_label, rec_code, far))
}

/// The counts, widths and `u32` arrays that start a `MODL` section.
struct Head {
    records: usize,
    far: usize,
    vertex_width: usize,
    label_width: usize,
    band_lod: Vec<u32>,
    band_strips: Vec<u32>,
    strip_records: Vec<u32>,
    strip_begins: Vec<u32>,
    slot_size: Vec<u32>,
    begin_node: Vec<u32>,
    begin_res: Vec<u32>,
}

impl Head {
    fn with_records(
        self,
        rec_vertex: Narrow,
        rec_label: Narrow,
        rec_code: Vec<u8>,
        far: Vec<(u32, u32)>,
    ) -> Arrays {
        Arrays {
            strip_records: self.strip_records,
            strip_begins: self.strip_begins,
            begin_node: self.begin_node,
            begin_res: self.begin_res,
            rec_vertex,
            rec_label,
            rec_code,
            far,
            slot_size: self.slot_size,
            band_lod: self.band_lod,
            band_strips: self.band_strips,
        }
    }
}

/// Reads a `MODL` section's head from `r`. Version 3 (`coded` `None`):
/// the counts must account for every byte of `r`, records and tail
/// included; version 5 (`coded`: the bytes the codes' and the tail's parts
/// announce): the head is its own part, the record count must be the
/// codes' bytes, the far arcs fit the tail, and the other parts are
/// checked by their reader.
fn read_head(r: &mut Reader<'_>, max_lod: usize, coded: Option<(u64, u64)>) -> Result<Head> {
    let records = coded.map(|c| c.0);
    let left = r.remaining() as u64;
    let strips = r.count("strip count", left / 12)?;
    let bands = r.count("band count", left / 8)?;
    let begins = r.count("beginning count", left / 8)?;
    let at = r.pos;
    let record_count = r.count("record count", records.unwrap_or(left / 3))?;
    if records.is_some_and(|n| n != record_count as u64) {
        r.pos = at;
        return Err(r.error(format!(
            "{record_count} records, {} bytes of codes",
            records.unwrap_or(0)
        )));
    }
    let far = r.count("far arc count", coded.map_or(left, |c| c.1) / 8)?;
    let mut width = |what: &str| -> Result<usize> {
        match r.u8()? {
            w @ (2 | 4) => Ok(usize::from(w)),
            w => {
                r.pos -= 1;
                Err(r.error(format!("{what} width {w}, not 2 or 4")))
            }
        }
    };
    let (vertex_width, label_width) = (width("vertex")?, width("label")?);
    let words = 4 * (2 * bands + 1 + 3 * (strips + 1) + 2 * begins) as u64 - 4;
    let needed = if records.is_some() {
        words
    } else {
        words
            + 4 * (2 * far + max_lod + 1) as u64
            + ((vertex_width + label_width + 1) * record_count) as u64
    };
    if needed != r.remaining() as u64 {
        return Err(r.error(format!(
            "{} bytes for {strips} strips, {bands} bands, {begins} beginnings, {record_count} \
             records, {far} far arcs and {} LoDs; {needed} expected",
            r.remaining(),
            max_lod + 1
        )));
    }
    Ok(Head {
        records: record_count,
        far,
        vertex_width,
        label_width,
        band_lod: r.words(bands)?,
        band_strips: r.words(bands + 1)?,
        strip_records: r.words(strips + 1)?,
        strip_begins: r.words(strips + 1)?,
        slot_size: r.words(strips)?,
        begin_node: r.words(begins)?,
        begin_res: r.words(begins)?,
    })
}

/// The far arcs and the LoD → triangle table (read by `parse`,
/// `table_at_end`) that end a `MODL` section, from `r`, which must end
/// there.
fn read_far(r: &mut Reader<'_>, far: usize, max_lod: usize) -> Result<Vec<(u32, u32)>> {
    let far_words = r.words(2 * far)?;
    let far = far_words.chunks_exact(2).map(|p| (p[0], p[1])).collect();
    r.take(4 * (max_lod + 1))?;
    r.finish()?;
    Ok(far)
}

/// The model of a version-3 file: its arrays with the recipe.
fn assemble(a: Arrays, parsed: Parsed<'_>) -> MtsModel {
    MtsModel {
        positions: parsed.positions,
        properties: parsed.mesh.properties,
        strip_records: a.strip_records,
        strip_begins: a.strip_begins,
        begin_node: a.begin_node,
        begin_res: a.begin_res,
        rec_vertex: a.rec_vertex,
        rec_label: a.rec_label,
        rec_code: a.rec_code,
        far: a.far,
        slot_size: a.slot_size,
        band_lod: a.band_lod,
        band_strips: a.band_strips,
        recipe: super::Recipe {
            strips: parsed.strips,
            collapses: parsed.collapses,
            options: parsed.options,
        },
    }
}

/// The LoD → triangle count table that ends the `MODL` section in `r`
/// (`lods` entries), checked to start at the strips' `triangles` and
/// never grow.
fn table_at_end(r: &Reader<'_>, lods: usize, triangles: u32) -> Result<Vec<u32>> {
    let mut t = r.clone();
    let Some(start) = t.bytes.len().checked_sub(4 * lods) else {
        return Err(t.error(format!(
            "{} bytes cannot end with a table of {lods} LoDs",
            t.bytes.len()
        )));
    };
    t.pos = start;
    let counts = t.words(lods)?;
    if counts[0] != triangles || counts.windows(2).any(|w| w[1] > w[0]) {
        t.pos = start;
        return Err(t.error(format!(
            "the LoD → triangle table does not start at the strips' {triangles} triangles \
             and fall"
        )));
    }
    Ok(counts)
}

/// The `PROP` section of `p`.
pub(crate) fn properties_payload(p: &crate::mesh::Properties) -> Vec<u8> {
    use crate::mesh::Texture;
    let flags = u8::from(p.normals.is_some())
        | u8::from(p.uvs.is_some()) << 1
        | u8::from(p.colors.is_some()) << 2
        | u8::from(!p.position_ids.is_empty()) << 3
        | u8::from(p.texture.is_some()) << 4;
    let mut out = vec![flags];
    let mut floats = |xs: &[f32]| {
        for x in xs {
            out.extend_from_slice(&x.to_le_bytes());
        }
    };
    for n in p.normals.iter().flatten() {
        floats(&n.to_array());
    }
    for t in p.uvs.iter().flatten() {
        floats(&t.to_array());
    }
    for c in p.colors.iter().flatten() {
        floats(&c.to_array());
    }
    for &id in &p.position_ids {
        put_varint(&mut out, u64::from(id));
    }
    let bytes = |b: &[u8], out: &mut Vec<u8>| {
        put_varint(out, b.len() as u64);
        out.extend_from_slice(b);
    };
    match &p.texture {
        Some(Texture::File(path)) => {
            out.push(0);
            bytes(path.to_string_lossy().as_bytes(), &mut out);
        }
        Some(Texture::Embedded { mime, bytes: image }) => {
            out.push(1);
            bytes(mime.as_bytes(), &mut out);
            bytes(image, &mut out);
        }
        None => {}
    }
    out
}

/// Reads and checks the `PROP` section for a mesh with `positions`.
pub(crate) fn read_properties(
    r: &mut Reader<'_>,
    positions: &[Vec3],
) -> Result<crate::mesh::Properties> {
    use crate::mesh::{Properties, Texture};
    use glam::{Vec2, Vec4};
    let n = positions.len();
    let at = r.pos;
    let flags = r.u8()?;
    if flags >= 32 {
        r.pos = at;
        return Err(r.error(format!("property flags {flags:#x}: unknown bits")));
    }
    let floats_per_vertex = 3 * usize::from(flags & 1 != 0)
        + 2 * usize::from(flags & 2 != 0)
        + 4 * usize::from(flags & 4 != 0);
    if floats_per_vertex * 4 * n > r.remaining() {
        return Err(r.error(format!(
            "{} bytes left, {} needed for the property streams of {n} vertices",
            r.remaining(),
            floats_per_vertex * 4 * n
        )));
    }
    let mut p = Properties::default();
    let read = |r: &mut Reader<'_>, k: usize| -> Result<Vec<[f32; 4]>> {
        (0..n)
            .map(|_| {
                let mut v = [0f32; 4];
                for x in v.iter_mut().take(k) {
                    *x = r.f32()?;
                }
                Ok(v)
            })
            .collect()
    };
    if flags & 1 != 0 {
        p.normals = Some(
            read(r, 3)?
                .iter()
                .map(|v| Vec3::new(v[0], v[1], v[2]))
                .collect(),
        );
    }
    if flags & 2 != 0 {
        p.uvs = Some(read(r, 2)?.iter().map(|v| Vec2::new(v[0], v[1])).collect());
    }
    if flags & 4 != 0 {
        p.colors = Some(read(r, 4)?.iter().map(|v| Vec4::from_array(*v)).collect());
    }
    if flags & 8 != 0 {
        if n > r.remaining() {
            return Err(r.error(format!("{} bytes left for {n} position ids", r.remaining())));
        }
        p.position_ids = (0..n)
            .map(|_| r.count("position id", n as u64).map(|v| v as u32))
            .collect::<Result<_>>()?;
    }
    if flags & 16 != 0 {
        let kind = r.u8()?;
        let bytes = |r: &mut Reader<'_>, what: &str| -> Result<Vec<u8>> {
            let len = r.count(what, r.remaining() as u64)?;
            Ok(r.take(len)?.to_vec())
        };
        p.texture = Some(match kind {
            0 => Texture::File(
                String::from_utf8_lossy(&bytes(r, "texture path length")?)
                    .into_owned()
                    .into(),
            ),
            1 => Texture::Embedded {
                mime: String::from_utf8_lossy(&bytes(r, "MIME type length")?).into_owned(),
                bytes: bytes(r, "texture length")?,
            },
            k => {
                r.pos -= 1;
                return Err(r.error(format!("texture kind {k}, not 0 (file) or 1 (embedded)")));
            }
        });
    }
    let start = r.base;
    r.finish()?;
    p.validate(positions)
        .map_err(|m| parse_error(&r.file, start, "PROP", m))?;
    Ok(p)
}

/// Reads and checks the `CMPN` section: each step's companion moves,
/// replayed with the steps so that no vertex is removed twice or used
/// after its removal.
fn read_companions(
    r: &mut Reader<'_>,
    steps: &[Collapse],
    vertices: usize,
    optimal: bool,
) -> Result<Vec<Vec<(u32, u32)>>> {
    let mut removed_at = vec![false; vertices];
    // Steps without companions past the last one with some get no list
    // (a mesh without seams has none at all).
    let mut out: Vec<Vec<(u32, u32)>> = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        if !optimal {
            // Checked against the earlier steps' companions too.
            if removed_at[s.removed as usize] || removed_at[s.kept as usize] {
                return Err(r.error(format!(
                    "step {i} uses a vertex an earlier companion removed"
                )));
            }
            removed_at[s.removed as usize] = true;
        }
        let count = r.count("companion count", (r.remaining() / 2) as u64)?;
        if count > 0 && optimal {
            return Err(r.error(format!("step {i}: companions with optimal placement")));
        }
        let mut moves = Vec::with_capacity(count);
        for _ in 0..count {
            let at = r.pos;
            let removed = r.count("removed vertex", vertices as u64 - 1)?;
            let kept = r.count("kept vertex", vertices as u64 - 1)?;
            if removed == kept || removed_at[removed] || removed_at[kept] {
                r.pos = at;
                return Err(r.error(format!(
                    "step {i}: companion ({removed}, {kept}) uses a removed vertex"
                )));
            }
            removed_at[removed] = true;
            moves.push((removed as u32, kept as u32));
        }
        if !moves.is_empty() {
            out.resize_with(i, Vec::new);
            out.push(moves);
        }
    }
    r.finish()?;
    Ok(out)
}

pub(crate) fn flag(r: &mut Reader<'_>, what: &str) -> Result<bool> {
    match r.u8()? {
        0 => Ok(false),
        1 => Ok(true),
        b => {
            r.pos -= 1;
            Err(r.error(format!("{what} flag is {b}, not 0 or 1")))
        }
    }
}

/// The triangle count after each step of a checked sequence: triangles of
/// each vertex in per-vertex lists, moved onto the target as it replaces
/// the vertex. O(triangles + moved entries).
pub(crate) fn replay_counts(
    mesh: &Mesh,
    steps: &[Collapse],
    optimal: bool,
    companions: &[Vec<(u32, u32)>],
) -> Vec<u32> {
    let total = mesh.vertex_count() + if optimal { steps.len() } else { 0 };
    let mut tris = mesh.triangles.clone();
    let mut of: Vec<Vec<u32>> = vec![Vec::new(); total];
    for (t, tri) in tris.iter().enumerate() {
        for &v in tri {
            of[v as usize].push(t as u32);
        }
    }
    let mut alive = vec![true; tris.len()];
    let mut count = tris.len() as u32;
    let mut counts = Vec::with_capacity(steps.len() + 1);
    counts.push(count);
    let mut moves = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        moves.clear();
        if optimal {
            let target = (mesh.vertex_count() + i) as u32;
            moves.extend([(s.removed, target), (s.kept, target)]);
        } else {
            moves.push((s.removed, s.kept));
        }
        moves.extend(companions.get(i).into_iter().flatten().copied());
        for &(v, target) in &moves {
            let list = std::mem::take(&mut of[v as usize]);
            for &t in &list {
                if !alive[t as usize] {
                    continue;
                }
                let tri = &mut tris[t as usize];
                for x in tri.iter_mut() {
                    if *x == v {
                        *x = target;
                    }
                }
                if crate::mesh::is_degenerate(*tri) {
                    alive[t as usize] = false;
                    count -= 1;
                } else {
                    of[target as usize].push(t);
                }
            }
        }
        counts.push(count);
    }
    counts
}

pub(crate) fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

pub(crate) fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

pub(crate) fn unzigzag(v: u64) -> i64 {
    ((v >> 1) as i64) ^ -((v & 1) as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_and_zigzag_round_trip() {
        for v in [
            0i64,
            1,
            -1,
            63,
            -64,
            1 << 40,
            -(1 << 40),
            i64::from(u32::MAX),
        ] {
            let mut b = Vec::new();
            put_varint(&mut b, zigzag(v));
            let mut r = Reader {
                bytes: &b,
                pos: 0,
                base: 0,
                section: "t",
                file: PathBuf::from("t"),
            };
            assert_eq!(unzigzag(r.varint().unwrap()), v);
            r.finish().unwrap();
        }
        let long = [0xffu8; 11];
        let mut r = Reader {
            bytes: &long,
            pos: 0,
            base: 0,
            section: "t",
            file: PathBuf::from("t"),
        };
        assert!(r.varint().is_err());
    }
}
