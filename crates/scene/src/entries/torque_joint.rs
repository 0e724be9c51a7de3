//! `[[torque_joint]]`.

use super::*;

/// `[[torque_joint]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueJointEntry {
    /// Optional, unique among its kind: actuators refer to it by name.
    pub name: Option<String>,
    /// The mass turned.
    pub end: String,
    /// The mass it turns about.
    pub joint: String,
    /// Default `[0, 0, 1]`.
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
    /// N m, default 0.
    #[serde(default)]
    pub torque: f64,
}

fn default_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl Build for TorqueJointEntry {
    fn build(&self, _k: usize, at: &At, cx: &mut Builder) -> Result<(), SceneError> {
        let j = self;
        let jdef = TorqueJointDef {
            end: cx.names.one(at, "end", &j.end)?,
            joint: cx.names.one(at, "joint", &j.joint)?,
            axis: DVec3::from_array(j.axis),
            torque: j.torque,
        };
        let id = cx.world.add_torque_joint(jdef).map_err(|e| at.model(e))?;
        crate::nervous::insert(
            &mut cx.handles.torque_joints,
            at,
            "torque joint",
            &j.name,
            id,
        )?;

        Ok(())
    }
}
