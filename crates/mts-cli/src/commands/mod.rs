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
    save_mesh_as(mesh, path, crate::args::GltfOut::default())
}

/// [`save_mesh`] with the glTF encoding `out` asks for: quantized or
/// compressed levels are written in vertex-cache order (triangles, then
/// vertices in order of first use), what the codecs and GPUs do best with.
pub fn save_mesh_as(
    mesh: &mts::Mesh,
    path: &std::path::Path,
    out: crate::args::GltfOut,
) -> anyhow::Result<()> {
    let encoding = out.encoding();
    if encoding != mts::mesh::io::Encoding::Plain {
        out.check(path)?;
        // Compressed, the writer reorders for its codec, but from the
        // cache order it does better than from the level's own: the
        // bunny's file 208,944 bytes against 210,088.
        let ordered = mts::mesh::io::order_for_cache(mesh);
        mts::mesh::io::save_gltf_as(&ordered, path, encoding)?;
        return Ok(());
    }
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
