//! `animats render`: pictures of the right size, not blank, with the floor
//! and the creatures where the camera puts them, the same bytes every run,
//! clear refusals, and the contact pile where its rocks came to lie.

mod common;
use animats_engine::DVec3;
use animats_render::camera::View;
use animats_render::{Camera, Image};
use common::{animats, animats_within, scratch, text, write, STIFF_SCENE};

fn decode_png(path: &std::path::Path) -> Image {
    let file = std::fs::File::open(path).expect("open png");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("png header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("png data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    Image {
        width: info.width,
        height: info.height,
        rgb: buf,
    }
}

fn run_ok(args: &[&str]) -> String {
    let o = animats(args);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{args:?}: {err}");
    out
}

/// `animats render scene --seconds t` to a PNG in `dir`, `size` pixels,
/// seen from `eye` towards `target`, without a caption; with the picture,
/// the scene as the library has it at the same time (1 ms steps, the
/// scenes' own) and the camera's projection, to say where things must be.
fn still(
    dir: &std::path::Path,
    scene: &str,
    seconds: f64,
    size: (u32, u32),
    eye: DVec3,
    target: DVec3,
) -> (Image, animats_scene::Scene, View) {
    let out = dir.join("still.png");
    let camera = format!(
        "{},{},{}:{},{},{}",
        eye.x, eye.y, eye.z, target.x, target.y, target.z
    );
    run_ok(&[
        "render",
        scene,
        "--seconds",
        &seconds.to_string(),
        "--width",
        &size.0.to_string(),
        "--height",
        &size.1.to_string(),
        "--camera",
        &camera,
        "--no-caption",
        "--out",
        out.to_str().expect("a UTF-8 scratch path"),
    ]);
    let img = decode_png(&out);
    assert_eq!((img.width, img.height), size);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(scene);
    let mut lib = animats_scene::load(&path).expect("scene");
    for _ in 0..(seconds * 1000.0).round() as usize {
        lib.step(0.001).expect("step");
    }
    let fov_y = 50.0;
    let view = View::new(&Camera { eye, target, fov_y }, size.0, size.1);
    (img, lib, view)
}

#[test]
fn a_png_shows_the_ball_and_the_floor_where_the_camera_puts_them() {
    let (img, scene, view) = still(
        &scratch("render-png"),
        "scenes/bouncing_ball.toml",
        0.2,
        (320, 200),
        DVec3::new(0.0, 0.8, 2.0),
        DVec3::new(0.0, 0.4, 0.0),
    );
    // Where the ball is at t = 0.2 s, from the library.
    let ball = scene.world.position(scene.particle("ball").expect("ball"));
    assert!(
        (ball.y - (1.05 - 0.5 * 9.8 * 0.04)).abs() < 1e-3,
        "free fall: {ball}"
    );
    let (x, y, _) = view.project(ball).expect("in view");
    let p = img.pixel(x as u32, y as u32);
    // The scene's particles are steel blue (0x6fa8dc), shaded.
    assert!(
        p[2] > p[0] + 40 && p[2] > 100,
        "the ball at ({x:.0}, {y:.0}): {p:?}"
    );
    // The floor under it (a checker of green-grey) and the sky at the top.
    let (fx, fy, _) = view
        .project(DVec3::new(0.05, 0.0, 0.35))
        .expect("floor in view");
    let f = img.pixel(fx as u32, fy as u32);
    assert!(
        f[1] > f[2] && f[1] > 90,
        "floor at ({fx:.0}, {fy:.0}): {f:?}"
    );
    let sky = img.pixel(160, 1);
    assert!(
        sky[2] >= sky[0] && sky.iter().all(|&c| c > 150),
        "sky: {sky:?}"
    );

    // Not blank: many colours and real contrast.
    let lum: Vec<f64> = img
        .rgb
        .chunks_exact(3)
        .map(|c| f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2]))
        .collect();
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    let var = lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64;
    assert!(var > 500.0, "variance {var}");
}

