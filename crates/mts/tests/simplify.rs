//! The contraction sequence: hand-made meshes with a known outcome, the
//! per-LoD invariants on random meshes (valid indices, no flipped normal,
//! non-increasing counts, consistent representatives), and real models.

use glam::Vec3;
use mts::distance::{surface_distance, Surface, SurfaceDistance};
use mts::mesh::Mesh;
use mts::simplify::{Placement, SimplifyOptions, StopReason};
use mts::{peers, simplify, Collapses};
use proptest::prelude::*;

mod common;
use common::{model, random_surface};

/// A flat `n × n` grid of unit squares in the z = 0 plane, CCW from +z.
fn flat_grid(n: u32) -> Mesh {
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let positions = (0..=n)
        .flat_map(|y| (0..=n).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
        .collect();
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
}

/// Checks every LoD against the naive replay and returns nothing: indices
/// valid, counts as recorded and non-increasing, representatives agree
/// with the forest walk, no triangle turned against its input normal.
fn check_every_lod(mesh: &Mesh, c: &Collapses) {
    c.validate().unwrap();
    let n = mesh.vertex_count() + c.appended().len();
    let positions: Vec<Vec3> = mesh.positions.iter().chain(c.appended()).copied().collect();
    let mut previous = usize::MAX;
    // No contraction makes a fin: an edge with more triangles than two or
    // than the input's most crowded edge.
    let input_crowding = most_crowded_edge(&mesh.triangles).max(2);
    for lod in 0..=c.max_lod() {
        let rep = c.representatives(lod);
        for v in 0..n as u32 {
            assert_eq!(
                rep[v as usize],
                c.representative(v, lod),
                "pc-rep of {v} at {lod}"
            );
        }
        let tris = c.triangles_at(mesh, lod);
        assert_eq!(tris.len(), c.triangle_count(lod), "count at LoD {lod}");
        assert!(tris.len() <= previous, "count grows at LoD {lod}");
        previous = tris.len();
        let mut kept = 0;
        for (t, input) in mesh.triangles.iter().enumerate() {
            let now = input.map(|v| rep[v as usize]);
            if mts::mesh::is_degenerate(now) {
                continue;
            }
            kept += 1;
            assert!(now.iter().all(|&v| (v as usize) < n));
            let normal = |t: [u32; 3]| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                (b - a).cross(c - a)
            };
            let (n0, n1) = (normal(*input), normal(now));
            if n0.length() > 1e-12 && n1.length() > 1e-12 {
                assert!(
                    n0.normalize().dot(n1.normalize()) > 0.0,
                    "triangle {t} flipped at LoD {lod}: {input:?} -> {now:?}"
                );
            }
        }
        assert_eq!(kept, tris.len());
        assert!(
            most_crowded_edge(&tris) <= input_crowding,
            "LoD {lod} has an edge with {} triangles (input: {})",
            most_crowded_edge(&tris),
            most_crowded_edge(&mesh.triangles)
        );
    }
}

