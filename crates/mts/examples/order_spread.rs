//! How much the Hausdorff ratio to meshoptimizer's `simplify` depends on
//! the order of the input's vertices.
//!
//! Both simplifiers break ties by index, so at a few dozen triangles a
//! renumbering of the same surface can move a row of the quality table by
//! tens of percent (`bunny.ply` and `bunny_compact.ply` are one surface in
//! two orders). This runs the bench report's quality row (our LoD at the
//! share, meshoptimizer at its triangle count, both compared at one count,
//! 100,000 samples a side) on the file's own order and on `orders - 1`
//! seeded random renumberings, and prints each ratio and their minimum,
//! median and maximum: a median above 1 is a systematic gap, a single
//! high order is tie noise.
//!
//! Run with `cargo run --release -p mts --features peers --example order_spread -- MESH SHARE
//! [ORDERS]`, e.g. `… -- ../shared/models/beetle.obj 0.1 6`; or with
//! `-- --all DIR [ORDERS]` for every `.obj` and `.ply` in `DIR` at 10% and
//! 1% (the 40 rows of the README table for `../shared/models`), followed
//! by the summary the project's quality notes quote: the geometric mean
//! of the median ratios, the rows whose median is above 1.15, the rows
//! with some order above 1.15, and the same for the files' own orders.

use mts::distance::{surface_distance, Surface};
use mts::mesh::io::{load, LoadOptions};
use mts::{Mesh, SimplifyOptions};
use std::path::Path;

/// Above this ratio to meshoptimizer's Hausdorff a row fails the target.
const TARGET: f64 = 1.15;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: order_spread MESH SHARE [ORDERS] | order_spread --all DIR [ORDERS]";
    if args.get(1).map(String::as_str) == Some("--all") {
        let dir = args.get(2).ok_or(usage)?;
        let orders: u64 = args.get(3).map_or(Ok(6), |s| s.parse())?;
        if orders == 0 {
            return Err(usage.into());
        }
        return all(Path::new(dir), orders);
    }
    let path = args.get(1).ok_or(usage)?;
    let share: f64 = args.get(2).ok_or(usage)?.parse()?;
    let orders: u64 = args.get(3).map_or(Ok(6), |s| s.parse())?;
    if !(share > 0.0 && share < 1.0) || orders == 0 {
        return Err(usage.into());
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    row(&mesh, share, orders);
    Ok(())
}

/// Prints one row (each order's ratio, then minimum, median and maximum)
/// and returns the ratios in order (the file's own first) and the median.
fn row(mesh: &Mesh, share: f64, orders: u64) -> (Vec<f64>, f64) {
    let mut ratios = Vec::new();
    for order in 0..orders {
        let ratio = quality_ratio(&renumber(mesh, order), share);
        print!("{ratio:.2} ");
        ratios.push(ratio);
    }
    let mut sorted = ratios.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    println!(
        "| min {:.2} median {median:.2} max {:.2}",
        sorted[0],
        sorted[sorted.len() - 1]
    );
    (ratios, median)
}

/// Every `.obj` then every `.ply` in `dir` (each sorted by name) at 10%
/// and 1%, then the summary.
fn all(dir: &Path, orders: u64) -> Result<(), Box<dyn std::error::Error>> {
    let mut files = Vec::new();
    for ext in ["obj", "ply"] {
        let mut these: Vec<_> = std::fs::read_dir(dir)?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == ext))
            .collect();
        these.sort();
        files.extend(these);
    }
    let (mut medians, mut files_own) = (Vec::new(), Vec::new());
    let (mut median_above, mut some_above, mut own_above) = (Vec::new(), Vec::new(), Vec::new());
    for file in &files {
        let (mesh, _) = load(file, LoadOptions::default())?;
        let name = file
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        for share in [0.1, 0.01] {
            print!("{name} {share} ");
            let (ratios, median) = row(&mesh, share, orders);
            let label = |x: f64| format!("{name}@{share}={x:.2}");
            let worst = ratios.iter().copied().fold(0.0, f64::max);
            if median > TARGET {
                median_above.push(label(median));
            }
            if worst > TARGET {
                some_above.push(label(worst));
            }
            if ratios[0] > TARGET {
                own_above.push(label(ratios[0]));
            }
            medians.push(median);
            files_own.push(ratios[0]);
        }
    }
    let geomean = |v: &[f64]| (v.iter().map(|x| x.ln()).sum::<f64>() / v.len() as f64).exp();
    println!(
        "geometric mean of the medians {:.3}; medians above {TARGET}: {} {:?}",
        geomean(&medians),
        median_above.len(),
        median_above
    );
    println!(
        "rows with some order above {TARGET}: {} {some_above:?}",
        some_above.len()
    );
    println!(
        "files' own orders: geometric mean {:.3}; above {TARGET}: {} {own_above:?}",
        geomean(&files_own),
        own_above.len()
    );
    Ok(())
}

/// `mesh` with its vertices renumbered by a seeded shuffle (order 0 keeps
/// the file's order); triangles keep their order and corners.
fn renumber(mesh: &Mesh, order: u64) -> Mesh {
    let n = mesh.vertex_count();
    let mut new_index: Vec<u32> = (0..n as u32).collect();
    if order > 0 {
        // xorshift64, seeded per order: reproducible without a dependency.
        let mut x = order.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        for i in (1..n).rev() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            new_index.swap(i, (x % (i as u64 + 1)) as usize);
        }
    }
    let mut positions = mesh.positions.clone();
    for (old, &new) in new_index.iter().enumerate() {
        positions[new as usize] = mesh.positions[old];
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| new_index[v as usize]))
        .collect();
    Mesh {
        positions,
        triangles,
        properties: Default::default(),
    }
}

/// Our Hausdorff over meshoptimizer's at `share`, as the bench report's
/// quality table measures it.
fn quality_ratio(mesh: &Mesh, share: f64) -> f64 {
    const SAMPLES: usize = 100_000;
    let collapses = mts::simplify(mesh, &SimplifyOptions::default()).collapses;
    let (theirs, lod) =
        mts::peers::meshopt::simplify_to_lod(mesh, &collapses, collapses.lod_for_ratio(share));
    let ours = collapses.mesh_at(mesh, lod);
    let d = surface_distance(mesh.into(), (&ours).into(), SAMPLES).hausdorff;
    let e = surface_distance(mesh.into(), Surface::over(mesh, &theirs), SAMPLES).hausdorff;
    if e > 0.0 {
        d / e
    } else if d > 0.0 {
        f64::INFINITY
    } else {
        1.0
    }
}
