//! Cost of `Engine::step` per joint per internal substep, for a few scene sizes (scalar path, default
//! settings, camera orbiting). A quick baseline until the criterion benchmarks of the performance work land:
//! `cargo run --release --example step_cost`. Prints medians over repeated runs (the machine is shared).

use std::time::Instant;

use glam::{Quat, Vec3};
use kodawari::{ChainParams, Engine, EngineSettings, Transform};

fn scene(chains: usize, joints: usize) -> Engine {
    let mut engine = Engine::new(EngineSettings::default()).expect("default settings are valid");
    let base: Vec<Transform> =
        (0..joints).map(|i| Transform::new(Vec3::new(0.0, 0.1 + 0.03 * i as f32, 0.0), Quat::IDENTITY)).collect();
    for _ in 0..chains {
        engine.create_chain(ChainParams::default(), &base).expect("valid chain");
    }
    engine
}

fn main() {
    let head = Transform::new(Vec3::new(0.0, 1.6, 0.0), Quat::IDENTITY);
    println!("{:>10} {:>8} {:>14} {:>16}", "chains", "joints", "us per frame", "ns/joint/substep");
    for (chains, joints) in [(1usize, 8usize), (100, 8), (100, 16), (1000, 16), (1, 256)] {
        let mut engine = scene(chains, joints);
        let frames = (2_000_000 / (chains * joints)).clamp(60, 2000);
        let mut per_frame = Vec::new();
        for round in 0..7 {
            let start = Instant::now();
            for frame in 0..frames {
                let angle = (round * frames + frame) as f32 * 0.01;
                let camera = head.position + Vec3::new(3.0 * angle.cos(), 0.1, 3.0 * angle.sin());
                engine.step(1.0 / 60.0, camera, head).expect("valid step");
            }
            per_frame.push(start.elapsed().as_secs_f64() / frames as f64);
        }
        per_frame.sort_by(f64::total_cmp);
        let median = per_frame[per_frame.len() / 2];
        let substeps = engine.stats().substeps_last_step as f64;
        let dynamic_joints = (chains * (joints - 1)) as f64;
        println!(
            "{chains:>10} {joints:>8} {:>14.1} {:>16.0}",
            median * 1e6,
            median * 1e9 / (dynamic_joints * substeps)
        );
    }
}
