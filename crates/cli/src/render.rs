//! `animats render SCENE [--seconds S] --out FILE`: headless pictures of a
//! scene with the software renderer: the last frame or a frame sheet as
//! PNG, an animated GIF, or an MP4 through ffmpeg.

use crate::{positive_f64, Failure};
use animats_engine::DVec3;
use animats_render::gif_file::encode_gif;
use animats_render::video::{encode_mp4, ffmpeg_available};
use animats_render::{picture, render, Camera, Image};
use animats_scene::evaluate::centre_at;
use animats_view::{BellShape, Describe, Drawing};
use animats_view::{SceneStage, Stage};
use rayon::prelude::*;
use std::path::PathBuf;
use std::str::FromStr;
use std::time::Instant;

/// Where the camera is.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraSpec {
    /// The live view's starting framing, moved along with what the scene
    /// follows (its `[evolve]` particles, `--follow NAME`, or its one
    /// creature), fixed when it follows nothing.
    Auto,
    /// That framing, moved along with what the scene follows, or else with
    /// the centre of its creatures (in whole checker periods of the floor).
    Follow,
    /// The live view's starting framing, never moving.
    Fixed,
    /// An eye and a target, m.
    At(DVec3, DVec3),
}

impl FromStr for CameraSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let vector = |v: &str| -> Result<DVec3, String> {
            let c: Vec<f64> = v
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("`{v}` is not three numbers x,y,z"))?;
            match c[..] {
                [x, y, z] if c.iter().all(|u| u.is_finite()) => Ok(DVec3::new(x, y, z)),
                _ => Err(format!("`{v}` is not three finite numbers x,y,z")),
            }
        };
        match s {
            "auto" => Ok(CameraSpec::Auto),
            "follow" => Ok(CameraSpec::Follow),
            "fixed" => Ok(CameraSpec::Fixed),
            _ => {
                let (eye, target) = s
                    .split_once(':')
                    .ok_or("expected auto, follow, fixed, or EYE:TARGET as x,y,z:x,y,z")?;
                let (eye, target) = (vector(eye)?, vector(target)?);
                if eye.distance(target) < 1e-9 {
                    return Err("the eye and the target are the same point".into());
                }
                Ok(CameraSpec::At(eye, target))
            }
        }
    }
}

/// Arguments of `animats render`.
#[derive(clap::Args)]
pub struct Args {
    /// The scene file (TOML); with --zoo, the directory of an `animats
    /// evolve` run of a [morphology] scene or of a quality-diversity run.
    scene: PathBuf,
    /// With --zoo, more runs' directories: each run's (and each lane's)
    /// best body first, the best of them first, then each one's second
    /// best, and so on.
    #[arg(requires = "zoo")]
    more_runs: Vec<PathBuf>,
    /// The run's best bodies side by side, each walking in its own
    /// picture captioned with its rank and fitness: this many (default 6),
    /// from the bodies alive at the run's last checkpoint: each lane's best
    /// (the best first), then each lane's second, and so on.
    #[arg(long, num_args = 0..=1, default_missing_value = "6", value_parser = clap::value_parser!(u32).range(1..=36))]
    zoo: Option<u32>,
    /// With --zoo on a quality-diversity run (map-elites, cma-me): these
    /// cells' elites (archive.csv's `index`), comma-separated; without it,
    /// N elites spread over the map, the best first, then each time the
    /// one farthest from those taken.
    #[arg(long, requires = "zoo", value_delimiter = ',')]
    elite: Option<Vec<u64>>,
    /// Simulated seconds to render; without it, the scene's evaluation
    /// (its `[evolve] duration`, or else its `[world] duration`; with
    /// --zoo, the run's).
    // (Negative numbers are values, so that `--seconds -1` is refused as a
    // bad --seconds, not as an unknown flag.)
    #[arg(long, value_parser = positive_f64, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// The picture: .png (the last frame, or a sheet with --sheet), .gif
    /// (animated), or .mp4 (needs ffmpeg).
    #[arg(long, short)]
    out: PathBuf,
    /// Pixels across.
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(16..=4096))]
    width: u32,
    /// Pixels down.
    #[arg(long, default_value_t = 400, value_parser = clap::value_parser!(u32).range(16..=4096))]
    height: u32,
    /// Frames per simulated second (GIF and MP4).
    #[arg(long, default_value_t = 25.0, value_parser = positive_f64)]
    fps: f64,
    /// Camera: `auto` (the live view's framing, following the scene's
    /// `[evolve]` particles, `--follow NAME` or its one creature, in steps
    /// of two floor squares so the floor stands still; without a floor,
    /// smoothly and up and down too), `follow` (the same,
    /// or the centre of all creatures when the scene follows nothing),
    /// `fixed` (the opening framing, still) or `EYE:TARGET` as
    /// `x,y,z:x,y,z`, metres.
    #[arg(long, default_value = "auto")]
    camera: CameraSpec,
    /// The creature or particle the camera frames and follows.
    #[arg(long)]
    follow: Option<String>,
    /// Vertical field of view, degrees.
    #[arg(long, default_value_t = 50.0, value_parser = fov)]
    fov: f64,
    /// Write a PNG sheet of this many frames, evenly spaced from t = 0 to
    /// the end, instead of the last frame.
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=100))]
    sheet: Option<u32>,
    /// Leave out the time caption.
    #[arg(long)]
    no_caption: bool,
}

