//! Independent regions contracted at once: a contraction sequence made on
//! every core, for large meshes (issue 34, item 3; measured in
//! `docs/experiments/simplify-speed.md`, "independent regions").
//!
//! The triangles are cut into `regions` parts by median bisection of their
//! centroids along each part's longest axis. A vertex used by two parts is
//! locked ([`super::simplify_locked`], as the hierarchy's groups lock
//! their borders). Each part is contracted on its own, on every core, down
//! to [`REGION_SHARE`] of its triangles (or the caller's target share when
//! larger). The parts' steps are merged into one sequence by absolute
//! error: parts move disjoint vertices, so any interleaving that keeps each
//! part's order is a valid sequence, and a part's errors are running maxima.
//! Then what the parts leave is contracted serially to the end, borders
//! free.
//!
//! **Decision: one round of parts to a quarter, then the serial rest.**
//! Measured on five models against the serial sequence: halving rounds
//! (8, 4, 2 parts) are faster (the 1M icosphere's whole sequence 0.28 ×
//! the serial time on two cores) but lock a new border at each round and
//! lose quality at 1% (bunny 1.9 × the Hausdorff error, fandisk 15 ×);
//! one round to 25% stays within a few per cent of the serial sequence's
//! errors at 10% and 1% (lucy 12% more Hausdorff at 10% at worst), and
//! takes 0.46–0.70 × its time on two cores. It is not the default: the
//! serial sequence is the reference the report's quality figures hold.
//!
//! **Decision: the rest's errors start from the parts' last error.** The
//! serial rest measures its error against the mesh the parts left, not
//! the input; adding the largest error before it keeps the sequence's
//! errors non-decreasing and bounds the input's distance by the triangle
//! inequality, as far as each error bounds the surface's displacement.
//! A screen-space LoD choice reads them as it reads the serial sequence's.

use super::{simplify_locked, Collapse, Collapses, Placement, Simplification, SimplifyOptions};
use crate::mesh::Mesh;
use glam::Vec3;

/// A step of a part: its error in model units, the step, and the
/// triangles it removes.
type PartStep = (f64, Collapse, u32);

/// Share of its triangles each part is contracted to before the serial
/// rest.
pub const REGION_SHARE: f64 = 0.25;

/// Most parts [`simplify_in_regions`] cuts a mesh into.
pub const MAX_REGIONS: usize = 64;

/// Why [`simplify_in_regions`] cannot run on `mesh` with `options`, if it
/// cannot: vertex properties (a part's seams and companion moves are not
/// cut yet), optimal placement (created vertices are numbered per part) or
/// virtual pairs (they would join vertices of two parts).
#[must_use]
pub fn regions_refusal(mesh: &Mesh, options: &SimplifyOptions) -> Option<&'static str> {
    if !mesh.properties.is_empty() {
        Some("regions need a mesh of positions only (its vertex properties are not cut into regions yet)")
    } else if options.placement == Placement::Optimal {
        Some("regions need endpoint placement")
    } else if options.pair_distance.is_some() {
        Some("regions cannot pair vertices across parts (no pair distance)")
    } else {
        None
    }
}

/// The contraction sequence of `mesh` made in `regions` parts at once, then
/// serially (module documentation). `regions` is rounded down to a power
/// of two and capped at [`MAX_REGIONS`]; below 2 it is [`super::simplify`].
/// `options.stop_at_triangles` ends the serial rest there (the parts stop
/// at that share when it is above [`REGION_SHARE`]).
///
/// # Panics
/// If [`regions_refusal`] refuses `mesh` and `options`, or as
/// [`super::simplify`].
#[must_use]
pub fn simplify_in_regions(
    mesh: &Mesh,
    options: &SimplifyOptions,
    regions: usize,
) -> Simplification {
    if let Some(why) = regions_refusal(mesh, options) {
        panic!("simplify_in_regions: {why}");
    }
    let regions = regions.min(MAX_REGIONS);
    if regions < 2 || mesh.triangles.is_empty() {
        return simplify_locked(mesh, options, &[]);
    }
    let parts = cut_into_regions(mesh, 1 << regions.ilog2());
    let locked = region_borders(mesh, &parts);
    let total = mesh.triangle_count() as f64;
    let share = options
        .stop_at_triangles
        .map_or(REGION_SHARE, |t| (t as f64 / total).max(REGION_SHARE));
    let done = crate::parallel::map_indexed(
        parts.len(),
        || vec![u32::MAX; mesh.positions.len()],
        |local, i| contract_part(mesh, &parts[i], &locked, share, options, local),
    );
    let mut steps: Vec<PartStep> = Vec::new();
    let mut rest = Vec::new();
    for (part_steps, left) in done {
        steps.extend(part_steps);
        rest.extend(left);
    }
    // Stable: each part's steps stay in their order.
    steps.sort_by(|a, b| a.0.total_cmp(&b.0));
    let offset = steps.last().map_or(0.0, |s| s.0);
    // What the parts leave, as a mesh of its own (every vertex used), so
    // the simplifier's diagonal is the one its errors are scaled back by.
    let (left, vertices) = mesh.submesh(&rest, &mut vec![u32::MAX; mesh.positions.len()]);
    let tail = simplify_locked(&left, options, &[]);
    steps.extend(part_steps(&left, &vertices, &tail.collapses, offset));
    // The parts hold disjoint triangles, so the count after a step is the
    // count before less what the step removed in its own part.
    let input = mesh.diagonal_f64().max(f64::MIN_POSITIVE);
    let mut running = 0.0f32;
    let mut counts = Vec::with_capacity(steps.len() + 1);
    counts.push(mesh.triangle_count() as u32);
    let steps: Vec<Collapse> = steps
        .into_iter()
        .map(|(error, c, removed)| {
            running = running.max((error / input) as f32);
            counts.push(counts[counts.len() - 1] - removed);
            Collapse {
                error: running,
                ..c
            }
        })
        .collect();
    debug_assert_eq!(
        counts,
        crate::model::format::replay_counts(mesh, &steps, false, &[])
    );
    let mut stop = tail.stop;
    stop.lod = steps.len();
    let collapses = Collapses::new(mesh.vertex_count(), steps, counts, Vec::<Vec3>::new());
    debug_assert_eq!(collapses.validate(), Ok(()));
    debug_assert_eq!(collapses.triangle_count(stop.lod), stop.triangles);
    Simplification { collapses, stop }
}

