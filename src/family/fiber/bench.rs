use crate::bench::FamilyBench;
pub const BENCH: FamilyBench = FamilyBench::NONE;
