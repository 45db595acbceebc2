//! Physical properties of the engine through its Rust API (SPEC 3.4-3.6, 6.1). Each test prints the
//! figure it measures (`cargo test --test physics -- --nocapture`).

mod common;

use common::*;
#[path = "../benches/support/pendulum.rs"]
mod pendulum;

use glam::{Quat, Vec3};
use kodawari::{ChainParams, EngineSettings, Solver, Transform};
use pendulum::{Pendulum, Tolerance};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);

/// A limp 9-joint chain released horizontally swings hard; every segment keeps its length within 1e-4, also
/// in the interpolated output at render rates that do not divide the substep rate.
#[test]
fn swinging_chain_is_inextensible() {
    for fps in [60.0f32, 144.0, 100.0] {
        let mut engine = engine_with(EngineSettings::default());
        let base = straight_chain(9, Vec3::ZERO, Vec3::X, 0.1);
        let lengths = segment_lengths(&base);
        let id = engine.create_chain(limp(), &base).unwrap();
        let mut worst = 0.0f32;
        for _ in 0..(4.0 * fps) as usize {
            engine.step(1.0 / fps, Vec3::new(0.0, 0.0, 5.0), at(HEAD)).unwrap();
            worst = worst.max(max_stretch(&chain_world(&engine, id), &lengths));
        }
        println!("max relative stretch, 9-joint limp chain, 4 s at {fps} fps: {worst:.2e}");
        assert!(worst <= 1e-4, "stretch {worst} at {fps} fps");
    }
}

/// Fine ropes: 0.8 m in 100 and 256 segments, released straight at 45 degrees, swaying with the head. The per-substep
/// multipliers are many segment lengths here, so the direct (symplectic) solve fails on most substeps; the
/// fallback must still leave every segment within 1e-4 of its length (Gauss-Seidel alone stretched the
/// 256-joint rope by 170%). Both solvers: the lane solver (four ropes, one group) hands a failed lane to the same
/// fallback.
#[test]
fn fine_rope_stays_inextensible_when_the_direct_solve_fails() {
    for solver in [Solver::Lanes, Solver::Scalar] {
        for joints in [100usize, 256] {
            let mut engine = engine_with(EngineSettings::default());
            engine.set_solver(solver);
            let segment = 0.8 / (joints - 1) as f32;
            let base = straight_chain(joints, Vec3::ZERO, Vec3::new(1.0, -1.0, 0.0), segment);
            let lengths = segment_lengths(&base);
            let copies = if solver == Solver::Lanes { 4 } else { 1 };
            let ids: Vec<_> =
                (0..copies).map(|_| engine.create_chain(ChainParams::default(), &base).unwrap()).collect();
            let mut worst = 0.0f32;
            for frame in 0..600 {
                let t = frame as f32 / 60.0;
                let sway = Vec3::new(0.04 * (std::f32::consts::PI * t).sin(), 0.0, 0.0);
                engine.step(1.0 / 60.0, Vec3::new(0.0, 0.0, 5.0), at(HEAD + sway)).unwrap();
                for &id in &ids {
                    worst = worst.max(max_stretch(&chain_world(&engine, id), &lengths));
                }
            }
            let fallbacks = engine.stats().solver_fallbacks;
            let substeps = engine.stats().substeps_total;
            println!(
                "{solver:?} solver, {copies} x {joints}-joint 0.8 m rope, 10 s: max relative stretch {worst:.2e}, fallback in {fallbacks} of {} chain-substeps",
                substeps * copies
            );
            assert!(fallbacks > 0, "the scene no longer exercises the fallback");
            let in_lanes = if solver == Solver::Lanes { copies as u32 } else { 0 };
            assert_eq!(engine.stats().lane_chains, in_lanes);
            assert!(worst <= 1e-4, "stretch {worst} with {joints} joints ({solver:?})");
        }
    }
}

