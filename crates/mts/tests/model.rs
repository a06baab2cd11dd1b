//! The MTS model against the replay oracle: every LoD of generated and
//! random meshes, the positional rule recomputed naively, coherent against
//! from-scratch extraction over several LoD sequences, dirty ranges, the
//! `.mts` file (round trip and corrupt bytes), and real models.

mod common;

use common::{model, random_surface};
use mts::mesh::generate::Generated;
use mts::model::{format::seal, BuildOptions};
use mts::simplify::{Placement, SimplifyOptions};
use mts::strip::encode::RESTART_U32;
use mts::strip::sorted_canonical;
use mts::{stripify, Collapses, Extractor, Mesh, MtsModel, StripifyOptions};
use proptest::prelude::*;
use std::path::Path;

fn single_band() -> BuildOptions {
    BuildOptions {
        band_slack: f64::INFINITY,
        ..BuildOptions::default()
    }
}

/// Bands stripified by the cache-aware pass (the `.mts` file records it).
fn cache_aware() -> BuildOptions {
    let d = BuildOptions::default();
    BuildOptions {
        stripify: StripifyOptions {
            cache_aware: true,
            ..d.stripify
        },
        ..d
    }
}

#[test]
fn cache_aware_bands_hold_the_invariant() {
    let mesh: Mesh = "icosphere:5k".parse::<Generated>().unwrap().build();
    let m = build(&mesh, &SimplifyOptions::default(), &cache_aware());
    check_lods(&mesh, &m, 7);
}

fn build(mesh: &Mesh, simplify: &SimplifyOptions, options: &BuildOptions) -> MtsModel {
    let strips = stripify(mesh, &StripifyOptions::default());
    let collapses = mts::simplify(mesh, simplify).collapses;
    mts::model::build(mesh, &strips, &collapses, options)
}

/// The naive positional rule of `build.rs` on one run of representatives:
/// contiguous between live windows `a < b` when `b - a - 3 <= 1 + (b odd)`,
/// otherwise a restart and a start at `b` or (odd `b`) `b - 1`.
fn rule(run: &[u32]) -> Vec<u32> {
    let live: Vec<usize> = (0..run.len().saturating_sub(2))
        .filter(|&i| !mts::mesh::is_degenerate([run[i], run[i + 1], run[i + 2]]))
        .collect();
    let mut out = Vec::new();
    let mut prev: Option<usize> = None;
    for &b in &live {
        let odd = b % 2;
        let start = match prev {
            Some(a) if b as i64 - a as i64 - 3 <= 1 + odd as i64 => a + 3,
            Some(_) => {
                out.push(RESTART_U32);
                b - odd
            }
            None => b - odd,
        };
        let start = prev.map_or(start, |a| start.max(a + 3));
        out.extend((start..=b + 2).map(|p| run[p]));
        prev = Some(b);
    }
    out
}

/// Every `step`-th LoD: the oracle's triangles, coherent output identical
/// to from-scratch output, the compact count, and (single band) the naive
/// rule strip by strip. Dirty ranges cover every changed index.
fn check_lods(mesh: &Mesh, m: &MtsModel, step: usize) {
    m.validate().unwrap();
    let collapses: &Collapses = m.collapses();
    let mut coherent = Extractor::new(m);
    let mut scratch = Extractor::new(m);
    let mut before = coherent.buffer().to_vec();
    let mut compact = Vec::new();
    let mut lod = 0;
    loop {
        coherent.set_lod(lod);
        scratch.set_lod_from_scratch(lod);
        assert_eq!(
            coherent.buffer(),
            scratch.buffer(),
            "LoD {lod}: coherent differs"
        );
        for (i, (a, b)) in before.iter().zip(coherent.buffer()).enumerate() {
            if a != b {
                assert!(
                    coherent.dirty_ranges().iter().any(|r| r.contains(&i)),
                    "LoD {lod}: index {i} changed outside the dirty ranges"
                );
            }
        }
        before.copy_from_slice(coherent.buffer());
        let want = sorted_canonical(&collapses.triangles_at(mesh, lod));
        assert_eq!(sorted_canonical(&scratch.triangles()), want, "LoD {lod}");
        assert_eq!(want.len(), m.triangle_count(lod));
        coherent.write_compact(&mut compact);
        assert_eq!(compact.len(), coherent.indices_sent());
        let active = coherent.active_range();
        assert!(coherent.buffer()[..active.start]
            .iter()
            .all(|&i| i == RESTART_U32));
        assert!(coherent.buffer()[active.end..]
            .iter()
            .all(|&i| i == RESTART_U32));
        if m.band_count() == 1 {
            let rep = collapses.representatives(lod);
            for (s, run) in m.base_strips().runs().enumerate() {
                let r: Vec<u32> = run.iter().map(|&v| rep[v as usize]).collect();
                assert_eq!(coherent.strip(s), &rule(&r)[..], "LoD {lod} strip {s}");
            }
        }
        if lod == collapses.max_lod() {
            break;
        }
        lod = (lod + step).min(collapses.max_lod());
    }
}

