//! The software renderer puts things where the camera says they are, hides
//! what is behind, shades, and gives the same bytes every time.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_render::camera::View;
use animats_render::gif_file::encode_gif;
use animats_render::picture::hex;
use animats_render::{render, Camera, Image, Picture, Rod, Sphere};
use glam::DVec3;

const W: u32 = 320;
const H: u32 = 200;

fn camera() -> Camera {
    Camera {
        eye: DVec3::new(0.0, 1.0, 3.0),
        target: DVec3::new(0.0, 0.5, 0.0),
        fov_y: 50.0,
    }
}

fn ball(centre: DVec3, radius: f64, colour: u32) -> Sphere {
    Sphere {
        centre,
        radius,
        colour: hex(colour),
        shadow: true,
    }
}

/// Where `p` lands on the output image.
fn pixel_of(p: DVec3) -> (u32, u32) {
    let (x, y, _) = View::new(&camera(), W, H).project(p).expect("in front");
    (x as u32, y as u32)
}

fn floor_scene(spheres: Vec<Sphere>) -> Picture {
    Picture {
        spheres,
        floor: Some(0.25),
        ..Picture::default()
    }
}

fn luma(p: [u8; 3]) -> f64 {
    0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2])
}

#[test]
fn a_sphere_appears_where_the_camera_projects_it_and_its_size_follows_perspective() {
    let centre = DVec3::new(0.3, 0.5, 0.0);
    let r = 0.15;
    let img = render(
        &floor_scene(vec![ball(centre, r, 0xff0000)]),
        &camera(),
        W,
        H,
    );
    assert_eq!(
        (img.width, img.height, img.rgb.len()),
        (W, H, (W * H * 3) as usize)
    );
    let (x, y) = pixel_of(centre);
    let p = img.pixel(x, y);
    assert!(
        p[0] > 120 && p[1] < 60 && p[2] < 60,
        "red at the sphere's centre ({x}, {y}): {p:?}"
    );
    // Its edge, at r·f/z pixels from the centre: red inside, not outside.
    let view = View::new(&camera(), W, H);
    let radius_px = r * view.scale(view.depth(centre));
    let inside = img.pixel(x, (f64::from(y) - 0.8 * radius_px) as u32);
    let outside = img.pixel(x, (f64::from(y) - 1.25 * radius_px) as u32);
    assert!(
        inside[0] > 100 && inside[1] < 80,
        "inside the rim: {inside:?}"
    );
    assert!(
        !(outside[0] > 100 && outside[1] < 80),
        "outside the rim: {outside:?}"
    );
}

#[test]
fn sky_above_the_horizon_and_a_checkered_floor_below() {
    let img = render(&floor_scene(vec![]), &camera(), W, H);
    let sky = img.pixel(W / 2, 2);
    assert!(
        sky[2] > sky[0] && luma(sky) > 150.0,
        "light blue sky at the top: {sky:?}"
    );
    // Centres of two neighbouring squares: one light, one dark.
    let light = img.pixel(
        pixel_of(DVec3::new(0.125, 0.0, 0.625)).0,
        pixel_of(DVec3::new(0.125, 0.0, 0.625)).1,
    );
    let dark = img.pixel(
        pixel_of(DVec3::new(0.375, 0.0, 0.625)).0,
        pixel_of(DVec3::new(0.375, 0.0, 0.625)).1,
    );
    assert!(
        light[1] > light[2] && dark[1] > dark[2],
        "green-grey floor: {light:?} {dark:?}"
    );
    assert!(
        luma(light) > luma(dark) + 8.0,
        "a checker: {light:?} vs {dark:?}"
    );
}

#[test]
fn the_nearer_of_two_spheres_hides_the_other_and_a_resting_sphere_casts_a_shadow() {
    let far = ball(DVec3::new(0.0, 0.5, -1.0), 0.3, 0x0000ff);
    let near = ball(DVec3::new(0.0, 0.5, 1.0), 0.1, 0xff0000);
    for order in [vec![far, near], vec![near, far]] {
        let img = render(&floor_scene(order), &camera(), W, H);
        let (x, y) = pixel_of(near.centre);
        let p = img.pixel(x, y);
        assert!(
            p[0] > 120 && p[2] < 80,
            "the near red sphere is in front, whatever the order: {p:?}"
        );
    }
    // A sphere just above the floor darkens the floor under it (beside its
    // silhouette) against the same square without it.
    let resting = ball(DVec3::new(0.125, 0.11, -0.375), 0.1, 0xffffff);
    let spot = DVec3::new(0.125, 0.0, -0.375 + 0.07);
    let (x, y) = pixel_of(spot);
    let with = render(&floor_scene(vec![resting]), &camera(), W, H).pixel(x, y);
    let without = render(&floor_scene(vec![]), &camera(), W, H).pixel(x, y);
    assert!(
        luma(with) < 0.9 * luma(without),
        "shadow: {with:?} vs bare {without:?}"
    );
}

