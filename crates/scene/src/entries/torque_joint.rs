//! `[[torque_joint]]`.

use super::*;

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
