//! meshoptimizer's cluster LoD as a peer (`peers::clusterlod`): the DAG
//! of a mesh, and its cut for a viewpoint by the core's projected-error
//! rule. Full detail at threshold 0, fewer triangles farther away and at
//! larger thresholds, no crack on closed surfaces, no panic on odd input.
#![cfg(feature = "peers")]

mod common;

use glam::{Vec2, Vec3};
use mts::mesh::generate::Generated;
use mts::peers::clusterlod::{self, ClusterLod, Cut};
use mts::strip::sorted_canonical;
use mts::{Error, Mesh, Projection};
use proptest::prelude::*;
use std::collections::HashMap;

const CAMERA: Projection = Projection::Perspective {
    fov_y: std::f32::consts::FRAC_PI_3,
    viewport_height: 1080.0,
};

fn generated(name: &str) -> Mesh {
    name.parse::<Generated>().unwrap().build()
}

fn built(mesh: &Mesh) -> ClusterLod {
    let lod = ClusterLod::build(mesh).unwrap();
    assert_eq!(lod.validate(), Ok(()));
    lod
}

/// Eyes around a unit sphere: near the surface, a little out, far.
fn eyes() -> Vec<Vec3> {
    let directions = [
        Vec3::Z,
        Vec3::new(1.0, 1.0, 0.3).normalize(),
        Vec3::new(-0.4, 0.2, -1.0).normalize(),
    ];
    let distances = [1.15f32, 1.5, 3.0, 8.0];
    directions
        .iter()
        .flat_map(|&d| distances.iter().map(move |&r| d * r))
        .collect()
}

/// What keeps a set of triangles from being a closed, consistently
/// oriented surface, judged by positions.
#[derive(Debug, Default, PartialEq)]
struct Defects {
    /// Edges used more often one way than the other: a hole, a T-junction
    /// or a flipped triangle.
    open_edges: usize,
    /// Pairs of coincident triangles of opposite orientation: a fold of
    /// zero area, closed on both sides.
    folds: usize,
    /// Edges used more than once each way once the folds are set aside.
    non_manifold_edges: usize,
}

/// The triangles on one set of three points: each way round.
type BothWays = (Vec<[u32; 3]>, Vec<[u32; 3]>);

fn defects(positions: &[Vec3], triangles: &[[u32; 3]]) -> Defects {
    let mut point = HashMap::new();
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let next = point.len() as u32;
            *point.entry(p.to_array().map(f32::to_bits)).or_insert(next)
        })
        .collect();
    // Per set of three points: the triangles each way round.
    let mut faces: HashMap<[u32; 3], BothWays> = HashMap::new();
    for t in triangles {
        let p = t.map(|v| ids[v as usize]);
        let mut key = p;
        key.sort_unstable();
        let even = [
            [key[0], key[1], key[2]],
            [key[1], key[2], key[0]],
            [key[2], key[0], key[1]],
        ]
        .contains(&p);
        let entry = faces.entry(key).or_default();
        if even {
            entry.0.push(p);
        } else {
            entry.1.push(p);
        }
    }
    let mut found = Defects::default();
    // Per undirected edge: uses as (low, high) and as (high, low).
    let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    for (even, odd) in faces.values() {
        let pairs = even.len().min(odd.len());
        found.folds += pairs;
        for p in even.iter().skip(pairs).chain(odd.iter().skip(pairs)) {
            for k in 0..3 {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                let entry = uses.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    entry.0 += 1;
                } else {
                    entry.1 += 1;
                }
            }
        }
    }
    found.open_edges = uses.values().filter(|u| u.0 != u.1).count();
    found.non_manifold_edges = uses.values().filter(|u| u.0 == u.1 && u.0 > 1).count();
    found
}

