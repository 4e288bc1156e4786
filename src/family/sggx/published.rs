//! The course's comparisons, measured.

use crate::validate::Item;
use std::path::Path;

pub fn items(_generated: &Path) -> Vec<Item> {
    vec![]
}
