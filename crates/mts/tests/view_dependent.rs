//! `hierarchy::ViewDependent`: the arena a renderer draws follows the cut
//! camera after camera, walking only what changed.

use glam::Vec3;
use mts::hierarchy::{self, Frustum, HierarchyOptions, View, ViewDependent};
use mts::mesh::Mesh;
use mts::screen_error::Projection;
use mts::strip::sorted_canonical;

fn hilly_grid(n: u32) -> Mesh {
    let mut mesh = mts::mesh::generate::grid(n, n);
    for p in &mut mesh.positions {
        p.z = 1.5 * (p.x * 0.31).sin() * (p.y * 0.23).cos() + 0.6 * (p.x * 0.07 + p.y * 0.11).sin();
    }
    mesh
}

fn projection() -> Projection {
    Projection::Perspective {
        fov_y: 60f32.to_radians(),
        viewport_height: 1080.0,
    }
}

/// A flight from far out over one corner to low over the grid's middle.
fn path(n: u32, frames: usize) -> Vec<Vec3> {
    let n = n as f32;
    (0..frames)
        .map(|i| {
            let t = i as f32 / (frames - 1) as f32;
            Vec3::new(
                -n + 1.5 * n * t,
                -n + 1.4 * n * t,
                2.0 * n * (1.0 - t) + 4.0,
            )
        })
        .collect()
}

fn view(eye: Vec3, px: f32, frustum: Option<Frustum>) -> View {
    View {
        projection: projection(),
        eye,
        pixel_threshold: px,
        frustum,
    }
}

#[test]
fn the_arena_draws_the_cut_after_every_camera() {
    let n = 56;
    // Small clusters, so that many groups change at once (see the end).
    let options = HierarchyOptions {
        cluster_triangles: 32,
        group_clusters: 4,
        ..HierarchyOptions::default()
    };
    let mesh = hilly_grid(n);
    let h = hierarchy::build(&mesh, &options).unwrap();
    assert!(h.level_count() >= 3, "{} levels", h.level_count());
    let mut vd = ViewDependent::new(&h);
    let (mut changed, mut entered, mut left, mut clusters) = (0, 0, 0, 0);
    let mut most_walks = 0;
    let eyes = path(n, 60);
    for px in [0.5f32, 2.0] {
        for (i, &eye) in eyes.iter().enumerate() {
            let before = vd.buffer().to_vec();
            let u = vd.update(&view(eye, px, None));
            let context = format!("frame {i} at {px} px");
            let cut = vd.cut().clone();
            let expected = sorted_canonical(&cut.triangles(&h));
            assert_eq!(sorted_canonical(&vd.triangles()), expected, "{context}");
            assert_eq!(vd.triangle_count(), expected.len(), "{context}");
            assert_eq!(u.groups_drawn, cut.groups.len(), "{context}");
            assert_eq!(u.clusters_drawn, cut.clusters.len(), "{context}");
            // The dirty ranges hold every index that changed.
            let mut after = before.clone();
            after.resize(vd.buffer().len(), u32::MAX);
            for r in vd.dirty_ranges() {
                after[r.clone()].copy_from_slice(&vd.buffer()[r.clone()]);
            }
            assert_eq!(after, vd.buffer(), "{context}");
            // The padding is restarts: what is sent is the strips alone.
            let sent = vd.buffer().iter().filter(|&&v| v != u32::MAX).count();
            assert!(sent <= vd.indices_sent(), "{context}");
            assert!(
                vd.indices_sent()
                    < 2 * vd.triangle_count() + 8 * (cut.groups.len() + cut.clusters.len()) + 3,
                "{context}"
            );
            changed += u.groups_changed;
            most_walks = most_walks.max(u.groups_changed + u.groups_entered);
            entered += u.groups_entered;
            left += u.groups_left;
            clusters += u.clusters_entered;
        }
    }
    // The flight exercised every kind of change, and some update walked
    // enough groups to walk them on every core (runtime.rs,
    // `PARALLEL_WALKS`: 24).
    assert!(changed > 0 && entered > 0 && left > 0 && clusters > 0);
    assert!(
        most_walks >= 24,
        "at most {most_walks} groups walked at once"
    );
}

