//! The baselines against the replay oracle and against MTS: every LoD of a
//! generated mesh, spread LoDs of the bunny, switching up, down and at
//! random against switching from scratch, dirty ranges, random meshes
//! (proptest), the progressive mesh file, and the cluster tree's stream.

mod common;

use common::{model, random_surface};
use mts::baselines::{DiscreteLods, MultilevelMesh, ProgressiveMesh};
use mts::mesh::generate::Generated;
use mts::model::sequence;
use mts::strip::sorted_canonical;
use mts::{Collapses, Extractor, LodSource, Mesh, StripifyOptions};
use proptest::prelude::*;

fn torus() -> Mesh {
    "torus:2k".parse::<Generated>().unwrap().build()
}

fn collapses(mesh: &Mesh) -> Collapses {
    mts::simplify(mesh, &Default::default()).collapses
}

/// Every LoD in `lods`, in that order: the source's triangles are the
/// oracle's, and every index that changed lies in a dirty range.
fn check_against_oracle(mesh: &Mesh, c: &Collapses, source: &mut dyn LodSource, lods: &[usize]) {
    let mut before: Vec<u32> = Vec::new();
    for &lod in lods {
        assert_eq!(source.set_lod(lod), lod);
        assert_eq!(source.lod(), Some(lod));
        let got = sorted_canonical(&source.triangles());
        let want = sorted_canonical(&c.triangles_at(mesh, lod));
        assert_eq!(
            got,
            want,
            "{}: LoD {lod} differs from the oracle",
            source.name()
        );
        assert_eq!(source.triangle_count(lod), c.triangle_count(lod));
        let now = source.indices();
        for (i, (a, b)) in before.iter().zip(now).enumerate() {
            if a != b {
                assert!(
                    source.dirty_ranges().iter().any(|r| r.contains(&i)),
                    "{}: LoD {lod}: index {i} changed outside the dirty ranges",
                    source.name()
                );
            }
        }
        for i in before.len()..now.len() {
            assert!(
                source.dirty_ranges().iter().any(|r| r.contains(&i)),
                "{}: LoD {lod}: new index {i} not dirty",
                source.name()
            );
        }
        assert!(source
            .dirty_ranges()
            .windows(2)
            .all(|w| w[0].end < w[1].start));
        before = now.to_vec();
    }
}

/// The orders every source is driven through: down, up, Table 2's random
/// sequence, and alternating extremes.
fn orders(max_lod: usize) -> Vec<Vec<usize>> {
    let down: Vec<usize> = (0..=max_lod).collect();
    let up: Vec<usize> = (0..=max_lod).rev().collect();
    let random = sequence::random(max_lod, 200, 7);
    let jumps: Vec<usize> = (0..20)
        .map(|i| if i % 2 == 0 { max_lod } else { i % 5 })
        .collect();
    vec![down, up, random, jumps]
}

#[test]
fn pm_matches_the_oracle_at_every_lod_of_a_torus() {
    let mesh = torus();
    let c = collapses(&mesh);
    assert_eq!(mesh.triangle_count(), 1936);
    for lods in orders(c.max_lod()) {
        let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
        pm.validate();
        check_against_oracle(&mesh, &c, &mut pm, &lods);
    }
}

#[test]
fn pm_file_round_trips_and_rejects_damage() {
    let mesh = torus();
    let c = collapses(&mesh);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let bytes = pm.to_bytes();
    let mut back = ProgressiveMesh::from_bytes(&bytes, "torus.pm").unwrap();
    back.validate();
    assert_eq!(back.to_bytes(), bytes);
    for lod in [0, 1, 100, c.max_lod() / 2, c.max_lod()] {
        pm.set_lod(lod);
        back.set_lod(lod);
        assert_eq!(pm.indices(), back.indices(), "LoD {lod}");
    }
    // Every truncation is an error, never a panic.
    for len in (0..bytes.len()).step_by(97).chain([bytes.len() - 1]) {
        let e = ProgressiveMesh::from_bytes(&bytes[..len], "cut.pm").unwrap_err();
        assert!(e.to_string().contains("cut.pm"), "{e}");
    }
    let mut long = bytes.clone();
    long.push(0);
    assert!(ProgressiveMesh::from_bytes(&long, "long.pm")
        .unwrap_err()
        .to_string()
        .contains("unexpected bytes"));
    let mut magic = bytes.clone();
    magic[0] ^= 1;
    assert!(ProgressiveMesh::from_bytes(&magic, "m.pm")
        .unwrap_err()
        .to_string()
        .contains("not a progressive mesh"));
    // Flipped bytes past the positions: an error or a valid mesh, never a panic.
    let records = 28 + 12 * mesh.vertex_count();
    for at in (records..bytes.len()).step_by(13) {
        let mut b = bytes.clone();
        b[at] ^= 0x5a;
        if let Ok(pm) = ProgressiveMesh::from_bytes(&b, "flip.pm") {
            pm.validate();
        }
    }
}

#[test]
fn multilevel_matches_the_oracle_at_every_lod_of_a_torus() {
    let mesh = torus();
    let c = collapses(&mesh);
    for lods in orders(c.max_lod()) {
        let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
        ml.validate();
        check_against_oracle(&mesh, &c, &mut ml, &lods);
    }
}

