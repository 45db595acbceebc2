//! Colliders (SPEC 3.7, issue 6): no tunneling, resting contact, inside colliders, friction, skipping, and
//! input validation. Each test prints the penetration it measured (`cargo test --test collisions --
//! --nocapture`).

mod common;

use common::*;
use glam::{Quat, Vec3};
use kodawari::{ChainId, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, Transform};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const CAMERA: Vec3 = Vec3::new(0.0, 1.6, 5.0);

fn particles(engine: &Engine, id: ChainId) -> Vec<Vec3> {
    let mut out = Vec::new();
    engine.for_each_chain_particle(id, |p| out.push(p)).unwrap();
    out
}

/// Distance from `p` to the segment `a`-`b`.
fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).length()
}

/// Smallest distance between two segments, by dense sampling of the first (exact enough for a test bar of
/// 1e-4 m on segments of a few centimetres: 2000 samples).
fn segment_distance(a0: Vec3, a1: Vec3, b0: Vec3, b1: Vec3) -> f32 {
    (0..=2000).map(|i| distance_to_segment(a0.lerp(a1, i as f32 / 2000.0), b0, b1)).fold(f32::INFINITY, f32::min)
}

/// How deep the chain's particles and segments reach into a capsule (radius `radius` around `axis`):
/// positive is penetration, in metres.
fn capsule_penetration(points: &[Vec3], axis: (Vec3, Vec3), radius: f32) -> f32 {
    let joints = points.iter().map(|p| radius - distance_to_segment(*p, axis.0, axis.1));
    let segments = points.windows(2).map(|w| radius - segment_distance(w[0], w[1], axis.0, axis.1));
    joints.chain(segments).fold(f32::NEG_INFINITY, f32::max)
}

fn hanging_chain(engine: &mut Engine, joints: usize, params: ChainParams) -> ChainId {
    let base = straight_chain(joints, Vec3::ZERO, -Vec3::Y, 0.05);
    engine.create_chain(params, &base).unwrap()
}

/// Local +Y of a capsule turned onto world Z.
fn capsule_along_z(position: Vec3) -> Transform {
    Transform::new(position, Quat::from_rotation_arc(Vec3::Y, Vec3::Z))
}

/// A capsule (an arm) sweeping at 10 m/s through the middle of a hanging chain never leaves a joint or a
/// segment inside it, checked after every substep; also when the host moves it only once per frame and the
/// engine interpolates it across four substeps. (Substep and frame rates are powers of two so that every
/// call runs exactly the substeps it should and the capsule's pose at the checked substep is known.)
#[test]
fn fast_capsule_never_tunnels_through_a_chain() {
    let (radius, half_height, speed) = (0.03f32, 0.1f32, 10.0f32);
    for frame_rate in [256.0f32, 64.0] {
        for stiffness in [0.0f32, 0.5] {
            let mut engine = engine_with(EngineSettings { substep_rate: 256.0, ..Default::default() });
            let params = ChainParams { stiffness, radius: 0.005, friction: 0.3, ..Default::default() };
            let id = hanging_chain(&mut engine, 9, params);
            let start = Vec3::new(-0.3, HEAD.y - 0.25, 0.0);
            let def = ColliderDef {
                shape: ColliderShape::Capsule { radius, half_height },
                transform: capsule_along_z(start),
                layers: 1,
            };
            engine.create_collider(&def).unwrap();
            engine.step(1.0 / 256.0, CAMERA, at(HEAD)).unwrap();
            let mut worst = f32::NEG_INFINITY;
            let mut worst_stretch = 0.0f32;
            let mut time = 0.0f32;
            while time < 0.06 {
                time += 1.0 / frame_rate;
                let centre = start + Vec3::X * speed * time;
                engine.set_collider_transforms([capsule_along_z(centre)].into_iter()).unwrap();
                engine.step(1.0 / frame_rate, CAMERA, at(HEAD)).unwrap();
                let axis = (centre - Vec3::Z * half_height, centre + Vec3::Z * half_height);
                let points = particles(&engine, id);
                worst = worst.max(capsule_penetration(&points, axis, radius));
                let stretch = points.windows(2).map(|w| ((w[1] - w[0]).length() / 0.05 - 1.0).abs());
                worst_stretch = stretch.fold(worst_stretch, f32::max);
            }
            println!(
                "capsule at {speed} m/s, {frame_rate} Hz frames, stiffness {stiffness}: max penetration {worst:.2e} m \
                 (negative: clearance), max segment stretch {worst_stretch:.2e}"
            );
            assert!(worst <= 0.0, "penetration {worst} m at {frame_rate} Hz, stiffness {stiffness}");
            // The hit gives part of the chain 10 m/s within one substep; the lengths give a little meanwhile
            // (2.4e-2 measured for the limp chain; see docs/robustness.md).
            assert!(worst_stretch <= 0.03, "stretch {worst_stretch}");
            // The capsule did meet the chain: it was carried along.
            assert!(particles(&engine, id)[8].x > 0.05, "the chain was not hit: {:?}", particles(&engine, id));
        }
    }
}

