//! `mts simplify`: record the contraction sequence, take one LoD of it
//! and measure its error beside meshoptimizer's simplify.

use crate::args::*;
use crate::stdout::{outln, warnln};
use anyhow::{bail, Result};
use clap::Args;
use mts::mesh::Mesh;
use mts::peers;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
#[command(group(clap::ArgGroup::new("target").required(true).args(["ratio", "triangles"])))]
pub struct SimplifyArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// Keep this share of the triangles (0..1).
    #[arg(allow_negative_numbers = true, long)]
    pub ratio: Option<f64>,
    /// Keep at most this many triangles.
    #[arg(allow_negative_numbers = true, long)]
    pub triangles: Option<usize>,
    /// Write the simplified mesh (.obj, .ply, .glb or .gltf, by extension): the level's own vertices with their properties.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub gltf: GltfOut,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Place each surviving vertex at the quadric's optimum (new vertices)
    /// instead of keeping an endpoint.
    #[arg(long)]
    pub optimal: bool,
    /// Also contract vertex pairs closer than this share of the diagonal.
    #[arg(allow_negative_numbers = true, long, value_name = "SHARE", value_parser = non_negative::<f32>)]
    pub pair_distance: Option<f32>,
    /// Weight of the boundary-preserving planes.
    #[arg(allow_negative_numbers = true, long, value_parser = non_negative::<f64>)]
    pub boundary_weight: Option<f64>,
    /// Weight of texture-coordinate distortion in the cost, where the mesh
    /// has texture coordinates (an error of 1/weight costs one bounding-box diagonal).
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    pub uv_weight: Option<f32>,
    /// Weight of normal distortion in the cost, where the mesh has them.
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    pub normal_weight: Option<f32>,
    /// Weight of colour distortion in the cost, where the mesh has them.
    #[arg(long, value_name = "WEIGHT", allow_hyphen_values = true, value_parser = non_negative::<f32>)]
    pub color_weight: Option<f32>,
    /// Surface samples per side for the error measurement.
    #[arg(long, default_value_t = mts::distance::DEFAULT_SAMPLES, value_parser = count_in::<1, MAX_SAMPLES>, allow_negative_numbers = true)]
    pub samples: usize,
    /// Skip meshoptimizer.
    #[arg(long)]
    pub no_meshopt: bool,
    /// Contract the mesh in N parts at once on every core (a power of two,
    /// 2 to 64; others round down), each to a quarter of its triangles
    /// with its border locked, then the rest serially: a different
    /// sequence, about half the time on two cores and a quarter or less on
    /// large meshes (docs/experiments/simplify-speed.md). A mesh of
    /// positions only (--positions-only), endpoint placement, no pair
    /// distance.
    #[arg(long, value_name = "N", value_parser = count_in::<2, 64>, allow_negative_numbers = true)]
    pub regions: Option<usize>,
}