/// Triangles on each (unordered) edge.
fn edge_counts(tris: &[[u32; 3]]) -> std::collections::HashMap<(u32, u32), usize> {
    let mut count = std::collections::HashMap::new();
    for t in tris {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    count
}

/// The most triangles on one (unordered) edge.
fn most_crowded_edge(tris: &[[u32; 3]]) -> usize {
    edge_counts(tris).into_values().max().unwrap_or(0)
}

/// A torus whose 10,000 vertices all sit on one point (what a zeroed
/// position stream gives): every triangle is degenerate in space though
/// not by index, every error is zero, and the sequence runs to its end
/// (the torus's topology kept).
/// Each vertex stands for ever more members there, all at distance zero;
/// the member walk is skipped when the triangle inequality already bounds
/// them (before, torus:20k so made took 9.7 s to simplify, torus:40k over
/// a minute: `Contractor::forward_error`).
#[test]
fn a_mesh_on_one_point_simplifies_to_its_end_at_zero_error() {
    let mut mesh = mts::mesh::generate::torus(100, 50);
    for p in &mut mesh.positions {
        *p = Vec3::splat(0.5);
    }
    let s = simplify(&mesh, &SimplifyOptions::default());
    let c = &s.collapses;
    assert!(c.max_lod() >= mesh.vertex_count() / 2, "{}", c.max_lod());
    assert!((0..=c.max_lod()).all(|lod| c.error(lod) == 0.0));
    // Down to a few dozen triangles: a torus keeps its hole (at least 14).
    let last = c.triangle_count(c.max_lod());
    assert!((14..=64).contains(&last), "{last}");
}

#[test]
fn flat_grid_keeps_its_square_with_zero_error() {
    // 4x4 squares, 32 triangles, all in one plane:
    //   12--13--14--15--16
    //   |  / |  / |  / |  /|      every interior or straight-border vertex
    //   ...                      can go at zero cost; the four corners
    //   0 --1 --2 --3 --4        cannot without cutting the square.
    let mesh = flat_grid(4);
    let s = simplify(&mesh, &SimplifyOptions::default());
    let c = &s.collapses;
    check_every_lod(&mesh, c);
    // Two triangles (the square itself) are reached with no error at all...
    let lod = c.lod_for_triangles(2);
    assert_eq!(c.triangle_count(lod), 2);
    assert_eq!(c.error(lod), 0.0);
    let mut corners: Vec<u32> = c.triangles_at(&mesh, lod).into_iter().flatten().collect();
    corners.sort_unstable();
    corners.dedup();
    assert_eq!(corners, vec![0, 4, 20, 24]);
    let d = surface_distance(
        (&mesh).into(),
        Surface::over(&mesh, &c.triangles_at(&mesh, lod)),
        2000,
    );
    assert!(d.hausdorff < 1e-6, "{d:?}");
    // ...and only cutting a corner costs something.
    assert!(c.error(lod + 1) > 0.0);
    // An open sheet is cut down to nothing.
    assert_eq!(s.stop.reason, StopReason::NoTriangleLeft);
    assert_eq!(c.triangle_count(c.max_lod()), 0);
}

#[test]
fn flat_ties_go_to_the_nearest_neighbour() {
    // A flat grid whose second and third columns are 0.1 apart: every
    // contraction that keeps the square is free by the planes, so the
    // order is the tie-break's (the distance moved). The first step joins
    // two vertices of those columns in one row; vertex order would have
    // started at the left column.
    let xs = [0.0, 1.0, 1.1, 3.0, 4.0];
    let mut mesh = flat_grid(4);
    for p in &mut mesh.positions {
        p.x = xs[p.x as usize];
    }
    let s = simplify(&mesh, &SimplifyOptions::default());
    check_every_lod(&mesh, &s.collapses);
    let first = s.collapses.steps()[0];
    let (a, b) = (first.removed, first.kept);
    assert_eq!(a / 5, b / 5, "{first:?}: not in one row");
    let mut columns = [a % 5, b % 5];
    columns.sort_unstable();
    assert_eq!(columns, [1, 2], "{first:?}");
    assert_eq!(first.error, 0.0, "the recorded error has no tie-break term");
}

#[test]
fn tetrahedron_folds_flat_then_vanishes() {
    // The first contraction lands one triangle on the three vertices of
    // another, with the opposite winding (a doubled sheet); the second
    // removes both. meshoptimizer's simplify also takes a tetrahedron to
    // no triangle at a target of 0.
    let mesh = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        properties: Default::default(),
    };
    let s = simplify(&mesh, &SimplifyOptions::default());
    let c = &s.collapses;
    check_every_lod(&mesh, c);
    assert_eq!(c.max_lod(), 2);
    let folded = c.triangles_at(&mesh, 1);
    assert_eq!(folded.len(), 2, "{folded:?}");
    let corners = |t: [u32; 3]| {
        let mut c = t;
        c.sort_unstable();
        c
    };
    assert_eq!(corners(folded[0]), corners(folded[1]));
    let rotations = |t: [u32; 3]| [t, [t[1], t[2], t[0]], [t[2], t[0], t[1]]];
    let reversed = [folded[1][0], folded[1][2], folded[1][1]];
    assert!(
        rotations(folded[0]).contains(&reversed),
        "{folded:?}: same winding"
    );
    assert!(c.triangles_at(&mesh, 2).is_empty());
    assert!(c.error(2) >= c.error(1) && c.error(1) > 0.0);
    assert_eq!(s.stop.reason, StopReason::NoTriangleLeft);
    assert_eq!((s.stop.triangles, s.stop.vertices), (0, 0));
    assert_eq!(s.stop.to_string(), "no triangle left at LoD 2");
    // Asked to stop at no triangle, it reached its target.
    let options = SimplifyOptions {
        stop_at_triangles: Some(0),
        ..SimplifyOptions::default()
    };
    let to_zero = simplify(&mesh, &options);
    assert_eq!(to_zero.stop.reason, StopReason::TargetReached);
    assert_eq!(to_zero.collapses.steps(), c.steps());
}