#[test]
fn torus_every_lod_one_band_and_banded() {
    let mesh: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
    let one = build(&mesh, &SimplifyOptions::default(), &single_band());
    assert_eq!(one.band_count(), 1);
    check_lods(&mesh, &one, 1);
    let banded = build(&mesh, &SimplifyOptions::default(), &BuildOptions::default());
    assert!(banded.band_count() > 1, "a 2K torus degrades past 10%");
    check_lods(&mesh, &banded, 1);
}

#[test]
fn optimal_placement_every_lod() {
    let mesh: Mesh = "icosphere:1k".parse::<Generated>().unwrap().build();
    let options = SimplifyOptions {
        placement: Placement::Optimal,
        ..SimplifyOptions::default()
    };
    check_lods(&mesh, &build(&mesh, &options, &single_band()), 1);
    check_lods(&mesh, &build(&mesh, &options, &BuildOptions::default()), 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn every_lod_of_random_surfaces(m in random_surface()) {
        check_lods(&m, &build(&m, &SimplifyOptions::default(), &single_band()), 1);
        check_lods(&m, &build(&m, &SimplifyOptions::default(), &BuildOptions::default()), 1);
    }
}

/// The next LoD of a random request sequence: mostly steps of a few LoDs
/// either way (which re-walk strips from one of their segments), now and
/// then a jump anywhere.
fn next_request(x: &mut u64, current: usize, max_lod: usize) -> usize {
    *x ^= *x << 13;
    *x ^= *x >> 7;
    *x ^= *x << 17;
    let r = (*x >> 8) as usize;
    if r % 5 == 0 {
        r / 5 % (max_lod + 1)
    } else {
        (current + r / 5 % 4)
            .saturating_sub(r / 20 % 4)
            .min(max_lod)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Coherence inside strips: random requests give the same buffer as
    /// walking every strip, and every changed index is in a dirty range.
    #[test]
    fn coherent_extraction_equals_scratch_on_random_requests(
        m in random_surface(),
        seed in 1u64..u64::MAX,
    ) {
        for options in [single_band(), BuildOptions::default()] {
            let model = build(&m, &SimplifyOptions::default(), &options);
            let max_lod = model.max_lod();
            let mut coherent = Extractor::new(&model);
            let mut scratch = Extractor::new(&model);
            let mut before = coherent.buffer().to_vec();
            let (mut x, mut lod) = (seed, 0);
            for _ in 0..80 {
                lod = next_request(&mut x, lod, max_lod);
                coherent.set_lod(lod);
                scratch.set_lod_from_scratch(lod);
                prop_assert_eq!(coherent.buffer(), scratch.buffer(), "LoD {}", lod);
                for (i, (a, b)) in before.iter().zip(coherent.buffer()).enumerate() {
                    prop_assert!(
                        a == b || coherent.dirty_ranges().iter().any(|r| r.contains(&i)),
                        "LoD {}: index {} changed outside the dirty ranges", lod, i
                    );
                }
                before.copy_from_slice(coherent.buffer());
            }
        }
    }
}

/// One long strip (the built-in icosphere's LoD 0 is one): random requests
/// near LoD 0 re-walk it from its segments and match the walk from scratch.
#[test]
fn a_long_strip_rewalks_from_its_segments() {
    let mesh: Mesh = "icosphere:20k".parse::<Generated>().unwrap().build();
    let m = build(&mesh, &SimplifyOptions::default(), &BuildOptions::default());
    let mut coherent = Extractor::new(&m);
    let mut scratch = Extractor::new(&m);
    coherent.set_lod(0);
    let (mut x, mut lod) = (0x2545_f491_4f6c_dd1du64, 0);
    let (mut walked, mut whole) = (0, 0);
    for _ in 0..500 {
        lod = next_request(&mut x, lod, 200);
        walked += coherent.set_lod(lod).indices_walked;
        let all = scratch.set_lod_from_scratch(lod).indices_walked;
        assert_eq!(coherent.buffer(), scratch.buffer(), "LoD {lod}");
        let used: usize = (0..m.strip_count()).map(|s| scratch.strip(s).len()).sum();
        assert_eq!(all, used, "from scratch walks every strip whole");
        whole += all;
    }
    // Steps of a few LoDs walk a few segments; jumps (one request in
    // five) walk more.
    assert!(
        walked * 10 < whole,
        "{walked} indices walked, {whole} from scratch"
    );
    // One-step changes near LoD 0 walk a few segments of 32 indices each,
    // not the strip.
    coherent.set_lod(0);
    let mut walked = 0;
    for i in 0..200 {
        walked += coherent.set_lod(1 + i % 2).indices_walked;
    }
    let sent = coherent.indices_sent();
    assert!(
        walked < 200 * 256,
        "{walked} indices walked in 200 one-step changes of a {sent}-index buffer"
    );
}

/// LoD sequences of the paper's Table 2 and a return trip.
fn sequences(max_lod: usize) -> Vec<(&'static str, Vec<usize>)> {
    let linear: Vec<usize> = (0..=max_lod).collect();
    let down: Vec<usize> = (0..=max_lod).rev().collect();
    let mut exponential = vec![0];
    let mut k = 1;
    while k <= max_lod {
        exponential.push(k);
        k *= 2;
    }
    exponential.extend(exponential.clone().into_iter().rev());
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let random = (0..300)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % (max_lod as u64 + 1)) as usize
        })
        .collect();
    vec![
        ("linear", linear),
        ("down", down),
        ("exponential", exponential),
        ("random", random),
    ]
}