pub fn run(args: &SimplifyArgs) -> Result<()> {
    if let Some(out) = &args.output {
        args.source.check_output(out)?;
        args.gltf.check(out)?;
    }
    use mts::distance::surface_distance;
    use mts::peers::quality::{self, Measurement};
    use mts::simplify::{Placement, SimplifyOptions};
    let (name, mesh, _) = args.source.load()?;
    let input = mesh.triangle_count();
    let target = match (args.triangles, args.ratio) {
        (Some(n), _) => n,
        (None, Some(r)) if (0.0..=1.0).contains(&r) => (r * input as f64).round() as usize,
        (None, Some(r)) => bail!("--ratio must be between 0 and 1, not {r}"),
        (None, None) => bail!("give --ratio or --triangles"),
    };
    let defaults = SimplifyOptions::default();
    let mut options = SimplifyOptions {
        placement: if args.optimal {
            Placement::Optimal
        } else {
            Placement::Endpoint
        },
        pair_distance: args.pair_distance,
        boundary_weight: args.boundary_weight.unwrap_or(defaults.boundary_weight),
        stop_at_triangles: None,
        attribute_weights: mts::simplify::AttributeWeights {
            uv: args.uv_weight.unwrap_or(defaults.attribute_weights.uv),
            normal: args
                .normal_weight
                .unwrap_or(defaults.attribute_weights.normal),
            color: args
                .color_weight
                .unwrap_or(defaults.attribute_weights.color),
        },
    };
    if args.regions.is_some() {
        if let Some(why) = mts::simplify::regions_refusal(&mesh, &options) {
            bail!("{name}: --regions: {why}");
        }
    }
    let run = |options: &SimplifyOptions| match args.regions {
        Some(n) => mts::simplify::simplify_in_regions(&mesh, options, n),
        None => mts::simplify(&mesh, options),
    };
    let t = Instant::now();
    let whole = run(&options);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    options.stop_at_triangles = Some(target);
    let t = Instant::now();
    let partial = run(&options);
    let ms_to_target = t.elapsed().as_secs_f64() * 1e3;
    let collapses = &whole.collapses;
    let lod = collapses.lod_for_triangles(target);
    // The early-stopped run must be a prefix of the whole sequence (in
    // regions the parts stop at another share, so only the serial one).
    if args.regions.is_none()
        && partial.collapses.steps() != &collapses.steps()[..partial.collapses.max_lod()]
    {
        bail!("internal error: the sequence stopped at the target differs from the whole one");
    }
    let skipped = peers::meshopt::refusal(&mesh);
    if let Some(why) = &skipped {
        warnln!("{name}: {why}");
    }
    // Our LoD over every input and appended position, referenced or not:
    // the surface `mts simplify` has always measured (the bench drops the
    // unreferenced ones, and both keep their own figures).
    let ours_at = |lod| Mesh {
        positions: mesh
            .positions
            .iter()
            .chain(collapses.appended())
            .copied()
            .collect(),
        triangles: collapses.triangles_at(&mesh, lod),
        properties: Default::default(),
    };
    // Compare at one triangle count: ours at the target, meshoptimizer
    // asked for the same; when it stops above it, ours at its count.
    let (lod, d, peer) = if !args.no_meshopt && skipped.is_none() {
        let q = quality::compare(&mesh, collapses, lod, args.samples, ours_at);
        let peer = json!({
            "triangles": q.meshopt.triangle_count,
            "ms": q.meshopt_ms,
            "hausdorff": q.meshopt.distance.hausdorff,
            "rms": q.meshopt.distance.rms,
        });
        (q.lod, q.ours, peer)
    } else {
        let ours = ours_at(lod);
        let d = Measurement {
            triangle_count: ours.triangle_count(),
            distance: surface_distance((&mesh).into(), (&ours).into(), args.samples),
        };
        (lod, d, serde_json::Value::Null)
    };
    if let Some(path) = &args.output {
        super::save_mesh_as(&collapses.mesh_at(&mesh, lod), path, args.gltf)?;
    }
    let v = json!({
        "mesh": name,
        "input_triangles": input,
        "target": target,
        "triangles": d.triangle_count,
        "lod": lod,
        "max_lod": collapses.max_lod(),
        "ms": ms,
        "ms_to_target": ms_to_target,
        "quadric_error": collapses.error(lod),
        "hausdorff": d.distance.hausdorff,
        "rms": d.distance.rms,
        "stop": whole.stop.to_string(),
        "regions": args.regions,
        "meshopt": peer,
    });
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
        return Ok(());
    }
    outln!(
        "{name}: {input} triangles -> target {target}; sequence of {} contractions, {}",
        collapses.max_lod(),
        whole.stop
    )?;
    outln!("{:<26}{:>14}{:>14}", "", "mts", "meshopt")?;
    let peer = &v["meshopt"];
    let show = |x: &serde_json::Value, digits: usize| {
        x.as_f64()
            .map_or_else(|| "-".to_string(), |x| format!("{x:.digits$}"))
    };
    let rows = [
        (
            "triangles",
            show(&v["triangles"], 0),
            show(&peer["triangles"], 0),
        ),
        (
            "ms (to target)",
            format!("{ms_to_target:.1}"),
            show(&peer["ms"], 1),
        ),
        (
            "Hausdorff / diagonal",
            show(&v["hausdorff"], 6),
            show(&peer["hausdorff"], 6),
        ),
        ("RMS / diagonal", show(&v["rms"], 6), show(&peer["rms"], 6)),
    ];
    for (label, mine, theirs) in rows {
        outln!("{label:<26}{mine:>14}{theirs:>14}")?;
    }
    outln!("{:<26}{:>14.1}", "ms (whole sequence)", ms)?;
    Ok(())
}
