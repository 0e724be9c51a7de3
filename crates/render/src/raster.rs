//! The software renderer: every primitive is ray-cast exactly over its
//! projected bounding box into a colour and depth buffer, at twice the
//! output resolution (then averaged down: antialiasing). No GPU, no display,
//! no threads inside a frame: the same picture gives the same bytes.
//!
//! Order: sky or water and the checkered floor (one ray per pixel; or the
//! terrain's triangles, each over its projected box), blob
//! shadows of the spheres under a light from straight above, spheres and
//! rods (depth-tested), then the translucent bells blended over them, then
//! the fog of the water (or of distance in air), then the caption.

use crate::camera::{Camera, View};
use crate::image::Image;
use crate::picture::{hex, Bell, Colour, Picture, Rod, Sphere};
use animats_engine::Terrain;
use animats_view::GroundMesh;
use glam::DVec3;

/// Samples per pixel along each axis.
const SUPERSAMPLE: u32 = 2;
/// Where the light comes from (the live view's sun).
const SUN: DVec3 = DVec3::new(0.3, 1.0, 0.5);
/// Water fog density, 1/m (the live view's).
const WATER_FOG: f64 = 0.18;

/// Colour and depth buffers at the supersampled size.
#[derive(Default)]
struct Canvas {
    width: u32,
    height: u32,
    colour: Vec<Colour>,
    /// Distance along each pixel's ray to what it shows; infinite for sky.
    depth: Vec<f64>,
    /// Where each pixel's ray meets the floor, if it shows the floor.
    floor: Vec<Option<DVec3>>,
    /// Each pixel column's and row's part of its ray ([`View::column`],
    /// [`View::row`]).
    columns: Vec<DVec3>,
    rows: Vec<DVec3>,
}

impl Canvas {
    /// The canvas sized for a `w` × `h` picture seen by `view`, reusing
    /// the buffers of the last picture: a GIF's frames, drawn one after
    /// another on a thread, then allocate nothing (a fresh 64 MB a frame
    /// for a zoo's 640 × 400 tiles had the kernel zeroing new pages for a
    /// tenth of the render's time).
    fn clear(&mut self, view: &View, w: u32, h: u32) {
        let n = (w * h) as usize;
        (self.width, self.height) = (w, h);
        // Sized only: `backdrop` writes every pixel first.
        self.colour.resize(n, Colour::ZERO);
        self.depth.resize(n, f64::INFINITY);
        self.floor.resize(n, None);
        self.columns.clear();
        self.columns
            .extend((0..w).map(|x| view.column(f64::from(x) + 0.5)));
        self.rows.clear();
        self.rows
            .extend((0..h).map(|y| view.row(f64::from(y) + 0.5)));
    }

    /// The unit ray through the centre of pixel (x, y): [`View::ray`]'s
    /// bits, from the parts computed once a frame.
    #[inline]
    fn ray(&self, x: u32, y: u32) -> DVec3 {
        (self.columns[x as usize] + self.rows[y as usize]).normalize()
    }
}

thread_local! {
    /// Each thread's canvas, kept from one picture to the next.
    static CANVAS: std::cell::RefCell<Canvas> = std::cell::RefCell::default();
}

/// Renders `picture` seen by `camera` as a `width` × `height` image.
pub fn render(picture: &Picture, camera: &Camera, width: u32, height: u32) -> Image {
    CANVAS.with(|c| match c.try_borrow_mut() {
        Ok(mut c) => render_on(&mut c, picture, camera, width, height),
        // (Only if a render were to call itself.)
        Err(_) => render_on(&mut Canvas::default(), picture, camera, width, height),
    })
}

