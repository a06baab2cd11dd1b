//! The `.mts` file: a versioned little-endian binary format.
//!
//! **Decision: the file stores what the graphs are built from, not the
//! graphs.** The graphs are a deterministic function of the LoD-0 strips,
//! the contraction sequence and the build options ([`super::build`]), and
//! building them costs O(strip changes), about the time of reading them.
//! Stored explicitly (the paper's way) the bunny's graphs with their bands
//! take about 20 bytes per triangle on top of the vertices; stored as their
//! inputs the whole file is under the raw mesh size. So the loader
//! validates every count, index and label of the inputs and then builds.
//!
//! Layout (all integers little-endian):
//!
//! ```text
//! header   magic "MTSMODEL" | version u32 | section count u32 | file length u64 | checksum u64
//! section  tag [u8; 4] | payload length u64 | payload
//! ```
//!
//! The checksum is FNV-1a (64 bit) of every byte after the header. Sections,
//! in this order:
//! - `META`: varints vertex count, appended vertex count, run count, strip
//!   index count, step count; then band slack (f64), the band stripifier's
//!   options (patches u8, min patch quads varint, two swap penalties as f32
//!   with NaN for none, join ends u8), optimal placement u8.
//! - `POSI`: `3 × f32` per vertex (input vertices, then appended ones).
//! - `STRP`: each run's length (varint), then every index as a zigzag
//!   varint of its difference from the previous index.
//! - `STEP`: per contraction: removed (varint), kept (varint), error (f32).
//!
//! Every count is checked against the bytes that must hold it before
//! anything is allocated, so a corrupt file costs at most its own size.

use super::{build, BuildOptions, MtsModel};
use crate::error::{Error, Place, Result};
use crate::mesh::Mesh;
use crate::simplify::{Collapse, Collapses};
use crate::strip::{StripifyOptions, Strips};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The file's first bytes.
pub const MAGIC: &[u8; 8] = b"MTSMODEL";
/// The version this crate writes and reads.
pub const VERSION: u32 = 1;
const HEADER_LEN: usize = 32;
const TAGS: [&[u8; 4]; 4] = [b"META", b"POSI", b"STRP", b"STEP"];

impl MtsModel {
    /// The model as `.mts` bytes.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
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
        meta.push(u8::from(so.join_ends));
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

        let mut body = Vec::new();
        for (tag, payload) in TAGS.iter().zip([meta, posi, strp, step]) {
            body.extend_from_slice(*tag);
            body.extend_from_slice(&(payload.len() as u64).to_le_bytes());
            body.extend_from_slice(&payload);
        }
        let mut out = Vec::with_capacity(HEADER_LEN + body.len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(TAGS.len() as u32).to_le_bytes());
        out.extend_from_slice(&((HEADER_LEN + body.len()) as u64).to_le_bytes());
        out.extend_from_slice(&crate::checksum::fnv1a64(&body).to_le_bytes());
        out.extend_from_slice(&body);
        out
    }

    /// Writes the model to `path`.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_bytes()).map_err(|source| Error::Io {
            file: path.to_owned(),
            source,
        })
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
        let recipe = parse(bytes, file)?;
        let model = build(
            &recipe.mesh,
            &recipe.strips,
            &recipe.collapses,
            &recipe.options,
        );
        model.validate().map_err(|e| {
            parse_error(
                file,
                0,
                "model",
                format!("built model is invalid: {}", e.message),
            )
        })?;
        Ok(model)
    }
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
    let sum = crate::checksum::fnv1a64(&bytes[HEADER_LEN..]);
    bytes[24..32].copy_from_slice(&sum.to_le_bytes());
}

/// What a file holds, validated.
struct Parsed {
    mesh: Mesh,
    strips: Strips,
    collapses: Collapses,
    options: BuildOptions,
}

fn parse_error(file: &Path, byte: usize, element: &str, message: String) -> Error {
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
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Offset of `bytes` in the file, for error places.
    base: usize,
    section: &'static str,
    file: PathBuf,
}

