//! The streamed `.mts` file (version 6): coarse LoDs first, so that a
//! prefix of the file opens.
//!
//! **Decision: a prefix holds whole recipes of coarse LoDs, built when
//! opened; the ready arrays stay where version 5 has them.** A version-6
//! file is a version-5 file ([`super::compress`]) with `PRFX` sections
//! (chunks) between its header and its `META`, coarsest first. A chunk
//! at LoD `L` is the recipe of the model of LoDs `L..=max_lod`: the mesh
//! at `L` (its live vertices only, renumbered in order, with their
//! properties), its strips, and the steps after `L`, as a version-1 or 2
//! file, coded as one part. Opening a prefix builds the finest chunk it
//! holds whole ([`MtsModel::from_prefix`]): the chunk's LoD `k` is the
//! file's LoD `L + k`, the same triangles (the tests check it), in strips
//! made for that mesh. Why not the ready arrays by LoD, as the issue
//! first pictured: the model's types, its extractor and its loader's trust
//! (the ready walk against the recipe's replay from LoD 0) all assume
//! LoD 0 is present, and a coarse model is cheap to build (a tenth of
//! the bunny's triangles builds in tens of milliseconds), so a recipe per
//! chunk costs a few percent of the file (`docs/experiments/
//! compressed-file.md` measures it) and no change to the model. The whole
//! file loads as version 5 and skips the chunks; `mts verify` checks
//! them against the whole model.
//!
//! Chunk payload (one part, [`super::compress`], coded unless that does
//! not shrink it): varints the first LoD `L` (at least 1), the whole
//! model's triangle count, its triangle count at LoD `L − 1` (so a reader
//! knows whether a budget asks for a LoD the chunk lacks); a flags byte
//! (bit 0: the model's texture is the first chunk's); the chunk's vertex
//! count `n`, then `n` vertex numbers of the whole model (the first, then
//! each as its difference from the previous less one: strictly
//! increasing), then the recipe file. An embedded texture is held by the
//! first chunk only (and by the whole file's `PROP`); a later chunk
//! opened alone builds the first too, for its texture, when its flag says
//! so.
//!
//! Memory: a chunk may decode to at most `MAX_EXPANSION` (1,024) × its own
//! bytes, checked before it is decoded, and one chunk is decoded at a
//! time; with the version-5 sections' own bound the whole file asks for
//! at most twice `MAX_EXPANSION` (1,024) × its bytes.
//!
//! A sequence with optimal placement (created vertices) gets no chunks:
//! a chunk's vertices are input vertices.

use super::compress::{check_expansion_of, only_part, pack_one};
use super::format::{
    file_version, parse_error, put_varint, Reader, COMPRESSED_VERSION, HEADER_LEN, MAGIC, VERSION,
};
use super::{build, MtsModel};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::simplify::{Collapse, Collapses};
use crate::strip::stripify;
use std::ops::RangeInclusive;
use std::path::Path;

/// The version of the streamed file: version 5 with coarse chunks first.
pub const STREAMED_VERSION: u32 = 6;
/// The shares of the input's triangles at which `mts build` writes chunks
/// by default: 1% and 10% (about 4% of the file on the bunny).
pub const DEFAULT_PREFIX_SHARES: [f64; 2] = [0.01, 0.1];
/// Most chunks a file may hold.
pub const MAX_PREFIXES: usize = 16;
/// The tag of a chunk's section.
pub(crate) const PREFIX_TAG: &[u8; 4] = b"PRFX";

/// What a prefix of an `.mts` file opens as ([`MtsModel::from_prefix`]).
#[derive(Debug)]
pub struct Prefix {
    /// The model: the whole file's, or a chunk's, whose LoD `k` is the
    /// file's LoD `first_lod + k`.
    pub model: MtsModel,
    /// The file's LoD that is the model's LoD 0.
    pub first_lod: usize,
    /// The whole model's triangle count at LoD 0.
    pub full_triangles: usize,
    /// The whole model's triangle count at LoD `first_lod − 1`, the
    /// finest LoD the prefix lacks (0 for the whole file): a budget of at
    /// least this many triangles asks for a LoD it does not hold.
    pub finer_triangles: usize,
    /// For a chunk, the whole model's number of each of the model's
    /// vertices; empty when the whole file was read.
    pub vertex_ids: Vec<u32>,
    /// Bytes of the prefix read: the end of the chunk, or the file.
    pub bytes_used: usize,
    /// The file's length as its header declares it.
    pub file_bytes: u64,
    whole: bool,
}

