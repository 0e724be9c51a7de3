//! Compiled kernels kept on disk: NVRTC takes about ten seconds to compile
//! the step and the evaluation for a GPU, so the CUBIN it gives is stored
//! under a name made from everything that decides its bytes (the source,
//! the options, NVRTC's version and the architecture) and read back by the
//! next [`crate::Device::open`] that would compile the same thing.
//!
//! The folder: `$ANIMATS_CACHE` if set (`off`, or empty, keeps nothing),
//! else `$XDG_CACHE_HOME/animats`, else `$HOME/.cache/animats`. A file is
//! written under a temporary name and renamed into place, so a reader never
//! sees half of one; one that the driver then refuses is replaced.

use std::path::{Path, PathBuf};

/// The folder compiled kernels are kept in, or `None` where caching is off
/// or no folder is known.
pub fn folder() -> Option<PathBuf> {
    folder_from(
        std::env::var_os("ANIMATS_CACHE"),
        std::env::var_os("XDG_CACHE_HOME"),
        std::env::var_os("HOME"),
    )
}

fn folder_from(
    own: Option<std::ffi::OsString>,
    xdg: Option<std::ffi::OsString>,
    home: Option<std::ffi::OsString>,
) -> Option<PathBuf> {
    if let Some(own) = own {
        return (!own.is_empty() && own != "off").then(|| PathBuf::from(own));
    }
    let nonempty = |v: Option<std::ffi::OsString>| v.filter(|v| !v.is_empty());
    nonempty(xdg)
        .map(|x| PathBuf::from(x).join("animats"))
        .or_else(|| nonempty(home).map(|h| PathBuf::from(h).join(".cache").join("animats")))
}

/// The file a kernel compiled from `parts` (source, options, versions:
/// everything its bytes depend on) for `sm_{arch}` is kept in.
pub fn file(folder: &Path, parts: &[&str], arch: (i32, i32)) -> PathBuf {
    folder.join(format!(
        "kernel-{:016x}-sm_{}{}.cubin",
        fnv1a(parts),
        arch.0,
        arch.1
    ))
}

/// FNV-1a (64 bits) over the parts, each followed by a zero byte so that
/// moving text from one part to the next changes the key.
fn fnv1a(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &byte in part.as_bytes().iter().chain(&[0u8]) {
            h ^= u64::from(byte);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The kernel kept in `path`, if there is a nonempty one.
pub fn read(path: &Path) -> Option<Vec<u8>> {
    std::fs::read(path).ok().filter(|b| !b.is_empty())
}

/// Keeps `bytes` in `path` (creating its folder): written to a temporary
/// file beside it, then renamed. `Err` says what failed; the caller goes on
/// without the cache.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let dir = path
        .parent()
        .ok_or_else(|| format!("{}: no folder", path.display()))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    let written = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("{}: {e}", path.display()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_folder_follows_the_variables_in_order() {
        let s = |v: &str| Some(std::ffi::OsString::from(v));
        assert_eq!(
            folder_from(s("/c"), s("/x"), s("/h")),
            Some(PathBuf::from("/c"))
        );
        assert_eq!(folder_from(s("off"), s("/x"), s("/h")), None);
        assert_eq!(folder_from(s(""), s("/x"), s("/h")), None);
        assert_eq!(
            folder_from(None, s("/x"), s("/h")),
            Some(PathBuf::from("/x/animats"))
        );
        assert_eq!(
            folder_from(None, s(""), s("/h")),
            Some(PathBuf::from("/h/.cache/animats"))
        );
        assert_eq!(folder_from(None, None, None), None);
    }

    #[test]
    fn every_part_and_the_architecture_change_the_name() {
        let d = Path::new("/c");
        let base = file(d, &["source", "--fmad=false", "13.0"], (9, 0));
        for other in [
            file(d, &["source ", "--fmad=false", "13.0"], (9, 0)),
            file(d, &["source", "--fmad=true", "13.0"], (9, 0)),
            file(d, &["source", "--fmad=false", "13.5"], (9, 0)),
            file(d, &["sourc", "e--fmad=false", "13.0"], (9, 0)),
            file(d, &["source", "--fmad=false", "13.0"], (10, 0)),
        ] {
            assert_ne!(base, other);
        }
        assert_eq!(base, file(d, &["source", "--fmad=false", "13.0"], (9, 0)));
        // FNV-1a's published value for "a" (then our zero byte).
        assert_eq!(fnv1a(&[]), 0xcbf2_9ce4_8422_2325);
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        h ^= u64::from(b'a');
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
        assert_eq!(h, 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn a_kept_kernel_reads_back_whole_and_leaves_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("animats-cache-test-{}", std::process::id()));
        let path = file(&dir.join("deeper"), &["x"], (9, 0));
        assert_eq!(read(&path), None);
        let bytes: Vec<u8> = (0..=255u8).cycle().take(100_000).collect();
        write(&path, &bytes).unwrap();
        assert_eq!(read(&path).as_deref(), Some(&bytes[..]));
        write(&path, b"again").unwrap();
        assert_eq!(read(&path).as_deref(), Some(&b"again"[..]));
        let names: Vec<_> = std::fs::read_dir(dir.join("deeper"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        std::fs::write(&path, b"").unwrap();
        assert_eq!(read(&path), None, "an empty file is no kernel");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
