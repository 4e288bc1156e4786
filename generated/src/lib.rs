//! shadefit-runtime: shading approximations and lookup tables emitted by shadefit.
//!
//! Each emitted module holds the f32 coefficients (or table) of one fit and a CPU version of
//! its WGSL function; [`wgsl::module`] returns the WGSL library of the same name and
//! [`FUNCTIONS`] lists every emitted function. Everything but this file, `Cargo.toml`,
//! `tests/`, `examples/` and the folders under `src/` is written by `shadefit build`.
//!
//! Hand-written runtime (in `src/runtime/`):
//! - [`compose`] / [`compose_shader`]: concatenate WGSL libraries, resolving
//!   `#import shadefit::NAME` lines and naga_oil's forms (`NAME::item` calls, item imports,
//!   aliases; no dependencies, always available);
//! - [`lut`]: the lookup-table modules as R32Float textures and WGSL accessors for them
//!   (texture creation needs the `gpu` feature, which brings in wgpu);
//! - `gpu` (feature `gpu`): a headless wgpu adapter and device chosen from the environment
//!   (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`);
//! - [`skin`]: the directional curvature the skin LUTs take (Rust, and the WGSL library
//!   `shadefit::skin_curvature`), and the skin LUTs' KTX2 textures (upload with `gpu`).

#![allow(clippy::excessive_precision, clippy::approx_constant)]

/// CPU version of an emitted function, by arity.
#[derive(Clone, Copy)]
pub enum Cpu {
    One(fn(f32) -> f32),
    Two(fn(f32, f32) -> f32),
    Three(fn(f32, f32, f32) -> f32),
}

/// One emitted function: its module (WGSL import path `shadefit::MODULE`), its name in WGSL
/// and Rust, the domain its arguments are clamped to, and its CPU version.
#[derive(Clone, Copy)]
pub struct EmittedFunction {
    pub module: &'static str,
    pub name: &'static str,
    pub domain: &'static [[f32; 2]],
    pub cpu: Cpu,
}

mod runtime;

pub use runtime::compose::{ComposeError, compose, compose_shader, compose_shader_named};
#[cfg(feature = "gpu")]
pub use runtime::gpu;
pub use runtime::lut;
pub use runtime::skin;

include!("emitted.rs");
