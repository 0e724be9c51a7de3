//! `[[angle_joint]]`.

use super::*;

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
