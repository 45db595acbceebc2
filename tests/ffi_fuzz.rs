//! API fuzzing through the C ABI (SPEC 6.2): random sequences of C calls — create/destroy engines, chains
//! (0..40 joints, random and invalid floats), view shapes, colliders (random shapes, sizes, poses, layers;
//! batched pose updates with random counts), per-joint radii, teleports, anchors with random counts, steps
//! with random (also invalid) dt, reads with random capacities, resets, def changes, solver switches (also to
//! unknown values) — driven by proptest with
//! a fixed ChaCha seed, so CI runs are reproducible.
//!
//! Invariants: no call returns `KDW_STATUS_PANIC`; every successful read returns finite values; issued ids
//! are never 0; a destroyed object's id is rejected afterwards; a rejected call leaves the engine's state
//! hash unchanged; every engine is destroyed at the end (no leak: run under valgrind, see
//! `docs/robustness.md`).
//!
//! Quick: 256 cases of up to 200 calls. Long: `cargo test --release --test ffi_fuzz -- --ignored`
//! (`KDW_FUZZ_CASES` and `KDW_FUZZ_SEED` override the long run's case count and seed).

use std::ptr::null_mut;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use kodawari::ffi::chain::*;
use kodawari::ffi::collider::*;
use kodawari::ffi::engine::*;
use kodawari::ffi::status::*;
use kodawari::ffi::types::*;
use kodawari::ffi::view_shape::*;

/// One fuzz call, as raw random material that `apply` interprets.
#[derive(Clone, Debug)]
struct Call {
    kind: u8,
    pick: u64,
    pick2: u64,
    n: u32,
    f: [f32; 4],
}

/// Floats: mostly ordinary values, often special ones (non-finite, zero, huge, tiny, subnormal).
fn any_float() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -2.0f32..2.0,
        1 => -100.0f32..100.0,
        2 => prop::sample::select(vec![
            0.0,
            -0.0,
            1.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e30,
            -1e30,
            f32::MAX,
            f32::MIN_POSITIVE,
            1e-40,
            1e4,
            -1e4,
            1.0 / 60.0,
            0.1,
        ]),
    ]
}

fn call() -> impl Strategy<Value = Call> {
    (0u8..30, any::<u64>(), any::<u64>(), 0u32..40, [any_float(), any_float(), any_float(), any_float()])
        .prop_map(|(kind, pick, pick2, n, f)| Call { kind, pick, pick2, n, f })
}

/// What the fuzzer knows: live engines, and every id it was ever given (with whether it is still alive).
#[derive(Default)]
struct World {
    engines: Vec<*mut kdw_engine>,
    chains: Vec<(usize, u64, bool)>,
    views: Vec<(usize, u64, bool)>,
    colliders: Vec<(usize, u64, bool)>,
    calls: u64,
    ok_calls: u64,
    /// Let huge finite positions through (the known-bug replay).
    untamed: bool,
}

fn vec3(x: f32, y: f32, z: f32) -> kdw_vec3 {
    kdw_vec3 { x, y, z }
}

fn quat(x: f32, y: f32, z: f32, w: f32) -> kdw_quat {
    kdw_quat { x, y, z, w }
}

/// A joint array: usually a valid bent chain, sometimes with a random float dropped in (`f`).
fn joints(n: u32, seed: u64, f: f32) -> Vec<kdw_transform> {
    let mut out: Vec<kdw_transform> = (0..n)
        .map(|i| {
            let a = (seed % 7) as f32 * 0.1 * i as f32;
            kdw_transform {
                position: vec3(0.05 * a.sin() * i as f32, -0.05 * i as f32, 0.01 * (seed % 3) as f32 * i as f32),
                rotation: quat(0.0, (a * 0.5).sin(), 0.0, (a * 0.5).cos()),
            }
        })
        .collect();
    if n > 0 && seed.is_multiple_of(4) {
        let k = (seed / 4) as usize % n as usize;
        match (seed / 64) % 4 {
            0 => out[k].position.x = f,
            1 => out[k].rotation.w = f,
            2 => out[k].rotation = quat(0.0, 0.0, 0.0, 0.0),
            _ => out[k].position = out[(k + 1) % n as usize].position,
        }
    }
    out
}

