//! `kdw_engines_step` through the C ABI: the same results as stepping each engine alone, and every bad
//! input (NULL or repeated handle, bad view reference, bad dt) rejected before any engine moves.

use std::ptr::{null, null_mut};

use kodawari::ffi::batch::kdw_engines_step;
use kodawari::ffi::chain::{kdw_chain_create, kdw_chain_def_default};
use kodawari::ffi::engine::*;
use kodawari::ffi::status::*;
use kodawari::ffi::types::*;

fn transform(x: f32, y: f32, z: f32) -> kdw_transform {
    kdw_transform { position: kdw_vec3 { x, y, z }, rotation: kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } }
}

fn engine_with_chain(seed: usize) -> *mut kdw_engine {
    let mut engine = null_mut();
    assert_eq!(kdw_engine_create(&kdw_engine_def_default(), &mut engine), KDW_STATUS_OK);
    let joints: Vec<kdw_transform> =
        (0..6).map(|i| transform(0.04 * i as f32, -0.01 * (seed * i) as f32, 0.0)).collect();
    let mut chain = 0;
    let status = kdw_chain_create(engine, &kdw_chain_def_default(), joints.as_ptr(), 6, &mut chain);
    assert_eq!(status, KDW_STATUS_OK);
    engine
}

fn hashes(engines: &[*mut kdw_engine]) -> Vec<u64> {
    engines
        .iter()
        .map(|&e| {
            let mut hash = 0;
            assert_eq!(kdw_engine_state_hash(e, &mut hash), KDW_STATUS_OK);
            hash
        })
        .collect()
}

#[test]
fn batch_matches_single_steps_and_rejects_bad_input() {
    let alone: Vec<_> = (0..8).map(engine_with_chain).collect();
    let batched: Vec<_> = (0..8).map(engine_with_chain).collect();
    let references: Vec<kdw_transform> = (0..8).map(|i| transform(i as f32, 1.6, 0.0)).collect();
    let camera = kdw_vec3 { x: 0.0, y: 1.6, z: 4.0 };
    for _ in 0..20 {
        for (&e, k) in alone.iter().zip(&references) {
            assert_eq!(kdw_engine_step(e, 1.0 / 60.0, &camera, k), KDW_STATUS_OK);
        }
        let status = kdw_engines_step(batched.as_ptr(), 8, 1.0 / 60.0, &camera, references.as_ptr());
        assert_eq!(status, KDW_STATUS_OK);
    }
    assert_eq!(hashes(&batched), hashes(&alone));

    let before = hashes(&batched);
    let mut repeated = batched.clone();
    repeated[5] = repeated[2];
    let mut with_null = batched.clone();
    with_null[3] = null_mut();
    let mut bad_reference = references.clone();
    bad_reference[6].position.y = f32::NAN;
    let cases = [
        (kdw_engines_step(repeated.as_ptr(), 8, 1.0 / 60.0, &camera, references.as_ptr()), KDW_STATUS_INVALID_ARGUMENT),
        (kdw_engines_step(with_null.as_ptr(), 8, 1.0 / 60.0, &camera, references.as_ptr()), KDW_STATUS_NULL_POINTER),
        (kdw_engines_step(null(), 8, 1.0 / 60.0, &camera, references.as_ptr()), KDW_STATUS_NULL_POINTER),
        (kdw_engines_step(batched.as_ptr(), 8, 1.0 / 60.0, null(), references.as_ptr()), KDW_STATUS_NULL_POINTER),
        (kdw_engines_step(batched.as_ptr(), 8, 1.0 / 60.0, &camera, null()), KDW_STATUS_NULL_POINTER),
        (
            kdw_engines_step(batched.as_ptr(), 8, 1.0 / 60.0, &camera, bad_reference.as_ptr()),
            KDW_STATUS_INVALID_ARGUMENT,
        ),
        (kdw_engines_step(batched.as_ptr(), 8, f32::NAN, &camera, references.as_ptr()), KDW_STATUS_INVALID_ARGUMENT),
        (kdw_engines_step(batched.as_ptr(), 8, -1.0, &camera, references.as_ptr()), KDW_STATUS_INVALID_ARGUMENT),
    ];
    for (i, (status, expected)) in cases.into_iter().enumerate() {
        assert_eq!(status, expected, "case {i}");
        assert_eq!(hashes(&batched), before, "case {i} changed an engine");
    }
    assert_eq!(kdw_engines_step(null(), 0, 1.0 / 60.0, &camera, null()), KDW_STATUS_OK, "an empty batch");
    for e in alone.into_iter().chain(batched) {
        assert_eq!(kdw_engine_destroy(e), KDW_STATUS_OK);
    }
}
