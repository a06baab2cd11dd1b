//! The renewal rows of Table 1: the paper's single band, today's bands and
//! strips with their own lifetimes, each replayed over the model's own
//! strips and sequence by `mts::model::lifetimes` (issue 34, item 1;
//! `docs/experiments/strip-lifetimes.md`, step 0f), so the report compares
//! the three models' bytes and indices sent on every input.

use crate::bench::results::{Model, RenewalRow};
use mts::methods::SHARES;
use mts::model::lifetimes::{measure_renewal, Renewal, RenewalMeasure};
use mts::model::{BuildOptions, DEFAULT_BAND_SLACK};
use mts::{Mesh, MtsModel};
use std::fmt::Write;

/// A strips row's neighbourhood: fewest and most triangles.
type Unit = Option<(u32, u32)>;

/// The rows measured: (name, slack, neighbourhood), the default bands
/// second (the reference of every ratio).
const ROWS: [(&str, f64, Unit); 5] = [
    ("single band", f64::INFINITY, None),
    ("bands", DEFAULT_BAND_SLACK, None),
    ("bands", 0.3, None),
    ("strips", DEFAULT_BAND_SLACK, Some((0, 256))),
    ("strips", DEFAULT_BAND_SLACK, Some((64, 1024))),
];

/// The rows of `model` (built from `mesh` with the default options).
pub fn measure(model: &MtsModel, mesh: &Mesh) -> Vec<RenewalRow> {
    let collapses = model.collapses();
    // 100 shares for the ratios, then the report's.
    let hundred: Vec<f64> = (1..=100).rev().map(|p| f64::from(p) / 100.0).collect();
    let lods: Vec<usize> = hundred
        .iter()
        .chain(&SHARES)
        .map(|&r| collapses.lod_for_ratio(r))
        .collect();
    let run = |slack: f64, unit: Unit| {
        let options = BuildOptions {
            band_slack: slack,
            ..model.build_options().clone()
        };
        let renewal = unit.map_or(Renewal::Bands, |(lo, hi)| Renewal::Strips {
            min_triangles: lo,
            max_triangles: hi,
        });
        measure_renewal(
            mesh,
            model.base_strips(),
            collapses,
            &options,
            renewal,
            &lods,
        )
    };
    let measured: Vec<RenewalMeasure> = ROWS.iter().map(|&(_, s, u)| run(s, u)).collect();
    let reference = &measured[1].indices[..hundred.len()];
    ROWS.iter()
        .zip(&measured)
        .map(|(&(name, slack, unit), m)| {
            let ratios: Vec<f64> = m.indices[..hundred.len()]
                .iter()
                .zip(reference)
                .map(|(&a, &b)| a as f64 / b.max(1) as f64)
                .collect();
            RenewalRow {
                renewal: name.to_string(),
                slack: slack.is_finite().then_some(slack),
                unit_triangles: unit.map(|(lo, hi)| [u64::from(lo), u64::from(hi)]),
                strips_born: m.strips as u64,
                renewals: m.renewals as u64,
                records: m.records as u64,
                memory_bytes: m.memory_bytes as u64,
                indices_per_triangle: m.indices[hundred.len()..]
                    .iter()
                    .zip(&m.triangles[hundred.len()..])
                    .map(|(&i, &t)| i as f64 / t.max(1) as f64)
                    .collect(),
                mean_ratio: ratios.iter().sum::<f64>() / ratios.len() as f64,
                worst_ratio: ratios.iter().copied().fold(0.0, f64::max),
                shares_above: ratios.iter().filter(|&&r| r > 1.02).count() as u64,
            }
        })
        .collect()
}

/// The report's table of every model's rows.
pub fn table(s: &mut String, models: &[Model]) {
    let _ = writeln!(s, "Each model's own strips and contraction sequence replayed by one builder (`mts::model::lifetimes`): the paper's single band; bands, every strip stripified afresh where the strips send more than 1 + slack times their indices per triangle at the band's start (0.1 is the model `mts build` makes); strips with their own lifetimes, a strip renewed with its neighbourhood (MIN..MAX triangles) where it alone decays past the slack (`docs/experiments/strip-lifetimes.md`, step 0f). Bytes: records, per-strip and per-beginning tables and positions in one layout for every row (properties not counted). Ratios: indices sent at each of the 100 shares 100%..1% against bands 0.1's.\n");
    let shares: Vec<String> = SHARES.iter().map(|s| format!("{}%", s * 100.0)).collect();
    let _ = writeln!(
        s,
        "| model | renewal | strips born | renewals | records | bytes | bytes / raw | indices / triangle at {} | mean / worst ratio | shares > 2% above |",
        shares.join(" / ")
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for m in models {
        for r in &m.renewal {
            let name = match (r.slack, r.unit_triangles) {
                (None, _) => r.renewal.clone(),
                (Some(slack), None) => format!("{} {slack}", r.renewal),
                (Some(slack), Some([lo, hi])) => format!("{} {slack}, {lo}..{hi}", r.renewal),
            };
            let indices: Vec<String> = r
                .indices_per_triangle
                .iter()
                .map(|i| format!("{i:.3}"))
                .collect();
            let _ = writeln!(
                s,
                "| {} | {name} | {} | {} | {} | {} | {:.2} | {} | {:.3} / {:.3} | {} |",
                m.name,
                r.strips_born,
                r.renewals,
                r.records,
                r.memory_bytes,
                r.memory_bytes as f64 / m.bytes.raw.max(1) as f64,
                indices.join(" / "),
                r.mean_ratio,
                r.worst_ratio,
                r.shares_above,
            );
        }
    }
}
