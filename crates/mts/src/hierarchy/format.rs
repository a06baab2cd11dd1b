//! The `.mts` file of a [`Hierarchy`]: version 4 of the format of
//! [`crate::model::format`], with its header and sections, holding the
//! input's vertices once, the clusters and every group with its model
//! ready to walk.
//!
//! Layout (all integers little-endian):
//!
//! ```text
//! header   magic "MTSMODEL" | version u32 = 4 | section count u32 = 7 | file length u64 | checksum u64
//! section  tag [u8; 4] | payload length u64 | payload
//! ```
//!
//! The checksum is [`crate::checksum::fnv1a64_words`] of every byte after
//! the header, as in version 3 ([`crate::model::format::seal`] reseals a
//! version-4 file too). A version-4 file holds a hierarchy, versions 1 to
//! 3 a per-object model: each loader names the other kind when given it,
//! and [`crate::model::format::holds`] tells them apart from the header.
//! Sections, in this order:
//! - `HIER`: varints input vertex count, input triangle count, cluster
//!   count, cluster triangle count, cluster strip index count, group count.
//! - `POSI`: `3 × f32` per input vertex.
//! - `PROP`: the input's properties (texture included), as in versions 2
//!   and 3.
//! - `CLUS`: per cluster, varints: the start of its triangles less the end
//!   of the previous cluster's (zigzag), its triangle count, the same two
//!   for its strip indices, its producer and its consumer each plus one (0
//!   for none).
//! - `CSTR`: the clusters' strips: per index a varint, 0 for a restart,
//!   otherwise one more than the zigzag of its difference from the
//!   previous index that is not a restart.
//! - `GRPS`: per group, its length (`u64`), then: level (varint); floor,
//!   diagonal, centre (3) and radius (`f32` each); inputs, outputs and
//!   children (each a varint count, then varints); its vertex map (a
//!   varint count, then zigzag varints of the differences); a flag `u8`;
//!   its model's sections as a version-3 file has them (tag, `u64` length,
//!   payload): `META`, `STRP`, `STEP`, `CMPN`, `MODL`. With flag 0 the
//!   model's vertices are not stored: they are the input vertices of its
//!   map, with their properties (no texture; position ids renumbered in
//!   order of first use), what [`super::build`] gives a group. With flag 1
//!   (a model whose vertices are not that) its `POSI` follows `META` and
//!   its `PROP` follows `STEP`, as in version 3.
//!
//! Every count is checked against the bytes that must hold it before
//! anything is allocated, every index against its range; the groups'
//! models are decoded on all cores, each checked against its recipe as a
//! version-3 file is and, through its vertex map, its LoD 0 against its
//! input clusters' triangles (every model vertex is drawn there, so the
//! map is checked whole) and its last LoD against its output clusters';
//! the whole is then checked by [`Hierarchy::validate`].
//! What loading leaves to trust is a group's LoDs in between: its model
//! against its recipe is sampled, as a version-3 file's is; `mts verify`
//! checks every LoD and sweeps cameras for cracks.

use super::{Cluster, Group, Hierarchy, NO_GROUP};
use crate::error::{Error, Place, Result};
use crate::mesh::Properties;
use crate::model::format::{
    check_header, properties_payload, put_sections, put_varint, read_model, read_properties,
    seal_body, split_sections, unzigzag, zigzag, Holds, ModelSections, Reader, Vertices,
};
use crate::strip::encode::RESTART_U32 as RESTART;
use crate::strip::sorted_canonical;
use glam::Vec3;
use std::path::Path;

/// The version of a hierarchy's `.mts` file (a model's are 1 to
/// [`crate::model::format::VERSION`]).
pub const VERSION: u32 = 4;

