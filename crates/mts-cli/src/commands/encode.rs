//! `mts encode`: the cluster tree's packet stream of a mesh.

use crate::args::*;
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use mts::mesh::Mesh;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct EncodeArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// The stream file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    pub json: bool,
}

/// The raw mesh with 16-bit indices (12 bytes per vertex, 6 per
/// triangle) plus its property values, so that a method carrying
/// properties is compared with a raw mesh carrying them too.
pub fn raw_bytes_u16(mesh: &Mesh) -> usize {
    mesh.raw_bytes_u16() + mesh.properties.bytes_per_vertex() * mesh.vertex_count()
}

/// What [`raw_bytes_u16`] adds per vertex, for the sentences that say
/// how raw is counted (nothing without properties).
pub fn with_properties(mesh: &Mesh) -> String {
    match mesh.properties.bytes_per_vertex() {
        0 => String::new(),
        b => format!(" and {b} of properties"),
    }
}

pub fn run(args: &EncodeArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let (name, mesh, _) = args.source.load()?;
    let t = Instant::now();
    let tree = mts::baselines::ClusterTree::new(&mesh)?;
    let bytes = tree.to_stream();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    mts::output::write_file(&args.output, &bytes)?;
    let raw = raw_bytes_u16(&mesh);
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "vertices": mesh.vertex_count(),
                "triangles": mesh.triangle_count(),
                "bytes": bytes.len(),
                "raw_bytes_u16": raw,
                "ratio": bytes.len() as f64 / raw as f64,
                "ms": ms,
            })
        )?;
    } else {
        outln!(
            "{name}: {} vertices, {} triangles -> {} bytes = {:.1}% of raw ({raw} bytes: 12 per vertex{} + 6 per triangle), {ms:.0} ms -> {}",
            mesh.vertex_count(),
            mesh.triangle_count(),
            bytes.len(),
            100.0 * bytes.len() as f64 / raw as f64,
            with_properties(&mesh),
            args.output.display()
        )?;
    }
    Ok(())
}