/// A limp chain draped over a sphere under gravity settles on it and stays outside within 1e-4 m.
#[test]
fn chain_rests_on_a_sphere() {
    let mut engine = engine_with(EngineSettings::default());
    let sphere_radius = 0.1f32;
    // Root just above the sphere's top, chain lying sideways: it falls onto the sphere and drapes over it.
    let base = straight_chain(12, Vec3::ZERO, Vec3::X, 0.03);
    let params = ChainParams { stiffness: 0.0, radius: 0.0, damping: 2.0, ..Default::default() };
    let id = engine.create_chain(params, &base).unwrap();
    let centre = HEAD - Vec3::Y * (sphere_radius + 0.001);
    let def = ColliderDef { shape: ColliderShape::Sphere { radius: sphere_radius }, transform: at(centre), layers: 1 };
    engine.create_collider(&def).unwrap();
    let mut worst = f32::NEG_INFINITY;
    let mut worst_stretch = 0.0f32;
    for _ in 0..(60 * 4) {
        engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        let points = particles(&engine, id);
        worst = worst.max(capsule_penetration(&points, (centre, centre), sphere_radius));
        let stretch = points.windows(2).map(|w| ((w[1] - w[0]).length() / 0.03 - 1.0).abs());
        worst_stretch = stretch.fold(worst_stretch, f32::max);
    }
    let tip = *particles(&engine, id).last().unwrap();
    println!(
        "chain on a sphere: max penetration over 4 s {worst:.2e} m, max stretch {worst_stretch:.2e}, tip at {tip}"
    );
    assert!(worst <= 1e-4, "penetration {worst} m");
    assert!(worst_stretch <= 1e-3, "stretch {worst_stretch}");
    assert!(tip.y < centre.y, "the chain should drape down the far side, tip {tip}");
    assert!(engine.stats().contact_pairs_tested > 0);
}

/// Particles of a chain swinging inside an "inside" sphere stay within it (radius minus their own).
#[test]
fn inside_sphere_keeps_the_chain_in() {
    let mut engine = engine_with(EngineSettings::default());
    // Starts inside (tip 0.27 m from the centre), swings down and out against the wall.
    let base = straight_chain(6, Vec3::ZERO, Vec3::X, 0.05);
    let particle_radius = 0.01;
    let params = ChainParams { stiffness: 0.0, radius: particle_radius, ..Default::default() };
    let id = engine.create_chain(params, &base).unwrap();
    let ball = 0.3f32;
    let centre = HEAD + Vec3::Y * 0.1;
    let def = ColliderDef { shape: ColliderShape::InsideSphere { radius: ball }, transform: at(centre), layers: 1 };
    engine.create_collider(&def).unwrap();
    let mut worst = f32::NEG_INFINITY;
    let mut touched = false;
    for _ in 0..(60 * 3) {
        engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        for p in particles(&engine, id) {
            let excursion = (p - centre).length() - (ball - particle_radius);
            worst = worst.max(excursion);
            touched |= excursion > -1e-4;
        }
    }
    assert!(touched, "the chain never reached the wall");
    println!("inside sphere: max excursion beyond radius - particle radius {worst:.2e} m");
    assert!(worst <= 1e-5, "excursion {worst} m");
}

/// A chain lying across a 20-degree slope does not swing down it with friction 1 (tan 20° < 1) and does
/// with friction 0.
#[test]
fn friction_holds_a_chain_on_a_slope() {
    let slope = 20f32.to_radians();
    let tilt = Quat::from_rotation_z(slope);
    let mut tip_drop = Vec::new();
    for friction in [0.0f32, 1.0] {
        let mut engine = engine_with(EngineSettings::default());
        // The chain lies along the plane's horizontal line (world Z), resting on the plane through the root.
        let base = straight_chain(8, Vec3::ZERO, Vec3::Z, 0.05);
        let params = ChainParams { stiffness: 0.0, radius: 0.0, friction, ..Default::default() };
        let id = engine.create_chain(params, &base).unwrap();
        let def = ColliderDef { shape: ColliderShape::Plane, transform: Transform::new(HEAD, tilt), layers: 1 };
        engine.create_collider(&def).unwrap();
        engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        let before = particles(&engine, id)[7];
        for _ in 0..60 {
            engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        }
        let after = particles(&engine, id)[7];
        let normal = tilt * Vec3::Y;
        let below_plane = particles(&engine, id).iter().map(|p| -(*p - HEAD).dot(normal)).fold(f32::MIN, f32::max);
        println!(
            "friction {friction}: tip dropped {:.4} m in 1 s, deepest below plane {below_plane:.2e} m",
            before.y - after.y
        );
        assert!(below_plane <= 1e-5, "below the plane by {below_plane}");
        tip_drop.push(before.y - after.y);
    }
    assert!(tip_drop[0] > 0.05, "without friction the chain swings down the slope: {tip_drop:?}");
    assert!(tip_drop[1] < 0.002, "friction 1 holds it on a 20-degree slope: {tip_drop:?}");
}

