//! mts: continuous level of detail with multiresolution triangle strips.

pub mod error;
pub mod mesh;
pub mod peers;

pub use error::{Error, Place, Result};
pub use mesh::Mesh;
pub mod strip;

pub use strip::{stripify, Strips, StripifyOptions};