#[test]
fn a_hole_of_three_edges_closes() {
    // An octahedron without its face (+X, +Y, +Z): the hole's border is
    // the three edges between those vertices. Contracting one of them
    // merges the two others into one edge of two triangles and closes the
    // hole. The link condition refuses it (+Z is a common neighbour of +X
    // and +Y without a triangle on them), and contractions it allows keep
    // the topology, so every LoD would keep a border; merging two border
    // edges makes no fin and is allowed.
    let mesh = Mesh {
        positions: vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z],
        triangles: vec![
            [0, 5, 2],
            [0, 3, 5],
            [0, 4, 3],
            [1, 2, 5],
            [1, 5, 3],
            [1, 3, 4],
            [1, 4, 2],
        ],
        properties: Default::default(),
    };
    let s = simplify(&mesh, &SimplifyOptions::default());
    let c = &s.collapses;
    check_every_lod(&mesh, c);
    assert!(c.max_lod() >= 1, "{}", s.stop);
    // The first contraction is along a hole edge, and closes it.
    let first = c.steps()[0];
    let hole = [0, 2, 4];
    assert!(
        hole.contains(&first.removed) && hole.contains(&first.kept),
        "{first:?}"
    );
    let closed = c.triangles_at(&mesh, 1);
    assert_eq!(closed.len(), 6);
    let mut edges = std::collections::HashMap::new();
    for t in &closed {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(edges.values().all(|&n| n == 2), "{closed:?}");
}

#[test]
fn spike_goes_after_every_free_contraction() {
    // A flat 4x4 grid whose centre vertex (12) is raised: the vertices far
    // from it are free to go (error 0), the spike is expensive, so it is
    // removed only after every free contraction, and its removal raises
    // the error.
    let mut mesh = flat_grid(4);
    mesh.positions[12].z = 2.0;
    let s = simplify(&mesh, &SimplifyOptions::default());
    let c = &s.collapses;
    check_every_lod(&mesh, c);
    let free = c.steps().iter().take_while(|st| st.error == 0.0).count();
    assert!(free >= 4, "{free} free contractions");
    let spike = c
        .steps()
        .iter()
        .position(|st| st.removed == 12)
        .unwrap_or(c.max_lod());
    assert!(
        spike >= free,
        "spike removed at step {spike}, before free step {free}"
    );
    if spike < c.max_lod() {
        assert!(c.error(spike + 1) > c.error(spike));
    }
}

#[test]
fn stop_at_target_is_a_prefix_of_the_whole_sequence() {
    let mesh = mts::mesh::generate::icosphere(8, 0.1, 3);
    let whole = simplify(&mesh, &SimplifyOptions::default());
    let options = SimplifyOptions {
        stop_at_triangles: Some(100),
        ..SimplifyOptions::default()
    };
    let part = simplify(&mesh, &options);
    assert_eq!(part.stop.reason, StopReason::TargetReached);
    assert!(part.stop.triangles <= 100);
    let k = part.collapses.max_lod();
    assert_eq!(part.collapses.steps(), &whole.collapses.steps()[..k]);
    assert_eq!(whole.collapses.lod_for_triangles(part.stop.triangles), k);
    // Closed genus-0 surface: it folds flat into a doubled triangle and
    // then vanishes.
    let last = whole.collapses.max_lod();
    assert_eq!(
        whole.stop.reason,
        StopReason::NoTriangleLeft,
        "{}",
        whole.stop
    );
    assert_eq!(whole.collapses.triangle_count(last), 0);
    assert_eq!(whole.collapses.triangle_count(last - 1), 2);
}

#[test]
fn lod_lookup_by_budget_and_ratio() {
    let mesh = flat_grid(6);
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    assert_eq!(c.lod_for_triangles(72), 0);
    assert_eq!(c.lod_for_triangles(usize::MAX), 0);
    for budget in 0..72 {
        let k = c.lod_for_triangles(budget);
        if c.triangle_count(c.max_lod()) <= budget {
            assert!(c.triangle_count(k) <= budget);
            assert!(k == 0 || c.triangle_count(k - 1) > budget);
        } else {
            assert_eq!(k, c.max_lod());
        }
    }
    assert_eq!(c.lod_for_ratio(1.0), 0);
    assert_eq!(c.lod_for_ratio(0.5), c.lod_for_triangles(36));
    assert_eq!(c.lod_for_ratio(7.0), 0);
}