/// `mesh`'s triangle indices cut into `parts` (rounded up to a power of
/// two) by median bisection of their centroids along each part's longest
/// axis (ties by index, so the cut is deterministic).
#[must_use]
pub fn cut_into_regions(mesh: &Mesh, parts: usize) -> Vec<Vec<u32>> {
    let centroid = |t: u32| {
        let [a, b, c] = mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
        (a + b + c) / 3.0
    };
    let mut out = vec![(0..mesh.triangles.len() as u32).collect::<Vec<u32>>()];
    while out.len() < parts {
        let mut next = Vec::with_capacity(2 * out.len());
        for mut part in out {
            let (lo, hi) = part
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &t| {
                    (lo.min(centroid(t)), hi.max(centroid(t)))
                });
            let axis = (hi - lo).max_position();
            let mid = part.len() / 2;
            if mid > 0 {
                part.select_nth_unstable_by(mid, |&a, &b| {
                    centroid(a)[axis]
                        .total_cmp(&centroid(b)[axis])
                        .then(a.cmp(&b))
                });
            }
            let upper = part.split_off(mid);
            next.push(part);
            next.push(upper);
        }
        out = next;
    }
    out
}

/// One flag per vertex of `mesh`: used by triangles of two or more of
/// `parts` (triangle indices), the vertices [`simplify_in_regions`] locks.
#[must_use]
pub fn region_borders(mesh: &Mesh, parts: &[Vec<u32>]) -> Vec<bool> {
    let mut owner = vec![u32::MAX; mesh.positions.len()];
    let mut locked = vec![false; mesh.positions.len()];
    for (p, tris) in parts.iter().enumerate() {
        for &t in tris {
            for v in mesh.triangles[t as usize] {
                let o = &mut owner[v as usize];
                if *o == u32::MAX {
                    *o = p as u32;
                } else if *o != p as u32 {
                    locked[v as usize] = true;
                }
            }
        }
    }
    locked
}

/// Part `triangles` contracted to `share` of its triangles, its border
/// locked: its steps over the input's vertices, each with its error in
/// model units, and the triangles it leaves. `local` is a scratch vertex
/// map (all `u32::MAX`, left so).
fn contract_part(
    mesh: &Mesh,
    triangles: &[u32],
    locked: &[bool],
    share: f64,
    options: &SimplifyOptions,
    local: &mut [u32],
) -> (Vec<PartStep>, Vec<[u32; 3]>) {
    let tris: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&t| mesh.triangles[t as usize])
        .collect();
    let (part, vertices) = mesh.submesh(&tris, local);
    let flags: Vec<bool> = vertices.iter().map(|&v| locked[v as usize]).collect();
    let part_options = SimplifyOptions {
        stop_at_triangles: Some((share * part.triangle_count() as f64).ceil() as usize),
        ..*options
    };
    let s = simplify_locked(&part, &part_options, &flags);
    let steps = part_steps(&part, &vertices, &s.collapses, 0.0);
    let left = s
        .collapses
        .triangles_at(&part, s.collapses.max_lod())
        .into_iter()
        .map(|t| t.map(|v| vertices[v as usize]))
        .collect();
    (steps, left)
}

