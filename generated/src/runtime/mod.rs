//! Hand-written runtime of the crate: WGSL composition, lookup-table textures, headless wgpu,
//! skin curvature. (Files in this folder are never touched by `shadefit build`.)

pub mod compose;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod lut;
pub mod skin;

/// Hand-written WGSL libraries (`#import shadefit::NAME` like the emitted ones).
pub fn library(name: &str) -> Option<&'static str> {
    match name {
        "skin_curvature" => Some(skin::CURVATURE_WGSL),
        _ => None,
    }
}
