//! The hierarchy's `.mts` file (version 4, `hierarchy/format.rs`, and its
//! coded version 7): round trips equal, every truncation and flipped byte
//! is an error or (resealed) a checked hierarchy, never a panic, a huge
//! count or an amplifying part allocates nothing, and each loader names a
//! file of the other kind.

use mts::hierarchy::{self, Hierarchy, HierarchyOptions};
use mts::mesh::generate::Generated;
use mts::mesh::{Mesh, Texture};
use mts::model::format::{holds, seal, Holds};
use mts::MtsModel;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

mod common;

/// The largest single allocation any test of this binary made: a count
/// trusted from a file would show here (no legitimate one reaches
/// [`ALLOCATION_LIMIT`]).
static LARGEST: AtomicUsize = AtomicUsize::new(0);
const ALLOCATION_LIMIT: usize = 256 << 20;

struct Tracking;

unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Tracking = Tracking;

const FILE: &str = "h.mts";

/// An `n × n` grid of unit squares whose heights are a few waves (as in
/// `tests/hierarchy.rs`).
fn hilly_grid(n: u32) -> Mesh {
    let mut mesh = mts::mesh::generate::grid(n, n);
    for p in &mut mesh.positions {
        p.z = 1.5 * (p.x * 0.31).sin() * (p.y * 0.23).cos() + 0.6 * (p.x * 0.07 + p.y * 0.11).sin();
    }
    mesh
}

fn build(mesh: &Mesh) -> Hierarchy {
    hierarchy::build(mesh, &HierarchyOptions::default()).unwrap()
}

/// A torus with normals, UVs, colours, seams and an embedded texture.
fn torus() -> Mesh {
    let mut mesh = "torus:2k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    mesh.properties.texture = Some(Texture::Embedded {
        mime: "image/png".into(),
        bytes: common::PNG.to_vec(),
    });
    mesh
}

fn load(bytes: &[u8]) -> mts::Result<Hierarchy> {
    Hierarchy::from_bytes(bytes, Path::new(FILE))
}

/// A section: its tag, its payload's start and length.
type Section = ([u8; 4], usize, usize);

/// The sections of a file.
fn sections(bytes: &[u8]) -> Vec<Section> {
    let mut out = Vec::new();
    let mut pos = 32;
    while pos < bytes.len() {
        let tag: [u8; 4] = bytes[pos..pos + 4].try_into().unwrap();
        let len = u64::from_le_bytes(bytes[pos + 4..pos + 12].try_into().unwrap()) as usize;
        out.push((tag, pos + 12, len));
        pos += 12 + len;
    }
    assert_eq!(pos, bytes.len());
    out
}

/// `bytes` with section `i`'s payload replaced by `payload`, resealed.
fn with_section(bytes: &[u8], i: usize, payload: &[u8]) -> Vec<u8> {
    let (_, start, len) = sections(bytes)[i];
    let mut out = bytes[..start - 8].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(payload);
    out.extend_from_slice(&bytes[start + len..]);
    seal(&mut out);
    out
}

fn varint(bytes: &[u8], pos: &mut usize) -> u64 {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let b = bytes[*pos];
        *pos += 1;
        v |= u64::from(b & 0x7f) << shift;
        if b & 0x80 == 0 {
            break;
        }
    }
    v
}

fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// The groups' records in a `GRPS` payload: (start, length) after each
/// record's length.
fn group_records(grps: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < grps.len() {
        let len = u64::from_le_bytes(grps[pos..pos + 8].try_into().unwrap()) as usize;
        out.push((pos + 8, len));
        pos += 8 + len;
    }
    out
}

/// `payload` with the varint at `at` replaced by `v`.
fn set_varint(payload: &[u8], at: usize, v: u64) -> Vec<u8> {
    let mut end = at;
    varint(payload, &mut end);
    let mut out = payload[..at].to_vec();
    put_varint(&mut out, v);
    out.extend_from_slice(&payload[end..]);
    out
}

/// Group `g`'s record of `bytes` replaced by `record`, lengths fixed,
/// resealed.
fn with_group(bytes: &[u8], g: usize, record: &[u8]) -> Vec<u8> {
    let (_, start, len) = sections(bytes)[5];
    let grps = &bytes[start..start + len];
    let (at, n) = group_records(grps)[g];
    let mut new = grps[..at - 8].to_vec();
    new.extend_from_slice(&(record.len() as u64).to_le_bytes());
    new.extend_from_slice(record);
    new.extend_from_slice(&grps[at + n..]);
    with_section(bytes, 5, &new)
}

