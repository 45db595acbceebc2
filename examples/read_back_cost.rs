//! The cost of reading every joint back, through the Rust API and through the C ABI, on 100 chains of 16
//! joints: `cargo run --release --example read_back_cost`. Prints the median time of one read of the world
//! transforms (`read_world`, `kdw_engine_read_world`) and of the local rotations (`read_local_rotations`,
//! `kdw_engine_read_local_rotations`, what Unity reads) over rounds that alternate the four, so load on a
//! shared machine hits them alike.

use std::time::Instant;

use glam::{Quat, Vec3};
use kodawari::ffi::chain::{kdw_chain_create, kdw_chain_def_default};
use kodawari::ffi::engine::{
    kdw_engine, kdw_engine_create, kdw_engine_def_default, kdw_engine_destroy, kdw_engine_read_local_rotations,
    kdw_engine_read_world, kdw_engine_step,
};
use kodawari::ffi::status::KDW_STATUS_OK;
use kodawari::ffi::types::{kdw_quat, kdw_transform, kdw_vec3};
use kodawari::{ChainParams, Engine, EngineSettings, Transform};

const CHAINS: usize = 100;
const JOINTS: usize = 16;
const READS: usize = 20_000;
const ROUNDS: usize = 9;

fn main() {
    let mut rust = Engine::new(EngineSettings::default()).expect("engine");
    let mut c: *mut kdw_engine = std::ptr::null_mut();
    assert_eq!(kdw_engine_create(&kdw_engine_def_default(), &mut c), KDW_STATUS_OK);
    let def = kdw_chain_def_default();
    for i in 0..CHAINS {
        let base: Vec<Transform> = (0..JOINTS)
            .map(|j| Transform::new(Vec3::new(0.01 * i as f32, -0.025 * j as f32, 0.0), Quat::IDENTITY))
            .collect();
        rust.create_chain(ChainParams::default(), &base).expect("chain");
        let base: Vec<kdw_transform> = base.into_iter().map(Into::into).collect();
        let mut id = 0;
        assert_eq!(kdw_chain_create(c, &def, base.as_ptr(), JOINTS as u32, &mut id), KDW_STATUS_OK);
    }
    let camera = Vec3::new(0.0, 0.0, 3.0);
    rust.step(1.0 / 60.0, camera, Transform::IDENTITY).expect("step");
    let (c_camera, c_k) = (kdw_vec3::from(camera), kdw_transform::from(Transform::IDENTITY));
    assert_eq!(kdw_engine_step(c, 1.0 / 60.0, &c_camera, &c_k), KDW_STATUS_OK);

    let mut rust_out = vec![Transform::IDENTITY; CHAINS * JOINTS];
    let mut c_out = vec![kdw_transform::default(); CHAINS * JOINTS];
    let time = |read: &mut dyn FnMut()| {
        let start = Instant::now();
        for _ in 0..READS {
            read();
        }
        start.elapsed().as_secs_f64() / READS as f64 * 1e6
    };
    let mut rust_rotations = vec![Quat::IDENTITY; CHAINS * JOINTS];
    let mut c_rotations = vec![kdw_quat::default(); CHAINS * JOINTS];
    let (mut rust_us, mut c_us, mut rust_local_us, mut c_local_us) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..ROUNDS {
        rust_local_us.push(time(&mut || {
            rust.read_local_rotations(&mut rust_rotations).expect("read");
            std::hint::black_box(&rust_rotations);
        }));
        c_local_us.push(time(&mut || {
            let mut written = 0;
            let capacity = c_rotations.len() as u32;
            let status = kdw_engine_read_local_rotations(c, c_rotations.as_mut_ptr(), capacity, &mut written);
            assert_eq!(status, KDW_STATUS_OK);
            std::hint::black_box(&c_rotations);
        }));
        rust_us.push(time(&mut || {
            rust.read_world(&mut rust_out).expect("read");
            std::hint::black_box(&rust_out);
        }));
        c_us.push(time(&mut || {
            let mut written = 0;
            let status = kdw_engine_read_world(c, c_out.as_mut_ptr(), c_out.len() as u32, &mut written);
            assert_eq!(status, KDW_STATUS_OK);
            std::hint::black_box(&c_out);
        }));
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (r, k) = (median(rust_us), median(c_us));
    let (rl, kl) = (median(rust_local_us), median(c_local_us));
    println!("{CHAINS} x {JOINTS} joints, median of {ROUNDS} rounds of {READS} reads:");
    println!("Rust read_world {r:.2} us, C kdw_engine_read_world {k:.2} us, C / Rust {:.3}", k / r);
    println!(
        "Rust read_local_rotations {rl:.2} us, C kdw_engine_read_local_rotations {kl:.2} us, C / Rust {:.3}",
        kl / rl
    );
    assert_eq!(kdw_engine_destroy(c), KDW_STATUS_OK);
}
