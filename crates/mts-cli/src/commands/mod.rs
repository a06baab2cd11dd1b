//! One module per command: its arguments (`…Args`) and `run`.

pub mod bench;
pub mod build;
pub mod compare;
pub mod convert;
pub mod decode;
pub mod demo;
pub mod distance;
pub mod encode;
pub mod extract;
pub mod info;
pub mod lods;
pub mod render;
pub mod simplify;
pub mod strips;
pub mod verify;
pub mod view;

/// Writes `mesh` to `path` in the format its extension names, atomically;
/// what the format cannot hold of the mesh's properties is named in one
/// warning.
pub fn save_mesh(mesh: &mts::Mesh, path: &std::path::Path) -> anyhow::Result<()> {
    let lost = mts::mesh::io::dropped_by(mesh, path);
    if !lost.is_empty() {
        crate::stdout::warnln!(
            "{}: the format cannot hold the mesh's {}: dropped",
            path.display(),
            lost.join(", ")
        );
    }
    mts::mesh::io::save_mesh(mesh, path)?;
    Ok(())
}