/// A single pendulum's small-angle period is 2 pi sqrt(L / g).
#[test]
fn pendulum_period_matches_theory() {
    let settings = EngineSettings::default();
    let mut engine = engine_with(settings);
    let length = 0.5f32;
    let angle = 0.05f32;
    let base = vec![
        Transform::new(Vec3::ZERO, Quat::IDENTITY),
        Transform::new(Vec3::new(length * angle.sin(), -length * angle.cos(), 0.0), Quat::IDENTITY),
    ];
    let id = engine.create_chain(limp(), &base).unwrap();
    let dt = 1.0 / 960.0;
    let mut previous_x = f32::NAN;
    let mut crossings = Vec::new();
    for frame in 0..(960 * 4) {
        engine.step(dt, Vec3::new(0.0, 0.0, 5.0), at(HEAD)).unwrap();
        let x = chain_world(&engine, id)[1].position.x;
        if previous_x > 0.0 && x <= 0.0 {
            // Linear interpolation of the downward zero crossing.
            crossings.push((frame as f32 - 1.0 + previous_x / (previous_x - x)) * dt);
        }
        previous_x = x;
    }
    let periods: Vec<f32> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    let measured = periods.iter().sum::<f32>() / periods.len() as f32;
    // Small-angle period with the first finite-amplitude correction (1 + theta^2 / 16).
    let theory = 2.0 * std::f32::consts::PI * (length / 9.81f32).sqrt() * (1.0 + angle * angle / 16.0);
    println!(
        "pendulum period: measured {measured:.6} s, theory {theory:.6} s, relative error {:.2e}",
        measured / theory - 1.0
    );
    assert!((measured / theory - 1.0).abs() < 1e-3);
}

/// Without gravity and with a still root, a chain settles onto the blended rest shape.
#[test]
fn settles_to_blended_rest_shape() {
    let settings = EngineSettings { gravity: Vec3::ZERO, ..Default::default() };
    let mut engine = engine_with(settings);
    let base = straight_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, 0.03);
    let left = curled_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, Vec3::Z, 0.25, 0.03);
    let right = curled_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, -Vec3::Z, 0.15, 0.03);
    let id = engine.create_chain(ChainParams::default(), &base).unwrap();
    engine.add_view_shape(id, -Vec3::X, &left, 1.0).unwrap();
    engine.add_view_shape(id, Vec3::X, &right, 2.0).unwrap();
    // Start seen from one side, then park the camera at an oblique view so the rest shape is a blend.
    engine.step(1.0 / 60.0, HEAD + Vec3::new(-3.0, 0.0, 0.0), at(HEAD)).unwrap();
    let camera = HEAD + Vec3::new(1.0, 0.2, 1.5);
    for _ in 0..(60 * 30) {
        engine.step(1.0 / 60.0, camera, at(HEAD)).unwrap();
    }
    let mut rest = vec![Transform::IDENTITY; 8];
    engine.chain_rest_shape(id, &mut rest).unwrap();
    let out = chain_world(&engine, id);
    let length = chain_length(&base);
    let error =
        out.iter().zip(&rest).map(|(o, r)| (o.position - (HEAD + r.position)).length()).fold(0.0, f32::max) / length;
    let bend = (rest[7].position - base[7].position).length() / length;
    println!(
        "rest fidelity: max joint error {error:.2e} chain lengths (blend differs from base by {bend:.2} chain lengths)"
    );
    assert!(bend > 0.1, "the blend must differ from the base for this test to mean anything");
    assert!(error <= 1e-5, "error {error}");
}

