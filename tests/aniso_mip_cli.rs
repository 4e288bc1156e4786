//! `shadefit aniso-mip` (a family command): a tiny synthetic normal map and aniso map in, two
//! KTX2 mip chains out; bad input exits 2 naming the file and the field, and writes nothing.

use std::path::Path;
use std::process::{Command, Output};

fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(rgb).unwrap();
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shadefit")).args(args).output().unwrap()
}

/// A 6×4 texture: flat normals on the left half, normals tilted along ±x on the right; one
/// anisotropic block everywhere (α_t 0.6 along x, α_b 0.2: channels 0.6, ½, 0.2).
fn inputs(dir: &Path) -> (String, String) {
    let (w, h) = (6u32, 4u32);
    let mut n = Vec::new();
    let mut a = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let tilt: i32 = if x < 3 { 0 } else if (x + y) % 2 == 0 { 60 } else { -60 };
            n.extend([(128 + tilt) as u8, 128, 230]);
            a.extend([153u8, 128, 51]);
        }
    }
    let (np, ap) = (dir.join("n.png"), dir.join("a.png"));
    write_png(&np, w, h, &n);
    write_png(&ap, w, h, &a);
    (np.to_string_lossy().into(), ap.to_string_lossy().into())
}

#[test]
fn writes_two_mip_chains() {
    let dir = tempfile::tempdir().unwrap();
    let (np, ap) = inputs(dir.path());
    let out = dir.path().join("t");
    for bits in ["8", "16"] {
        let o = run(&["aniso-mip", "--normal", &np, "--aniso", &ap, "--out", out.to_str().unwrap(), "--bits", bits]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("3 levels") && text.contains("0 not converged"), "{text}");
        let normal = std::fs::read(dir.path().join("t.normal.ktx2")).unwrap();
        let aniso = std::fs::read(dir.path().join("t.aniso.ktx2")).unwrap();
        // 6×4 → 3×2 → 1×1; RG and RGBA UNORM of the requested width (VkFormat 16/77, 37/91).
        let rn = ktx2::Reader::new(&normal[..]).unwrap();
        let ra = ktx2::Reader::new(&aniso[..]).unwrap();
        let (fmt_n, fmt_a) = if bits == "8" { (16, 37) } else { (77, 91) };
        assert_eq!(rn.header().format.map(|f| f.value()), Some(fmt_n));
        assert_eq!(ra.header().format.map(|f| f.value()), Some(fmt_a));
        assert_eq!((rn.header().pixel_width, rn.header().pixel_height, rn.header().level_count), (6, 4, 3));
        let sizes: Vec<usize> = ra.levels().map(|l| l.data.len()).collect();
        let b = if bits == "8" { 1 } else { 2 };
        assert_eq!(sizes, vec![24 * 4 * b, 6 * 4 * b, 4 * b]);
        // Level 1's left texel (flat normals, one block) keeps the block's channels: the
        // α_t channel 0.6 = 153/255 comes back to one code.
        let l1 = ra.levels().nth(1).unwrap().data;
        let first = if b == 1 { l1[0] as f64 / 255.0 } else { u16::from_le_bytes([l1[0], l1[1]]) as f64 / 65535.0 };
        assert!((first - 0.6).abs() <= 1.0 / 255.0, "{first}");
    }
    // Same inputs, same bytes (texels in parallel, collected in order).
    let again = dir.path().join("u");
    run(&["aniso-mip", "--normal", &np, "--aniso", &ap, "--out", again.to_str().unwrap(), "--bits", "16"]);
    assert_eq!(std::fs::read(dir.path().join("t.aniso.ktx2")).unwrap(), std::fs::read(dir.path().join("u.aniso.ktx2")).unwrap());
}

#[test]
fn bad_input_exits_2_naming_file_and_field_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (np, _) = inputs(dir.path());
    let small = dir.path().join("small.png");
    write_png(&small, 2, 2, &[0; 12]);
    let out = dir.path().join("x");
    let o = run(&["aniso-mip", "--normal", &np, "--aniso", small.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("small.png") && err.contains("size"), "{err}");
    let missing = dir.path().join("missing.png");
    let o = run(&["aniso-mip", "--normal", missing.to_str().unwrap(), "--aniso", &np, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.png: file"));
    let o = run(&["aniso-mip", "--normal", &np, "--aniso", &np, "--out", out.to_str().unwrap(), "--bits", "12"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--bits"));
    let names: Vec<String> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    assert!(names.iter().all(|n| !n.starts_with('x')), "written: {names:?}");
}
