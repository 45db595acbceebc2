//! The lane solver (chains side by side in SIMD lanes) against the scalar reference solver, and its
//! determinism policy: a chain's result does not depend on its lane, its group or the kernel copy that ran.

mod common;

use common::*;
use glam::{Quat, Vec3};
use kodawari::{ChainId, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, Solver, Transform};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);

/// The head sways and turns, the camera orbits: every chain bends, turns and re-blends its rest shape.
fn head(frame: usize) -> Transform {
    let t = frame as f32 / 60.0;
    Transform::new(
        HEAD + Vec3::new(0.15 * (5.0 * t).sin(), 0.05 * (7.0 * t).sin(), 0.1 * (3.0 * t).cos()),
        Quat::from_rotation_y(0.6 * (2.0 * t).sin()) * Quat::from_rotation_x(0.3 * (3.0 * t).sin()),
    )
}

fn drive(engine: &mut Engine, frames: std::ops::Range<usize>) {
    for frame in frames {
        let camera = orbit_camera(HEAD, 3.0, frame as f32 * 0.05);
        if engine.collider_count() > 0 {
            engine.set_collider_transforms(colliders(&head(frame)).into_iter()).unwrap();
        }
        engine.step(1.0 / 60.0, camera, head(frame)).unwrap();
    }
}

/// A head sphere the strands fall onto and a shoulder capsule under them, riding with the head.
const HEAD_RADIUS: f32 = 0.09;

fn colliders(head: &Transform) -> [Transform; 2] {
    let shoulder = Transform::new(Vec3::new(0.0, -0.25, 0.0), Quat::from_rotation_z(std::f32::consts::FRAC_PI_2));
    [*head, head.mul(&shoulder)]
}

fn add_colliders(engine: &mut Engine) {
    let [head_pose, shoulder_pose] = colliders(&head(0));
    let sphere = ColliderDef { shape: ColliderShape::Sphere { radius: HEAD_RADIUS }, transform: head_pose, layers: 1 };
    let capsule = ColliderDef {
        shape: ColliderShape::Capsule { radius: 0.06, half_height: 0.15 },
        transform: shoulder_pose,
        layers: 1,
    };
    engine.create_collider(&sphere).unwrap();
    engine.create_collider(&capsule).unwrap();
}

struct Strand {
    joints: usize,
    params: ChainParams,
    views: bool,
}

/// Chains of every kind: 12 stiff-ish chains of 8 joints (a lane group of 8 and one of 4), 4 limp chains of 5
/// joints (a limp group of 4: no shape matching), 5 chains of 16 joints (a group of 8 with 3 spare lanes), 4
/// chains of 2 joints (a group of 4 whose direct solve has a single bond, both the first and the last) and
/// single chains of 3 and 20 joints (the scalar solver), with and without view shapes.
fn strands() -> Vec<Strand> {
    let mut kinds: Vec<(usize, f32)> = Vec::new();
    kinds.extend((0..12).map(|i| (8, [0.3, 0.5, 0.8, 1.0][i % 4])));
    kinds.extend((0..4).map(|_| (5, 0.0)));
    kinds.extend((0..5).map(|i| (16, [0.2, 0.5, 0.7, 0.9, 0.4][i])));
    kinds.extend((0..4).map(|i| (2, [0.3, 0.5, 0.8, 1.0][i])));
    kinds.extend([(3, 0.0), (20, 0.6)]);
    kinds
        .into_iter()
        .enumerate()
        .map(|(i, (joints, stiffness))| Strand {
            joints,
            params: ChainParams {
                stiffness,
                damping: 0.5 + (i % 3) as f32,
                radius: 0.01 + 0.002 * i as f32,
                ..Default::default()
            },
            views: i % 2 == 0,
        })
        .collect()
}

/// The chains the lane solver takes from [`strands`]: all but the last 1 or 2 of a joint count after its groups
/// of 8 (the five 16-joint chains run as a group of 8 with three spare lanes).
const STRANDS_IN_LANES: u32 = 12 + 4 + 5 + 4;
/// The two-joint chains among them.
const TWO_JOINT_STRANDS: u32 = 4;