/// Group `g`'s record in `bytes`.
fn group_record(bytes: &[u8], g: usize) -> Vec<u8> {
    let (_, start, len) = sections(bytes)[5];
    let grps = &bytes[start..start + len];
    let (at, n) = group_records(grps)[g];
    grps[at..at + n].to_vec()
}

/// The offsets in a group record of: its input count, its vertex map
/// count, its flag, and its model's sections (tag, payload start, length).
fn group_layout(record: &[u8]) -> (usize, usize, usize, Vec<Section>) {
    let mut pos = 0;
    varint(record, &mut pos);
    pos += 24;
    let inputs = pos;
    for _ in 0..3 {
        let n = varint(record, &mut pos);
        for _ in 0..n {
            varint(record, &mut pos);
        }
    }
    let map = pos;
    let n = varint(record, &mut pos);
    for _ in 0..n {
        varint(record, &mut pos);
    }
    let flag = pos;
    pos += 1;
    let mut model = Vec::new();
    while pos < record.len() {
        let tag: [u8; 4] = record[pos..pos + 4].try_into().unwrap();
        let len = u64::from_le_bytes(record[pos + 4..pos + 12].try_into().unwrap()) as usize;
        model.push((tag, pos + 12, len));
        pos += 12 + len;
    }
    (inputs, map, flag, model)
}

fn assert_parse_error(result: mts::Result<Hierarchy>, context: &str) -> String {
    match result {
        Ok(_) => panic!("{context}: accepted"),
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains(FILE), "{context}: {text}");
            text
        }
    }
}

#[test]
fn a_hilly_grid_round_trips_equal() {
    let mesh = hilly_grid(40);
    let h = build(&mesh);
    assert!(h.level_count() >= 3 && h.groups().len() >= 8);
    let bytes = h.to_bytes();
    assert_eq!(holds(&bytes), Some(Holds::Hierarchy));
    assert_eq!(
        mts::model::format::file_version(&bytes),
        Some(hierarchy::format::VERSION)
    );
    assert_eq!(load(&bytes).unwrap(), h);
    // Written whole, read back the same; written again, the same bytes.
    let dir = common::scratch("hierarchy_format", "grid");
    let path = dir.join("grid.mts");
    h.save(&path).unwrap();
    let loaded = Hierarchy::load(&path).unwrap();
    assert_eq!(loaded, h);
    assert_eq!(loaded.to_bytes(), bytes);
    // Every group's vertices are the input's, gathered: not stored again.
    for g in 0..h.groups().len() {
        let (_, _, flag, model) = group_layout(&group_record(&bytes, g));
        assert_eq!(group_record(&bytes, g)[flag], 0, "group {g}");
        assert_eq!(model.len(), 5);
    }
    assert!(h.raw_bytes() == 12 * mesh.vertex_count() + 12 * mesh.triangle_count());
}

#[test]
fn a_torus_with_properties_seams_and_a_texture_round_trips_equal() {
    let mesh = torus();
    let h = build(&mesh);
    assert!(!h.properties().position_ids.is_empty());
    let bytes = h.to_bytes();
    let loaded = load(&bytes).unwrap();
    assert_eq!(loaded, h);
    assert_eq!(loaded.properties().texture, mesh.properties.texture);
    for g in loaded.groups() {
        assert!(g.model.properties().texture.is_none());
    }
    for g in 0..h.groups().len() {
        let record = group_record(&bytes, g);
        assert_eq!(record[group_layout(&record).2], 0, "group {g}");
    }
    // A positions-only input too.
    let plain = "torus:2k".parse::<Generated>().unwrap().build();
    let h = build(&plain);
    assert_eq!(load(&h.to_bytes()).unwrap(), h);
}

