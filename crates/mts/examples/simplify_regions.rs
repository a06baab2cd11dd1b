//! Independent regions contracted at once (issue 34, item 3): the time and
//! quality of a parallel contraction sequence beside the serial one.
//!
//! The scheme, as meshoptimizer's cluster LoD simplifies groups: the
//! triangles are cut into `R` regions by median bisection of their
//! centroids along the longest axis (`simplify::cut_into_regions`; the
//! library's `simplify_in_regions` is this example's one round to 25%); each region (its vertices on a
//! border with another region locked, `simplify::simplify_locked`) is
//! contracted on its own down to a share of its triangles (`stop=S`, 0 for
//! as far as it goes; default 0.25); the regions' steps are
//! merged into one sequence by absolute error (steps of different regions
//! touch different vertices, so any interleaving is a valid sequence);
//! then the mesh they leave, borders unlocked, is contracted serially to
//! the end. The whole sequence is therefore another sequence than the
//! serial one, and its levels are measured like the report's (Hausdorff
//! and RMS against the input, relative to its diagonal, 200K samples).
//!
//! Times, medians of `RUNS` runs: the serial sequence; the regions one
//! after the other (their sum and their largest: the phase's time on one
//! core, and on `R` cores), the serial rest; and the whole scheme on this
//! machine's cores. Positions only (properties dropped).
//!
//! `cargo run --release -p mts --example simplify_regions -- MESH|gen:NAME:SIZE [R...] [stop=S...]`,
//! e.g. `… -- ../shared/models/bunny.ply 2 4 8 stop=0 stop=0.25`.

use mts::distance::{surface_distance, Surface, DEFAULT_SAMPLES};
use mts::mesh::generate::Generated;
use mts::mesh::io::{load, LoadOptions};
use mts::simplify::{cut_into_regions, region_borders, simplify_locked};
use mts::{Mesh, SimplifyOptions};
use std::path::Path;
use std::time::Instant;

const RUNS: usize = 3;

/// One step of a sequence over the input's vertices.
#[derive(Clone, Copy)]
struct Step {
    removed: u32,
    kept: u32,
    /// Error in model units (the step's relative error × its mesh's
    /// diagonal), for merging the regions' steps.
    error: f64,
}

/// The submesh of `triangles` (indices into `mesh.triangles`) with its own
/// vertex numbering (`Mesh::submesh`), the input vertex of each local one,
/// and the local lock flags.
fn submesh(mesh: &Mesh, triangles: &[u32], locked: &[bool]) -> (Mesh, Vec<u32>, Vec<bool>) {
    let tris: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&t| mesh.triangles[t as usize])
        .collect();
    let (sub, vertices) = mesh.submesh(&tris, &mut vec![u32::MAX; mesh.positions.len()]);
    let flags = vertices.iter().map(|&v| locked[v as usize]).collect();
    (sub, vertices, flags)
}

/// A region's steps over the input's vertices, and its last LoD's
/// triangles over them.
fn contract_region(
    sub: &Mesh,
    vertices: &[u32],
    locked: &[bool],
    stop: f64,
) -> (Vec<Step>, Vec<[u32; 3]>) {
    let options = SimplifyOptions {
        stop_at_triangles: Some((stop * sub.triangle_count() as f64) as usize),
        ..SimplifyOptions::default()
    };
    let s = simplify_locked(sub, &options, locked);
    let d = sub.diagonal_f64();
    let steps = s
        .collapses
        .steps()
        .iter()
        .map(|c| Step {
            removed: vertices[c.removed as usize],
            kept: vertices[c.kept as usize],
            error: f64::from(c.error) * d,
        })
        .collect();
    let last = s
        .collapses
        .triangles_at(sub, s.collapses.max_lod())
        .into_iter()
        .map(|t| t.map(|v| vertices[v as usize]))
        .collect();
    (steps, last)
}

/// What one run of the scheme made.
struct Scheme {
    steps: Vec<Step>,
    /// Steps made by the regions (the first ones).
    region_steps: usize,
    /// Triangles the regions leave.
    left: usize,
    /// Per round, the regions' times when run one after another (empty in
    /// parallel).
    region_ms: Vec<Vec<f64>>,
    /// The serial rest's time.
    rest_ms: f64,
}

