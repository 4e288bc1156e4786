//! `libktx-check FILE.ktx2...`: loads each file with libktx (ktxTexture2_CreateFromMemory with
//! KTX_TEXTURE_CREATE_LOAD_IMAGE_DATA_BIT, which inflates zstd) and prints one JSON line per
//! file: the header as libktx read it and the SHA-256 of each level's image data, level 0 first.
//! A file libktx refuses prints its error code and ends the run with exit status 1.

use libktx_rs_sys as ktx;
use sha2::{Digest, Sha256};
use std::process::ExitCode;

/// A texture libktx created; destroyed through its vtable on drop.
struct Texture(*mut ktx::ktxTexture2);

impl Texture {
    fn load(bytes: &[u8], flags: ktx::ktxTextureCreateFlags) -> Result<Texture, String> {
        let mut t = std::ptr::null_mut();
        // SAFETY: `bytes` outlives the call; libktx copies what it keeps.
        let rc = unsafe { ktx::ktxTexture2_CreateFromMemory(bytes.as_ptr(), bytes.len(), flags, &mut t) };
        if rc != ktx::ktx_error_code_e_KTX_SUCCESS || t.is_null() {
            // SAFETY: ktxErrorString returns a static C string for any code.
            let name = unsafe { std::ffi::CStr::from_ptr(ktx::ktxErrorString(rc)) }.to_string_lossy().into_owned();
            return Err(format!("libktx error {rc} ({name})"));
        }
        Ok(Texture(t))
    }

    fn base(&self) -> *mut ktx::ktxTexture {
        self.0.cast()
    }

    fn get(&self) -> &ktx::ktxTexture2 {
        // SAFETY: a texture libktx created and has not destroyed.
        unsafe { &*self.0 }
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        // SAFETY: ktxTexture_Destroy is the macro `This->vtbl->Destroy(This)`.
        unsafe { ((*self.get().vtbl).Destroy.unwrap())(self.base()) }
    }
}

fn check(path: &str) -> Result<String, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{e}"))?;
    // Loading inflates zstd and then reports scheme NONE; the file's scheme is read from a
    // texture created without the image data.
    let scheme = Texture::load(&bytes, ktx::ktxTextureCreateFlagBits_KTX_TEXTURE_CREATE_NO_FLAGS)?.get().supercompressionScheme;
    let t = Texture::load(&bytes, ktx::ktxTextureCreateFlagBits_KTX_TEXTURE_CREATE_LOAD_IMAGE_DATA_BIT)?;
    let h = t.get();
    // SAFETY: the vtable of a live texture; GetImageOffset/GetImageSize are what the
    // ktxTexture_GetImageOffset/ktxTexture_GetImageSize macros call.
    let vtbl = unsafe { &*h.vtbl };
    // SAFETY: pData holds dataSize bytes once the image data is loaded.
    let data = unsafe { std::slice::from_raw_parts(h.pData, h.dataSize) };
    let mut level_sha256 = Vec::new();
    for level in 0..h.numLevels {
        let mut offset = 0;
        // SAFETY: a level below numLevels of a live texture, not supercompressed once loaded.
        let rc = unsafe { (vtbl.GetImageOffset.unwrap())(t.base(), level, 0, 0, &mut offset) };
        if rc != ktx::ktx_error_code_e_KTX_SUCCESS {
            return Err(format!("libktx error {rc} (GetImageOffset, level {level})"));
        }
        // GetImageSize is one image: a depth slice of a 3-D texture, one face, one layer. The
        // level holds them all, consecutively (KTX 2.0 mip level layout).
        let image = unsafe { (vtbl.GetImageSize.unwrap())(t.base(), level) };
        let slices = if h.numDimensions == 3 { (h.baseDepth >> level).max(1) } else { 1 };
        let size = image * (slices * h.numLayers * h.numFaces) as usize;
        let bytes = data.get(offset..offset + size).ok_or(format!("level {level}: {offset}+{size} past the {} bytes of data", data.len()))?;
        level_sha256.push(format!("\"{:x}\"", Sha256::digest(bytes)));
    }
    // libktx keeps counts (height, depth and layers 1 when absent, levels max(1, levelCount));
    // printed as the header's fields, 0 where the header has 0.
    let height = if h.numDimensions >= 2 { h.baseHeight } else { 0 };
    let depth = if h.numDimensions == 3 { h.baseDepth } else { 0 };
    let layers = if h.isArray { h.numLayers } else { 0 };
    let levels = if h.generateMipmaps { 0 } else { h.numLevels };
    let name = std::path::Path::new(path).file_name().unwrap().to_string_lossy();
    Ok(format!(
        "{{\"file\":{},\"vkFormat\":{},\"width\":{},\"height\":{height},\"depth\":{depth},\"layers\":{layers},\"faces\":{},\"levels\":{levels},\"supercompression\":{scheme},\"level_sha256\":[{}]}}",
        json_string(&name),
        h.vkFormat,
        h.baseWidth,
        h.numFaces,
        level_sha256.join(",")
    ))
}

/// A JSON string literal (file names are plain, but a quote or backslash stays valid JSON).
fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' | '\\' => out.extend(['\\', c]),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn main() -> ExitCode {
    let mut status = ExitCode::SUCCESS;
    for path in std::env::args().skip(1) {
        match check(&path) {
            Ok(line) => println!("{line}"),
            Err(e) => {
                eprintln!("libktx-check: {path}: {e}");
                status = ExitCode::FAILURE;
            }
        }
    }
    status
}
