//! The bench: what `mts bench` measures ([`measure`], [`methods`],
//! [`figure6`], [`scene`], [`vertex_work`], [`view_dependent`]; `mts bench
//! render` in [`render`], `mts bench view-dependent` in
//! [`view_dependent`]), the typed results it writes
//! ([`results`]), and what is made from them alone: `report.md`
//! ([`report`], [`charts`]), the README's section ([`summary`]) and the
//! invariants CI holds a run to ([`check`]).
//!
//! Imports go one way, so that no two files import each other: `results`
//! imports none of the others; `charts` and `check` only `results`;
//! `report` `results`, `charts` and the constants of `measure` and
//! `view_dependent`; `summary` `report` and `charts`; the measuring files
//! (`measure`, `methods`, `figure6`, `scene`, `vertex_work`) `results` and
//! each other, never the Markdown; `render` (the `bench render` command)
//! the measuring and `report`; `view_dependent` (`mts bench
//! view-dependent`, and the report's flights through `measure`) only
//! `results`.

pub mod charts;
pub mod check;
pub mod figure6;
pub mod measure;
pub mod methods;
pub mod render;
pub mod render_hierarchy;
pub mod renewal;
pub mod report;
pub mod results;
pub mod scene;
pub mod summary;
pub mod vertex_work;
pub mod view_dependent;