fn build(solver: Solver, strands: &[Strand], with_colliders: bool) -> (Engine, Vec<(ChainId, f32)>) {
    let (mut engine, ids) = build_with_subject_at(strands, usize::MAX, solver);
    if with_colliders {
        add_colliders(&mut engine);
    }
    (engine, ids)
}

/// Largest distance between the two engines' joints, per chain length, over `frames`, checked every frame.
fn largest_difference(strands: &[Strand], in_lanes: u32, frames: usize, with_colliders: bool) -> f32 {
    let (mut lanes, ids) = build(Solver::Lanes, strands, with_colliders);
    let (mut scalar, scalar_ids) = build(Solver::Scalar, strands, with_colliders);
    let mut worst = 0.0f32;
    for frame in 0..frames {
        drive(&mut lanes, frame..frame + 1);
        drive(&mut scalar, frame..frame + 1);
        assert_eq!(lanes.stats().lane_chains, in_lanes, "frame {frame}");
        assert_same_work(&lanes, &scalar, frame);
        // Limp chains have no shape matching, so both solvers compute the very same positions (the root's
        // orientation, anchor times rest, is multiplied in a different order).
        for (s, (&(id, _), &(scalar_id, _))) in strands.iter().zip(ids.iter().zip(&scalar_ids)) {
            if s.params.stiffness == 0.0 {
                let positions =
                    |engine: &Engine, id| chain_world(engine, id).iter().map(|t| t.position).collect::<Vec<_>>();
                assert_eq!(positions(&lanes, id), positions(&scalar, scalar_id), "limp chain, frame {frame}");
            }
        }
        assert_eq!(scalar.stats().lane_chains, 0);
        for (&(id, length), &(scalar_id, _)) in ids.iter().zip(&scalar_ids) {
            let (a, b) = (chain_world(&lanes, id), chain_world(&scalar, scalar_id));
            for (x, y) in a.iter().zip(&b) {
                worst = worst.max((x.position - y.position).length() / length);
            }
        }
    }
    worst
}

/// The same contact passes and fallbacks, counted the same way, whichever solver ran them: equal up to the
/// few decisions a rounding difference can flip (a final contact round more or less when the deepest
/// correction sits at the settled distance, a fallback when the direct solve ends at the stagnation floor).
fn assert_same_work(lanes: &Engine, scalar: &Engine, frame: usize) {
    let (a, b) = (lanes.stats(), scalar.stats());
    let pairs = a.contact_pairs_tested.abs_diff(b.contact_pairs_tested) as f64;
    assert!(pairs <= 1e-3 * b.contact_pairs_tested as f64, "frame {frame}: contact pairs {a:?} vs {b:?}");
    let fallbacks = a.solver_fallbacks.abs_diff(b.solver_fallbacks) as f64;
    assert!(fallbacks <= 2.0 + 0.01 * b.solver_fallbacks as f64, "frame {frame}: fallbacks {a:?} vs {b:?}");
}

/// The two solvers implement the same operations; they differ by float rounding, which the motion amplifies
/// only slowly over a second of strong swaying (the limp chains are chaotic n-pendulums).
#[test]
fn lane_solver_matches_the_scalar_solver() {
    let strands = strands();
    let worst = largest_difference(&strands, STRANDS_IN_LANES, 60, false);
    println!(
        "lane vs scalar solver, 1 s of swaying, {} chains ({STRANDS_IN_LANES} in lanes): largest joint distance {worst:.2e} chain lengths",
        strands.len()
    );
    assert!(worst <= 1e-4, "{worst}");
}

