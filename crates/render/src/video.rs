//! MP4 through `ffmpeg` (H.264, yuv420p, bit-exact flags so the same frames
//! give the same file), when it is installed. Frames go down a pipe as raw
//! RGB; nothing touches the disk but ffmpeg's output.

use crate::image::Image;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// Whether `ffmpeg` can be run.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Encodes `frames` (all of one size) at `fps` frames a second into `path`
/// as MP4.
pub fn encode_mp4(frames: &[Image], fps: f64, path: &Path) -> Result<(), String> {
    let first = frames.first().ok_or("no frames to encode")?;
    let (w, h) = (first.width, first.height);
    let mut child = Command::new("ffmpeg")
        .args(["-hide_banner", "-loglevel", "error", "-nostdin", "-y"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
        .args([
            "-s",
            &format!("{w}x{h}"),
            "-r",
            &format!("{fps}"),
            "-i",
            "-",
        ])
        // yuv420p needs even sizes.
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
        .args(["-c:v", "libx264", "-pix_fmt", "yuv420p", "-threads", "1"])
        .args([
            "-fflags",
            "+bitexact",
            "-flags:v",
            "+bitexact",
            "-map_metadata",
            "-1",
        ])
        .args(["-f", "mp4"])
        .arg(path)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run ffmpeg: {e}"))?;
    let written = {
        let mut stdin = child.stdin.take().ok_or("cannot write to ffmpeg")?;
        frames.iter().try_for_each(|f| {
            if f.width != w || f.height != h {
                return Err("every frame of a video must be the same size".to_string());
            }
            stdin.write_all(&f.rgb).map_err(|e| e.to_string())
        })
    };
    let output = child
        .wait_with_output()
        .map_err(|e| format!("ffmpeg: {e}"))?;
    if !output.status.success() {
        let why = String::from_utf8_lossy(&output.stderr);
        return Err(format!("ffmpeg failed ({}): {}", output.status, why.trim()));
    }
    written.map_err(|e| format!("ffmpeg stopped reading frames: {e}"))
}
