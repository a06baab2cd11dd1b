//! Version 5 of the `.mts` file: the version-3 sections, each coded with
//! Zstandard, the model's records split by column.
//!
//! **Decision: a general-purpose coder over the arrays as they are, split
//! into columns, rather than a coder of our own.** The ready arrays are
//! about ten stripifications of the mesh (one per band) with their labels
//! and codes. Measured on the bunny's 6.28 MB `MODL` section
//! (`docs/experiments/compressed-file.md`): order-0 entropy of the node
//! vertices' differences is 11.8 bits, but the vertex column codes to
//! about 8.8 bits a node with Zstandard, because a band's strips repeat
//! stretches of the band before it, which only a coder that matches
//! earlier bytes finds; labels code to 1.6 bits a record and codes to 0.7.
//! Splitting the section into columns, each its own frame, gains 13–20%
//! over coding it whole (each frame's entropy tables fit one kind of
//! value). Zstandard decodes at memory speed, which a coder of our own
//! would have to match. Cost: a C library in the core (`zstd-sys`).
//!
//! Layout: the header and section table of version 3 ([`super::format`]),
//! with the same seven tags; the checksum is of the coded body. Each
//! section's payload is a varint part count (1, or 6 for `MODL`) and then
//! per part: the coding (`u8`: 0 stored, 1 a Zstandard frame, 2 a
//! Zstandard frame of the bytes transposed, then the row width `u8`), a
//! varint decoded length, a varint coded length and the coded bytes
//! (coding 3 is the steps' own, `STEPS`). A
//! section's decoded parts, concatenated, are its version-3 payload,
//! except that the `MODL` section's vertices part holds only the records
//! that start a node (a node's later records hold vertex 0); the parts of
//! `MODL` are its counts and widths, its `u32` tables, the records'
//! vertices, labels and codes, and its tail (far arcs, LoD → triangle
//! table). The writer keeps, per part, the smallest of stored, coded,
//! (for positions, tables and tail) coded transposed, and (for the steps)
//! coded by column.
//!
//! **Decision: a file may ask loading to hold at most `MAX_EXPANSION` ×
//! its own bytes** in all, checked over every part's header before
//! anything is decoded or allocated (`check_expansion`): each part's
//! announced length, weighted by what decoding it holds at once (3 for a
//! transposed part: the frame's output, the part, a copy into its array;
//! 6 for the steps' columns, whose rows may take twice the part; the
//! `MODL` codes 5, for the vertex array of up to 4 bytes a record their
//! count sizes). Per file, not per part: a column can legitimately code a
//! thousand to one (the companion section of a model without seams is one
//! zero byte per step), while the positions, a fifth of the file, hardly
//! shrink; the writer stores the densest parts plainly in the (never seen)
//! case that the whole file would exceed the bound.
//!
//! Loading decodes `MODL` on a second thread while the recipe's sections
//! are decoded, then parses as version 3 does (every count, index and
//! label checked; the ready walk compared with the recipe's replay).

use super::format::{put_varint, Reader};
use crate::error::Result;

/// How many times its own bytes a file may ask loading to hold
/// ([`check_expansion`]).
pub(crate) const MAX_EXPANSION: u64 = 1024;

/// The Zstandard level `mts build` writes at: the measured balance of size
/// and writing time (`docs/experiments/compressed-file.md`: on the bunny,
/// level 17 writes 3 % more bytes than 19 in half its time, and 12 % fewer
/// than 15, where Zstandard's slower match search starts).
pub const DEFAULT_LEVEL: i32 = 17;

const STORED: u8 = 0;
const ZSTD: u8 = 1;
/// A Zstandard frame of the part's bytes transposed: read as rows of a
/// width (the `u8` after the coding), byte 0 of every row first, then
/// byte 1, ... Numbers of one kind then put their like bytes (exponents,
/// high bytes) side by side: the bunny's positions code 19% smaller, the
/// `MODL` tables 45%, the LoD → triangle table 96%.
const TRANSPOSED: u8 = 2;