/// Root swaying 0.2 m at 1 Hz for 3 s: the tip's path at 30, 60, 144 and 240 fps matches the 960 fps run.
#[test]
fn frame_rate_invariance() {
    let base = curled_chain(9, Vec3::ZERO, Vec3::new(1.0, -1.0, 0.0), Vec3::Z, 0.1, 0.05);
    let length = chain_length(&base);
    let duration = 3.5f64;
    let run = |fps: u32| -> Vec<(f64, Vec3)> {
        let mut engine = engine_with(EngineSettings::default());
        let id = engine.create_chain(ChainParams::default(), &base).unwrap();
        let frames = (duration * fps as f64).round() as u32;
        let mut tips = Vec::with_capacity(frames as usize);
        for frame in 1..=frames {
            let t = frame as f64 / fps as f64;
            // Still until 0.5 s (a frame boundary at every rate), so every run starts from the same state
            // whenever its first frame lands.
            let phase = (t - 0.5).max(0.0);
            let root = HEAD + Vec3::new(0.2 * (2.0 * std::f64::consts::PI * phase).sin() as f32, 0.0, 0.0);
            engine.step(1.0 / fps as f32, root + Vec3::new(0.0, 0.0, 3.0), at(root)).unwrap();
            tips.push((t, chain_world(&engine, id)[8].position));
        }
        tips
    };
    let reference = run(960);
    for fps in [30u32, 60, 144, 240] {
        let tips = run(fps);
        let common = gcd(fps, 960);
        let (stride, ref_stride) = ((fps / common) as usize, (960 / common) as usize);
        let (mut sum, mut count, mut worst) = (0.0f32, 0usize, 0.0f32);
        for (i, (t, tip)) in tips.iter().enumerate().skip(stride - 1).step_by(stride) {
            let (rt, rtip) = reference[(i + 1) / stride * ref_stride - 1];
            assert!((t - rt).abs() < 1e-9);
            let e = (*tip - rtip).length() / length;
            sum += e * e;
            count += 1;
            worst = worst.max(e);
        }
        let rms = (sum / count as f32).sqrt();
        println!("frame-rate invariance at {fps} fps vs 960: RMS tip error {rms:.2e}, max {worst:.2e} chain lengths");
        assert!(rms <= 0.01, "{fps} fps: rms {rms}");
    }
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Camera orbiting at 180 deg/s around a chain with two view shapes, no gravity: momentum suppression
/// keeps the chain from whipping.
#[test]
fn momentum_suppression_tames_orbiting_camera() {
    let base = straight_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, 0.04);
    let left = curled_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, Vec3::Z, 0.3, 0.04);
    let right = curled_chain(8, Vec3::new(0.0, 0.1, 0.0), Vec3::Y, -Vec3::Z, 0.3, 0.04);
    let length = chain_length(&base);
    let run = |stiffness: f32, suppression: f32| -> (f32, f32, f32) {
        let settings = EngineSettings { gravity: Vec3::ZERO, ..Default::default() };
        let mut engine = engine_with(settings);
        let params = ChainParams { stiffness, momentum_suppression: suppression, damping: 0.0, ..Default::default() };
        let id = engine.create_chain(params, &base).unwrap();
        engine.add_view_shape(id, -Vec3::X, &left, 1.0).unwrap();
        engine.add_view_shape(id, Vec3::X, &right, 1.0).unwrap();
        let (mut peak, mut worst_track) = (0.0f32, 0.0f32);
        let mut rest = vec![Transform::IDENTITY; 8];
        for frame in 0..120 {
            let angle = std::f32::consts::PI * frame as f32 / 60.0;
            engine.step(1.0 / 60.0, orbit_camera(HEAD, 3.0, angle), at(HEAD)).unwrap();
            peak = peak.max(engine.chain_kinetic_energy(id).unwrap());
            engine.chain_rest_shape(id, &mut rest).unwrap();
            let out = chain_world(&engine, id);
            let track =
                out.iter().zip(&rest).map(|(o, r)| (o.position - (HEAD + r.position)).length()).fold(0.0, f32::max);
            worst_track = worst_track.max(track / length);
        }
        // The orbit stops: what energy is left?
        let stop_angle = std::f32::consts::PI * 2.0;
        engine.step(1.0 / 60.0, orbit_camera(HEAD, 3.0, stop_angle), at(HEAD)).unwrap();
        let residual = engine.chain_kinetic_energy(id).unwrap();
        (peak, residual, worst_track)
    };
    for stiffness in [0.1f32, 0.5, 0.9, 0.99, 1.0] {
        let (peak_on, residual_on, track_on) = run(stiffness, 1.0);
        let (peak_off, residual_off, track_off) = run(stiffness, 0.0);
        println!(
            "stiffness {stiffness}: peak KE on/off {peak_on:.3e}/{peak_off:.3e} (ratio {:.2e}), residual KE ratio {:.2e}, tracking error on/off {track_on:.4}/{track_off:.4} chain lengths",
            peak_on / peak_off,
            residual_on / residual_off
        );
        // Stiff chains follow their rest shape, so what the changing rest shape injects is all there is:
        // suppression must remove nearly all of it. Soft chains lag and swing by design (reported only).
        if stiffness >= 0.9 {
            assert!(peak_on <= 0.01 * peak_off, "stiffness {stiffness}: peak KE ratio {}", peak_on / peak_off);
            assert!(track_on <= 0.02, "stiffness {stiffness}: tracking error {track_on} chain lengths");
        }
    }
}