#[test]
fn optimal_placement_appends_vertices_and_keeps_the_invariants() {
    let mesh = mts::mesh::generate::icosphere(6, 0.2, 9);
    let options = SimplifyOptions {
        placement: Placement::Optimal,
        ..SimplifyOptions::default()
    };
    let c = simplify(&mesh, &options).collapses;
    assert!(c.is_optimal_placement());
    assert_eq!(c.appended().len(), c.max_lod());
    check_every_lod(&mesh, &c);
    let m = c.mesh_at(&mesh, c.lod_for_ratio(0.25));
    m.validate().unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn every_lod_of_random_surfaces_is_valid(m in random_surface()) {
        let s = simplify(&m, &SimplifyOptions::default());
        check_every_lod(&m, &s.collapses);
        prop_assert_eq!(s.stop.lod, s.collapses.max_lod());
        prop_assert_eq!(s.stop.triangles, s.collapses.triangle_count(s.stop.lod));
    }

    #[test]
    fn the_surface_stays_within_the_recorded_error_of_each_removed_vertex(m in random_surface()) {
        // After step k, the removed vertex's input position lies within the
        // recorded error of the triangles around the vertex it went to.
        let c = simplify(&m, &SimplifyOptions::default()).collapses;
        let diagonal = f64::from(m.diagonal());
        for (k, step) in c.steps().iter().enumerate() {
            let p = m.positions[step.removed as usize];
            let nearest = c
                .triangles_at(&m, k + 1)
                .iter()
                .filter(|t| t.contains(&step.kept))
                .map(|t| {
                    let [a, b, d] = t.map(|v| m.positions[v as usize]);
                    f64::from(mts::distance::bvh::closest_on_triangle(p, a, b, d).distance(p))
                })
                .fold(f64::INFINITY, f64::min);
            if nearest.is_finite() {
                prop_assert!(
                    nearest / diagonal <= f64::from(c.error(k + 1)) * 1.001 + 1e-6,
                    "step {}: {:?} is {} off, recorded error {}",
                    k, step, nearest / diagonal, c.error(k + 1)
                );
            }
        }
    }

    #[test]
    fn every_input_vertex_a_removed_vertex_stands_for_stays_within_the_recorded_error(
        m in random_surface()
    ) {
        // The same for the input vertices contracted into the removed one
        // before: all of them lie within the recorded error of the kept
        // vertex's triangles after the step.
        let c = simplify(&m, &SimplifyOptions::default()).collapses;
        let diagonal = f64::from(m.diagonal());
        for (k, step) in c.steps().iter().enumerate() {
            let before = c.representatives(k);
            let around: Vec<[u32; 3]> = c
                .triangles_at(&m, k + 1)
                .into_iter()
                .filter(|t| t.contains(&step.kept))
                .collect();
            if around.is_empty() {
                continue;
            }
            for v in (0..m.vertex_count() as u32).filter(|&v| before[v as usize] == step.removed) {
                let p = m.positions[v as usize];
                let nearest = around
                    .iter()
                    .map(|t| {
                        let [a, b, d] = t.map(|w| m.positions[w as usize]);
                        f64::from(mts::distance::bvh::closest_on_triangle(p, a, b, d).distance(p))
                    })
                    .fold(f64::INFINITY, f64::min);
                prop_assert!(
                    nearest / diagonal <= f64::from(c.error(k + 1)) * 1.001 + 1e-6,
                    "step {}: input vertex {} of {:?} is {} off, recorded error {}",
                    k, v, step, nearest / diagonal, c.error(k + 1)
                );
            }
        }
    }

    #[test]
    fn virtual_pairs_keep_the_invariants(m in random_surface()) {
        let options = SimplifyOptions { pair_distance: Some(0.3), ..SimplifyOptions::default() };
        let s = simplify(&m, &options);
        check_every_lod(&m, &s.collapses);
    }
}

#[test]
fn bunny_error_against_meshoptimizer() {
    let Some(mesh) = model("bunny.ply") else {
        return;
    };
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    c.validate().unwrap();
    for ratio in [0.1, 0.01] {
        let (a, b, _) = against_meshoptimizer(&mesh, &c, ratio);
        assert!(c.triangle_count(c.lod_for_ratio(ratio)) <= (ratio * 69451.0).round() as usize);
        assert!(
            a.hausdorff <= 1.15 * b.hausdorff,
            "ratio {ratio}: Hausdorff {} against meshopt {}",
            a.hausdorff,
            b.hausdorff
        );
        assert!(
            a.rms <= 1.15 * b.rms,
            "ratio {ratio}: RMS {} against {}",
            a.rms,
            b.rms
        );
    }
}