impl Prefix {
    /// Whether the whole file was read (every LoD, the ready model).
    #[must_use]
    pub fn is_whole(&self) -> bool {
        self.whole
    }

    /// Whether the prefix holds the LoD the whole file would draw within
    /// `budget` triangles.
    #[must_use]
    pub fn holds_budget(&self, budget: usize) -> bool {
        self.whole || budget < self.finer_triangles
    }

    /// The file's LoDs the prefix can draw.
    #[must_use]
    pub fn lods_available(&self) -> RangeInclusive<usize> {
        self.first_lod..=self.first_lod + self.model.max_lod()
    }

    /// The model's LoD for the file's `lod`, clamped to what the prefix
    /// holds (a finer LoD than it holds draws its first).
    #[must_use]
    pub fn model_lod(&self, lod: usize) -> usize {
        let r = self.lods_available();
        lod.clamp(*r.start(), *r.end()) - self.first_lod
    }

    /// The file's LoD with at most `budget` triangles, among those the
    /// prefix holds (its last when even that has more; its first when the
    /// whole file would draw a finer one, [`Prefix::holds_budget`]).
    #[must_use]
    pub fn lod_for_triangles(&self, budget: usize) -> usize {
        self.first_lod + self.model.lod_for_triangles(budget)
    }

    /// The whole model's number of the model's vertex `v`.
    #[must_use]
    pub fn file_vertex(&self, v: u32) -> u32 {
        if self.vertex_ids.is_empty() {
            v
        } else {
            self.vertex_ids[v as usize]
        }
    }
}

/// The recipe model of `model`'s LoDs `lod..=max_lod` and each of its
/// vertices' number in `model` (`full` is `model.mesh()`); `None` for a
/// sequence with optimal placement (see the module docs).
pub(crate) fn coarse_model(
    model: &MtsModel,
    full: &Mesh,
    lod: usize,
) -> Option<(MtsModel, Vec<u32>)> {
    let c = model.collapses();
    if c.is_optimal_placement() || lod > c.max_lod() {
        return None;
    }
    let n = c.vertex_count();
    // Live at `lod`: never removed by its first `lod` steps (companions
    // included), so the later steps name only these.
    let alive: Vec<u32> = (0..n as u32)
        .filter(|&v| c.parent_from_lod[v as usize] as usize > lod)
        .collect();
    let mut new_id = vec![u32::MAX; n];
    for (i, &v) in alive.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    let triangles = c
        .triangles_at(full, lod)
        .into_iter()
        .map(|t| t.map(|v| new_id[v as usize]))
        .collect();
    let mut properties = model.properties().gather(&alive);
    properties.texture = model.properties().texture.clone();
    let mesh = Mesh {
        positions: alive.iter().map(|&v| full.positions[v as usize]).collect(),
        triangles,
        properties,
    };
    let steps: Vec<Collapse> = c.steps()[lod..]
        .iter()
        .map(|s| Collapse {
            removed: new_id[s.removed as usize],
            kept: new_id[s.kept as usize],
            error: s.error,
        })
        .collect();
    let companions: Vec<Vec<(u32, u32)>> = (lod..c.max_lod())
        .map(|i| {
            c.companions(i)
                .map(|(r, k)| (new_id[r as usize], new_id[k as usize]))
                .collect()
        })
        .collect();
    let collapses = Collapses::with_companions(
        alive.len(),
        steps,
        c.triangle_counts()[lod..].to_vec(),
        Vec::new(),
        companions,
    );
    let options = model.build_options();
    let strips = stripify(&mesh, &options.stripify);
    let coarse = build(&mesh, &strips, &collapses, options);
    debug_assert_eq!(coarse.triangle_count(0), model.triangle_count(lod));
    Some((coarse, alive))
}