#[test]
fn coherent_equals_scratch_on_every_sequence() {
    let mesh: Mesh = "icosphere:20k".parse::<Generated>().unwrap().build();
    let m = build(&mesh, &SimplifyOptions::default(), &BuildOptions::default());
    for (name, seq) in sequences(m.max_lod()) {
        let mut coherent = Extractor::new(&m);
        let mut scratch = Extractor::new(&m);
        let mut walked = 0;
        for &lod in &seq {
            walked += coherent.set_lod(lod).strips_walked;
            scratch.set_lod_from_scratch(lod);
            assert_eq!(coherent.buffer(), scratch.buffer(), "{name}: LoD {lod}");
        }
        if name == "linear" {
            // Coherence re-walks a small share of the strips per step.
            let strips = m.stats().strips;
            assert!(
                walked < strips * seq.len() / 20,
                "{walked} walks over {} steps",
                seq.len()
            );
        }
    }
}

#[test]
fn file_round_trip_builds_the_same_model() {
    let mesh: Mesh = "icosphere:5k".parse::<Generated>().unwrap().build();
    for options in [BuildOptions::default(), single_band(), cache_aware()] {
        let m = build(&mesh, &SimplifyOptions::default(), &options);
        let bytes = m.to_bytes();
        let back = MtsModel::from_bytes(&bytes, Path::new("mem.mts")).unwrap();
        assert_eq!(back, m);
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 3);
        // The recipe alone (version 1) loads by building the same model.
        let recipe = m.to_recipe_bytes();
        assert_eq!(u32::from_le_bytes(recipe[8..12].try_into().unwrap()), 1);
        let built = MtsModel::from_bytes(&recipe, Path::new("mem.mts")).unwrap();
        assert_eq!(built, m);
        assert!(
            recipe.len() < m.raw_bytes(),
            "{} bytes, raw {}",
            recipe.len(),
            m.raw_bytes()
        );
        // The ready file is the recipe, the model's arrays (positions are
        // in the recipe already), the LoD → triangle table, and the empty
        // property and companion sections (one byte per step), plus section
        // headers and counts: nothing else.
        let arrays = m.stats().memory_bytes - 12 * m.positions().len();
        let table = 4 * (m.max_lod() + 1) + m.max_lod();
        let extra = bytes.len() - recipe.len();
        assert!(
            extra >= arrays + table && extra <= arrays + table + 100,
            "{extra} extra bytes for {arrays} bytes of arrays and {table} of table"
        );
    }
    let opt = SimplifyOptions {
        placement: Placement::Optimal,
        ..SimplifyOptions::default()
    };
    let m = build(&mesh, &opt, &BuildOptions::default());
    let back = MtsModel::from_bytes(&m.to_bytes(), Path::new("mem.mts")).unwrap();
    assert_eq!(back, m);
}