/// The contraction steps (`STEP`: per step the removed and kept vertices
/// as varints and the error as `f32`) as rows of three `u32`, transposed
/// (as [`TRANSPOSED`] with rows of 12 bytes), then a Zstandard frame: the
/// removed vertex; the kept one's difference from it and the error's bits'
/// difference from the step before, each zigzagged (`i32` wrapping). The
/// bunny's steps code to 151 KB instead of 213 KB. The frame may decode to
/// at most twice the part's announced length (a step is at least 6 bytes
/// in the section, 12 as a row).
const STEPS: u8 = 3;

fn zigzag32(d: i32) -> u32 {
    ((d << 1) ^ (d >> 31)) as u32
}

fn unzigzag32(v: u32) -> i32 {
    (v >> 1) as i32 ^ -((v & 1) as i32)
}

/// The `STEP` payload `v3` as rows of three `u32` (see [`STEPS`]), or
/// `None` if it is not a whole number of steps with `u32` vertices.
fn steps_to_rows(v3: &[u8]) -> Option<Vec<u8>> {
    let mut r = Reader::new(v3, 0, "STEP", std::path::Path::new(""));
    let mut out = Vec::with_capacity(v3.len() * 2);
    let mut prev = 0u32;
    while r.remaining() > 0 {
        let removed = u32::try_from(r.varint().ok()?).ok()?;
        let kept = u32::try_from(r.varint().ok()?).ok()?;
        let bits = r.f32().ok()?.to_bits();
        let kept_d = zigzag32((kept as i32).wrapping_sub(removed as i32));
        let error_d = zigzag32((bits as i32).wrapping_sub(prev as i32));
        prev = bits;
        for x in [removed, kept_d, error_d] {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    Some(out)
}

/// The `STEP` payload of `rows` (the inverse of [`steps_to_rows`]),
/// written until it is longer than `limit` bytes (then it is wrong).
fn rows_to_steps(rows: &[u8], limit: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(rows.len().min(limit));
    let mut prev = 0u32;
    for row in rows.chunks_exact(12) {
        if out.len() > limit {
            break;
        }
        let word = |i: usize| u32::from_le_bytes([row[i], row[i + 1], row[i + 2], row[i + 3]]);
        let removed = word(0);
        let kept = (removed as i32).wrapping_add(unzigzag32(word(4))) as u32;
        let bits = (prev as i32).wrapping_add(unzigzag32(word(8))) as u32;
        prev = bits;
        put_varint(&mut out, u64::from(removed));
        put_varint(&mut out, u64::from(kept));
        out.extend_from_slice(&bits.to_le_bytes());
    }
    out
}

/// `data` read as rows of `width` bytes, transposed (or back with
/// `inverse`); its length is a multiple of `width`.
fn transpose(data: &[u8], width: usize, inverse: bool) -> Vec<u8> {
    let rows = data.len() / width;
    let mut out = vec![0u8; data.len()];
    for row in 0..rows {
        for col in 0..width {
            let (a, b) = (row * width + col, col * rows + row);
            if inverse {
                out[a] = data[b];
            } else {
                out[b] = data[a];
            }
        }
    }
    out
}

/// Parts of the `MODL` section.
const MODL_PARTS: usize = 6;

/// The names of the `MODL` section's parts, for errors.
const MODL_PART_NAMES: [&str; MODL_PARTS] =
    ["counts", "tables", "vertices", "labels", "codes", "tail"];

/// The row width each part is tried transposed at ([`TRANSPOSED`]), in the
/// order of [`super::format`]'s tags then the `MODL` parts: positions
/// (three `f32`), the `MODL` tables (`u32`) and tail (`u32`); 0 for the
/// others (varints, or columns whose bytes gain nothing).
const ROW_WIDTHS: [u8; 6 + MODL_PARTS] = [0, 12, 0, 0, 0, 0, 0, 4, 0, 0, 0, 4];

/// The index of the `STEP` section among the parts the writer codes.
const STEP_PART: usize = 3;

/// A part as written: its coding, row width (for [`TRANSPOSED`]) and
/// bytes (the data itself where stored).
struct Coded {
    coding: u8,
    width: u8,
    frame: Vec<u8>,
}

/// The version-5 payloads of a model: `recipe` (the six sections before
/// `MODL`, in their order, a part each) and the `MODL` section's `modl`
/// parts (vertices of node-starting records only), each coded at `level`
/// on every core. A part Zstandard does not shrink is stored; then, while
/// the file would decode to more than [`MAX_EXPANSION`] × its coded bytes,
/// the part coded most densely is stored instead (never needed on a real
/// model: positions hardly shrink).
pub(crate) fn pack(recipe: &[Vec<u8>], modl: &[Vec<u8>; MODL_PARTS], level: i32) -> Vec<Vec<u8>> {
    let parts: Vec<&Vec<u8>> = recipe.iter().chain(modl.iter()).collect();
    let mut coded = crate::parallel::map_indexed(
        parts.len(),
        || (),
        |(), i| {
            let data = parts[i];
            let mut best = Coded {
                coding: STORED,
                width: 0,
                frame: Vec::new(),
            };
            let width = ROW_WIDTHS.get(i).copied().unwrap_or(0);
            let mut tries = vec![(ZSTD, 0u8)];
            if width > 0 && data.len() % usize::from(width) == 0 {
                tries.push((TRANSPOSED, width));
            }
            let rows = if i == STEP_PART {
                steps_to_rows(data)
            } else {
                None
            };
            if rows.is_some() {
                tries.push((STEPS, 0));
            }
            for (coding, width) in tries {
                let frame = match (coding, &rows) {
                    (TRANSPOSED, _) => {
                        zstd::bulk::compress(&transpose(data, usize::from(width), false), level)
                    }
                    (STEPS, Some(rows)) => zstd::bulk::compress(&transpose(rows, 12, false), level),
                    _ => zstd::bulk::compress(data, level),
                };
                let size = if best.coding == STORED {
                    data.len()
                } else {
                    best.frame.len()
                };
                match frame {
                    Ok(f) if f.len() < size => {
                        best = Coded {
                            coding,
                            width,
                            frame: f,
                        }
                    }
                    _ => {}
                }
            }
            best
        },
    );
    let size = |c: &Coded, p: &Vec<u8>| {
        if c.coding == STORED {
            p.len()
        } else {
            c.frame.len()
        }
    };
    let decoded: u64 = parts.iter().map(|p| p.len() as u64).sum();
    loop {
        let total: u64 = coded
            .iter()
            .zip(&parts)
            .map(|(c, p)| size(c, p) as u64)
            .sum();
        if decoded <= MAX_EXPANSION * total {
            break;
        }
        let densest = (0..parts.len())
            .filter(|&i| coded[i].coding != STORED)
            .max_by_key(|&i| parts[i].len() / coded[i].frame.len().max(1));
        let Some(i) = densest else { break };
        coded[i].coding = STORED;
    }
    let section = |range: std::ops::Range<usize>| {
        let mut out = Vec::new();
        put_varint(&mut out, range.len() as u64);
        for i in range {
            out.push(coded[i].coding);
            if coded[i].coding == TRANSPOSED {
                out.push(coded[i].width);
            }
            put_varint(&mut out, parts[i].len() as u64);
            let bytes: &[u8] = if coded[i].coding == STORED {
                parts[i]
            } else {
                &coded[i].frame
            };
            put_varint(&mut out, bytes.len() as u64);
            out.extend_from_slice(bytes);
        }
        out
    };
    let mut out: Vec<Vec<u8>> = (0..recipe.len()).map(|i| section(i..i + 1)).collect();
    out.push(section(recipe.len()..parts.len()));
    out
}

/// A section of one part holding `data`: coded with Zstandard at `level`,
/// or stored when that does not shrink it or would decode to more than
/// [`MAX_EXPANSION`] × its bytes (a version-6 chunk, `model/prefix.rs`).
pub(crate) fn pack_one(data: &[u8], level: i32) -> Vec<u8> {
    let frame = zstd::bulk::compress(data, level)
        .ok()
        .filter(|f| f.len() < data.len() && data.len() as u64 <= MAX_EXPANSION * f.len() as u64);
    let mut out = Vec::with_capacity(frame.as_ref().map_or(data.len(), Vec::len) + 24);
    put_varint(&mut out, 1);
    out.push(if frame.is_some() { ZSTD } else { STORED });
    put_varint(&mut out, data.len() as u64);
    let bytes = frame.as_deref().unwrap_or(data);
    put_varint(&mut out, bytes.len() as u64);
    out.extend_from_slice(bytes);
    out
}

/// Checks, before anything is decoded, that the parts of coded
/// `sections` ask loading to hold at most `MAX_EXPANSION` × `file_len`
/// bytes in all: each part's announced length times [`holding`] (each
/// part's header checked as it is read). Each section is one part, but
/// the last with `modl_last` (a version-5 file's `MODL`, six parts); a
/// version-6 chunk and a version-7 hierarchy's sections are checked here
/// too.
pub(crate) fn check_expansion(
    sections: &[Reader<'_>],
    modl_last: bool,
    file_len: usize,
) -> Result<()> {
    check_expansion_of(sections, modl_last, file_len, "the file's")
}

/// [`check_expansion`] of `len` bytes that `whose` names in the error
/// ("the chunk's").
pub(crate) fn check_expansion_of(
    sections: &[Reader<'_>],
    modl_last: bool,
    file_len: usize,
    whose: &str,
) -> Result<()> {
    let budget = MAX_EXPANSION * file_len as u64 + 64;
    let mut total = 0u64;
    for (i, s) in sections.iter().enumerate() {
        let mut r = s.clone();
        let expected = if modl_last && i + 1 == sections.len() {
            MODL_PARTS
        } else {
            1
        };
        part_count(&mut r, expected)?;
        for name in MODL_PART_NAMES.iter().take(expected) {
            let name = if expected == 1 { s.section } else { name };
            let at = r.pos;
            let part = next_part(&mut r, name)?;
            let weight = holding(part.coding) + if name == "codes" { 4 } else { 0 };
            total = total.saturating_add(part.decoded.saturating_mul(weight));
            if total > budget {
                r.pos = at;
                return Err(r.error(format!(
                    "{}the parts so far would take {total} bytes to decode, more than \
                     {MAX_EXPANSION} × {whose} {file_len}",
                    part_prefix(name, &r)
                )));
            }
        }
    }
    Ok(())
}

/// How many times its announced length decoding a part of `coding` holds
/// at once, at most (see the module documentation).
fn holding(coding: u8) -> u64 {
    match coding {
        TRANSPOSED => 3,
        STEPS => 6,
        _ => 1,
    }
}

/// Reads the part count of the section `r` reads, which must be
/// `expected`.
fn part_count(r: &mut Reader<'_>, expected: usize) -> Result<()> {
    let at = r.pos;
    let count = r.count("part count", expected as u64)?;
    if count != expected {
        r.pos = at;
        return Err(r.error(format!("{count} parts, expected {expected}")));
    }
    Ok(())
}

/// A part whose header has been read: where it is, and what it is.
pub(crate) struct Part<'a> {
    at: usize,
    name: &'static str,
    coding: u8,
    /// The row width of a [`TRANSPOSED`] part (1 to 16), else 0.
    width: u8,
    decoded: u64,
    bytes: &'a [u8],
}

/// Reads the next part's header from `r`, checked against the bytes left,
/// and steps over its bytes ([`check_expansion`] bounds what they decode
/// to). `name` names it in
/// errors.
fn next_part<'a>(r: &mut Reader<'a>, name: &'static str) -> Result<Part<'a>> {
    let at = r.pos;
    let coding = r.u8()?;
    let width = if coding == TRANSPOSED { r.u8()? } else { 0 };
    let decoded = r.varint()?;
    let coded = r.count(&format!("{name}: coded length"), r.remaining() as u64)?;
    let all: &'a [u8] = r.bytes;
    let start = r.pos;
    r.take(coded)?;
    let bytes = &all[start..start + coded];
    let problem = match coding {
        STORED if decoded != coded as u64 => Some(format!("stored, {coded} bytes for {decoded}")),
        TRANSPOSED if !(1..=16).contains(&width) || decoded % u64::from(width) != 0 => Some(
            format!("transposed in rows of {width} bytes, which {decoded} bytes are not"),
        ),
        STORED | ZSTD | TRANSPOSED | STEPS => None,
        c => Some(format!(
            "coding {c}, not 0 (stored), 1 (Zstandard), 2 (transposed) or 3 (steps)"
        )),
    };
    if let Some(p) = problem {
        r.pos = at;
        return Err(r.error(format!("{}{p}", part_prefix(name, r))));
    }
    Ok(Part {
        at,
        name,
        coding,
        width,
        decoded,
        bytes,
    })
}

impl Part<'_> {
    /// Decodes the part straight into `out`, little-endian `T`s: its
    /// announced length must be `out`'s. `r` (the section's reader) places
    /// errors.
    pub(crate) fn decode_into<T: bytemuck::Pod>(
        &self,
        r: &Reader<'_>,
        out: &mut [T],
        from_le: fn(T) -> T,
    ) -> Result<()> {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(out);
        let expected = bytes.len();
        let got = if self.decoded != expected as u64 {
            Err(format!("{} bytes, {expected} expected", self.decoded))
        } else if self.coding == TRANSPOSED || self.coding == STEPS {
            bytes.copy_from_slice(&self.decode(r)?);
            Ok(())
        } else if self.coding == STORED {
            bytes.copy_from_slice(self.bytes);
            Ok(())
        } else {
            match zstd::bulk::decompress_to_buffer(self.bytes, bytes) {
                Ok(n) if n == expected => Ok(()),
                Ok(n) => Err(format!(
                    "the Zstandard frame decodes to {n} bytes, {expected} announced"
                )),
                Err(e) => Err(format!(
                    "the Zstandard frame of {} bytes does not decode to the {expected} \
                     announced: {e}",
                    self.bytes.len()
                )),
            }
        };
        match got {
            Ok(()) => {
                if cfg!(target_endian = "big") {
                    out.iter_mut().for_each(|x| *x = from_le(*x));
                }
                Ok(())
            }
            Err(problem) => Err(self.error(r, &problem)),
        }
    }

    /// The bytes the part announces it decodes to (bounded, with the
    /// other parts', by [`check_expansion`]).
    pub(crate) fn decoded_len(&self) -> u64 {
        self.decoded
    }

    /// The decoded bytes, into a buffer of the announced length at most
    /// (the decoder stops where it would need more; twice that for the
    /// steps' rows, [`STEPS`]). `r` (the section's reader) places errors.
    pub(crate) fn decode(&self, r: &Reader<'_>) -> Result<Vec<u8>> {
        if self.coding == STORED {
            return Ok(self.bytes.to_vec());
        }
        let (decoded, coded) = (self.decoded, self.bytes.len());
        if self.coding == STEPS {
            let room = usize::try_from(decoded.saturating_mul(2)).unwrap_or(usize::MAX);
            let problem = match zstd::bulk::decompress(self.bytes, room) {
                Ok(rows) if rows.len() % 12 == 0 => {
                    let steps = rows_to_steps(&transpose(&rows, 12, true), decoded as usize);
                    if steps.len() as u64 == decoded {
                        return Ok(steps);
                    }
                    format!(
                        "{} steps make {} bytes, {decoded} announced",
                        rows.len() / 12,
                        steps.len()
                    )
                }
                Ok(rows) => format!("{} bytes of steps are not rows of 12", rows.len()),
                Err(e) => {
                    format!("the Zstandard frame of {coded} bytes of steps does not decode: {e}")
                }
            };
            return Err(self.error(r, &problem));
        }
        let problem = match zstd::bulk::decompress(self.bytes, decoded as usize) {
            Ok(out) if out.len() as u64 == decoded && self.coding == TRANSPOSED => {
                return Ok(transpose(&out, usize::from(self.width), true));
            }
            Ok(out) if out.len() as u64 == decoded => return Ok(out),
            Ok(out) => format!(
                "the Zstandard frame decodes to {} bytes, {decoded} announced",
                out.len()
            ),
            Err(e) => format!(
                "the Zstandard frame of {coded} bytes does not decode to the {decoded} \
                 announced: {e}"
            ),
        };
        Err(self.error(r, &problem))
    }

    /// `problem` as an error at the part's header in the section `r`
    /// reads.
    fn error(&self, r: &Reader<'_>, problem: &str) -> crate::Error {
        let mut at = r.clone();
        at.pos = self.at;
        at.error(format!("{}{problem}", part_prefix(self.name, r)))
    }
}

/// What names part `name` in an error of the section `r` reads: nothing
/// for a section of one part (the error names the section).
fn part_prefix(name: &str, r: &Reader<'_>) -> String {
    if name == r.section {
        String::new()
    } else {
        format!("{name}: ")
    }
}

/// The one part of a recipe section of a version-5 file, its header read.
pub(crate) fn only_part<'a>(section: &Reader<'a>) -> Result<(Reader<'a>, Part<'a>)> {
    let mut r = section.clone();
    part_count(&mut r, 1)?;
    let name = r.section;
    let part = next_part(&mut r, name)?;
    r.finish()?;
    Ok((r, part))
}

/// The version-3 payloads of a version-5 file's recipe `sections` (one
/// part each).
pub(crate) fn unpack_recipe(sections: Vec<Reader<'_>>) -> Result<Vec<Vec<u8>>> {
    sections
        .into_iter()
        .map(|s| {
            let (r, part) = only_part(&s)?;
            part.decode(&r)
        })
        .collect()
}

/// The tail of a version-5 `MODL` section (far arcs and the LoD → triangle
/// table), decoded alone: what the recipe's side of the loader reads.
pub(crate) fn modl_tail(mut r: Reader<'_>) -> Result<Vec<u8>> {
    let parts = modl_parts(&mut r)?;
    parts[MODL_PARTS - 1].decode(&r)
}

/// The headers of a version-5 `MODL` section's parts, read from `r` to its
/// end.
pub(crate) fn modl_parts<'a>(r: &mut Reader<'a>) -> Result<Vec<Part<'a>>> {
    part_count(r, MODL_PARTS)?;
    let parts = MODL_PART_NAMES
        .iter()
        .map(|name| next_part(r, name))
        .collect::<Result<Vec<_>>>()?;
    r.finish()?;
    Ok(parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transposing_and_back_gives_the_bytes() {
        let data: Vec<u8> = (0..96u8).collect();
        for width in [1, 2, 4, 12, 16] {
            let t = transpose(&data, width, false);
            assert_eq!(transpose(&t, width, true), data, "width {width}");
        }
        // Rows of 4: the first byte of every row first.
        assert_eq!(&transpose(&data[..8], 4, false), &[0, 4, 1, 5, 2, 6, 3, 7]);
    }

    /// Steps whose differences wrap (vertex 0 kept for vertex 2^32 - 1,
    /// errors that fall, a NaN's bits): the rows give the section back
    /// byte for byte.
    #[test]
    fn steps_by_column_give_the_section_back() {
        let mut v3 = Vec::new();
        for (removed, kept, error) in [
            (5u64, 7u64, 0.0f32),
            (u64::from(u32::MAX), 0, 1.5),
            (0, u64::from(u32::MAX), -2.0),
            (300, 299, f32::NAN),
            (1, 2, f32::MAX),
        ] {
            put_varint(&mut v3, removed);
            put_varint(&mut v3, kept);
            v3.extend_from_slice(&error.to_le_bytes());
        }
        let rows = steps_to_rows(&v3).unwrap();
        assert_eq!(rows.len(), 5 * 12);
        assert_eq!(rows_to_steps(&rows, v3.len()), v3);
        assert!(
            rows_to_steps(&rows, 3).len() < v3.len(),
            "stops past the limit"
        );
        // Not a whole number of steps, or a vertex past u32: not coded so.
        assert_eq!(steps_to_rows(&v3[..v3.len() - 1]), None);
        let mut wide = Vec::new();
        put_varint(&mut wide, 1 << 32);
        put_varint(&mut wide, 0);
        wide.extend_from_slice(&0f32.to_le_bytes());
        assert_eq!(steps_to_rows(&wide), None);
    }
}
