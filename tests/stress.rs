//! Numerical-stability stress (SPEC 3.9, 6.2) through the Rust API: extreme time steps, teleports and flips,
//! extreme parameters and sizes, world scale, distance from the origin, violent shaking, folded shapes,
//! long settling (denormals) and a random-motion soak.
//!
//! Every scenario prints the figure it measures (`cargo test --test stress -- --nocapture`). Quick versions
//! run in `cargo test`; the long versions are `#[ignore]`d:
//! `cargo test --release --test stress -- --ignored --nocapture`.
//!
//! Pass criteria: every read-back position and rotation finite; max relative segment stretch <= 1e-4 in
//! normal scenarios and <= 1e-3 in violent ones; no energy growth for a still, undamped, limp chain;
//! back to rest once the root stops (default damping); identical runs give identical state hashes.

mod common;

use std::time::Instant;

use common::*;
use glam::{Quat, Vec3};
use kodawari::{ChainId, ChainParams, Engine, EngineSettings, Transform};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
/// Max relative segment stretch in normal scenarios.
const NORMAL: f32 = 1e-4;
/// Max relative segment stretch in violent ones (shaking, teleports without teleport handling, huge dt).
const VIOLENT: f32 = 1e-3;

// ---- harness ------------------------------------------------------------------------------------------

/// One engine with chains, stepped with checks after every frame.
struct Rig {
    engine: Engine,
    chains: Vec<(ChainId, Vec<f32>)>,
    /// Worst stretch beyond the float32 rounding floor of the read-back positions (which grows with the
    /// distance from the world origin: 1e-3 m at 1e4 m).
    worst_stretch: f32,
    /// Worst raw stretch of the read-back positions.
    worst_raw: f32,
    frames: u64,
    name: String,
}

impl Rig {
    fn new(name: &str, settings: EngineSettings) -> Self {
        Self {
            engine: engine_with(settings),
            chains: Vec::new(),
            worst_stretch: 0.0,
            worst_raw: 0.0,
            frames: 0,
            name: name.into(),
        }
    }

    fn with_chain(name: &str, settings: EngineSettings, params: ChainParams, base: &[Transform]) -> Self {
        let mut rig = Self::new(name, settings);
        rig.add(params, base);
        rig
    }

    fn add(&mut self, params: ChainParams, base: &[Transform]) -> ChainId {
        let id = self.engine.create_chain(params, base).unwrap();
        self.chains.push((id, segment_lengths(base)));
        id
    }

    fn id(&self) -> ChainId {
        self.chains[0].0
    }

    /// Steps with the view reference (the chains' anchor) at `k`, the camera 3 units in front of it.
    fn step(&mut self, dt: f32, k: Transform) {
        self.step_camera(dt, k.transform_point(Vec3::new(0.0, 0.1, 3.0)), k);
    }

    fn step_camera(&mut self, dt: f32, camera: Vec3, k: Transform) {
        self.engine.step(dt, camera, k).unwrap_or_else(|e| panic!("{}: step rejected: {e:?}", self.name));
        self.frames += 1;
        self.check();
    }

    /// Everything read back is finite; records the worst stretch.
    fn check(&mut self) {
        let world = world(&self.engine);
        let mut locals = vec![Quat::IDENTITY; self.engine.joint_count()];
        self.engine.read_local_rotations(&mut locals).unwrap();
        let finite = world.iter().all(|t| t.position.is_finite() && t.rotation.is_finite())
            && locals.iter().all(|q| q.is_finite());
        assert!(finite, "{}: non-finite output at frame {}", self.name, self.frames);
        for (id, lengths) in &self.chains {
            let ke = self.engine.chain_kinetic_energy(*id).unwrap();
            assert!(ke.is_finite(), "{}: non-finite kinetic energy at frame {}", self.name, self.frames);
            let joints = chain_world(&self.engine, *id);
            let stretch = max_stretch(&joints, lengths);
            let extent = joints.iter().map(|t| t.position.abs().max_element()).fold(0.0, f32::max);
            let shortest = lengths.iter().copied().fold(f32::INFINITY, f32::min);
            let floor = 4.0 * f32::EPSILON * extent / shortest;
            self.worst_raw = self.worst_raw.max(stretch);
            self.worst_stretch = self.worst_stretch.max(stretch - floor);
        }
    }

    fn kinetic_energy(&self) -> f32 {
        self.chains.iter().map(|(id, _)| self.engine.chain_kinetic_energy(*id).unwrap()).sum()
    }

    fn assert_stretch(&self, bound: f32) {
        assert!(
            self.worst_stretch <= bound,
            "{}: max relative stretch {:.3e} > {bound:.0e}",
            self.name,
            self.worst_stretch
        );
    }
}

/// A small deterministic PRNG (xorshift64*), so the soak needs no extra dependency.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    fn vec3(&mut self, r: f32) -> Vec3 {
        Vec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
}

/// Root swaying `amplitude` along x at `hz`, rotating a little about z.
fn sway(t: f64, amplitude: f32, hz: f64) -> Transform {
    let phase = (2.0 * std::f64::consts::PI * hz * t).sin() as f32;
    Transform::new(HEAD + Vec3::new(amplitude * phase, 0.0, 0.0), Quat::from_rotation_z(0.3 * phase))
}

/// A chain hanging at 45 degrees, bent a little: it swings as soon as it starts.
fn test_chain(n: usize, segment: f32) -> Vec<Transform> {
    curled_chain(n, Vec3::new(0.0, -0.05, 0.0), Vec3::new(1.0, -1.0, 0.2), Vec3::Z, 0.08, segment)
}

// ---- time steps ---------------------------------------------------------------------------------------