#[test]
fn the_same_scene_renders_the_same_bytes() {
    let dir = scratch("render-same");
    for name in ["a", "b"] {
        for ext in ["png", "gif"] {
            let out = dir.join(format!("{name}.{ext}"));
            run_ok(&[
                "render",
                "scenes/seaworld.toml",
                "--seconds",
                "1",
                "--fps",
                "5",
                "--width",
                "160",
                "--height",
                "100",
                "--out",
                out.to_str().unwrap(),
            ]);
        }
    }
    for ext in ["png", "gif"] {
        let a = std::fs::read(dir.join(format!("a.{ext}"))).expect("a");
        let b = std::fs::read(dir.join(format!("b.{ext}"))).expect("b");
        assert!(a.len() > 1000, "{ext}: {} bytes", a.len());
        assert!(a == b, "{ext}: two runs differ");
    }
    let gif = std::fs::read(dir.join("a.gif")).expect("gif");
    let mut decoder = gif::DecodeOptions::new()
        .read_info(gif.as_slice())
        .expect("gif");
    let mut frames = 0;
    while decoder.read_next_frame().expect("frame").is_some() {
        frames += 1;
    }
    assert_eq!(frames, 6, "t = 0, 0.2, ... 1.0 s at 5 frames a second");
}

/// Without `--seconds`, a render lasts the scene's run: its `[world]
/// duration` (4 s for the bouncing ball; `[evolve] duration` comes first,
/// tested with the zoo in `bodies.rs`).
#[test]
fn without_seconds_a_render_lasts_the_scene_s_duration() {
    let dir = scratch("render-duration");
    let out = dir.join("ball.png");
    let said = run_ok(&[
        "render",
        "scenes/bouncing_ball.toml",
        "--width",
        "64",
        "--height",
        "48",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        said.contains("1 frame of 64x48") && said.contains("to t = 4.00 s"),
        "{said}"
    );
    assert_eq!(decode_png(&out).width, 64);
}

#[test]
fn a_sheet_tiles_the_frames() {
    let dir = scratch("render-sheet");
    let out = dir.join("sheet.png");
    let stdout = run_ok(&[
        "render",
        "scenes/roobot.toml",
        "--seconds",
        "2",
        "--sheet",
        "5",
        "--width",
        "120",
        "--height",
        "80",
        "--camera",
        "follow",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(stdout.contains("5 frames of 120x80"), "{stdout}");
    let img = decode_png(&out);
    assert_eq!((img.width, img.height), (360, 160), "3 columns, 2 rows");
}

#[test]
fn bad_requests_exit_2_and_a_blow_up_exits_3_leaving_nothing() {
    let dir = scratch("render-bad");
    let x = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let (bmp, png, gif) = (x("x.bmp"), x("x.png"), x("x.gif"));
    let sea = "scenes/seaworld.toml";
    let cases: [(&[&str], &str); 7] = [
        (
            &[sea, "--seconds", "1", "--out", &bmp],
            ".png, .gif or .mp4",
        ),
        (&["nope.toml", "--seconds", "1", "--out", &png], "nope.toml"),
        (
            &[sea, "--seconds", "1", "--out", "/nonexistent-dir/x.png"],
            "does not exist",
        ),
        (
            &[sea, "--seconds", "1", "--camera", "1,2:3", "--out", &png],
            "--camera",
        ),
        (&[sea, "--seconds", "-1", "--out", &png], "--seconds"),
        (
            &[sea, "--seconds", "1", "--sheet", "4", "--out", &gif],
            "--sheet",
        ),
        (
            &[sea, "--seconds", "1e300", "--out", &gif],
            "2.5e301 frames (--seconds × --fps) are more than 20000",
        ),
    ];
    for (args, expect) in cases {
        let all: Vec<&str> = std::iter::once("render")
            .chain(args.iter().copied())
            .collect();
        let o = animats(&all);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(expect), "{all:?}: {err}");
    }
    // No ffmpeg on the PATH: a clear message, nothing written.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_animats"))
        .args([
            "render",
            "scenes/seaworld.toml",
            "--seconds",
            "1",
            "--out",
            &x("x.mp4"),
        ])
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .env("PATH", dir.to_str().unwrap())
        .output()
        .expect("run");
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("needs ffmpeg"), "{err}");
    assert!(!dir.join("x.mp4").exists());

    let scene = write(&dir, "stiff.toml", STIFF_SCENE);
    let gif = dir.join("blow.gif");
    let o = animats(&[
        "render",
        &scene,
        "--seconds",
        "10",
        "--out",
        gif.to_str().unwrap(),
    ]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains("`wobbly`") && err.contains("nothing was written"),
        "{err}"
    );
    assert!(!gif.exists());
}

#[test]
fn an_mp4_comes_from_ffmpeg_when_it_is_installed() {
    if !animats_render::video::ffmpeg_available() {
        // CI installs ffmpeg (.ci/run); the refusal without it is tested above.
        eprintln!("ffmpeg is not installed: the MP4 test cannot run here");
        return;
    }
    let dir = scratch("render-mp4");
    let mut files = Vec::new();
    for name in ["a.mp4", "b.mp4"] {
        let out = dir.join(name);
        run_ok(&[
            "render",
            "scenes/seaworld.toml",
            "--seconds",
            "1",
            "--fps",
            "10",
            "--width",
            "161",
            "--height",
            "100",
            "--out",
            out.to_str().unwrap(),
        ]);
        files.push(std::fs::read(&out).expect("mp4"));
    }
    assert_eq!(&files[0][4..8], b"ftyp", "an MP4 file");
    assert!(files[0] == files[1], "the same scene gives the same MP4");
    assert!(!dir.join("a.mp4.partial").exists());
    let probe = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=width,height,nb_read_frames",
            "-of",
            "csv=p=0",
        ])
        .arg(dir.join("a.mp4"))
        .output();
    if let Ok(p) = probe {
        let info = String::from_utf8_lossy(&p.stdout);
        assert_eq!(
            info.trim(),
            "162,100,11",
            "padded to an even width; 11 frames (t = 0 to 1 s)"
        );
    }
}

