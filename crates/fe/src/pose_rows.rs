//! A run's current result as the checks compare it ([`Run`], [`PoseRows`]): the types the
//! campaign's readers (`campaign::runs`) return and the mesh study (`mesh::study`) and
//! the verification compare, apart from the campaign so that the mesh study needs no
//! campaign code (it is handed a runner).

use crate::manifest::ManifestEntry;
use crate::results::Row;
use std::collections::BTreeMap;

/// A current result: its rows and how it was made.
#[derive(Debug, Clone)]
pub struct Run {
    /// The CSV's rows, depth 0 first.
    pub rows: Vec<Row>,
    /// Its manifest entry.
    pub entry: ManifestEntry,
}

/// Each selected pose's result, or why there is none (the run failed, or the result is
/// not current for this spec).
pub type PoseRows = BTreeMap<String, std::result::Result<Run, String>>;

/// The depths of `a` and `b` agree row by row (the same must points).
pub fn same_depths(a: &[Row], b: &[Row]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x.depth_mm - y.depth_mm).abs() <= 1e-9 * (1.0 + x.depth_mm.abs()))
}