/// With colliders the lane solver runs the contact pass on the lanes that can touch one (scalar, lane by
/// lane): the same contacts as the scalar solver, up to the rounding the rest of the substep differs by.
#[test]
fn lane_solver_matches_the_scalar_solver_with_colliders() {
    // Thin strands (8 to 12 mm joints, three frictions), so that no joint next to a root is buried in the head
    // sphere, where no contact can be resolved and rounding differences grow without bound. Without the
    // two-joint chains, whose one moving joint is next to its root: on one of them (of 0.03 m) the solvers'
    // difference grows from rounding at frame 2 to a fifth of its length by frame 41 as it rides the sphere.
    let strands: Vec<Strand> = strands()
        .into_iter()
        .filter(|s| s.joints != 2)
        .enumerate()
        .map(|(i, s)| {
            let radius = 0.008 + 0.0002 * i as f32;
            let friction = [0.0, 0.3, 0.6][i % 3];
            Strand { params: ChainParams { radius, friction, ..s.params }, ..s }
        })
        .collect();
    let worst = largest_difference(&strands, STRANDS_IN_LANES - TWO_JOINT_STRANDS, 60, true);
    // The colliders matter: without them the strands end up elsewhere.
    let (mut with, ids) = build(Solver::Lanes, &strands, true);
    let (mut without, without_ids) = build(Solver::Lanes, &strands, false);
    drive(&mut with, 0..60);
    drive(&mut without, 0..60);
    let pairs = with.stats().contact_pairs_tested;
    let mut moved = 0.0f32;
    let mut deepest = 0.0f32;
    for (&(id, length), &(other, _)) in ids.iter().zip(&without_ids) {
        let (a, b) = (chain_world(&with, id), chain_world(&without, other));
        for (x, y) in a.iter().zip(&b).skip(1) {
            moved = moved.max((x.position - y.position).length() / length);
            let head_pose = head(59);
            deepest = deepest.max(HEAD_RADIUS - (x.position - head_pose.position).length());
        }
    }
    println!(
        "lane vs scalar solver with a head sphere and a shoulder capsule, 1 s: largest joint distance {worst:.2e} \
         chain lengths; {pairs} contact pairs tested; the colliders moved a joint by {moved:.2} chain lengths; \
         deepest joint centre inside the head sphere {deepest:.1e} m"
    );
    assert!(pairs > 0 && moved > 0.05, "the colliders must change the motion ({pairs} pairs, moved {moved})");
    assert!(deepest <= 0.0, "a joint centre is {deepest} m inside the head sphere");
    assert!(worst <= 1e-4, "{worst}");
}

/// A chain's particles in the latest internal state, as bits.
fn particle_bits(engine: &Engine, id: ChainId) -> Vec<[u32; 3]> {
    let mut bits = Vec::new();
    engine.for_each_chain_particle(id, |x| bits.push(x.to_array().map(f32::to_bits))).unwrap();
    bits
}