#[test]
fn a_rod_joins_its_ends() {
    let a = DVec3::new(-0.5, 0.5, 0.0);
    let b = DVec3::new(0.5, 0.8, 0.0);
    let pic = Picture {
        rods: vec![Rod {
            a,
            b,
            radius: 0.02,
            colour: hex(0x00c000),
        }],
        ..Picture::default()
    };
    let img = render(&pic, &camera(), W, H);
    for f in [0.25, 0.5, 0.75] {
        let (x, y) = pixel_of(a.lerp(b, f));
        let p = img.pixel(x, y);
        assert!(p[1] > 100 && p[0] < 90, "green along the rod at {f}: {p:?}");
    }
}

#[test]
fn water_tints_and_fogs_with_distance() {
    let near = ball(DVec3::new(-0.4, 0.5, 1.5), 0.1, 0xffffff);
    let far = ball(DVec3::new(0.4, 0.5, -8.0), 0.5, 0xffffff);
    let pic = Picture {
        spheres: vec![near, far],
        water: true,
        floor: Some(0.1),
        ..Picture::default()
    };
    let img = render(&pic, &camera(), W, H);
    let top = img.pixel(W / 2, 1);
    assert!(top[2] > top[0] + 40, "blue water above: {top:?}");
    let n = img.pixel(pixel_of(near.centre).0, pixel_of(near.centre).1);
    let f = img.pixel(pixel_of(far.centre).0, pixel_of(far.centre).1);
    assert!(
        luma(n) > luma(f) + 40.0,
        "the far white sphere fades into the water: near {n:?}, far {f:?}"
    );
    assert!(f[2] > f[0], "and takes its colour: {f:?}");
}

#[test]
fn the_same_picture_renders_the_same_bytes() {
    let pic = Picture {
        spheres: (0..40)
            .map(|k| {
                let a = f64::from(k) * 0.7;
                ball(
                    DVec3::new(a.cos(), 0.1 + 0.02 * f64::from(k), a.sin() - 0.5),
                    0.05,
                    0x6fa8dc,
                )
            })
            .collect(),
        floor: Some(0.1),
        caption: Some("t = 1.00 s".into()),
        ..Picture::default()
    };
    let a = render(&pic, &camera(), W, H);
    let b = render(&pic, &camera(), W, H);
    assert_eq!(a, b);
    assert_eq!(a.png().expect("png"), b.png().expect("png"));
    // Each thread keeps its canvas from one picture to the next, unclear
    // (the backdrop writes every pixel first): pictures of other sizes,
    // under water, with no floor, leave nothing behind; a fresh thread
    // draws the same.
    let water = Picture {
        water: true,
        ..pic.clone()
    };
    render(&water, &camera(), W + 37, H / 2);
    render(&Picture::default(), &camera(), 16, 9);
    render(&water, &camera(), W, H);
    assert_eq!(render(&pic, &camera(), W, H), a, "after other pictures");
    let fresh = std::thread::spawn(move || render(&pic, &camera(), W, H));
    assert_eq!(fresh.join().expect("thread"), a, "on a fresh thread");
}

#[test]
fn gifs_and_sheets_hold_every_frame() {
    let frames: Vec<Image> = (0..3)
        .map(|k| {
            let pic = floor_scene(vec![ball(
                DVec3::new(-0.5 + 0.5 * f64::from(k), 0.3, 0.0),
                0.1,
                0xff0000,
            )]);
            render(&pic, &camera(), 64, 40)
        })
        .collect();
    let bytes = encode_gif(&frames, 4).expect("gif");
    assert_eq!(&bytes[..6], b"GIF89a");
    // Played back (unchanged pixels are transparent over the last frame),
    // every frame is its source within the palette's error.
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(bytes.as_slice()).expect("decode");
    let mut shown = vec![0u8; 64 * 40 * 3];
    let mut n = 0;
    while let Some(frame) = decoder.read_next_frame().expect("frame") {
        assert_eq!((frame.width, frame.height, frame.delay), (64, 40, 4));
        for (px, rgba) in shown.chunks_exact_mut(3).zip(frame.buffer.chunks_exact(4)) {
            if rgba[3] == 255 {
                px.copy_from_slice(&rgba[..3]);
            }
        }
        let error: f64 = shown
            .iter()
            .zip(&frames[n].rgb)
            .map(|(a, b)| f64::from(a.abs_diff(*b)))
            .sum::<f64>()
            / shown.len() as f64;
        assert!(error < 4.0, "frame {n}: mean error {error} per channel");
        n += 1;
    }
    assert_eq!(n, 3);
    assert_eq!(encode_gif(&frames, 4).expect("gif"), bytes, "deterministic");

    let sheet = Image::sheet(&frames, 2);
    assert_eq!((sheet.width, sheet.height), (128, 80));
    assert_eq!(
        sheet.pixel(64 + 10, 40 + 10),
        [0, 0, 0],
        "the empty fourth place is black"
    );
    assert_eq!(sheet.pixel(64 + 10, 10), frames[1].pixel(10, 10));
}