fn fov(s: &str) -> Result<f64, String> {
    let v = positive_f64(s)?;
    if v < 170.0 {
        Ok(v)
    } else {
        Err(format!("must be below 170 degrees, got {s}"))
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Png,
    Gif,
    Mp4,
}

/// How long to render `scene` without `--seconds`: what its fitness is
/// measured over, or else its run's length.
fn scene_seconds(scene: &animats_scene::Scene) -> f64 {
    scene.evolve.as_ref().map_or(scene.duration, |e| e.duration)
}

/// The most frames an animation may have.
const MAX_FRAMES: u64 = 20_000;

/// Simulated instants of the frames.
fn frame_times(
    seconds: f64,
    format: Format,
    fps: f64,
    sheet: Option<u32>,
) -> Result<Vec<f64>, Failure> {
    Ok(match (format, sheet) {
        (Format::Png, None) => vec![seconds],
        (Format::Png, Some(n)) => (0..n)
            .map(|k| seconds * f64::from(k) / f64::from(n - 1))
            .collect(),
        _ => {
            let n = (seconds * fps + 1e-9).floor();
            if n > MAX_FRAMES as f64 {
                return Err(Failure::Input(format!(
                    "{n:.1e} frames (--seconds × --fps) are more than {MAX_FRAMES}: lower --seconds or --fps"
                )));
            }
            (0..=n as u64).map(|k| k as f64 / fps).collect()
        }
    })
}

/// One instant: where everything is and the shape of each bell.
struct Snapshot {
    t: f64,
    positions: Vec<DVec3>,
    bells: Vec<Option<BellShape>>,
    /// The actuators' levels (muscles are coloured by them).
    levels: Vec<f64>,
}

fn snapshot(stage: &SceneStage, drawing: &Drawing) -> Snapshot {
    let positions = stage.scene().world.state().pos.clone();
    let bells = drawing.bell_shapes(&positions, &stage.creatures());
    Snapshot {
        t: stage.time(),
        positions,
        bells,
        levels: stage.scene().nervous.actuator_levels(),
    }
}

/// Centre of the particles `picked` (of everything, if there are none).
fn centre_of(picked: &[usize], positions: &[DVec3]) -> DVec3 {
    if picked.is_empty() {
        return positions.iter().sum::<DVec3>() / positions.len().max(1) as f64;
    }
    picked.iter().map(|&i| positions[i]).sum::<DVec3>() / picked.len() as f64
}

/// What the output's name asks for; refused (before any work) if it
/// cannot be written.
fn format_of(args: &Args) -> Result<Format, Failure> {
    let ext = args
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => Format::Png,
        Some("gif") => Format::Gif,
        Some("mp4") => Format::Mp4,
        _ => {
            return Err(Failure::Input(format!(
                "{}: the output must end in .png, .gif or .mp4",
                args.out.display()
            )))
        }
    };
    if args.sheet.is_some() && format != Format::Png {
        return Err(Failure::Input("--sheet makes a .png".into()));
    }
    if format == Format::Mp4 && !ffmpeg_available() {
        return Err(Failure::Input(format!(
            "{}: writing .mp4 needs ffmpeg, which is not installed here (or not on PATH); install it (apt install ffmpeg) or write a .gif",
            args.out.display()
        )));
    }
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(Failure::Input(format!(
                "{}: the directory {} does not exist",
                args.out.display(),
                dir.display()
            )));
        }
    }
    Ok(format)
}

