//! shadefit: integrals behind real-time shading models, fitted, verified and emitted.
//!
//! Pipeline: spec → integrate → sample → fit → verify → emit. See ARCHITECTURE.md.

pub mod fit;
pub mod integrate;
pub mod family;
pub mod quantity;
pub mod shading;
pub mod bench;
pub mod build;
pub mod cli;
pub mod emit;
pub mod pipeline;
pub mod plot;
pub mod scene;
pub mod spec;
pub mod validate;