#[test]
fn the_default_raster_configuration_is_recorded() {
    let c = clusterlod::config();
    assert_eq!(
        (c.max_vertices, c.min_triangles, c.max_triangles),
        (128, 42, 128)
    );
    assert!(c.partition_spatial && !c.partition_sort);
    assert_eq!(c.partition_size, 16);
    assert!(!c.cluster_spatial);
    assert_eq!(c.cluster_split_factor, 2.0);
    assert!(c.optimize_clusters && !c.optimize_bounds);
    assert_eq!(c.optimize_clusters_level, 1);
    assert_eq!((c.simplify_ratio, c.simplify_threshold), (0.5, 0.85));
    assert_eq!(
        (
            c.simplify_error_merge_previous,
            c.simplify_error_merge_additive
        ),
        (1.0, 0.0)
    );
    assert_eq!(c.simplify_error_factor_sloppy, 2.0);
    assert_eq!(c.simplify_error_edge_limit, 0.0);
    assert!(c.simplify_error_clamped && c.simplify_permissive && c.simplify_fallback_sloppy);
    assert!(!c.simplify_fallback_permissive && !c.simplify_regularize);
    assert!(!c.simplify_preserve_folds && !c.simplify_dilate_borders);
}

#[test]
fn a_quad_is_one_terminal_cluster_drawn_at_any_threshold() {
    //  3 ─── 2
    //  │   ╱ │
    //  │  ╱  │
    //  │ ╱   │
    //  0 ─── 1
    let mesh = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        properties: Default::default(),
    };
    let lod = built(&mesh);
    assert_eq!(
        (lod.groups().len(), lod.clusters().len(), lod.level_count()),
        (1, 1, 1)
    );
    assert!(lod.groups()[0].simplified.is_terminal());
    assert_eq!(lod.clusters()[0].refined, None);
    assert_eq!(lod.clusters()[0].bounds.error, 0.0);
    for threshold in [0.0, 1.0, 1e30] {
        let cut = lod.cut(Vec3::new(0.0, 0.0, 1e6), CAMERA, threshold);
        assert_eq!((cut.cluster_count(), cut.triangle_count()), (1, 2));
        assert_eq!(
            sorted_canonical(&cut.triangles),
            sorted_canonical(&mesh.triangles)
        );
    }
}

#[test]
fn threshold_zero_draws_exactly_the_input() {
    for name in ["icosphere:20k", "grid:20k"] {
        let mesh = generated(name);
        let lod = built(&mesh);
        assert_eq!(lod.triangle_count(), mesh.triangle_count(), "{name}");
        assert!(
            lod.level_count() > 1,
            "{name}: {} levels",
            lod.level_count()
        );
        // Zero, and thresholds that mean nothing, ask for full detail.
        for threshold in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let cut = lod.cut(Vec3::new(0.0, 0.0, 1e4), CAMERA, threshold);
            assert_eq!(
                sorted_canonical(&cut.triangles),
                sorted_canonical(&mesh.triangles),
                "{name} at {threshold}"
            );
            let input_clusters = lod
                .clusters()
                .iter()
                .filter(|c| c.refined.is_none())
                .count();
            assert_eq!(cut.cluster_count(), input_clusters);
        }
    }
}

#[test]
fn a_far_camera_draws_fewer_triangles_and_the_farthest_the_coarsest() {
    for name in ["icosphere:20k", "grid:20k"] {
        let mesh = generated(name);
        let lod = built(&mesh);
        let centre = mesh.bounds().map(|(lo, hi)| 0.5 * (lo + hi)).unwrap();
        let size = mesh.diagonal();
        let drawn = |distance: f32| {
            lod.cut(
                centre + Vec3::new(0.3, 0.5, 1.0).normalize() * distance * size,
                CAMERA,
                1.0,
            )
            .triangle_count()
        };
        let counts: Vec<usize> = [0.6f32, 1.0, 3.0, 10.0, 100.0, 1e4].map(drawn).to_vec();
        assert!(
            counts.windows(2).all(|w| w[1] <= w[0]),
            "{name}: {counts:?}"
        );
        assert!(counts[3] < mesh.triangle_count(), "{name}: {counts:?}");
        // Beyond every error: the terminal groups' clusters, nothing else.
        let coarsest: usize = lod
            .groups()
            .iter()
            .filter(|g| g.simplified.is_terminal())
            .flat_map(|g| g.clusters.clone())
            .map(|c| lod.clusters()[c as usize].triangles.len())
            .sum();
        assert_eq!(drawn(1e9), coarsest, "{name}");
        assert!(coarsest < mesh.triangle_count() / 10, "{name}: {coarsest}");
    }
}

