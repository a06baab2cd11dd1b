//! `mts`: the command-line tool. Each command is a module of
//! [`commands`]; what several take (the mesh source, the LoD, bounded
//! numbers) is in [`args`]; the bench's measuring and report are in
//! [`bench`].

use crate::stdout::warnln;
use anyhow::Result;
use clap::{Parser, Subcommand};

mod args;
mod bench;
mod commands;
mod demo_scene;
mod gltf_scene;
mod stdout;
mod timing;
mod viewer;

#[derive(Parser)]
#[command(
    name = "mts",
    version,
    about = "Continuous level of detail with multiresolution triangle strips"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The main job: build the model of the built-in mesh (or a file),
    /// sweep its LoDs and print the side-by-side summary.
    Demo(commands::demo::DemoArgs),
    /// Cut a mesh into triangle strips and compare with meshoptimizer's.
    Strips(commands::strips::StripsArgs),
    /// Record the quadric-error contraction sequence, take one LoD of it and
    /// measure its error beside meshoptimizer's simplify.
    Simplify(commands::simplify::SimplifyArgs),
    /// Hausdorff and RMS distance of a mesh to a reference mesh.
    Distance(commands::distance::DistanceArgs),
    /// Write a mesh (a file or a generated one) as .obj, .ply, .glb or .gltf (by the output's extension).
    Convert(commands::convert::ConvertArgs),
    /// Build the MTS model (strips, contraction sequence, per-strip graphs)
    /// and write it as an .mts file.
    Build(commands::build::BuildArgs),
    /// Describe an .mts file: sizes, bands, and strip quality at several
    /// LoDs against stripifying that LoD's mesh from scratch.
    Info(commands::info::InfoArgs),
    /// Extract one LoD of a model as restart-encoded strips.
    Extract(commands::extract::ExtractArgs),
    /// Write a chain of LoDs as one glTF file with MSFT_lod (each level an
    /// indexed list in vertex-cache order with its own vertices).
    Lods(commands::lods::LodsArgs),
    /// Encode a mesh as the cluster tree's packet stream (a progressive,
    /// incrementally decodable file).
    Encode(commands::encode::EncodeArgs),
    /// Decode a packet stream, or only its first bytes (what a receiver
    /// draws while the stream arrives).
    Decode(commands::decode::DecodeArgs),
    /// Every method side by side on one mesh: bytes, build time and
    /// microseconds per LoD change on the linear, exponential and random
    /// request sequences.
    Compare(commands::compare::CompareArgs),
    /// Check a model against the replay oracle and coherent against
    /// from-scratch extraction; exits non-zero on any mismatch.
    Verify(commands::verify::VerifyArgs),
    /// Measure the MTS paper's tables on this machine: report.md and
    /// results.json (`mts bench render`: render throughput alone).
    Bench(commands::bench::BenchArgs),
    /// Draw one LoD headless (Mesa's lavapipe without a GPU) into a PNG,
    /// by the MTS strips or the oracle triangle list.
    Render(commands::render::RenderArgs),
    /// Open a window on a model (orbit camera; wheel, Up/Down change the
    /// LoD, A toggles the automatic LoD, Escape quits).
    View(commands::view::ViewArgs),
}

fn run(cli: &Cli) -> Result<()> {
    use commands as c;
    match &cli.command {
        Command::Demo(args) => c::demo::run(args),
        Command::Strips(args) => c::strips::run(args),
        Command::Simplify(args) => c::simplify::run(args),
        Command::Distance(args) => c::distance::run(args),
        Command::Convert(args) => c::convert::run(args),
        Command::Build(args) => c::build::run(args),
        Command::Info(args) => c::info::run(args),
        Command::Extract(args) => c::extract::run(args),
        Command::Lods(args) => c::lods::run(args),
        Command::Encode(args) => c::encode::run(args),
        Command::Decode(args) => c::decode::run(args),
        Command::Compare(args) => c::compare::run(args),
        Command::Verify(args) => c::verify::run(args),
        Command::Bench(args) => c::bench::run(args),
        Command::Render(args) => c::render::run(args),
        Command::View(args) => c::view::run(args),
    }
}

fn main() -> std::process::ExitCode {
    // Mesa's implicit Vulkan layer VK_LAYER_MESA_device_select connects to
    // Wayland to rank GPUs by the display they drive, and without
    // XDG_RUNTIME_DIR (no Wayland session: a headless run) libwayland prints
    // "error: XDG_RUNTIME_DIR is invalid or not set" twice, as if it were
    // ours. With no session there is no display to rank by: the layer is
    // switched off by its documented variable, unless the user set it.
    // Set before any thread starts.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<stdout::ClosedPipe>().is_some() => {
            std::process::ExitCode::from(141)
        }
        Err(e) => {
            // One line: the context, then each cause not already said.
            let mut line = e.to_string();
            for cause in e.chain().skip(1) {
                let text = cause.to_string();
                if !line.contains(&text) {
                    line = format!("{line}: {text}");
                }
            }
            // Standard error may be closed or full too: then the status
            // alone tells.
            warnln!("error: {line}");
            std::process::ExitCode::FAILURE
        }
    }
}
