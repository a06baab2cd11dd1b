//! Property error of our LoDs against meshoptimizer's attribute-aware
//! simplification (`simplifyWithAttributes`) at one triangle count, beside
//! the geometric error of both.
//!
//! For spot.obj (texture coordinates), pirate.obj (texture coordinates and
//! normals) and beetle.obj (normals), loaded with their properties, at 10%
//! and 1% of the triangles: one row each with the triangle counts, the
//! Hausdorff distance and RMS (relative to the diagonal, as `mts simplify`
//! reports them) and the RMS and maximum of each property error (UV units,
//! degrees, RGBA distance), ours then meshoptimizer's. Where meshoptimizer
//! stops above the count, ours is taken at its count, as in every quality
//! comparison (`simplify_to_lod`). 200,000 samples a side.
//!
//! Run with `cargo run --release -p mts --features peers --example
//! property_error [-- [--models DIR] [--uv-weight W] [--normal-weight W]]`;
//! the models default to `../shared/models`, the weights to
//! `MESHOPT_WEIGHTS`.

use mts::distance::{property_error, surface_distance, Stat, DEFAULT_SAMPLES};
use mts::mesh::io::{load, LoadOptions};
use mts::peers::meshopt::{refusal, simplify_with_attributes_to_lod, MESHOPT_WEIGHTS};
use mts::{Mesh, SimplifyOptions};
use std::path::PathBuf;

const MODELS: [&str; 3] = ["spot.obj", "pirate.obj", "beetle.obj"];
const SHARES: [f64; 2] = [0.1, 0.01];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let usage = "usage: property_error [--models DIR] [--uv-weight W] [--normal-weight W] \
                 [--our-uv-weight W] [--our-normal-weight W] [--samples N]";
    let mut ours = SimplifyOptions::default();
    let mut samples = DEFAULT_SAMPLES;
    let mut dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    let mut weights = MESHOPT_WEIGHTS;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or(usage)?;
        match flag.as_str() {
            "--models" => dir = PathBuf::from(value),
            "--uv-weight" => weights.uv = value.parse()?,
            "--normal-weight" => weights.normal = value.parse()?,
            "--our-uv-weight" => ours.attribute_weights.uv = value.parse()?,
            "--our-normal-weight" => ours.attribute_weights.normal = value.parse()?,
            "--samples" => samples = value.parse()?,
            _ => return Err(usage.into()),
        }
    }
    println!(
        "meshoptimizer weights: normal {}, uv {}, colour {}; ours: normal {}, uv {}, colour {}; \
         {samples} samples a side; each pair is ours/meshoptimizer",
        weights.normal,
        weights.uv,
        weights.color,
        ours.attribute_weights.normal,
        ours.attribute_weights.uv,
        ours.attribute_weights.color
    );
    println!(
        "{:<11} {:>5} {:>9} {:>15} {:>15} {:>13} {:>13} {:>11} {:>13} {:>13}",
        "model",
        "share",
        "triangles",
        "Hausdorff",
        "RMS",
        "UV rms",
        "UV max",
        "normal° rms",
        "normal° max",
        "colour rms"
    );
    let options = LoadOptions {
        properties: true,
        ..LoadOptions::default()
    };
    for name in MODELS {
        if !dir.join(name).exists() {
            println!("{name:<11} not in {}: skipped", dir.display());
            continue;
        }
        let (mesh, _) = load(&dir.join(name), options)?;
        let collapses = mts::simplify(&mesh, &ours).collapses;
        for share in SHARES {
            print!("{name:<11} {:>4}% ", share * 100.0);
            if let Some(why) = refusal(&mesh) {
                println!("{why}");
                continue;
            }
            let lod = collapses.lod_for_ratio(share);
            let (theirs, lod) = simplify_with_attributes_to_lod(&mesh, &collapses, lod, weights);
            let ours = collapses.mesh_at(&mesh, lod);
            let theirs = Mesh {
                triangles: theirs,
                ..mesh.clone()
            };
            row(&mesh, &ours, &theirs, samples);
        }
    }
    Ok(())
}

/// Prints the rest of a row: `ours` and `theirs` measured against `mesh`.
fn row(mesh: &Mesh, ours: &Mesh, theirs: &Mesh, samples: usize) {
    let geometry = |lod: &Mesh| surface_distance(mesh.into(), lod.into(), samples);
    let (d_ours, d_theirs) = (geometry(ours), geometry(theirs));
    let p_ours = property_error(mesh, ours, samples);
    let p_theirs = property_error(mesh, theirs, samples);
    let pair = |a: Option<f64>, b: Option<f64>, digits: usize| match (a, b) {
        (Some(a), Some(b)) => format!("{a:.digits$}/{b:.digits$}"),
        _ => "-".to_owned(),
    };
    let rms = |s: Option<Stat>| s.map(|s| s.rms);
    let max = |s: Option<Stat>| s.map(|s| s.max);
    println!(
        "{:>9} {:>15} {:>15} {:>13} {:>13} {:>11} {:>13} {:>13}",
        format!("{}/{}", ours.triangle_count(), theirs.triangle_count()),
        pair(Some(d_ours.hausdorff), Some(d_theirs.hausdorff), 5),
        pair(Some(d_ours.rms), Some(d_theirs.rms), 5),
        pair(rms(p_ours.uv), rms(p_theirs.uv), 4),
        pair(max(p_ours.uv), max(p_theirs.uv), 3),
        pair(rms(p_ours.normal_degrees), rms(p_theirs.normal_degrees), 1),
        pair(max(p_ours.normal_degrees), max(p_theirs.normal_degrees), 1),
        pair(rms(p_ours.color), rms(p_theirs.color), 4),
    );
}