/// The chunks of `model` at `shares` of its triangles, coarsest first,
/// each a `PRFX` payload coded at `level`: none at LoD 0 (the whole file
/// is that) and one per distinct LoD.
pub(crate) fn chunks(model: &MtsModel, shares: &[f64], level: i32) -> Vec<Vec<u8>> {
    let mut lods: Vec<usize> = shares
        .iter()
        .map(|&s| model.lod_for_ratio(s))
        .filter(|&l| l > 0)
        .collect();
    lods.sort_unstable_by(|a, b| b.cmp(a));
    lods.dedup();
    lods.truncate(MAX_PREFIXES);
    if model.collapses().is_optimal_placement() {
        return Vec::new();
    }
    // The whole mesh once: each chunk replays it to its LoD.
    let full = model.mesh();
    let mut out = Vec::with_capacity(lods.len());
    for (i, lod) in lods.into_iter().enumerate() {
        let Some((mut coarse, ids)) = coarse_model(model, &full, lod) else {
            return Vec::new();
        };
        if i > 0 {
            // The first chunk holds the texture (see the module docs).
            coarse.properties.texture = None;
        }
        let mut data = Vec::new();
        for x in [lod, model.triangle_count(0), model.triangle_count(lod - 1)] {
            put_varint(&mut data, x as u64);
        }
        let texture_in_first = i > 0 && model.properties().texture.is_some();
        data.push(u8::from(texture_in_first));
        put_varint(&mut data, ids.len() as u64);
        let mut prev = 0u32;
        for (j, &v) in ids.iter().enumerate() {
            put_varint(&mut data, u64::from(if j == 0 { v } else { v - prev - 1 }));
            prev = v;
        }
        data.extend_from_slice(&coarse.to_recipe_bytes());
        out.push(pack_one(&data, level));
    }
    out
}

/// A chunk's section: where its payload starts in the file, and the
/// payload.
struct ChunkAt<'a> {
    at: usize,
    payload: &'a [u8],
}

/// The chunks of a version-6 file held whole in `bytes` (a prefix of the
/// file, or all of it), in file order; the header's magic and version
/// must have been checked.
fn whole_chunks<'a>(bytes: &'a [u8], file: &Path) -> Result<Vec<ChunkAt<'a>>> {
    let declared = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
    let Some(count) = declared
        .checked_sub(super::format::TAGS.len())
        .filter(|&c| c <= MAX_PREFIXES)
    else {
        return Err(parse_error(
            file,
            12,
            "header",
            format!(
                "{declared} sections: version {STREAMED_VERSION} has {} to {}",
                super::format::TAGS.len(),
                super::format::TAGS.len() + MAX_PREFIXES
            ),
        ));
    };
    let mut out = Vec::with_capacity(count);
    let mut pos = HEADER_LEN;
    for i in 0..count {
        let Some(head) = bytes.get(pos..pos + 12) else {
            break;
        };
        if &head[..4] != PREFIX_TAG {
            return Err(parse_error(
                file,
                pos,
                "section table",
                format!(
                    "section {i} is {:?}, expected \"PRFX\"",
                    String::from_utf8_lossy(&head[..4])
                ),
            ));
        }
        let mut len = [0u8; 8];
        len.copy_from_slice(&head[4..]);
        let len = u64::from_le_bytes(len);
        let start = pos + 12;
        let Some(end) = usize::try_from(len)
            .ok()
            .and_then(|l| start.checked_add(l))
            .filter(|&e| e <= bytes.len())
        else {
            break;
        };
        out.push(ChunkAt {
            at: start,
            payload: &bytes[start..end],
        });
        pos = end;
    }
    Ok(out)
}