impl Reader<'_> {
    fn error(&self, message: impl Into<String>) -> Error {
        parse_error(
            &self.file,
            self.base + self.pos,
            self.section,
            message.into(),
        )
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn take(&mut self, n: usize) -> Result<&[u8]> {
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

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    fn f32(&mut self) -> Result<f32> {
        let b = self.take(4)?;
        Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn f64(&mut self) -> Result<f64> {
        let mut a = [0u8; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(f64::from_le_bytes(a))
    }

    fn varint(&mut self) -> Result<u64> {
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
    fn count(&mut self, what: &str, max: u64) -> Result<usize> {
        let at = self.pos;
        let v = self.varint()?;
        if v > max {
            self.pos = at;
            return Err(self.error(format!("{what} {v} exceeds {max}")));
        }
        Ok(v as usize)
    }

    fn finish(&self) -> Result<()> {
        if self.remaining() != 0 {
            return Err(self.error(format!(
                "{} unexpected bytes at the end of the section",
                self.remaining()
            )));
        }
        Ok(())
    }
}

fn parse(bytes: &[u8], file: &Path) -> Result<Parsed> {
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
    if version != VERSION {
        return Err(Error::UnknownFormat {
            file: file.to_owned(),
            message: format!("byte 8: .mts version {version}; this build reads version {VERSION}"),
        });
    }
    let header = |byte, m: String| parse_error(file, byte, "header", m);
    if u32_at(12) as usize != TAGS.len() {
        return Err(header(
            12,
            format!("{} sections, expected {}", u32_at(12), TAGS.len()),
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
    let sum = crate::checksum::fnv1a64(body);
    if u64_at(24) != sum {
        return Err(header(
            24,
            format!("checksum {:#018x}, content gives {sum:#018x}", u64_at(24)),
        ));
    }
    // Split into sections.
    let mut sections = Vec::with_capacity(TAGS.len());
    let mut top = Reader {
        bytes: body,
        pos: 0,
        base: HEADER_LEN,
        section: "section table",
        file: file.to_owned(),
    };
    for (i, tag) in TAGS.iter().enumerate() {
        let at = top.pos;
        let got = top.take(4)?.to_vec();
        if got != *tag {
            top.pos = at;
            return Err(top.error(format!(
                "section {i} is {:?}, expected {:?}",
                String::from_utf8_lossy(&got),
                String::from_utf8_lossy(*tag)
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
        top.take(len as usize)?;
        sections.push(Reader {
            bytes: &body[start..start + len as usize],
            pos: 0,
            base: HEADER_LEN + start,
            section: SECTION_NAMES[i],
            file: file.to_owned(),
        });
    }
    top.finish()?;
    let [mut meta, mut posi, mut strp, mut step]: [Reader; 4] = sections
        .try_into()
        .map_err(|_| parse_error(file, HEADER_LEN, "section table", "section count".into()))?;

    // META: counts, each bounded by the bytes of the section that holds it.
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
    let join_ends = flag(&mut meta, "join ends")?;
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

    // POSI.
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
    let mesh = Mesh {
        positions: positions[..vertices].to_vec(),
        triangles: strips.triangles(),
        properties: Default::default(),
    };
    if mesh.triangles.is_empty() {
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
    let appended_positions = positions[vertices..].to_vec();
    let counts = replay_counts(&mesh, &list, optimal);
    let collapses = Collapses::new(vertices, list, counts, appended_positions);
    Ok(Parsed {
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
            },
        },
    })
}

const SECTION_NAMES: [&str; 4] = ["META", "POSI", "STRP", "STEP"];

fn flag(r: &mut Reader<'_>, what: &str) -> Result<bool> {
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
pub(crate) fn replay_counts(mesh: &Mesh, steps: &[Collapse], optimal: bool) -> Vec<u32> {
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
    for (i, s) in steps.iter().enumerate() {
        let target = if optimal {
            (mesh.vertex_count() + i) as u32
        } else {
            s.kept
        };
        let moved: &[u32] = if optimal {
            &[s.removed, s.kept]
        } else {
            &[s.removed]
        };
        for &v in moved {
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

fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

fn unzigzag(v: u64) -> i64 {
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
