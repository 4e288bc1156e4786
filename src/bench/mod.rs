//! `shadefit bench`: run time against error, for the integrators, the fits, the default tables
//! (side by side with a straightforward numpy/scipy implementation of the same integrals) and
//! the shader forms a user picks from.
//!
//! - [`integrals`]: every integrator, method × tolerance (or resolution) → wall time,
//!   integrand evaluations and max error against a converged reference.
//! - [`fits`]: every fit solver × objective → time, iterations, max and rms error.
//! - [`tables`]: each default table, shadefit against `benches/numpy_tables.py` at equal max
//!   error, with the speed ratio.
//! - [`forms`]: shader cost (op counts from naga's IR, [`ops`]) against max error, several
//!   approximation forms per quantity.
//!
//! Quick mode (`--quick`, what the test command runs) uses fewer points and settings; both
//! modes print one table per section, or one JSON document with `--json`.

pub mod forms;
pub mod ops;