/// Checks the chunks of a whole version-6 file that loaded as `model`,
/// without building them: each decodes (within `MAX_EXPANSION` × its
/// bytes) to its first LoD (at most `model`'s last), the model's triangle
/// count, strictly increasing vertex numbers of `model`, and a recipe
/// file whose header, length and checksum hold. So a corrupt chunk makes
/// the file corrupt; whether a chunk draws the model's triangles is
/// `mts verify`'s ([`Prefix::check_against`]). About a millisecond for
/// the bunny's.
pub(crate) fn check_chunks(chunks: &[Reader<'_>], file: &Path, model: &MtsModel) -> Result<()> {
    for (i, r) in chunks.iter().enumerate() {
        let c = ChunkAt {
            at: r.base,
            payload: r.bytes,
        };
        let data = decode_chunk(i, &c, file)?;
        let mut d = Reader::new(&data, 0, DECODED_NAMES[i], file);
        let head = ChunkHead::read(&mut d)?;
        let lod = head.first_lod;
        let full = model.triangle_count(0);
        let finer = model.triangle_count(lod.saturating_sub(1));
        if lod > model.max_lod() || head.full_triangles != full || head.finer_triangles != finer {
            return Err(d.error(format!(
                "a chunk from LoD {lod} of a model of {} triangles ({} at LoD {}), the \
                 file's has {} LoDs and {full} triangles ({finer})",
                head.full_triangles,
                head.finer_triangles,
                lod.saturating_sub(1),
                model.max_lod() + 1
            )));
        }
        if let Some(&last) = head.ids.last() {
            if last as usize >= model.collapses().vertex_count() {
                return Err(d.error(format!("vertex number {last} past the model's")));
            }
        }
        super::format::check_header(
            &data[head.recipe_at..],
            file,
            super::format::Holds::Model,
            super::format::section_count,
        )
        .map_err(|e| d.error(format!("the chunk's recipe: {e}")))?;
    }
    Ok(())
}

/// The names of chunk `i`'s section and of its decoded bytes in errors.
const CHUNK_NAMES: [&str; MAX_PREFIXES] = [
    "PRFX 0", "PRFX 1", "PRFX 2", "PRFX 3", "PRFX 4", "PRFX 5", "PRFX 6", "PRFX 7", "PRFX 8",
    "PRFX 9", "PRFX 10", "PRFX 11", "PRFX 12", "PRFX 13", "PRFX 14", "PRFX 15",
];
const DECODED_NAMES: [&str; MAX_PREFIXES] = [
    "PRFX 0, decoded",
    "PRFX 1, decoded",
    "PRFX 2, decoded",
    "PRFX 3, decoded",
    "PRFX 4, decoded",
    "PRFX 5, decoded",
    "PRFX 6, decoded",
    "PRFX 7, decoded",
    "PRFX 8, decoded",
    "PRFX 9, decoded",
    "PRFX 10, decoded",
    "PRFX 11, decoded",
    "PRFX 12, decoded",
    "PRFX 13, decoded",
    "PRFX 14, decoded",
    "PRFX 15, decoded",
];

/// A decoded chunk's fields before its recipe (see the module docs).
struct ChunkHead {
    first_lod: usize,
    full_triangles: usize,
    finer_triangles: usize,
    texture_in_first: bool,
    ids: Vec<u32>,
    /// Where the recipe file starts.
    recipe_at: usize,
}

impl ChunkHead {
    /// Reads the head from `d` (places in errors are offsets in the
    /// decoded chunk); the recipe must be a version-1 or 2 file.
    fn read(d: &mut Reader<'_>) -> Result<ChunkHead> {
        let max = u64::from(u32::MAX);
        let at = d.pos;
        let first_lod = d.count("first LoD", max)?;
        if first_lod == 0 {
            d.pos = at;
            return Err(d.error("a chunk from LoD 0 (the whole file is that)"));
        }
        let full_triangles = d.count("triangle count", max)?;
        let finer_triangles = d.count("triangle count at the LoD before", max)?;
        let flags = d.u8()?;
        if flags > 1 {
            return Err(d.error(format!("flags {flags:#04x}, only bit 0 is defined")));
        }
        let n = d.count("vertex count", d.remaining() as u64)?;
        let mut ids = Vec::with_capacity(n);
        let mut next = 0u64;
        for _ in 0..n {
            let v = next.checked_add(d.varint()?).filter(|&v| v <= max);
            let Some(v) = v else {
                return Err(d.error("a vertex number past 32 bits"));
            };
            ids.push(v as u32);
            next = v + 1;
        }
        let recipe_at = d.pos;
        let version = file_version(&d.bytes[recipe_at..]);
        if !matches!(version, Some(1 | 2)) {
            return Err(d.error(format!(
                "holds {}, not a recipe (version 1 or 2)",
                version.map_or("no .mts file".into(), |v| format!("a version-{v} file"))
            )));
        }
        Ok(ChunkHead {
            first_lod,
            full_triangles,
            finer_triangles,
            texture_in_first: flags & 1 == 1,
            ids,
            recipe_at,
        })
    }
}

/// A chunk's part decoded, within `MAX_EXPANSION` × its bytes.
fn decode_chunk(i: usize, chunk: &ChunkAt<'_>, file: &Path) -> Result<Vec<u8>> {
    let section = Reader::new(chunk.payload, chunk.at, CHUNK_NAMES[i], file);
    check_expansion_of(
        std::slice::from_ref(&section),
        false,
        chunk.payload.len(),
        "the chunk's",
    )?;
    let (r, part) = only_part(&section)?;
    part.decode(&r)
}

/// Decodes and builds chunk `i` of a file of `file_bytes`; with the
/// flag that its texture is the first chunk's.
fn open_chunk(
    i: usize,
    chunk: &ChunkAt<'_>,
    file: &Path,
    file_bytes: u64,
) -> Result<(Prefix, bool)> {
    let data = decode_chunk(i, chunk, file)?;
    let mut d = Reader::new(&data, 0, DECODED_NAMES[i], file);
    let head = ChunkHead::read(&mut d)?;
    let n = head.ids.len();
    // The recipe's own places are relative to its start, which the
    // message gives.
    let at = head.recipe_at;
    let model = MtsModel::from_bytes(&data[at..], file).map_err(|e| match e {
        Error::Parse { place, message, .. } => d.error(format!(
            "the chunk's recipe (from byte {at} of the decoded chunk), its byte {} ({}): \
             {message}",
            place.byte.unwrap_or(0),
            place.element.as_deref().unwrap_or("?")
        )),
        other => other,
    })?;
    if model.collapses().vertex_count() != n {
        return Err(d.error(format!(
            "{n} vertex numbers for a recipe of {} vertices",
            model.collapses().vertex_count()
        )));
    }
    let (first_lod, full) = (head.first_lod, head.full_triangles);
    if model.triangle_count(0) > full
        || head.finer_triangles > full
        || head.finer_triangles < model.triangle_count(0)
        || first_lod.checked_add(model.max_lod()).is_none()
    {
        return Err(d.error(format!(
            "a chunk of {} triangles from LoD {first_lod} ({} at the LoD before), for a \
             model of {full}",
            model.triangle_count(0),
            head.finer_triangles
        )));
    }
    let prefix = Prefix {
        model,
        first_lod,
        full_triangles: full,
        finer_triangles: head.finer_triangles,
        vertex_ids: head.ids,
        bytes_used: chunk.at + chunk.payload.len(),
        file_bytes,
        whole: false,
    };
    Ok((prefix, head.texture_in_first))
}

/// Where a chunk of a version-6 file ends and its first LoD: what a
/// reader that fetches a file piece by piece needs to know to ask for
/// the bytes of a LoD ([`chunk_index`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chunk {
    /// The file's LoD that the chunk's model starts at.
    pub first_lod: usize,
    /// The byte after the chunk: a prefix of this many bytes opens it.
    pub end: usize,
}