/// The determinism policy: a chain's motion is the same to the bit in a group of 4 and at any lane of a group
/// of 16, 8 or 4 among other chains of its length, also in a group whose spare lanes repeat a chain, on the
/// AVX-512 and AVX2 kernels (where the CPU has them) and on the portable one. (Alone, a chain takes the scalar solver: too few of
/// its kind for a group.)
#[test]
fn a_chains_motion_does_not_depend_on_its_lane_or_group() {
    let crowd = |count: usize, subject: usize| -> Vec<Strand> {
        let mut strands: Vec<Strand> = (0..count)
            .map(|i| Strand {
                joints: 10,
                params: ChainParams {
                    stiffness: 0.2 + 0.05 * (i % 12) as f32,
                    damping: i as f32,
                    ..Default::default()
                },
                views: i % 3 == 0,
            })
            .collect();
        strands[subject] =
            Strand { joints: 10, params: ChainParams { stiffness: 0.6, ..Default::default() }, views: true };
        strands
    };
    for with_colliders in [false, true] {
        let build = |strands: &[Strand], subject: usize, solver: Solver| {
            let (mut engine, ids) = build_with_subject_at(strands, subject, solver);
            if with_colliders {
                add_colliders(&mut engine);
            }
            (engine, ids)
        };
        let (mut small, ids) = build(&crowd(4, 2), 2, Solver::Lanes);
        drive(&mut small, 0..90);
        assert_eq!(small.stats().lane_chains, 4);
        assert_eq!(small.stats().contact_pairs_tested > 0, with_colliders);
        let reference = particle_bits(&small, ids[2].0);
        let reference_pose = chain_world(&small, ids[2].0);
        // 12 chains: lanes 0-7 form a group of 8, 8-11 a group of 4. 11: the last three a group of 4 with a
        // spare lane; 13: the last five a group of 8 with three.
        // The first chain of a group with spare lanes is the one they repeat: (11, 8) and (13, 8); 3 and 6
        // chains: a lone group of 4 or 8 with spare lanes. Where the CPU has AVX-512: 16 chains a group of 16,
        // 20 a group of 16 and one of 4, 29 groups of 16 and 8 and a group of 8 with three spare lanes (on the
        // portable kernel, and on other CPUs, groups of 8 and 4 instead).
        let places = [
            (12, 0usize),
            (12, 3),
            (12, 7),
            (12, 9),
            (12, 11),
            (11, 8),
            (11, 9),
            (13, 8),
            (13, 12),
            (3, 0),
            (6, 5),
            (16, 0),
            (16, 15),
            (20, 17),
            (29, 21),
            (29, 27),
        ];
        for solver in [Solver::Lanes, Solver::LanesPortable] {
            for (count, position) in places {
                let (mut engine, ids) = build(&crowd(count, position), position, solver);
                drive(&mut engine, 0..90);
                assert_eq!(engine.stats().lane_chains, count as u32, "every chain in lanes");
                let what = format!("{solver:?}, {count} chains, lane position {position}, colliders {with_colliders}");
                assert_eq!(particle_bits(&engine, ids[position].0), reference, "{what}");
                assert_eq!(chain_world(&engine, ids[position].0), reference_pose, "{what}");
            }
        }
    }
    println!("lane solver kernel: {}", kodawari::simd_path());
}

/// Chain `i` grows in a direction of its own (angle `0.7 i` around the head), but the one at `subject`, which
/// always gets angle 0.
fn build_with_subject_at(strands: &[Strand], subject: usize, solver: Solver) -> (Engine, Vec<(ChainId, f32)>) {
    let mut engine = Engine::new(EngineSettings::default()).unwrap();
    engine.set_solver(solver);
    let mut ids = Vec::new();
    for (i, s) in strands.iter().enumerate() {
        let angle = if i == subject { 0.0 } else { i as f32 * 0.7 };
        let direction = Vec3::new(angle.cos(), 0.4, angle.sin());
        let base = curled_chain(s.joints, Vec3::new(0.0, 0.1, 0.0), direction, Vec3::Y, 0.2, 0.03);
        let id = engine.create_chain(s.params, &base).unwrap();
        if s.views {
            let view = curled_chain(s.joints, Vec3::new(0.0, 0.1, 0.0), direction, Vec3::X, -0.4, 0.03);
            engine.add_view_shape(id, Vec3::X, &view, 2.0).unwrap();
        }
        ids.push((id, chain_length(&base)));
    }
    (engine, ids)
}

/// A chain that collides with nothing (mask 0) in a lane group whose other chains touch colliders runs exactly
/// as in a group without any contacts.
#[test]
fn a_lane_without_contacts_is_unaffected_by_contacts_in_its_group() {
    let crowd: Vec<Strand> = (0..4)
        .map(|i| Strand {
            joints: 10,
            params: ChainParams {
                stiffness: 0.3 + 0.1 * i as f32,
                radius: 0.01,
                collision_mask: if i == 2 { 0 } else { u32::MAX },
                ..Default::default()
            },
            views: i % 2 == 0,
        })
        .collect();
    let (mut alone, ids) = build_with_subject_at(&crowd, 2, Solver::Lanes);
    drive(&mut alone, 0..90);
    assert_eq!(alone.stats().contact_pairs_tested, 0);
    let (mut mixed, mixed_ids) = build_with_subject_at(&crowd, 2, Solver::Lanes);
    add_colliders(&mut mixed);
    drive(&mut mixed, 0..90);
    assert_eq!(mixed.stats().lane_chains, 4);
    assert!(mixed.stats().contact_pairs_tested > 0, "the other three chains must touch the colliders");
    assert_eq!(particle_bits(&mixed, mixed_ids[2].0), particle_bits(&alone, ids[2].0));
}