/// Runs the scene to each of `times`, taking a snapshot at each.
fn shoot(
    args: &Args,
    stage: &mut SceneStage,
    drawing: &Drawing,
    times: &[f64],
) -> Result<Vec<Snapshot>, Failure> {
    let dt = stage.dt();
    // As `simulate` and `evaluate`: at most 1e12 steps.
    let last = times.last().copied().unwrap_or(0.0);
    let steps = last / dt;
    if steps > animats_scene::evaluate::MAX_STEPS {
        return Err(Failure::Input(format!(
            "{}: {last} s at dt = {dt} s is {steps:.1e} steps, more than {:e}: lower --seconds",
            args.scene.display(),
            animats_scene::evaluate::MAX_STEPS
        )));
    }
    // A world that splits its work over threads enters the pool once for
    // all the frames' steps, not at every step (the same bits).
    let pooled = stage.scene().world.steps_on_pool();
    let run = || -> Result<Vec<Snapshot>, Failure> {
        let mut snapshots = Vec::with_capacity(times.len());
        for &t in times {
            while stage.time() < t - 0.5 * dt {
                stage.step(dt).map_err(|e| {
                    Failure::Blowup(format!(
                        "{}: {e}; nothing was written",
                        args.scene.display()
                    ))
                })?;
            }
            snapshots.push(snapshot(stage, drawing));
        }
        Ok(snapshots)
    };
    animats_engine::on_pool_if(pooled, run)
}

/// Where the creature started, marked by a post on the ground, and how far
/// it has gone: along the scene's `[evolve]` axis for its `[evolve]`
/// particles' centre of mass (what fitness counts), else across the
/// ground for the watched particles' centre.
struct Course {
    /// Particles whose centre counts.
    ids: Vec<animats_engine::ParticleId>,
    /// Every particle's mass, kg.
    mass: Vec<f64>,
    /// The axis (unit), or `None`: horizontal distance.
    axis: Option<DVec3>,
    /// The centre at t = 0.
    start: DVec3,
    /// The post: its foot and height, m.
    post: (DVec3, f64),
}

impl Course {
    fn new(stage: &SceneStage, watched: &[usize], at_start: &Snapshot) -> Option<Course> {
        let scene = stage.scene();
        let (ids, axis) = match &scene.evolve {
            Some(e) => (e.particles.clone(), Some(e.axis)),
            None if !watched.is_empty() => {
                let all: Vec<_> = scene.world.particle_ids().collect();
                (watched.iter().map(|&i| all[i]).collect(), None)
            }
            None => return None,
        };
        let mass = scene.world.particles().mass.clone();
        let start = centre_at(&at_start.positions, &mass, &ids);
        let radius = &scene.world.particles().radius;
        let top = watched
            .iter()
            .map(|&i| at_start.positions[i].y + radius[i])
            .fold(0.0f64, f64::max);
        let height = (0.6 * top).clamp(0.05, 1.0);
        Some(Course {
            ids,
            mass,
            axis,
            start,
            post: (DVec3::new(start.x, 0.0, start.z), height),
        })
    }

    /// Draws the start post into `picture`; the distance gone by `s`, m.
    fn mark(&self, picture: &mut animats_render::Picture, s: &Snapshot) -> f64 {
        let (foot, h) = self.post;
        let colour = animats_render::picture::hex(0xf2c14e);
        picture.rods.push(animats_render::Rod {
            a: foot,
            b: foot + DVec3::Y * h,
            radius: (0.03 * h).max(0.002),
            colour,
        });
        picture.spheres.push(animats_render::Sphere {
            centre: foot + DVec3::Y * h,
            radius: (0.08 * h).max(0.005),
            colour,
            shadow: true,
        });
        let moved = centre_at(&s.positions, &self.mass, &self.ids) - self.start;
        match self.axis {
            Some(axis) => moved.dot(axis),
            None => DVec3::new(moved.x, 0.0, moved.z).length(),
        }
    }
}

