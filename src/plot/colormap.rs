//! Colour maps, as piecewise-linear interpolation between anchor colours.
//!
//! Anchors are taken from matplotlib's tables: viridis (every 16th of its 256 entries, by
//! van der Walt & Smith, CC0) and the reversed ColorBrewer RdBu diverging scheme (Cynthia
//! Brewer, Apache-2.0), so negative values are blue, zero is near-white and positive red.

use plotters::style::RGBColor;

/// (position in [0, 1], r, g, b) with components in [0, 1].
type Anchor = (f64, f64, f64, f64);

/// viridis entries 0, 16, 32, …, 240, 255 (indices / 255 as positions).
const VIRIDIS: [Anchor; 17] = [
    (0.0 / 255.0, 0.267004, 0.004874, 0.329415),
    (16.0 / 255.0, 0.282327, 0.094955, 0.417331),
    (32.0 / 255.0, 0.278826, 0.175490, 0.483397),
    (48.0 / 255.0, 0.258965, 0.251537, 0.524736),
    (64.0 / 255.0, 0.229739, 0.322361, 0.545706),
    (80.0 / 255.0, 0.199430, 0.387607, 0.554642),
    (96.0 / 255.0, 0.172719, 0.448791, 0.557885),
    (112.0 / 255.0, 0.149039, 0.508051, 0.557250),
    (128.0 / 255.0, 0.127568, 0.566949, 0.550556),
    (143.0 / 255.0, 0.120081, 0.622161, 0.534946),
    (159.0 / 255.0, 0.153894, 0.680203, 0.504172),
    (175.0 / 255.0, 0.239374, 0.735588, 0.455688),
    (191.0 / 255.0, 0.360741, 0.785964, 0.387814),
    (207.0 / 255.0, 0.506271, 0.828786, 0.300362),
    (223.0 / 255.0, 0.668054, 0.861999, 0.196293),
    (239.0 / 255.0, 0.835270, 0.886029, 0.102646),
    (1.0, 0.993248, 0.906157, 0.143936),
];

/// ColorBrewer RdBu (11 classes), reversed: dark blue → near-white → dark red.
const RDBU_R: [Anchor; 11] = [
    (0.0, 0.019608, 0.188235, 0.380392),
    (0.1, 0.129412, 0.400000, 0.674510),
    (0.2, 0.262745, 0.576471, 0.764706),
    (0.3, 0.572549, 0.772549, 0.870588),
    (0.4, 0.819608, 0.898039, 0.941176),
    (0.5, 0.968627, 0.968627, 0.968627),
    (0.6, 0.992157, 0.858824, 0.780392),
    (0.7, 0.956863, 0.647059, 0.509804),
    (0.8, 0.839216, 0.376471, 0.301961),
    (0.9, 0.698039, 0.094118, 0.168627),
    (1.0, 0.403922, 0.000000, 0.121569),
];

/// Colour of `t` ∈ [0, 1] (clamped; NaN maps to mid-grey) on viridis or, if `diverging`,
/// on reversed RdBu.
pub(crate) fn color(t: f64, diverging: bool) -> RGBColor {
    if t.is_nan() {
        return RGBColor(160, 160, 160);
    }
    let table: &[Anchor] = if diverging { &RDBU_R } else { &VIRIDIS };
    let t = t.clamp(0.0, 1.0);
    let i = table.partition_point(|a| a.0 <= t).clamp(1, table.len() - 1);
    let (a, b) = (table[i - 1], table[i]);
    let u = ((t - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
    let c = |x: f64, y: f64| ((x + (y - x) * u) * 255.0).round().clamp(0.0, 255.0) as u8;
    RGBColor(c(a.1, b.1), c(a.2, b.2), c(a.3, b.3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_centre() {
        assert_eq!(color(0.0, false), RGBColor(68, 1, 84));
        assert_eq!(color(1.0, false), RGBColor(253, 231, 37));
        assert_eq!(color(0.5, true), RGBColor(247, 247, 247));
        assert_eq!(color(-3.0, true), color(0.0, true));
        assert_eq!(color(3.0, true), color(1.0, true));
    }
}
