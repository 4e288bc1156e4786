//! What the GPU tests share: reporting past the test harness's capture, whether CI demands
//! that the GPU tests run, and the rewrite that moves an emitted `const` array into a storage
//! buffer (so a compute shader reads the table through memory, as a large LUT would be bound).

#![allow(dead_code)] // each test uses what it needs

use shadefit_runtime::gpu;
use std::io::Write;

/// A line on stderr even when the harness captures output (figures the tests measure).
pub fn report(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Whether `CI` is set (non-empty, not `0` or `false`): a GPU test must run, not skip.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// `library` with `const NAME: array<ELEM, N> = array<ELEM, N>(...);` replaced by a read-only
/// storage buffer `NAME` at group 0, binding 3 (`elem` as the WGSL spells it, e.g. `f32`,
/// `vec3f`; a vec3 in storage has a 16-byte stride).
pub fn const_array_in_buffer(library: &str, name: &str, elem: &str) -> String {
    let head = format!("const {name}: array<{elem}, ");
    let start = library.find(&head).unwrap_or_else(|| panic!("no `{head}`"));
    let n_end = library[start + head.len()..].find('>').unwrap() + start + head.len();
    let n = &library[start + head.len()..n_end];
    let close = library[start..].find("\n);\n").unwrap() + start;
    let decl = format!("@group(0) @binding(3) var<storage, read> {name}: array<{elem}, {n}>;");
    format!("{}{decl}{}", &library[..start], &library[close + 3..])
}

/// The headless device, or None (after a message) where the test is skipped; under CI a
/// missing adapter is a failure.
pub fn device(label: &str) -> Option<gpu::Gpu> {
    match pollster::block_on(gpu::headless(label)) {
        Ok(g) => {
            report(&format!("{label}: adapter {}", gpu::describe(&g.adapter.get_info())));
            Some(g)
        }
        Err(e) if in_ci() => panic!("CI is set, so the GPU test must run, but: {e} (run scripts/setup-vulkan, set WGPU_BACKEND=vulkan)"),
        Err(e) => {
            report(&format!("{label} SKIPPED: {e} (install lavapipe with scripts/setup-vulkan; CI=true makes this a failure)"));
            None
        }
    }
}
