//! shadefit-runtime: shading approximations and lookup tables emitted by shadefit.
//!
//! Each emitted module holds the f32 coefficients (or table) of one fit and a CPU version of
//! its WGSL function; [`wgsl::module`] returns the WGSL library of the same name. Everything
//! but this file, `Cargo.toml` and `tests/` is written by `shadefit build`.

#![allow(clippy::excessive_precision, clippy::approx_constant)]

include!("emitted.rs");
