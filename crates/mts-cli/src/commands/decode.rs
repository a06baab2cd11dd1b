//! `mts decode`: a packet stream, or its first bytes, decoded.

use crate::args::*;
use crate::stdout::outln;
use anyhow::Result;
use clap::Args;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct DecodeArgs {
    /// The stream file.
    pub stream: PathBuf,
    /// Decode only the first N bytes (the packets they hold completely).
    #[arg(allow_negative_numbers = true, long)]
    pub bytes: Option<usize>,
    /// Write the decoded mesh (.obj, .ply, .glb or .gltf, by extension).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &DecodeArgs) -> Result<()> {
    use mts::baselines::cluster::stream;
    if let Some(out) = &args.output {
        check_output(out, &[&args.stream])?;
    }
    let all = mts::mesh::io::read_file(&args.stream)?;
    let file = args.stream.display().to_string();
    let t = Instant::now();
    // A prefix shorter than the file is decoded as far as it goes; the
    // whole file is decoded strictly (checksum and all) however it was asked.
    let d = match args.bytes {
        Some(n) if n < all.len() => stream::decode_prefix(&all[..n], &file)?,
        _ => stream::decode(&all, &file)?,
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let mesh = d.mesh();
    mesh.validate()?;
    if let Some(out) = &args.output {
        super::save_mesh(&mesh, out)?;
    }
    if args.json {
        outln!(
            "{}",
            json!({
                "input": file,
                "bytes_read": args.bytes.unwrap_or(all.len()).min(all.len()),
                "bytes_used": d.bytes_used,
                "vertices": d.positions.len(),
                "triangles": d.triangles.len(),
                "total_vertices": d.total_vertices,
                "total_triangles": d.total_triangles,
                "complete": d.is_complete(),
                "ms": ms,
            })
        )?;
    } else {
        outln!(
            "{file}: {} of {} vertices and {} of {} triangles from {} bytes ({}), {ms:.1} ms",
            d.positions.len(),
            d.total_vertices,
            d.triangles.len(),
            d.total_triangles,
            d.bytes_used,
            if d.is_complete() {
                "complete"
            } else {
                "partial"
            }
        )?;
    }
    Ok(())
}