fn transform(f: [f32; 4], valid: bool, untamed: bool) -> kdw_transform {
    let tame = |x: f32| if untamed { x } else { tame(x) };
    if valid {
        kdw_transform {
            position: vec3(f[0].clamp(-5.0, 5.0), 1.6, 0.0),
            rotation: quat(0.0, f[1].clamp(-1.0, 1.0), 0.0, 1.0),
        }
    } else {
        // Finite values tamed: a view reference at 1e30 is a known bug (`fuzz_finding_view_reference_at_1e30`).
        kdw_transform { position: vec3(tame(f[0]), tame(f[1]), tame(f[2])), rotation: quat(f[3], 0.0, 0.0, f[1]) }
    }
}

/// Finite values clamped to +-1e3 (non-finite ones kept, to be rejected): huge but valid gravity is a known
/// bug (ffi_bad_input::huge_gravity_stays_finite), so the fuzzer does not rediscover it every run.
fn tame(x: f32) -> f32 {
    if x.is_finite() { x.clamp(-1e3, 1e3) } else { x }
}

fn finite_transforms(t: &[kdw_transform]) -> bool {
    t.iter().all(|t| {
        [t.position.x, t.position.y, t.position.z, t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w]
            .iter()
            .all(|v| v.is_finite())
    })
}

fn hash(engine: *mut kdw_engine) -> u64 {
    let mut h = 0;
    assert_eq!(kdw_engine_state_hash(engine, &mut h), KDW_STATUS_OK);
    h
}

impl World {
    fn engine(&self, pick: u64) -> Option<(usize, *mut kdw_engine)> {
        if self.engines.is_empty() {
            None
        } else {
            let i = pick as usize % self.engines.len();
            Some((i, self.engines[i]))
        }
    }

    /// A chain id for engine `e`: mostly one of its live chains, else anything known (stale, foreign, a view
    /// shape id), 0, or random bits.
    fn chain_id(&self, e: usize, pick: u64) -> u64 {
        let own: Vec<u64> = self.chains.iter().filter(|c| c.0 == e && c.2).map(|c| c.1).collect();
        match pick % 10 {
            0 => 0,
            1 => pick,
            2 if !self.views.is_empty() => self.views[(pick / 10) as usize % self.views.len()].1,
            3 | 4 if !self.chains.is_empty() => self.chains[(pick / 10) as usize % self.chains.len()].1,
            _ if !own.is_empty() => own[(pick / 10) as usize % own.len()],
            _ => 0,
        }
    }

    fn view_id(&self, e: usize, pick: u64) -> u64 {
        let own: Vec<u64> = self.views.iter().filter(|c| c.0 == e && c.2).map(|c| c.1).collect();
        match pick % 10 {
            0 => 0,
            1 => pick,
            2 if !self.chains.is_empty() => self.chains[(pick / 10) as usize % self.chains.len()].1,
            3 | 4 if !self.views.is_empty() => self.views[(pick / 10) as usize % self.views.len()].1,
            _ if !own.is_empty() => own[(pick / 10) as usize % own.len()],
            _ => 0,
        }
    }

    /// A collider id for engine `e`: mostly one of its live colliders, else anything known (stale, foreign, a
    /// chain id), 0, or random bits.
    fn collider_id(&self, e: usize, pick: u64) -> u64 {
        let own: Vec<u64> = self.colliders.iter().filter(|c| c.0 == e && c.2).map(|c| c.1).collect();
        match pick % 10 {
            0 => 0,
            1 => pick,
            2 if !self.chains.is_empty() => self.chains[(pick / 10) as usize % self.chains.len()].1,
            3 | 4 if !self.colliders.is_empty() => self.colliders[(pick / 10) as usize % self.colliders.len()].1,
            _ if !own.is_empty() => own[(pick / 10) as usize % own.len()],
            _ => 0,
        }
    }

