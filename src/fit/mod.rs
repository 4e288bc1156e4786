//! Fitting: model forms (`model`) and their expression trees (`expr`, evaluated in f32 here and
//! rendered by `emit`), the problem on data (`problem`), solvers (`solve`),
//! reports (`report`), the denominator positivity proof (`positivity`) and the f32 coefficients
//! of emitted code (`f32round`).

pub mod expr;
pub mod f32round;
pub mod fields;
pub mod minimax;
pub mod model;
pub mod positivity;
pub mod problem;
pub mod published;
pub mod report;
pub mod simplex;
pub mod solve;

pub use model::{Pin, RationalModel, Term};
pub use problem::Data;
pub use report::FitReport;
pub use solve::{fit, fit_rescaled, Fit, FitError, FitOptions, LsqSolver, Objective};