#[test]
fn non_manifold_models_against_meshoptimizer() {
    // The two rows of the quality table that failed last: their ends are
    // decided by fins (beetle's edges of three triangles) and coincident
    // triangle pairs (bunny_res4's edges of four). Compared as the bench
    // report compares them: our LoD at the share, meshoptimizer asked for
    // its triangle count (and our LoD at meshoptimizer's count where it
    // stops above it).
    for name in ["beetle.obj", "bunny_res4.ply"] {
        let Some(mesh) = model(name) else {
            return;
        };
        let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
        for ratio in [0.1, 0.01] {
            let (a, b, triangles) = against_meshoptimizer(&mesh, &c, ratio);
            assert!(
                a.hausdorff <= 1.15 * b.hausdorff,
                "{name} at {ratio}: Hausdorff {} ({triangles} triangles) against meshopt {}",
                a.hausdorff,
                b.hausdorff
            );
        }
    }
}

/// Our LoD at `ratio` and meshoptimizer's `simplify` at its triangle count,
/// measured against `mesh` (50,000 samples a side), as the bench report
/// compares them (`peers::quality::compare`: where meshoptimizer stops
/// above our count, our LoD at its count); and our triangle count.
fn against_meshoptimizer(
    mesh: &Mesh,
    c: &Collapses,
    ratio: f64,
) -> (SurfaceDistance, SurfaceDistance, usize) {
    let q = peers::quality::compare(mesh, c, c.lod_for_ratio(ratio), 50_000, |lod| Mesh {
        positions: mesh.positions.clone(),
        triangles: c.triangles_at(mesh, lod),
        properties: Default::default(),
    });
    (q.ours.distance, q.meshopt.distance, q.ours.triangle_count)
}

/// The comparison is meshoptimizer's `simplify_to_lod` and the two
/// distances a caller would measure by hand, at the LoD it reports (on
/// this torus, meshoptimizer reaches the count asked for: the LoD stays).
#[test]
fn quality_comparison_is_both_measurements_at_one_lod() {
    let mesh: Mesh = "torus:5k"
        .parse::<mts::mesh::generate::Generated>()
        .unwrap()
        .build();
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    let asked = c.lod_for_ratio(0.1);
    let q = peers::quality::compare(&mesh, &c, asked, 5_000, |lod| c.mesh_at(&mesh, lod));
    let (theirs, lod) = peers::meshopt::simplify_to_lod(&mesh, &c, asked);
    let ours = c.mesh_at(&mesh, lod);
    assert_eq!((asked, q.lod, lod), (2205, 2205, 2205));
    assert_eq!(
        (q.ours.triangle_count, q.meshopt.triangle_count),
        (490, 490)
    );
    assert_eq!(theirs.len(), 490);
    assert_eq!(
        q.ours.distance,
        surface_distance((&mesh).into(), (&ours).into(), 5_000)
    );
    assert_eq!(
        q.meshopt.distance,
        surface_distance((&mesh).into(), Surface::over(&mesh, &theirs), 5_000)
    );
    assert!(q.meshopt_ms > 0.0);
}

#[test]
fn open_models_keep_their_borders() {
    // Border vertices only move along border edges, so at 10% every border
    // vertex of the LoD is an input border vertex and stays put.
    let Some(mesh) = model("bunny.ply") else {
        return;
    };
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    let border = |tris: &[[u32; 3]]| {
        let mut v: Vec<u32> = edge_counts(tris)
            .into_iter()
            .filter(|&(_, c)| c == 1)
            .flat_map(|((a, b), _)| [a, b])
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let input = border(&mesh.triangles);
    let at = border(&c.triangles_at(&mesh, c.lod_for_ratio(0.1)));
    assert!(!at.is_empty());
    assert!(at.iter().all(|v| input.binary_search(v).is_ok()));
}

#[test]
fn beetle_keeps_every_invariant_with_its_fin_edges() {
    // beetle.obj has 47 edges of three triangles. Their vertices may leave
    // them (see `Edges::slides` in contract.rs); no LoD may gain an edge
    // of more than three triangles for it.
    let Some(mesh) = model("beetle.obj") else {
        return;
    };
    assert_eq!(most_crowded_edge(&mesh.triangles), 3);
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    assert!(c.max_lod() > 1000, "{}", c.max_lod());
    check_every_lod(&mesh, &c);
    // The fins fold onto their sheets on the way down (a doubled triangle
    // is allowed): at 81 triangles, where refusing it left 31 edges of
    // three, no more remain than meshoptimizer keeps (3).
    let fins = |tris: &[[u32; 3]]| edge_counts(tris).values().filter(|&&n| n == 3).count();
    let at = c.triangles_at(&mesh, c.lod_for_triangles(81));
    assert!(
        fins(&at) <= 3,
        "{} edges of three at {} triangles",
        fins(&at),
        at.len()
    );
}
