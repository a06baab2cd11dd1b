//! mts: continuous level of detail with multiresolution triangle strips.

pub mod error;
pub mod mesh;

pub use error::{Error, Place, Result};
pub use mesh::Mesh;
