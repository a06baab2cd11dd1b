//! Other people's implementations that `mts` is measured against.

pub mod clusterlod;
pub mod meshopt;
pub mod quality;