/// Fine ropes over the head sphere: their direct solve fails on most substeps, also in the final contact
/// rounds, so the lane solver's masked solve and per-lane fallback run there. Until the first decision a
/// rounding difference flips (a fallback in frame 5), the same counts as the scalar solver, and a difference
/// no larger than a one-ulp move of the roots makes on the scalar solver itself; after it the ropes part
/// ways (the fallback and the contacts are not smooth), so the rest of the run checks the determinism policy
/// instead: a rope's bits do not depend on its lane or on its neighbours, whatever they fall back on.
#[test]
fn fine_ropes_on_a_collider_match_the_scalar_solver() {
    let build_ropes_nudged = |solver: Solver, subject: usize, nudge: f32| {
        let mut engine = Engine::new(EngineSettings::default()).unwrap();
        engine.set_solver(solver);
        let mut ids = Vec::new();
        for i in 0..4 {
            let (angle, stiffness) = if i == subject { (0.0, 0.5) } else { (i as f32 * 1.3, 0.2 + 0.2 * i as f32) };
            let direction = Vec3::new(angle.cos(), 0.2, angle.sin());
            let base = straight_chain(100, Vec3::new(0.0, 0.1 + nudge, 0.0), direction, 0.8 / 99.0);
            let params = ChainParams { stiffness, radius: 0.004, ..Default::default() };
            ids.push((engine.create_chain(params, &base).unwrap(), chain_length(&base)));
        }
        add_colliders(&mut engine);
        (engine, ids)
    };
    let build_ropes = |solver: Solver, subject: usize| build_ropes_nudged(solver, subject, 0.0);
    let (mut lanes, ids) = build_ropes(Solver::Lanes, 0);
    let (mut scalar, scalar_ids) = build_ropes(Solver::Scalar, 0);
    // The control: the scalar solver against itself with the ropes' roots moved by a float32 rounding step.
    let (mut nudged, nudged_ids) = build_ropes_nudged(Solver::Scalar, 0, 1e-8);
    let mut control = 0.0f32;
    let mut worst = 0.0f32;
    for frame in 0..5 {
        drive(&mut lanes, frame..frame + 1);
        drive(&mut scalar, frame..frame + 1);
        drive(&mut nudged, frame..frame + 1);
        for (&(id, length), &(other, _)) in scalar_ids.iter().zip(&nudged_ids) {
            let (a, b) = (chain_world(&scalar, id), chain_world(&nudged, other));
            for (x, y) in a.iter().zip(&b) {
                control = control.max((x.position - y.position).length() / length);
            }
        }
        assert_eq!(lanes.stats().lane_chains, 4);
        assert_eq!(lanes.stats().contact_pairs_tested, scalar.stats().contact_pairs_tested, "frame {frame}");
        assert_eq!(lanes.stats().solver_fallbacks, scalar.stats().solver_fallbacks, "frame {frame}");
        for (&(id, length), &(scalar_id, _)) in ids.iter().zip(&scalar_ids) {
            let (a, b) = (chain_world(&lanes, id), chain_world(&scalar, scalar_id));
            for (x, y) in a.iter().zip(&b) {
                worst = worst.max((x.position - y.position).length() / length);
            }
        }
    }
    assert!(lanes.stats().solver_fallbacks > 0, "the scene must exercise the fallback");
    // Fine ropes beyond the direct solve's wave limit (bug 1) amplify any rounding difference: the lane solver
    // must stay within what a one-ulp move of the roots does to the scalar solver itself.
    assert!(worst <= control, "lanes vs scalar {worst} beyond the scene's own rounding sensitivity {control}");

    drive(&mut lanes, 5..30);
    let reference = particle_bits(&lanes, ids[0].0);
    let (mut moved, moved_ids) = build_ropes(Solver::LanesPortable, 3);
    drive(&mut moved, 0..30);
    assert_eq!(particle_bits(&moved, moved_ids[3].0), reference, "the rope at lane 3 among other neighbours");
    let (fallbacks, chain_substeps) = (lanes.stats().solver_fallbacks, lanes.stats().substeps_total * 4);
    println!(
        "fine ropes on the head sphere: lanes vs scalar {worst:.2e} chain lengths over 5 frames (scalar vs scalar \
         with the roots 1e-8 m apart: {control:.2e}); 0.5 s: fallback in {fallbacks} of {chain_substeps} \
         chain-substeps, {} contact pairs, the same bits at lane 0 and 3",
        lanes.stats().contact_pairs_tested
    );
}