fn small_file() -> Vec<u8> {
    let mesh: Mesh = "torus:300".parse::<Generated>().unwrap().build();
    build(&mesh, &SimplifyOptions::default(), &BuildOptions::default()).to_bytes()
}

fn load_error(bytes: &[u8]) -> mts::Error {
    MtsModel::from_bytes(bytes, Path::new("bad.mts")).expect_err("corrupt file accepted")
}

/// The section and byte offset a load error names (panics on any other
/// error than a parse error).
fn place_of(e: &mts::Error) -> (&str, u64) {
    match e {
        mts::Error::Parse { file, place, .. } => {
            assert_eq!(file, Path::new("bad.mts"));
            (place.element.as_deref().unwrap(), place.byte.unwrap())
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// Offset of a section's payload.
fn section(bytes: &[u8], tag: &[u8; 4]) -> usize {
    let mut at = 32;
    loop {
        let len = u64::from_le_bytes(bytes[at + 4..at + 12].try_into().unwrap()) as usize;
        if &bytes[at..at + 4] == tag {
            return at + 12;
        }
        at += 12 + len;
    }
}

/// The `MODL` section's counts (strips, bands, beginnings, records, far
/// arcs) and the offset just after them, where the widths are.
fn modl_counts(file: &[u8]) -> (usize, [usize; 5]) {
    let mut at = section(file, b"MODL");
    let mut counts = [0usize; 5];
    for c in &mut counts {
        let (mut v, mut shift) = (0usize, 0);
        loop {
            let b = file[at];
            at += 1;
            v |= usize::from(b & 0x7f) << shift;
            shift += 7;
            if b & 0x80 == 0 {
                break;
            }
        }
        *c = v;
    }
    (at, counts)
}

#[test]
fn corrupt_files_get_errors_naming_the_place() {
    let good = small_file();
    let n = good.len() as u64;
    // Truncated: the header's file length (byte 16) disagrees.
    let e = load_error(&good[..good.len() - 7]);
    assert_eq!(place_of(&e), ("header", 16), "{e}");
    let mut b = good.clone();
    b[0] = b'X';
    let e = load_error(&b);
    assert!(matches!(e, mts::Error::UnknownFormat { .. }), "{e:?}");
    let mut b = good.clone();
    b[8] = 9;
    let e = load_error(&b);
    assert!(matches!(e, mts::Error::UnknownFormat { .. }), "{e:?}");
    // A flipped byte: the header's checksum (byte 24) disagrees.
    let mut b = good.clone();
    b[good.len() - 1] ^= 0x55;
    assert_eq!(place_of(&load_error(&b)), ("header", 24));
    // Past the checksum: absurd counts, bad indices, NaN, bad steps, each
    // at the start of its section's payload.
    let meta = section(&good, b"META");
    let mut b = good.clone();
    b[meta..meta + 3].copy_from_slice(&[0xff, 0xff, 0x7f]); // 2,097,151 vertices
    seal(&mut b);
    assert_eq!(place_of(&load_error(&b)), ("META", meta as u64));
    let posi = section(&good, b"POSI");
    let mut b = good.clone();
    b[posi..posi + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    seal(&mut b);
    assert_eq!(place_of(&load_error(&b)), ("POSI", posi as u64));
    let step = section(&good, b"STEP");
    let mut b = good.clone();
    b[step] = 0x7e; // a first step whose fields no longer parse as written
    seal(&mut b);
    assert_eq!(place_of(&load_error(&b)), ("STEP", step as u64));
    // The ready model: a width that is neither 2 nor 4, and a record whose
    // arc jumps out of its strip, each named in MODL.
    let (at, [strips, bands, begins, records, far]) = modl_counts(&good);
    let mut b = good.clone();
    b[at] = 3;
    seal(&mut b);
    let e = load_error(&b);
    assert_eq!(place_of(&e), ("MODL", at as u64), "{e}");
    assert!(e.to_string().contains("vertex width 3"), "{e}");
    let (vw, lw) = (usize::from(good[at]), usize::from(good[at + 1]));
    let codes = at + 2 + 4 * (2 * bands + 1 + 3 * strips + 2 + 2 * begins) + (vw + lw) * records;
    assert_eq!(far, 0);
    let mut b = good.clone();
    b[codes + records - 1] = 5; // the last record jumps past the end
    seal(&mut b);
    let e = load_error(&b);
    assert_eq!(place_of(&e).0, "MODL", "{e}");
    assert!(
        e.to_string().contains("not a later node of the strip"),
        "{e}"
    );
    // Bytes after the last section: named at the end of the table.
    let mut b = good.clone();
    b.extend_from_slice(&[0; 16]);
    seal(&mut b);
    assert_eq!(place_of(&load_error(&b)), ("section table", n));
    // Every truncation and every single-byte flip (sealed) is an error or
    // a valid model, never a panic.
    for cut in (0..good.len()).step_by(7) {
        let _ = MtsModel::from_bytes(&good[..cut], Path::new("cut.mts"));
    }
    for i in (32..good.len()).step_by(3) {
        let mut b = good.clone();
        b[i] ^= 0xa5;
        seal(&mut b);
        if let Ok(m) = MtsModel::from_bytes(&b, Path::new("flip.mts")) {
            m.validate().unwrap();
            let mut ex = Extractor::new(&m);
            ex.set_lod(m.max_lod() / 2);
            assert_eq!(ex.overflows(), 0);
        }
    }
}

#[test]
fn fuzz_findings_stay_fixed() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    // Files here are load_mts findings; the loaders' findings sit in
    // folders of their own (tests/hostile.rs reads them).
    for e in entries.flatten().filter(|e| e.path().is_file()) {
        let bytes = std::fs::read(e.path()).unwrap();
        let mut sealed = bytes.clone();
        seal(&mut sealed);
        for b in [&bytes, &sealed] {
            if let Ok(m) = MtsModel::from_bytes(b, &e.path()) {
                m.validate().unwrap();
                let mut ex = Extractor::new(&m);
                ex.set_lod(m.max_lod());
                assert_eq!(ex.overflows(), 0);
            }
        }
    }
}

#[test]
fn bunny_quality_size_and_oracle() {
    let Some(mesh) = model("bunny.ply") else {
        return;
    };
    let m = build(&mesh, &SimplifyOptions::default(), &BuildOptions::default());
    check_lods(&mesh, &m, 97);
    // The recipe-only file is within the 1.5 x raw; the ready
    // file (what `save` writes) is not: see docs/experiments/compact-model.md.
    let bytes = m.to_recipe_bytes().len();
    assert!(
        bytes * 2 <= m.raw_bytes() * 3,
        "{bytes} bytes, raw {}",
        m.raw_bytes()
    );
    let mut ex = Extractor::new(&m);
    for ratio in [0.5, 0.25, 0.1, 0.05, 0.01] {
        let lod = m.lod_for_ratio(ratio);
        ex.set_lod(lod);
        let fresh = stripify(
            &m.collapses().mesh_at(&mesh, lod),
            &StripifyOptions::default(),
        );
        let q = ex.indices_sent() as f64 / fresh.restart_index_count() as f64;
        assert!(
            q <= 1.15,
            "{ratio}: {q:.3} x the indices of stripifying that level"
        );
    }
}

/// Every LoD of models up to this many triangles is verified; larger
/// ones at [`SPREAD_LODS`] LoDs spread over the sequence.
const EVERY_LOD_UP_TO: usize = 20_000;
const SPREAD_LODS: usize = 200;

fn verify_model(name: &str, mesh: &Mesh) {
    let m = build(mesh, &SimplifyOptions::default(), &BuildOptions::default());
    m.validate().unwrap();
    let n = (mesh.triangle_count() > EVERY_LOD_UP_TO).then_some(SPREAD_LODS);
    let lods = mts::model::spread_lods(m.max_lod(), n);
    let report = mts::model::verify(&m, mesh, &lods);
    assert_eq!(report.lods_checked, lods.len(), "{name}");
    assert!(report.lods_checked >= SPREAD_LODS.min(m.max_lod() + 1));
    assert_eq!(
        report.mismatches, 0,
        "{name}: first mismatch {:?}",
        report.first_mismatch
    );
}

#[test]
fn generated_meshes_hold_the_invariant() {
    for g in ["icosphere:20k", "torus:8k", "grid:5k", "icosphere:80k"] {
        let mesh: Mesh = g.parse::<Generated>().unwrap().build();
        verify_model(g, &mesh);
    }
}

#[test]
fn real_models_hold_the_invariant() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        eprintln!("skipped: {} not found", dir.display());
        return;
    };
    let mut names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".ply") || n.ends_with(".obj"))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no models in {}", dir.display());
    for name in names {
        let Some(mesh) = model(&name) else { continue };
        verify_model(&name, &mesh);
    }
}