#[test]
fn each_loader_names_a_file_of_the_other_kind() {
    let mesh = hilly_grid(12);
    let h = build(&mesh);
    let bytes = h.to_bytes();
    let e = MtsModel::from_bytes(&bytes, Path::new(FILE)).unwrap_err();
    let text = e.to_string();
    assert!(
        matches!(e, mts::Error::UnknownFormat { .. }) && text.contains("hierarchy"),
        "{text}"
    );
    let (model, _, _) = mts::model::build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
    for model_bytes in [
        model.to_bytes(),
        model.to_recipe_bytes(),
        model.to_compressed_bytes(3),
    ] {
        assert_eq!(holds(&model_bytes), Some(Holds::Model));
        let text = assert_parse_error(load(&model_bytes), "a model");
        assert!(text.contains("per-object model"), "{text}");
    }
    let mut other = bytes.clone();
    other[8] = 8;
    assert_eq!(holds(&other), None);
    let text = assert_parse_error(load(&other), "version 8");
    assert!(text.contains("version 8"), "{text}");
    assert_eq!(holds(b"MTSMODEL"), None);
}

/// A small file: a few groups over several levels (small clusters).
fn small() -> (Hierarchy, Vec<u8>) {
    let options = HierarchyOptions {
        cluster_triangles: 16,
        ..HierarchyOptions::default()
    };
    let h = hierarchy::build(&hilly_grid(10), &options).unwrap();
    assert!(
        h.groups().len() >= 4 && h.level_count() >= 2,
        "{} groups, {} levels",
        h.groups().len(),
        h.level_count()
    );
    let bytes = h.to_bytes();
    (h, bytes)
}

#[test]
fn every_truncation_is_an_error() {
    let (_, bytes) = small();
    for n in 0..bytes.len() {
        assert_parse_error(load(&bytes[..n]), &format!("{n} bytes"));
    }
    // Resealed, so that the sections' own checks are reached.
    let step = (bytes.len() / 1500).max(1);
    for n in (32..bytes.len()).step_by(step) {
        let mut cut = bytes[..n].to_vec();
        seal(&mut cut);
        assert_parse_error(load(&cut), &format!("{n} bytes, resealed"));
    }
}

/// Each section (and each of a group's model sections) with a byte
/// flipped: refused by the checksum; resealed, refused or loaded as a
/// hierarchy that passes `validate`, never a panic.
#[test]
fn a_flipped_byte_in_each_section_is_an_error() {
    let (_, bytes) = small();
    let mut places: Vec<(String, usize, usize)> = sections(&bytes)
        .into_iter()
        .map(|(tag, start, len)| (String::from_utf8_lossy(&tag).into_owned(), start, len))
        .collect();
    assert_eq!(places.len(), 6);
    let (_, grps, _) = sections(&bytes)[5];
    let first = group_records(&bytes[grps..])[0].0 + grps;
    let record = group_record(&bytes, 0);
    for (tag, start, len) in group_layout(&record).3 {
        let name = format!("group 0 {}", String::from_utf8_lossy(&tag));
        places.push((name, first + start, len));
    }
    let (mut refused, mut accepted) = (0, 0);
    for (name, start, len) in places {
        assert!(len > 0, "{name} is empty");
        let mut flipped = bytes.clone();
        flipped[start + len / 2] ^= 0x10;
        assert_parse_error(load(&flipped), &format!("{name} flipped"));
        for k in 0..len.min(48) {
            let at = start + k * len / len.min(48);
            for mask in [0x01u8, 0x80, 0xff] {
                let mut flipped = bytes.clone();
                flipped[at] ^= mask;
                seal(&mut flipped);
                match load(&flipped) {
                    Err(e) => {
                        assert!(e.to_string().contains(FILE), "{e}");
                        refused += 1;
                    }
                    Ok(h) => {
                        h.validate().unwrap();
                        accepted += 1;
                    }
                }
            }
        }
    }
    // Most resealed flips land on counts, indices and structure.
    assert!(
        refused > 2 * accepted,
        "{refused} refused, {accepted} accepted"
    );
}

