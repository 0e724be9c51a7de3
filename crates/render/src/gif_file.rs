//! Animated GIF encoding with the `gif` crate. One palette for the whole
//! animation (NeuQuant over frames sampled across it, from `color_quant`,
//! the quantiser the `gif` crate itself uses), so colours do not flicker
//! from frame to frame; after the first frame, pixels that did not change
//! are written transparent, which a fixed camera turns into long runs that
//! compress to almost nothing.

use crate::image::Image;
use color_quant::NeuQuant;
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Frames sampled to choose the palette.
const PALETTE_FRAMES: usize = 8;
/// The palette index kept for "unchanged since the last frame".
const UNCHANGED: u8 = 255;
/// Frames mapped to the palette and compressed side by side at a time.
const BATCH: usize = 16;

/// The palette index found for each colour (`0x00BBGGRR`): NeuQuant's
/// search, made once a colour.
type Known = HashMap<u32, u8, BuildHasherDefault<ColourHash>>;

/// A hash for a colour key: one multiplication (std's SipHash, made for
/// keys an adversary chooses, took a tenth of a GIF's encoding).
#[derive(Default)]
struct ColourHash(u64);

impl Hasher for ColourHash {
    fn finish(&self) -> u64 {
        // The product's high half folded into its low bits too: hashbrown
        // takes the bucket from the low bits and a tag from the high.
        self.0 ^ (self.0 >> 32)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u32(&mut self, k: u32) {
        self.write_u64(u64::from(k));
    }
    fn write_u64(&mut self, k: u64) {
        self.0 = (self.0 ^ k).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

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
    let mut enc = gif::Encoder::new(&mut out, gw, gh, &palette).map_err(|e| e.to_string())?;
    enc.set_repeat(gif::Repeat::Infinite)
        .map_err(|e| e.to_string())?;
    // A batch of frames at a time, each frame's palette indices and then
    // its LZW compression on every thread (the gif crate compresses a
    // frame alone as `write_frame` would: the same bytes), written in
    // order; batches keep the indices of only a few frames in memory.
    let mut shown: Vec<u8> = Vec::new();
    for (b, batch) in frames.chunks(BATCH).enumerate() {
        let indices: Vec<Vec<u8>> = batch
            .par_iter()
            .map_init(HashMap::default, |known: &mut Known, f| {
                f.rgb
                    .chunks_exact(3)
                    .map(|p| {
                        let key = u32::from_le_bytes([p[0], p[1], p[2], 0]);
                        *known
                            .entry(key)
                            .or_insert_with(|| quant.index_of(&[p[0], p[1], p[2], 255]) as u8)
                    })
                    .collect()
            })
            .collect();
        let encoded: Vec<gif::Frame> = (0..batch.len())
            .into_par_iter()
            .map(|j| {
                let k = b * BATCH + j;
                let before = if j == 0 { &shown } else { &indices[j - 1] };
                let buffer = if k == 0 {
                    indices[j].clone()
                } else {
                    indices[j]
                        .iter()
                        .zip(before)
                        .map(|(now, before)| if now == before { UNCHANGED } else { *now })
                        .collect()
                };
                let mut frame = gif::Frame {
                    width: gw,
                    height: gh,
                    delay,
                    dispose: gif::DisposalMethod::Keep,
                    transparent: (k > 0).then_some(UNCHANGED),
                    buffer: Cow::Owned(buffer),
                    ..gif::Frame::default()
                };
                frame.make_lzw_pre_encoded();
                frame
            })
            .collect();
        for frame in &encoded {
            enc.write_lzw_pre_encoded_frame(frame)
                .map_err(|e| e.to_string())?;
        }
        if let Some(last) = indices.into_iter().last() {
            shown = last;
        }
    }
    drop(enc);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `encode_gif` wrote before it worked in batches on many
    /// threads: each frame mapped and compressed in turn by `write_frame`.
    fn one_by_one(frames: &[Image], delay: u16) -> Vec<u8> {
        let (w, h) = (frames[0].width as u16, frames[0].height as u16);
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
        let mut enc = gif::Encoder::new(&mut out, w, h, &palette).expect("encoder");
        enc.set_repeat(gif::Repeat::Infinite).expect("repeat");
        let mut shown: Vec<u8> = Vec::new();
        for (k, f) in frames.iter().enumerate() {
            let indices: Vec<u8> = f
                .rgb
                .chunks_exact(3)
                .map(|p| quant.index_of(&[p[0], p[1], p[2], 255]) as u8)
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
                width: w,
                height: h,
                delay,
                dispose: gif::DisposalMethod::Keep,
                transparent: (k > 0).then_some(UNCHANGED),
                buffer: Cow::Owned(buffer),
                ..gif::Frame::default()
            };
            enc.write_frame(&frame).expect("frame");
        }
        drop(enc);
        out
    }

    /// 1, 16, 17 and 41 frames (one batch, exactly one, one pixel over,
    /// several): a still background, a square that moves, colours that
    /// change slowly; the bytes are those of the frame-by-frame encoding.
    #[test]
    fn batches_on_threads_write_the_frame_by_frame_bytes() {
        let frame = |k: usize| {
            let (w, h) = (48u32, 30u32);
            let mut rgb = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    let inside = (x as usize).abs_diff(5 + k % 37) < 4 && y.abs_diff(15) < 5;
                    rgb.extend(if inside {
                        [200, (k * 5 % 256) as u8, 40]
                    } else {
                        [(x * 5) as u8, (y * 8) as u8, 120]
                    });
                }
            }
            Image {
                width: w,
                height: h,
                rgb,
            }
        };
        for n in [1, BATCH, BATCH + 1, 41] {
            let frames: Vec<Image> = (0..n).map(frame).collect();
            let ours = encode_gif(&frames, 4).expect("gif");
            assert_eq!(ours, one_by_one(&frames, 4), "{n} frames");
        }
    }
}
