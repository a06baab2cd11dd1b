//! The cache-aware strips against issue 24's figure, model by model.
//!
//! For each mesh: the cache-aware stripifier's indices per triangle
//! (restart values included) against meshoptimizer's stripifier, and its
//! modelled vertex work (FIFO 16 over the triangle order, batches of 96
//! over the restart buffer) against the meshoptimizer-ordered list's + 0.05.
//! Prints one row per mesh, then how many meet each part of the figure.
//!
//! Run with `cargo run --release -p mts --features peers --example cache_strips -- MESH...`,
//! e.g. `-- ../shared/models/*.{obj,ply}`.

use mts::mesh::io::{load, LoadOptions};
use mts::strip::stats::StripStats;
use mts::strip::vertex_work::list_fifo16_batch96;
use mts::{peers, stripify, StripifyOptions};
use std::path::Path;

/// How far above the ordered list's vertex work the strips may be.
const SLACK: f64 = 0.05;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("usage: cache_strips MESH...".into());
    }
    println!(
        "{:<20}{:>8} {:>7}{:>7}{:>7} {:>7}{:>7}{:>7} {:>7}{:>7}  ok {:>8}{:>8}{:>7}",
        "mesh",
        "tris",
        "ipt",
        "fifo",
        "b96",
        "mo ipt",
        "mo fifo",
        "mo b96",
        "l fifo",
        "l b96",
        "runs",
        "swaps",
        "|d-6|"
    );
    let (mut ok_ipt, mut ok_fifo, mut ok_b96, mut n) = (0, 0, 0, 0);
    for p in &paths {
        let (mesh, _) = load(Path::new(p), LoadOptions::default())?;
        let options = StripifyOptions {
            cache_aware: true,
            ..StripifyOptions::default()
        };
        let ours = StripStats::new(&stripify(&mesh, &options), 0.0);
        let theirs = StripStats::new(&peers::meshopt::stripify(&mesh), 0.0);
        let list = peers::meshopt::optimize_vertex_cache(&mesh.triangles, mesh.vertex_count());
        let (list_fifo, list_b96) = list_fifo16_batch96(&list, mesh.vertex_count());
        let mut fan = vec![0i64; mesh.vertex_count()];
        for &v in mesh.triangles.iter().flatten() {
            fan[v as usize] += 1;
        }
        let irregular: i64 = fan.iter().map(|&d| (d - 6).abs()).sum();
        let bound = irregular as f64 / mesh.triangle_count() as f64;
        let a = ours.indices_per_triangle < theirs.indices_per_triangle;
        let b = ours.acmr <= list_fifo + SLACK;
        let c = ours.acmr_batch96 <= list_b96 + SLACK;
        n += 1;
        ok_ipt += usize::from(a);
        ok_fifo += usize::from(b);
        ok_b96 += usize::from(c);
        let name = Path::new(p)
            .file_name()
            .map_or(p.clone(), |s| s.to_string_lossy().into());
        println!(
            "{:<20}{:>8} {:>7.3}{:>7.3}{:>7.3} {:>7.3}{:>7.3}{:>7.3} {:>7.3}{:>7.3}  {}{}{} {:>8}{:>8}{:>7.3}",
            name,
            mesh.triangle_count(),
            ours.indices_per_triangle,
            ours.acmr,
            ours.acmr_batch96,
            theirs.indices_per_triangle,
            theirs.acmr,
            theirs.acmr_batch96,
            list_fifo,
            list_b96,
            if a { 'i' } else { '-' },
            if b { 'f' } else { '-' },
            if c { 'b' } else { '-' },
            ours.strips,
            ours.swaps,
            bound,
        );
    }
    println!(
        "meet: indices {ok_ipt}/{n}, fifo16 {ok_fifo}/{n}, batch96 {ok_b96}/{n} \
         (i: indices below meshoptimizer's strips; f, b: within {SLACK} of the ordered list)"
    );
    Ok(())
}
