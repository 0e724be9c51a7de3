//! Trajectory files: CSV (`t,particle,x,y,z,vx,vy,vz`, one row per particle
//! per recorded step) or JSON Lines (one object per recorded step), numbers in
//! their shortest form that reads back to the same f64.
//!
//! Files are written under a temporary name beside the target and renamed
//! into place only when the run succeeds, so a file with the requested name
//! is always complete.

use animats_engine::State;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The trajectory formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Comma-separated values with a header.
    Csv,
    /// One JSON object per line.
    JsonLines,
}

impl Format {
    /// The format for a file name, from its extension.
    pub fn from_path(path: &Path) -> Result<Format, String> {
        match path.extension().and_then(|e| e.to_str()) {
            Some("csv") => Ok(Format::Csv),
            Some("jsonl") => Ok(Format::JsonLines),
            _ => Err(format!(
                "{}: unknown output format: name the file .csv or .jsonl",
                path.display()
            )),
        }
    }
}

/// The fewest bytes a trajectory of `frames` recorded steps of particles
/// named `names` can take: each particle's row or object holds its name
/// and seven numbers (t, position, velocity), each at least three
/// characters (`0.0`), with their separators.
pub fn least_bytes(frames: u64, names: &[String]) -> f64 {
    let per_frame: usize = names.iter().map(|n| n.len() + 7 * 4 + 1).sum();
    frames as f64 * per_frame as f64
}

/// Bytes free to an unprivileged writer on the file system holding `dir`
/// (`None` where that cannot be found out).
pub fn free_bytes(dir: &Path) -> Option<f64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
        // SAFETY: `c` is a NUL-terminated path and `st` a zeroed statvfs
        // that the call fills in; nothing else is read or written.
        unsafe {
            let mut st: libc::statvfs = std::mem::zeroed();
            if libc::statvfs(c.as_ptr(), &mut st) != 0 {
                return None;
            }
            Some(st.f_bavail as f64 * st.f_frsize as f64)
        }
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// Refuses, before anything is simulated, a trajectory of `frames`
/// recorded steps that could not fit in the free space where `path` is
/// to be written (a step mistyped a thousand times too small would
/// otherwise fill the disk for hours before failing).
pub fn check_room(path: &Path, frames: u64, names: &[String]) -> Result<(), String> {
    let need = least_bytes(frames, names);
    let dir = path.parent().unwrap_or(Path::new("."));
    let Some(free) = free_bytes(dir) else {
        return Ok(());
    };
    if need > free {
        return Err(format!(
            "{}: the trajectory would take at least {} ({frames} recorded steps of {} particles), more than the {} free there: record fewer with --every N, or raise --dt or lower --duration",
            path.display(),
            size(need),
            names.len(),
            size(free)
        ));
    }
    Ok(())
}

/// A byte count for people: `4.2 GB`.
fn size(bytes: f64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    if u == 0 {
        format!("{v:.0} {}", units[0])
    } else {
        format!("{v:.1} {}", units[u])
    }
}

/// Writes recorded steps of a run to a temporary file, renamed on success.
pub struct Trajectory {
    format: Format,
    names: Vec<String>,
    out: BufWriter<File>,
    tmp: PathBuf,
    path: PathBuf,
    frames: u64,
    /// Set once the temporary file has been renamed; otherwise dropping the
    /// trajectory deletes it.
    moved: bool,
}

fn num(buf: &mut ryu::Buffer, x: f64) -> &str {
    buf.format(x)
}

