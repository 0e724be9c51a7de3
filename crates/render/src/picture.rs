//! What the renderer draws: spheres, rods (springs and joints' axles),
//! jellyfish bells, the floor and the water, made from the one drawing model (`animats_view::Drawing`)
//! that the live view's page draws too.

use animats_view::{BellShape, Drawing};
use glam::DVec3;

/// An RGB colour, components in [0, 1].
pub type Colour = DVec3;

/// A colour from 0xRRGGBB.
pub fn hex(c: u32) -> Colour {
    DVec3::new(
        f64::from((c >> 16) & 0xff),
        f64::from((c >> 8) & 0xff),
        f64::from(c & 0xff),
    ) / 255.0
}

/// A solid sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, m.
    pub centre: DVec3,
    /// Radius, m.
    pub radius: f64,
    /// Colour.
    pub colour: Colour,
    /// Whether it casts a shadow on the floor.
    pub shadow: bool,
}

/// A solid cylinder between two points (a spring).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rod {
    /// One end, m.
    pub a: DVec3,
    /// The other end, m.
    pub b: DVec3,
    /// Radius, m.
    pub radius: f64,
    /// Colour.
    pub colour: Colour,
}

/// A translucent half-ellipsoid (a jellyfish's bell): its rim is a circle
/// of `radius` around `centre` square to `axis`, its crown `height` along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bell {
    /// Centre of the rim, m.
    pub centre: DVec3,
    /// Unit vector from the rim to the crown.
    pub axis: DVec3,
    /// Rim radius, m.
    pub radius: f64,
    /// Crown height, m.
    pub height: f64,
    /// Colour.
    pub colour: Colour,
}

/// Everything in one picture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Picture {
    /// Spheres.
    pub spheres: Vec<Sphere>,
    /// Rods.
    pub rods: Vec<Rod>,
    /// Bells, drawn translucent over the rest.
    pub bells: Vec<Bell>,
    /// The floor at y = 0, checkered in squares of this size, m.
    pub floor: Option<f64>,
    /// The floor's shape instead of the plane y = 0: its triangles, drawn
    /// with the same checker, and the terrain, for the shadows' heights.
    pub ground: Option<(animats_view::GroundMesh, animats_engine::Terrain)>,
    /// Under water (tinted and fogged) rather than in air.
    pub water: bool,
    /// A caption for the top-left corner.
    pub caption: Option<String>,
}

/// The picture of `drawing` (`animats_view::Drawing`, the one drawing
/// model) with the particles at `positions`, its bells shaped as `bells`
/// says and its muscles coloured by the actuators' `levels` (scene order;
/// empty: every rod its own colour).
pub fn picture(
    drawing: &Drawing,
    positions: &[DVec3],
    bells: &[Option<BellShape>],
    levels: &[f64],
) -> Picture {
    let at = |i: usize| positions.get(i).copied().unwrap_or(DVec3::ZERO);
    let spheres = drawing
        .balls
        .iter()
        .enumerate()
        .map(|(i, b)| Sphere {
            centre: at(i),
            radius: b.radius,
            colour: hex(b.colour),
            shadow: b.shadow,
        })
        .collect();
    let mut rods: Vec<Rod> = drawing
        .rods
        .iter()
        .zip(drawing.rod_colours(levels))
        .map(|(r, colour)| Rod {
            a: at(r.a),
            b: at(r.b),
            radius: r.radius,
            colour: hex(colour),
        })
        .collect();
    // Joints: their axles, drawn as rods after the springs.
    rods.extend(
        drawing
            .axles
            .iter()
            .zip(drawing.axle_ends(positions))
            .zip(drawing.axle_colours(levels))
            .map(|((x, [a, b]), colour)| Rod {
                a: DVec3::from_array(a),
                b: DVec3::from_array(b),
                radius: x.radius,
                colour: hex(colour),
            }),
    );
    let bells = drawing
        .bells
        .iter()
        .zip(bells)
        .filter_map(|(plan, shape)| {
            let s = shape.as_ref()?;
            Some(Bell {
                centre: DVec3::from_array(s.centre),
                axis: DVec3::from_array(s.axis),
                radius: s.radius,
                height: s.height,
                colour: hex(plan.colour),
            })
        })
        .collect();
    Picture {
        spheres,
        rods,
        bells,
        floor: drawing.floor,
        ground: drawing.ground.clone().zip(drawing.terrain.clone()),
        water: drawing.water,
        caption: None,
    }
}