#[test]
fn a_huge_count_is_an_error_without_allocating() {
    let (h, bytes) = small();
    let huge = [1u64 << 28, u64::from(u32::MAX), 1 << 40, u64::MAX];
    let hier = &bytes[sections(&bytes)[0].1..][..sections(&bytes)[0].2];
    for field in 0..6 {
        let mut at = 0;
        for _ in 0..field {
            varint(hier, &mut at);
        }
        for &n in &huge {
            let file = with_section(&bytes, 0, &set_varint(hier, at, n));
            let text = assert_parse_error(load(&file), &format!("HIER count {field} = {n}"));
            assert!(text.contains("HIER"), "{text}");
        }
    }
    // A group's list counts, its vertex map's, its model's vertex count.
    let g = h.groups().len() - 1;
    let record = group_record(&bytes, g);
    let (inputs, map, _, model) = group_layout(&record);
    for at in [inputs, map] {
        for &n in &huge {
            let file = with_group(&bytes, g, &set_varint(&record, at, n));
            let text = assert_parse_error(load(&file), &format!("group count at {at} = {n}"));
            assert!(text.contains(&format!("group {g} GRPS")), "{text}");
        }
    }
    let (tag, start, len) = model[0];
    assert_eq!(&tag, b"META");
    for field in 0..5 {
        let mut at = 0;
        for _ in 0..field {
            varint(&record[start..], &mut at);
        }
        for &n in &huge {
            let meta = set_varint(&record[start..start + len], at, n);
            let mut lie = record[..start - 8].to_vec();
            lie.extend_from_slice(&(meta.len() as u64).to_le_bytes());
            lie.extend_from_slice(&meta);
            lie.extend_from_slice(&record[start + len..]);
            let file = with_group(&bytes, g, &lie);
            let text = assert_parse_error(load(&file), &format!("META count {field} = {n}"));
            assert!(text.contains(&format!("group {g} META")), "{text}");
        }
    }
    // A section or group length past the end.
    let mut file = bytes.clone();
    let (_, start, _) = sections(&bytes)[3];
    file[start - 8..start].copy_from_slice(&u64::MAX.to_le_bytes());
    seal(&mut file);
    assert_parse_error(load(&file), "section length");
    assert!(LARGEST.load(Ordering::Relaxed) < ALLOCATION_LIMIT);
}

#[test]
fn structural_lies_are_refused() {
    let (h, bytes) = small();
    let g = h.groups().len() - 1;
    let record = group_record(&bytes, g);
    let (inputs, _, flag, _) = group_layout(&record);
    // An input cluster out of range, then one that is another's.
    let mut first = inputs;
    varint(&record, &mut first);
    for c in [h.clusters().len() as u64, 0] {
        let file = with_group(&bytes, g, &set_varint(&record, first, c));
        assert_parse_error(load(&file), &format!("input cluster {c}"));
    }
    // HIER's cluster triangle or strip index count above the clusters'
    // totals (found by the hostile-input harness: it loaded).
    let (_, hier, len) = sections(&bytes)[0];
    let payload = &bytes[hier..hier + len];
    for k in [3, 4] {
        let mut at = 0;
        for _ in 0..k {
            varint(payload, &mut at);
        }
        let n = varint(payload, &mut at.clone());
        let lie = set_varint(payload, at, n + 2);
        let text = assert_parse_error(load(&with_section(&bytes, 0, &lie)), "HIER count");
        // Two more strip indices are read from CSTR, which ends first.
        let expected = if k == 3 { "the clusters hold" } else { "CSTR" };
        assert!(text.contains(expected), "{text}");
    }
    // The own-vertices flag set without the sections.
    let mut lie = record.clone();
    lie[flag] = 1;
    assert_parse_error(load(&with_group(&bytes, g, &lie)), "flag 1");
    lie[flag] = 2;
    assert_parse_error(load(&with_group(&bytes, g, &lie)), "flag 2");
    // A vertex map entry moved to another input vertex: the model's LoD 0
    // no longer draws its input clusters' triangles.
    let (_, map, flag, _) = group_layout(&record);
    let vertices = &h.groups()[g].vertices;
    let mut lie = record[..map].to_vec();
    put_varint(&mut lie, vertices.len() as u64);
    let mut prev = 0i64;
    for (i, &v) in vertices.iter().enumerate() {
        let v = if i + 1 == vertices.len() {
            (i64::from(v) + 1) % h.vertex_count() as i64
        } else {
            i64::from(v)
        };
        put_varint(&mut lie, ((v - prev) << 1 ^ (v - prev) >> 63) as u64);
        prev = v;
    }
    lie.extend_from_slice(&record[flag..]);
    let file = with_group(&bytes, g, &lie);
    let text = assert_parse_error(load(&file), "vertex map");
    assert!(
        text.contains("input clusters hold other triangles"),
        "{text}"
    );
    // A NaN radius.
    let mut level = 0;
    varint(&record, &mut level);
    let mut lie = record.clone();
    lie[level + 20..level + 24].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_parse_error(load(&with_group(&bytes, g, &lie)), "NaN radius");
    // A changed floor: the whole's validation names it.
    let mut lie = record.clone();
    lie[level..level + 4].copy_from_slice(&123.0f32.to_le_bytes());
    let text = assert_parse_error(load(&with_group(&bytes, g, &lie)), "floor");
    assert!(text.contains("floor"), "{text}");
}