/// Pixels that are the roobot's orange (palette 0xe07b39, shaded): far
/// redder than the green-grey floor and the pale sky.
fn orange_pixels(img: &Image) -> usize {
    img.rgb
        .chunks(3)
        .filter(|p| {
            let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
            r > g + 40 && r > b + 70
        })
        .count()
}

/// A hopping roobot leaves a fixed framing within two seconds; by default
/// the camera follows a scene's one creature (or its [evolve] particles, or
/// the creature `--follow` names), so the last frame still shows it.
#[test]
fn walkers_stay_in_the_picture_by_default() {
    let dir = scratch("render-follow");
    let (followed, fixed) = (dir.join("followed.png"), dir.join("fixed.png"));
    let args = |out: &std::path::Path, camera: &str| {
        run_ok(&[
            "render",
            "scenes/roobot.toml",
            "--seconds",
            "6",
            "--width",
            "240",
            "--height",
            "160",
            "--camera",
            camera,
            "--out",
            out.to_str().unwrap(),
        ]);
        orange_pixels(&decode_png(out))
    };
    let (seen, gone) = (args(&followed, "auto"), args(&fixed, "fixed"));
    assert!(seen > 150, "the followed roobot covers {seen} pixels");
    assert!(
        gone < 10,
        "the fixed camera still sees {gone} roobot pixels"
    );
    // One of three roobots heading apart, by name.
    let one = dir.join("north.png");
    run_ok(&[
        "render",
        "scenes/roobots.toml",
        "--seconds",
        "6",
        "--width",
        "240",
        "--height",
        "160",
        "--follow",
        "north",
        "--out",
        one.to_str().unwrap(),
    ]);
    assert!(orange_pixels(&decode_png(&one)) > 150);
    let o = animats(&[
        "render",
        "scenes/roobots.toml",
        "--seconds",
        "1",
        "--follow",
        "south",
        "--out",
        one.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o)
            .1
            .contains("no creature or particle called `south`"),
        "{}",
        text(&o).1
    );
}