/// The camera of each frame: the opening framing (`base`), moved with what
/// is `watched` (from where it was at the start) as `--camera` says.
struct Cameras {
    base: Camera,
    spec: CameraSpec,
    follows: bool,
    watched: Vec<usize>,
    start: DVec3,
    period: f64,
    fov: f64,
    /// Also follow upwards (in the same whole periods): hoppers.
    vertical: bool,
    /// No floor (a swimmer): follow every way, smoothly.
    floorless: bool,
}

impl Cameras {
    fn new(args: &Args, stage: &SceneStage, describe: &Describe, at_start: &Snapshot) -> Cameras {
        let followed = stage.followed().to_vec();
        // What the camera keeps in view: the followed particles, or else
        // every creature's.
        let watched: Vec<usize> = if followed.is_empty() {
            let creatures = &stage.scene().creatures;
            creatures
                .iter()
                .flat_map(|c| c.particles.iter().copied())
                .collect()
        } else {
            followed.clone()
        };
        let start = centre_of(&watched, &at_start.positions);
        Cameras {
            base: Camera::framing(DVec3::from_array(describe.target), describe.distance),
            follows: match &args.camera {
                CameraSpec::Auto => !followed.is_empty(),
                CameraSpec::Follow => true,
                _ => false,
            },
            spec: args.camera.clone(),
            watched,
            start,
            // In whole periods of the floor's checker: the floor looks the
            // same in every frame, which also keeps GIFs small.
            period: 2.0 * describe.drawing.floor.unwrap_or(0.5),
            fov: args.fov,
            vertical: false,
            floorless: describe.drawing.floor.is_none(),
        }
    }

    /// Frames the watched creature snugly (`render`'s default camera on a
    /// creature): its extent at the start (the watched particles and every
    /// creature that holds one) fills 40 % of the frame's width, or 60 % of
    /// its height if that is the tighter, seen from the usual direction —
    /// so a 0.3 m walker is not a speck in a 2 m frame.
    fn snug(&mut self, args: &Args, stage: &SceneStage, at_start: &Snapshot) {
        if !matches!(args.camera, CameraSpec::Auto | CameraSpec::Follow) || self.watched.is_empty()
        {
            return;
        }
        let aspect = f64::from(args.width) / f64::from(args.height.max(1));
        let Some((centre, distance)) = animats_view::snug_watched(
            stage.scene(),
            &self.watched,
            &at_start.positions,
            args.fov,
            aspect,
        ) else {
            return;
        };
        self.base = Camera::framing(DVec3::new(centre.x, centre.y.max(0.0), centre.z), distance);
    }

    fn of(&self, s: &Snapshot) -> Camera {
        let base = self.base;
        let c = match &self.spec {
            CameraSpec::Auto | CameraSpec::Follow if self.follows => {
                let moved = centre_of(&self.watched, &s.positions) - self.start;
                // Without a floor (a swimmer) nothing needs to stand still:
                // the camera moves with the creature, every way.
                let shift = if self.floorless {
                    moved
                } else {
                    let up = if self.vertical { moved.y.max(0.0) } else { 0.0 };
                    (DVec3::new(moved.x, up, moved.z) / self.period).round() * self.period
                };
                Camera {
                    eye: base.eye + shift,
                    target: base.target + shift,
                    ..base
                }
            }
            CameraSpec::At(eye, target) => Camera {
                eye: *eye,
                target: *target,
                ..base
            },
            _ => base,
        };
        Camera {
            fov_y: self.fov,
            ..c
        }
    }
}