/// The steps of `collapses` (a sequence of `part`, whose vertex `i` is
/// `vertices[i]`) over the input's vertices, each with its error in model
/// units plus `offset` (the simplifier's errors are relative to the
/// part's own diagonal) and the triangles it removes.
fn part_steps(part: &Mesh, vertices: &[u32], collapses: &Collapses, offset: f64) -> Vec<PartStep> {
    let scale = part.diagonal_f64();
    let counts = collapses.triangle_counts();
    collapses
        .steps()
        .iter()
        .enumerate()
        .map(|(i, c)| {
            (
                offset + f64::from(c.error) * scale,
                Collapse {
                    removed: vertices[c.removed as usize],
                    kept: vertices[c.kept as usize],
                    error: 0.0,
                },
                counts[i] - counts[i + 1],
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::distance::{surface_distance, Surface};
    use crate::mesh::generate::Generated;

    fn mesh(name: &str) -> Mesh {
        name.parse::<Generated>().unwrap().build()
    }

    /// A sequence made in parts is a valid sequence of the whole mesh: its
    /// table agrees with a replay at every LoD sampled, it ends where its
    /// stop says, and it goes about as far as the serial one.
    #[test]
    fn a_sequence_made_in_regions_is_valid_and_complete() {
        for (name, regions) in [("torus:20k", 4), ("icosphere:10k", 8), ("grid:5k", 2)] {
            let m = mesh(name);
            let options = SimplifyOptions::default();
            let s = simplify_in_regions(&m, &options, regions);
            let c = &s.collapses;
            assert_eq!(c.validate(), Ok(()), "{name}");
            assert_eq!(c.triangle_count(0), m.triangle_count(), "{name}");
            assert_eq!(s.stop.lod, c.max_lod(), "{name}");
            assert_eq!(c.triangle_count(c.max_lod()), s.stop.triangles, "{name}");
            for lod in (0..=c.max_lod()).step_by(c.max_lod() / 7 + 1) {
                assert_eq!(
                    c.triangles_at(&m, lod).len(),
                    c.triangle_count(lod),
                    "{name} LoD {lod}"
                );
            }
            let serial = crate::simplify(&m, &options);
            assert!(
                c.max_lod() * 100 >= serial.collapses.max_lod() * 95,
                "{name}: {} steps against {}",
                c.max_lod(),
                serial.collapses.max_lod()
            );
        }
    }

    /// Its levels are about as close to the input as the serial
    /// sequence's (the measured figures are in simplify-speed.md; here a
    /// loose bound that a broken merge or lock would break).
    #[test]
    fn levels_made_in_regions_stay_close_to_the_serial_ones() {
        let m = mesh("torus:20k");
        let options = SimplifyOptions::default();
        let parts = simplify_in_regions(&m, &options, 4).collapses;
        let serial = crate::simplify(&m, &options).collapses;
        for share in [0.1, 0.01] {
            let budget = (share * m.triangle_count() as f64) as usize;
            let error = |c: &Collapses| {
                let tris = c.triangles_at(&m, c.lod_for_triangles(budget));
                surface_distance((&m).into(), Surface::over(&m, &tris), 20_000).hausdorff
            };
            let (ours, reference) = (error(&parts), error(&serial));
            assert!(
                ours <= 1.5 * reference + 1e-4,
                "{share}: {ours} against {reference}"
            );
        }
    }

    /// A target stops the serial rest there, and the parts above it.
    #[test]
    fn a_target_is_where_the_sequence_stops() {
        let m = mesh("icosphere:10k");
        for target in [5_000, 1_000, 100] {
            let options = SimplifyOptions {
                stop_at_triangles: Some(target),
                ..SimplifyOptions::default()
            };
            let s = simplify_in_regions(&m, &options, 4);
            assert!(s.stop.triangles <= target, "{target}: {}", s.stop.triangles);
            assert!(
                s.stop.triangles + 10 >= target,
                "{target}: {}",
                s.stop.triangles
            );
            assert_eq!(s.collapses.validate(), Ok(()));
        }
    }

    /// More parts than triangles: empty parts contract nothing and the
    /// sequence is still valid (the replay check runs in debug builds).
    #[test]
    fn more_regions_than_triangles_give_a_valid_sequence() {
        for name in ["icosphere:20", "grid:8", "torus:50"] {
            let m = mesh(name);
            let s = simplify_in_regions(&m, &SimplifyOptions::default(), MAX_REGIONS);
            assert_eq!(s.collapses.validate(), Ok(()), "{name}");
            assert_eq!(
                s.collapses.triangle_count(s.collapses.max_lod()),
                s.stop.triangles,
                "{name}"
            );
            assert!(s.stop.triangles < m.triangle_count(), "{name}");
        }
    }

    #[test]
    fn one_region_is_the_serial_sequence_and_properties_are_refused() {
        let m = mesh("torus:3k");
        let options = SimplifyOptions::default();
        assert_eq!(
            simplify_in_regions(&m, &options, 1).collapses,
            crate::simplify(&m, &options).collapses
        );
        let mut with = m.clone();
        with.properties.normals = Some(vec![Vec3::Z; with.positions.len()]);
        assert!(regions_refusal(&with, &options).is_some());
        let optimal = SimplifyOptions {
            placement: Placement::Optimal,
            ..options
        };
        assert!(regions_refusal(&m, &optimal).is_some());
        assert_eq!(regions_refusal(&m, &options), None);
    }
}