impl Trajectory {
    /// Creates the temporary file (failing here, before any simulation, if the
    /// output cannot be written) and writes the header.
    pub fn create(path: &Path, names: &[String]) -> Result<Trajectory, String> {
        let format = Format::from_path(path)?;
        let file_name = path
            .file_name()
            .ok_or_else(|| format!("{}: not a file name", path.display()))?
            .to_string_lossy()
            .into_owned();
        let tmp = path.with_file_name(format!(".{file_name}.tmp-{}", std::process::id()));
        let file = File::create(&tmp)
            .map_err(|e| format!("{}: cannot write the output file: {e}", path.display()))?;
        let mut t = Trajectory {
            format,
            names: names.to_vec(),
            out: BufWriter::with_capacity(1 << 20, file),
            tmp,
            path: path.to_path_buf(),
            frames: 0,
            moved: false,
        };
        if format == Format::Csv {
            t.io(|o| writeln!(o, "t,particle,x,y,z,vx,vy,vz"))?;
        }
        Ok(t)
    }

    fn io(
        &mut self,
        f: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
    ) -> Result<(), String> {
        f(&mut self.out).map_err(|e| format!("{}: write failed: {e}", self.path.display()))
    }

    /// Records the state at time `t` (after `step` steps).
    pub fn record(&mut self, t: f64, step: u64, state: &State) -> Result<(), String> {
        self.record_with(t, step, state, None)
    }

    /// Records a scene after `step` steps; in JSON lines, each controller's
    /// state and levels beside the particles (see [`brains_json`]).
    pub fn record_scene(&mut self, scene: &animats_scene::Scene, step: u64) -> Result<(), String> {
        let extra = (self.format == Format::JsonLines)
            .then(|| brains_json(scene))
            .flatten();
        self.record_with(
            scene.world.time(),
            step,
            scene.world.state(),
            extra.as_deref(),
        )
    }

    fn record_with(
        &mut self,
        t: f64,
        step: u64,
        state: &State,
        extra: Option<&str>,
    ) -> Result<(), String> {
        self.frames += 1;
        let mut b = ryu::Buffer::new();
        let mut line = String::with_capacity(64 * state.len() + 32);
        match self.format {
            Format::Csv => {
                let tt = num(&mut b, t).to_string();
                for (i, name) in self.names.iter().enumerate() {
                    let (p, v) = (state.pos[i], state.vel[i]);
                    line.push_str(&tt);
                    line.push(',');
                    line.push_str(name);
                    for x in [p.x, p.y, p.z, v.x, v.y, v.z] {
                        line.push(',');
                        line.push_str(num(&mut b, x));
                    }
                    line.push('\n');
                }
            }
            Format::JsonLines => {
                line.push_str("{\"t\":");
                line.push_str(num(&mut b, t));
                line.push_str(",\"step\":");
                line.push_str(&step.to_string());
                line.push_str(",\"particles\":[");
                for (i, name) in self.names.iter().enumerate() {
                    let (p, v) = (state.pos[i], state.vel[i]);
                    if i > 0 {
                        line.push(',');
                    }
                    // Names are validated to [A-Za-z0-9_.:#/-]: no escaping needed.
                    line.push_str("{\"name\":\"");
                    line.push_str(name);
                    line.push_str("\",\"position\":[");
                    for (k, x) in [p.x, p.y, p.z].into_iter().enumerate() {
                        if k > 0 {
                            line.push(',');
                        }
                        line.push_str(num(&mut b, x));
                    }
                    line.push_str("],\"velocity\":[");
                    for (k, x) in [v.x, v.y, v.z].into_iter().enumerate() {
                        if k > 0 {
                            line.push(',');
                        }
                        line.push_str(num(&mut b, x));
                    }
                    line.push_str("]}");
                }
                line.push(']');
                if let Some(extra) = extra {
                    line.push_str(extra);
                }
                line.push_str("}\n");
            }
        }
        self.io(|o| o.write_all(line.as_bytes()))
    }

    /// Number of recorded steps.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Flushes and moves the file into place.
    pub fn finish(mut self) -> Result<PathBuf, String> {
        self.io(|o| o.flush())?;
        self.out
            .get_ref()
            .sync_all()
            .map_err(|e| format!("{}: write failed: {e}", self.path.display()))?;
        std::fs::rename(&self.tmp, &self.path).map_err(|e| {
            format!(
                "{}: cannot move the output into place: {e}",
                self.path.display()
            )
        })?;
        self.moved = true;
        Ok(self.path.clone())
    }