/// Writes `frames` as the output asks, whole or not at all.
fn write(args: &Args, format: Format, frames: &[Image]) -> Result<(), Failure> {
    let bytes = match (format, args.sheet) {
        (Format::Png, None) => frames
            .last()
            .map(Image::png)
            .transpose()
            .map_err(Failure::Other)?,
        (Format::Png, Some(n)) => {
            let columns = f64::from(n).sqrt().ceil() as u32;
            Some(
                Image::sheet(frames, columns)
                    .png()
                    .map_err(Failure::Other)?,
            )
        }
        (Format::Gif, _) => {
            // GIF delays are in hundredths of a second.
            let delay = (100.0 / args.fps).round().clamp(2.0, 65535.0) as u16;
            Some(encode_gif(frames, delay).map_err(Failure::Other)?)
        }
        (Format::Mp4, _) => None,
    };
    match bytes {
        // Through a temporary file: no partial picture under the final name.
        Some(b) => animats_files::write_atomically(&args.out, &b).map_err(Failure::Other),
        None => {
            let partial = args.out.with_extension("mp4.partial");
            let encoded = encode_mp4(frames, args.fps, &partial);
            if let Err(e) = encoded {
                let _ = std::fs::remove_file(&partial);
                return Err(Failure::Other(e));
            }
            std::fs::rename(&partial, &args.out)
                .map_err(|e| Failure::Other(format!("{}: cannot write: {e}", args.out.display())))
        }
    }
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    if args.zoo.is_some() {
        return zoo(&args);
    }
    let format = format_of(&args)?;
    let mut stage = SceneStage::following(args.scene.clone(), args.follow.as_deref())
        .map_err(Failure::Input)?;
    let seconds = args.seconds.unwrap_or_else(|| scene_seconds(stage.scene()));
    let times = frame_times(seconds, format, args.fps, args.sheet)?;
    crate::warn(&args.scene, stage.warnings());
    let describe = stage.describe();
    let drawing = &describe.drawing;
    let start = Instant::now();
    // Where things are at t = 0, which the framing is for (the first frame
    // drawn may be later: a PNG draws only the last).
    let at_start = snapshot(&stage, drawing);
    let snapshots = shoot(&args, &mut stage, drawing, &times)?;
    let mut cameras = Cameras::new(&args, &stage, &describe, &at_start);
    cameras.snug(&args, &stage, &at_start);
    let course = Course::new(&stage, &cameras.watched, &at_start);
    let frames: Vec<Image> = snapshots
        .par_iter()
        .map(|s| {
            let mut picture = picture(drawing, &s.positions, &s.bells, &s.levels);
            let gone = course.as_ref().map(|c| c.mark(&mut picture, s));
            if !args.no_caption {
                picture.caption = Some(match gone {
                    Some(d) => format!("t = {:.2} s   distance {d:.2} m", s.t),
                    None => format!("t = {:.2} s", s.t),
                });
            }
            render(&picture, &cameras.of(s), args.width, args.height)
        })
        .collect();
    write(&args, format, &frames)?;
    let size = std::fs::metadata(&args.out).map_or(0, |m| m.len());
    say!(
        "{}: {} frame{} of {}x{} rendered in {:.2} s, to t = {:.2} s; wrote {} ({size} bytes)",
        args.scene.display(),
        frames.len(),
        if frames.len() == 1 { "" } else { "s" },
        args.width,
        args.height,
        start.elapsed().as_secs_f64(),
        snapshots.last().map_or(0.0, |s| s.t),
        args.out.display()
    );
    Ok(())
}