/// Four or eight limp chains (no shape matching) on the lane solver and the same on the scalar solver, driven
/// for `frames`: every frame, all of them in one lane group, the same contact pairs and fallbacks, the same bits.
fn drive_limp_side_by_side(
    lanes: &mut Engine,
    ids: &[ChainId],
    scalar: &mut Engine,
    scalar_ids: &[ChainId],
    frames: usize,
) {
    for frame in 0..frames {
        drive(lanes, frame..frame + 1);
        drive(scalar, frame..frame + 1);
        assert_same_frame(lanes, ids, scalar, scalar_ids, frame);
    }
}

/// After `frame`: every chain of `ids` in lanes, and the same contact pairs, fallbacks and bits on both solvers.
fn assert_same_frame(lanes: &Engine, ids: &[ChainId], scalar: &Engine, scalar_ids: &[ChainId], frame: usize) {
    assert_eq!(lanes.stats().lane_chains, ids.len() as u32);
    assert_eq!(lanes.stats().contact_pairs_tested, scalar.stats().contact_pairs_tested, "frame {frame}");
    assert_eq!(lanes.stats().solver_fallbacks, scalar.stats().solver_fallbacks, "frame {frame}");
    for (&id, &scalar_id) in ids.iter().zip(scalar_ids) {
        assert_eq!(particle_bits(lanes, id), particle_bits(scalar, scalar_id), "frame {frame}");
    }
}

/// Bug 9's ropes (docs/robustness.md) side by side: roots inside the head sphere's reach, so the contact
/// rounds turn the joints the roots hold and let the joint past them slide on the sphere
/// (`inextensible::solve_sliding`), which the lane solver runs lane by lane with the scalar code. Limp ropes
/// have no shape matching, so both solvers must compute the very same positions and do the same work. Four
/// ropes make a group of 4 (the contact pass lane by lane); eight a group of 8, whose contact pass screens the
/// segments in lanes where the CPU has AVX2 (`lanes::outside`).
#[test]
fn ropes_rooted_inside_a_collider_match_the_scalar_solver() {
    for ropes in [4, 8] {
        ropes_rooted_inside_a_collider(ropes);
    }
}

fn ropes_rooted_inside_a_collider(ropes: usize) {
    let build_rooted = |solver: Solver| {
        let mut engine = Engine::new(EngineSettings::default()).unwrap();
        engine.set_solver(solver);
        let radius = 0.02;
        let mut ids = Vec::new();
        for i in 0..ropes {
            let around = i as f32 * 0.4 - 0.6;
            let out = Vec3::new(around.cos(), 0.0, around.sin());
            // 9 mm inside the reach with 4 mm segments: the first joints are held (`collision::held_by_root`).
            let root = out * (HEAD_RADIUS + radius - 0.009);
            let base = straight_chain(32, root, out * 0.3 - Vec3::Y, 0.004);
            let params = ChainParams { stiffness: 0.0, radius, damping: 2.0, ..Default::default() };
            ids.push(engine.create_chain(params, &base).unwrap());
        }
        add_colliders(&mut engine);
        (engine, ids)
    };
    let (mut lanes, ids) = build_rooted(Solver::Lanes);
    let (mut scalar, scalar_ids) = build_rooted(Solver::Scalar);
    drive_limp_side_by_side(&mut lanes, &ids, &mut scalar, &scalar_ids, 30);
    // The joints past the held ones (2 x 9 mm of rest length from the root) are out of the sphere's reach.
    let head_pose = head(29);
    let deepest = ids
        .iter()
        .flat_map(|&id| chain_world(&lanes, id).into_iter().skip(5))
        .map(|joint| HEAD_RADIUS + 0.02 - (joint.position - head_pose.position).length())
        .fold(f32::NEG_INFINITY, f32::max);
    println!(
        "{ropes} ropes rooted inside the head sphere's reach, 0.5 s: the same bits on both solvers, {} contact \
         pairs, {} fallbacks; deepest joint past the held ones {deepest:.1e} m inside the sphere's reach",
        lanes.stats().contact_pairs_tested,
        lanes.stats().solver_fallbacks
    );
    assert!(deepest <= 1e-4, "{deepest}");
}