/// No colliders, a zero mask, a collider on another layer, or one out of reach: the contact pass never runs.
#[test]
fn collision_code_is_skipped_when_nothing_can_touch() {
    let run = |mask: u32, layers: u32, offset: Vec3, with_collider: bool| {
        let mut engine = engine_with(EngineSettings::default());
        hanging_chain(&mut engine, 8, ChainParams { collision_mask: mask, ..Default::default() });
        if with_collider {
            let def = ColliderDef {
                shape: ColliderShape::Sphere { radius: 0.05 },
                transform: at(HEAD - Vec3::Y * 0.2 + offset),
                layers,
            };
            engine.create_collider(&def).unwrap();
        }
        for _ in 0..10 {
            engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        }
        engine.stats().contact_pairs_tested
    };
    assert_eq!(run(u32::MAX, 1, Vec3::ZERO, false), 0, "no colliders");
    assert_eq!(run(0, 1, Vec3::ZERO, true), 0, "empty mask");
    assert_eq!(run(0b10, 0b01, Vec3::ZERO, true), 0, "other layer");
    assert_eq!(run(u32::MAX, 1, Vec3::X * 5.0, true), 0, "out of reach");
    // At least one pass per iteration: 10 frames x 4 substeps x 2 iterations x 7 segments.
    assert!(run(u32::MAX, 1, Vec3::ZERO, true) >= 10 * 4 * 2 * 7, "touching");
}

/// Bad collider input of every kind is rejected with a message and leaves the engine bit-identical.
#[test]
fn bad_collider_input_leaves_state_unchanged() {
    let mut engine = engine_with(EngineSettings::default());
    let id = hanging_chain(&mut engine, 6, ChainParams::default());
    let sphere = ColliderDef::default();
    engine.create_collider(&sphere).unwrap();
    engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
    let hash = engine.state_hash();
    let shape = |shape| ColliderDef { shape, ..sphere };
    let bad_defs = [
        shape(ColliderShape::Sphere { radius: f32::NAN }),
        shape(ColliderShape::Sphere { radius: -1.0 }),
        shape(ColliderShape::Sphere { radius: f32::INFINITY }),
        shape(ColliderShape::Capsule { radius: 0.0, half_height: 0.0 }),
        shape(ColliderShape::Capsule { radius: 0.1, half_height: -0.1 }),
        shape(ColliderShape::InsideSphere { radius: 0.0 }),
        shape(ColliderShape::InsideCapsule { radius: 0.0, half_height: 1.0 }),
        ColliderDef { transform: Transform::new(Vec3::NAN, Quat::IDENTITY), ..sphere },
        ColliderDef { transform: Transform::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)), ..sphere },
        ColliderDef { transform: Transform::new(Vec3::splat(2e9), Quat::IDENTITY), ..sphere },
    ];
    for def in bad_defs {
        let error = engine.create_collider(&def).unwrap_err();
        assert!(!error.message.is_empty());
        assert_eq!(engine.state_hash(), hash, "{def:?}");
    }
    let bad = Transform::new(Vec3::new(0.0, f32::NAN, 0.0), Quat::IDENTITY);
    assert!(engine.set_collider_transforms([bad].into_iter()).is_err());
    assert!(engine.set_collider_transforms([at(HEAD), at(HEAD)].into_iter()).is_err());
    assert!(engine.set_chain_joint_radii(id, &[0.01; 5]).is_err());
    assert!(engine.set_chain_joint_radii(id, &[0.01, 0.01, -0.01, 0.01, 0.01, 0.01]).is_err());
    assert!(engine.set_chain_joint_radii(id, &[0.01, 0.01, f32::NAN, 0.01, 0.01, 0.01]).is_err());
    let mut params = engine.chain_params(id).unwrap();
    params.friction = -0.5;
    assert!(engine.set_chain_params(id, params).is_err());
    assert!(engine.destroy_collider(kodawari::ColliderId::from_bits(id.to_bits())).is_err(), "a chain id");
    assert_eq!(engine.state_hash(), hash);
    // And good input changes it.
    engine.set_chain_joint_radii(id, &[0.01; 6]).unwrap();
    assert_ne!(engine.state_hash(), hash);
}

