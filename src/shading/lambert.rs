//! Lambert's lobe, f = 1/π (unit albedo), in the default cosine measure: a lobe is its BRDF.

use super::lobe::Lobe;
use std::f64::consts::PI;

/// The Lambertian lobe of unit albedo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambert;

impl Lobe for Lambert {
    type View = ();

    fn view(&self, _mu_v: f64) {}

    fn eval(&self, _view: &(), _vh: f64, _ch: f64, _mu_l: f64) -> f64 {
        1.0 / PI
    }
}
