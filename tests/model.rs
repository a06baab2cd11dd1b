//! The MTS model against the replay oracle.

use mts::mesh::generate::Generated;
use mts::simplify::SimplifyOptions;
use mts::strip::sorted_canonical;
use mts::{model, stripify, Extractor, Mesh, StripifyOptions};

fn check_all_lods(mesh: &Mesh, step: usize) {
    let strips = stripify(mesh, &StripifyOptions::default());
    let collapses = mts::simplify(mesh, &SimplifyOptions::default()).collapses;
    let m = model::build(mesh, &strips, &collapses, &model::BuildOptions::default());
    m.check().unwrap();
    let mut coherent = Extractor::new(&m);
    let mut scratch = Extractor::new(&m);
    let mut lod = 0;
    while lod <= collapses.max_lod() {
        coherent.set_lod(lod);
        scratch.set_lod_from_scratch(lod);
        assert_eq!(
            coherent.buffer(),
            scratch.buffer(),
            "LoD {lod}: coherent differs"
        );
        let want = sorted_canonical(&collapses.triangles_at(mesh, lod));
        let got = sorted_canonical(&scratch.triangles());
        assert_eq!(got.len(), want.len(), "LoD {lod}: triangle count");
        assert_eq!(got, want, "LoD {lod}: triangles");
        lod += step;
    }
}

#[test]
fn torus_every_lod() {
    let mesh: Mesh = "torus:2k".parse::<Generated>().unwrap().build();
    check_all_lods(&mesh, 1);
}

#[test]
fn file_round_trip_builds_the_same_model() {
    let mesh: Mesh = "icosphere:5k".parse::<Generated>().unwrap().build();
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let m = model::build(&mesh, &strips, &collapses, &model::BuildOptions::default());
    let bytes = m.to_bytes();
    let back = mts::MtsModel::from_bytes(&bytes, std::path::Path::new("mem.mts")).unwrap();
    assert_eq!(back, m);
    println!("{} bytes, raw {}", bytes.len(), m.raw_bytes());
}