/// Destroying a collider keeps the others in order; a destroyed collider's id goes stale.
#[test]
fn collider_ids_and_order() {
    let mut engine = engine_with(EngineSettings::default());
    let ids: Vec<_> = (0..3).map(|_| engine.create_collider(&ColliderDef::default()).unwrap()).collect();
    engine.destroy_collider(ids[1]).unwrap();
    assert!(!engine.is_collider_valid(ids[1]));
    assert!(engine.destroy_collider(ids[1]).is_err());
    assert_eq!(engine.collider_ids().collect::<Vec<_>>(), vec![ids[0], ids[2]]);
    assert_eq!(engine.stats().collider_count, 2);
}

/// A chain created inside colliders (SPEC 6.2: colliders overlapping the chain at start) is pushed out
/// without exploding: everything stays finite, ends outside, and no joint is flung faster than 3 m/s (the
/// push out of the overlap is not turned into velocity; what remains is the fall onto the colliders).
#[test]
fn chain_created_inside_colliders_is_pushed_out_calmly() {
    let mut engine = engine_with(EngineSettings::default());
    let base = straight_chain(10, Vec3::ZERO, Vec3::new(1.0, -1.0, 0.2), 0.04);
    let id = engine.create_chain(ChainParams { radius: 0.0, ..Default::default() }, &base).unwrap();
    let ball = ColliderDef {
        shape: ColliderShape::Sphere { radius: 0.12 },
        transform: at(HEAD + Vec3::new(0.12, -0.12, 0.0)),
        layers: 1,
    };
    let bar = ColliderDef {
        shape: ColliderShape::Capsule { radius: 0.03, half_height: 0.2 },
        transform: Transform::new(HEAD + Vec3::new(0.25, -0.25, 0.0), Quat::from_rotation_x(1.0)),
        layers: 1,
    };
    engine.create_collider(&ball).unwrap();
    engine.create_collider(&bar).unwrap();
    let mut fastest = 0.0f32;
    let centre = HEAD + Vec3::new(0.12, -0.12, 0.0);
    for frame in 0..120 {
        engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
        assert!(particles(&engine, id).iter().all(|p| p.is_finite()), "frame {frame}");
        // Unit masses: no joint is faster than sqrt(2 E).
        fastest = fastest.max((2.0 * engine.chain_kinetic_energy(id).unwrap()).sqrt());
    }
    let inside = capsule_penetration(&particles(&engine, id), (centre, centre), 0.12);
    println!("created inside colliders: fastest joint {fastest:.2} m/s, final penetration of the ball {inside:.2e} m");
    assert!(inside <= 1e-4, "{inside}");
    assert!(fastest <= 3.0, "{fastest}");
}

/// A hair root inside the head sphere's reach (the scalp lies inside the sphere inflated by the joint
/// radius) with segments shorter than that overlap: the first joints can clear the sphere only with the
/// chain pointing nearly straight out from the root, if at all. Those joints are not pushed out one by one
/// (which stretched the segments next to the root by up to 146 % and made the lengths solve fail on all 480
/// substeps): the contact of the segment leaving them turns them about the root, lengths kept, and the joint
/// past them slides on the sphere in the contact rounds' lengths solves. The joints farther along clear it.
#[test]
fn joints_the_root_holds_inside_a_collider_keep_their_lengths() {
    let held = RootedInside { joints: 16, segment: 0.004, depth: 0.009, sphere: true }.run();
    println!("root held inside, 16 joints: {held}");
    // Measured 2.9e-5 while it swings (1.7e-3 when the held joints stayed put and the next was pushed).
    held.assert_lengths_and_contacts(1e-4);
    held.assert_direct_solves();
}

