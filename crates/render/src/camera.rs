//! A pinhole camera: where it is, what it looks at, and how wide it sees.
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use glam::DVec3;

/// A perspective camera with the world's +y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the eye is, m.
    pub eye: DVec3,
    /// The point at the centre of the picture, m.
    pub target: DVec3,
    /// Vertical field of view, degrees.
    pub fov_y: f64,
}

impl Camera {
    /// Looking at `target` from `distance` metres away, from the direction
    /// the live view starts from (front right, 21° up).
    pub fn framing(target: DVec3, distance: f64) -> Camera {
        Camera {
            eye: target + DIRECTION.normalize() * distance,
            target,
            fov_y: 50.0,
        }
    }
}

/// The live view's default viewing direction (from the target to the eye).
pub const DIRECTION: DVec3 = DVec3::new(0.55, 0.45, 1.0);

/// A camera fixed to an image size: casts rays and projects points.
#[derive(Clone, Copy, Debug)]
pub struct View {
    /// The eye.
    pub eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half: f64,
    aspect: f64,
    width: f64,
    height: f64,
}

impl View {
    /// The camera on an image of `width` × `height` pixels.
    pub fn new(camera: &Camera, width: u32, height: u32) -> View {
        let forward = (camera.target - camera.eye)
            .try_normalize()
            .unwrap_or(DVec3::NEG_Z);
        // Looking straight up or down, "up" on the picture is -z.
        let right = forward.cross(DVec3::Y).try_normalize().unwrap_or(DVec3::X);
        let up = right.cross(forward);
        View {
            eye: camera.eye,
            forward,
            right,
            up,
            tan_half: (camera.fov_y.clamp(1.0, 170.0).to_radians() / 2.0).tan(),
            aspect: f64::from(width) / f64::from(height.max(1)),
            width: f64::from(width),
            height: f64::from(height),
        }
    }

    /// The unit ray through the point (px, py) of the image (pixel centres
    /// are at half-integers).
    pub fn ray(&self, px: f64, py: f64) -> DVec3 {
        (self.column(px) + self.row(py)).normalize()
    }

    /// The part of [`Self::ray`] (before its normalisation) that depends
    /// only on `px`: the renderer computes it once for each column.
    pub fn column(&self, px: f64) -> DVec3 {
        let x = (2.0 * px / self.width - 1.0) * self.tan_half * self.aspect;
        self.forward + self.right * x
    }

    /// The part of [`Self::ray`] that depends only on `py`, added last.
    pub fn row(&self, py: f64) -> DVec3 {
        let y = (1.0 - 2.0 * py / self.height) * self.tan_half;
        self.up * y
    }

    /// Where `p` appears on the image (x, y in pixels) and its depth along
    /// the view axis; None behind the eye.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64, f64)> {
        let d = p - self.eye;
        let z = d.dot(self.forward);
        if z <= 1e-9 {
            return None;
        }
        let x = d.dot(self.right) / (z * self.tan_half * self.aspect);
        let y = d.dot(self.up) / (z * self.tan_half);
        Some((
            (x + 1.0) / 2.0 * self.width,
            (1.0 - y) / 2.0 * self.height,
            z,
        ))
    }

    /// Pixels per metre at depth `z`.
    pub fn scale(&self, z: f64) -> f64 {
        self.height / (2.0 * self.tan_half * z)
    }

    /// Depth along the view axis of `p`.
    pub fn depth(&self, p: DVec3) -> f64 {
        (p - self.eye).dot(self.forward)
    }
}
