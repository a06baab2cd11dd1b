//! Every method over one mesh and contraction sequence: bytes, build and
//! load time, microseconds per LoD change (`mts compare`, Table 2).

use crate::bench::results::MethodRow;
use crate::timing::median_ms;
use anyhow::Result;
use mts::mesh::Mesh;
use mts::methods::Method;
use mts::peers;
use std::collections::BTreeMap;
use std::time::Instant;

/// Every method (MTS and the baselines) over the same mesh and contraction
/// sequence, measured in one run: build milliseconds (MTS: `mts_ms`, the
/// whole pipeline; the baselines: their own construction from the mesh and
/// MTS's sequence), bytes in memory and on disk, and microseconds per LoD
/// change over the Table 2 sequences of `requests` requests each.
pub fn measure_methods(
    model: &mts::MtsModel,
    mesh: &Mesh,
    mts_ms: f64,
    requests: usize,
    mts_file: &[u8],
) -> Result<Vec<MethodRow>> {
    use mts::model::requests;
    let raw = crate::commands::encode::raw_bytes_u16(mesh);
    let mut rows = Vec::new();
    for &method in Method::ALL {
        if method == Method::Discrete {
            if let Some(why) = peers::meshopt::refusal(mesh) {
                rows.push(MethodRow::Skipped {
                    method: "discrete".into(),
                    skipped: why,
                });
                continue;
            }
        }
        let t = Instant::now();
        let mut source = method.source(model, mesh)?;
        // The baselines start from the contraction sequence MTS recorded;
        // its time is MTS's simplify stage, counted in MTS's build.
        let build_ms =
            t.elapsed().as_secs_f64() * 1e3 + if method == Method::Mts { mts_ms } else { 0.0 };
        let max_lod = source.max_lod();
        let counts: Vec<u32> = (0..=max_lod)
            .map(|l| source.triangle_count(l) as u32)
            .collect();
        let sequences = requests::table2(&counts, requests);
        let mut us = BTreeMap::new();
        for (label, lods) in &sequences {
            source.set_lod(max_lod);
            let t = Instant::now();
            for &l in lods {
                source.set_lod(l);
            }
            let per = t.elapsed().as_secs_f64() * 1e6 / lods.len().max(1) as f64;
            us.insert((*label).to_string(), per);
        }
        // MTS from scratch: the same requests, every strip walked each time.
        let scratch = (method == Method::Mts).then(|| {
            let mut ex = mts::Extractor::new(model);
            sequences
                .iter()
                .map(|(label, lods)| {
                    ex.set_lod_from_scratch(max_lod);
                    let t = Instant::now();
                    for &l in lods {
                        ex.set_lod_from_scratch(l);
                    }
                    let per = t.elapsed().as_secs_f64() * 1e6 / lods.len().max(1) as f64;
                    ((*label).to_string(), per)
                })
                .collect::<BTreeMap<_, _>>()
        });
        // MTS's file is the one the caller coded (about a second to code
        // again); the others serialize here.
        let file = if method == Method::Mts {
            mts_file.len()
        } else {
            source.file_bytes()
        };
        let load_ms = load_ms_of(method, model, mesh, mts_file)?;
        rows.push(MethodRow::Measured(crate::bench::results::Method {
            method: source.name().to_string(),
            build_ms,
            memory_bytes: source.memory_bytes() as u64,
            file_bytes: file as u64,
            file_ratio_to_raw_u16: file as f64 / raw as f64,
            load_ms,
            us_per_change: us,
            us_per_change_scratch: scratch,
        }));
    }
    Ok(rows)
}

/// Median milliseconds (of 5) from a method's file bytes in memory to a
/// source ready for its first LoD: MTS decodes, parses and validates its
/// ready `.mts` (the coded file `mts build` writes) and makes an extractor; the progressive mesh parses its file; the
/// cluster tree decodes its whole packet stream (its receiver). `None` for
/// the methods without a file reader (multilevel, discrete LoDs).
/// `mts_file`: MTS's file bytes.
fn load_ms_of(
    method: Method,
    model: &mts::MtsModel,
    mesh: &Mesh,
    mts_file: &[u8],
) -> Result<Option<f64>> {
    use mts::baselines::{cluster, ClusterTree, ProgressiveMesh};
    // Median of 5 loads of the same bytes (so an error is every run's).
    let timed = |mut load: Box<dyn FnMut() -> mts::Result<()> + '_>| -> Result<Option<f64>> {
        let (results, ms) = median_ms(5, &mut load);
        results?;
        Ok(Some(ms))
    };
    match method {
        Method::Mts => timed(Box::new(move || {
            let m = mts::MtsModel::from_bytes(mts_file, std::path::Path::new("model.mts"))?;
            std::hint::black_box(mts::Extractor::new(&m).buffer().len());
            Ok(())
        })),
        Method::Pm => {
            let bytes = ProgressiveMesh::new(mesh, model.collapses())?.to_bytes();
            timed(Box::new(move || {
                ProgressiveMesh::from_bytes(&bytes, "model.pm").map(drop)
            }))
        }
        Method::Cluster => {
            let bytes = ClusterTree::new(mesh)?.to_stream();
            timed(Box::new(move || {
                cluster::stream::decode(&bytes, "model.stream").map(drop)
            }))
        }
        Method::Multilevel | Method::Discrete => Ok(None),
    }
}
