//! The baselines against the replay oracle and against MTS: every LoD of a
//! generated mesh, spread LoDs of the bunny, switching up, down and at
//! random against switching from scratch, dirty ranges, random meshes
//! (proptest), the progressive mesh file, and the cluster tree's stream.

mod common;

use common::{model, random_surface};
use mts::baselines::cluster::stream;
use mts::baselines::{ClusterTree, DiscreteLods, MultilevelMesh, ProgressiveMesh};
use mts::mesh::generate::Generated;
use mts::model::requests;
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
    let random = requests::random(max_lod, 200, 7);
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
        pm.validate().unwrap();
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
    back.validate().unwrap();
    assert_eq!(back.to_bytes(), bytes);
    for lod in [0, 1, 100, c.max_lod() / 2, c.max_lod()] {
        pm.set_lod(lod);
        back.set_lod(lod);
        assert_eq!(pm.indices(), back.indices(), "LoD {lod}");
    }
    // Every truncation is an error, never a panic.
    for len in (0..bytes.len()).step_by(97).chain([bytes.len() - 1]) {
        match ProgressiveMesh::from_bytes(&bytes[..len], "cut.pm").unwrap_err() {
            mts::Error::Parse { file, .. } => assert_eq!(file, std::path::Path::new("cut.pm")),
            other => panic!("{len} bytes: expected a parse error, got {other:?}"),
        }
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
            pm.validate().unwrap();
        }
    }
}

#[test]
fn multilevel_matches_the_oracle_at_every_lod_of_a_torus() {
    let mesh = torus();
    let c = collapses(&mesh);
    for lods in orders(c.max_lod()) {
        let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
        ml.validate().unwrap();
        check_against_oracle(&mesh, &c, &mut ml, &lods);
    }
}

