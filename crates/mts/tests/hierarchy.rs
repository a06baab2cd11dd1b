//! Locked vertices in the contraction sequence, and the view-dependent
//! hierarchy built on them: its structure, each group's strips against its
//! replay, and cuts over sweeps of cameras drawn without a crack.

use glam::Vec3;
use mts::hierarchy::{self, Cut, Hierarchy, HierarchyOptions};
use mts::mesh::generate::Generated;
use mts::mesh::Mesh;
use mts::simplify::{simplify_locked, Placement, SimplifyOptions};
use mts::strip::sorted_canonical;
use mts::{simplify, Collapses, Extractor, Projection};
use std::collections::HashMap;

mod common;

/// FNV-1a over every step's error and moves, the LoD table and the
/// created positions: the sequence, bit for bit.
fn checksum(c: &Collapses) -> u64 {
    let mut b = Vec::new();
    for i in 0..c.max_lod() {
        b.extend(c.steps()[i].error.to_bits().to_le_bytes());
        for (from, to) in c.moves(i) {
            b.extend(from.to_le_bytes());
            b.extend(to.to_le_bytes());
        }
    }
    for t in c.triangle_counts() {
        b.extend(t.to_le_bytes());
    }
    for p in c.appended() {
        for x in p.to_array() {
            b.extend(x.to_bits().to_le_bytes());
        }
    }
    mts::checksum::fnv1a64(&b)
}

/// Sequences recorded before locks existed (commit 181d041): with no lock,
/// or a lock of no vertex, the sequence is the same bit for bit.
#[test]
fn unlocked_sequences_are_unchanged() {
    let pins = [
        (
            "grid:2k",
            false,
            Placement::Endpoint,
            1087,
            0x04300a9a6727a6e4u64,
        ),
        (
            "icosphere:5k",
            false,
            Placement::Endpoint,
            2560,
            0xcbeff85a02e0f16d,
        ),
        (
            "torus:2k",
            true,
            Placement::Endpoint,
            955,
            0x9b65e2d0aff96488,
        ),
        (
            "icosphere:5k",
            false,
            Placement::Optimal,
            2560,
            0x709f07cbd03d4983,
        ),
    ];
    for (name, properties, placement, lods, sum) in pins {
        let g: Generated = name.parse().unwrap();
        let mesh = if properties {
            g.build_with_properties()
        } else {
            g.build()
        };
        let options = SimplifyOptions {
            placement,
            ..SimplifyOptions::default()
        };
        let s = simplify(&mesh, &options);
        assert_eq!(
            (s.collapses.max_lod(), checksum(&s.collapses)),
            (lods, sum),
            "{name}"
        );
        assert_eq!(simplify_locked(&mesh, &options, &[]), s, "{name}");
        let none = vec![false; mesh.vertex_count()];
        assert_eq!(simplify_locked(&mesh, &options, &none), s, "{name}");
    }
}

/// An `n × n` grid of unit squares whose heights are a few waves, so that
/// simplification errors are not zero.
fn hilly_grid(n: u32) -> Mesh {
    let mut mesh = mts::mesh::generate::grid(n, n);
    for p in &mut mesh.positions {
        p.z = 1.5 * (p.x * 0.31).sin() * (p.y * 0.23).cos() + 0.6 * (p.x * 0.07 + p.y * 0.11).sin();
    }
    mesh
}

/// Directed edges drawn more often than their reverse, each as many times
/// more, sorted.
fn open_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edges.entry((a, b)).or_default() += 1;
            *edges.entry((b, a)).or_default() -= 1;
        }
    }
    let mut open: Vec<(u32, u32)> = edges
        .into_iter()
        .filter(|&(_, net)| net > 0)
        .flat_map(|(e, net)| std::iter::repeat_n(e, net as usize))
        .collect();
    open.sort_unstable();
    open
}