/// The chunks of a whole version-6 file, coarsest first (each decoded as
/// far as its first LoD, not built); empty for another version.
///
/// # Errors
/// As [`MtsModel::from_prefix`] for a corrupt chunk's start.
pub fn chunk_index(bytes: &[u8], file: &Path) -> Result<Vec<Chunk>> {
    if file_version(bytes) != Some(STREAMED_VERSION) || bytes.len() < HEADER_LEN {
        return Ok(Vec::new());
    }
    whole_chunks(bytes, file)?
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let data = decode_chunk(i, c, file)?;
            let mut d = Reader::new(&data, 0, DECODED_NAMES[i], file);
            Ok(Chunk {
                first_lod: ChunkHead::read(&mut d)?.first_lod,
                end: c.at + c.payload.len(),
            })
        })
        .collect()
}

/// The bytes of a file of `file_len` bytes with `chunks` that a reader
/// needs to draw `lod`: the end of the first chunk that holds it, or the
/// whole file.
#[must_use]
pub fn bytes_for_lod(chunks: &[Chunk], file_len: usize, lod: usize) -> usize {
    chunks
        .iter()
        .find(|c| c.first_lod <= lod)
        .map_or(file_len, |c| c.end)
}

impl MtsModel {
    /// The model as a streamed `.mts` file (version [`STREAMED_VERSION`]):
    /// [`MtsModel::to_compressed_bytes`] with chunks of the coarse LoDs at
    /// `shares` of the triangles first (none for an empty `shares`, or a
    /// sequence with optimal placement: then the version-5 file), so that
    /// a prefix opens ([`MtsModel::from_prefix`]).
    #[must_use]
    pub fn to_streamed_bytes(&self, level: i32, shares: &[f64]) -> Vec<u8> {
        let chunks = chunks(self, shares, level);
        if chunks.is_empty() {
            return self.to_compressed_bytes(level);
        }
        let mut body = Vec::new();
        let count = chunks.len();
        super::format::put_sections(&mut body, chunks.into_iter().map(|c| (PREFIX_TAG, c)));
        let sections = self.coded_sections(level);
        let total = count + sections.len();
        super::format::put_sections(&mut body, sections);
        super::format::seal_body(STREAMED_VERSION, total, &body)
    }