#[test]
fn switching_gives_the_same_buffer_as_from_scratch() {
    let mesh = torus();
    let c = collapses(&mesh);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
    for lod in requests::random(c.max_lod(), 100, 3) {
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
    let all: usize = (0..d.level_count()).map(|l| d.level_triangles(l)).sum();
    assert_eq!(d.dirty_ranges().len(), 1);
    assert_eq!(d.dirty_ranges()[0], 0..3 * all);
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

#[test]
fn cluster_tree_matches_its_own_replay_at_every_lod() {
    let mesh = torus();
    let tree = ClusterTree::new(&mesh).unwrap();
    let c = tree.collapses().clone();
    assert_eq!(c.max_lod(), mesh.vertex_count() - 1);
    for i in 1..c.max_lod() {
        assert!(tree.size(i - 1) <= tree.size(i));
    }
    for lods in orders(c.max_lod()) {
        let mut t = tree.clone();
        check_against_oracle(&mesh, &c, &mut t, &lods);
    }
    // Threshold selection: sizes below the threshold stay joined.
    let s = tree.size(700);
    let lod = tree.lod_for_size(s);
    assert!(lod <= 700 && tree.size(lod) >= s && (lod == 0 || tree.size(lod - 1) < s));
    assert_eq!(tree.lod_for_size(f32::INFINITY), c.max_lod());
    assert_eq!(tree.lod_for_size(0.0), 0);
}

#[test]
fn cluster_refine_then_simplify_returns_the_same_mesh() {
    let mesh = torus();
    let mut tree = ClusterTree::new(&mesh).unwrap();
    for (coarse, fine) in [(900, 10), (500, 499), (967, 0), (300, 100)] {
        tree.set_lod(coarse);
        let before = tree.indices().to_vec();
        tree.set_lod(fine);
        assert_eq!(
            sorted_canonical(&tree.triangles()),
            sorted_canonical(&tree.collapses().triangles_at(&mesh, fine))
        );
        tree.set_lod(coarse);
        assert_eq!(
            tree.indices(),
            &before[..],
            "{coarse} -> {fine} -> {coarse}"
        );
    }
}

/// The decoded stream, mapped back to input numbering, is the input.
fn assert_decodes_to(mesh: &Mesh, tree: &ClusterTree, d: &stream::Decoded) {
    let order = tree.stream_order();
    assert!(d.is_complete());
    assert_eq!(d.positions.len(), mesh.vertex_count());
    for (j, p) in d.positions.iter().enumerate() {
        assert_eq!(*p, mesh.positions[order[j] as usize], "vertex {j}");
    }
    let back: Vec<[u32; 3]> = d
        .triangles
        .iter()
        .map(|t| t.map(|v| order[v as usize]))
        .collect();
    assert_eq!(sorted_canonical(&back), sorted_canonical(&mesh.triangles));
}

#[test]
fn cluster_stream_decodes_to_the_mesh_and_every_prefix_is_valid() {
    let mesh = torus();
    let tree = ClusterTree::new(&mesh).unwrap();
    let bytes = tree.to_stream();
    let raw = 12 * mesh.vertex_count() + 6 * mesh.triangle_count();
    assert!(bytes.len() < raw, "{} bytes against {raw} raw", bytes.len());
    let full = stream::decode(&bytes, "torus.stream").unwrap();
    assert_decodes_to(&mesh, &tree, &full);
    assert_eq!(full.bytes_used, bytes.len());
    assert_eq!(stream::decode_prefix(&bytes, "p").unwrap(), full);
    let mut last = (0, 0);
    for len in stream::HEADER_BYTES..=bytes.len() {
        let d = stream::decode_prefix(&bytes[..len], "prefix").unwrap();
        let m = d.mesh();
        m.validate().unwrap();
        // A prefix is a prefix: what it holds is the start of the full decode.
        assert_eq!(d.positions, full.positions[..d.positions.len()]);
        assert!(d.bytes_used <= len);
        let now = (d.positions.len(), d.triangles.len());
        assert!(now.0 >= last.0 && now.1 >= last.1);
        last = now;
        // Each triangle already decoded may still change vertex as later
        // splits arrive, but it is never degenerate.
        assert!(d.triangles.iter().all(|&t| !mts::mesh::is_degenerate(t)));
    }
    assert_eq!(last, (mesh.vertex_count(), mesh.triangle_count()));
}

#[test]
fn cluster_prefix_with_whole_nodes_is_the_trees_lod() {
    let mesh = torus();
    let mut tree = ClusterTree::new(&mesh).unwrap();
    let bytes = tree.to_stream();
    let n = mesh.vertex_count();
    for len in (stream::HEADER_BYTES..bytes.len()).step_by(211) {
        let d = stream::decode_prefix(&bytes[..len], "prefix").unwrap();
        let vertices = d.positions.len();
        // Only a prefix whose last node has all its new triangles is a LoD.
        let lod = n - vertices;
        if d.triangles.len() != tree.triangle_count(lod) {
            continue;
        }
        tree.set_lod(lod);
        let order = tree.stream_order();
        let back: Vec<[u32; 3]> = d
            .triangles
            .iter()
            .map(|t| t.map(|v| order[v as usize]))
            .collect();
        assert_eq!(
            sorted_canonical(&back),
            sorted_canonical(&tree.triangles()),
            "{len} bytes, LoD {lod}"
        );
    }
}

#[test]
fn corrupt_and_truncated_streams_get_clear_errors() {
    let mesh = torus();
    let tree = ClusterTree::new(&mesh).unwrap();
    let bytes = tree.to_stream();
    let e = stream::decode(&bytes[..10], "short.stream")
        .unwrap_err()
        .to_string();
    assert!(e.contains("short.stream") && e.contains("truncated"), "{e}");
    assert!(stream::decode_prefix(&bytes[..10], "s").is_err());
    for len in [stream::HEADER_BYTES, bytes.len() / 2, bytes.len() - 1] {
        let e = stream::decode(&bytes[..len], "cut.stream")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("checksum") || e.contains("truncated"),
            "{len}: {e}"
        );
    }
    let mut magic = bytes.clone();
    magic[3] = b'X';
    assert!(stream::decode(&magic, "m")
        .unwrap_err()
        .to_string()
        .contains("magic"));
    let mut long = bytes.clone();
    long.push(0);
    assert!(stream::decode(&long, "l").is_err());
    // A flipped bit anywhere in the body: the checksum catches it; the
    // prefix decoder (no checksum) errors or yields a valid mesh.
    for at in (stream::HEADER_BYTES..bytes.len()).step_by(37) {
        let mut b = bytes.clone();
        b[at] ^= 0x10;
        let e = stream::decode(&b, "flip").unwrap_err().to_string();
        assert!(e.contains("checksum"), "{e}");
        if let Ok(d) = stream::decode_prefix(&b, "flip") {
            d.mesh().validate().unwrap();
        }
    }
    // Inconsistent header counts.
    let mut counts = bytes.clone();
    counts[16..20].copy_from_slice(&0u32.to_le_bytes());
    assert!(stream::decode(&counts, "c")
        .unwrap_err()
        .to_string()
        .contains("inconsistent"));
}

#[test]
fn bunny_spread_lods_match_the_oracle_and_mts() {
    let Some(mesh) = model("bunny.ply") else {
        return;
    };
    let c = collapses(&mesh);
    let strips = mts::stripify(&mesh, &StripifyOptions::default());
    let m = mts::model::build(&mesh, &strips, &c, &Default::default());
    let mut ex = Extractor::new(&m);
    let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
    let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
    let mut lods = mts::model::spread_lods(c.max_lod(), Some(25));
    // Down, then back up, then jumps.
    let up: Vec<usize> = lods.iter().rev().copied().collect();
    lods.extend(up);
    lods.extend(requests::random(c.max_lod(), 10, 11));
    for &lod in &lods {
        LodSource::set_lod(&mut ex, lod);
        pm.set_lod(lod);
        ml.set_lod(lod);
        let want = sorted_canonical(&c.triangles_at(&mesh, lod));
        assert_eq!(
            sorted_canonical(&LodSource::triangles(&ex)),
            want,
            "mts at {lod}"
        );
        assert_eq!(sorted_canonical(&pm.triangles()), want, "pm at {lod}");
        assert_eq!(
            sorted_canonical(&ml.triangles()),
            want,
            "multilevel at {lod}"
        );
        assert_eq!(pm.indices(), ml.indices(), "pm and multilevel at {lod}");
    }
    // The paper's memory claim, with 16-bit indices (34,834 vertices).
    assert_eq!(ml.raw_bytes(), 12 * 34_834 + 6 * 69_451);
    assert_eq!(ml.structure_bytes(), ml.raw_bytes() + 2 * c.max_lod());
    assert!((ml.structure_bytes() as f64) < 1.1 * ml.raw_bytes() as f64);
}

#[test]
fn bunny_cluster_stream_is_at_most_85_percent_of_raw() {
    let Some(mesh) = model("bunny.ply") else {
        return;
    };
    let tree = ClusterTree::new(&mesh).unwrap();
    let bytes = tree.to_stream();
    let raw = 12 * mesh.vertex_count() + 6 * mesh.triangle_count();
    assert!(
        bytes.len() * 100 <= raw * 85,
        "{} bytes, {raw} raw",
        bytes.len()
    );
    let d = stream::decode(&bytes, "bunny.stream").unwrap();
    assert_decodes_to(&mesh, &tree, &d);
    let half = stream::decode_prefix(&bytes[..bytes.len() / 2], "half").unwrap();
    half.mesh().validate().unwrap();
    assert!(half.triangles.len() > mesh.triangle_count() / 3);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_meshes_every_lod(mesh in random_surface()) {
        let c = collapses(&mesh);
        let mut pm = ProgressiveMesh::new(&mesh, &c).unwrap();
        let mut ml = MultilevelMesh::new(&mesh, &c).unwrap();
        pm.validate().unwrap();
        ml.validate().unwrap();
        let mut lods: Vec<usize> = (0..=c.max_lod()).collect();
        lods.extend(requests::random(c.max_lod(), 20, 5));
        check_against_oracle(&mesh, &c, &mut pm, &lods);
        check_against_oracle(&mesh, &c, &mut ml, &lods);
        let back = ProgressiveMesh::from_bytes(&pm.to_bytes(), "random.pm").unwrap();
        prop_assert_eq!(back.to_bytes(), pm.to_bytes());
    }

    #[test]
    fn random_meshes_cluster_tree(mesh in random_surface()) {
        let tree = ClusterTree::new(&mesh).unwrap();
        let c = tree.collapses().clone();
        let lods: Vec<usize> = (0..=c.max_lod()).rev().chain(requests::random(c.max_lod(), 20, 9)).collect();
        check_against_oracle(&mesh, &c, &mut tree.clone(), &lods);
        let bytes = tree.to_stream();
        let d = stream::decode(&bytes, "random.stream").unwrap();
        assert_decodes_to(&mesh, &tree, &d);
        for len in stream::HEADER_BYTES..bytes.len() {
            let p = stream::decode_prefix(&bytes[..len], "prefix").unwrap();
            p.mesh().validate().unwrap();
            prop_assert_eq!(&p.positions[..], &d.positions[..p.positions.len()]);
        }
    }
}

#[test]
fn cluster_view_dependent_cut_is_finer_near_the_eye() {
    let mesh = torus();
    let tree = ClusterTree::new(&mesh).unwrap();
    let order = tree.stream_order();
    let back = |tris: &[[u32; 3]]| -> Vec<[u32; 3]> {
        tris.iter().map(|t| t.map(|v| order[v as usize])).collect()
    };
    let eye = glam::Vec3::new(3.0, 0.0, 0.0);
    // Threshold 0 unfolds everything; an infinite one nothing.
    assert_eq!(
        sorted_canonical(&back(&tree.view_dependent(eye, 0.0))),
        sorted_canonical(&mesh.triangles)
    );
    assert!(tree.view_dependent(eye, f32::INFINITY).is_empty());
    let (lo, hi) = mesh.bounds().unwrap();
    let mut last = usize::MAX;
    for threshold in [0.001, 0.01, 0.03, 0.1, 0.3] {
        let tris = tree.view_dependent(eye, threshold);
        // Nested cuts: fewer triangles as the threshold grows.
        assert!(
            tris.len() <= last,
            "{threshold}: {} after {last}",
            tris.len()
        );
        last = tris.len();
        let m = Mesh {
            positions: tree.positions().to_vec(),
            triangles: tris.clone(),
            properties: Default::default(),
        };
        assert!(tris.iter().all(|&t| !mts::mesh::is_degenerate(t)));
        assert!(tris
            .iter()
            .flatten()
            .all(|&v| (v as usize) < m.positions.len()));
        // The half of the torus facing the eye keeps more triangles.
        let mid = (lo.x + hi.x) / 2.0;
        let near = tris
            .iter()
            .filter(|t| t.iter().all(|&v| m.positions[v as usize].x > mid))
            .count();
        let far = tris
            .iter()
            .filter(|t| t.iter().all(|&v| m.positions[v as usize].x < mid))
            .count();
        // 0.03 and 0.1 cut the torus: its far half loses more.
        if threshold == 0.03 || threshold == 0.1 {
            assert!(near > 2 * far, "{threshold}: near {near}, far {far}");
        }
    }
}