#[test]
fn a_locked_border_keeps_its_vertices_and_edges_at_every_lod() {
    let n = 16;
    let mesh = hilly_grid(n);
    let on_border = |v: u32| {
        let (x, y) = (v % (n + 1), v / (n + 1));
        x == 0 || y == 0 || x == n || y == n
    };
    let locked: Vec<bool> = (0..mesh.vertex_count() as u32).map(on_border).collect();
    let s = simplify_locked(&mesh, &SimplifyOptions::default(), &locked);
    let c = &s.collapses;
    c.validate().unwrap();
    // The interior simplifies all the same.
    assert!(c.triangle_count(c.max_lod()) * 4 < mesh.triangle_count());
    let border = open_edges(&mesh.triangles);
    assert_eq!(border.len(), 4 * n as usize);
    for lod in 0..=c.max_lod() {
        for v in (0..mesh.vertex_count() as u32).filter(|&v| on_border(v)) {
            assert_eq!(
                c.representative(v, lod),
                v,
                "border vertex {v} gone at LoD {lod}"
            );
        }
        assert_eq!(open_edges(&c.triangles_at(&mesh, lod)), border, "LoD {lod}");
    }
    for i in 0..c.max_lod() {
        assert!(c.moves(i).all(|(from, _)| !on_border(from)), "step {i}");
    }
}

/// Every vertex locked but the interior ones of odd coordinates, which are
/// pairwise apart: every contraction is onto a locked vertex, so the
/// created vertex must sit exactly on it.
#[test]
fn optimal_placement_keeps_locked_vertices_where_they_are() {
    let n = 16;
    let mesh = hilly_grid(n);
    let free = |v: u32| {
        let (x, y) = (v % (n + 1), v / (n + 1));
        x % 2 == 1 && y % 2 == 1 && x < n && y < n
    };
    let locked: Vec<bool> = (0..mesh.vertex_count() as u32).map(|v| !free(v)).collect();
    let options = SimplifyOptions {
        placement: Placement::Optimal,
        ..SimplifyOptions::default()
    };
    let c = simplify_locked(&mesh, &options, &locked).collapses;
    c.validate().unwrap();
    assert!(c.max_lod() >= 32, "{} steps", c.max_lod());
    let position = |v: u32| match mesh.positions.get(v as usize) {
        Some(&p) => p,
        None => c.appended()[v as usize - mesh.vertex_count()],
    };
    let mut moved = 0;
    for lod in 0..=c.max_lod() {
        for v in (0..mesh.vertex_count() as u32).filter(|&v| locked[v as usize]) {
            let r = c.representative(v, lod);
            moved += usize::from(r != v);
            assert_eq!(
                position(r),
                mesh.positions[v as usize],
                "vertex {v} at LoD {lod}"
            );
        }
    }
    // Locked vertices were contracted onto (and replaced by created ones
    // at their very positions), not refused.
    assert!(moved > 0);
}

#[test]
fn seams_lock_by_point() {
    let mesh = "torus:2k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    let locked: Vec<bool> = mesh.positions.iter().map(|p| p.x > 0.3).collect();
    let c = simplify_locked(&mesh, &SimplifyOptions::default(), &locked).collapses;
    c.validate().unwrap();
    assert!(c.has_companions());
    assert!(c.triangle_count(c.max_lod()) * 2 < mesh.triangle_count());
    for i in 0..c.max_lod() {
        assert!(
            c.moves(i).all(|(from, _)| !locked[from as usize]),
            "step {i}"
        );
    }
}

