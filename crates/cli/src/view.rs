//! `animats view SCENE`: run a scene live and watch it in the browser (a
//! run's directory: its best, or `--elite CELL` of its map).

use crate::{positive_f64, Failure};
use animats_viewer::{Options, SceneStage, Server};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Where and how to serve a live view (shared with `animats evolve --view`).
#[derive(clap::Args, Clone)]
pub struct Serving {
    /// Port to serve on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to bind: 127.0.0.1 serves this machine only; 0.0.0.0 serves
    /// the network, to browsers that open the printed URL with its access
    /// token (the page can pause, reset and move things).
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Frames streamed to the browser per second.
    #[arg(long, default_value_t = 30.0, value_parser = positive_f64)]
    pub display_fps: f64,
    /// Most browser tabs watching at once.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub max_clients: u64,
}

impl Serving {
    /// Binds the server, failing with a clear message (exit 2).
    pub fn bind(&self, speed: f64) -> Result<Server, Failure> {
        let server = Server::bind(Options {
            host: self.host.clone(),
            port: self.port,
            display_hz: self.display_fps,
            speed,
            max_clients: self.max_clients as usize,
        })
        .map_err(Failure::Input)?;
        let url = server.url().map_err(Failure::Other)?;
        say!("animats view: watching at {url} (paused until a tab connects; Ctrl-C to stop)");
        Ok(server)
    }
}

/// Arguments of `animats view`.
#[derive(clap::Args)]
pub struct Args {
    /// The scene file (TOML), or the directory of an `animats evolve` run:
    /// its best.toml, or with --elite one elite of its map.
    scene: PathBuf,
    /// With a quality-diversity run's directory: the elite of this cell
    /// (archive.csv's `index`; the heat map is archive.png).
    #[arg(long)]
    elite: Option<u64>,
    #[command(flatten)]
    serving: Serving,
    /// Real-time factor to start at (simulated seconds per wall second;
    /// 0: flat out). The page can change it.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// The particle or creature (`NAME` for `NAME.part`) the camera frames
    /// and follows; default the scene's `[evolve]` particles, or its first
    /// roobot or quadruped.
    #[arg(long)]
    follow: Option<String>,
}

/// The scene to watch: a file as given; a run's directory's best.toml, or
/// its elite of cell `elite`.
fn scene_of(path: &std::path::Path, elite: Option<u64>) -> Result<PathBuf, Failure> {
    if !path.is_dir() {
        return match elite {
            Some(_) => Err(Failure::Input(format!(
                "--elite picks from a quality-diversity run's directory; {} is a file",
                path.display()
            ))),
            None => Ok(path.to_path_buf()),
        };
    }
    let file = match elite {
        Some(i) => path.join("elites").join(format!("{i}.toml")),
        None => path.join("best.toml"),
    };
    if file.exists() {
        Ok(file)
    } else {
        Err(Failure::Input(match elite {
            Some(i) => format!(
                "{}: no elite in cell {i} (archive.csv lists the cells; archive.png shows them)",
                path.display()
            ),
            None => format!(
                "{}: not the directory of an `animats evolve` run (no best.toml)",
                path.display()
            ),
        }))
    }
}

/// Runs the command: serves until Ctrl-C.
pub fn run(args: Args) -> Result<(), Failure> {
    if !args.speed.is_finite() || args.speed < 0.0 {
        return Err(Failure::Input(format!(
            "--speed must be 0 (flat out) or a positive number, got {}",
            args.speed
        )));
    }
    let scene = scene_of(&args.scene, args.elite)?;
    let stage =
        SceneStage::following(scene.clone(), args.follow.as_deref()).map_err(Failure::Input)?;
    crate::warn(&scene, stage.warnings());
    // The handler before the address is printed: a Ctrl-C that comes as
    // soon as the address does stops the view cleanly. (Before it, a
    // process started with SIGINT ignored, as a shell's background jobs
    // are, lost that Ctrl-C and served on.)
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let server = args.serving.bind(args.speed)?;
    let s = server
        .serve(Box::new(stage), stop)
        .map_err(Failure::Other)?;
    say!(
        "simulated {:.2} s in {:.2} s ({:.1}x real time, {} steps), {} frames streamed",
        s.simulated,
        s.wall,
        s.real_time_factor(),
        s.steps,
        s.frames
    );
    Ok(())
}