/// One round: `triangles` (over `mesh`'s vertices) cut into `parts`
/// regions, each contracted to `stop` of its triangles with its border
/// locked, on every core (`parallel`) or one after another (each timed
/// into `times`). Returns the steps merged by error (from `offset` on) and
/// the triangles left.
fn round(
    mesh: &Mesh,
    triangles: Vec<[u32; 3]>,
    parts: usize,
    stop: f64,
    parallel: bool,
    times: &mut Vec<f64>,
) -> (Vec<Step>, Vec<[u32; 3]>) {
    let current = Mesh {
        positions: mesh.positions.clone(),
        triangles,
        properties: Default::default(),
    };
    let regions = cut_into_regions(&current, parts);
    let locked = region_borders(&current, &regions);
    let subs: Vec<_> = regions
        .iter()
        .map(|tris| submesh(&current, tris, &locked))
        .collect();
    type Done = (Vec<Step>, Vec<[u32; 3]>);
    let results: Vec<Done> = if parallel {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let next = std::sync::atomic::AtomicUsize::new(0);
        let slots: Vec<std::sync::Mutex<Option<Done>>> =
            subs.iter().map(|_| std::sync::Mutex::new(None)).collect();
        std::thread::scope(|scope| {
            for _ in 0..threads.min(subs.len()) {
                scope.spawn(|| loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some((sub, vertices, flags)) = subs.get(i) else {
                        break;
                    };
                    *slots[i].lock().unwrap() = Some(contract_region(sub, vertices, flags, stop));
                });
            }
        });
        slots
            .into_iter()
            .map(|m| m.into_inner().unwrap().unwrap())
            .collect()
    } else {
        subs.iter()
            .map(|(sub, vertices, flags)| {
                let t = Instant::now();
                let r = contract_region(sub, vertices, flags, stop);
                times.push(t.elapsed().as_secs_f64() * 1e3);
                r
            })
            .collect()
    };
    // Merge by error, each region's own order kept (a stable sort of
    // steps whose errors are running maxima within each region).
    let mut steps: Vec<Step> = Vec::new();
    let mut rest = Vec::new();
    for (s, last) in results {
        steps.extend(s);
        rest.extend(last);
    }
    steps.sort_by(|a, b| a.error.total_cmp(&b.error));
    (steps, rest)
}

/// The scheme's whole sequence: a round of `parts` regions, then (with
/// `halving`) rounds of half as many regions each down to 2, then the
/// serial rest; regions on every core (`parallel`) or one after another
/// (timed). A later round's errors start from the last error before it
/// (its mesh's error against the input bounds none of them otherwise).
fn scheme(mesh: &Mesh, parts: usize, stop: f64, halving: bool, parallel: bool) -> Scheme {
    let mut steps: Vec<Step> = Vec::new();
    let mut current = mesh.triangles.clone();
    let mut region_ms = Vec::new();
    let mut p = parts;
    while p >= 2 {
        let mut times = Vec::new();
        let (s, rest) = round(mesh, current, p, stop, parallel, &mut times);
        let offset = steps.last().map_or(0.0, |s| s.error);
        steps.extend(s.into_iter().map(|x| Step {
            error: offset + x.error,
            ..x
        }));
        current = rest;
        region_ms.push(times);
        if !halving {
            break;
        }
        p /= 2;
    }
    let left = current.len();
    let region_steps = steps.len();
    // The mesh the regions leave, contracted serially to the end.
    let t = Instant::now();
    let (merged, vertices) = mesh.submesh(&current, &mut vec![u32::MAX; mesh.positions.len()]);
    let offset = steps.last().map_or(0.0, |s| s.error);
    let d = merged.diagonal_f64();
    let tail = mts::simplify(&merged, &SimplifyOptions::default());
    steps.extend(tail.collapses.steps().iter().map(|c| Step {
        removed: vertices[c.removed as usize],
        kept: vertices[c.kept as usize],
        error: offset + f64::from(c.error) * d,
    }));
    Scheme {
        steps,
        region_steps,
        left,
        region_ms,
        rest_ms: t.elapsed().as_secs_f64() * 1e3,
    }
}

/// The input's triangles after the first `k` steps (degenerate ones
/// dropped).
fn triangles_after(mesh: &Mesh, steps: &[Step], k: usize) -> Vec<[u32; 3]> {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    for s in &steps[..k] {
        parent[s.removed as usize] = s.kept;
    }
    let find = |parent: &mut Vec<u32>, mut v: u32| {
        let mut root = v;
        while parent[root as usize] != root {
            root = parent[root as usize];
        }
        while parent[v as usize] != root {
            let next = parent[v as usize];
            parent[v as usize] = root;
            v = next;
        }
        root
    };
    mesh.triangles
        .iter()
        .map(|t| t.map(|v| find(&mut parent, v)))
        .filter(|[a, b, c]| a != b && b != c && a != c)
        .collect()
}