/// The coded file (version 7): the same hierarchy back from a third or
/// less of version 4's bytes; every truncation refused; a flipped byte in
/// a frame refused or (resealed) a checked hierarchy; a part announcing
/// more than 1,024 times the file refused before anything is decoded.
#[test]
fn the_coded_file_round_trips_smaller_and_refuses_corruption() {
    let (h, plain) = small();
    let coded = h.to_compressed_bytes(3);
    assert_eq!(
        mts::model::format::file_version(&coded),
        Some(hierarchy::format::CODED_VERSION)
    );
    assert_eq!(holds(&coded), Some(Holds::Hierarchy));
    assert_eq!(load(&coded).unwrap(), h);
    assert!(
        coded.len() * 2 < plain.len(),
        "{} against {}",
        coded.len(),
        plain.len()
    );
    let text = MtsModel::from_bytes(&coded, Path::new(FILE))
        .unwrap_err()
        .to_string();
    assert!(text.contains("hierarchy"), "{text}");
    for n in (0..coded.len()).step_by((coded.len() / 400).max(1)) {
        assert_parse_error(load(&coded[..n]), &format!("{n} bytes"));
        let mut cut = coded[..n].to_vec();
        seal(&mut cut);
        assert_parse_error(load(&cut), &format!("{n} bytes, resealed"));
    }
    let (mut refused, mut accepted) = (0, 0);
    for (tag, start, len) in sections(&coded) {
        for k in 0..len.min(32) {
            let mut flipped = coded.clone();
            flipped[start + k * len / len.min(32)] ^= 0x41;
            assert_parse_error(load(&flipped), "flipped, not resealed");
            seal(&mut flipped);
            match load(&flipped) {
                Err(e) => {
                    let text = e.to_string();
                    assert!(
                        text.contains(FILE),
                        "{}: {text}",
                        String::from_utf8_lossy(&tag)
                    );
                    refused += 1;
                }
                Ok(back) => {
                    back.validate().unwrap();
                    accepted += 1;
                }
            }
        }
    }
    assert!(
        refused > 2 * accepted,
        "{refused} refused, {accepted} accepted"
    );
    // GRPS announcing a terabyte: refused by the bound, nothing allocated
    // for it.
    let (_, grps, len) = sections(&coded)[5];
    let mut part = coded[grps..grps + len].to_vec();
    assert_eq!(part[0], 1, "one part");
    let mut at = 2;
    varint(&part, &mut at);
    let mut huge = part[..2].to_vec();
    put_varint(&mut huge, 1 << 40);
    huge.extend_from_slice(&part[at..]);
    part = huge;
    let bomb = with_section(&coded, 5, &part);
    // A quarter of the bound, announced as steps by column (which decoding
    // holds six times over): over the bound by the weights the model's
    // file uses too.
    let (_, grps, len) = sections(&coded)[5];
    let frame = &coded[grps..grps + len];
    let mut at = 2;
    varint(frame, &mut at);
    let mut steps = vec![1, 3];
    put_varint(&mut steps, 1024 * coded.len() as u64 / 4 / 12 * 12);
    steps.extend_from_slice(&frame[at..]);
    let text = assert_parse_error(load(&with_section(&coded, 5, &steps)), "steps announced");
    assert!(text.contains("more than 1024"), "{text}");
    let before = LARGEST.load(Ordering::Relaxed);
    let text = assert_parse_error(load(&bomb), "a terabyte announced");
    assert!(text.contains("1024"), "{text}");
    assert!(LARGEST.load(Ordering::Relaxed) <= before.max(ALLOCATION_LIMIT));
}
