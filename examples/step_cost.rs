//! Cost of `Engine::step` per joint per internal substep, for a few scene sizes (scalar path, default
//! settings, camera orbiting). A quick baseline until the criterion benchmarks of the performance work land:
//! `cargo run --release --example step_cost`. Prints medians over repeated runs (the machine is shared).
//!
//! Two motions: a still head, where the upright chains only settle under gravity along their own axis (the
//! cheapest case: nothing bends or turns), and a head swaying 0.2 m at 1 Hz, where every chain bends and
//! every solver iteration does real work.
//!
//! `cargo run --release --example step_cost -- CHAINS JOINTS FRAMES [still|sway] [LENGTH]` runs one scene once for
//! a fixed workload (after one warm-up frame), for instruction counts, e.g.
//! `valgrind --tool=callgrind target/release/examples/step_cost 10 16 50 sway`; divide `Engine::step`'s
//! inclusive count by `CHAINS * (JOINTS - 1)` and by the substeps of all frames, warm-up included (printed).

use std::time::Instant;

use glam::{Quat, Vec3};
use kodawari::{ChainParams, Engine, EngineSettings, Transform};

/// Segment length of the default scenes (m).
const SPACING: f32 = 0.03;

fn scene(chains: usize, joints: usize, spacing: f32) -> Engine {
    let mut engine = Engine::new(EngineSettings::default()).expect("default settings are valid");
    // `KDW_SOLVER=scalar` measures the scalar reference solver instead of the lane solver, `portable` the lane
    // solver's portable (SSE2) kernel.
    match std::env::var("KDW_SOLVER").as_deref() {
        Ok("scalar") => engine.set_solver(kodawari::Solver::Scalar),
        Ok("portable") => engine.set_solver(kodawari::Solver::LanesPortable),
        _ => {}
    }
    let base: Vec<Transform> =
        (0..joints).map(|i| Transform::new(Vec3::new(0.0, 0.1 + spacing * i as f32, 0.0), Quat::IDENTITY)).collect();
    for _ in 0..chains {
        engine.create_chain(ChainParams::default(), &base).expect("valid chain");
    }
    engine
}

/// Steps frames `frames` at 60 fps with the camera orbiting the head (and the head swaying if `sway`).
fn run(engine: &mut Engine, frames: std::ops::Range<usize>, sway: bool) {
    for frame in frames {
        let t = frame as f32 / 60.0;
        let offset = if sway { 0.2 * (std::f32::consts::TAU * t).sin() } else { 0.0 };
        let head = Transform::new(Vec3::new(offset, 1.6, 0.0), Quat::IDENTITY);
        let angle = frame as f32 * 0.01;
        let camera = Vec3::new(0.0, 1.6, 0.0) + Vec3::new(3.0 * angle.cos(), 0.1, 3.0 * angle.sin());
        engine.step(1.0 / 60.0, camera, head).expect("valid step");
    }
}

/// Median seconds per frame over 7 rounds.
fn time_per_frame(chains: usize, joints: usize, sway: bool) -> (f64, f64) {
    let mut engine = scene(chains, joints, SPACING);
    let frames = (2_000_000 / (chains * joints)).clamp(60, 2000);
    let mut per_frame = Vec::new();
    for round in 0..7 {
        let start = Instant::now();
        run(&mut engine, round * frames..(round + 1) * frames, sway);
        per_frame.push(start.elapsed().as_secs_f64() / frames as f64);
    }
    per_frame.sort_by(f64::total_cmp);
    (per_frame[per_frame.len() / 2], engine.stats().substeps_last_step as f64)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() >= 3 {
        let number = |i: usize| args[i].parse::<usize>().expect("usage: step_cost CHAINS JOINTS FRAMES [still|sway]");
        let (chains, joints, frames) = (number(0), number(1), number(2));
        let sway = args.get(3).is_some_and(|m| m == "sway");
        // An optional fifth argument, the chain length in metres, makes fine ropes (e.g. 1000 joints in 0.8 m,
        // the performance report's 1 x 1000 scene).
        let spacing =
            args.get(4).map_or(SPACING, |l| l.parse::<f32>().expect("chain length in m") / (joints - 1) as f32);
        let mut engine = scene(chains, joints, spacing);
        let start = Instant::now();
        run(&mut engine, 0..frames + 1, sway);
        let elapsed = start.elapsed().as_secs_f64();
        let stats = engine.stats();
        let substeps = stats.substeps_total;
        println!(
            "{chains} chains x {joints} joints, {} frames ({}), {substeps} substeps, {} solver fallbacks: \
             {:.0} ns/joint/substep",
            frames + 1,
            if sway { "sway" } else { "still" },
            stats.solver_fallbacks,
            elapsed * 1e9 / ((chains * (joints - 1)) as f64 * substeps as f64),
        );
        return;
    }
    println!("{:>8} {:>7} {:>15} {:>15} {:>15} {:>15}", "", "", "still head", "", "swaying head", "");
    println!(
        "{:>8} {:>7} {:>15} {:>15} {:>15} {:>15}",
        "chains", "joints", "us per frame", "ns/joint/subst", "us per frame", "ns/joint/subst"
    );
    for (chains, joints) in [(1usize, 8usize), (100, 8), (100, 16), (1000, 16), (1, 256)] {
        let dynamic_joints = (chains * (joints - 1)) as f64;
        print!("{chains:>8} {joints:>7}");
        for sway in [false, true] {
            let (median, substeps) = time_per_frame(chains, joints, sway);
            print!(" {:>15.1} {:>15.0}", median * 1e6, median * 1e9 / (dynamic_joints * substeps));
        }
        println!();
    }
}