#[test]
fn a_camera_change_walks_less_than_a_fresh_arena() {
    let n = 40;
    let mesh = hilly_grid(n);
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    let eyes = path(n, 200);
    let mut vd = ViewDependent::new(&h);
    let (mut coherent, mut fresh) = (0usize, 0usize);
    for &eye in &eyes {
        coherent += vd.update(&view(eye, 1.0, None)).strips_walked;
        fresh += ViewDependent::new(&h)
            .update(&view(eye, 1.0, None))
            .strips_walked;
    }
    assert!(
        coherent * 4 < fresh,
        "{coherent} strips walked coherently, {fresh} afresh"
    );
}

#[test]
fn culling_leaves_out_only_what_lies_outside_the_frustum() {
    let n = 64;
    let mesh = hilly_grid(n);
    let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
    let eye = Vec3::new(32.0, 32.0, 5.0);
    let target = Vec3::new(50.0, 50.0, 0.0);
    let view_proj =
        glam::camera::rh::proj::directx::perspective(60f32.to_radians(), 1.0, 0.1, 500.0)
            * glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Z);
    let frustum = Frustum::from_view_projection(view_proj);
    let mut all = ViewDependent::new(&h);
    all.update(&view(eye, 1.0, None));
    let mut culled = ViewDependent::new(&h);
    culled.update(&view(eye, 1.0, Some(frustum)));
    assert!(culled.triangle_count() < all.triangle_count());
    assert!(culled.triangle_count() > 0);
    // Every drawn triangle survives culling unless all its corners are
    // outside one plane; and everything culled was of the full cut.
    let kept = sorted_canonical(&culled.triangles());
    let full = sorted_canonical(&all.triangles());
    let inside = |p: Vec3| {
        let c = view_proj * p.extend(1.0);
        c.w > 0.0 && c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w
    };
    for t in &full {
        let seen = t.iter().any(|&v| inside(mesh.positions[v as usize]));
        if seen {
            assert!(
                kept.binary_search(t).is_ok(),
                "a visible triangle {t:?} was culled"
            );
        }
    }
    for t in &kept {
        assert!(full.binary_search(t).is_ok());
    }
    // A frustum seeing everything culls nothing.
    assert!(frustum.may_see(target, 0.0));
    assert!(!frustum.may_see(eye - 10.0 * (target - eye), 1.0));
}

/// Diagnostic: the recorded error of each group's LoDs against the
/// distance from its removed vertices to its surface at that LoD.
#[test]
fn the_top_down_cut_is_the_exhaustive_one() {
    let grid = hilly_grid(48);
    let mut torus = "torus:4k"
        .parse::<mts::mesh::generate::Generated>()
        .unwrap()
        .build_with_properties();
    torus.properties.texture = None;
    for (name, mesh) in [("grid", grid), ("torus", torus)] {
        let h = hierarchy::build(&mesh, &HierarchyOptions::default()).unwrap();
        let (lo, hi) = mts::mesh::bounds_of(&mesh.positions).unwrap();
        let (centre, size) = (0.5 * (lo + hi), lo.distance(hi));
        let mut scratch = hierarchy::Selection::default();
        let mut cut = hierarchy::Cut::default();
        let mut kinds = (0, 0);
        for i in 0..40 {
            let a = i as f32 * 0.37;
            let eye = centre
                + size
                    * (0.1 + 0.05 * i as f32)
                    * Vec3::new(a.cos(), a.sin(), 0.3 + 0.2 * (a * 0.5).sin());
            for px in [0.0f32, 0.5, 2.0, 16.0, f32::NAN] {
                hierarchy::select_into(&h, &projection(), eye, px, &mut scratch, &mut cut);
                let reference = hierarchy::select_exhaustive(&h, &projection(), eye, px);
                assert_eq!(cut, reference, "{name}: eye {eye}, {px} px");
                assert_eq!(hierarchy::select(&h, &projection(), eye, px), reference);
                kinds.0 += cut.groups.len();
                kinds.1 += cut.clusters.len();
            }
        }
        assert!(kinds.0 > 0 && kinds.1 > 0, "{name}: {kinds:?}");
    }
}
