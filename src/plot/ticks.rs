//! Axis ticks and their labels, computed here rather than by plotters so that the labels of
//! small quantities (errors of 1e-4) read well and log axes show decades.

/// Tick positions on one axis, with the formatting shared by all of them.
#[derive(Clone, Debug)]
pub struct Ticks {
    /// Positions in axis coordinates (log10 of the value on a log axis).
    pub values: Vec<f64>,
    /// Unlabelled minor positions (2×…9× each decade on a log axis of at most 6 decades).
    pub minor: Vec<f64>,
    /// Spacing of a linear axis (drives the number of decimals); unused on a log axis.
    step: f64,
    /// Largest |tick| of a linear axis, which picks fixed or scientific notation.
    magnitude: f64,
    log: bool,
}

/// At most `target` + 1 round ticks inside [lo, hi], as many as that allows.
pub fn linear(lo: f64, hi: f64, target: usize) -> Ticks {
    // The smallest step of 1, 2 or 5 times a power of ten giving at most target + 1 ticks.
    let count = |step: f64| (hi / step + 1e-9).floor() - (lo / step - 1e-9).ceil() + 1.0;
    let mut p = 10f64.powf(((hi - lo) / target.max(2) as f64).log10().floor() - 1.0);
    let step = 'search: loop {
        for m in [1.0, 2.0, 5.0] {
            if count(m * p) <= (target + 1) as f64 {
                break 'search m * p;
            }
        }
        p *= 10.0;
    };
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let values: Vec<f64> = (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < step * 1e-9 { 0.0 } else { v }
        })
        .collect();
    let magnitude = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    Ticks { values, minor: Vec::new(), step, magnitude, log: false }
}

/// Ticks of a log10 axis spanning the integer exponents [lo_exp, hi_exp]: every decade
/// (every other one past 8 decades), plus 2× and 5× when the axis spans at most 2 decades.
pub fn log_decades(lo_exp: i32, hi_exp: i32) -> Ticks {
    let every = if hi_exp - lo_exp > 8 { 2 } else { 1 };
    let mut values = Vec::new();
    for e in lo_exp..=hi_exp {
        if (e - lo_exp) % every == 0 {
            values.push(e as f64);
        }
        if hi_exp - lo_exp <= 2 && e < hi_exp {
            values.push(e as f64 + 2f64.log10());
            values.push(e as f64 + 5f64.log10());
        }
    }
    let minor = if hi_exp - lo_exp <= 6 {
        (lo_exp..hi_exp).flat_map(|e| (2..10).map(move |m| e as f64 + (m as f64).log10())).collect()
    } else {
        Vec::new()
    };
    Ticks { values, minor, step: 1.0, magnitude: 1.0, log: true }
}

impl Ticks {
    /// Label of the tick at `v` (axis coordinates).
    pub fn label(&self, v: f64) -> String {
        if self.log {
            let e = v.floor();
            let mantissa = 10f64.powf(v - e).round() as i64;
            return if mantissa == 1 { format!("1e{}", e as i32) } else { format!("{mantissa}e{}", e as i32) };
        }
        if v.abs() < self.step * 1e-6 {
            return "0".to_string();
        }
        let decimals = |step: f64| (-step.log10() - 1e-9).ceil().max(0.0) as usize;
        if self.magnitude >= 1e-2 && self.magnitude < 1e5 {
            format!("{:.*}", decimals(self.step), v)
        } else {
            // Each label with its own exponent, mantissa digits down to the step, trailing
            // zeros dropped: 1e-3, 5e-4, 1.2e-3.
            let e = (v.abs() * (1.0 + 1e-9)).log10().floor();
            let scale = 10f64.powf(e);
            let m = format!("{:.*}", decimals(self.step / scale), v / scale);
            let m = if m.contains('.') { m.trim_end_matches('0').trim_end_matches('.').to_string() } else { m };
            format!("{m}e{}", e as i32)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_and_labels() {
        let t = linear(0.0, 1.0, 5);
        assert_eq!(t.values.len(), 6);
        assert_eq!(t.label(t.values[1]), "0.2");
        let t = linear(-3.2e-4, 2.9e-4, 6);
        let labels: Vec<String> = t.values.iter().map(|&v| t.label(v)).collect();
        assert_eq!(labels, ["-3e-4", "-2e-4", "-1e-4", "0", "1e-4", "2e-4"]);
        let t = linear(-1e-3, 1e-3, 8);
        let labels: Vec<String> = t.values.iter().map(|&v| t.label(v)).collect();
        assert_eq!(labels, ["-1e-3", "-5e-4", "0", "5e-4", "1e-3"]);
        let t = linear(0.0, 1.2e-3, 12);
        assert_eq!(t.label(t.values[10]), "1e-3");
        assert_eq!(t.label(t.values[11]), "1.1e-3");
        let t = linear(0.66, 1.0, 6);
        assert_eq!(t.label(t.values[0]), "0.70");
    }

    #[test]
    fn log_ticks() {
        let t = log_decades(-5, -3);
        let labels: Vec<String> = t.values.iter().map(|&v| t.label(v)).collect();
        assert_eq!(labels, ["1e-5", "2e-5", "5e-5", "1e-4", "2e-4", "5e-4", "1e-3"]);
    }
}
