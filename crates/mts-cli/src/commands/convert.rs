//! `mts convert`: write a mesh in another format.

use crate::args::*;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// The OBJ file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &ConvertArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let (_, mesh, _) = args.source.load()?;
    super::save_mesh(&mesh, &args.output)?;
    Ok(())
}
