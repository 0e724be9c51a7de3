//! # animats-files
//!
//! Output files that never look complete when they are not: every file
//! animats writes whole (logs, parameter sets, checkpoints, pictures) goes
//! through [`write_atomically`], so after a crash, a full disk or Ctrl-C a
//! file is either the old one, the new one, or absent. And input read
//! with a bound ([`read_text`]), so that a stream that never ends is
//! refused instead of filling memory.

#![warn(missing_docs)]

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file in the same directory,
/// synced and then renamed over `path`. On failure the temporary file is
/// removed and the error names `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: cannot write: {e}", path.display())
    })
}

/// Reads the text of `path`, refusing more than `limit` bytes. The bound
/// is counted while reading, not taken from the file's stated size, so a
/// stream that never ends (`/dev/zero`, a pipe) is refused with an error of
/// kind [`std::io::ErrorKind::FileTooLarge`] once `limit` bytes are read,
/// instead of being read until memory runs out.
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_string(&mut text)?;
    if text.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!("more than {limit} bytes"),
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_leaves_nothing_on_failure() {
        let dir = std::env::temp_dir().join(format!("animats-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        write_atomically(&path, b"first").unwrap();
        write_atomically(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let missing = dir.join("no/such/dir/out.txt");
        let e = write_atomically(&missing, b"x").unwrap_err();
        assert!(e.contains("out.txt"), "{e}");
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("out.txt")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reads_up_to_its_bound_and_refuses_a_stream_that_never_ends() {
        let dir = std::env::temp_dir().join(format!("animats-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("in.txt");
        std::fs::write(&path, "abcdef").unwrap();
        assert_eq!(read_text(&path, 6).unwrap(), "abcdef");
        let e = read_text(&path, 5).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        assert_eq!(e.to_string(), "more than 5 bytes");
        std::fs::remove_dir_all(&dir).unwrap();
        // A device whose stated size is 0 and whose stream never ends.
        let zero = Path::new("/dev/zero");
        if zero.exists() {
            let e = read_text(zero, 1 << 20).unwrap_err();
            assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        }
    }
}
