//! Hot loops allocate nothing (SPEC 6.3, issue 5): after a warm-up, a frame (anchors, collider poses, step
//! with view shapes and colliders, read-back) makes no heap allocation, through the Rust API and through the C
//! ABI. A counting global allocator (`common::counting`) measures it; this file holds one test so nothing
//! else runs meanwhile.

mod common;

use common::counting::{Counting, allocations};
use common::*;
use glam::{Quat, Vec3};
use kodawari::{AnchorSource, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, Transform};

#[global_allocator]
static GLOBAL: Counting = Counting;

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);

fn scene() -> (Engine, usize, usize) {
    let mut engine = engine_with(EngineSettings::default());
    for c in 0..6 {
        let params = ChainParams {
            anchor: if c % 2 == 0 { AnchorSource::ViewReference } else { AnchorSource::Own },
            damping: if c == 5 { 20.0 } else { 1.0 },
            ..Default::default()
        };
        let direction = Vec3::new(1.0, -0.5 * c as f32, 0.3);
        let id = engine.create_chain(params, &straight_chain(5 + c, Vec3::ZERO, direction, 0.04)).unwrap();
        if c < 4 {
            let side = curled_chain(5 + c, Vec3::ZERO, direction, Vec3::Z, 0.2, 0.04);
            engine.add_view_shape(id, Vec3::X, &side, 1.0).unwrap();
            engine.add_view_shape(id, -Vec3::X, &side, 2.0).unwrap();
        }
    }
    // Eight chains of 9 joints that touch no collider. With the 9-joint chain above (which does) they make
    // nine of a kind: a lane group of eight, which holds the colliding chain (the group runs the contact pass
    // lane by lane), and one left for the scalar solver.
    for c in 0..8 {
        let params = ChainParams { collision_mask: 0, stiffness: 0.3 + 0.05 * c as f32, ..Default::default() };
        let direction = Vec3::new(0.5, 1.0, 0.1 * c as f32);
        let id = engine.create_chain(params, &straight_chain(9, Vec3::ZERO, direction, 0.03)).unwrap();
        if c % 2 == 0 {
            let side = curled_chain(9, Vec3::ZERO, direction, Vec3::X, 0.3, 0.03);
            engine.add_view_shape(id, Vec3::Z, &side, 1.0).unwrap();
        }
    }
    let head = ColliderDef { shape: ColliderShape::Sphere { radius: 0.1 }, transform: at(HEAD), layers: 1 };
    let arm = ColliderDef {
        shape: ColliderShape::Capsule { radius: 0.04, half_height: 0.2 },
        transform: at(HEAD + Vec3::new(0.2, -0.2, 0.0)),
        layers: 1,
    };
    engine.create_collider(&head).unwrap();
    engine.create_collider(&arm).unwrap();
    let joints = engine.joint_count();
    (engine, 14, joints)
}

fn frame(engine: &mut Engine, n: usize, anchors: &mut [Transform], out: &mut [Transform], rotations: &mut [Quat]) {
    let angle = n as f32 * 0.05;
    let k = Transform::new(HEAD + Vec3::X * 0.1 * angle.sin(), Quat::from_rotation_y(0.3 * angle.cos()));
    for a in anchors.iter_mut() {
        *a = k;
    }
    let arm = at(HEAD + Vec3::new(0.2 * angle.cos(), -0.2, 0.0));
    engine.set_collider_transforms([at(HEAD), arm].into_iter()).unwrap();
    // Frame times vary (0 to 3 substeps) and the camera orbits, so the blend changes every frame.
    let dt = [1.0 / 60.0, 1.0 / 144.0, 1.0 / 30.0][n % 3];
    engine.step_with_anchors(anchors.iter().copied(), dt, orbit_camera(HEAD, 3.0, angle), k).unwrap();
    engine.read_world(out).unwrap();
    engine.read_local_rotations(rotations).unwrap();
}

#[test]
fn a_frame_allocates_nothing() {
    let (mut engine, chains, joints) = scene();
    let mut anchors = vec![Transform::IDENTITY; chains];
    let mut out = vec![Transform::IDENTITY; joints];
    let mut rotations = vec![Quat::IDENTITY; joints];
    for n in 0..30 {
        frame(&mut engine, n, &mut anchors, &mut out, &mut rotations);
    }
    let before = allocations();
    for n in 30..330 {
        frame(&mut engine, n, &mut anchors, &mut out, &mut rotations);
    }
    let rust_allocations = allocations() - before;
    assert_eq!(engine.stats().lane_chains, 8, "eight of the nine equal chains form a lane group");
    assert!(engine.stats().contact_pairs_tested > 0);

    // The same frame through the C ABI's one-call path.
    use kodawari::ffi::engine::*;
    use kodawari::ffi::types::*;
    let mut handle = std::ptr::null_mut();
    assert_eq!(kdw_engine_create(&kdw_engine_def_default(), &mut handle), 0);
    let joints_c: Vec<kdw_transform> =
        straight_chain(8, Vec3::ZERO, Vec3::X, 0.05).into_iter().map(Into::into).collect();
    let mut chain = 0;
    let def = kodawari::ffi::chain::kdw_chain_def_default();
    assert_eq!(kodawari::ffi::chain::kdw_chain_create(handle, &def, joints_c.as_ptr(), 8, &mut chain), 0);
    let k: kdw_transform = at(HEAD).into();
    let anchor = [k];
    let mut local = vec![kdw_quat::default(); 8];
    let mut written = 0;
    let mut c_frame = |n: usize| {
        let camera: kdw_vec3 = orbit_camera(HEAD, 3.0, n as f32 * 0.05).into();
        let status = kdw_engine_step_and_read(
            handle,
            1.0 / 60.0,
            &camera,
            &k,
            anchor.as_ptr(),
            1,
            local.as_mut_ptr(),
            8,
            &mut written,
        );
        assert_eq!(status, 0);
    };
    for n in 0..30 {
        c_frame(n);
    }
    let before = allocations();
    for n in 30..330 {
        c_frame(n);
    }
    let c_allocations = allocations() - before;

    // Several engines in one batch call (serial build; the thread pool's own bookkeeping is rayon's).
    let handles: Vec<*mut kdw_engine> = (0..4)
        .map(|_| {
            let mut e = std::ptr::null_mut();
            assert_eq!(kdw_engine_create(&kdw_engine_def_default(), &mut e), 0);
            let mut id = 0;
            assert_eq!(kodawari::ffi::chain::kdw_chain_create(e, &def, joints_c.as_ptr(), 8, &mut id), 0);
            e
        })
        .collect();
    let references = [k; 4];
    let batch_frame = |n: usize| {
        let camera: kdw_vec3 = orbit_camera(HEAD, 3.0, n as f32 * 0.05).into();
        let status =
            kodawari::ffi::batch::kdw_engines_step(handles.as_ptr(), 4, 1.0 / 60.0, &camera, references.as_ptr());
        assert_eq!(status, 0);
    };
    for n in 0..30 {
        batch_frame(n);
    }
    let before = allocations();
    for n in 30..330 {
        batch_frame(n);
    }
    let batch_allocations = if cfg!(feature = "parallel") { 0 } else { allocations() - before };
    for e in handles.into_iter().chain([handle]) {
        assert_eq!(kdw_engine_destroy(e), 0);
    }
    println!(
        "allocations over 300 frames: Rust API {rust_allocations}, C ABI {c_allocations}, batch call {batch_allocations}"
    );
    assert_eq!((rust_allocations, c_allocations, batch_allocations), (0, 0, 0));
}