/// Checks the drawn triangles against the input by points (a seam's
/// vertices are one point) and returns how many directed edges are drawn
/// more than once (folds: a group simplified to a doubled sheet; refused
/// unless `folds_allowed`). A crack, a T-junction or a torn seam leaves a
/// drawn edge whose reverse is drawn fewer times than it is: every such
/// edge must join two points of the input's own boundary (which groups may
/// simplify), and the boundary's loops stay closed (each point has as many
/// such edges in as out). On a closed input without folds every drawn
/// edge is then drawn exactly once in each direction: two triangles.
fn check_watertight(input: &Mesh, drawn: &[[u32; 3]], folds_allowed: bool, context: &str) -> usize {
    let point = |v: u32| input.properties.position_id(v);
    let by_points =
        |tris: &[[u32; 3]]| -> Vec<[u32; 3]> { tris.iter().map(|t| t.map(point)).collect() };
    let mut on_boundary = std::collections::HashSet::new();
    for (a, b) in open_edges(&by_points(&input.triangles)) {
        on_boundary.insert(a);
        on_boundary.insert(b);
    }
    let drawn = by_points(drawn);
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &drawn {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[2] != t[0],
            "{context}: degenerate {t:?}"
        );
        for i in 0..3 {
            *count.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    let folds = count.values().filter(|&&k| k > 1).count();
    assert!(
        folds_allowed || folds == 0,
        "{context}: {folds} edges drawn twice in one direction"
    );
    let mut balance: HashMap<u32, i32> = HashMap::new();
    for (a, b) in open_edges(&drawn) {
        assert!(
            on_boundary.contains(&a) && on_boundary.contains(&b),
            "{context}: open edge {a}->{b} inside the input (a crack)"
        );
        *balance.entry(a).or_default() += 1;
        *balance.entry(b).or_default() -= 1;
    }
    assert!(
        balance.values().all(|&d| d == 0),
        "{context}: an open boundary loop"
    );
    folds
}

fn camera() -> Projection {
    Projection::Perspective {
        fov_y: 60f32.to_radians(),
        viewport_height: 1080.0,
    }
}

/// What a sweep exercised: cuts, groups drawn strictly inside their LoD
/// range, clusters drawn as they are, and the levels groups were drawn at.
#[derive(Default, Debug)]
struct Seen {
    cuts: usize,
    between: usize,
    clusters: usize,
    levels: std::collections::BTreeSet<u32>,
    folds: usize,
}

/// Every cut of `h` over `eyes` × `thresholds` is watertight where `mesh`
/// is, and each group on it draws, through an extractor, exactly its
/// replay at its LoD.
fn sweep(
    mesh: &Mesh,
    h: &Hierarchy,
    eyes: &[Vec3],
    thresholds: &[f32],
    folds_allowed: bool,
) -> Seen {
    let mut seen = Seen::default();
    for &eye in eyes {
        for &t in thresholds {
            let cut: Cut = hierarchy::select(h, &camera(), eye, t);
            let context = format!("eye {eye}, {t} px");
            let drawn = cut.triangles(h);
            assert_eq!(drawn.len(), cut.triangle_count(h), "{context}");
            seen.folds += check_watertight(mesh, &drawn, folds_allowed, &context);
            for &(g, lod) in &cut.groups {
                let group = &h.groups()[g as usize];
                let mut ex = Extractor::new(&group.model);
                ex.set_lod(lod as usize);
                let replay = group
                    .model
                    .collapses()
                    .triangles_at(&group.model.mesh(), lod as usize);
                assert_eq!(
                    sorted_canonical(&ex.triangles()),
                    sorted_canonical(&replay),
                    "{context}: group {g}"
                );
                seen.between += usize::from(lod > 0 && (lod as usize) < group.model.max_lod());
                seen.levels.insert(group.level);
            }
            seen.clusters += cut.clusters.len();
            seen.cuts += 1;
        }
    }
    seen
}

/// Structure every hierarchy has, and every group's strips against its
/// replay at every LoD.
fn check_structure(mesh: &Mesh, h: &Hierarchy) {
    h.validate().unwrap();
    assert_eq!(h.triangle_count(), mesh.triangle_count());
    for (i, g) in h.groups().iter().enumerate() {
        let lods: Vec<usize> = (0..=g.model.max_lod()).collect();
        let report = mts::model::verify(&g.model, &g.model.mesh(), &lods);
        assert_eq!(
            report.mismatches, 0,
            "group {i}: {:?}",
            report.first_mismatch
        );
        for k in 1..=g.model.max_lod() {
            assert!(g.error(k) >= g.error(k - 1));
        }
    }
    // Full detail draws the input exactly.
    let cut = hierarchy::select(h, &camera(), Vec3::ZERO, 0.0);
    assert!(
        cut.clusters.is_empty()
            && cut
                .groups
                .iter()
                .all(|&(g, lod)| lod == 0 && h.groups()[g as usize].level == 0)
    );
    assert_eq!(
        sorted_canonical(&cut.triangles(h)),
        sorted_canonical(&mesh.triangles)
    );
}

#[test]
fn a_hilly_grid_is_drawn_without_cracks_from_everywhere() {
    let mesh = hilly_grid(48);
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    check_structure(&mesh, &h);
    assert!(h.level_count() >= 3, "{} levels", h.level_count());
    let mut eyes = Vec::new();
    for i in 0..=8 {
        let s = i as f32 / 8.0;
        eyes.push(Vec3::new(-2.0 + 52.0 * s, -2.0 + 20.0 * s, 3.0 + 10.0 * s));
    }
    eyes.push(Vec3::new(24.0, 24.0, 400.0));
    let seen = sweep(&mesh, &h, &eyes, &[0.25, 1.0, 4.0, 16.0], false);
    assert!(
        seen.between > 0 && seen.clusters > 0 && seen.levels.len() >= 3,
        "{seen:?}"
    );
}

#[test]
fn a_closed_sphere_is_drawn_without_cracks_from_everywhere() {
    let mesh = "icosphere:5k".parse::<Generated>().unwrap().build();
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    check_structure(&mesh, &h);
    let eyes: Vec<Vec3> = (0..8)
        .map(|i| {
            let a = i as f32 * 0.8;
            (1.05 + 0.5 * i as f32) * Vec3::new(a.cos(), a.sin(), 0.3).normalize()
        })
        .collect();
    let seen = sweep(&mesh, &h, &eyes, &[0.25, 1.0, 4.0], false);
    assert!(seen.between > 0 && seen.levels.len() >= 2, "{seen:?}");
}

#[test]
fn seams_never_open_in_a_cut() {
    let mesh = "torus:4k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    check_structure(&mesh, &h);
    let eyes: Vec<Vec3> = (0..6)
        .map(|i| Vec3::new(1.6 + 0.8 * i as f32, 0.2 * i as f32, 0.5))
        .collect();
    // Folds are allowed here: at 8 px a level-2 group whose locked border
    // runs along the seam ring simplifies into slivers on that ring, the
    // neighbour's slivers over them (the sequence's doubled sheets, with
    // the border kept: no crack). Counted, to see it go when fixed.
    let seen = sweep(&mesh, &h, &eyes, &[0.5, 2.0, 8.0], true);
    assert!(seen.between > 0, "{seen:?}");
    assert!(seen.folds <= 2, "{seen:?}");
}

#[test]
fn optimal_placement_is_refused() {
    let mesh = hilly_grid(8);
    let mut options = HierarchyOptions::default();
    options.pipeline.simplify.placement = Placement::Optimal;
    assert!(matches!(
        hierarchy::build(&mesh, &options),
        Err(mts::Error::InvalidArgument(_))
    ));
}

/// The figures of `docs/experiments/hierarchy.md`: a hilly grid of about
/// `MTS_HIERARCHY_TRIANGLES` triangles (1M by default), seen from near one
/// corner, the hierarchy against the per-object model at the same
/// threshold. Run with `cargo test --release -p mts --test hierarchy --
/// --ignored --nocapture`.
#[test]
#[ignore = "a figure: minutes in release"]
fn figures_near_a_corner_of_a_hilly_grid() {
    use std::time::Instant;
    let triangles: f64 = std::env::var("MTS_HIERARCHY_TRIANGLES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1e6);
    let n = (triangles / 2.0).sqrt().round() as u32;
    let mesh = hilly_grid(n);
    let raw = 12 * mesh.vertex_count() + 12 * mesh.triangle_count();
    let t = Instant::now();
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    let build_s = t.elapsed().as_secs_f64();
    let levels: Vec<usize> = (0..h.level_count() as u32)
        .map(|l| h.groups().iter().filter(|g| g.level == l).count())
        .collect();
    println!(
        "grid {n}x{n}: {} triangles, hierarchy built in {build_s:.1} s: {} groups over {} levels {levels:?}, {} clusters, memory {:.2} x raw",
        mesh.triangle_count(),
        h.groups().len(),
        h.level_count(),
        h.clusters().len(),
        h.memory_bytes() as f64 / raw as f64
    );
    let t = Instant::now();
    let (model, _, _) = mts::model::build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
    let model_s = t.elapsed().as_secs_f64();
    println!(
        "per-object model built in {model_s:.1} s, memory {:.2} x raw",
        model.stats().memory_bytes as f64 / raw as f64
    );
    let (lo, hi) = mts::mesh::bounds_of(&mesh.positions).unwrap();
    let (centre, radius) = (0.5 * (lo + hi), 0.5 * lo.distance(hi));
    for eye in [Vec3::new(-5.0, -5.0, 15.0), Vec3::new(-50.0, -50.0, 60.0)] {
        for px in [0.5f32, 1.0, 2.0] {
            let t = Instant::now();
            let cut = hierarchy::select(&h, &camera(), eye, px);
            let select_ms = t.elapsed().as_secs_f64() * 1e3;
            let drawn = cut.triangle_count(&h);
            let static_triangles: usize = cut
                .clusters
                .iter()
                .map(|&c| h.cluster_triangles(c as usize).len())
                .sum();
            let ppu =
                camera().pixels_per_unit(mts::screen_error::nearest_distance(eye, centre, radius));
            let lod = mts::lod_for_screen_error(model.collapses(), mesh.diagonal(), 1.0, ppu, px);
            println!(
                "eye {eye} at {px} px: hierarchy {drawn} triangles ({} groups, {} clusters holding {static_triangles}; select {select_ms:.2} ms), per-object {} ({:.3} x)",
                cut.groups.len(),
                cut.clusters.len(),
                model.triangle_count(lod),
                drawn as f64 / model.triangle_count(lod) as f64
            );
        }
    }
}

/// The sum of the directed edges of `triangles` (each edge counted along
/// minus against), zero entries left out.
fn net_edges(triangles: impl IntoIterator<Item = [u32; 3]>) -> HashMap<(u32, u32), i32> {
    let mut net: HashMap<(u32, u32), i32> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *net.entry((a, b)).or_default() += 1;
            *net.entry((b, a)).or_default() -= 1;
        }
    }
    net.retain(|_, n| *n != 0);
    net
}