/// The version of a hierarchy's coded file (what `mts build --hierarchy`
/// writes): version 4 with each section's payload one part coded with
/// Zstandard ([`crate::model::compress`]: a part count, coding, decoded
/// and coded lengths, bytes; stored where coding does not shrink it).
/// Decoded, then read as version 4. The parts may announce at most 1,024 ×
/// the file's bytes in all, checked before anything is decoded.
pub const CODED_VERSION: u32 = 7;

/// Names of the decoded sections of a version-7 file in errors (places in
/// them are offsets in the decoded bytes).
const DECODED_NAMES: [&str; 6] = [
    "HIER, decoded",
    "POSI, decoded",
    "PROP, decoded",
    "CLUS, decoded",
    "CSTR, decoded",
    "GRPS, decoded",
];

const TAGS: [&[u8; 4]; 6] = [b"HIER", b"POSI", b"PROP", b"CLUS", b"CSTR", b"GRPS"];
/// A group model's sections without its vertices (flag 0), and with them.
const MODEL_TAGS: [&[u8; 4]; 5] = [b"META", b"STRP", b"STEP", b"CMPN", b"MODL"];
const OWN_MODEL_TAGS: [&[u8; 4]; 7] = [
    b"META", b"POSI", b"STRP", b"STEP", b"PROP", b"CMPN", b"MODL",
];
/// The fewest bytes a group takes in `GRPS`: its length, six floats, four
/// counts, the flag and five empty section headers.
const MIN_GROUP_BYTES: usize = 8 + 24 + 4 + 1 + 5 * 12;

