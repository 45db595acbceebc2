//! Scene builders shared by the Rust integration tests.
#![allow(dead_code)]

pub mod counting;

use glam::{Quat, Vec3};
use kodawari::{ChainId, ChainParams, Engine, EngineSettings, Transform};

/// `n` joints from `root` along `direction` with spacing `segment`, identity rotations... except that each
/// joint's rotation turns +Y onto the chain direction, so bone axes are +Y like a typical rig.
pub fn straight_chain(n: usize, root: Vec3, direction: Vec3, segment: f32) -> Vec<Transform> {
    let dir = direction.normalize();
    let rotation = Quat::from_rotation_arc(Vec3::Y, dir);
    (0..n).map(|i| Transform::new(root + dir * (segment * i as f32), rotation)).collect()
}

/// A chain bent by `bend` radians per joint about `axis`, starting along `direction`.
pub fn curled_chain(n: usize, root: Vec3, direction: Vec3, axis: Vec3, bend: f32, segment: f32) -> Vec<Transform> {
    let mut joints = Vec::with_capacity(n);
    let mut p = root;
    let mut dir = direction.normalize();
    for _ in 0..n {
        let rotation = Quat::from_rotation_arc(Vec3::Y, dir);
        joints.push(Transform::new(p, rotation));
        p += dir * segment;
        dir = (Quat::from_axis_angle(axis.normalize(), bend) * dir).normalize();
    }
    joints
}

pub fn chain_length(joints: &[Transform]) -> f32 {
    joints.windows(2).map(|w| (w[1].position - w[0].position).length()).sum()
}

pub fn world(engine: &Engine) -> Vec<Transform> {
    let mut out = vec![Transform::IDENTITY; engine.joint_count()];
    engine.read_world(&mut out).unwrap();
    out
}

pub fn chain_world(engine: &Engine, id: ChainId) -> Vec<Transform> {
    let mut out = vec![Transform::IDENTITY; engine.chain_joint_count(id).unwrap()];
    engine.read_chain_world(id, &mut out).unwrap();
    out
}

/// Largest relative deviation of any segment from its length in `lengths`.
pub fn max_stretch(joints: &[Transform], lengths: &[f32]) -> f32 {
    joints
        .windows(2)
        .zip(lengths)
        .map(|(w, l)| ((w[1].position - w[0].position).length() / l - 1.0).abs())
        .fold(0.0, f32::max)
}

pub fn segment_lengths(joints: &[Transform]) -> Vec<f32> {
    joints.windows(2).map(|w| (w[1].position - w[0].position).length()).collect()
}

pub fn engine_with(settings: EngineSettings) -> Engine {
    Engine::new(settings).unwrap()
}

pub fn limp() -> ChainParams {
    ChainParams { stiffness: 0.0, damping: 0.0, ..Default::default() }
}

/// The view reference at `position`, unrotated.
pub fn at(position: Vec3) -> Transform {
    Transform::new(position, Quat::IDENTITY)
}

/// A camera on a horizontal circle of `radius` around `centre` at `angle` radians.
pub fn orbit_camera(centre: Vec3, radius: f32, angle: f32) -> Vec3 {
    centre + Vec3::new(radius * angle.cos(), 0.0, radius * angle.sin())
}
