//! `[[angle_joint]]`.

use super::*;

/// `[[angle_joint]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleJointEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// End of the first arm.
    pub a: String,
    /// Where the arms meet.
    pub joint: String,
    /// End of the second arm.
    pub b: String,
    /// N m/rad, >= 0.
    pub stiffness: f64,
    /// N m s/rad, >= 0, default 0.
    #[serde(default)]
    pub damping: f64,
    /// rad in [0, π]; default the initial angle.
    pub rest_angle: Option<f64>,
}

impl Build for AngleJointEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let j = self;
        let jdef = AngleJointDef {
            a: cx.names.one(at, "a", &j.a)?,
            joint: cx.names.one(at, "joint", &j.joint)?,
            b: cx.names.one(at, "b", &j.b)?,
            stiffness: j.stiffness,
            damping: j.damping,
            rest_angle: j.rest_angle,
        };
        let id = cx.world.add_angle_joint(jdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(&mut cx.handles.angle_joints, at, "angle joint", &j.name, id)?;

        Ok(())
    }
}