impl Hierarchy {
    /// The hierarchy as `.mts` bytes (version 4): what
    /// [`Hierarchy::save`] writes.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let payloads = self.payloads();
        let mut body = Vec::new();
        put_sections(&mut body, TAGS.iter().copied().zip(payloads));
        seal_body(VERSION, TAGS.len(), &body)
    }

    /// The hierarchy as coded `.mts` bytes (version [`CODED_VERSION`]),
    /// each section coded with Zstandard at `level` (1 to 22) on every
    /// core: what `mts build --hierarchy` writes.
    #[must_use]
    pub fn to_compressed_bytes(&self, level: i32) -> Vec<u8> {
        let payloads = self.payloads();
        let coded = crate::parallel::map_indexed(
            payloads.len(),
            || (),
            |(), i| crate::model::compress::pack_one(&payloads[i], level),
        );
        let mut body = Vec::new();
        put_sections(&mut body, TAGS.iter().copied().zip(coded));
        seal_body(CODED_VERSION, TAGS.len(), &body)
    }

    /// The payloads of the sections, in the order of `TAGS`.
    fn payloads(&self) -> [Vec<u8>; 6] {
        let mut hier = Vec::new();
        for n in [
            self.vertex_count,
            self.triangle_count,
            self.clusters.len(),
            self.cluster_triangle_total(),
            self.cluster_strips.len(),
            self.groups.len(),
        ] {
            put_varint(&mut hier, n as u64);
        }
        let mut posi = Vec::with_capacity(12 * self.positions.len());
        for p in &self.positions {
            for x in p.to_array() {
                posi.extend_from_slice(&x.to_le_bytes());
            }
        }
        let prop = properties_payload(&self.properties);
        let mut clus = Vec::new();
        let (mut tri_end, mut strip_end) = (0i64, 0i64);
        let plus_one = |g: u32| if g == NO_GROUP { 0 } else { u64::from(g) + 1 };
        for c in &self.clusters {
            for (range, end) in [(&c.triangles, &mut tri_end), (&c.strip, &mut strip_end)] {
                put_varint(&mut clus, zigzag(i64::from(range.start) - *end));
                put_varint(&mut clus, u64::from(range.end.saturating_sub(range.start)));
                *end = i64::from(range.end);
            }
            put_varint(&mut clus, plus_one(c.producer));
            put_varint(&mut clus, plus_one(c.consumer));
        }
        let mut cstr = Vec::new();
        let mut prev = 0i64;
        for &v in &self.cluster_strips {
            if v == RESTART {
                cstr.push(0);
            } else {
                put_varint(&mut cstr, zigzag(i64::from(v) - prev) + 1);
                prev = i64::from(v);
            }
        }
        let mut grps = Vec::new();
        for g in &self.groups {
            let payload = self.group_payload(g);
            grps.extend_from_slice(&(payload.len() as u64).to_le_bytes());
            grps.extend_from_slice(&payload);
        }
        [hier, posi, prop, clus, cstr, grps]
    }

    /// One group's record in `GRPS` (without its length).
    fn group_payload(&self, g: &Group) -> Vec<u8> {
        let mut out = Vec::new();
        put_varint(&mut out, u64::from(g.level));
        for x in [
            g.floor, g.diagonal, g.centre.x, g.centre.y, g.centre.z, g.radius,
        ] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        for list in [&g.inputs, &g.outputs, &g.children] {
            put_varint(&mut out, list.len() as u64);
            for &x in list {
                put_varint(&mut out, u64::from(x));
            }
        }
        put_varint(&mut out, g.vertices.len() as u64);
        let mut prev = 0i64;
        for &v in &g.vertices {
            put_varint(&mut out, zigzag(i64::from(v) - prev));
            prev = i64::from(v);
        }
        // The model's vertices are left out when they are what loading
        // gathers from the input's (the vertex map is checked first, so
        // gathering cannot index out of range).
        let in_range = g
            .vertices
            .iter()
            .all(|&v| (v as usize) < self.positions.len());
        let gathered = in_range && {
            let (positions, properties) = gather(&self.positions, &self.properties, &g.vertices);
            positions == g.model.positions && properties == g.model.properties
        };
        out.push(u8::from(!gathered));
        put_sections(&mut out, g.model.sections(!gathered));
        out
    }

    /// Writes the hierarchy to `path` (see [`Hierarchy::to_bytes`]), whole
    /// or not at all ([`crate::output`]).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::output::write_file(path, &self.to_bytes())
    }

    /// Reads a hierarchy from `path` (see [`Hierarchy::from_bytes`]).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as
    /// [`Hierarchy::from_bytes`].
    pub fn load(path: &Path) -> Result<Hierarchy> {
        let bytes = crate::mesh::io::read_file(path)?;
        Hierarchy::from_bytes(&bytes, path)
    }

    /// Parses version-4 `.mts` bytes, checks every count and index, each
    /// group's model against its recipe and the whole with
    /// [`Hierarchy::validate`]. `file` names the source in errors.
    ///
    /// Cost: one pass over the bytes, the groups' models decoded and
    /// checked on all cores, then [`Hierarchy::validate`].
    ///
    /// # Errors
    /// [`Error::UnknownFormat`] for a wrong magic or version (a per-object
    /// model's file says so), [`Error::Parse`] naming the byte offset and
    /// the section (and group) of the first problem otherwise, or the
    /// broken invariant.
    pub fn from_bytes(bytes: &[u8], file: &Path) -> Result<Hierarchy> {
        let (version, mut top) = check_header(bytes, file, Holds::Hierarchy, |_| TAGS.len())?;
        let sections = split_sections(&mut top, &TAGS)?;
        top.finish()?;
        if version != CODED_VERSION {
            return Hierarchy::from_sections(sections, &top, file);
        }
        // Every part's header first, and what they announce bounded, then
        // each section decoded (on all cores) and read as version 4.
        crate::model::compress::check_expansion(&sections, false, bytes.len())?;
        let parts = sections
            .iter()
            .map(crate::model::compress::only_part)
            .collect::<Result<Vec<_>>>()?;
        let decoded = crate::parallel::map_indexed(
            parts.len(),
            || (),
            |(), i| {
                let (r, part) = &parts[i];
                part.decode(r)
            },
        )
        .into_iter()
        .collect::<Result<Vec<Vec<u8>>>>()?;
        let readers = decoded
            .iter()
            .zip(DECODED_NAMES)
            .map(|(d, name)| Reader::new(d, 0, name, file))
            .collect();
        Hierarchy::from_sections(readers, &top, file)
    }

    /// Reads the six sections of a version-4 file (or a version-7 file's,
    /// decoded).
    fn from_sections(
        sections: Vec<Reader<'_>>,
        top: &Reader<'_>,
        file: &Path,
    ) -> Result<Hierarchy> {
        let [mut hier, mut posi, mut prop, mut clus, mut cstr, mut grps]: [Reader; 6] = sections
            .try_into()
            .map_err(|_| top.error("section count"))?;

        // HIER: counts, each bounded by the bytes of the section that holds it.
        let vertices = hier.count(
            "vertex count",
            ((posi.remaining() / 12) as u64).min(u64::from(u32::MAX)),
        )?;
        // A strip of n indices draws at most n triangles.
        let triangles = hier.count("triangle count", cstr.remaining() as u64)?;
        let cluster_count = hier.count("cluster count", (clus.remaining() / 6) as u64)?;
        let cluster_triangles = hier.count("cluster triangle count", cstr.remaining() as u64)?;
        let strip_indices = hier.count("cluster strip index count", cstr.remaining() as u64)?;
        let group_count = hier.count(
            "group count",
            ((grps.remaining() / MIN_GROUP_BYTES) as u64).min(u64::from(u32::MAX - 1)),
        )?;
        hier.finish()?;

        // POSI and PROP.
        if posi.remaining() != 12 * vertices {
            return Err(posi.error(format!(
                "{} bytes for {vertices} vertices",
                posi.remaining()
            )));
        }
        let mut positions = Vec::with_capacity(vertices);
        for i in 0..vertices {
            let p = Vec3::new(posi.f32()?, posi.f32()?, posi.f32()?);
            if !p.is_finite() {
                posi.pos -= 12;
                return Err(posi.error(format!("vertex {i} is not finite: {p}")));
            }
            positions.push(p);
        }
        posi.finish()?;
        let properties = read_properties(&mut prop, &positions)?;

        // CLUS.
        let mut clusters = Vec::with_capacity(cluster_count);
        let (mut tri_end, mut strip_end) = (0usize, 0usize);
        for i in 0..cluster_count {
            let at = clus.pos;
            let mut range =
                |end: &mut usize, total: usize, what: &str| -> Result<std::ops::Range<u32>> {
                    let start = *end as i64 + unzigzag(clus.varint()?);
                    if start < 0 || start as usize > total {
                        clus.pos = at;
                        return Err(clus.error(format!(
                            "cluster {i}: its {what} start at {start}, outside 0..={total}"
                        )));
                    }
                    let len = clus.count(
                        &format!("cluster {i}'s {what} count"),
                        (total - start as usize) as u64,
                    )?;
                    *end = start as usize + len;
                    Ok(start as u32..*end as u32)
                };
            let tris = range(&mut tri_end, cluster_triangles, "triangles")?;
            let strip = range(&mut strip_end, strip_indices, "strip indices")?;
            let mut group = |what: &str| -> Result<u32> {
                let g = clus.count(&format!("cluster {i}'s {what}"), group_count as u64)?;
                Ok(if g == 0 { NO_GROUP } else { g as u32 - 1 })
            };
            let producer = group("producer")?;
            let consumer = group("consumer")?;
            clusters.push(Cluster {
                triangles: tris,
                producer,
                consumer,
                strip,
            });
        }
        clus.finish()?;

        let input_triangles: usize = clusters
            .iter()
            .filter(|c| c.producer == NO_GROUP)
            .map(|c| c.triangles.len())
            .sum();
        if input_triangles != triangles {
            return Err(parse_error(
                file,
                hier.base,
                "HIER",
                format!("{triangles} input triangles, the input's clusters hold {input_triangles}"),
            ));
        }

        // CSTR.
        let mut strips = Vec::with_capacity(strip_indices);
        let mut prev = 0i64;
        for i in 0..strip_indices {
            let at = cstr.pos;
            let x = cstr.varint()?;
            if x == 0 {
                strips.push(RESTART);
                continue;
            }
            let v = prev + unzigzag(x - 1);
            if v < 0 || v >= vertices as i64 {
                cstr.pos = at;
                return Err(cstr.error(format!(
                    "strip index {i} is {v}, vertices are 0..{vertices}"
                )));
            }
            strips.push(v as u32);
            prev = v;
        }
        cstr.finish()?;
        // The clusters' triangles, decoded from their strips for the
        // checks below (not kept: the strips are what is drawn).
        let mut tris = Vec::with_capacity(cluster_triangles);
        for (i, c) in clusters.iter().enumerate() {
            let strip = &strips[c.strip.start as usize..c.strip.end as usize];
            let drawn = super::strips::triangles_of(strip);
            if drawn.len() != c.triangles.len() || c.triangles.start as usize != tris.len() {
                return Err(parse_error(
                    file,
                    clus.base,
                    "CLUS",
                    format!(
                        "cluster {i}: its strips draw {} triangles, it says {:?} (after {})",
                        drawn.len(),
                        c.triangles,
                        tris.len()
                    ),
                ));
            }
            tris.extend(drawn);
        }
        // The counts HIER gives are the clusters' totals (a larger one
        // would be a lie that nothing else reads).
        if tris.len() != cluster_triangles || strip_end != strip_indices {
            return Err(parse_error(
                file,
                hier.base,
                "HIER",
                format!(
                    "{cluster_triangles} cluster triangles and {strip_indices} strip indices, \
                     the clusters hold {} and {strip_end}",
                    tris.len()
                ),
            ));
        }

        // GRPS: cut into groups here, decoded on all cores.
        let mut records = Vec::with_capacity(group_count);
        for g in 0..group_count {
            let mut len = [0u8; 8];
            len.copy_from_slice(grps.take(8)?);
            let len = u64::from_le_bytes(len);
            if len > grps.remaining() as u64 {
                grps.pos -= 8;
                return Err(grps.error(format!(
                    "group {g}: length {len} exceeds the {} bytes left",
                    grps.remaining()
                )));
            }
            let start = grps.pos;
            let bytes = &grps.bytes[start..start + len as usize];
            grps.pos += len as usize;
            records.push(Reader::new(bytes, grps.base + start, "GRPS", file));
        }
        grps.finish()?;
        let context = Context {
            positions: &positions,
            properties: &properties,
            clusters: &clusters,
            cluster_triangles: &tris,
            file,
        };
        let groups = decode_groups(records, &context)?;
        if let Some(g) = (1..groups.len()).find(|&g| groups[g].level < groups[g - 1].level) {
            return Err(parse_error(
                file,
                grps.base,
                &format!("group {g} GRPS"),
                format!(
                    "level {} after level {}: groups are stored by level",
                    groups[g].level,
                    groups[g - 1].level
                ),
            ));
        }

        drop(tris);
        let h = Hierarchy {
            clusters,
            groups,
            positions,
            properties,
            cluster_strips: strips,
            vertex_count: vertices,
            triangle_count: triangles,
        };
        h.validate().map_err(|e| Error::Parse {
            file: file.to_owned(),
            place: Place {
                element: Some("hierarchy".into()),
                ..Place::default()
            },
            message: e.to_string(),
        })?;
        Ok(h)
    }

    /// Bytes of the raw input mesh with 32-bit indices, as
    /// [`crate::MtsModel::raw_bytes`] counts them: 12 per vertex plus its
    /// properties' bytes, and 12 per triangle. The reference of
    /// `mts build --hierarchy --json`'s `raw_bytes`.
    #[must_use]
    pub fn raw_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.vertex_count + 12 * self.triangle_count
    }
}