    /// Opens the first bytes of an `.mts` file: the whole model when they
    /// are the whole file (any model version), else the finest chunk of a
    /// version-6 file they hold whole ([`Prefix`]), built.
    ///
    /// # Errors
    /// As [`MtsModel::from_bytes`] for a whole file; for a part of one,
    /// [`Error::Parse`] when it holds no whole chunk (naming the bytes the
    /// first needs) or is not of version 6, or a chunk is corrupt.
    pub fn from_prefix(bytes: &[u8], file: &Path) -> Result<Prefix> {
        let declared = (bytes.len() >= HEADER_LEN && &bytes[..8] == MAGIC).then(|| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&bytes[16..24]);
            u64::from_le_bytes(a)
        });
        let version = file_version(bytes);
        if declared.is_none() && MAGIC.starts_with(&bytes[..bytes.len().min(8)]) {
            return Err(parse_error(
                file,
                bytes.len(),
                "header",
                format!(
                    "{} bytes: the {HEADER_LEN}-byte header has not arrived; a version-\
                     {STREAMED_VERSION} file opens once its first chunk has",
                    bytes.len()
                ),
            ));
        }
        let whole = declared.is_none_or(|d| d <= bytes.len() as u64);
        if whole {
            let model = MtsModel::from_bytes(bytes, file)?;
            return Ok(Prefix {
                full_triangles: model.triangle_count(0),
                finer_triangles: 0,
                model,
                first_lod: 0,
                vertex_ids: Vec::new(),
                bytes_used: bytes.len(),
                file_bytes: bytes.len() as u64,
                whole: true,
            });
        }
        let file_bytes = declared.unwrap_or(0);
        if version != Some(STREAMED_VERSION) {
            return Err(parse_error(
                file,
                bytes.len(),
                "file",
                format!(
                    "{} of the {file_bytes} bytes: a version-{} file opens only whole \
                     (version {STREAMED_VERSION}, what `mts build` writes, opens from its \
                     first chunk; versions {VERSION} and {COMPRESSED_VERSION} do not stream)",
                    bytes.len(),
                    version.unwrap_or(0)
                ),
            ));
        }
        let chunks = whole_chunks(bytes, file)?;
        let Some(last) = chunks.last() else {
            // Where the first section ends, when its header has arrived.
            let first_end = bytes.get(HEADER_LEN..HEADER_LEN + 12).map(|h| {
                let mut a = [0u8; 8];
                a.copy_from_slice(&h[4..]);
                (HEADER_LEN as u64 + 12).saturating_add(u64::from_le_bytes(a))
            });
            return Err(parse_error(
                file,
                bytes.len(),
                "file",
                format!(
                    "{} of the {file_bytes} bytes hold no whole chunk ({}; a file without \
                     chunks opens only whole)",
                    bytes.len(),
                    first_end.map_or(
                        format!(
                            "the first section's 12-byte header ends at byte {}",
                            HEADER_LEN + 12
                        ),
                        |e| format!("its first section ends at byte {e}")
                    )
                ),
            ));
        };
        let (mut prefix, texture_in_first) = open_chunk(chunks.len() - 1, last, file, file_bytes)?;
        if texture_in_first && chunks.len() > 1 {
            let (first, _) = open_chunk(0, &chunks[0], file, file_bytes)?;
            prefix.model.properties.texture = first.model.properties.texture;
        }
        Ok(prefix)
    }

    /// The chunks of a whole version-6 file, each opened as
    /// [`MtsModel::from_prefix`] would (coarsest first); empty for
    /// another version. What `mts verify` checks against the whole model
    /// ([`Prefix::check_against`]).
    ///
    /// # Errors
    /// As [`MtsModel::from_prefix`] for a corrupt chunk.
    pub fn prefixes_of(bytes: &[u8], file: &Path) -> Result<Vec<Prefix>> {
        if file_version(bytes) != Some(STREAMED_VERSION) || bytes.len() < HEADER_LEN {
            return Ok(Vec::new());
        }
        let file_bytes = bytes.len() as u64;
        whole_chunks(bytes, file)?
            .iter()
            .enumerate()
            .map(|(i, c)| Ok(open_chunk(i, c, file, file_bytes)?.0))
            .collect()
    }
}

