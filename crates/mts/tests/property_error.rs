//! Property error on real models: zero against itself, seams and touching
//! parts included; nonzero and bounded for a LoD; and (with `peers`)
//! meshoptimizer's attribute-aware simplification wired as documented.

mod common;

use mts::distance::property_error;
use mts::{simplify, SimplifyOptions};

#[test]
fn a_model_against_itself_measures_zero() {
    // spot has UV seams; pirate has UV and normal seams and 217 positions
    // repeated by separate `v` lines where parts touch.
    for name in ["spot.obj", "pirate.obj"] {
        let Some(mesh) = common::model_with_properties(name) else {
            return;
        };
        let e = property_error(&mesh, &mesh.clone(), 20_000);
        let uv = e.uv.unwrap();
        assert!(uv.max < 1e-6, "{name}: {uv:?}");
        if let Some(n) = e.normal_degrees {
            // Normals interpolated with f32 weights: a few thousandths of
            // a degree where neighbouring normals differ a lot.
            assert!(n.max < 0.01, "{name}: {n:?}");
        }
        assert_eq!(e.color, None);
    }
}

#[test]
fn a_coarse_lod_of_spot_has_bounded_uv_error() {
    let Some(mesh) = common::model_with_properties("spot.obj") else {
        return;
    };
    let c = simplify(&mesh, &SimplifyOptions::default()).collapses;
    let at = |share: f64| {
        let lod = c.mesh_at(&mesh, c.lod_for_ratio(share));
        property_error(&mesh, &lod, 50_000).uv.unwrap()
    };
    let (fine, coarse) = (at(0.1), at(0.01));
    // spot's UVs lie in the unit square: no error beyond its diagonal.
    for s in [fine, coarse] {
        assert!(
            s.rms > 0.0 && s.rms < s.max && s.max <= 2f64.sqrt(),
            "{s:?}"
        );
    }
    // A few hundredths of the texture at 10%, a few tenths at 1% (58
    // triangles), where samples across moved seams dominate.
    assert!(fine.rms > 0.01 && fine.rms < 0.05, "{fine:?}");
    assert!(coarse.rms > fine.rms && coarse.rms < 0.3, "{coarse:?}");
}

#[cfg(feature = "peers")]
mod peers {
    use super::*;
    use mts::peers::meshopt::{
        simplify, simplify_with_attributes, simplify_with_attributes_to_lod, MESHOPT_WEIGHTS,
    };

    #[test]
    fn without_properties_it_is_plain_simplify() {
        let Some(mesh) = common::model("bunny_res3.ply") else {
            return;
        };
        let target = mesh.triangle_count() / 10;
        assert_eq!(
            simplify_with_attributes(&mesh, target, MESHOPT_WEIGHTS),
            simplify(&mesh, target)
        );
    }

    #[test]
    fn uv_weights_lower_meshoptimizer_uv_error_on_spot() {
        let Some(mesh) = common::model_with_properties("spot.obj") else {
            return;
        };
        let c = super::simplify(&mesh, &SimplifyOptions::default()).collapses;
        let lod = c.lod_for_ratio(0.1);
        let uv_rms = |uv: f32| {
            let weights = mts::simplify::AttributeWeights {
                uv,
                ..MESHOPT_WEIGHTS
            };
            let (theirs, at) = simplify_with_attributes_to_lod(&mesh, &c, lod, weights);
            // The LoD to compare with has at most their count.
            assert!(c.triangle_count(at) <= theirs.len().max(c.triangle_count(lod)));
            let theirs = mts::mesh::Mesh {
                triangles: theirs,
                ..mesh.clone()
            };
            property_error(&mesh, &theirs, 50_000).uv.unwrap().rms
        };
        let (blind, weighted) = (uv_rms(0.0), uv_rms(MESHOPT_WEIGHTS.uv));
        assert!(weighted < 0.9 * blind, "{weighted} against {blind}");
    }
}