/// Issue 31, item 8: a ready file whose records were changed and the file
/// resealed (checksum recomputed). Loading compares the strips with the
/// recipe's replay at LoD 0 and at one LoD drawn per load
/// (`model/digest.rs`): whatever loads draws the recipe's triangles at LoD
/// 0, and every change to the LoD table at LoD 0 is refused.
#[test]
fn resealed_ready_models_that_lie_are_refused() {
    let good = small_file();
    let (at, [strips, bands, begins, records, far]) = modl_counts(&good);
    let (vw, lw) = (usize::from(good[at]), usize::from(good[at + 1]));
    assert_eq!((vw, lw, far), (2, 2, 0), "the layout this test reads");
    let vertices = at + 2 + 4 * (2 * bands + 1 + 3 * strips + 2 + 2 * begins);
    let labels = vertices + vw * records;
    let codes = labels + lw * records;
    let table = codes + records + 8 * far;
    let model = MtsModel::from_bytes(&good, Path::new("good.mts")).unwrap();
    let add_one = |at: usize, width: usize| {
        let mut b = good.clone();
        if width == 2 {
            let v = u16::from_le_bytes([b[at], b[at + 1]]).wrapping_add(1);
            b[at..at + 2].copy_from_slice(&v.to_le_bytes());
        } else {
            let v = u32::from_le_bytes(b[at..at + 4].try_into().unwrap()).wrapping_add(1);
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        seal(&mut b);
        b
    };
    let mesh = model.mesh();
    let all: Vec<usize> = (0..=model.max_lod()).collect();
    // Each change: refused, harmless (the model still draws the recipe's
    // triangles at every LoD: a field no walk reads), or a lie; whatever
    // loads draws LoD 0 right.
    let judge = |bytes: &[u8]| match MtsModel::from_bytes(bytes, Path::new("bad.mts")) {
        Err(e) => {
            assert!(e.to_string().contains("MODL"), "{e}");
            0
        }
        Ok(m) => {
            assert_eq!(mts::model::verify(&m, &mesh, &[0]).mismatches, 0);
            usize::from(mts::model::verify(&m, &mesh, &all).mismatches != 0) + 1
        }
    };
    // Only records that start a node name a vertex (later arcs of a node
    // repeat nothing).
    let mut vertex = [0; 3];
    for r in 0..records {
        if r == 0 || good[codes + r - 1] & 0x80 == 0 {
            vertex[judge(&add_one(vertices + 2 * r, 2))] += 1;
        }
    }
    let mut label = [0; 3];
    for r in 0..records {
        label[judge(&add_one(labels + 2 * r, 2))] += 1;
    }
    let mut entries = [0; 3];
    for lod in 0..=model.max_lod() {
        entries[judge(&add_one(table + 4 * lod, 4))] += 1;
    }
    eprintln!(
        "refused / harmless / lies: record vertices {vertex:?}, labels {label:?}, table {entries:?}"
    );
    // Band 0's nodes walked at LoD 0 (an eighth of this model's) are
    // always checked, and table entry 0 is read when the file is parsed;
    // the rest is caught when the drawn LoD falls where the lie shows.
    assert!(vertex[0] * 10 > vertex.iter().sum::<usize>(), "{vertex:?}");
    assert!(entries[0] >= 1, "{entries:?}");
}

/// The library refuses, as an error, the options the CLI refuses with a
/// message: optimal placement on a mesh with properties (issue 32).
#[test]
fn options_the_model_cannot_hold_are_an_error_not_a_panic() {
    use mts::model::{try_build_from_mesh, PipelineOptions};
    let mesh = "torus:300"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    let mut options = PipelineOptions::default();
    options.simplify.placement = Placement::Optimal;
    let e = try_build_from_mesh(&mesh, &options, &mut |_, _| {}).unwrap_err();
    assert!(matches!(e, mts::Error::InvalidArgument(_)), "{e:?}");
    assert!(e.to_string().contains("optimal placement"), "{e}");
    let plain: Mesh = "torus:300".parse::<Generated>().unwrap().build();
    let (model, _, _) = try_build_from_mesh(&plain, &options, &mut |_, _| {}).unwrap();
    assert_eq!(model.triangle_count(0), plain.triangle_count());
    assert!(model.max_lod() > 0);
}