/// The statement behind [`check_watertight`], group by group and for every
/// LoD whether a camera draws it or not: by points, a group's triangles at
/// any LoD have the directed-edge sum of its input but on edges between two
/// points of the input's boundary (the only ones it may simplify; its outer
/// border is locked).
fn check_groups_keep_boundary(input: &Mesh, h: &Hierarchy) {
    let point = |v: u32| input.properties.position_id(v);
    let by_points = |tris: Vec<[u32; 3]>| net_edges(tris.into_iter().map(|t| t.map(point)));
    let boundary: std::collections::HashSet<u32> = by_points(input.triangles.clone())
        .into_keys()
        .flat_map(|(a, b)| [a, b])
        .collect();
    for (i, g) in h.groups().iter().enumerate() {
        let first = by_points(g.triangles_at(0));
        for lod in 1..=g.model.max_lod() {
            let now = by_points(g.triangles_at(lod));
            for (&(a, b), &n) in now.iter().chain(&first) {
                let kept = now.get(&(a, b)) == first.get(&(a, b));
                assert!(
                    kept || (boundary.contains(&a) && boundary.contains(&b)),
                    "group {i} (level {}) at LoD {lod}: edge {a}->{b} counts {n}, {:?} at LoD 0",
                    g.level,
                    first.get(&(a, b))
                );
            }
        }
    }
}

