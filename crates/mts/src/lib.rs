//! # mts — continuous level of detail with multiresolution triangle strips
//!
//! A mesh is loaded ([`mesh::io`]) or generated ([`mesh::generate`]), cut
//! into generalized triangle strips ([`stripify()`], a STRIPE-style hybrid
//! search) and simplified into one contraction sequence ([`simplify()`]);
//! from both, [`model::build`] makes the multiresolution model
//! ([`MtsModel`]) whose [`Extractor`] emits strips for any LoD, re-walking
//! only the strips that changed. The design (data flow, LoD numbering, the
//! invariant every test leans on, the strip encoding) is `docs/design.md`
//! in the repository; where the code is and why, `ARCHITECTURE.md`. The
//! wgpu renderer is the crate `mts-render`; this crate has no GPU, no CLI
//! and, by default, no C++ peer (feature `peers`:
//! meshoptimizer, and the discrete-LoD baseline made from it) and no glTF
//! (feature `gltf`: [`mesh::io`] reads and writes `.gltf`/`.glb`). The methods
//! MTS is measured against ([`baselines`]: progressive mesh,
//! progressive multilevel mesh, cluster tree with its packet stream,
//! discrete LoDs) and MTS itself share one interface, [`LodSource`].
//!
//! ```
//! use mts::mesh::generate::Generated;
//! use mts::strip::sorted_canonical;
//! use mts::{stripify, StripifyOptions};
//!
//! let mesh: mts::Mesh = "torus:20k".parse::<Generated>()?.build();
//! let strips = stripify(&mesh, &StripifyOptions::default());
//! // The strips draw exactly the mesh's triangles, with their winding...
//! assert_eq!(sorted_canonical(&strips.triangles()), sorted_canonical(&mesh.triangles));
//! // ...for far fewer indices than a triangle list (3 per triangle).
//! assert!(strips.restart_index_count() < mesh.triangle_count() * 11 / 10);
//! let gpu_buffer: Vec<u32> = strips.to_restart_u32();
//! # assert!(!gpu_buffer.is_empty());
//! # Ok::<(), mts::Error>(())
//! ```

pub mod baselines;
pub mod checksum;
pub mod distance;
pub mod encoding;
pub mod error;
pub mod hierarchy;
pub mod lod;
pub mod mesh;
pub mod methods;
pub mod model;
pub mod output;
mod parallel;
#[cfg(feature = "peers")]
pub mod peers;
pub mod screen_error;
pub mod simplify;
pub mod strip;

pub use error::{Error, Invalid, Place, Result};
pub use lod::{LodSource, Topology};
pub use mesh::Mesh;
pub use model::{Extractor, MtsModel};
pub use screen_error::{lod_for_screen_error, lod_for_screen_error_of, Projection};
pub use simplify::{simplify, Collapses, SimplifyOptions};
pub use strip::{stripify, StripifyOptions, Strips};
