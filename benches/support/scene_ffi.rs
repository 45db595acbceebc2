//! A scene built and driven only through the C ABI (`kodawari::ffi`, the functions `include/kodawari.h`
//! declares), exactly as a C or Unity host calls them, for the C ABI overhead comparison. The chains, anchors
//! and camera are those of [`scenes`](super::scenes), so the Rust-side [`SceneRun`](super::scenes::SceneRun)
//! does the same work.
#![allow(dead_code)]

use std::ptr;

use kodawari::ffi::chain::{kdw_chain_create, kdw_chain_def_default};
use kodawari::ffi::engine::{
    kdw_engine, kdw_engine_create, kdw_engine_def_default, kdw_engine_destroy, kdw_engine_read_world,
    kdw_engine_set_anchors, kdw_engine_step, kdw_engine_step_and_read,
};
use kodawari::ffi::status::{KDW_STATUS_OK, kdw_status};
use kodawari::ffi::types::{KDW_ANCHOR_OWN, kdw_quat, kdw_transform, kdw_vec3};
use kodawari::ffi::view_shape::kdw_chain_add_view_shape;

use super::scenes::{CameraMotion, FRAME_DT, Layout, Scene, camera_position, frame_time, head_pose};

/// How the host spends its native calls per frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FfiFrame {
    /// One call: `kdw_engine_step_and_read` (anchors in, local rotations out), the Unity path.
    StepAndRead,
    /// Three calls: `kdw_engine_set_anchors`, `kdw_engine_step`, `kdw_engine_read_world`.
    SetAnchorsStepReadWorld,
}

fn check(status: kdw_status, what: &str) {
    assert_eq!(status, KDW_STATUS_OK, "{what} failed with status {status}");
}

/// An engine owned through its C handle.
pub struct FfiSceneRun {
    engine: *mut kdw_engine,
    layout: Layout,
    camera: CameraMotion,
    mode: FfiFrame,
    frame: u64,
    heads: Vec<kdw_transform>,
    anchors: Vec<kdw_transform>,
    world: Vec<kdw_transform>,
    rotations: Vec<kdw_quat>,
}

impl FfiSceneRun {
    /// `scene` with `view_shapes` view shapes per chain and no colliders, at default settings.
    pub fn new(scene: &Scene, view_shapes: usize, camera: CameraMotion, mode: FfiFrame) -> Self {
        let def = kdw_engine_def_default();
        let mut engine = ptr::null_mut();
        check(kdw_engine_create(&def, &mut engine), "kdw_engine_create");
        let layout = Layout::new(scene);
        let mut chain_def = kdw_chain_def_default();
        chain_def.anchor = KDW_ANCHOR_OWN;
        for i in 0..scene.chains {
            let (base, views) = layout.shapes(i, view_shapes);
            let base: Vec<kdw_transform> = base.into_iter().map(Into::into).collect();
            let mut chain = 0;
            check(
                kdw_chain_create(engine, &chain_def, base.as_ptr(), base.len() as u32, &mut chain),
                "kdw_chain_create",
            );
            for (from, joints) in views {
                let joints: Vec<kdw_transform> = joints.into_iter().map(Into::into).collect();
                let from = kdw_vec3::from(from);
                let mut view = 0;
                let status = kdw_chain_add_view_shape(
                    engine,
                    chain,
                    &from,
                    joints.as_ptr(),
                    joints.len() as u32,
                    1.0,
                    &mut view,
                );
                check(status, "kdw_chain_add_view_shape");
            }
        }
        let joints = layout.joint_counts.iter().sum();
        Self {
            engine,
            camera,
            mode,
            frame: 0,
            heads: vec![kdw_transform::default(); layout.characters],
            anchors: vec![kdw_transform::default(); scene.chains],
            world: vec![kdw_transform::default(); joints],
            rotations: vec![kdw_quat::default(); joints],
            layout,
        }
    }

    /// One host frame through the C ABI, the same inputs as [`SceneRun::frame`](super::scenes::SceneRun).
    pub fn frame(&mut self) {
        let t = frame_time(self.frame);
        self.frame += 1;
        for (c, head) in self.heads.iter_mut().enumerate() {
            *head = head_pose(c, t).into();
        }
        for (anchor, &c) in self.anchors.iter_mut().zip(&self.layout.character_of) {
            *anchor = self.heads[c];
        }
        let k = self.heads[0];
        let camera = kdw_vec3::from(camera_position(&k.into(), self.camera, t));
        let mut written = 0;
        match self.mode {
            FfiFrame::StepAndRead => {
                let status = kdw_engine_step_and_read(
                    self.engine,
                    FRAME_DT,
                    &camera,
                    &k,
                    self.anchors.as_ptr(),
                    self.anchors.len() as u32,
                    self.rotations.as_mut_ptr(),
                    self.rotations.len() as u32,
                    &mut written,
                );
                check(status, "kdw_engine_step_and_read");
            }
            FfiFrame::SetAnchorsStepReadWorld => {
                let anchors = self.anchors.len() as u32;
                check(kdw_engine_set_anchors(self.engine, self.anchors.as_ptr(), anchors), "kdw_engine_set_anchors");
                check(kdw_engine_step(self.engine, FRAME_DT, &camera, &k), "kdw_engine_step");
                let capacity = self.world.len() as u32;
                let status = kdw_engine_read_world(self.engine, self.world.as_mut_ptr(), capacity, &mut written);
                check(status, "kdw_engine_read_world");
            }
        }
    }
}

impl Drop for FfiSceneRun {
    fn drop(&mut self) {
        check(kdw_engine_destroy(self.engine), "kdw_engine_destroy");
    }
}