/// The smallest crack `random_surfaces_are_cut_without_cracks` led to: one
/// flipped triangle in a hilly 4 × 4 grid, clusters of 4 triangles. Each
/// corner of the flipped triangle has two edges held twice in the same
/// direction (boundary edges, as the directed-edge sum counts them, that
/// the simplifier took for interior ones), and level 0 contracted corner 11
/// onto 7, a point of the group's locked border inside the input: two
/// edges from 7 then had no reverse, open from (20, -4, 8) at 64 px. Such
/// points are locked now (`hierarchy/build.rs`, `loose_border_points`).
#[test]
fn a_flipped_triangle_is_cut_without_cracks() {
    let mut mesh = hilly_grid(4);
    let flipped = mesh
        .triangles
        .iter()
        .position(|&t| t == [11, 12, 17])
        .expect("the grid's triangle (11, 12, 17)");
    mesh.triangles[flipped] = [11, 17, 12];
    mesh.validate().unwrap();
    let options = HierarchyOptions {
        cluster_triangles: 4,
        ..HierarchyOptions::default()
    };
    let h = hierarchy::build(&mesh, &options).unwrap();
    check_structure(&mesh, &h);
    assert!(h.level_count() >= 2, "{} levels", h.level_count());
    check_groups_keep_boundary(&mesh, &h);
    let eyes = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(5.0, 5.0, 3.0),
        Vec3::new(20.0, -4.0, 8.0),
        Vec3::new(2.0, 2.0, 40.0),
    ];
    let seen = sweep(&mesh, &h, &eyes, &[0.5, 4.0, 64.0, 1e6], true);
    assert!(seen.levels.len() >= 2, "{seen:?}");
}