/// The pose a call returns shows the call's own time, not an earlier internal state: a limp double pendulum
/// (1 m, released straight out) against the exact reference at each call's time `t`, at a frame rate that
/// divides the substep rate (the pose is the newest internal state) and at one that does not (the last
/// substep's motion carried on by less than a substep). The same poses against the reference one substep
/// earlier, `t - h`, are far off: what a one-substep display latency would show.
#[test]
fn the_pose_shows_the_call_time() {
    let links = 2;
    let reference = Pendulum::uniform(links, 1.0 / links as f64, 1.0, [0.0, -9.81]);
    let start = reference.state_at_rest(&vec![std::f64::consts::FRAC_PI_2; links]);
    let exact = |times: &[f64]| -> Vec<Vec<Vec3>> {
        let (states, _) = reference.solve(0.0, &start, times, Tolerance::REFERENCE);
        let to_world = |q: &[f64; 2]| HEAD + Vec3::new(q[0] as f32, q[1] as f32, 0.0);
        times.iter().zip(&states).map(|(t, y)| reference.positions(*t, y).iter().map(to_world).collect()).collect()
    };
    let h = 1.0 / EngineSettings::default().substep_rate as f64;
    for fps in [60u32, 144] {
        let mut engine = engine_with(EngineSettings::default());
        let id = engine.create_chain(limp(), &straight_chain(links + 1, Vec3::ZERO, Vec3::X, 0.5)).unwrap();
        let times: Vec<f64> = (1..=fps / 2).map(|k| k as f64 / fps as f64).collect();
        let earlier: Vec<f64> = times.iter().map(|t| t - h).collect();
        let (now, before) = (exact(&times), exact(&earlier));
        let (mut at_call, mut one_substep_earlier, mut count) = (0.0f64, 0.0f64, 0usize);
        for k in 0..times.len() {
            engine.step(1.0 / fps as f32, HEAD + Vec3::new(0.0, 0.0, 3.0), at(HEAD)).unwrap();
            let pose = chain_world(&engine, id);
            for j in 1..pose.len() {
                at_call += (pose[j].position - now[k][j]).length_squared() as f64;
                one_substep_earlier += (pose[j].position - before[k][j]).length_squared() as f64;
                count += 1;
            }
        }
        let (at_call, one_substep_earlier) =
            ((at_call / count as f64).sqrt(), (one_substep_earlier / count as f64).sqrt());
        println!(
            "{fps} fps: RMS joint error against the reference at the call time {at_call:.2e} m, one substep earlier {one_substep_earlier:.2e} m"
        );
        assert!(at_call <= 1e-3, "{fps} fps: {at_call}");
        assert!(one_substep_earlier >= 10.0 * at_call, "{fps} fps: {one_substep_earlier} vs {at_call}");
    }
}