#[test]
fn cuts_of_a_closed_icosphere_are_crack_free() {
    let mesh = generated("icosphere:20k");
    assert_eq!(
        defects(&mesh.positions, &mesh.triangles),
        Defects::default()
    );
    let lod = built(&mesh);
    // meshoptimizer leaves one fold in this DAG: a cluster at depth 6 holds
    // one triangle both ways round (found by this test; not an opening).
    let folded: Vec<bool> = (0..lod.clusters().len())
        .map(|c| defects(lod.positions(), lod.cluster_triangles(c)).folds > 0)
        .collect();
    assert_eq!(folded.iter().filter(|&&f| f).count(), 1);
    let mut cut = Cut::default();
    let mut mixed = 0;
    for eye in eyes() {
        for threshold in [0.5f32, 1.0, 2.0, 4.0, 32.0] {
            lod.cut_into(eye, CAMERA, threshold, &mut cut);
            let drawn_folds = cut.clusters.iter().filter(|&&c| folded[c as usize]).count();
            assert_eq!(
                defects(lod.positions(), &cut.triangles),
                Defects {
                    folds: drawn_folds,
                    ..Defects::default()
                },
                "eye {eye}, {threshold} px: {} triangles",
                cut.triangle_count()
            );
            let depth = |c: &u32| lod.groups()[lod.clusters()[*c as usize].group as usize].depth;
            let deepest = cut.clusters.iter().map(depth).max().unwrap();
            let shallowest = cut.clusters.iter().map(depth).min().unwrap();
            mixed += usize::from(deepest > shallowest);
        }
    }
    // A third of the cuts join clusters of several depths (22 of 60 with
    // meshoptimizer 1.3): borders between depths are tested.
    assert!(mixed >= 20, "{mixed} of 60 cuts mix depths");
}

#[test]
fn cuts_of_a_seamed_torus_keep_their_seams_closed() {
    // Split vertices at the UV seams: permissive simplification with the
    // seams protected, as in meshoptimizer's demo, must not open them.
    let mesh = "torus:20k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    assert!(!mesh.properties.position_ids.is_empty() && mesh.properties.uvs.is_some());
    assert_eq!(
        defects(&mesh.positions, &mesh.triangles),
        Defects::default()
    );
    let lod = built(&mesh);
    assert_eq!(lod.triangle_count(), mesh.triangle_count());
    for eye in eyes() {
        for threshold in [0.5f32, 2.0] {
            let cut = lod.cut(eye * 2.0, CAMERA, threshold);
            assert_eq!(
                defects(lod.positions(), &cut.triangles),
                Defects::default(),
                "eye {eye}, {threshold} px"
            );
        }
    }
}

#[test]
fn a_larger_threshold_or_a_farther_eye_never_draws_more() {
    let mesh = generated("icosphere:20k");
    let lod = built(&mesh);
    let thresholds = [0.0f32, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 32.0, 1e3];
    for eye in eyes() {
        let counts: Vec<usize> = thresholds
            .iter()
            .map(|&t| lod.cut(eye, CAMERA, t).triangle_count())
            .collect();
        assert!(
            counts.windows(2).all(|w| w[1] <= w[0]),
            "eye {eye}: {counts:?}"
        );
        assert!(counts[0] == mesh.triangle_count() && counts[8] < counts[0]);
        let along: Vec<usize> = [1.1f32, 1.2, 1.5, 2.0, 4.0, 16.0, 64.0]
            .iter()
            .map(|&r| lod.cut(eye.normalize() * r, CAMERA, 1.0).triangle_count())
            .collect();
        assert!(
            along.windows(2).all(|w| w[1] <= w[0]),
            "toward {eye}: {along:?}"
        );
    }
}