/// Sphere contact in the renderer (issue 12): `render scenes/pile.toml`
/// seen from above after 3 s shows the rocks where the library puts them:
/// the highest rocks (nothing above them to hide them) are drawn in the
/// rocks' grey-brown at their projected centres, not the floor's green or
/// the boulder's blue.
#[test]
fn the_pile_renders_its_rocks_where_they_came_to_lie() {
    let (img, scene, view) = still(
        &scratch("render-pile"),
        "scenes/pile.toml",
        3.0,
        (320, 320),
        DVec3::new(0.0, 2.5, 0.001),
        DVec3::ZERO,
    );
    let mut rocks: Vec<DVec3> = (0..200)
        .map(|k| {
            let id = scene.particle(&format!("rock{k}")).expect("rock");
            scene.world.position(id)
        })
        .collect();
    rocks.sort_by(|a, b| b.y.total_cmp(&a.y));
    for rock in &rocks[..5] {
        let (x, y, _) = view.project(*rock).expect("in view");
        let p = img.pixel(x as u32, y as u32);
        // 0x7d7468, shaded: red over blue; the floor is green over red, the
        // boulder blue over red.
        assert!(
            p[0] > p[2] + 8 && p[0] >= p[1],
            "the rock at {rock}, pixel ({x:.0}, {y:.0}): {p:?}"
        );
    }
}

/// A picture more than 10¹² steps away is refused, as `simulate` and
/// `evaluate` refuse such runs, before a step is taken: `--seconds 1e9`
/// of the walker (dt 0.5 ms: 2×10¹² steps) exits 2 naming the scene and
/// the count, and writes nothing. Without the check it would step for
/// weeks; the test gives it 60 s.
#[test]
fn a_render_too_many_steps_away_is_refused() {
    let dir = scratch("render-far");
    let out = dir.join("far.png");
    let o = animats_within(
        &[
            "render",
            "scenes/walker.toml",
            "--seconds",
            "1e9",
            "--out",
            out.to_str().unwrap(),
        ],
        60,
    )
    .expect("still stepping after 60 s: the step count was not checked");
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "scenes/walker.toml: 1000000000 s at dt = 0.0005 s is 2.0e12 steps, more than 1e12"
        ),
        "{err}"
    );
    assert!(!out.exists());
}

/// A scene whose fitness watches one particle of a creature (the thesis's
/// scene watches the roobot's hip) is framed around the whole creature:
/// at the start every roobot pixel lies inside the picture, clear of its
/// edges. (Framed around the hip alone, the hip and the head filled the
/// picture and ran off its top.)
#[test]
fn a_watched_particle_s_whole_creature_is_framed() {
    let dir = scratch("render-watched");
    let out = dir.join("hop.png");
    run_ok(&[
        "render",
        "scenes/hop_evolver.toml",
        "--seconds",
        "0.05",
        "--width",
        "320",
        "--height",
        "200",
        "--no-caption",
        "--out",
        out.to_str().unwrap(),
    ]);
    let img = decode_png(&out);
    let (w, h) = (img.width as usize, img.height as usize);
    let orange = |x: usize, y: usize| {
        let p = &img.rgb[3 * (y * w + x)..3 * (y * w + x) + 3];
        let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
        r > g + 40 && r > b + 70
    };
    let seen = orange_pixels(&img);
    let edge = (0..w)
        .flat_map(|x| [(x, 0), (x, 1), (x, h - 2), (x, h - 1)])
        .chain((0..h).flat_map(|y| [(0, y), (1, y), (w - 2, y), (w - 1, y)]))
        .filter(|&(x, y)| orange(x, y))
        .count();
    assert!(seen > 500, "the roobot covers {seen} pixels");
    assert_eq!(edge, 0, "{edge} roobot pixels on the picture's edges");
}