    fn is_live_collider(&self, e: usize, id: u64) -> bool {
        self.colliders.iter().any(|c| c.0 == e && c.1 == id && c.2)
    }

    fn collider_count(engine: *mut kdw_engine) -> u32 {
        let mut n = 0;
        assert_eq!(kdw_engine_collider_count(engine, &mut n), KDW_STATUS_OK);
        n
    }

    fn is_live_chain(&self, e: usize, id: u64) -> bool {
        self.chains.iter().any(|c| c.0 == e && c.1 == id && c.2)
    }

    fn is_live_view(&self, e: usize, id: u64) -> bool {
        self.views.iter().any(|c| c.0 == e && c.1 == id && c.2)
    }

    fn chain_count(engine: *mut kdw_engine) -> u32 {
        let mut n = 0;
        assert_eq!(kdw_engine_chain_count(engine, &mut n), KDW_STATUS_OK);
        n
    }

    fn joint_count(engine: *mut kdw_engine) -> u32 {
        let mut n = 0;
        assert_eq!(kdw_engine_joint_count(engine, &mut n), KDW_STATUS_OK);
        n
    }

    /// Performs one call and checks the invariants that do not need a model of the physics.
    fn apply(&mut self, c: &Call) -> Result<(), TestCaseError> {
        self.calls += 1;
        let Some((e, engine)) = self.engine(c.pick) else {
            // No engine yet: create one (valid def most of the time).
            return self.create_engine(c);
        };
        let before = hash(engine);
        let mut ok_means_finite_read = None::<Vec<kdw_transform>>;
        let status = match c.kind {
            0 => return self.create_engine(c),
            1 => {
                if c.pick2.is_multiple_of(8) {
                    // Destroy the engine: every id of it dies with it.
                    prop_assert_eq!(kdw_engine_destroy(engine), KDW_STATUS_OK);
                    self.engines.remove(e);
                    self.chains.retain(|x| x.0 != e);
                    self.views.retain(|x| x.0 != e);
                    self.colliders.retain(|x| x.0 != e);
                    for x in self.chains.iter_mut().chain(self.views.iter_mut()).chain(self.colliders.iter_mut()) {
                        if x.0 > e {
                            x.0 -= 1;
                        }
                    }
                    return Ok(());
                }
                KDW_STATUS_OK
            }
            2 | 3 => {
                // Create a chain with 0..40 joints, a def with random floats now and then.
                let mut def = kdw_chain_def_default();
                match c.pick2 % 6 {
                    0 => def.stiffness = c.f[0],
                    1 => def.damping = c.f[0].abs() * 100.0,
                    // Masses below ~3e-39 or near f32::MAX are known bugs (ffi_bad_input::tiny_mass_stays_finite,
                    // ffi_bad_input::huge_mass_kinetic_energy_stays_finite).
                    2 => {
                        def.mass = match c.f[1] {
                            m if m.is_finite() && m > 0.0 => m.clamp(1e-30, 1e30),
                            m => m,
                        }
                    }
                    3 => def.anchor = (c.pick2 / 6 % 3) as u32,
                    _ => def.stiffness = c.f[2].abs().min(1.0),
                }
                // Radius stays modest: a huge radius is a known bug (ffi_bad_input::huge_radius_stays_finite).
                def.radius = (c.f[3].abs() % 1.0).max(0.0);
                if !def.radius.is_finite() {
                    def.radius = 0.02;
                }
                let j = joints(c.n, c.pick2 / 7, c.f[1]);
                let mut id = 0;
                let s = kdw_chain_create(engine, &def, j.as_ptr(), c.n, &mut id);
                if s == KDW_STATUS_OK {
                    prop_assert_ne!(id, 0, "issued chain id 0");
                    prop_assert!(!self.chains.iter().any(|x| x.1 == id), "chain id {:#x} issued twice", id);
                    self.chains.push((e, id, true));
                }
                s
            }
            4 => {
                let id = self.chain_id(e, c.pick2);
                let s = kdw_chain_destroy(engine, id);
                if s == KDW_STATUS_OK {
                    prop_assert!(self.is_live_chain(e, id), "destroyed a chain id that was not live: {:#x}", id);
                    for x in self.chains.iter_mut().filter(|x| x.1 == id) {
                        x.2 = false;
                    }
                    // Its view shapes die with it; the world learns that from the API below.
                    let mut valid = 9;
                    prop_assert_eq!(kdw_chain_is_valid(engine, id, &mut valid), KDW_STATUS_OK);
                    prop_assert_eq!(valid, 0, "destroyed chain still valid");
                    prop_assert_eq!(kdw_chain_reset(engine, id), KDW_STATUS_INVALID_ID);
                    for v in self.views.iter_mut().filter(|v| v.0 == e && v.2) {
                        let mut alive = 9;
                        prop_assert_eq!(kdw_view_shape_is_valid(engine, v.1, &mut alive), KDW_STATUS_OK);
                        v.2 = alive == 1;
                    }
                } else {
                    prop_assert!(!self.is_live_chain(e, id), "live chain {:#x} not destroyed: {}", id, s);
                }
                s
            }
            5 | 6 => {
                let chain = self.chain_id(e, c.pick2);
                let mut n = 0;
                kdw_chain_joint_count(engine, chain, &mut n);
                let n = if c.pick.is_multiple_of(5) { c.n } else { n };
                let j = joints(n, c.pick2 / 11 + 1, c.f[2]);
                let mut id = 0;
                let s = kdw_chain_add_view_shape(
                    engine,
                    chain,
                    &vec3(c.f[0], c.f[1], 1.0),
                    j.as_ptr(),
                    n,
                    c.f[3].abs(),
                    &mut id,
                );
                if s == KDW_STATUS_OK {
                    prop_assert_ne!(id, 0, "issued view shape id 0");
                    prop_assert!(self.is_live_chain(e, chain), "view shape added to a dead chain");
                    self.views.push((e, id, true));
                }
                s
            }
            7 => {
                let id = self.view_id(e, c.pick2);
                let s = kdw_view_shape_remove(engine, id);
                if s == KDW_STATUS_OK {
                    prop_assert!(self.is_live_view(e, id), "removed a view shape id that was not live");
                    for x in self.views.iter_mut().filter(|x| x.1 == id) {
                        x.2 = false;
                    }
                    prop_assert_eq!(kdw_view_shape_set_influence(engine, id, 1.0), KDW_STATUS_INVALID_ID);
                } else {
                    prop_assert!(!self.is_live_view(e, id), "live view shape not removed: {}", s);
                }
                s
            }
            8 => kdw_view_shape_set_influence(engine, self.view_id(e, c.pick2), c.f[0]),
            9 => kdw_view_shape_set_direction(engine, self.view_id(e, c.pick2), &vec3(c.f[0], c.f[1], c.f[2])),
            10 => {
                let j = joints(c.n, c.pick2, c.f[0]);
                kdw_view_shape_set_joints(engine, self.view_id(e, c.pick2), j.as_ptr(), c.n)
            }
            11 => {
                // Anchors: the right count most of the time, random ones otherwise.
                let chains = Self::chain_count(engine);
                let count = match c.pick2 % 4 {
                    0 => c.n,
                    _ => chains,
                };
                let anchors: Vec<kdw_transform> = (0..count)
                    .map(|i| transform(c.f, !c.pick2.is_multiple_of(3) || i + 1 < count, self.untamed))
                    .collect();
                kdw_engine_set_anchors(engine, anchors.as_ptr(), count)
            }
            12..=14 => {
                let dt = match c.pick2 % 4 {
                    0 => c.f[0],
                    1 => c.f[0].abs() * 0.1,
                    _ => 1.0 / 60.0,
                };
                let k = transform(c.f, !c.pick2.is_multiple_of(5), self.untamed);
                let camera =
                    if c.pick2.is_multiple_of(7) { vec3(tame(c.f[3]), 0.0, c.f[1]) } else { vec3(0.0, 1.7, 3.0) };
                let s = kdw_engine_step(engine, dt, &camera, &k);
                if s == KDW_STATUS_OK && dt > 0.0 {
                    // This step's counters: chains in lanes are awake, and the scalar solver puts none in lanes.
                    let mut stats = kdw_engine_stats::default();
                    prop_assert_eq!(kdw_engine_get_stats(engine, &mut stats), KDW_STATUS_OK);
                    let mut solver = u32::MAX;
                    prop_assert_eq!(kdw_engine_get_solver(engine, &mut solver), KDW_STATUS_OK);
                    prop_assert!(stats.lane_chains + stats.chains_asleep <= stats.chain_count, "{:?}", stats);
                    prop_assert!(solver != KDW_SOLVER_SCALAR || stats.lane_chains == 0, "lanes on the scalar solver");
                }
                s
            }
            15 | 16 => {
                let joints = Self::joint_count(engine);
                let capacity = match c.pick2 % 3 {
                    0 => c.n,
                    _ => joints,
                };
                let mut out = vec![kdw_transform::default(); capacity as usize];
                let mut written = 0;
                let s = kdw_engine_read_world(engine, out.as_mut_ptr(), capacity, &mut written);
                if s == KDW_STATUS_OK {
                    prop_assert_eq!(written, joints);
                    out.truncate(written as usize);
                    ok_means_finite_read = Some(out);
                } else {
                    prop_assert!(capacity < joints && s == KDW_STATUS_BUFFER_TOO_SMALL, "read_world: {}", s);
                }
                let mut rotations = vec![kdw_quat::default(); capacity as usize];
                let s2 = kdw_engine_read_local_rotations(engine, rotations.as_mut_ptr(), capacity, &mut written);
                if s2 == KDW_STATUS_OK {
                    let finite = rotations[..written as usize]
                        .iter()
                        .all(|q| [q.x, q.y, q.z, q.w].iter().all(|v| v.is_finite()));
                    prop_assert!(finite, "non-finite local rotation");
                }
                s
            }
            17 => {
                let chain = self.chain_id(e, c.pick2);
                let mut out = vec![kdw_transform::default(); c.n as usize];
                let mut written = 0;
                let s = if c.pick.is_multiple_of(2) {
                    kdw_chain_read_world(engine, chain, out.as_mut_ptr(), c.n, &mut written)
                } else {
                    kdw_chain_read_rest_shape(engine, chain, out.as_mut_ptr(), c.n, &mut written)
                };
                if s == KDW_STATUS_OK {
                    out.truncate(written as usize);
                    ok_means_finite_read = Some(out);
                }
                let mut energy = f32::NAN;
                if kdw_chain_kinetic_energy(engine, chain, &mut energy) == KDW_STATUS_OK {
                    prop_assert!(energy.is_finite() && energy >= 0.0, "kinetic energy {}", energy);
                }
                s
            }
            18 => {
                if c.pick2.is_multiple_of(2) {
                    kdw_engine_reset(engine)
                } else {
                    kdw_chain_reset(engine, self.chain_id(e, c.pick2))
                }
            }
            19 => {
                let mut def = kdw_engine_def_default();
                match c.pick2 % 10 {
                    0 => def.gravity = vec3(tame(c.f[0]), tame(c.f[1]), tame(c.f[2])),
                    1 => def.substep_rate = c.f[0] * 1000.0,
                    2 => def.max_substeps = c.n * 30,
                    3 => def.iterations = c.n * 2,
                    4 => def.time_scale = c.f[0] * 10.0,
                    5 => def.teleport_distance = c.f[0],
                    6 => def.teleport_angle = c.f[0],
                    7 => def.teleport_mode = (c.pick2 / 10 % 3) as u32,
                    // Scale multiplies gravity and radii: tamed like gravity (huge valid gravity is a known bug).
                    8 => def.scale = if c.f[1].is_finite() { c.f[1].abs().clamp(0.0, 1e3) } else { c.f[1] },
                    _ => def.struct_size = c.n,
                }
                kdw_engine_set_def(engine, &def)
            }
            20 => {
                let mut def = kdw_chain_def_default();
                match c.pick2 % 7 {
                    0 => def.stiffness = c.f[0],
                    1 => def.damping = c.f[0] * 500.0,
                    2 => def.momentum_suppression = c.f[0],
                    3 => def.gravity_scale = c.f[0] * 50.0,
                    4 => def.friction = c.f[0] * 6.0,
                    5 => def.collision_mask = (c.pick2 >> 8) as u32,
                    _ => def.struct_size = c.n,
                }
                kdw_chain_set_def(engine, self.chain_id(e, c.pick2), &def)
            }
            21 => {
                if c.pick.is_multiple_of(8) {
                    // Switch solver between steps: the three KDW_SOLVER_* values and an unknown one.
                    let solver = (c.pick2 % 4) as u32;
                    let s = kdw_engine_set_solver(engine, solver);
                    let mut now = u32::MAX;
                    prop_assert_eq!(kdw_engine_get_solver(engine, &mut now), KDW_STATUS_OK);
                    if solver <= KDW_SOLVER_SCALAR {
                        prop_assert!(s == KDW_STATUS_OK && now == solver, "set_solver({}): {}, now {}", solver, s, now);
                    } else {
                        prop_assert_eq!(s, KDW_STATUS_INVALID_ARGUMENT, "set_solver({})", solver);
                    }
                    s
                } else {
                    kdw_engine_set_gravity(engine, &vec3(tame(c.f[0] * 20.0), tame(c.f[1] * 20.0), tame(c.f[2])))
                }
            }
            22 => {
                let chain = self.chain_id(e, c.pick2);
                let mut n = 0;
                kdw_chain_joint_count(engine, chain, &mut n);
                let n = if c.pick.is_multiple_of(4) { c.n } else { n };
                let j = joints(n, c.pick2 / 13 + 2, c.f[0]);
                kdw_chain_set_base_shape(engine, chain, j.as_ptr(), n)
            }
            23 => {
                let mut stats = kdw_engine_stats::default();
                let s = kdw_engine_get_stats(engine, &mut stats);
                prop_assert_eq!(stats.collider_count, Self::collider_count(engine), "stats.collider_count");
                s
            }
            24 | 25 => {
                // Create a collider: any shape (also unknown ones), random sizes, a valid or broken pose.
                let mut def = kdw_collider_def_default();
                def.shape = (c.pick2 % 6) as u32;
                def.radius = if c.pick2.is_multiple_of(3) { c.f[0] } else { c.f[0].abs() % 0.5 };
                def.half_height = if c.pick2.is_multiple_of(5) { c.f[1] } else { c.f[1].abs() % 0.5 };
                def.transform = transform(c.f, !c.pick2.is_multiple_of(4), self.untamed);
                def.layers = (c.pick2 >> 16) as u32;
                if c.pick2.is_multiple_of(11) {
                    def.struct_size = c.n;
                }
                const UNWRITTEN: u64 = 0xDEAD_BEEF_CAFE_F00D;
                let mut id = UNWRITTEN;
                let s = kdw_collider_create(engine, &def, &mut id);
                if s == KDW_STATUS_OK {
                    prop_assert_ne!(id, 0, "issued collider id 0");
                    prop_assert!(!self.colliders.iter().any(|x| x.1 == id), "collider id {:#x} issued twice", id);
                    self.colliders.push((e, id, true));
                } else {
                    prop_assert_eq!(id, UNWRITTEN, "failed collider create wrote its output");
                }
                s
            }
            26 => {
                let id = self.collider_id(e, c.pick2);
                let s = kdw_collider_destroy(engine, id);
                if s == KDW_STATUS_OK {
                    prop_assert!(self.is_live_collider(e, id), "destroyed a collider id that was not live: {:#x}", id);
                    for x in self.colliders.iter_mut().filter(|x| x.1 == id) {
                        x.2 = false;
                    }
                    let mut valid = 9;
                    prop_assert_eq!(kdw_collider_is_valid(engine, id, &mut valid), KDW_STATUS_OK);
                    prop_assert_eq!(valid, 0, "destroyed collider still valid");
                    prop_assert_eq!(kdw_collider_set_layers(engine, id, 1), KDW_STATUS_INVALID_ID);
                } else {
                    prop_assert!(!self.is_live_collider(e, id), "live collider {:#x} not destroyed: {}", id, s);
                }
                s
            }
            27 => {
                // Batched collider poses: the right count most of the time, one broken pose now and then.
                let colliders = Self::collider_count(engine);
                let count = if c.pick2.is_multiple_of(4) { c.n } else { colliders };
                let poses: Vec<kdw_transform> = (0..count)
                    .map(|i| transform(c.f, !c.pick2.is_multiple_of(3) || i + 1 < count, self.untamed))
                    .collect();
                let s = kdw_engine_set_collider_transforms(engine, poses.as_ptr(), count);
                if count != colliders {
                    prop_assert_eq!(s, KDW_STATUS_INVALID_ARGUMENT, "collider pose count {} of {}", count, colliders);
                }
                s
            }
            28 => {
                let chain = self.chain_id(e, c.pick2);
                match c.pick2 % 4 {
                    0 => kdw_collider_set_layers(engine, self.collider_id(e, c.pick2 / 4), (c.pick2 >> 32) as u32),
                    1 => kdw_chain_teleport(engine, chain),
                    2 => kdw_engine_teleport(engine),
                    _ => {
                        // Per-joint radii: one per joint mostly (or none), random (also invalid) values.
                        let mut n = 0;
                        kdw_chain_joint_count(engine, chain, &mut n);
                        let n = match c.pick % 5 {
                            0 => c.n,
                            1 => 0,
                            _ => n,
                        };
                        let radii: Vec<f32> = (0..n)
                            .map(|j| if j as u64 == c.pick2 % 7 { c.f[j as usize % 4] } else { c.f[2].abs() % 0.05 })
                            .collect();
                        kdw_chain_set_joint_radii(engine, chain, radii.as_ptr(), n)
                    }
                }
            }
            _ => {
                // Collider ids read back: creation order, exactly the live ones the fuzzer knows.
                let colliders = Self::collider_count(engine);
                let capacity = if c.pick2.is_multiple_of(3) { c.n } else { colliders };
                let mut ids = vec![0u64; capacity as usize];
                let mut written = 0;
                let s = kdw_engine_get_collider_ids(engine, ids.as_mut_ptr(), capacity, &mut written);
                if s == KDW_STATUS_OK {
                    prop_assert_eq!(written, colliders);
                    let live: Vec<u64> = self.colliders.iter().filter(|x| x.0 == e && x.2).map(|x| x.1).collect();
                    prop_assert_eq!(&ids[..written as usize], &live[..], "collider ids out of creation order");
                } else {
                    prop_assert!(capacity < colliders && s == KDW_STATUS_BUFFER_TOO_SMALL, "collider ids: {}", s);
                }
                s
            }
        };
        prop_assert_ne!(status, KDW_STATUS_PANIC, "call kind {} panicked", c.kind);
        if status == KDW_STATUS_OK {
            self.ok_calls += 1;
            if let Some(out) = ok_means_finite_read {
                prop_assert!(finite_transforms(&out), "non-finite read-back after call kind {}", c.kind);
            }
        } else {
            prop_assert_eq!(
                hash(engine),
                before,
                "rejected call kind {} (status {}) changed the state",
                c.kind,
                status
            );
        }
        Ok(())
    }