proptest::proptest! {
    // 64 cases, or `PROPTEST_CASES` (which `with_cases` would override).
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(64),
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// On random open surfaces (holes, flipped and doubled triangles, a
    /// second part), with small clusters so that there are several levels:
    /// every group keeps the input's boundary at every LoD and every cut
    /// keeps it outside its own border (folds allowed: the input has
    /// doubled triangles). The boundary points whose fan is not a half-disc
    /// are locked for it (`loose_border_points` in `hierarchy/build.rs`);
    /// the shrunk cases of `hierarchy.proptest-regressions` cracked before.
    #[test]
    fn random_surfaces_are_cut_without_cracks(mesh in common::random_surface()) {
        let options = HierarchyOptions { cluster_triangles: 8, ..HierarchyOptions::default() };
        let h = hierarchy::build(&mesh, &options).unwrap();
        h.validate().unwrap();
        check_groups_keep_boundary(&mesh, &h);
        let eyes = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(5.0, 5.0, 3.0), Vec3::new(20.0, -4.0, 8.0)];
        for eye in eyes {
            for px in [0.5f32, 4.0, 64.0] {
                let cut = hierarchy::select(&h, &camera(), eye, px);
                check_watertight(&mesh, &cut.triangles(&h), true, &format!("eye {eye}, {px} px"));
            }
        }
    }
}

/// `build_with_progress` reports every group once, from any thread: the
/// triangles reported add up to every group's input over all levels, which
/// is the input's at level 0 and about half as much again per level, and
/// the hierarchy is the one `build` makes.
#[test]
fn build_reports_its_progress_group_by_group() {
    let mesh = "terrain:20k".parse::<Generated>().unwrap().build();
    let options = HierarchyOptions::default();
    let calls = std::sync::Mutex::new(Vec::new());
    let h = hierarchy::build_with_progress(&mesh, &options, &|p| {
        calls.lock().unwrap().push(p);
    })
    .unwrap();
    let calls = calls.into_inner().unwrap();
    assert_eq!(calls.len(), h.groups().len());
    let expected = 2 * mesh.triangle_count();
    assert!(calls.iter().all(|p| p.triangles_expected == expected));
    let last = calls.iter().map(|p| p.triangles_done).max().unwrap();
    let inputs: usize = h
        .groups()
        .iter()
        .flat_map(|g| &g.inputs)
        .map(|&c| h.cluster_triangle_count(c as usize))
        .sum();
    assert_eq!(last, inputs);
    assert!(
        last > mesh.triangle_count() && last < expected + expected / 10,
        "{last}"
    );
    let levels = calls.iter().map(|p| p.level).max().unwrap() as usize;
    assert_eq!(levels + 1, h.level_count());
    let plain = hierarchy::build(&mesh, &options).unwrap();
    assert_eq!(plain.to_bytes(), h.to_bytes());
}

/// `verify_groups`: one report per group, in group order, each at the LoDs
/// asked for its model, none with a mismatch.
#[test]
fn every_group_verifies_on_every_core() {
    let mesh = "terrain:20k".parse::<Generated>().unwrap().build();
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    let reports = h.verify_groups(|max_lod| vec![0, max_lod / 2, max_lod]);
    assert_eq!(reports.len(), h.groups().len());
    for (g, r) in h.groups().iter().zip(&reports) {
        assert_eq!(r.mismatches, 0, "{:?}", r.first_mismatch);
        assert_eq!(r.lods_checked, 3, "max LoD {}", g.model.max_lod());
    }
}