/// The finest level of `steps` with at most `budget` triangles.
fn level(mesh: &Mesh, steps: &[Step], budget: usize) -> Vec<[u32; 3]> {
    let (mut lo, mut hi) = (0, steps.len());
    if triangles_after(mesh, steps, hi).len() > budget {
        return triangles_after(mesh, steps, hi);
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if triangles_after(mesh, steps, mid).len() <= budget {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    triangles_after(mesh, steps, lo)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let input = args
        .get(1)
        .ok_or("usage: simplify_regions MESH|gen:NAME:SIZE [R...]")?;
    let mut mesh = if let Some(g) = input.strip_prefix("gen:") {
        g.parse::<Generated>()?.build()
    } else {
        load(Path::new(input), LoadOptions::default())?.0
    };
    mesh.properties = Default::default();
    let mut parts: Vec<usize> = Vec::new();
    let mut stops: Vec<f64> = Vec::new();
    for a in &args[2..] {
        match a.strip_prefix("stop=") {
            Some(s) => stops.push(s.parse()?),
            None => parts.push(a.parse()?),
        }
    }
    if parts.is_empty() {
        parts = vec![2, 4, 8];
    }
    if stops.is_empty() {
        stops = vec![0.25];
    }
    if let Some(&p) = parts.iter().find(|p| !p.is_power_of_two()) {
        return Err(format!("{p} regions: a power of two").into());
    }
    let n = mesh.triangle_count();
    let serial_ms = median(
        (0..RUNS)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(mts::simplify(&mesh, &SimplifyOptions::default()));
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    );
    // meshoptimizer's simplify to 10% in the same run (with `--features
    // peers`), the figure's reference.
    #[cfg(feature = "peers")]
    let meshopt_ms = Some(median(
        (0..RUNS)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(mts::peers::meshopt::simplify(&mesh, n / 10));
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    ));
    #[cfg(not(feature = "peers"))]
    let meshopt_ms: Option<f64> = None;
    let serial = mts::simplify(&mesh, &SimplifyOptions::default());
    let serial_steps: Vec<Step> = serial
        .collapses
        .steps()
        .iter()
        .map(|c| Step {
            removed: c.removed,
            kept: c.kept,
            error: f64::from(c.error),
        })
        .collect();
    let quality = |steps: &[Step]| {
        [0.1, 0.01].map(|r| {
            let tris = level(&mesh, steps, (r * n as f64) as usize);
            let d = surface_distance((&mesh).into(), Surface::over(&mesh, &tris), DEFAULT_SAMPLES);
            (tris.len(), d.hausdorff, d.rms)
        })
    };
    let show = |q: [(usize, f64, f64); 2]| {
        q.map(|(t, h, r)| format!("{t}: {h:.5} / {r:.6}"))
            .join(" | ")
    };
    println!(
        "{input}: {n} triangles, {} cores; medians of {RUNS}; meshoptimizer's simplify to 10%: {}",
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        meshopt_ms.map_or("not measured (--features peers)".into(), |m| format!(
            "{m:.1} ms"
        ))
    );
    println!();
    println!("| sequence | regions' steps | triangles left by the regions | regions one after another: sum / largest (summed over rounds) ms | rest ms | on this machine ms | on R cores ms (largest + rest) | against serial here / on R cores | 10% and 1%: triangles: Hausdorff / RMS |");
    println!("|---|---|---|---|---|---|---|---|---|");
    println!(
        "| serial | — | — | — | — | {serial_ms:.1} | — | 1 | {} |",
        show(quality(&serial_steps))
    );
    for (&stop, &r, halving) in stops.iter().flat_map(|s| {
        parts
            .iter()
            .flat_map(move |r| [false, true].map(move |h| (s, r, h)))
    }) {
        if halving && r <= 2 {
            continue;
        }
        let mut sums = Vec::new();
        let mut largest = Vec::new();
        let mut rests = Vec::new();
        let mut walls = Vec::new();
        let mut last = None;
        for _ in 0..RUNS {
            let one = scheme(&mesh, r, stop, halving, false);
            sums.push(one.region_ms.iter().flatten().sum());
            largest.push(
                one.region_ms
                    .iter()
                    .map(|t| t.iter().copied().fold(0.0, f64::max))
                    .sum(),
            );
            rests.push(one.rest_ms);
            let t = Instant::now();
            last = Some(scheme(&mesh, r, stop, halving, true));
            walls.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let last = last.expect("RUNS > 0");
        let (sum, big, rest, wall) = (median(sums), median(largest), median(rests), median(walls));
        let name = if halving {
            format!(
                "{r}, {}, ..., 2 regions, each round to {:.0}%",
                r / 2,
                stop * 100.0
            )
        } else {
            format!("{r} regions to {:.0}%", stop * 100.0)
        };
        println!(
            "| {name} | {} | {} | {sum:.1} / {big:.1} | {rest:.1} | {wall:.1} | {:.1} | {:.2} / {:.2} | {} |",
            last.region_steps,
            last.left,
            big + rest,
            wall / serial_ms,
            (big + rest) / serial_ms,
            show(quality(&last.steps)),
        );
    }
    Ok(())
}