fn render_on(c: &mut Canvas, picture: &Picture, camera: &Camera, width: u32, height: u32) -> Image {
    let (w, h) = (width.max(1) * SUPERSAMPLE, height.max(1) * SUPERSAMPLE);
    let view = View::new(camera, w, h);
    c.clear(&view, w, h);
    let sun = SUN.normalize();
    backdrop(c, &view, picture);
    if let (Some(cell), Some((mesh, _))) = (picture.floor, &picture.ground) {
        ground(c, &view, mesh, cell, picture.water);
    }
    if picture.floor.is_some() {
        let terrain = picture.ground.as_ref().map(|(_, t)| t);
        for s in picture.spheres.iter().filter(|s| s.shadow) {
            shadow(c, &view, s, terrain);
        }
    }
    for s in &picture.spheres {
        sphere(c, &view, s, sun);
    }
    for r in &picture.rods {
        rod(c, &view, r, sun);
    }
    for b in &picture.bells {
        bell(c, &view, b, sun);
    }
    fog(c, picture.water);
    let mut image = downsample(c, width.max(1), height.max(1));
    if let Some(caption) = &picture.caption {
        image.caption(caption);
    }
    image
}

fn water_colour(ray: DVec3) -> Colour {
    // Lighter towards the surface.
    hex(0x0d3b5c).lerp(hex(0x2a6f97), (0.5 + 0.5 * ray.y).clamp(0.0, 1.0))
}

fn sky_colour(ray: DVec3) -> Colour {
    hex(0xdfe9f2).lerp(hex(0x9fbdd8), ray.y.clamp(0.0, 1.0).sqrt())
}

/// Sky (or water) and the floor, one ray per pixel: every pixel's colour,
/// depth and floor point written (the canvas is not cleared before).
fn backdrop(c: &mut Canvas, view: &View, picture: &Picture) {
    let (light, dark) = floor_colours(picture.water);
    // Lambert under the sun, as the live view's floor.
    let lit = 0.55 + 0.45 * SUN.normalize().y;
    let back = Backdrop {
        light: light * lit,
        dark: dark * lit,
        cell: picture.floor.filter(|_| picture.ground.is_none()),
        eye: view.eye,
        water: picture.water,
    };
    let w = c.width as usize;
    for (y, row) in c.rows.iter().enumerate() {
        let at = y * w;
        let mut colour = &mut c.colour[at..at + w];
        let mut depth = &mut c.depth[at..at + w];
        let mut floor = &mut c.floor[at..at + w];
        let mut columns = &c.columns[..];
        // Four pixels at a time, whose square roots and divisions the
        // compiler computes side by side; the rest one by one.
        while columns.len() >= 4 {
            back.pixels::<4>(columns, *row, colour, depth, floor);
            (columns, colour, depth, floor) = (
                &columns[4..],
                &mut colour[4..],
                &mut depth[4..],
                &mut floor[4..],
            );
        }
        for k in 0..columns.len() {
            back.pixels::<1>(
                &columns[k..],
                *row,
                &mut colour[k..],
                &mut depth[k..],
                &mut floor[k..],
            );
        }
    }
}

/// What the backdrop draws.
struct Backdrop {
    light: Colour,
    dark: Colour,
    /// The flat floor's checker size, if it draws the floor.
    cell: Option<f64>,
    eye: DVec3,
    water: bool,
}

