//! Operation counts of WGSL functions from naga's IR.

use serde::Serialize;

/// Operation counts of one function, inclusive of its callees.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct OpCounts {
    pub add: usize,
    pub mul: usize,
    pub div: usize,
    pub transc: usize,
    pub tex: usize,
    pub const_loads: usize,
    pub other: usize,
}
