//! PNG encoding of RGB images with the `png` crate.

use std::io::Write;

/// Encodes an 8-bit RGB image (row-major, 3 bytes per pixel) as PNG.
pub fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, String> {
    if rgb.len() != (width * height * 3) as usize {
        return Err(format!(
            "image buffer is {} bytes, expected {}",
            rgb.len(),
            width * height * 3
        ));
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(rgb).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    out.flush().map_err(|e| e.to_string())?;
    Ok(out)
}