    fn create_engine(&mut self, c: &Call) -> Result<(), TestCaseError> {
        if self.engines.len() >= 4 {
            return Ok(());
        }
        let mut def = kdw_engine_def_default();
        if c.pick2.is_multiple_of(4) {
            def.substep_rate = c.f[0] * 1000.0;
        }
        if c.pick2.is_multiple_of(9) {
            def.struct_size = c.n;
        }
        let mut engine = null_mut();
        let s = kdw_engine_create(&def, &mut engine);
        prop_assert_ne!(s, KDW_STATUS_PANIC);
        if s == KDW_STATUS_OK {
            prop_assert!(!engine.is_null());
            self.engines.push(engine);
        } else {
            prop_assert!(engine.is_null(), "failed create wrote its output");
        }
        Ok(())
    }
}

impl Drop for World {
    fn drop(&mut self) {
        for engine in self.engines.drain(..) {
            assert_eq!(kdw_engine_destroy(engine), KDW_STATUS_OK);
        }
    }
}

/// Runs `cases` random call sequences of up to `max_calls` calls from `seed`.
fn fuzz(cases: u32, max_calls: usize, seed: [u8; 32]) {
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed));
    let totals = std::cell::Cell::new((0u64, 0u64));
    let result = runner.run(&prop::collection::vec(call(), 1..=max_calls), |calls| {
        let mut world = World::default();
        for c in &calls {
            world.apply(c)?;
        }
        let (a, b) = totals.get();
        totals.set((a + world.calls, b + world.ok_calls));
        Ok(())
        // `world` drops here: every engine is destroyed.
    });
    let (calls, ok_calls) = totals.get();
    println!("fuzz: {cases} cases, {calls} C calls ({ok_calls} accepted, the rest rejected with a status)");
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn fuzz_quick() {
    fuzz(256, 200, *b"kodawari fuzz seed, fixed for CI");
}