/// Hair ropes of 600 segments of 2.5 cm, limp, hanging from the swaying head: their direct solve fails on
/// most substeps and the Gauss-Newton projection converges, so after two such substeps in a row a solve goes
/// straight to the projection (`inextensible::solve_warm`) until its next retry of the direct solve. The lane
/// solver decides the same per lane: without shape matching both solvers compute the very same positions and
/// count the same fallbacks, frame by frame.
#[test]
fn hair_ropes_that_keep_falling_back_match_the_scalar_solver() {
    let build_ropes = |solver: Solver| {
        let mut engine = Engine::new(EngineSettings::default()).unwrap();
        engine.set_solver(solver);
        let ids: Vec<ChainId> = (0..4)
            .map(|i| {
                let around = i as f32 * 1.1;
                let base = straight_chain(
                    601,
                    Vec3::new(0.0, 0.1, 0.0),
                    Vec3::new(0.2 * around.cos(), -1.0, 0.2 * around.sin()),
                    0.025,
                );
                let params = ChainParams { stiffness: 0.0, damping: 0.2 * i as f32, ..Default::default() };
                engine.create_chain(params, &base).unwrap()
            })
            .collect();
        (engine, ids)
    };
    let (mut lanes, ids) = build_ropes(Solver::Lanes);
    let (mut scalar, scalar_ids) = build_ropes(Solver::Scalar);
    drive_limp_side_by_side(&mut lanes, &ids, &mut scalar, &scalar_ids, 30);
    let (fallbacks, chain_substeps) = (lanes.stats().solver_fallbacks, lanes.stats().substeps_total * 4);
    println!(
        "hair ropes, 0.5 s: the same bits on both solvers; fallback in {fallbacks} of {chain_substeps} chain-substeps"
    );
    // Most substeps fall back, so streaks of two and more run (and skip the direct solve).
    assert!(fallbacks * 10 >= chain_substeps * 6, "{fallbacks} of {chain_substeps}");
}

/// A ball created where eight limp ropes hang, deep inside it (a collider created on the chains): the substep
/// starts with pre-stabilisation's rounds of lengths and contacts at the start positions
/// (`collision::pre_stabilise`), whose first contact pass the lane solver runs in lanes for a group of 8
/// (`lanes::outside::pre_stabilise`, screened where the CPU has AVX2), the rounds lane by lane. A second ball is
/// created around the ropes' roots, so that each root holds joints inside it (bug 9): those lanes take the scalar
/// turn in pre-stabilisation's first pass. Limp ropes have no shape matching, so both solvers must compute the
/// very same positions and do the same work, frame by frame.
#[test]
fn ropes_a_ball_appears_around_match_the_scalar_solver() {
    let around_the_middles = ropes_a_ball_appears_around(head(0).position - Vec3::new(0.0, 0.25, 0.0), 0.16);
    println!(
        "a ball created around 8 limp ropes: {} joints up to {:.3} m inside its reach; 10 frames later the deepest \
         {:.1e} m; the same bits on both solvers",
        around_the_middles.joints_inside, around_the_middles.deepest_before, around_the_middles.deepest_after
    );
    assert!(
        around_the_middles.joints_inside >= 8 && around_the_middles.deepest_before > 0.02,
        "{} joints, {} m",
        around_the_middles.joints_inside,
        around_the_middles.deepest_before
    );
    assert!(around_the_middles.deepest_after <= 1e-3, "{}", around_the_middles.deepest_after);

    let around_the_roots = ropes_a_ball_appears_around(head(10).position, 0.13);
    println!(
        "a ball created around the roots of 8 limp ropes: {} roots inside its reach; the same bits on both solvers",
        around_the_roots.roots_inside
    );
    assert_eq!(around_the_roots.roots_inside, 8);
}