#[test]
fn the_group_test_is_monotone_up_the_dag() {
    // What makes the cut consistent: a group's sphere holds its children's,
    // its error is at least theirs, so a group within the threshold has
    // every child within it too.
    let mesh = generated("icosphere:20k");
    let lod = built(&mesh);
    let groups = lod.groups();
    for c in lod.clusters() {
        let Some(r) = c.refined else { continue };
        let (parent, child) = (
            &groups[c.group as usize].simplified,
            &groups[r as usize].simplified,
        );
        let reach = parent.centre.distance(child.centre) + child.radius;
        assert!(
            reach <= parent.radius * (1.0 + 1e-5),
            "{parent:?} does not hold {child:?}"
        );
        assert!(child.error <= parent.error);
    }
    for eye in eyes() {
        for threshold in [0.5f32, 1.0, 2.0, 8.0] {
            let within: Vec<bool> = groups
                .iter()
                .map(|g| g.simplified.projects_within(eye, CAMERA, threshold))
                .collect();
            for c in lod.clusters() {
                if let Some(r) = c.refined {
                    assert!(!within[c.group as usize] || within[r as usize]);
                }
            }
        }
    }
}

#[test]
fn errors_convert_to_the_cores_unit() {
    let mesh = generated("icosphere:20k");
    let lod = built(&mesh);
    let d = mesh.diagonal();
    assert_eq!(lod.diagonal(), d);
    let g = lod
        .groups()
        .iter()
        .find(|g| g.simplified.error > 0.0 && !g.simplified.is_terminal());
    let b = g.unwrap().simplified;
    assert_eq!(b.relative_error(d), b.error / d);
    let terminal = lod.groups().last().unwrap().simplified;
    assert!(terminal.is_terminal());
    assert_eq!(terminal.relative_error(d), f32::INFINITY);
    // The threshold is met exactly at error × pixels per unit = threshold.
    let eye = b.centre + Vec3::X * (b.radius + 3.0);
    let pixels = b.error * CAMERA.pixels_per_unit(3.0);
    assert!(b.projects_within(eye, CAMERA, pixels * 1.001));
    assert!(!b.projects_within(eye, CAMERA, pixels * 0.999));
    // Inside the sphere only a zero error is small enough; a projection that
    // shows nothing takes any finite error.
    assert!(!b.projects_within(b.centre, CAMERA, 1e30));
    let blind = Projection::Perspective {
        fov_y: f32::NAN,
        viewport_height: 1080.0,
    };
    assert!(b.projects_within(eye, blind, 1.0) && !terminal.projects_within(eye, blind, 1.0));
}

#[test]
fn odd_meshes_are_empty_dags_or_errors_never_panics() {
    let empty = built(&Mesh::default());
    assert_eq!(
        (
            empty.clusters().len(),
            empty.level_count(),
            empty.triangle_count()
        ),
        (0, 0, 0)
    );
    assert_eq!(empty.cut(Vec3::ZERO, CAMERA, 1.0).triangle_count(), 0);
    let lonely = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X],
        ..Mesh::default()
    };
    assert_eq!(built(&lonely).positions().len(), 2);

    // A repeated index, a collinear triangle, a triangle of one point,
    // then a proper one: meshoptimizer keeps them all in full detail.
    let degenerate = Mesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::Y,
            Vec3::ZERO,
        ],
        triangles: vec![[0, 0, 1], [0, 1, 2], [0, 4, 0], [0, 1, 3]],
        properties: Default::default(),
    };
    let lod = built(&degenerate);
    assert_eq!(lod.triangle_count(), 4);
    assert_eq!(lod.cut(Vec3::Z, CAMERA, 0.0).triangle_count(), 4);

    // 5,000 copies of one triangle: one vertex in every triangle.
    let pile = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        triangles: vec![[0, 1, 2]; 5_000],
        properties: Default::default(),
    };
    let lod = built(&pile);
    assert_eq!(lod.triangle_count(), 5_000);
    let far = lod.cut(Vec3::Z * 1e6, CAMERA, 1.0).triangle_count();
    assert!((1..=5_000).contains(&far), "{far}");

    let refused = |mesh: &Mesh, what: &str| match ClusterLod::build(mesh) {
        Err(Error::InvalidMesh { message, .. }) => assert!(message.contains(what), "{message}"),
        other => panic!("{what}: {other:?}"),
    };
    let mut bad = degenerate.clone();
    bad.triangles.push([0, 1, 5]);
    refused(&bad, "triangle 4 names vertex 5");
    let mut bad = degenerate.clone();
    bad.positions[2].y = f32::NAN;
    refused(&bad, "vertex 2");
    let mut bad = degenerate.clone();
    bad.properties.uvs = Some(vec![Vec2::ZERO; 3]);
    refused(&bad, "texture coordinates");
    let mut bad = degenerate;
    bad.properties.normals = Some(vec![Vec3::new(f32::INFINITY, 0.0, 0.0); 5]);
    refused(&bad, "not finite");
}

