//! The n-pendulum scenario of the accuracy benchmark (`benches/accuracy.rs`), for the side-by-side with
//! rapier3d: a 1 m chain of `joints - 1` equal links, 1 kg at each dynamic joint, released straight out along
//! +x from a fixed root, gravity -9.81 y, no stiffness, no damping; RMS joint position error over the dynamic
//! joints and every 60 fps frame of 0.5 s, divided by the chain length (1 m), against the exact planar
//! reference of `pendulum.rs`.
#![allow(dead_code)]

use glam::{DVec3, Quat, Vec3};
use kodawari::{ChainId, ChainParams, Engine, EngineSettings, Transform};

use super::pendulum::{Pendulum, Tolerance};
use super::scenes::FRAME_DT;

pub const ROOT: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const CAMERA: Vec3 = Vec3::new(0.0, 1.6, 3.0);
const GRAVITY: f64 = 9.81;
pub const SECONDS: f64 = 0.5;
/// The reference is sampled at this rate (Hz): every frame time lies on it.
const GRID: f64 = 240.0;

/// Frames per second, exactly (`FRAME_DT` is an f32 and its reciprocal is not exactly 60).
fn frame_rate() -> f64 {
    (1.0 / FRAME_DT as f64).round()
}

/// The exact pendulum sampled on the grid.
pub struct Reference {
    pub joints: usize,
    positions: Vec<Vec<DVec3>>,
}

impl Reference {
    pub fn new(joints: usize) -> Self {
        let links = joints - 1;
        let p = Pendulum::uniform(links, 1.0 / links as f64, 1.0, [0.0, -GRAVITY]);
        let y0 = p.state_at_rest(&vec![std::f64::consts::FRAC_PI_2; links]);
        let times: Vec<f64> = (0..=(SECONDS * GRID).round() as usize).map(|i| i as f64 / GRID).collect();
        let (states, _) = p.solve(0.0, &y0, &times, Tolerance::REFERENCE);
        let root = ROOT.as_dvec3();
        let positions = times
            .iter()
            .zip(&states)
            .map(|(t, y)| p.positions(*t, y).iter().map(|q| root + DVec3::new(q[0], q[1], 0.0)).collect())
            .collect();
        Self { joints, positions }
    }

    pub fn at(&self, t: f64) -> &[DVec3] {
        let i = (t * GRID).round();
        assert!((t * GRID - i).abs() < 1e-6 && i >= 0.0, "time {t} is not on the reference grid");
        &self.positions[i as usize]
    }

    pub fn frames() -> u32 {
        (SECONDS * frame_rate()).round() as u32
    }

    pub fn name(&self) -> String {
        match self.joints {
            3 => "double pendulum".into(),
            n => format!("{}-link pendulum", n - 1),
        }
    }
}

/// RMS over the dynamic joints of `frames` (one list of joint positions per frame, frame k at time
/// `(k + 1) / 60`) against the reference.
pub fn rms_error(reference: &Reference, frames: &[Vec<DVec3>]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, positions) in frames.iter().enumerate() {
        let t = (k + 1) as f64 / frame_rate();
        let exact = reference.at(t);
        for j in 1..positions.len() {
            sum += (positions[j] - exact[j]).length_squared();
            count += 1;
        }
    }
    (sum / count as f64).sqrt()
}

/// kodawari's pendulum at default engine settings, driven one 60 Hz frame at a time.
pub struct KodawariPendulum {
    pub engine: Engine,
    chain: ChainId,
    out: Vec<Transform>,
}

impl KodawariPendulum {
    pub fn new(joints: usize) -> Self {
        let mut engine = Engine::new(EngineSettings::default()).expect("default settings are valid");
        let segment = 1.0 / (joints - 1) as f32;
        let base: Vec<Transform> =
            (0..joints).map(|i| Transform::new(Vec3::new(segment * i as f32, 0.0, 0.0), Quat::IDENTITY)).collect();
        let limp = ChainParams { stiffness: 0.0, damping: 0.0, ..Default::default() };
        let chain = engine.create_chain(limp, &base).expect("valid chain");
        Self { engine, chain, out: vec![Transform::IDENTITY; joints] }
    }

    /// One frame: step and read the chain back.
    pub fn frame(&mut self) {
        let root = Transform::new(ROOT, Quat::IDENTITY);
        self.engine.step(FRAME_DT, CAMERA, root).expect("valid step");
        self.engine.read_chain_world(self.chain, &mut self.out).expect("buffer fits");
    }

    pub fn positions(&self) -> Vec<DVec3> {
        self.out.iter().map(|t| t.position.as_dvec3()).collect()
    }
}

/// kodawari's error over the scenario, its pose after each call against the reference at the call's time.
pub fn kodawari_error(reference: &Reference) -> f64 {
    let mut run = KodawariPendulum::new(reference.joints);
    let frames: Vec<Vec<DVec3>> = (0..Reference::frames())
        .map(|_| {
            run.frame();
            run.positions()
        })
        .collect();
    rms_error(reference, &frames)
}
