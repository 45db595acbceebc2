//! Character-level robustness (SPEC 3.9, issue 6): teleports, engine scale, time scale and pause. Each
//! test prints its figure (`cargo test --test character -- --nocapture`).

mod common;

use common::*;
use glam::Vec3;
use kodawari::{ChainId, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, TeleportMode, Transform};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const CAMERA_OFFSET: Vec3 = Vec3::new(0.0, 0.0, 3.0);

/// Joint positions relative to the anchor `k` (translation only: the anchors here do not turn).
fn relative(engine: &Engine, id: ChainId, k: Vec3) -> Vec<Vec3> {
    chain_world(engine, id).iter().map(|t| t.position - k).collect()
}

fn max_difference(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().zip(b).map(|(a, b)| (*a - *b).length()).fold(0.0, f32::max)
}

/// A swinging chain whose character jumps 100 m (detected, carry mode) moves on exactly as if it had not
/// jumped: same pose relative to the anchor, same kinetic energy. Nothing is injected.
#[test]
fn hundred_metre_jump_injects_no_energy() {
    let run = |jump: bool| {
        let mut engine = engine_with(EngineSettings::default());
        let id = engine.create_chain(limp(), &straight_chain(8, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
        let mut k = HEAD;
        let mut poses = Vec::new();
        for frame in 0..120 {
            if jump && frame == 30 {
                k += Vec3::new(100.0, 0.0, -60.0);
            }
            engine.step(1.0 / 60.0, k + CAMERA_OFFSET, at(k)).unwrap();
            poses.push((relative(&engine, id, k), engine.chain_kinetic_energy(id).unwrap()));
        }
        poses
    };
    let (still, jumped) = (run(false), run(true));
    let mut worst_pose = 0.0f32;
    let mut worst_energy = 0.0f32;
    for ((a, ea), (b, eb)) in still.iter().zip(&jumped) {
        worst_pose = worst_pose.max(max_difference(a, b));
        worst_energy = worst_energy.max((ea - eb).abs() / ea.max(1e-6));
    }
    println!(
        "100 m jump: max pose difference {worst_pose:.2e} m, max relative kinetic energy difference {worst_energy:.2e}"
    );
    assert!(worst_pose <= 1e-4 && worst_energy <= 1e-3, "{worst_pose} {worst_energy}");
}

/// In reset mode a detected jump puts the chain at its rest shape, at rest.
#[test]
fn reset_mode_puts_the_chain_at_rest() {
    let settings = EngineSettings { teleport_mode: TeleportMode::Reset, ..Default::default() };
    let mut engine = engine_with(settings);
    let base = straight_chain(8, Vec3::ZERO, Vec3::X, 0.05);
    let id = engine.create_chain(limp(), &base).unwrap();
    for _ in 0..30 {
        engine.step(1.0 / 60.0, HEAD + CAMERA_OFFSET, at(HEAD)).unwrap();
    }
    assert!(engine.chain_kinetic_energy(id).unwrap() > 0.1);
    let far = HEAD + Vec3::new(0.0, 0.0, 100.0);
    engine.step(1.0 / 60.0, far + CAMERA_OFFSET, at(far)).unwrap();
    // One step after the reset: at most one frame of gravity, from the rest shape.
    let energy = engine.chain_kinetic_energy(id).unwrap();
    let expected_energy = 0.5 * 7.0 * (9.81f32 * (1.0 / 60.0)).powi(2);
    println!(
        "reset mode: kinetic energy one frame after a 100 m jump {energy:.3e} J (free fall for a frame: {expected_energy:.3e})"
    );
    assert!(energy <= expected_energy * 1.01, "{energy}");
}

/// An explicit teleport carries the chain even for a jump below the thresholds: the pose relative to the
/// anchor is what it would have been without the jump.
#[test]
fn explicit_teleport_carries_small_jumps() {
    let run = |teleport: bool| {
        let mut engine = engine_with(EngineSettings::default());
        let id = engine.create_chain(limp(), &straight_chain(8, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
        let mut k = HEAD;
        for frame in 0..60 {
            if frame == 20 {
                k += Vec3::new(0.5, 0.0, 0.0);
                if teleport {
                    engine.teleport_all();
                }
            }
            engine.step(1.0 / 60.0, k + CAMERA_OFFSET, at(k)).unwrap();
        }
        relative(&engine, id, k)
    };
    let mut engine = engine_with(EngineSettings::default());
    let id = engine.create_chain(limp(), &straight_chain(8, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
    for _ in 0..60 {
        engine.step(1.0 / 60.0, HEAD + CAMERA_OFFSET, at(HEAD)).unwrap();
    }
    let still = relative(&engine, id, HEAD);
    let (carried, whipped) = (run(true), run(false));
    println!(
        "0.5 m jump: with explicit teleport {:.2e} m from the unmoved run, without {:.2e} m",
        max_difference(&carried, &still),
        max_difference(&whipped, &still)
    );
    assert!(max_difference(&carried, &still) <= 1e-4);
    assert!(max_difference(&whipped, &still) > 0.01, "without the call the jump whips the chain");
}

/// A character scaled by 0.01 or 100 with the engine's scale set to match moves exactly like the unscaled
/// one: positions agree within 1e-4 of the chain length, with a collider in the scene.
#[test]
fn scaled_character_behaves_the_same() {
    let run = |scale: f32| {
        let settings = EngineSettings { scale, ..Default::default() };
        let mut engine = engine_with(settings);
        let base: Vec<Transform> = straight_chain(8, Vec3::ZERO, Vec3::new(1.0, -0.3, 0.2), 0.05)
            .into_iter()
            .map(|t| Transform::new(t.position * scale, t.rotation))
            .collect();
        let params = ChainParams { stiffness: 0.3, ..Default::default() };
        let id = engine.create_chain(params, &base).unwrap();
        let sphere = ColliderDef {
            shape: ColliderShape::Sphere { radius: 0.06 * scale },
            transform: at(Vec3::new(0.15, -0.2, 0.0) * scale),
            layers: 1,
        };
        engine.create_collider(&sphere).unwrap();
        let mut trace = Vec::new();
        for frame in 0..120 {
            let time = frame as f32 / 60.0;
            let k = Vec3::new(0.2 * (std::f32::consts::TAU * time).sin(), 0.0, 0.0) * scale;
            engine.step(1.0 / 60.0, k + CAMERA_OFFSET * scale, at(k)).unwrap();
            trace.push(chain_world(&engine, id).iter().map(|t| t.position / scale).collect::<Vec<_>>());
        }
        trace
    };
    let reference = run(1.0);
    for scale in [0.01f32, 100.0] {
        let scaled = run(scale);
        let per_frame: Vec<f32> = reference.iter().zip(&scaled).map(|(a, b)| max_difference(a, b)).collect();
        if std::env::var("KDW_DEBUG").is_ok() {
            println!("{:?}", per_frame.iter().map(|d| format!("{d:.1e}")).collect::<Vec<_>>());
        }
        let worst = per_frame.iter().copied().fold(0.0, f32::max);
        let relative_error = worst / 0.35;
        println!("scale {scale}: max difference from the unscaled run {relative_error:.2e} chain lengths");
        assert!(relative_error <= 1e-4, "scale {scale}: {relative_error}");
    }
}

/// Time scale 0 freezes everything: the state hash does not move over 600 frames, and the chain follows
/// a moving character rigidly.
#[test]
fn time_scale_zero_freezes_without_drift() {
    let mut engine = engine_with(EngineSettings::default());
    let id = engine.create_chain(limp(), &straight_chain(8, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
    for _ in 0..20 {
        engine.step(1.0 / 60.0, HEAD + CAMERA_OFFSET, at(HEAD)).unwrap();
    }
    engine.set_settings(EngineSettings { time_scale: 0.0, ..*engine.settings() }).unwrap();
    engine.step(1.0 / 60.0, HEAD + CAMERA_OFFSET, at(HEAD)).unwrap();
    let (hash, pose) = (engine.state_hash(), relative(&engine, id, HEAD));
    for _ in 0..600 {
        engine.step(1.0 / 60.0, HEAD + CAMERA_OFFSET, at(HEAD)).unwrap();
    }
    assert_eq!(engine.state_hash(), hash, "paused engine drifted");
    let moved = HEAD + Vec3::new(0.3, 0.1, 0.0);
    engine.step(1.0 / 60.0, moved + CAMERA_OFFSET, at(moved)).unwrap();
    let difference = max_difference(&relative(&engine, id, moved), &pose);
    println!("paused: pose relative to a moved character changed by {difference:.2e} m");
    assert!(difference <= 1e-6);
}

/// Slow motion at 0.1 is the same motion slowed: the chain's trajectory under a root moving with simulated
/// time matches the real-time run sampled at the same simulated times.
#[test]
fn slow_motion_is_the_same_motion_slowed() {
    let run = |time_scale: f32, frames: usize, every: usize| {
        let settings = EngineSettings { time_scale, ..Default::default() };
        let mut engine = engine_with(settings);
        let id = engine.create_chain(limp(), &straight_chain(8, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
        let mut samples = Vec::new();
        for frame in 1..=frames {
            // After 0.1 s standing still (both runs place the chain at the same pose), the root slides along x
            // at 0.5 m per simulated second: piecewise linear in simulated time with its kink on a frame
            // boundary of both runs, so the engine's interpolation between frames is exact at both rates.
            let simulated = frame as f32 / 60.0 * time_scale;
            let k = HEAD + Vec3::X * 0.5 * (simulated - 0.1).max(0.0);
            engine.step(1.0 / 60.0, k + CAMERA_OFFSET, at(k)).unwrap();
            if frame % every == 0 {
                samples.push(relative(&engine, id, k));
            }
        }
        samples
    };
    let normal = run(1.0, 60, 1);
    let slow = run(0.1, 600, 10);
    let worst = normal.iter().zip(&slow).map(|(a, b)| max_difference(a, b)).fold(0.0, f32::max);
    println!("slow motion 0.1 vs real time, 1 simulated second: max difference {:.2e} chain lengths", worst / 0.35);
    assert!(worst / 0.35 <= 1e-4, "{worst}");
}

/// A scale outside its range and a teleport of an unknown chain are rejected and change nothing.
#[test]
fn scale_and_teleport_settings_are_validated() {
    for scale in [0.0f32, -1.0, f32::NAN, f32::INFINITY, 1e7] {
        assert!(Engine::new(EngineSettings { scale, ..Default::default() }).is_err(), "scale {scale}");
    }
    let mut engine = engine_with(EngineSettings::default());
    let id = engine.create_chain(limp(), &straight_chain(4, Vec3::ZERO, Vec3::X, 0.05)).unwrap();
    let hash = engine.state_hash();
    assert!(engine.set_settings(EngineSettings { scale: f32::NAN, ..Default::default() }).is_err());
    assert!(engine.teleport_chain(kodawari::ChainId::from_bits(id.to_bits() ^ 1)).is_err());
    assert_eq!(engine.state_hash(), hash);
    engine.teleport_chain(id).unwrap();
    assert_ne!(engine.state_hash(), hash, "a requested teleport is state");
}
