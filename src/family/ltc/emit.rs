//! The light functions of an LTC table, in WGSL and as their f32 CPU twin in Rust.
//!
//! They take the texels a shader samples (ltc_1, ltc_2 at `PREFIX_uv`) as arguments, so the
//! same functions serve a texture, a storage buffer or a constant: `PREFIX_polygon` (a convex
//! polygon of up to 8 vertices, clipped to the horizon in the cosine space, Lambert's edge
//! sum), `PREFIX_rect` (a rectangle by centre and half edges, through the polygon),
//! `PREFIX_rect_sphere` (ltc_code's sphere path: the unclipped vector form factor F, then
//! |F|·w(F_z/|F|, |F|) with w = `PREFIX_sphere_clip`, the closed form of ltc_2.w), and
//! `PREFIX_scale` (F0·E + (1 − F0)·Fresnel term: ltc_code's specular colour of the integral).
//!
//! Orientation: a one-sided light shines on p when its vertices wind counter-clockwise about
//! the direction from p to the light (right-hand rule; for a rectangle, half_x × half_y points
//! away from p); two-sided lights shine both ways. Every input is sanitised (NaN and ±inf
//! become 0; directions are scaled before they are normalised, so no product overflows), and
//! every result is finite and in [0, 1] (the scale in [0, max(E, Fresnel)]).

use crate::emit::f32_literal;
use std::f64::consts::PI;