/// What every group's decoding reads.
struct Context<'a> {
    positions: &'a [Vec3],
    properties: &'a Properties,
    /// The clusters and their triangles, decoded and in range.
    clusters: &'a [Cluster],
    cluster_triangles: &'a [[u32; 3]],
    file: &'a Path,
}

/// Decodes every group's record on all cores; the first error in group
/// order (whichever thread met it) is the one returned.
fn decode_groups(records: Vec<Reader<'_>>, context: &Context<'_>) -> Result<Vec<Group>> {
    crate::parallel::map_indexed(
        records.len(),
        || (),
        |(), g| decode_group(records[g].clone(), g, context).map_err(|e| in_group(e, g)),
    )
    .into_iter()
    .collect()
}

/// Group `g`'s record.
fn decode_group(mut r: Reader<'_>, g: usize, c: &Context<'_>) -> Result<Group> {
    let base = r.base;
    let level = r.count("level", g as u64)? as u32;
    let mut floats = [0f32; 6];
    for x in &mut floats {
        *x = r.f32()?;
    }
    let [floor, diagonal, cx, cy, cz, radius] = floats;
    let centre = Vec3::new(cx, cy, cz);
    if !centre.is_finite()
        || [floor, diagonal, radius]
            .iter()
            .any(|x| !(x.is_finite() && *x >= 0.0))
    {
        r.pos -= 24;
        return Err(r.error(format!(
            "floor {floor}, diagonal {diagonal}, centre {centre} or radius {radius} is not a \
             finite number (of at least 0)"
        )));
    }
    let list = |r: &mut Reader<'_>, what: &str, below: usize| -> Result<Vec<u32>> {
        let n = r.count(
            &format!("{what} count"),
            (r.remaining() as u64).min(below as u64),
        )?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            out.push(r.count(what, below as u64 - 1)? as u32);
        }
        Ok(out)
    };
    let inputs = list(&mut r, "input cluster", c.clusters.len())?;
    let outputs = list(&mut r, "output cluster", c.clusters.len())?;
    let at = r.pos;
    let children = list(&mut r, "child", g)?;
    if children.windows(2).any(|w| w[0] >= w[1]) {
        r.pos = at;
        return Err(r.error("children not ascending"));
    }
    let n = c.positions.len();
    let count = r.count("vertex map count", (r.remaining() as u64).min(n as u64))?;
    let mut vertices = Vec::with_capacity(count);
    let mut prev = 0i64;
    for i in 0..count {
        let at = r.pos;
        let v = prev + unzigzag(r.varint()?);
        if v < 0 || v >= n as i64 {
            r.pos = at;
            return Err(r.error(format!("model vertex {i} is input vertex {v}, of 0..{n}")));
        }
        vertices.push(v as u32);
        prev = v;
    }
    let own = crate::model::format::flag(&mut r, "own vertices")?;
    let tags: &[&'static [u8; 4]] = if own { &OWN_MODEL_TAGS } else { &MODEL_TAGS };
    let sections = split_sections(&mut r, tags)?;
    r.finish()?;
    let mut it = sections.into_iter();
    let mut next = || it.next().ok_or_else(|| r.error("missing section"));
    let meta = next()?;
    let vertices_of = if own {
        let posi = next()?;
        let (strp, step, prop) = (next()?, next()?, next()?);
        (
            Vertices::Stored {
                posi,
                prop: Some(prop),
            },
            strp,
            step,
        )
    } else {
        let (positions, properties) = gather(c.positions, c.properties, &vertices);
        (
            Vertices::Given {
                positions,
                properties,
            },
            next()?,
            next()?,
        )
    };
    let (source, strp, step) = vertices_of;
    let (cmpn, modl) = (next()?, next()?);
    let model = read_model(
        ModelSections {
            meta,
            vertices: source,
            strp,
            step,
            cmpn: Some(cmpn),
            modl: Some(modl),
            modl_coded: false,
            arrays: None,
        },
        c.file,
        false,
    )?;
    let group = Group {
        level,
        inputs,
        outputs,
        children,
        vertices,
        model,
        floor,
        diagonal,
        centre,
        radius,
    };
    // Its first and last LoDs, through its vertex map, are its input and
    // output clusters' triangles (which no count or structure check sees).
    for (lod, list, what) in [
        (0, &group.inputs, "LoD 0 and its input"),
        (
            group.model.max_lod(),
            &group.outputs,
            "last LoD and its output",
        ),
    ] {
        let held: Vec<[u32; 3]> = list
            .iter()
            .flat_map(|&k| {
                let t = &c.clusters[k as usize].triangles;
                &c.cluster_triangles[t.start as usize..t.end as usize]
            })
            .copied()
            .collect();
        let drawn = group.triangles_at(lod);
        if sorted_canonical(&drawn) != sorted_canonical(&held) {
            return Err(parse_error(
                c.file,
                base,
                "GRPS",
                format!("its model's {what} clusters hold other triangles"),
            ));
        }
    }
    Ok(group)
}