/// What [`ropes_a_ball_appears_around`] saw: joints and roots inside the ball's reach as it was created, and the
/// deepest joint then and 10 frames later (m).
struct BallCreated {
    joints_inside: usize,
    roots_inside: usize,
    deepest_before: f32,
    deepest_after: f32,
}

/// Eight limp ropes hanging from the swaying head on the lane and the scalar solver, side by side; after 10 frames
/// a ball of `ball_radius` at `ball_centre` (world) is created in both, and 10 more frames run with it. Checks the
/// same bits, contact pairs and fallbacks frame by frame.
fn ropes_a_ball_appears_around(ball_centre: Vec3, ball_radius: f32) -> BallCreated {
    const ROPE_RADIUS: f32 = 0.01;
    let build = |solver: Solver| {
        let mut engine = Engine::new(EngineSettings::default()).unwrap();
        engine.set_solver(solver);
        let ids: Vec<ChainId> = (0..8)
            .map(|i| {
                let around = i as f32 * 0.785;
                let out = Vec3::new(around.cos(), 0.0, around.sin());
                let base = straight_chain(16, out * (HEAD_RADIUS + 0.03), out * 0.2 - Vec3::Y, 0.02);
                let params = ChainParams { stiffness: 0.0, radius: ROPE_RADIUS, damping: 2.0, ..Default::default() };
                engine.create_chain(params, &base).unwrap()
            })
            .collect();
        add_colliders(&mut engine);
        (engine, ids)
    };
    let (mut lanes, ids) = build(Solver::Lanes);
    let (mut scalar, scalar_ids) = build(Solver::Scalar);
    let depth = |joint: &Transform| ball_radius + ROPE_RADIUS - (joint.position - ball_centre).length();
    let inside_ball = |engine: &Engine| {
        let depths: Vec<f32> = ids.iter().flat_map(|&id| chain_world(engine, id)).map(|joint| depth(&joint)).collect();
        (depths.iter().filter(|&&depth| depth > 0.0).count(), depths.into_iter().fold(f32::NEG_INFINITY, f32::max))
    };
    drive_limp_side_by_side(&mut lanes, &ids, &mut scalar, &scalar_ids, 10);
    let (joints_inside, deepest_before) = inside_ball(&lanes);
    let roots_inside = ids.iter().filter(|&&id| depth(&chain_world(&lanes, id)[0]) > 0.0).count();
    let ball = ColliderDef {
        shape: ColliderShape::Sphere { radius: ball_radius },
        transform: Transform::new(ball_centre, Quat::IDENTITY),
        layers: 1,
    };
    for engine in [&mut lanes, &mut scalar] {
        engine.create_collider(&ball).unwrap();
    }
    for frame in 10..20 {
        for engine in [&mut lanes, &mut scalar] {
            let [head_pose, shoulder_pose] = colliders(&head(frame));
            let ball_pose = Transform::new(ball_centre, Quat::IDENTITY);
            engine.set_collider_transforms([head_pose, shoulder_pose, ball_pose].into_iter()).unwrap();
            engine.step(1.0 / 60.0, orbit_camera(HEAD, 3.0, frame as f32 * 0.05), head(frame)).unwrap();
        }
        assert_same_frame(&lanes, &ids, &scalar, &scalar_ids, frame);
    }
    let (_, deepest_after) = inside_ball(&lanes);
    BallCreated { joints_inside, roots_inside, deepest_before, deepest_after }
}
