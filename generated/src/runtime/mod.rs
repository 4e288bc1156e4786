//! Hand-written runtime of the crate: WGSL composition, lookup-table textures, headless wgpu.
//! (Files in this folder are never touched by `shadefit build`.)

pub mod compose;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod lut;