#[test]
fn nonsense_viewpoints_draw_a_whole_cut() {
    let mesh = generated("icosphere:20k");
    let lod = built(&mesh);
    for eye in [Vec3::NAN, Vec3::INFINITY, Vec3::ZERO] {
        let cut = lod.cut(eye, CAMERA, 1.0);
        assert_eq!(
            defects(lod.positions(), &cut.triangles).open_edges,
            0,
            "{eye}"
        );
    }
    let ortho = Projection::Orthographic {
        view_height: 3.0,
        viewport_height: 1080.0,
    };
    let cut = lod.cut(Vec3::Z * 5.0, ortho, 1.0);
    assert_eq!(defects(lod.positions(), &cut.triangles).open_edges, 0);
    assert!(cut.triangle_count() < mesh.triangle_count());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_surfaces_give_valid_dags_and_monotone_cuts(mesh in common::random_surface()) {
        let lod = ClusterLod::build(&mesh).unwrap();
        prop_assert_eq!(lod.validate(), Ok(()));
        let eye = Vec3::new(3.0, 2.0, 12.0);
        let full = lod.cut(eye, CAMERA, 0.0);
        prop_assert_eq!(sorted_canonical(&full.triangles), sorted_canonical(&mesh.triangles));
        let mut last = full.triangle_count();
        for threshold in [0.5f32, 2.0, 8.0, 64.0, 1e6] {
            let n = lod.cut(eye, CAMERA, threshold).triangle_count();
            prop_assert!(n <= last && n > 0, "{} after {} at {}", n, last, threshold);
            last = n;
        }
    }
}

/// The report's figures: `cargo test -p mts --features peers --release
/// --test clusterlod -- --ignored --nocapture`.
#[test]
#[ignore = "figures: a 1M-triangle build, run in release"]
fn figures_for_a_million_triangles() {
    let mesh = generated("icosphere:1m");
    let start = std::time::Instant::now();
    let lod = ClusterLod::build(&mesh).unwrap();
    let build = start.elapsed();
    let stored: usize = lod.clusters().iter().map(|c| c.triangles.len()).sum();
    println!(
        "icosphere:1m: {} triangles; DAG built in {:.2} s: {} clusters, {} groups, {} levels, {} triangles stored",
        mesh.triangle_count(),
        build.as_secs_f64(),
        lod.clusters().len(),
        lod.groups().len(),
        lod.level_count(),
        stored
    );
    let folded = (0..lod.clusters().len())
        .filter(|&c| defects(lod.positions(), lod.cluster_triangles(c)).folds > 0)
        .count();
    println!("clusters holding a fold: {folded}");
    let mut cut = Cut::default();
    for (eye, name) in [
        (Vec3::Z * 1.1, "near the surface (1.1)"),
        (Vec3::Z * 3.0, "at 3"),
        (Vec3::Z * 10.0, "at 10"),
    ] {
        for threshold in [0.5f32, 1.0, 2.0] {
            let start = std::time::Instant::now();
            lod.cut_into(eye, CAMERA, threshold, &mut cut);
            let took = start.elapsed();
            println!(
                "eye {name}, {threshold} px: {} clusters, {} triangles ({:.1}% of full detail), cut in {:.3} ms, {:?}",
                cut.cluster_count(),
                cut.triangle_count(),
                100.0 * cut.triangle_count() as f64 / mesh.triangle_count() as f64,
                took.as_secs_f64() * 1e3,
                defects(lod.positions(), &cut.triangles)
            );
        }
    }
}
