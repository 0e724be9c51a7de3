//! Checkpoints: the whole [`State`] of a run, written atomically (a temporary
//! file, synced, then renamed over the old one) so that a crash at any moment
//! leaves either the previous checkpoint or the new one, never half of one.
//!
//! The file is two lines: a header with the format name, version and an
//! FNV-1a checksum of the second line, then the state as JSON. A file that is
//! truncated, edited or from another program is refused with a message.

use crate::run::State;
use serde::{Deserialize, Serialize};
use std::path::Path;

const FORMAT: &str = "animats-evolve-checkpoint";
/// 2: optimisers' whole state and a full per-generation log (issue 10).
const VERSION: u32 = 2;

#[derive(Serialize, Deserialize)]
struct Header {
    format: String,
    version: u32,
    checksum: String,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

/// A checkpoint's name in a run's directory.
pub const FILE: &str = "checkpoint.json";

/// The files a run saves as it goes, by name, in the order they are
/// written: log.csv, best.toml (once there is a best), an archive's
/// archive.csv, then the checkpoint ([`FILE`]) last, so that one on disk
/// never stands for more than the files beside it. Made side by side on
/// the current rayon pool. `animats evolve` writes them during a run and
/// Python's `Evolution.save` whenever asked.
pub fn run_files(state: &State) -> Result<Vec<(&'static str, String)>, String> {
    let ((log, best), (archive, checkpoint)) = rayon::join(
        || (state.log_csv(), state.best_toml()),
        || (state.archive_csv(), encode(state)),
    );
    let mut files = vec![("log.csv", log)];
    if let Some(best) = best? {
        files.push(("best.toml", best));
    }
    if let Some(csv) = archive {
        files.push(("archive.csv", csv));
    }
    files.push((FILE, checkpoint?));
    Ok(files)
}

/// Writes `state` to `path` atomically.
pub fn save(path: &Path, state: &State) -> Result<(), String> {
    animats_files::write_atomically(path, encode(state)?.as_bytes())
}

/// `state` as a checkpoint file's text ([`save`] writes it; [`load`]
/// reads it back).
pub fn encode(state: &State) -> Result<String, String> {
    let body =
        serde_json::to_string(state).map_err(|e| format!("cannot encode the checkpoint: {e}"))?;
    let header = Header {
        format: FORMAT.into(),
        version: VERSION,
        checksum: format!("{:016x}", fnv1a(body.as_bytes())),
    };
    let header = serde_json::to_string(&header).map_err(|e| e.to_string())?;
    Ok(format!("{header}\n{body}\n"))
}

/// Reads a checkpoint, refusing anything that is not an intact one.
pub fn load(path: &Path) -> Result<State, String> {
    let shown = path.display();
    // `animats evolve` writes checkpoints as regular files: anything else
    // (a device, a pipe) could stream for ever.
    let meta =
        std::fs::metadata(path).map_err(|e| format!("{shown}: cannot read the checkpoint: {e}"))?;
    if !meta.is_file() {
        return Err(format!("{shown}: not a checkpoint (not a regular file)"));
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{shown}: cannot read the checkpoint: {e}"))?;
    let (header, body) = text
        .split_once('\n')
        .ok_or_else(|| format!("{shown}: not a checkpoint (no header line)"))?;
    let header: Header = serde_json::from_str(header)
        .map_err(|e| format!("{shown}: not an animats checkpoint (bad header: {e})"))?;
    if header.format != FORMAT {
        return Err(format!(
            "{shown}: not an animats evolution checkpoint (format `{}`)",
            header.format
        ));
    }
    if header.version != VERSION {
        return Err(format!(
            "{shown}: checkpoint version {} is not supported (expected {VERSION})",
            header.version
        ));
    }
    let body = body.strip_suffix('\n').unwrap_or(body);
    let sum = format!("{:016x}", fnv1a(body.as_bytes()));
    if sum != header.checksum {
        return Err(format!(
            "{shown}: the checkpoint is corrupt (checksum {sum}, expected {}); refusing to resume from it",
            header.checksum
        ));
    }
    let state: State = serde_json::from_str(body)
        .map_err(|e| format!("{shown}: the checkpoint is corrupt: {e}"))?;
    state
        .validate()
        .map_err(|e| format!("{shown}: the checkpoint is inconsistent: {e}"))?;
    Ok(state)
}
