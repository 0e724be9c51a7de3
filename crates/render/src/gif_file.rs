//! Animated GIF encoding with the `gif` crate. One palette for the whole
//! animation (NeuQuant over frames sampled across it, from `color_quant`,
//! the quantiser the `gif` crate itself uses), so colours do not flicker
//! from frame to frame; after the first frame, pixels that did not change
//! are written transparent, which a fixed camera turns into long runs that
//! compress to almost nothing.

use crate::image::Image;
use color_quant::NeuQuant;
use std::borrow::Cow;
use std::collections::HashMap;

/// Frames sampled to choose the palette.
const PALETTE_FRAMES: usize = 8;
/// The palette index kept for "unchanged since the last frame".
const UNCHANGED: u8 = 255;

/// Encodes `frames` (all of one size) as a looping GIF, each shown for
/// `delay` hundredths of a second.
pub fn encode_gif(frames: &[Image], delay: u16) -> Result<Vec<u8>, String> {
    let first = frames.first().ok_or("no frames to encode")?;
    let (w, h) = (first.width, first.height);
    let too_big = |x: u32| {
        u16::try_from(x)
            .map_err(|_| format!("a GIF is at most 65535 pixels wide and high, not {x}"))
    };
    let (gw, gh) = (too_big(w)?, too_big(h)?);
    if frames.iter().any(|f| f.width != w || f.height != h) {
        return Err("every frame of a GIF must be the same size".into());
    }

    let mut sample = Vec::new();
    let picks = PALETTE_FRAMES.min(frames.len());
    for k in 0..picks {
        let f = &frames[k * (frames.len() - 1) / picks.saturating_sub(1).max(1)];
        for p in f.rgb.chunks_exact(3) {
            sample.extend([p[0], p[1], p[2], 255]);
        }
    }
    let quant = NeuQuant::new(10, 255, &sample);
    let mut palette = quant.color_map_rgb();
    palette.resize(3 * 256, 0);

    let mut out = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut out, gw, gh, &palette).map_err(|e| e.to_string())?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        let mut known: HashMap<[u8; 3], u8> = HashMap::new();
        let mut shown: Vec<u8> = Vec::new();
        for (k, f) in frames.iter().enumerate() {
            let indices: Vec<u8> = f
                .rgb
                .chunks_exact(3)
                .map(|p| {
                    let c = [p[0], p[1], p[2]];
                    *known
                        .entry(c)
                        .or_insert_with(|| quant.index_of(&[c[0], c[1], c[2], 255]) as u8)
                })
                .collect();
            let buffer = if k == 0 {
                indices.clone()
            } else {
                indices
                    .iter()
                    .zip(&shown)
                    .map(|(now, before)| if now == before { UNCHANGED } else { *now })
                    .collect()
            };
            shown = indices;
            let frame = gif::Frame {
                width: gw,
                height: gh,
                delay,
                dispose: gif::DisposalMethod::Keep,
                transparent: (k > 0).then_some(UNCHANGED),
                buffer: Cow::Owned(buffer),
                ..gif::Frame::default()
            };
            enc.write_frame(&frame).map_err(|e| e.to_string())?;
        }
    }
    Ok(out)
}
