//! Golden `.mts` files: small models made from generated meshes
//! (`tests/golden/`), committed with what they load as — the triangle count
//! and the FNV-1a of the compact extracted index buffer at five LoDs. A
//! change to the loader, the format or the walk that alters what an
//! existing file draws fails here; a change that means to (a new format
//! version) makes new files and says so in its commit.
//!
//! Made with `mts build --generated torus:500`, `--generated grid:200
//! --optimal` and `--generated icosphere:320 --single-band` at 7d1145a.

use mts::checksum::fnv1a64;
use mts::{Extractor, MtsModel};
use std::path::Path;

/// (LoD, triangles, FNV-1a of the compact indices).
type Row = (usize, usize, u64);

/// (file, max LoD, rows at LoDs 0, max/4, max/2, 3·max/4 and max).
const GOLDEN: [(&str, usize, [Row; 5]); 3] = [
    (
        "torus_500.mts",
        231,
        [
            (0, 484, 16087870711033873167),
            (57, 370, 2082910137837571540),
            (115, 254, 1955104882782286438),
            (173, 138, 10434753664607909378),
            (231, 22, 1300129787846654284),
        ],
    ),
    (
        "grid_200_optimal.mts",
        117,
        [
            (0, 200, 677520875999798043),
            (29, 153, 12051581191716939937),
            (58, 101, 15122007031239585250),
            (87, 54, 16298385788210972974),
            (117, 3, 4737157830490732549),
        ],
    ),
    (
        "icosphere_320_single_band.mts",
        160,
        [
            (0, 320, 13256606767329646058),
            (40, 240, 11674595860577191517),
            (80, 160, 5124823488761272581),
            (120, 80, 6654021347831751918),
            // A closed surface folds flat and vanishes: no index at all.
            (160, 0, 14695981039346656037),
        ],
    ),
];

fn indices_hash(ex: &Extractor<'_>) -> u64 {
    let mut compact = Vec::new();
    ex.write_compact(&mut compact);
    let bytes: Vec<u8> = compact.iter().flat_map(|i| i.to_le_bytes()).collect();
    fnv1a64(&bytes)
}

#[test]
fn golden_files_load_as_they_always_did() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let mut report = String::new();
    let mut same = true;
    for (file, max_lod, rows) in GOLDEN {
        let model = MtsModel::load(&dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        model.validate().unwrap();
        let max = model.max_lod();
        let mut got = Vec::new();
        for lod in [0, max / 4, max / 2, 3 * max / 4, max] {
            let mut ex = Extractor::new(&model);
            ex.set_lod(lod);
            // Coherent from a far LoD draws the same as from scratch.
            let mut coherent = Extractor::new(&model);
            coherent.set_lod(max - lod);
            coherent.set_lod(lod);
            assert_eq!(
                indices_hash(&coherent),
                indices_hash(&ex),
                "{file} LoD {lod}"
            );
            got.push((lod, model.triangle_count(lod), indices_hash(&ex)));
        }
        same &= max == max_lod && got == rows;
        report.push_str(&format!("    (\"{file}\", {max}, {got:?}),\n"));
    }
    assert!(same, "golden files load differently; now:\n{report}");
}