/// The positions and properties of the input vertices `vertices` (in
/// range), as [`super::build`] gives a group's submesh: no texture (the
/// input's serves), position ids renumbered in order of first use, none at
/// all for an input without properties.
fn gather(
    positions: &[Vec3],
    properties: &Properties,
    vertices: &[u32],
) -> (Vec<Vec3>, Properties) {
    let pick = |v: &u32| positions[*v as usize];
    let positions = vertices.iter().map(pick).collect();
    if properties.is_empty() {
        return (positions, Properties::default());
    }
    fn stream<T: Copy>(s: &Option<Vec<T>>, vertices: &[u32]) -> Option<Vec<T>> {
        s.as_ref()
            .map(|s| vertices.iter().map(|&v| s[v as usize]).collect())
    }
    let position_ids = if properties.position_ids.is_empty() {
        Vec::new()
    } else {
        let mut new_id = std::collections::HashMap::new();
        vertices
            .iter()
            .map(|&v| {
                let next = new_id.len() as u32;
                *new_id
                    .entry(properties.position_ids[v as usize])
                    .or_insert(next)
            })
            .collect()
    };
    let gathered = Properties {
        normals: stream(&properties.normals, vertices),
        uvs: stream(&properties.uvs, vertices),
        colors: stream(&properties.colors, vertices),
        position_ids,
        texture: None,
    };
    (positions, gathered)
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

/// `e` with its place named as in group `g`.
fn in_group(e: Error, g: usize) -> Error {
    match e {
        Error::Parse {
            file,
            mut place,
            message,
        } => {
            let section = place.element.take().unwrap_or_default();
            place.element = Some(format!("group {g} {section}").trim_end().to_owned());
            Error::Parse {
                file,
                place,
                message,
            }
        }
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::{build, HierarchyOptions};

    /// A group whose model's vertices are not what loading gathers is
    /// stored with them (flag 1), and still loads equal.
    #[test]
    fn a_model_with_its_own_vertices_round_trips() {
        let mesh = "torus:2k"
            .parse::<crate::mesh::generate::Generated>()
            .unwrap()
            .build_with_properties();
        let mut h = build(&mesh, &HierarchyOptions::default()).unwrap();
        let plain = h.to_bytes();
        let path = Path::new("own.mts");
        assert_eq!(Hierarchy::from_bytes(&plain, path).unwrap(), h);
        let model = &mut h.groups[0].model;
        let normals = model.properties.normals.as_mut().unwrap();
        normals[0] = -normals[0];
        let own = h.to_bytes();
        assert!(own.len() > plain.len());
        assert_eq!(Hierarchy::from_bytes(&own, path).unwrap(), h);
    }
}
