//! Every level-of-detail method of the crate by name, and the one factory
//! that makes its [`LodSource`] over a model's mesh and contraction
//! sequence: what `mts extract --method`, `mts compare`, the bench, the
//! criterion benches and the tests all use, so that no list of methods is
//! written twice.
//!
//! Above [`crate::model`] and [`crate::baselines`] (it builds both), below
//! nothing.

use crate::baselines::{ClusterTree, MultilevelMesh, ProgressiveMesh};
use crate::error::Result;
use crate::lod::LodSource;
use crate::mesh::Mesh;
use crate::model::{Extractor, MtsModel};

/// The shares of the full triangle count the report measures at (Tables
/// 3–4, Figure 6) and the discrete baseline keeps.
pub const SHARES: [f64; 6] = [1.0, 0.5, 0.25, 0.1, 0.05, 0.01];

/// A level-of-detail method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Multiresolution triangle strips ([`Extractor`]).
    Mts,
    /// Progressive mesh (Hoppe 1996).
    Pm,
    /// Progressive multilevel mesh.
    Multilevel,
    /// Cluster tree (its own clustering: its LoD `k` is not MTS's).
    Cluster,
    /// meshoptimizer's simplify at [`SHARES`] (feature `peers`).
    #[cfg(feature = "peers")]
    Discrete,
}

impl Method {
    /// Every method, MTS first, in the order the report lists them.
    pub const ALL: &'static [Method] = &[
        Method::Mts,
        Method::Pm,
        Method::Multilevel,
        Method::Cluster,
        #[cfg(feature = "peers")]
        Method::Discrete,
    ];

    /// The name its source reports ([`LodSource::name`]) and the report
    /// uses.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Mts => "mts",
            Method::Pm => "pm",
            Method::Multilevel => "multilevel",
            Method::Cluster => "cluster",
            #[cfg(feature = "peers")]
            Method::Discrete => "discrete",
        }
    }

    /// The source of this method over `model`'s mesh `mesh` and its
    /// contraction sequence.
    ///
    /// # Errors
    /// What the baseline's constructor returns; for the discrete LoDs, an
    /// [`crate::Error::InvalidArgument`] when meshoptimizer would take quadratic
    /// time on `mesh` (`peers::meshopt::refusal`, feature `peers`).
    ///
    /// Cost: the method's construction (MTS: O(strips)).
    pub fn source<'m>(self, model: &'m MtsModel, mesh: &Mesh) -> Result<Box<dyn LodSource + 'm>> {
        let c = model.collapses();
        Ok(match self {
            Method::Mts => Box::new(Extractor::new(model)),
            Method::Pm => Box::new(ProgressiveMesh::new(mesh, c)?),
            Method::Multilevel => Box::new(MultilevelMesh::new(mesh, c)?),
            Method::Cluster => Box::new(ClusterTree::new(mesh)?),
            #[cfg(feature = "peers")]
            Method::Discrete => {
                if let Some(why) = crate::peers::meshopt::refusal(mesh) {
                    return Err(crate::Error::InvalidArgument(format!(
                        "the discrete LoDs are meshoptimizer's simplify: {why}"
                    )));
                }
                Box::new(crate::baselines::DiscreteLods::new(
                    mesh,
                    c.triangle_counts(),
                ))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each source names itself as its method does, and starts at the full
    /// mesh.
    #[test]
    fn every_method_builds_and_names_itself() {
        let mesh: Mesh = "torus:500"
            .parse::<crate::mesh::generate::Generated>()
            .unwrap()
            .build();
        let (model, _, _) =
            crate::model::build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
        for &m in Method::ALL {
            let mut source = m.source(&model, &mesh).unwrap();
            assert_eq!(source.name(), m.name());
            source.set_lod(0);
            assert_eq!(
                source.triangle_count(0),
                mesh.triangle_count(),
                "{}",
                m.name()
            );
        }
    }
}