#[test]
#[ignore = "long: cargo test --release --test ffi_fuzz -- --ignored"]
fn fuzz_long() {
    let cases = std::env::var("KDW_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(20_000);
    let seed_text = std::env::var("KDW_FUZZ_SEED").unwrap_or_else(|_| "kodawari long fuzz".into());
    let mut seed = [0u8; 32];
    for (i, b) in seed_text.bytes().enumerate() {
        seed[i % 32] ^= b.wrapping_add(i as u8);
    }
    fuzz(cases, 400, seed);
}

/// The minimal sequence the fuzzer found with huge finite view-reference positions allowed: engine, a
/// 4-joint chain (stiffness 1, radius 0), a step with the view reference at x = 1e30 (finite, accepted),
/// another engine, a 0.154 s step with the view reference back at (-1.54, 0, 0) turned 180 degrees, then
/// `kdw_engine_read_local_rotations` returns non-finite rotations.
#[test]
fn fuzz_finding_view_reference_at_1e30() {
    let calls: [(u8, u64, u64, u32, [f32; 4]); 6] = [
        (0, 0, 3056713775785829813, 0, [0.0; 4]),
        (2, 0, 2568863743994552524, 4, [0.0, 0.0, 1.1675329, 0.0]),
        (12, 0, 7484981178839060770, 0, [1e30, 1.1033645, 0.0, 1.2791041]),
        (0, 0, 0, 0, [0.0; 4]),
        (12, 0, 56718949326020325, 0, [-1.5421369, 0.0, 0.0, 0.99288744]),
        (15, 0, 5958772141809, 13, [-1.9219843, -1.1304773, 0.911151, -1e30]),
    ];
    let mut world = World::default();
    world.untamed = true;
    for (kind, pick, pick2, n, f) in calls {
        if let Err(e) = world.apply(&Call { kind, pick, pick2, n, f }) {
            panic!("{e}");
        }
    }
}
