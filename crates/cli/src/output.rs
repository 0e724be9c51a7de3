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