/// (WGSL module, Rust module) of table `name` (n texels a side), functions prefixed `p`.
pub fn module(name: &str, p: &str, n: usize, header: &[String]) -> (String, String) {
    let up = name.to_uppercase();
    let scale = f32_literal(((n - 1) as f64 / n as f64) as f32);
    let bias = f32_literal((0.5 / n as f64) as f32);
    let inv_2pi = f32_literal((0.5 / PI) as f32);
    let pi = f32_literal(PI as f32);
    let doc = [
        format!("LTC area lights: {n}x{n} tables ltc_1 (M^-1: a, c, b, d) and ltc_2 (E, Fresnel term, 0, clipped sphere form factor) in data/{name}_*.ktx2;"),
        format!("sample both at {p}_uv(roughness, n.v) (linear, clamp to edge), pass the texels to {p}_rect / {p}_polygon, multiply by {p}_scale(ltc_2, f0)."),
        "A one-sided light shines where its vertices wind counter-clockwise about the direction from p to the light.".to_string(),
    ];
    let mut w = String::new();
    for line in header {
        w.push_str(&format!("// {line}\n"));
    }
    w.push_str(&format!("#define_import_path shadefit::{name}\n\n"));
    for line in &doc {
        w.push_str(&format!("// {line}\n"));
    }
    w.push_str(&format!(
        r#"
const {up}_SIZE: u32 = {n}u;

// x, or 0 where x is NaN or ±inf.
fn {p}_finite(x: f32) -> f32 {{
    let bad = (bitcast<u32>(x) & 0x7fffffffu) >= 0x7f800000u;
    return select(x, 0f, bad);
}}

// The same per component (no emitted name ends in a digit: naga's other backends would rename it).
fn {p}_finite_vec(x: vec3<f32>) -> vec3<f32> {{
    return vec3<f32>({p}_finite(x.x), {p}_finite(x.y), {p}_finite(x.z));
}}

// The unit vector along x, scaled by its largest component first; 0 for a zero or non-finite x.
fn {p}_direction(x: vec3<f32>) -> vec3<f32> {{
    let y = {p}_finite_vec(x);
    let m = max(max(abs(y.x), abs(y.y)), abs(y.z));
    if !(m > 0f) {{
        return vec3<f32>(0f);
    }}
    let s = y / m;
    return s * inverseSqrt(dot(s, s));
}}

// Texture coordinates of (roughness, n·v) in the tables (texel nodes at i/(n - 1)).
fn {p}_uv(roughness: f32, n_dot_v: f32) -> vec2<f32> {{
    let r = clamp({p}_finite(roughness), 0f, 1f);
    let x = sqrt(1f - clamp({p}_finite(n_dot_v), 0f, 1f));
    return vec2<f32>(r, x) * {scale} + vec2<f32>({bias});
}}

// M^-1 of an ltc_1 texel applied to a direction in the frame of normal n and view v.
fn {p}_to_cosine(ltc_1: vec4<f32>, n: vec3<f32>, v: vec3<f32>, x: vec3<f32>) -> vec3<f32> {{
    var nn = {p}_direction(n);
    if dot(nn, nn) == 0f {{
        nn = vec3<f32>(0f, 0f, 1f);
    }}
    let vv = {p}_direction(v);
    var t = {p}_direction(vv - nn * dot(vv, nn));
    if dot(t, t) == 0f {{
        // v along n (or not given): any tangent (the table is isotropic at normal incidence).
        t = {p}_direction(cross(select(vec3<f32>(1f, 0f, 0f), vec3<f32>(0f, 1f, 0f), abs(nn.x) > 0.5f), nn));
    }}
    let b = cross(nn, t);
    let l = vec3<f32>(dot(t, x), dot(b, x), dot(nn, x));
    let q = vec4<f32>({p}_finite(ltc_1.x), {p}_finite(ltc_1.y), {p}_finite(ltc_1.z), {p}_finite(ltc_1.w));
    return vec3<f32>(q.x * l.x + q.z * l.z, l.y, q.y * l.x + q.w * l.z);
}}

// (a × b)·θ/sin θ for unit a, b: an edge's vector form factor times 2π (0 for a degenerate edge).
fn {p}_edge(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {{
    let c = cross(a, b);
    let s = length(c);
    let k = select(1f, atan2(s, dot(a, b)) / s, s > 0f);
    return c * k;
}}

// The LTC's integral over a convex polygon light of `count` (at most 8) vertices seen from p,
// clipped to the horizon in the cosine space.
fn {p}_polygon(ltc_1: vec4<f32>, n: vec3<f32>, v: vec3<f32>, p: vec3<f32>, vertices: array<vec3<f32>, 8>, count: u32, two_sided: bool) -> f32 {{
    let k = min(count, 8u);
    let origin = {p}_finite_vec(p);
    var corners = vertices;
    var q: array<vec3<f32>, 8>;
    for (var i = 0u; i < k; i++) {{
        q[i] = {p}_direction({p}_to_cosine(ltc_1, n, v, {p}_direction({p}_finite_vec(corners[i]) - origin)));
    }}
    var c: array<vec3<f32>, 9>;
    var m = 0u;
    for (var i = 0u; i < k; i++) {{
        let a = q[i];
        let b = q[(i + 1u) % k];
        if a.z >= 0f {{
            c[m] = a;
            m += 1u;
        }}
        if (a.z >= 0f) != (b.z >= 0f) {{
            let s = a.z / (a.z - b.z);
            c[m] = vec3<f32>(a.xy + s * (b.xy - a.xy), 0f);
            m += 1u;
        }}
    }}
    var sum = 0f;
    if m >= 3u {{
        for (var i = 0u; i < m; i++) {{
            sum += {p}_edge({p}_direction(c[i]), {p}_direction(c[(i + 1u) % m])).z;
        }}
    }}
    let r = sum * {inv_2pi};
    return clamp({p}_finite(select(max(r, 0f), abs(r), two_sided)), 0f, 1f);
}}

// A rectangle light of corners centre ∓ half_x ∓ half_y, through {p}_polygon.
fn {p}_rect(ltc_1: vec4<f32>, n: vec3<f32>, v: vec3<f32>, p: vec3<f32>, centre: vec3<f32>, half_x: vec3<f32>, half_y: vec3<f32>, two_sided: bool) -> f32 {{
    var corners: array<vec3<f32>, 8>;
    corners[0] = centre - half_x - half_y;
    corners[1] = centre + half_x - half_y;
    corners[2] = centre + half_x + half_y;
    corners[3] = centre - half_x + half_y;
    return {p}_polygon(ltc_1, n, v, p, corners, 4u, two_sided);
}}

// ltc_2.w in closed form: the horizon-clipped form factor of a spherical cap of sin^2(sigma) = s
// centred at cos(omega) = z, over s (Snyder 1996; max(z, 0) as s -> 0).
fn {p}_sphere_clip(z: f32, s: f32) -> f32 {{
    let zc = clamp({p}_finite(z), -1f, 1f);
    let sc = clamp({p}_finite(s), 0f, 1f);
    if zc * zc >= sc || sc < 1e-12f {{
        return max(zc, 0f);
    }}
    if sc >= 1f {{
        return 0.5f * (1f + zc);
    }}
    let sin_w = sqrt(1f - zc * zc);
    let x = sqrt(1f / sc - 1f);
    let y = clamp(-x * zc / sin_w, -1f, 1f);
    let r = sin_w * sqrt(max(1f - y * y, 0f));
    return clamp(((zc * acos(y) - x * r) * sc + atan(r / x)) / ({pi} * sc), 0f, 1f);
}}

// The rectangle by the sphere path: the unclipped vector form factor F in the cosine space,
// then |F| w(F_z/|F|, |F|).
fn {p}_rect_sphere(ltc_1: vec4<f32>, n: vec3<f32>, v: vec3<f32>, p: vec3<f32>, centre: vec3<f32>, half_x: vec3<f32>, half_y: vec3<f32>, two_sided: bool) -> f32 {{
    let origin = {p}_finite_vec(p);
    let cc = {p}_finite_vec(centre);
    let hx = {p}_finite_vec(half_x);
    let hy = {p}_finite_vec(half_y);
    var q: array<vec3<f32>, 4>;
    q[0] = {p}_direction({p}_to_cosine(ltc_1, n, v, {p}_direction(cc - hx - hy - origin)));
    q[1] = {p}_direction({p}_to_cosine(ltc_1, n, v, {p}_direction(cc + hx - hy - origin)));
    q[2] = {p}_direction({p}_to_cosine(ltc_1, n, v, {p}_direction(cc + hx + hy - origin)));
    q[3] = {p}_direction({p}_to_cosine(ltc_1, n, v, {p}_direction(cc - hx + hy - origin)));
    var f = vec3<f32>(0f);
    for (var i = 0u; i < 4u; i++) {{
        f += {p}_edge(q[i], q[(i + 1u) % 4u]);
    }}
    f = {p}_finite_vec(f * {inv_2pi});
    let len = length(f);
    let front = dot({p}_direction(cc - origin), {p}_direction(cross({p}_direction(hx), {p}_direction(hy)))) > 0f;
    if !(len > 0f) || (!front && !two_sided) {{
        return 0f;
    }}
    let fz = select(-f.z, f.z, front);
    let s = min(len, 1f);
    return clamp({p}_finite(s * {p}_sphere_clip(fz / len, s)), 0f, 1f);
}}

// The specular colour that multiplies a light's integral: F0 E + (1 - F0) times the Fresnel term.
fn {p}_scale(ltc_2: vec4<f32>, f0: vec3<f32>) -> vec3<f32> {{
    let f = clamp({p}_finite_vec(f0), vec3<f32>(0f), vec3<f32>(1f));
    return f * max({p}_finite(ltc_2.x), 0f) + (vec3<f32>(1f) - f) * max({p}_finite(ltc_2.y), 0f);
}}
"#
    ));
    let mut r = String::new();
    for line in header {
        r.push_str(&format!("//! {line}\n"));
    }
    r.push_str("//!\n");
    for line in &doc {
        r.push_str(&format!("//! {line}\n"));
    }
    r.push_str(&format!(
        r#"//! The CPU twin of the WGSL functions (same operations in f32).

/// Texels per side.
pub const {up}_SIZE: u32 = {n};
/// The tables as KTX2 textures (RGBA16F, and RGBA32F), as written by `shadefit build`.
pub const {up}_1_KTX2: &[u8] = include_bytes!("../data/{name}_1.ktx2");
pub const {up}_2_KTX2: &[u8] = include_bytes!("../data/{name}_2.ktx2");
pub const {up}_1_F32_KTX2: &[u8] = include_bytes!("../data/{name}_1_f32.ktx2");
pub const {up}_2_F32_KTX2: &[u8] = include_bytes!("../data/{name}_2_f32.ktx2");

type V3 = [f32; 3];

fn finite(x: f32) -> f32 {{
    if x.is_finite() {{ x }} else {{ 0.0 }}
}}

fn finite3(x: V3) -> V3 {{
    x.map(finite)
}}

fn add(a: V3, b: V3) -> V3 {{
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}}

fn sub(a: V3, b: V3) -> V3 {{
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}}

fn mul(a: V3, k: f32) -> V3 {{
    [a[0] * k, a[1] * k, a[2] * k]
}}

fn dot(a: V3, b: V3) -> f32 {{
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}}

fn cross(a: V3, b: V3) -> V3 {{
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}}

fn direction(x: V3) -> V3 {{
    let y = finite3(x);
    let m = y[0].abs().max(y[1].abs()).max(y[2].abs());
    if !(m > 0.0) {{
        return [0.0; 3];
    }}
    let s = mul(y, 1.0 / m);
    mul(s, 1.0 / dot(s, s).sqrt())
}}

/// Texture coordinates of (roughness, n·v) in the tables (texel nodes at i/(n - 1)).
pub fn {p}_uv(roughness: f32, n_dot_v: f32) -> [f32; 2] {{
    let r = finite(roughness).clamp(0.0, 1.0);
    let x = (1.0 - finite(n_dot_v).clamp(0.0, 1.0)).sqrt();
    [r * {scale} + {bias}, x * {scale} + {bias}]
}}

/// M^-1 of an ltc_1 texel applied to a direction in the frame of normal n and view v.
pub fn {p}_to_cosine(ltc_1: [f32; 4], n: V3, v: V3, x: V3) -> V3 {{
    let mut nn = direction(n);
    if dot(nn, nn) == 0.0 {{
        nn = [0.0, 0.0, 1.0];
    }}
    let vv = direction(v);
    let mut t = direction(sub(vv, mul(nn, dot(vv, nn))));
    if dot(t, t) == 0.0 {{
        let axis = if nn[0].abs() > 0.5 {{ [0.0, 1.0, 0.0] }} else {{ [1.0, 0.0, 0.0] }};
        t = direction(cross(axis, nn));
    }}
    let b = cross(nn, t);
    let l = [dot(t, x), dot(b, x), dot(nn, x)];
    let q = ltc_1.map(finite);
    [q[0] * l[0] + q[2] * l[2], l[1], q[1] * l[0] + q[3] * l[2]]
}}

/// (a × b)·θ/sin θ for unit a, b (0 for a degenerate edge).
pub fn {p}_edge(a: V3, b: V3) -> V3 {{
    let c = cross(a, b);
    let s = dot(c, c).sqrt();
    let k = if s > 0.0 {{ s.atan2(dot(a, b)) / s }} else {{ 1.0 }};
    mul(c, k)
}}

/// The LTC's integral over a convex polygon light (at most 8 vertices are read) seen from p,
/// clipped to the horizon in the cosine space.
pub fn {p}_polygon(ltc_1: [f32; 4], n: V3, v: V3, p: V3, vertices: &[V3], two_sided: bool) -> f32 {{
    let k = vertices.len().min(8);
    let origin = finite3(p);
    let q: Vec<V3> = vertices[..k].iter().map(|&x| direction({p}_to_cosine(ltc_1, n, v, direction(sub(finite3(x), origin))))).collect();
    let mut c: Vec<V3> = Vec::with_capacity(9);
    for i in 0..k {{
        let (a, b) = (q[i], q[(i + 1) % k]);
        if a[2] >= 0.0 {{
            c.push(a);
        }}
        if (a[2] >= 0.0) != (b[2] >= 0.0) {{
            let s = a[2] / (a[2] - b[2]);
            c.push([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), 0.0]);
        }}
    }}
    let mut sum = 0.0f32;
    if c.len() >= 3 {{
        for i in 0..c.len() {{
            sum += {p}_edge(direction(c[i]), direction(c[(i + 1) % c.len()]))[2];
        }}
    }}
    let r = sum * {inv_2pi};
    finite(if two_sided {{ r.abs() }} else {{ r.max(0.0) }}).clamp(0.0, 1.0)
}}

/// A rectangle light of corners centre ∓ half_x ∓ half_y, through the polygon.
#[allow(clippy::too_many_arguments)]
pub fn {p}_rect(ltc_1: [f32; 4], n: V3, v: V3, p: V3, centre: V3, half_x: V3, half_y: V3, two_sided: bool) -> f32 {{
    let corners = [
        sub(sub(centre, half_x), half_y),
        sub(add(centre, half_x), half_y),
        add(add(centre, half_x), half_y),
        add(sub(centre, half_x), half_y),
    ];
    {p}_polygon(ltc_1, n, v, p, &corners, two_sided)
}}

/// ltc_2.w in closed form: the clipped form factor of a cap of sin^2(sigma) = s at cos(omega) = z, over s.
pub fn {p}_sphere_clip(z: f32, s: f32) -> f32 {{
    let zc = finite(z).clamp(-1.0, 1.0);
    let sc = finite(s).clamp(0.0, 1.0);
    if zc * zc >= sc || sc < 1e-12 {{
        return zc.max(0.0);
    }}
    if sc >= 1.0 {{
        return 0.5 * (1.0 + zc);
    }}
    let sin_w = (1.0 - zc * zc).sqrt();
    let x = (1.0 / sc - 1.0).sqrt();
    let y = (-x * zc / sin_w).clamp(-1.0, 1.0);
    let r = sin_w * (1.0 - y * y).max(0.0).sqrt();
    (((zc * y.acos() - x * r) * sc + (r / x).atan()) / ({pi} * sc)).clamp(0.0, 1.0)
}}

/// The rectangle by the sphere path: |F| w(F_z/|F|, |F|) of the unclipped vector form factor F.
#[allow(clippy::too_many_arguments)]
pub fn {p}_rect_sphere(ltc_1: [f32; 4], n: V3, v: V3, p: V3, centre: V3, half_x: V3, half_y: V3, two_sided: bool) -> f32 {{
    let origin = finite3(p);
    let (cc, hx, hy) = (finite3(centre), finite3(half_x), finite3(half_y));
    let corner = |x: V3| direction({p}_to_cosine(ltc_1, n, v, direction(sub(x, origin))));
    let q = [
        corner(sub(sub(cc, hx), hy)),
        corner(sub(add(cc, hx), hy)),
        corner(add(add(cc, hx), hy)),
        corner(add(sub(cc, hx), hy)),
    ];
    let mut f = [0.0f32; 3];
    for i in 0..4 {{
        f = add(f, {p}_edge(q[i], q[(i + 1) % 4]));
    }}
    let f = finite3(mul(f, {inv_2pi}));
    let len = dot(f, f).sqrt();
    let front = dot(direction(sub(cc, origin)), direction(cross(direction(hx), direction(hy)))) > 0.0;
    if !(len > 0.0) || (!front && !two_sided) {{
        return 0.0;
    }}
    let fz = if front {{ f[2] }} else {{ -f[2] }};
    let s = len.min(1.0);
    finite(s * {p}_sphere_clip(fz / len, s)).clamp(0.0, 1.0)
}}

/// The specular colour that multiplies a light's integral: F0 E + (1 - F0) times the Fresnel term.
pub fn {p}_scale(ltc_2: [f32; 4], f0: V3) -> V3 {{
    let f = finite3(f0).map(|x| x.clamp(0.0, 1.0));
    let (e, fr) = (finite(ltc_2[0]).max(0.0), finite(ltc_2[1]).max(0.0));
    f.map(|x| x * e + (1.0 - x) * fr)
}}
"#
    ));
    (w, r)
}