#[test]
fn switching_gives_the_same_buffer_as_from_scratch() {
    let mesh = torus();
    let c = collapses(&mesh);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
    for lod in sequence::random(c.max_lod(), 100, 3) {
        pm.set_lod(lod);
        ml.set_lod(lod);
        let mut fresh_pm = ProgressiveMesh::new(&mesh, &c).unwrap();
        let mut fresh_ml = MultilevelMesh::new(&mesh, &c).unwrap();
        fresh_pm.set_lod(lod);
        fresh_ml.set_lod(lod);
        assert_eq!(pm.indices(), fresh_pm.indices(), "pm at LoD {lod}");
        assert_eq!(ml.indices(), fresh_ml.indices(), "multilevel at LoD {lod}");
        // Both keep the level order, so their buffers agree index for index.
        assert_eq!(pm.indices(), ml.indices(), "pm and multilevel at LoD {lod}");
    }
}

#[test]
fn pm_and_multilevel_draw_what_mts_draws() {
    let mesh = torus();
    let c = collapses(&mesh);
    let strips = mts::stripify(&mesh, &StripifyOptions::default());
    let model = mts::model::build(&mesh, &strips, &c, &Default::default());
    let mut ex = Extractor::new(&model);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
    for lod in 0..=c.max_lod() {
        LodSource::set_lod(&mut ex, lod);
        pm.set_lod(lod);
        ml.set_lod(lod);
        let want = sorted_canonical(&LodSource::triangles(&ex));
        assert_eq!(sorted_canonical(&pm.triangles()), want, "pm at LoD {lod}");
        assert_eq!(
            sorted_canonical(&ml.triangles()),
            want,
            "multilevel at LoD {lod}"
        );
    }
}

#[test]
fn multilevel_geomorph_ends_at_both_lods() {
    let mesh = torus();
    let c = collapses(&mesh);
    let ml = MultilevelMesh::new(&mesh, &c).unwrap();
    let (fine, coarse) = (100, 600);
    let mut at = Vec::new();
    ml.geomorph(fine, coarse, 1.0, &mut at).unwrap();
    assert_eq!(at.len(), mesh.vertex_count() - fine);
    assert_eq!(at, ml.positions()[..mesh.vertex_count() - fine]);
    ml.geomorph(fine, coarse, 0.0, &mut at).unwrap();
    // At t = 0 the fine triangles read through the coarse representatives:
    // every vertex sits on a vertex of LoD `coarse`.
    let coarse_vertices = &ml.positions()[..mesh.vertex_count() - coarse];
    assert!(at.iter().all(|p| coarse_vertices.contains(p)));
    let moved = at
        .iter()
        .zip(ml.positions())
        .filter(|(a, b)| a != b)
        .count();
    // Exactly the vertices removed between the two LoDs move (a torus
    // has no two vertices at one position).
    assert_eq!(moved, coarse - fine);
    ml.geomorph(fine, coarse, 0.5, &mut at).unwrap();
    assert!(ml.geomorph(coarse, fine, 0.5, &mut at).is_err());
    assert!(ml.geomorph(fine, coarse, 1.5, &mut at).is_err());
}

#[test]
fn multilevel_memory_is_within_the_papers_bound() {
    let mesh = torus();
    let c = collapses(&mesh);
    let ml = MultilevelMesh::new(&mesh, &c).unwrap();
    let (v, t) = (mesh.vertex_count(), mesh.triangle_count());
    // 16-bit indices: 12 per vertex, 6 per triangle, 2 per removed vertex.
    assert_eq!(ml.raw_bytes(), 12 * v + 6 * t);
    assert_eq!(ml.structure_bytes(), 12 * v + 6 * t + 2 * c.max_lod());
    assert!(ml.structure_bytes() as f64 <= 1.1 * ml.raw_bytes() as f64);
}

#[test]
fn discrete_answers_with_the_coarsest_level_above_the_budget() {
    let mesh = torus();
    let c = collapses(&mesh);
    let mut d = DiscreteLods::new(&mesh, c.triangle_counts());
    assert_eq!(d.level_triangles(0), 1936);
    assert!(d.level_count() >= 4, "{} levels", d.level_count());
    for l in 1..d.level_count() {
        assert!(d.level_triangles(l) < d.level_triangles(l - 1));
    }
    assert_eq!(d.set_lod(0), 0);
    assert_eq!(
        d.dirty_ranges(),
        &[0..3
            * (0..d.level_count())
                .map(|l| d.level_triangles(l))
                .sum::<usize>()]
    );
    assert_eq!(
        sorted_canonical(&d.triangles()),
        sorted_canonical(&mesh.triangles)
    );
    for lod in [1, 500, c.max_lod()] {
        d.set_lod(lod);
        assert!(d.dirty_ranges().is_empty());
        let level = d.level_for(lod);
        assert!(d.triangle_count(lod) >= c.triangle_count(lod));
        assert!(
            level + 1 == d.level_count() || d.level_triangles(level + 1) < c.triangle_count(lod)
        );
        assert_eq!(d.indices().len(), 3 * d.level_triangles(level));
    }
}
