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
//! Run with `cargo run --release --example order_spread -- MESH SHARE
//! [ORDERS]`, e.g. `… -- ../shared/models/beetle.obj 0.1 6`.

use mts::distance::{surface_distance, Surface};
use mts::mesh::io::{load, LoadOptions};
use mts::{Mesh, SimplifyOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: order_spread MESH SHARE [ORDERS]";
    let path = args.get(1).ok_or(usage)?;
    let share: f64 = args.get(2).ok_or(usage)?.parse()?;
    let orders: u64 = args.get(3).map_or(Ok(6), |s| s.parse())?;
    if !(share > 0.0 && share < 1.0) || orders == 0 {
        return Err(usage.into());
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let mut ratios = Vec::new();
    for order in 0..orders {
        let renumbered = renumber(&mesh, order);
        let ratio = quality_ratio(&renumbered, share);
        print!("{ratio:.2} ");
        ratios.push(ratio);
    }
    ratios.sort_by(f64::total_cmp);
    println!(
        "| min {:.2} median {:.2} max {:.2}",
        ratios[0],
        ratios[ratios.len() / 2],
        ratios[ratios.len() - 1]
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
