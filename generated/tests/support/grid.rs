//! Test inputs for the emitted functions, as f32 bit patterns (so NaNs, infinities, −0 and
//! subnormals travel unchanged into a shader, which reads them with `bitcast<f32>`).

use shadefit_runtime::{Cpu, EmittedFunction};

fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f32::from_bits(1);
    }
    let b = x.to_bits();
    f32::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// Special inputs for an argument with domain [lo, hi]: the domain edges and their
/// neighbours on both sides, values well outside, ±0, subnormals, ±MIN_POSITIVE, ±1, ±MAX,
/// ±inf and several NaNs (quiet, negative, signalling-pattern, all-ones payload).
pub fn specials(lo: f32, hi: f32) -> Vec<u32> {
    let mut v: Vec<u32> = [
        lo,
        hi,
        next_down(lo),
        next_up(lo),
        next_down(hi),
        next_up(hi),
        lo - 1.0,
        hi + 1.0,
        lo - 0.25 * (hi - lo),
        hi + 0.25 * (hi - lo),
        0.5 * (lo + hi),
        0.0,
        -0.0,
        f32::from_bits(1),
        -f32::from_bits(1),
        f32::from_bits(0x007f_ffff),
        -f32::from_bits(0x007f_ffff),
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        1.0,
        -1.0,
        next_down(1.0),
        next_up(1.0),
        f32::EPSILON,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ]
    .iter()
    .map(|x| x.to_bits())
    .collect();
    v.extend([0x7fc0_0000, 0xffc0_0000, 0x7f80_0001, 0xff80_0001, 0x7fff_ffff, 0xffff_ffff]);
    v
}

/// Values along one argument: the specials, `dense` evenly spaced points over [lo, hi], and
/// `nodes` + 1 evenly spaced points with their midpoints (table nodes and cell centres when
/// `nodes` is a table's cell count).
pub fn axis(lo: f32, hi: f32, dense: usize, nodes: usize) -> Vec<u32> {
    let mut v = specials(lo, hi);
    let at = |t: f64| (lo as f64 + (hi as f64 - lo as f64) * t) as f32;
    v.extend((0..dense).map(|i| at(i as f64 / (dense - 1) as f64).to_bits()));
    v.extend((0..=2 * nodes).map(|i| at(i as f64 / (2 * nodes) as f64).to_bits()));
    v.sort_unstable();
    v.dedup();
    v
}

/// All points of a function, flattened (arity words per point): the Cartesian product of its
/// axes. One-argument functions get 2^16 dense values, two-argument ones 256 per axis, and
/// three-argument ones 16 per axis with at most 8 node intervals (~60 values per axis with the
/// specials, ~2e5 points: 256 per axis would be 825 MB of inputs, over a device's 256 MiB
/// buffer limit, and more workgroups than one dispatch dimension allows).
pub fn points(f: &EmittedFunction, nodes: &[u32]) -> Vec<u32> {
    let three = f.domain.len() >= 3;
    let dense = match f.domain.len() {
        1 => 1 << 16,
        2 => 256,
        _ => 16,
    };
    let axes: Vec<Vec<u32>> = f
        .domain
        .iter()
        .enumerate()
        .map(|(k, [lo, hi])| {
            let n = nodes.get(k).map_or(64, |&n| n as usize - 1);
            axis(*lo, *hi, dense, if three { n.min(8) } else { n })
        })
        .collect();
    let mut out = Vec::new();
    match axes.as_slice() {
        [a] => out.extend(a),
        [a, b] => {
            for &y in b {
                for &x in a {
                    out.extend([x, y]);
                }
            }
        }
        [a, b, c] => {
            for &z in c {
                for &y in b {
                    for &x in a {
                        out.extend([x, y, z]);
                    }
                }
            }
        }
        _ => panic!("{}: arity {} not supported", f.name, f.domain.len()),
    }
    out
}

/// The CPU version at one point.
pub fn cpu(f: &EmittedFunction, p: &[u32]) -> f32 {
    let x = |i: usize| f32::from_bits(p[i]);
    match f.cpu {
        Cpu::One(g) => g(x(0)),
        Cpu::Two(g) => g(x(0), x(1)),
        Cpu::Three(g) => g(x(0), x(1), x(2)),
    }
}

/// A point for messages: `f(a, b)` with bit patterns for the odd values.
pub fn show(f: &EmittedFunction, p: &[u32]) -> String {
    let args: Vec<String> = p
        .iter()
        .map(|&b| {
            let x = f32::from_bits(b);
            if x.is_nan() || (x != 0.0 && x.abs() < f32::MIN_POSITIVE) { format!("{x:e} [0x{b:08x}]") } else { format!("{x:e}") }
        })
        .collect();
    format!("{}({})", f.name, args.join(", "))
}