impl Prefix {
    /// Checks that the chunk draws the whole model's triangles at each of
    /// `lods` (file LoDs, clamped to what the chunk holds): the same
    /// triangles (as sets, each facing the same way) in the whole model's
    /// vertices.
    ///
    /// # Errors
    /// A message naming the LoD and the counts.
    pub fn check_against(
        &self,
        whole: &MtsModel,
        lods: &[usize],
    ) -> std::result::Result<(), String> {
        if whole.triangle_count(0) != self.full_triangles {
            return Err(format!(
                "the chunk is of a model of {} triangles, the file's has {}",
                self.full_triangles,
                whole.triangle_count(0)
            ));
        }
        if *self.lods_available().end() != whole.max_lod() {
            return Err(format!(
                "the chunk's LoDs end at {}, the file's at {}",
                self.lods_available().end(),
                whole.max_lod()
            ));
        }
        let mut ours = super::Extractor::new(&self.model);
        let mut theirs = super::Extractor::new(whole);
        for &lod in lods {
            let lod = lod.clamp(self.first_lod, whole.max_lod());
            ours.set_lod(lod - self.first_lod);
            theirs.set_lod(lod);
            // The same triangle, facing the same way, from its least vertex.
            let canonical = |t: [u32; 3]| {
                let i = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
                [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
            };
            let mut a: Vec<[u32; 3]> = ours
                .triangles()
                .into_iter()
                .map(|t| canonical(t.map(|v| self.file_vertex(v))))
                .collect();
            let mut b: Vec<[u32; 3]> = theirs.triangles().into_iter().map(canonical).collect();
            a.sort_unstable();
            b.sort_unstable();
            if a != b {
                return Err(format!(
                    "at LoD {lod} the chunk from LoD {} draws {} triangles, the file {} \
                     (or other ones)",
                    self.first_lod,
                    a.len(),
                    b.len()
                ));
            }
        }
        Ok(())
    }
}
