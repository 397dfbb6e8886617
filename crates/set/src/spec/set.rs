//! `[set]`: the set's name and description.

use serde::{Deserialize, Serialize};

/// `[set]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetInfo {
    /// Short name.
    pub name: String,
    /// One line on what the set is.
    pub description: String,
}