/// dt of 0, 1e-6, 0.1, 1, 10 s and alternating 1/240 <-> 1/15.
#[test]
fn extreme_time_steps() {
    let base = test_chain(9, 0.05);
    // dt = 1e-6 runs under a still root here; `render_interpolation_keeps_lengths` covers tiny steps under
    // a moving one.
    type DtOf<'a> = &'a dyn Fn(u64) -> f32;
    let cases: [(&str, DtOf, u64, f32); 6] = [
        ("dt = 0", &|_| 0.0, 200, NORMAL),
        ("dt = 1e-6 (still root)", &|_| 1e-6, 20_000, NORMAL),
        ("dt = 0.1", &|_| 0.1, 300, NORMAL),
        ("dt = 1", &|_| 1.0, 200, VIOLENT),
        ("dt = 10", &|_| 10.0, 200, VIOLENT),
        ("dt alternating 1/240 <-> 1/15", &|f| if f % 2 == 0 { 1.0 / 240.0 } else { 1.0 / 15.0 }, 600, NORMAL),
    ];
    for (name, dt_of, frames, bound) in cases {
        let mut rig = Rig::with_chain(name, EngineSettings::default(), ChainParams::default(), &base);
        let hash0 = rig.engine.state_hash();
        let mut t = 0.0f64;
        for f in 0..frames {
            let dt = dt_of(f);
            t += dt as f64;
            rig.step(dt, if dt == 1e-6 { at(HEAD) } else { sway(t, 0.2, 1.0) });
        }
        if dt_of(0) == 0.0 {
            assert_eq!(rig.engine.state_hash(), hash0, "dt = 0 must change nothing");
        }
        let stats = rig.engine.stats();
        println!(
            "{name}: {frames} frames, {} substeps, {:.1} s dropped, max stretch {:.2e} (bound {bound:.0e})",
            stats.substeps_total, stats.time_dropped, rig.worst_raw
        );
        rig.assert_stretch(bound);
    }
}

/// Render rates above the substep rate read back a blend of the last two internal states (carried on past the
/// newest to the call's time). Blending joint positions linearly would shorten every segment that turned between them (a chord:
/// `1 - cos(theta / 2)`; measured 8.2e-3 at 144 fps before the read-back kept exact lengths). Root swaying
/// 0.2 m at 1 Hz from full speed, default settings.
fn render_interpolation_stretch(fps: f32, frames: u32) -> f32 {
    let base = test_chain(9, 0.05);
    let mut rig = Rig::with_chain("render interpolation", EngineSettings::default(), ChainParams::default(), &base);
    for f in 0..frames {
        rig.step(1.0 / fps, sway(f as f64 / fps as f64, 0.2, 1.0));
    }
    rig.worst_raw
}

#[test]
fn render_interpolation_keeps_lengths() {
    let mut worst = 0.0f32;
    for (fps, frames) in [(1e6f32, 20_000u32), (1000.0, 1000), (144.0, 288), (60.0, 120)] {
        let stretch = render_interpolation_stretch(fps, frames);
        println!("render interpolation at {fps} fps (240 Hz substeps): max stretch {stretch:.2e}");
        worst = worst.max(stretch);
    }
    assert!(worst <= NORMAL, "max stretch {worst:.2e}");
}

// ---- teleports and flips ------------------------------------------------------------------------------

/// Two identical scenes; in one the anchor jumps (and/or turns) for one frame's motion. Returns the shape
/// difference in the anchor frame (absolute) and the kinetic energies (jumped, reference).
fn teleport_once(jump: Transform) -> (f32, f32, f32, f32) {
    let base = test_chain(9, 0.05);
    // No gravity: a flip about a horizontal axis would otherwise turn gravity in the chain's frame, and the
    // two runs would differ physically after the jump.
    let settings = EngineSettings { gravity: Vec3::ZERO, ..Default::default() };
    let mut a = Rig::with_chain("reference", settings, ChainParams::default(), &base);
    let mut b = Rig::with_chain("teleported", settings, ChainParams::default(), &base);
    for f in 0..30 {
        let k = sway(f as f64 / 60.0, 0.2, 1.0);
        a.step(1.0 / 60.0, k);
        b.step(1.0 / 60.0, k);
    }
    // The view reference holds still for the teleport frame: a teleport carries the chain to the new anchor
    // and drops that frame's anchor motion, so only a still anchor gives a like-for-like comparison.
    let k = sway(29.0 / 60.0, 0.2, 1.0);
    let far = jump.mul(&k);
    a.step(1.0 / 60.0, k);
    b.step_camera(1.0 / 60.0, far.transform_point(Vec3::new(0.0, 0.1, 3.0)), far);
    let (pa, pb) = (chain_world(&a.engine, a.id()), chain_world(&b.engine, b.id()));
    let diff = pa
        .iter()
        .zip(&pb)
        .map(|(p, q)| (far.inverse_transform_point(q.position) - k.inverse_transform_point(p.position)).length())
        .fold(0.0, f32::max);
    let precision = 4.0 * f32::EPSILON * far.position.abs().max_element();
    (diff, precision, b.kinetic_energy(), a.kinetic_energy())
}

fn check_teleports(jumps: &[(&str, Transform)]) -> Vec<String> {
    let length = chain_length(&test_chain(9, 0.05));
    let mut failures = Vec::new();
    for (name, jump) in jumps {
        let (diff, precision, e_jump, e_ref) = teleport_once(*jump);
        let energy = ((e_jump - e_ref) / e_ref).abs();
        println!(
            "{name}: shape differs by {:.2e} chain lengths (float32 floor at that distance {:.1e}), kinetic energy {e_jump:.6e} J vs {e_ref:.6e} J (relative {energy:.1e})",
            diff / length,
            precision / length
        );
        if diff > 1e-4 * length + precision || energy > 1e-4 {
            failures.push(format!("{name}: shape {:.2e} chain lengths, energy {energy:.1e}", diff / length));
        }
    }
    failures
}