impl Backdrop {
    /// `N` pixels of a row: their rays (`Canvas::ray`'s operations, in
    /// separate arrays), where each meets the floor, and what each shows.
    #[inline(always)]
    fn pixels<const N: usize>(
        &self,
        columns: &[DVec3],
        row: DVec3,
        colour: &mut [Colour],
        depth: &mut [f64],
        floor: &mut [Option<DVec3>],
    ) {
        let eye = self.eye;
        let (mut x, mut y, mut z) = ([0.0; N], [0.0; N], [0.0; N]);
        for l in 0..N {
            let v = columns[l] + row;
            // glam's `normalize`: times 1 / √(x x + y y + z z).
            let r = 1.0 / ((v.x * v.x + v.y * v.y) + v.z * v.z).sqrt();
            (x[l], y[l], z[l]) = (v.x * r, v.y * r, v.z * r);
        }
        let (mut t, mut px, mut pz, mut fx, mut fz) =
            ([0.0; N], [0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        let cell = self.cell.unwrap_or(1.0);
        for l in 0..N {
            t[l] = -eye.y / y[l];
            px[l] = eye.x + x[l] * t[l];
            pz[l] = eye.z + z[l] * t[l];
            fx[l] = (px[l] / cell).floor();
            fz[l] = (pz[l] / cell).floor();
        }
        for l in 0..N {
            let ray = DVec3::new(x[l], y[l], z[l]);
            (colour[l], depth[l], floor[l]) =
                if self.cell.is_some() && !(ray.y >= -1e-9 || eye.y <= 0.0) {
                    let odd = odd_square(fx[l], fz[l]);
                    let p = DVec3::new(px[l], eye.y + y[l] * t[l], pz[l]);
                    (if odd { self.dark } else { self.light }, t[l], Some(p))
                } else if self.water {
                    (water_colour(ray), f64::INFINITY, None)
                } else {
                    (sky_colour(ray), f64::INFINITY, None)
                };
        }
    }
}

/// Whether the checker square (`fx`, `fz`) (the floors of a floor point's
/// coordinates over the square's size) is a dark one: as `(fx as i64 + fz
/// as i64).rem_euclid(2) == 1`, from each one's parity in floating point
/// (vectorised, where the conversions are one at a time), exact below
/// 2⁵³; the conversions decide the rest (never on a picture's floor).
#[inline(always)]
fn odd_square(fx: f64, fz: f64) -> bool {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2⁵³
    if fx.abs() < EXACT && fz.abs() < EXACT {
        let parity = |f: f64| f - 2.0 * (f * 0.5).floor();
        parity(fx) != parity(fz)
    } else {
        (fx as i64).wrapping_add(fz as i64).rem_euclid(2) == 1
    }
}

/// The floor's checker colours, unlit.
fn floor_colours(water: bool) -> (Colour, Colour) {
    if water {
        (hex(0xc2b280), hex(0xb2a272))
    } else {
        (hex(0x96a880), hex(0x80926c))
    }
}

/// The ground's triangles, checkered as the flat floor and lit by the sun
/// as it is (Lambert on each triangle's normal).
fn ground(c: &mut Canvas, view: &View, mesh: &GroundMesh, cell: f64, water: bool) {
    let (light, dark) = floor_colours(water);
    let sun = SUN.normalize();
    for [a, b, t] in mesh.corners() {
        let Some((x0, y0, x1, y1)) = triangle_bounds(c, view, [a, b, t]) else {
            continue;
        };
        let (e1, e2) = (b - a, t - a);
        let Some(mut normal) = e1.cross(e2).try_normalize() else {
            continue;
        };
        if normal.dot(view.eye - a) < 0.0 {
            normal = -normal;
        }
        // The flat floor's light, its change with the tilt made stronger
        // so that the relief shows.
        let lit = (0.55 + 0.45 * sun.y + 1.5 * (normal.dot(sun) - sun.y)).clamp(0.3, 1.1);
        for y in y0..y1 {
            for x in x0..x1 {
                let ray = c.ray(x, y);
                // Möller–Trumbore.
                let p = ray.cross(e2);
                let det = e1.dot(p);
                if det.abs() < 1e-15 {
                    continue;
                }
                let s = view.eye - a;
                let u = s.dot(p) / det;
                if !(0.0..=1.0).contains(&u) {
                    continue;
                }
                let q = s.cross(e1);
                let v = ray.dot(q) / det;
                if v < 0.0 || u + v > 1.0 {
                    continue;
                }
                let dist = e2.dot(q) / det;
                let i = (y * c.width + x) as usize;
                if dist <= 0.0 || dist >= c.depth[i] {
                    continue;
                }
                let hit = view.eye + ray * dist;
                let odd = ((hit.x / cell).floor() as i64 + (hit.z / cell).floor() as i64)
                    .rem_euclid(2)
                    == 1;
                c.colour[i] = if odd { dark } else { light } * lit;
                c.depth[i] = dist;
                c.floor[i] = Some(hit);
            }
        }
    }
}

/// Screen bounds of the part of a triangle in front of the eye (clipped
/// at a depth of 1 mm, so that a ground triangle reaching behind the eye
/// bounds only what shows of it).
fn triangle_bounds(c: &Canvas, view: &View, t: [DVec3; 3]) -> Option<(u32, u32, u32, u32)> {
    const NEAR: f64 = 1e-3;
    let mut front = Vec::with_capacity(4);
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let (dp, dq) = (view.depth(p) - NEAR, view.depth(q) - NEAR);
        if dp >= 0.0 {
            front.push(p);
        }
        if (dp >= 0.0) != (dq >= 0.0) {
            front.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    if front.is_empty() {
        return None;
    }
    bounds(c, view, &front, 1.0)
}

/// Pixel bounds (x0, y0, x1, y1) of the projection of the points, padded.
fn bounds(c: &Canvas, view: &View, points: &[DVec3], pad: f64) -> Option<(u32, u32, u32, u32)> {
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for p in points {
        let (x, y, _) = view.project(*p)?;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (w, h) = (f64::from(c.width), f64::from(c.height));
    let (x0, y0) = ((x0 - pad).floor().max(0.0), (y0 - pad).floor().max(0.0));
    let (x1, y1) = ((x1 + pad).ceil().min(w), (y1 + pad).ceil().min(h));
    (x0 < x1 && y0 < y1).then_some((x0 as u32, y0 as u32, x1 as u32, y1 as u32))
}

/// The box corners of a sphere, for its screen bounds.
fn corners(centre: DVec3, r: f64) -> [DVec3; 8] {
    let mut out = [DVec3::ZERO; 8];
    for (k, o) in out.iter_mut().enumerate() {
        let s = |bit: usize| if k & bit == 0 { -r } else { r };
        *o = centre + DVec3::new(s(1), s(2), s(4));
    }
    out
}

/// Screen bounds of a box, or the whole canvas when it reaches behind the eye.
fn box_bounds(c: &Canvas, view: &View, pts: &[DVec3]) -> Option<(u32, u32, u32, u32)> {
    if pts.iter().any(|p| view.depth(*p) <= 1e-6) {
        if pts.iter().all(|p| view.depth(*p) <= 1e-6) {
            return None;
        }
        return Some((0, 0, c.width, c.height));
    }
    bounds(c, view, pts, 1.0)
}

fn shade(base: Colour, normal: DVec3, ray: DVec3, sun: DVec3) -> Colour {
    let diffuse = normal.dot(sun).max(0.0);
    let half = (sun - ray).normalize();
    let specular = libm::pow(normal.dot(half).max(0.0), 40.0) * 0.25;
    base * (0.42 + 0.62 * diffuse) + DVec3::splat(specular)
}

/// A soft dark disc on the floor under a sphere, fading with its height.
fn shadow(c: &mut Canvas, view: &View, s: &Sphere, terrain: Option<&Terrain>) {
    let below = terrain.map_or(0.0, |t| t.height(s.centre.x, s.centre.z));
    let h = s.centre.y - below;
    if h <= 0.0 {
        return;
    }
    let r = s.radius * 1.1;
    let strength = 0.45 * libm::exp(-h / (6.0 * s.radius + 0.3));
    let ground = DVec3::new(s.centre.x, below, s.centre.z);
    let square = [
        ground + DVec3::new(-r, 0.0, -r),
        ground + DVec3::new(r, 0.0, -r),
        ground + DVec3::new(-r, 0.0, r),
        ground + DVec3::new(r, 0.0, r),
    ];
    let Some((x0, y0, x1, y1)) = box_bounds(c, view, &square) else {
        return;
    };
    for y in y0..y1 {
        for x in x0..x1 {
            let i = (y * c.width + x) as usize;
            let Some(p) = c.floor[i] else { continue };
            let d = DVec3::new(p.x - ground.x, 0.0, p.z - ground.z).length() / r;
            if d < 1.0 {
                c.colour[i] *= 1.0 - strength * (1.0 - d * d);
            }
        }
    }
}

fn sphere(c: &mut Canvas, view: &View, s: &Sphere, sun: DVec3) {
    let Some((x0, y0, x1, y1)) = box_bounds(c, view, &corners(s.centre, s.radius)) else {
        return;
    };
    let oc = view.eye - s.centre;
    let cc = oc.length_squared() - s.radius * s.radius;
    for y in y0..y1 {
        for x in x0..x1 {
            let ray = c.ray(x, y);
            let b = oc.dot(ray);
            let disc = b * b - cc;
            if disc < 0.0 {
                continue;
            }
            let t = -b - disc.sqrt();
            let i = (y * c.width + x) as usize;
            if t <= 0.0 || t >= c.depth[i] {
                continue;
            }
            let normal = (oc + ray * t) / s.radius;
            c.depth[i] = t;
            c.floor[i] = None;
            c.colour[i] = shade(s.colour, normal, ray, sun);
        }
    }
}

fn rod(c: &mut Canvas, view: &View, r: &Rod, sun: DVec3) {
    let ba = r.b - r.a;
    let baba = ba.length_squared();
    if baba < 1e-18 {
        return;
    }
    let mut pts = corners(r.a, r.radius).to_vec();
    pts.extend(corners(r.b, r.radius));
    let Some((x0, y0, x1, y1)) = box_bounds(c, view, &pts) else {
        return;
    };
    let oc = view.eye - r.a;
    let baoc = ba.dot(oc);
    for y in y0..y1 {
        for x in x0..x1 {
            let ray = c.ray(x, y);
            // Ray against the finite cylinder (the ends are under the spheres).
            let bard = ba.dot(ray);
            let k2 = baba - bard * bard;
            if k2.abs() < 1e-18 {
                continue;
            }
            let k1 = baba * oc.dot(ray) - baoc * bard;
            let k0 = baba * oc.length_squared() - baoc * baoc - r.radius * r.radius * baba;
            let h = k1 * k1 - k2 * k0;
            if h < 0.0 {
                continue;
            }
            let t = (-k1 - h.sqrt()) / k2;
            let along = baoc + t * bard;
            let i = (y * c.width + x) as usize;
            if t <= 0.0 || along < 0.0 || along > baba || t >= c.depth[i] {
                continue;
            }
            let normal = (oc + ray * t - ba * (along / baba)) / r.radius;
            c.depth[i] = t;
            c.floor[i] = None;
            c.colour[i] = shade(r.colour, normal, ray, sun);
        }
    }
}

fn bell(c: &mut Canvas, view: &View, b: &Bell, sun: DVec3) {
    if b.radius <= 0.0 || b.height <= 0.0 {
        return;
    }
    // A frame with the axis as local y; the ellipsoid becomes a unit sphere
    // after scaling by (radius, height, radius).
    let ey = b.axis;
    let ex = if ey.x.abs() < 0.9 { DVec3::X } else { DVec3::Z }
        .cross(ey)
        .normalize();
    let ez = ex.cross(ey);
    let scale = DVec3::new(b.radius, b.height, b.radius);
    let local = |v: DVec3| DVec3::new(v.dot(ex), v.dot(ey), v.dot(ez)) / scale;
    let reach = b.radius.max(b.height);
    let Some((x0, y0, x1, y1)) = box_bounds(c, view, &corners(b.centre, reach)) else {
        return;
    };
    let o = local(view.eye - b.centre);
    for y in y0..y1 {
        for x in x0..x1 {
            let ray = c.ray(x, y);
            let d = local(ray);
            let (a2, b2, c2) = (d.length_squared(), o.dot(d), o.length_squared() - 1.0);
            let disc = b2 * b2 - a2 * c2;
            if disc < 0.0 {
                continue;
            }
            let sq = disc.sqrt();
            let i = (y * c.width + x) as usize;
            // The first hit on the upper half: the outside of the crown, or
            // the inside seen through the open rim.
            for t in [(-b2 - sq) / a2, (-b2 + sq) / a2] {
                let p = o + d * t;
                if t <= 0.0 || p.y < 0.0 {
                    continue;
                }
                if t < c.depth[i] {
                    let n = (ex * (p.x / b.radius) + ey * (p.y / b.height) + ez * (p.z / b.radius))
                        .normalize();
                    let n = if n.dot(ray) > 0.0 { -n } else { n };
                    let lit = shade(b.colour, n, ray, sun);
                    c.colour[i] = c.colour[i].lerp(lit, 0.45);
                }
                break;
            }
        }
    }
}

/// Water fades everything into its colour with distance; air only the far
/// floor into the haze of the horizon.
fn fog(c: &mut Canvas, water: bool) {
    use animats_engine::math::{exp_lanes, LANES};
    let density = if water { WATER_FOG } else { 1.0 / 60.0 };
    // In air the haze is the sky's colour at the horizon (`sky_colour` of a
    // level ray: it reads only the ray's height), whatever the pixel.
    let horizon = sky_colour(DVec3::ZERO);
    // The pixels that show something, LANES at a time: `exp_lanes` gives
    // each lane `exp`'s bits, side by side.
    let fade = |c: &mut Canvas, at: &[usize]| {
        let mut arg = [0.0; LANES];
        for (a, &i) in arg.iter_mut().zip(at) {
            *a = -density * c.depth[i];
        }
        let keep = exp_lanes(arg);
        for (&keep, &i) in keep.iter().zip(at) {
            let haze = if water {
                let w = c.width as usize;
                water_colour(c.ray((i % w) as u32, (i / w) as u32))
            } else {
                horizon
            };
            c.colour[i] = haze.lerp(c.colour[i], keep);
        }
    };
    let mut at = [0usize; LANES];
    let mut k = 0;
    for i in 0..c.depth.len() {
        if c.depth[i].is_finite() {
            at[k] = i;
            k += 1;
            if k == LANES {
                fade(c, &at);
                k = 0;
            }
        }
    }
    fade(c, &at[..k]);
}

/// Averages each SUPERSAMPLE × SUPERSAMPLE block into one 8-bit pixel.
fn downsample(c: &Canvas, width: u32, height: u32) -> Image {
    let mut rgb = Vec::with_capacity((width * height * 3) as usize);
    let k = f64::from(SUPERSAMPLE * SUPERSAMPLE);
    for y in 0..height {
        for x in 0..width {
            let mut sum = Colour::ZERO;
            for dy in 0..SUPERSAMPLE {
                for dx in 0..SUPERSAMPLE {
                    let i = ((y * SUPERSAMPLE + dy) * c.width + x * SUPERSAMPLE + dx) as usize;
                    sum += c.colour[i];
                }
            }
            let v = sum / k;
            rgb.extend([v.x, v.y, v.z].map(|u| (u.clamp(0.0, 1.0) * 255.0 + 0.5) as u8));
        }
    }
    Image { width, height, rgb }
}

#[cfg(test)]
mod tests {
    use super::odd_square;

    /// `odd_square` is the integer conversions' answer for floors near
    /// zero, either side of 2⁵³ and 2⁶³, at the extremes, for ±0, ±∞ and
    /// NaN, and for a million random pairs of every magnitude.
    #[test]
    fn odd_squares_are_the_integer_parity() {
        let reference = |fx: f64, fz: f64| (fx as i64).wrapping_add(fz as i64).rem_euclid(2) == 1;
        let mut values = vec![
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            f64::MIN,
        ];
        for base in [
            0.0f64,
            2f64.powi(52),
            2f64.powi(53),
            2f64.powi(63),
            2f64.powi(64),
        ] {
            for d in -3..=3 {
                let v = (base + f64::from(d) * base.max(1.0) * f64::EPSILON).floor();
                values.extend([v, -v, v + 1.0, -v - 1.0]);
            }
        }
        for &a in &values {
            for &b in &values {
                assert_eq!(odd_square(a, b), reference(a, b), "{a:e}, {b:e}");
            }
        }
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..1_000_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let m = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let (a, b) = ((m * 2f64.powi((s % 70) as i32)).floor(), (-m * 3e4).floor());
            assert_eq!(odd_square(a, b), reference(a, b), "{a:e}, {b:e}");
        }
    }
}
