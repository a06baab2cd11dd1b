//! The methods MTS is measured against, over the same inputs and the same
//! LoD numbering, each behind [`crate::lod::LodSource`]:
//!
//! - [`pm`]: progressive mesh (Hoppe 1996), base mesh and vertex splits on a
//!   maintained triangle list;
//! - [`multilevel`]: progressive multilevel mesh, level-sorted arrays and a
//!   pc-rep array rebuilt per LoD change, geomorphs;
//! - `discrete` (feature `peers`): meshoptimizer's `simplify` at fixed
//!   ratios, what users do today;
//! - [`cluster`]: the cluster tree and its incrementally decodable packet
//!   stream.

mod bits;
pub mod cluster;
#[cfg(feature = "peers")]
pub mod discrete;
mod levels;
pub mod multilevel;
pub mod pm;
mod props;

pub use cluster::ClusterTree;
#[cfg(feature = "peers")]
pub use discrete::DiscreteLods;
pub use multilevel::MultilevelMesh;
pub use pm::ProgressiveMesh;
