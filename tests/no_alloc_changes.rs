//! No allocation in a step after a warm-up even when what the step runs changes (SPEC 6.3, issue 5): chains
//! longer than any stepped so far are enabled, chains move between lane groups and the scalar solver as others
//! are disabled, a slow frame needs the most substeps, and a fine rope's solver falls back. Buffers sized by
//! what a step happens to meet would grow on the first such frame, long after the warm-up; they are sized
//! when chains are created instead. A counting global allocator (`common::counting`) measures it; this file
//! holds one test so nothing else runs meanwhile.

mod common;

use common::counting::{Counting, allocations};
use common::*;
use glam::{Quat, Vec3};
use kodawari::{ChainId, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, Transform};

#[global_allocator]
static GLOBAL: Counting = Counting;

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);

struct Scene {
    engine: Engine,
    short: Vec<ChainId>,
    long: Vec<ChainId>,
}

/// Nine short chains (a lane group of eight and one for the scalar solver), nine long ones with view shapes
/// and a fine rope, all touching a head sphere; the long chains and the rope start disabled.
fn scene() -> Scene {
    let mut engine = engine_with(EngineSettings::default());
    let mut chain = |joints: usize, segment: f32, tilt: f32| {
        let direction = Vec3::new(tilt, -1.0, 0.2);
        engine.create_chain(ChainParams::default(), &straight_chain(joints, HEAD, direction, segment)).unwrap()
    };
    let short: Vec<ChainId> = (0..9).map(|c| chain(6, 0.03, 0.1 * c as f32)).collect();
    let mut long: Vec<ChainId> = (0..9).map(|c| chain(24, 0.02, -0.1 * c as f32)).collect();
    long.push(chain(300, 0.002, 0.5));
    for &id in &long[..9] {
        let side = curled_chain(24, HEAD, Vec3::new(0.0, -1.0, 0.2), Vec3::Z, 0.2, 0.02);
        engine.add_view_shape(id, Vec3::X, &side, 1.0).unwrap();
    }
    for &id in &long {
        engine.set_chain_enabled(id, false).unwrap();
    }
    let head = ColliderDef { shape: ColliderShape::Sphere { radius: 0.12 }, transform: at(HEAD), layers: 1 };
    engine.create_collider(&head).unwrap();
    Scene { engine, short, long }
}

fn frame(engine: &mut Engine, n: usize, dt: f32) {
    let angle = n as f32 * 0.05;
    let k = Transform::new(HEAD + Vec3::X * 0.1 * angle.sin(), Quat::from_rotation_y(0.5 * angle.cos()));
    engine.set_collider_transforms([Transform::new(k.position, Quat::IDENTITY)].into_iter()).unwrap();
    engine.step(dt, orbit_camera(HEAD, 3.0, angle), k).unwrap();
}

#[test]
fn a_step_allocates_nothing_when_what_it_runs_changes() {
    let Scene { mut engine, short, long } = scene();
    let mut out = vec![Transform::IDENTITY; engine.joint_count()];
    for n in 0..30 {
        frame(&mut engine, n, 1.0 / 60.0);
        engine.read_world(&mut out).unwrap();
    }
    let mut allocating_frames = Vec::new();
    let mut counted = |engine: &mut Engine, n: usize, dt: f32, what: &str| {
        let before = allocations();
        frame(engine, n, dt);
        engine.read_world(&mut out).unwrap();
        let made = allocations() - before;
        if made > 0 {
            allocating_frames.push(format!("{what} (frame {n}): {made}"));
        }
    };
    let mut n = 30;
    for &id in &long {
        engine.set_chain_enabled(id, true).unwrap();
    }
    for _ in 0..20 {
        counted(&mut engine, n, 1.0 / 60.0, "longer chains enabled");
        n += 1;
    }
    counted(&mut engine, n, 0.5, "a slow frame: the most substeps");
    n += 1;
    // Disabling chains of a kind moves the others between lane groups of 8 and 4 and the scalar solver.
    for (i, &id) in short.iter().chain(&long[..9]).enumerate() {
        engine.set_chain_enabled(id, i % 3 != 0).unwrap();
        counted(&mut engine, n, 1.0 / 60.0, "chains moved between groups");
        n += 1;
    }
    assert!(engine.stats().contact_pairs_tested > 0, "the chains touch the head");
    assert!(engine.stats().solver_fallbacks > 0, "the rope's direct solve falls back");
    assert!(allocating_frames.is_empty(), "{allocating_frames:#?}");
}