/// `--zoo N`: the N best bodies of the run in `args.scene` (a directory)
/// and of any `more_runs`, each in its own tile, the tiles side by side in
/// every frame.
fn zoo(args: &Args) -> Result<(), Failure> {
    let format = format_of(args)?;
    let count = args
        .elite
        .as_ref()
        .map_or(args.zoo.unwrap_or(6) as usize, Vec::len);
    let dirs: Vec<&PathBuf> = std::iter::once(&args.scene)
        .chain(&args.more_runs)
        .collect();
    // Each run's best bodies, best first.
    let mut runs = Vec::with_capacity(dirs.len());
    let mut cells = false;
    for dir in &dirs {
        let checkpoint = dir.join("checkpoint.json");
        if !checkpoint.exists() {
            return Err(Failure::Input(format!(
                "{}: not the directory of an `animats evolve` run (no checkpoint.json)",
                dir.display()
            )));
        }
        let state = animats_evolve::checkpoint::load(&checkpoint).map_err(Failure::Input)?;
        if let Some(archive) = state.archive() {
            // A quality-diversity run: elites from all over its map (or
            // the cells asked for), each its own "lane", named by its cell.
            let picked = match &args.elite {
                Some(cells) => cells
                    .iter()
                    .map(|&i| {
                        archive.get(i).ok_or_else(|| {
                            Failure::Input(format!(
                                "--elite {i}: {} has no elite in cell {i} (archive.csv lists them)",
                                dir.display()
                            ))
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?,
                None => spread(archive, count),
            };
            let problem = state.config.problem.build().map_err(Failure::Input)?;
            let picked = picked
                .into_iter()
                .map(|e| (e.genome.clone(), e.objective, e.index as usize));
            // One map: its elites side by side, best first. Several runs:
            // each run's picks as one lineage, so every run's best comes
            // before any run's second.
            let lanes = if dirs.len() == 1 {
                picked.map(|e| vec![e]).collect()
            } else {
                vec![picked.collect()]
            };
            runs.push((dir, problem, lanes));
            cells = true;
            continue;
        }
        let bodies = state.best_bodies(usize::MAX).ok_or_else(|| {
            Failure::Input(format!(
                "{}: --zoo shows the bodies of a [morphology] run or the elites of a quality-diversity run (map-elites, cma-me); this run evolved one controller a lane",
                dir.display()
            ))
        })?;
        let problem = state.config.problem.build().map_err(Failure::Input)?;
        // Each lane of the run on its own, best first.
        let mut lanes: Vec<Vec<(Vec<f64>, f64, usize)>> = Vec::new();
        for body in bodies {
            match lanes.iter_mut().find(|l| l[0].2 == body.2) {
                Some(l) => l.push(body),
                None => lanes.push(vec![body]),
            }
        }
        runs.push((dir, problem, lanes));
    }
    // Rank by rank: every lane's best (the best first), then every lane's
    // second, until `count`: as many different lineages as there are.
    let mut bodies = Vec::with_capacity(count);
    for rank in 0.. {
        let mut at_rank: Vec<_> = runs
            .iter()
            .flat_map(|(dir, problem, lanes)| {
                lanes.iter().filter_map(move |list| {
                    list.get(rank)
                        .map(|(g, f, lane)| (*dir, problem, g.clone(), *f, *lane))
                })
            })
            .collect();
        if at_rank.is_empty() || bodies.len() == count {
            break;
        }
        at_rank.sort_by(|a, b| b.3.total_cmp(&a.3));
        bodies.extend(at_rank.into_iter().take(count - bodies.len()));
    }
    // Without --seconds, as long as the best body's evaluation.
    let seconds = match (args.seconds, bodies.first()) {
        (Some(s), _) => s,
        (None, Some((run, problem, genome, ..))) => {
            let text = problem.scene_toml(genome, "").map_err(Failure::Other)?;
            let name = run.join("best.toml").display().to_string();
            let scene =
                animats_scene::parse(&text, &name).map_err(|e| Failure::Other(e.to_string()))?;
            scene_seconds(&scene)
        }
        (None, None) => {
            return Err(Failure::Input(format!(
                "{}: the run holds no bodies to show",
                args.scene.display()
            )))
        }
    };
    let times = frame_times(seconds, format, args.fps, args.sheet)?;
    let several = dirs.len() > 1;
    let dir = &args.scene;
    let start = Instant::now();
    // Each body in its own stage and camera, rendered as `render` renders a
    // scene, captioned with its rank and fitness.
    let tiles: Vec<Vec<Image>> = bodies
        .par_iter()
        .enumerate()
        .map(|(k, (run, problem, genome, fitness, lane))| {
            let text = problem.scene_toml(genome, "").map_err(Failure::Other)?;
            let name = run.join(format!("zoo-{k}.toml"));
            let scene = animats_scene::parse(&text, &name.display().to_string())
                .map_err(|e| Failure::Other(e.to_string()))?;
            let mut stage = SceneStage::from_scene(name, scene, None).map_err(Failure::Other)?;
            let mut describe = stage.describe();
            // An evolved body: closer than a scene's framing, as a tile
            // shows one small body. A controller's creature (a map of
            // roobots) keeps its scene's framing.
            if problem.variation().is_some() {
                describe.distance = describe.distance.min(1.1);
            }
            let drawing = &describe.drawing;
            let at_start = snapshot(&stage, drawing);
            let snapshots = shoot(args, &mut stage, drawing, &times)?;
            let mut cameras = Cameras::new(args, &stage, &describe, &at_start);
            // A controller's creature on a map (roobots) may hop high.
            cameras.vertical = problem.variation().is_none();
            Ok(snapshots
                .iter()
                .map(|s| {
                    let mut picture = picture(drawing, &s.positions, &s.bells, &s.levels);
                    picture.caption = Some(format!(
                        "#{} {}({} {lane}): {fitness:.2}{}",
                        k + 1,
                        if several {
                            format!("{} ", run_name(run))
                        } else {
                            String::new()
                        },
                        if cells { "cell" } else { "lane" },
                        if args.no_caption {
                            String::new()
                        } else {
                            format!("  t = {:.2} s", s.t)
                        }
                    ));
                    render(&picture, &cameras.of(s), args.width, args.height)
                })
                .collect())
        })
        .collect::<Result<_, Failure>>()?;
    let columns = (bodies.len() as f64).sqrt().ceil() as u32;
    // Each frame's tiles moved into its sheet and dropped there: the
    // tiles and the sheets are never both whole in memory (a 10 s zoo of
    // six 640 × 400 tiles is 1.2 GB of each).
    let mut tiles: Vec<_> = tiles.into_iter().map(Vec::into_iter).collect();
    let frames: Vec<Image> = (0..times.len())
        .map(|_| {
            let row: Vec<Image> = tiles.iter_mut().filter_map(Iterator::next).collect();
            Image::sheet(&row, columns)
        })
        .collect();
    let (w, h) = frames.first().map_or((0, 0), |f| (f.width, f.height));
    write(args, format, &frames)?;
    let size = std::fs::metadata(&args.out).map_or(0, |m| m.len());
    say!(
        "{}{}: {} {}, {} frame{} of {w}x{h} rendered in {:.2} s, to t = {:.2} s; wrote {} ({size} bytes)",
        dir.display(),
        if several {
            format!(" and {} more runs", dirs.len() - 1)
        } else {
            String::new()
        },
        bodies.len(),
        if cells { "elites" } else { "best bodies" },
        frames.len(),
        if frames.len() == 1 { "" } else { "s" },
        start.elapsed().as_secs_f64(),
        times.last().copied().unwrap_or(0.0),
        args.out.display()
    );
    for (k, (run, _, _, fitness, lane)) in bodies.iter().enumerate() {
        say!(
            "  #{}: fitness {fitness} ({}{} {lane})",
            k + 1,
            if several {
                format!("{}, ", run.display())
            } else {
                String::new()
            },
            if cells { "cell" } else { "lane" }
        );
    }
    Ok(())
}

/// `n` elites spread over the archive: the best first, then each time the
/// elite farthest (in cells, each measure's bins scaled to one) from those
/// already taken, the better among equals: the corners of a map come
/// early.
fn spread(
    archive: &animats_evolve::archive::GridArchive,
    n: usize,
) -> Vec<&animats_evolve::archive::Elite> {
    let bins = &archive.grid.bins;
    let at = |e: &animats_evolve::archive::Elite| -> Vec<f64> {
        archive
            .unravel(e.index)
            .iter()
            .zip(bins)
            .map(|(&c, &b)| (c as f64 + 0.5) / b as f64)
            .collect()
    };
    let mut left: Vec<&animats_evolve::archive::Elite> = archive.elites().iter().collect();
    left.sort_by(|a, b| {
        b.objective
            .total_cmp(&a.objective)
            .then(a.index.cmp(&b.index))
    });
    let mut taken: Vec<&animats_evolve::archive::Elite> = Vec::new();
    while taken.len() < n && !left.is_empty() {
        let k = if taken.is_empty() {
            0
        } else {
            let d = |e: &animats_evolve::archive::Elite| {
                let x = at(e);
                taken
                    .iter()
                    .map(|t| {
                        at(t)
                            .iter()
                            .zip(&x)
                            .map(|(a, b)| (a - b) * (a - b))
                            .sum::<f64>()
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            // `left` is best first: the first of the farthest is the best.
            let mut best = 0;
            let mut far = d(left[0]);
            for (i, e) in left.iter().enumerate().skip(1) {
                let di = d(e);
                if di > far {
                    far = di;
                    best = i;
                }
            }
            best
        };
        taken.push(left.remove(k));
    }
    taken
}

/// A run directory's last component, for a caption.
fn run_name(dir: &std::path::Path) -> String {
    dir.file_name().map_or_else(
        || dir.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