/// Bug 9 (docs/robustness.md, fixed): the chain above, only longer, so that it hangs by its weight along the
/// sphere. Its first joint past the held ones lay inside the sphere with the chain pulled taut from the root;
/// every contact round pushed it out and the lengths solve pulled it back by nearly as much, so the rounds
/// never settled and the substeps ended with that segment stretched: up to 2.2e-2 for 64 joints of 4 mm,
/// 5.5e-2 for 257 joints of 3.1 mm (1.1e-2 and 3.1e-2 in the last frame). The turn about the root and the
/// sliding joint settle them (see the test above).
///
/// These fine ropes fail the direct lengths solve on most substeps with or without the sphere (bug 1: the
/// same ropes without it fall back on 290 and 339 of 480 substeps, printed here), so the direct solves are
/// not asserted for them.
#[test]
fn a_long_rope_rooted_inside_a_collider_keeps_its_lengths() {
    let ropes = [
        RootedInside { joints: 64, segment: 0.004, depth: 0.009, sphere: true },
        RootedInside { joints: 257, segment: 0.003125, depth: 0.005, sphere: true },
    ];
    for rope in ropes {
        let held = rope.run();
        let alone = RootedInside { sphere: false, ..rope }.run();
        println!(
            "root held inside, {} joints of {} m: {held}; without the sphere: {} solver fallbacks",
            rope.joints, rope.segment, alone.fallbacks
        );
        held.assert_lengths_and_contacts(5e-3);
    }
}

/// A limp, damped chain whose root lies `depth` inside the reach of a head sphere (its radius plus the joint
/// radius), released straight at 73 degrees from the sphere's outward normal, run for 2 s.
#[derive(Clone, Copy)]
struct RootedInside {
    joints: usize,
    segment: f32,
    depth: f32,
    /// Whether the sphere is there (without it, the same rope for comparison).
    sphere: bool,
}

impl RootedInside {
    fn run(self) -> HeldRun {
        let RootedInside { joints, segment, depth, sphere } = self;
        let mut engine = engine_with(EngineSettings::default());
        let (sphere_radius, joint_radius) = (0.085f32, 0.02f32);
        // The chain is given in the anchor's frame, which is at the sphere's centre.
        let root = Vec3::X * (sphere_radius + joint_radius - depth);
        let base = straight_chain(joints, root, Vec3::new(0.3, -1.0, 0.0), segment);
        let params = ChainParams { stiffness: 0.0, radius: joint_radius, damping: 2.0, ..Default::default() };
        let id = engine.create_chain(params, &base).unwrap();
        let def =
            ColliderDef { shape: ColliderShape::Sphere { radius: sphere_radius }, transform: at(HEAD), layers: 1 };
        if sphere {
            engine.create_collider(&def).unwrap();
        }
        let mut run = HeldRun {
            worst_stretch: 0.0,
            last_stretch: 0.0,
            worst_free_depth: f32::NEG_INFINITY,
            fallbacks: 0,
            substeps: 0,
        };
        for _ in 0..120 {
            engine.step(1.0 / 60.0, CAMERA, at(HEAD)).unwrap();
            let points = particles(&engine, id);
            let stretch = points.windows(2).map(|w| ((w[1] - w[0]).length() / segment - 1.0).abs());
            run.last_stretch = stretch.fold(0.0, f32::max);
            run.worst_stretch = run.worst_stretch.max(run.last_stretch);
            // Joints at least twice the root's depth along the chain can clear the sphere with room to spare.
            let free = points.iter().enumerate().filter(|(j, _)| *j as f32 * segment >= 2.0 * depth);
            let depths = free.map(|(_, p)| sphere_radius + joint_radius - (*p - HEAD).length());
            run.worst_free_depth = depths.fold(run.worst_free_depth, f32::max);
        }
        let stats = engine.stats();
        (run.fallbacks, run.substeps) = (stats.solver_fallbacks, stats.substeps_total);
        run
    }
}

/// What [`RootedInside::run`] measured.
struct HeldRun {
    worst_stretch: f32,
    last_stretch: f32,
    worst_free_depth: f32,
    fallbacks: u64,
    substeps: u64,
}

impl HeldRun {
    fn assert_direct_solves(&self) {
        assert!(self.fallbacks * 20 <= self.substeps, "{} fallbacks", self.fallbacks);
    }

    fn assert_lengths_and_contacts(&self, swinging_stretch: f32) {
        assert!(self.worst_stretch <= swinging_stretch, "stretch {}", self.worst_stretch);
        assert!(self.last_stretch <= 1e-4, "stretch at the end {}", self.last_stretch);
        assert!(
            self.worst_free_depth <= 1e-4,
            "a joint that can clear the sphere is {} m inside",
            self.worst_free_depth
        );
    }
}

impl std::fmt::Display for HeldRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "max stretch {:.2e} (last frame {:.2e}), deepest free joint {:.2e} m, {} solver fallbacks in {} substeps",
            self.worst_stretch, self.last_stretch, self.worst_free_depth, self.fallbacks, self.substeps
        )
    }
}
