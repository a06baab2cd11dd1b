//! `mts convert`: write a mesh in another format.

use crate::args::*;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// The file to write (.obj, .ply, .glb or .gltf, by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub gltf: GltfOut,
}

pub fn run(args: &ConvertArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    args.gltf.check(&args.output)?;
    let (_, mesh, _) = args.source.load()?;
    super::save_mesh_as(&mesh, &args.output, args.gltf)?;
    Ok(())
}