    /// Keeps what was written under `NAME.partial` (never under the requested
    /// name) and returns that path.
    pub fn abandon(mut self) -> Option<PathBuf> {
        let _ = self.out.flush();
        let mut partial = self.path.clone().into_os_string();
        partial.push(".partial");
        let partial = PathBuf::from(partial);
        let kept = std::fs::rename(&self.tmp, &partial).ok().map(|_| partial);
        self.moved = kept.is_some();
        kept
    }
}

impl Drop for Trajectory {
    fn drop(&mut self) {
        if !self.moved {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// The JSON-lines fields of a scene's brains, `,"controllers":[...],
/// "sensors":{...},"actuators":{...}`, or `None` for a scene without any:
/// each controller's name, kind, state (FSM state name, else null), the
/// levels of its input sensors now (a creature's own senses: as its brain
/// read them for the step just taken) and of the actuators it set for that
/// step; then every sensor's and actuator's level by name.
pub fn brains_json(scene: &animats_scene::Scene) -> Option<String> {
    use animats_creatures::nervous_system::Inputs;
    let ns = &scene.nervous;
    if ns.is_empty() {
        return None;
    }
    let sensors = ns.sensor_levels(&scene.world);
    let actuators = ns.actuator_levels();
    let controllers: Vec<serde_json::Value> = ns
        .controllers
        .iter()
        .map(|c| {
            serde_json::json!({
                "name": c.name,
                "kind": c.brain.kind(),
                "state": c.brain.state(),
                "inputs": match &c.inputs {
                    Inputs::Sensors(list) => list.iter().map(|&i| sensors[i]).collect::<Vec<_>>(),
                    Inputs::Senses(_) => c.inputs_read().to_vec(),
                },
                "outputs": c.outputs.iter().map(|&i| actuators[i]).collect::<Vec<_>>(),
            })
        })
        .collect();
    let named = |names: Vec<&String>, levels: &[f64]| {
        serde_json::Value::Object(
            names
                .into_iter()
                .zip(levels)
                .map(|(n, l)| (n.clone(), serde_json::json!(l)))
                .collect(),
        )
    };
    let sensor_map = named(ns.sensors.iter().map(|(n, _)| n).collect(), &sensors);
    let actuator_map = named(ns.actuators.iter().map(|(n, _)| n).collect(), &actuators);
    Some(format!(
        ",\"controllers\":{},\"sensors\":{},\"actuators\":{}",
        serde_json::Value::Array(controllers),
        sensor_map,
        actuator_map
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use animats_engine::DVec3;

    /// [`least_bytes`] is a lower bound, and a tight one: particles at
    /// rest at the origin at t = 0 (every number `0.0`, the shortest
    /// there is) take exactly that in CSV, after the header, and more in
    /// JSON Lines. Were it one byte a particle too high, a trajectory
    /// that fits could be refused.
    #[test]
    fn least_bytes_is_the_size_of_the_shortest_trajectory() {
        let names: Vec<String> = ["a", "hip_f", "jelly.tentacle2.3"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let state = State {
            pos: vec![DVec3::ZERO; 3],
            vel: vec![DVec3::ZERO; 3],
        };
        let dir = std::env::temp_dir().join(format!("animats-least-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (file, exact) in [("t.csv", true), ("t.jsonl", false)] {
            let path = dir.join(file);
            let mut t = Trajectory::create(&path, &names).unwrap();
            for step in 0..5 {
                t.record(0.0, step, &state).unwrap();
            }
            t.finish().unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            let body = text
                .strip_prefix("t,particle,x,y,z,vx,vy,vz\n")
                .unwrap_or(&text);
            let bound = least_bytes(5, &names);
            if exact {
                assert_eq!(body.len() as f64, bound, "{body}");
            } else {
                assert!(body.len() as f64 > bound, "{} <= {bound}", body.len());
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