/// 180-degree flips of the anchor (with and without a jump) are carried rigidly: same shape in the anchor
/// frame, same kinetic energy.
#[test]
fn flips_keep_shape_and_energy() {
    let pi = std::f32::consts::PI;
    let failures = check_teleports(&[
        ("flip 180 deg about y", Transform::new(Vec3::ZERO, Quat::from_rotation_y(pi))),
        ("flip 180 deg about x (upside down)", Transform::new(Vec3::ZERO, Quat::from_rotation_x(pi))),
        ("jump 10 + flip 180 about z", Transform::new(Vec3::new(0.0, 10.0, 0.0), Quat::from_rotation_z(pi))),
    ]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// 1e4-unit jumps. The carry is computed from float32 anchor positions relative to the new origin
/// (1e-3 m apart at 1e4 m), so the chain lands up to that far off its anchor and snaps back in the next
/// substep: a kick of about 1e-3 m / h.
#[test]
#[ignore = "BUG: 1e4-unit teleport of a swinging 9-joint chain (no gravity) changes its kinetic energy by \
            8.8e-3 relative (diagonal jump; 1.7e-4 along x, 1.2e-3 with a 180-degree flip) instead of carrying it \
            rigidly (bar 1e-4)"]
fn far_jumps_keep_shape_and_energy() {
    let failures = check_teleports(&[
        ("jump 1e4 along x", Transform::new(Vec3::new(1e4, 0.0, 0.0), Quat::IDENTITY)),
        ("jump 1e4 diagonal", Transform::new(Vec3::splat(-1e4 / 3f32.sqrt()), Quat::IDENTITY)),
        ("jump 1e4 + flip 180", Transform::new(Vec3::new(0.0, 1e4, 0.0), Quat::from_rotation_z(std::f32::consts::PI))),
    ]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// The anchor flips 180 degrees every frame and jumps 1e4 units every 7th frame, for a while; then it
/// stays. With teleport handling the chain never stretches; it settles afterwards.
#[test]
fn repeated_teleports_and_flips() {
    let base = test_chain(9, 0.05);
    let mut rig = Rig::with_chain("repeated flips", EngineSettings::default(), ChainParams::default(), &base);
    let mut k = at(HEAD);
    let mut peak = 0.0f32;
    for f in 0..600u32 {
        if f < 300 {
            let axis = [Vec3::X, Vec3::Y, Vec3::Z][f as usize % 3];
            k.rotation = (Quat::from_axis_angle(axis, std::f32::consts::PI) * k.rotation).normalize();
            if f % 7 == 0 {
                k.position += Vec3::new(1e4, -1e4, 0.5e4) * if f % 14 == 0 { 1.0 } else { -1.0 };
            }
        }
        rig.step(1.0 / 60.0, k);
        peak = peak.max(rig.kinetic_energy());
    }
    for _ in 0..1200 {
        rig.step(1.0 / 60.0, k);
    }
    let rest = rig.kinetic_energy();
    println!(
        "repeated 180-degree flips + 1e4 jumps: max stretch beyond the float32 read-back floor {:.2e}, peak KE {peak:.3e} J, KE 20 s after {rest:.3e} J",
        rig.worst_stretch
    );
    rig.assert_stretch(NORMAL);
    assert!(rest <= 1e-6 * peak.max(1e-3), "not back to rest: {rest}");
}

/// Teleport handling disabled: a 1e4-unit jump is a real (absurd) motion over one frame. Nothing may
/// become non-finite and the chain must recover its lengths and come to rest.
#[test]
fn teleport_without_teleport_handling_stays_finite() {
    let base = test_chain(9, 0.05);
    let settings = EngineSettings { teleport_distance: f32::MAX, teleport_angle: 4.0, ..Default::default() };
    for (name, jump) in [
        ("1e4 jump, teleports off", Transform::new(Vec3::new(1e4, 0.0, 0.0), Quat::IDENTITY)),
        ("180 flip, teleports off", Transform::new(Vec3::ZERO, Quat::from_rotation_x(std::f32::consts::PI))),
    ] {
        let mut rig = Rig::with_chain(name, settings, ChainParams::default(), &base);
        for _ in 0..30 {
            rig.step(1.0 / 60.0, at(HEAD));
        }
        let k = jump.mul(&at(HEAD));
        rig.step(1.0 / 60.0, k);
        let during = rig.worst_stretch;
        let peak = rig.kinetic_energy();
        rig.worst_stretch = 0.0;
        for _ in 0..60 {
            rig.step(1.0 / 60.0, k);
        }
        let after_1s = rig.worst_stretch;
        for _ in 0..1800 {
            rig.step(1.0 / 60.0, k);
        }
        let rest = rig.kinetic_energy();
        println!(
            "{name}: stretch beyond the float32 read-back floor in the jump frame {during:.2e}, max in the next second {after_1s:.2e}, KE right after {peak:.3e} J, 30 s later {rest:.3e} J, solver fallbacks {}",
            rig.engine.stats().solver_fallbacks
        );
        assert!(after_1s <= VIOLENT, "{name}: lengths not recovered: {after_1s}");
        assert!(rest <= 1e-6 * peak.max(1e-3), "{name}: not back to rest");
    }
}

// ---- parameters and sizes ----------------------------------------------------------------------------

/// Stiffness 0 and 1, 1 and 64 iterations, 2 and 1000 joints, root swaying.
fn parameter_extremes(seconds: f64) {
    for joints in [2usize, 1000] {
        // 1000 joints of 5 mm: a 5 m rope.
        let segment = if joints == 2 { 0.2 } else { 0.005 };
        // The long rope starts hanging straight down.
        let base = if joints == 2 {
            test_chain(joints, segment)
        } else {
            straight_chain(joints, Vec3::ZERO, -Vec3::Y, segment)
        };
        for stiffness in [0.0f32, 1.0] {
            for iterations in [1u32, 64] {
                let name = format!("{joints} joints, stiffness {stiffness}, {iterations} iterations");
                let settings = EngineSettings { iterations, ..Default::default() };
                let params = ChainParams { stiffness, ..Default::default() };
                let mut rig = Rig::with_chain(&name, settings, params, &base);
                let frames = (seconds * 60.0) as u32 / if joints == 1000 { 3 } else { 1 };
                let started = Instant::now();
                for f in 0..frames {
                    rig.step(1.0 / 60.0, sway(f as f64 / 60.0, 0.2, 1.0));
                }
                let bound = NORMAL;
                if joints == 1000 {
                    // Finite is asserted; long chains are the subject of `long_chain_at_an_angle_...` (BUG).
                    println!(
                        "{name}: {frames} frames, max stretch {:.2e} (not asserted, see the BUG test), solver fallbacks {}, {:.2} s",
                        rig.worst_raw,
                        rig.engine.stats().solver_fallbacks,
                        started.elapsed().as_secs_f64()
                    );
                    continue;
                }
                println!(
                    "{name}: {frames} frames, max stretch {:.2e} (raw {:.2e}, bound {bound:.0e}), solver fallbacks {}, {:.2} s",
                    rig.worst_stretch,
                    rig.worst_raw,
                    rig.engine.stats().solver_fallbacks,
                    started.elapsed().as_secs_f64()
                );
                rig.assert_stretch(bound);
            }
        }
    }
}

#[test]
fn parameter_extremes_quick() {
    parameter_extremes(0.5);
}

#[test]
#[ignore = "long: cargo test --release --test stress -- --ignored"]
fn parameter_extremes_long() {
    parameter_extremes(20.0);
}

/// A long rope released straight at 45 degrees under a still root (limp, undamped): the direct
/// inextensibility solve fails every substep (its multipliers add up to many segment lengths along the
/// rope) and the fallback, though it converges, is not symplectic. Since the read-back rebuilds exact
/// segment lengths, the failure no longer shows as stretch in `read_world`; it shows in the solver-fallback
/// counter and in the energy balance (kinetic + gravitational from read-back positions), which a 100-joint
/// rope keeps to 3.5e-3 of its peak kinetic energy.
#[test]
#[ignore = "BUG (open): 1000-joint limp rope (5 mm segments) released straight at 45 degrees, still root, \
            defaults: 363 substeps without the direct solve in 2 s, total energy off by 3.58e-2 of the peak kinetic \
            energy (4.8e-2 with only the Gauss-Newton fallback, 0.37 before it); 200 joints: 161 fallbacks, 2.3e-2 \
            (was 1.0); 100 joints: fine. Diagnosed: the direct (symplectic) solve along the previous bonds \
            diverges on long pinned chains (the multipliers add up along the rope to many segment lengths, \
            shrinking its convergence radius); the fallbacks now converge (Gauss-Newton along the current bonds, \
            the exact projection where that fails) but are not symplectic, so energy drifts. Needs a direct \
            solve that converges there."]
fn long_chain_at_an_angle_stays_inextensible() {
    let mut failures = Vec::new();
    for (joints, segment) in [(1000usize, 0.005f32), (200, 0.025), (100, 0.05)] {
        let base = straight_chain(joints, Vec3::ZERO, Vec3::new(1.0, -1.0, 0.2), segment);
        let name = format!("{joints} joints of {segment} m released at 45 degrees");
        let params = ChainParams { stiffness: 0.0, damping: 0.0, ..Default::default() };
        let mut rig = Rig::with_chain(&name, EngineSettings::default(), params, &base);
        let g = 9.81f64;
        let potential = |rig: &Rig| -> f64 {
            chain_world(&rig.engine, rig.id()).iter().skip(1).map(|t| g * (t.position.y - HEAD.y) as f64).sum()
        };
        let (mut e0, mut peak, mut worst) = (None, 0.0f64, 0.0f64);
        for _ in 0..120 {
            rig.step(1.0 / 60.0, at(HEAD));
            let ke = rig.kinetic_energy() as f64;
            let energy = ke + potential(&rig);
            let e0 = *e0.get_or_insert(energy);
            peak = peak.max(ke);
            worst = worst.max((energy - e0).abs());
        }
        let fallbacks = rig.engine.stats().solver_fallbacks;
        println!(
            "{name}: solver fallbacks {fallbacks}, energy off by up to {worst:.1} J of {peak:.1} J peak kinetic ({:.2e}), read-back stretch {:.2e}",
            worst / peak,
            rig.worst_raw
        );
        if fallbacks > 0 || worst > 1e-2 * peak {
            failures.push(format!("{name}: {fallbacks} fallbacks, energy error {:.2e} of peak KE", worst / peak));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

// ---- scale and distance ------------------------------------------------------------------------------

/// Runs the sway scene with everything that has a length scaled by `s` (lengths, positions, gravity,
/// radius, teleport distance) and the root at `offset` (unscaled); returns each frame's joint positions
/// relative to the view reference, divided by `s`, and each frame's local rotations and kinetic energy.
fn sway_scene(s: f32, offset: Vec3, quantise: Option<Vec3>, frames: u32) -> Vec<(Vec<Vec3>, Vec<Quat>, f32)> {
    let base: Vec<Transform> = test_chain(9, 0.05).iter().map(|t| Transform::new(t.position * s, t.rotation)).collect();
    let default = EngineSettings::default();
    let settings =
        EngineSettings { gravity: default.gravity * s, teleport_distance: default.teleport_distance * s, ..default };
    let params = ChainParams { radius: ChainParams::default().radius * s, ..Default::default() };
    let mut rig = Rig::with_chain("scaled", settings, params, &base);
    let mut out = Vec::new();
    for f in 0..frames {
        let local = sway(f as f64 / 60.0, 0.2, 1.0);
        let mut position = local.position * s + offset;
        if let Some(far) = quantise {
            // The root motion a far-away character can express in float32, brought back to the origin.
            position = (local.position * s + far) - far;
        }
        let k = Transform::new(position, local.rotation);
        rig.step(1.0 / 60.0, k);
        let world = chain_world(&rig.engine, rig.id());
        let mut locals = vec![Quat::IDENTITY; rig.engine.joint_count()];
        rig.engine.read_local_rotations(&mut locals).unwrap();
        let shape = world.iter().map(|t| k.inverse_transform_point(t.position) / s).collect();
        out.push((shape, locals, rig.kinetic_energy()));
    }
    rig.assert_stretch(NORMAL);
    out
}

fn max_shape_difference(a: &[(Vec<Vec3>, Vec<Quat>, f32)], b: &[(Vec<Vec3>, Vec<Quat>, f32)]) -> (f32, f32) {
    let mut position = 0.0f32;
    let mut angle = 0.0f32;
    for ((pa, qa, _), (pb, qb, _)) in a.iter().zip(b) {
        for (x, y) in pa.iter().zip(pb) {
            position = position.max((*x - *y).length());
        }
        for (x, y) in qa.iter().zip(qb) {
            // 2 |q1 - q2| (sign-aligned) is the angle for small angles, without acos's float32 floor.
            let d = if x.dot(*y) < 0.0 { *x + *y } else { *x - *y };
            angle = angle.max(2.0 * d.length());
        }
    }
    (position, angle)
}

/// The same scene at world scale 1e-3 and 1e4 (lengths, positions and gravity scaled) matches the
/// unscaled one within 1e-4 chain lengths after undoing the scale.
#[test]
fn world_scale_covariance() {
    let length = chain_length(&test_chain(9, 0.05));
    let frames = 120;
    let reference = sway_scene(1.0, Vec3::ZERO, None, frames);
    let mut failures = Vec::new();
    for s in [1e-2f32, 1e-1, 1e1, 1e2, 1e4] {
        let scaled = sway_scene(s, Vec3::ZERO, None, frames);
        let (position, angle) = max_shape_difference(&reference, &scaled);
        println!(
            "world scale {s:.0e}: max joint difference {:.2e} chain lengths, max local-rotation difference {angle:.2e} rad over {frames} frames",
            position / length
        );
        if position > 1e-4 * length {
            failures.push((s, position / length));
        }
    }
    assert!(failures.is_empty(), "not scale-covariant (scale, chain lengths): {failures:?}");
}

#[test]
fn world_scale_millimetre_covariance() {
    let length = chain_length(&test_chain(9, 0.05));
    let reference = sway_scene(1.0, Vec3::ZERO, None, 120);
    let scaled = sway_scene(1e-3, Vec3::ZERO, None, 120);
    let (position, angle) = max_shape_difference(&reference, &scaled);
    println!("world scale 1e-3: max joint difference {:.2e} chain lengths, {angle:.2e} rad", position / length);
    assert!(position <= 1e-4 * length, "{} chain lengths", position / length);
}

/// A character 1e2 and 1e4 units from the origin moves like one at the origin. Two comparisons: against
/// the origin run given the same (float32-quantised) root motion, which must match to float precision; and
/// against the unquantised origin run, which shows what a host sees.
#[test]
fn far_from_origin_moves_like_at_origin() {
    let length = chain_length(&test_chain(9, 0.05));
    let frames = 180;
    let origin = sway_scene(1.0, Vec3::ZERO, None, frames);
    for distance in [1e2f32, 1e4, 1e5] {
        let far = Vec3::new(distance, -0.5 * distance, 0.25 * distance);
        let far_run = sway_scene(1.0, far, None, frames);
        let same_input = sway_scene(1.0, Vec3::ZERO, Some(far), frames);
        let (raw, raw_angle) = max_shape_difference(&origin, &far_run);
        let (quantised, quantised_angle) = max_shape_difference(&same_input, &far_run);
        let energy =
            same_input.iter().zip(&far_run).map(|(a, b)| ((a.2 - b.2) / a.2.max(1e-12)).abs()).fold(0.0, f32::max);
        let floor = 2.0 * f32::EPSILON * far.abs().max_element();
        println!(
            "root {distance:.0e} from the origin: vs the origin run {:.2e} chain lengths ({raw_angle:.1e} rad); vs the origin run with the same float32 root motion {:.2e} chain lengths ({quantised_angle:.1e} rad, KE relative {energy:.1e}); float32 read-back floor {:.1e}",
            raw / length,
            quantised / length,
            floor / length
        );
        assert!(quantised <= floor + 1e-6 * length, "{distance}: {quantised}");
        assert!(quantised_angle <= 1e-5, "{distance}: local rotations differ by {quantised_angle}");
        assert!(energy <= 1e-5, "{distance}: kinetic energy differs by {energy}");
    }
}

// ---- violent motion ----------------------------------------------------------------------------------

/// Root shaken at 100 Hz (1 cm amplitude, 4000 m/s^2 peak acceleration) for 2 s, then still: stretch stays
/// bounded and the chain comes back to rest with the default damping.
#[test]
fn shaken_at_100_hz_then_rests() {
    for (name, rate, fps) in [("2 kHz substeps, 2 kHz frames", 2000.0f32, 2000u32), ("defaults, 60 fps", 240.0, 60)] {
        let settings = EngineSettings { substep_rate: rate, ..Default::default() };
        let mut rig = Rig::with_chain(name, settings, ChainParams::default(), &test_chain(9, 0.05));
        let dt = 1.0 / fps as f32;
        let mut peak = 0.0f32;
        for f in 0..(2 * fps) {
            let t = f as f64 / fps as f64;
            let shake = (2.0 * std::f64::consts::PI * 100.0 * t).sin() as f32 * 0.01;
            rig.step(dt, Transform::new(HEAD + Vec3::new(shake, shake * 0.5, 0.0), Quat::IDENTITY));
            peak = peak.max(rig.kinetic_energy());
        }
        let shaking = rig.worst_raw;
        for _ in 0..(12 * fps) {
            rig.step(dt, at(HEAD));
        }
        let rest = rig.kinetic_energy();
        println!(
            "shaken at 100 Hz ({name}): max stretch {shaking:.2e}, peak KE {peak:.3e} J, KE 12 s after {rest:.3e} J"
        );
        rig.assert_stretch(VIOLENT);
        assert!(rest <= 1e-6 * peak.max(1e-3), "{name}: not back to rest: {rest}");
    }
}

// ---- degenerate shapes -------------------------------------------------------------------------------

fn joints(points: &[Vec3]) -> Vec<Transform> {
    let n = points.len();
    (0..n)
        .map(|i| {
            let dir = if i + 1 < n { points[i + 1] - points[i] } else { points[i] - points[i - 1] };
            Transform::new(points[i], Quat::from_rotation_arc(Vec3::Y, dir.normalize()))
        })
        .collect()
}

/// Base shapes folded back onto themselves (180-degree bends; non-adjacent joints at the same position),
/// as base, view shape and run-time base replacement. Creation is accepted, the rest shape decodes back
/// to the fold, and stepping stays finite and inextensible.
#[test]
fn folded_and_coincident_shapes() {
    let l = 0.05f32;
    let y = |k: f32| Vec3::new(0.0, -k * l, 0.0);
    let shapes: [(&str, Vec<Transform>); 4] = [
        // Down two segments, then straight back up: joint 3 sits on joint 1.
        ("fold 180 at joint 2", joints(&[y(0.0), y(1.0), y(2.0), y(1.0), y(0.0), y(-1.0)])),
        // Zig-zag on one line: joints 0, 2, 4 coincide, and 1, 3, 5.
        ("zig-zag, every other joint coincident", joints(&[y(0.0), y(1.0), y(0.0), y(1.0), y(0.0), y(1.0)])),
        // Horizontal fold: the second half lies on the first.
        (
            "horizontal fold",
            joints(&[Vec3::ZERO, Vec3::X * l, Vec3::X * 2.0 * l, Vec3::X * l, Vec3::ZERO, -Vec3::X * l]),
        ),
        // A closed loop: the tip comes back onto the root.
        (
            "closed square loop",
            joints(&[Vec3::ZERO, Vec3::X * l, Vec3::new(l, -l, 0.0), Vec3::new(0.0, -l, 0.0), Vec3::ZERO]),
        ),
    ];
    for (name, shape) in &shapes {
        let n = shape.len();
        for stiffness in [0.0f32, 0.5, 1.0] {
            let label = format!("{name}, stiffness {stiffness}");
            let params = ChainParams { stiffness, ..Default::default() };
            let mut rig = Rig::with_chain(&label, EngineSettings::default(), params, shape);
            // The same fold as a view shape of a straight chain, seen from the front.
            let straight = straight_chain(n, Vec3::ZERO, -Vec3::Y, l);
            let other = rig.add(params, &straight);
            rig.engine.add_view_shape(other, Vec3::Z, shape, 2.0).unwrap();
            let mut rest = vec![Transform::IDENTITY; n];
            rig.engine.chain_rest_shape(rig.id(), &mut rest).unwrap();
            let decode = rest.iter().zip(shape).map(|(r, s)| (r.position - s.position).length()).fold(0.0, f32::max);
            for f in 0..240 {
                rig.step(1.0 / 60.0, sway(f as f64 / 60.0, 0.1, 1.0));
            }
            // Replace the first chain's base by the straight one and back, at run time.
            rig.engine.set_base_shape(rig.id(), &straight).unwrap();
            for f in 240..300 {
                rig.step(1.0 / 60.0, sway(f as f64 / 60.0, 0.1, 1.0));
            }
            rig.engine.set_base_shape(rig.id(), shape).unwrap();
            for f in 300..420 {
                rig.step(1.0 / 60.0, sway(f as f64 / 60.0, 0.1, 1.0));
            }
            println!(
                "{label}: rest decodes to the fold within {:.1e} m, max stretch {:.2e}, solver fallbacks {}",
                decode,
                rig.worst_raw,
                rig.engine.stats().solver_fallbacks
            );
            assert!(decode <= 1e-5, "{label}: rest shape {decode} away from the fold");
            rig.assert_stretch(VIOLENT);
        }
    }
}

// ---- energy ------------------------------------------------------------------------------------------

/// A limp, undamped chain released horizontally under a still root: total energy (kinetic from the
/// engine + gravitational potential from read-back positions) must not grow by more than 1e-3 of the
/// energy available to the swing (horizontal to hanging).
///
/// Measured at one substep per call (256 Hz: an exact float step, so the read-back is the newest internal
/// state). The engine's velocity of substep k is `(x_k - x_{k-1}) / h`, so it is paired with the potential at
/// the midpoint of the read-backs of calls k - 1 and k (leapfrog). A symplectic integrator's energy error oscillates (fast whips of the tip show up as brief
/// spikes); growth is the median energy over the last fifth of the run against the start. Returns
/// (median growth, largest instantaneous deviation), both relative to the swing energy.
fn energy_conservation(seconds: f64, joints: usize) -> (f64, f64) {
    let rate = 256.0f32;
    let settings = EngineSettings { substep_rate: rate, ..Default::default() };
    let g = -settings.gravity.y as f64;
    let base = straight_chain(joints, Vec3::ZERO, Vec3::X, 0.8 / (joints - 1) as f32);
    let mut rig = Rig::with_chain("energy", settings, limp(), &base);
    let k = at(HEAD);
    let potential = |rig: &Rig| -> f64 {
        chain_world(&rig.engine, rig.id()).iter().skip(1).map(|t| g * (t.position.y - HEAD.y) as f64).sum()
    };
    let mut depth = 0.0f64;
    let mut available = 0.0f64;
    for l in segment_lengths(&base) {
        depth += l as f64;
        available += g * depth;
    }
    rig.step(1.0 / rate, k);
    let mut previous = potential(&rig);
    let steps = (seconds * rate as f64) as usize;
    let mut energies = Vec::with_capacity(steps);
    for _ in 0..steps {
        rig.step(1.0 / rate, k);
        let now = potential(&rig);
        energies.push(rig.kinetic_energy() as f64 + 0.5 * (now + previous));
        previous = now;
    }
    rig.assert_stretch(NORMAL);
    let e0 = energies[0];
    let mut late: Vec<f64> = energies[steps * 4 / 5..].to_vec();
    late.sort_by(f64::total_cmp);
    let growth = (late[late.len() / 2] - e0) / available;
    let spike = energies.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / available;
    (growth, spike)
}

#[test]
fn no_energy_growth_still_root() {
    for joints in [2usize, 3] {
        let (growth, spike) = energy_conservation(10.0, joints);
        println!(
            "energy, limp undamped {joints}-joint chain, still root, 10 s at 256 Hz: median change {growth:+.2e}, largest instantaneous deviation {spike:.2e} of the swing energy"
        );
        assert!(growth <= 1e-3, "{joints} joints: energy grew by {growth}");
    }
}

/// The 9-link case: the energy error wanders by about 1e-2 of the swing energy at 256 Hz and shrinks
/// roughly with h^2 (3e-4 at 4096 Hz), so it is the integrator's error rather than a secular drift, but it
/// exceeds the 1e-3 bar.
#[test]
#[ignore = "BUG: limp undamped 9-joint chain (0.8 m) released horizontally, still root, 256 Hz: total energy \
            median +9.1e-3 of the swing energy after 10 s, instantaneous excursions to 1.35e-1 (bar 1e-3 growth)"]
fn no_energy_growth_nine_links() {
    let (growth, spike) = energy_conservation(10.0, 9);
    println!(
        "energy, limp undamped 9-joint chain, still root, 10 s at 256 Hz: median change {growth:+.2e}, largest instantaneous deviation {spike:.2e} of the swing energy"
    );
    assert!(growth <= 1e-3, "energy grew by {growth}");
}

#[test]
#[ignore = "long: cargo test --release --test stress -- --ignored"]
fn no_energy_growth_still_root_long() {
    for joints in [2usize, 3] {
        let (growth, spike) = energy_conservation(300.0, joints);
        println!(
            "energy, limp undamped {joints}-joint chain, still root, 300 s at 256 Hz: median change {growth:+.2e}, largest instantaneous deviation {spike:.2e} of the swing energy"
        );
        assert!(growth <= 1e-3, "{joints} joints: energy grew by {growth}");
    }
}

// ---- settling and denormals --------------------------------------------------------------------------

/// A chain without gravity, released bent, settles for a long time with tiny velocities (which reach the
/// subnormal range of float32). Late steps must not be slower than early ones by more than 2x (median
/// step times; no absolute thresholds).
fn settling_timing(seconds: u32) -> (f64, f64, f32) {
    let settings = EngineSettings { gravity: Vec3::ZERO, ..Default::default() };
    let params = ChainParams { stiffness: 0.3, damping: 4.0, ..Default::default() };
    let mut engine = engine_with(settings);
    let base = straight_chain(32, Vec3::ZERO, Vec3::X, 0.02);
    let bent = curled_chain(32, Vec3::ZERO, Vec3::X, Vec3::Z, 0.15, 0.02);
    let ids: Vec<ChainId> = (0..8).map(|_| engine.create_chain(params, &base).unwrap()).collect();
    // Start bent: settle into the bent shape, then switch the rest shape back to straight.
    for id in &ids {
        engine.set_base_shape(*id, &bent).unwrap();
    }
    engine.step(1.0 / 60.0, Vec3::new(0.0, 0.0, 3.0), at(HEAD)).unwrap();
    for id in &ids {
        engine.set_base_shape(*id, &base).unwrap();
    }
    let camera = Vec3::new(0.0, 0.0, 3.0);
    let time_steps = |engine: &mut Engine, count: usize| -> f64 {
        let mut samples: Vec<f64> = (0..count)
            .map(|_| {
                let started = Instant::now();
                engine.step(1.0 / 60.0, camera, at(HEAD)).unwrap();
                started.elapsed().as_secs_f64()
            })
            .collect();
        samples.sort_by(f64::total_cmp);
        samples[count / 2]
    };
    let window = 600;
    let early = time_steps(&mut engine, window);
    let total = seconds as usize * 60;
    for _ in 0..total.saturating_sub(2 * window) {
        engine.step(1.0 / 60.0, camera, at(HEAD)).unwrap();
    }
    // The late window is measured up to three times (the best median counts) to shrug off machine noise.
    let late = (0..3).map(|_| time_steps(&mut engine, window)).fold(f64::INFINITY, f64::min);
    let ke: f32 = ids.iter().map(|id| engine.chain_kinetic_energy(*id).unwrap()).sum();
    let out = world(&engine);
    assert!(out.iter().all(|t| t.position.is_finite() && t.rotation.is_finite()));
    (early, late, ke)
}

#[test]
fn settling_has_no_denormal_slowdown() {
    let (early, late, ke) = settling_timing(120);
    println!(
        "settling 8 x 32 joints for 120 s: median step {:.1} us early, {:.1} us late (ratio {:.2}), final KE {ke:.3e} J (subnormal: {})",
        early * 1e6,
        late * 1e6,
        late / early,
        ke != 0.0 && ke.abs() < f32::MIN_POSITIVE
    );
    assert!(late <= 2.0 * early, "late steps {late} s vs early {early} s");
}

#[test]
#[ignore = "long: cargo test --release --test stress -- --ignored"]
fn settling_has_no_denormal_slowdown_long() {
    let (early, late, ke) = settling_timing(3600);
    println!(
        "settling 8 x 32 joints for 1 h: median step {:.1} us early, {:.1} us late (ratio {:.2}), final KE {ke:.3e} J",
        early * 1e6,
        late * 1e6,
        late / early
    );
    assert!(late <= 2.0 * early, "late steps {late} s vs early {early} s");
}

// ---- soak --------------------------------------------------------------------------------------------

/// `steps` frames of random root motion and random dt (0 to 1/15 s, sometimes exactly 0) with three chains
/// (default, limp, rigid; one with view shapes), occasional 1e4 jumps and 180-degree flips; then the root
/// stops. Returns the final state hash.
fn soak(steps: u64, seed: u64, whole_substeps: bool, verbose: bool) -> u64 {
    let mut rng = Rng(seed);
    let mut rig = Rig::new("soak", EngineSettings::default());
    let base = test_chain(9, 0.05);
    let curled = curled_chain(9, Vec3::new(0.0, -0.05, 0.0), Vec3::new(0.0, -1.0, 0.0), Vec3::X, 0.3, 0.05);
    let a = rig.add(ChainParams::default(), &base);
    rig.add(ChainParams { stiffness: 0.0, damping: 0.5, ..Default::default() }, &base);
    rig.add(ChainParams { stiffness: 1.0, ..Default::default() }, &curled);
    rig.engine.add_view_shape(a, Vec3::X, &curled, 2.0).unwrap();
    // The root wanders around `home` (a spring pulls it back) with a random-walk velocity capped at 5 m/s and
    // a random angular velocity; teleports move `home` along with the root.
    let mut home = HEAD;
    let mut position = HEAD;
    let mut velocity = Vec3::ZERO;
    let mut rotation = Quat::IDENTITY;
    let mut peak = 0.0f32;
    let mut teleports = 0;
    for _ in 0..steps {
        // Whole substeps (0 to 16 of them) keep the read-back on an internal state, so the stretch measures
        // the solver; fractional steps add the render-interpolation shortening (measured separately).
        let dt = if whole_substeps {
            (rng.next_u64() % 17) as f32 / 240.0
        } else if rng.unit() < 0.02 {
            0.0
        } else {
            rng.range(0.0, 1.0 / 15.0)
        };
        velocity += rng.vec3(30.0) * dt - (position - home) * (dt * 20.0);
        velocity = velocity.clamp_length_max(5.0);
        position += velocity * dt;
        rotation = (Quat::from_scaled_axis(rng.vec3(4.0) * dt) * rotation).normalize();
        let roll = rng.unit();
        if roll < 0.001 {
            let jump = rng.vec3(1e4);
            home += jump;
            position += jump;
            teleports += 1;
        } else if roll < 0.002 {
            rotation = (Quat::from_rotation_x(std::f32::consts::PI) * rotation).normalize();
            teleports += 1;
        }
        let camera = position + Quat::from_rotation_y(rng.range(0.0, 6.3)) * Vec3::new(0.0, 0.0, 3.0);
        rig.step_camera(dt, camera, Transform::new(position, rotation));
        peak = peak.max(rig.kinetic_energy());
    }
    let moving = rig.worst_stretch;
    for _ in 0..(60 * 30) {
        rig.step(1.0 / 60.0, Transform::new(position, rotation));
    }
    let rest = rig.kinetic_energy();
    if verbose {
        let stats = rig.engine.stats();
        println!(
            "soak {steps} frames (seed {seed:#x}, {}): {} substeps, {teleports} teleports, max stretch beyond the float32 read-back floor {moving:.2e} (raw {:.2e}), peak KE {peak:.3e} J, KE 30 s after the root stops {rest:.3e} J, solver fallbacks {}",
            if whole_substeps { "dt whole substeps" } else { "dt fractional" },
            stats.substeps_total,
            rig.worst_raw,
            stats.solver_fallbacks
        );
    }
    // Fractional steps read back interpolated states (see `render_interpolation_keeps_lengths`).
    if whole_substeps {
        rig.assert_stretch(VIOLENT);
    }
    assert!(rest <= 1e-6 * peak.max(1e-3), "not back to rest: {rest} J");
    rig.engine.state_hash()
}

#[test]
fn soak_quick() {
    for whole in [true, false] {
        let hash = soak(10_000, 0x5eed_0001, whole, true);
        assert_eq!(soak(10_000, 0x5eed_0001, whole, false), hash, "identical runs must give identical state hashes");
    }
}

#[test]
#[ignore = "long: cargo test --release --test stress -- --ignored"]
fn soak_long() {
    for whole in [true, false] {
        let hash = soak(1_000_000, 0x5eed_0002, whole, true);
        assert_eq!(soak(1_000_000, 0x5eed_0002, whole, false), hash, "identical runs must give identical state hashes");
    }
}

// ---- determinism -------------------------------------------------------------------------------------

/// Identical call sequences give identical state hashes across the scenarios above.
#[test]
fn identical_runs_identical_hashes() {
    let run = || {
        let base = test_chain(9, 0.05);
        let mut rig = Rig::with_chain("determinism", EngineSettings::default(), ChainParams::default(), &base);
        let mut rng = Rng(42);
        for f in 0..600u32 {
            let dt = [0.0, 1e-6, 1.0 / 240.0, 1.0 / 15.0, 1.0, 10.0][rng.next_u64() as usize % 6];
            let mut k = sway(f as f64 / 60.0, 0.2, 1.0);
            if f % 97 == 0 {
                k.position.x += 1e4;
            }
            rig.step(dt, k);
        }
        rig.engine.state_hash()
    };
    let (a, b) = (run(), run());
    println!("determinism: state hash {a:#018x} twice");
    assert_eq!(a, b);
}
