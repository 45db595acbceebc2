//! An ahoge (cowlick) seen by an orbiting camera, with and without view shapes.
//!
//! A head (the view reference joint K) bobs and sways its yaw at (0, 1.6, 0) while the camera circles it
//! once (2.5 m away, 1.7 m high, 60 fps, 6 s). Two engines hold the same 8-joint ahoge: it stands up from
//! the top of the head and curls forward, so it reads as a crescent from the sides. Engine A has no view
//! shapes: from the front and the back the camera looks along the curl and sees a short stub. Engine B
//! adds two view shapes so that, from every direction, the ahoge curls towards screen-left, across the
//! line of sight: the anime ahoge that always reads sideways.
//!
//! B's shapes follow one rule, "as seen from `d`, curl towards screen-left (`d × up`)", at three views
//! 120° apart: the base shape is that rule seen from the character's left, the view shapes are it seen
//! from front-right and from back-right. (View shapes at ±x would not work: the base already reads
//! sideways there, and a curl towards the side the camera is on points at the camera. Two view shapes at
//! front and back do not either: their weights are mirror-symmetric, so the camera at +θ and at -θ gets the
//! same blend, and the curl points at the camera on one side of the mirror.)
//!
//! Conventions: right-handed, Y up. The character faces +z, so its left is +x and its right is -x.
//! Orbit angle 0° is the camera in front of the face (+z); it increases towards the character's left.
//! Camera basis: `forward = normalize(head - camera)`, `right = normalize(forward × up)`, `up' = right ×
//! forward`. Screen coordinates are pinhole projections scaled to metres at the head's depth, so a length
//! ratio can exceed 1 slightly where the ahoge is nearer the camera than the head.
//!
//! Run: `cargo run --release --example ahoge_orbit`. Writes `docs/ahoge_orbit.csv` (one row per frame).

use std::f32::consts::{PI, TAU};
use std::fmt::Write as _;
use std::time::Instant;

use glam::{Quat, Vec3};
use kodawari::{ChainParams, Engine, EngineSettings, Transform};

const FPS: u32 = 60;
const ORBIT_SECONDS: f32 = 6.0;
/// Frames with the camera held in front before the orbit starts, so the chain settles under gravity.
const WARMUP_FRAMES: u32 = 60;
const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const CAMERA_RADIUS: f32 = 2.5;
const CAMERA_HEIGHT: f32 = 1.7;
const JOINTS: usize = 8;
const SEGMENT: f32 = 0.025;
/// Bend between consecutive segments: 7 segments turn by 6 × 22° = 132°, a crescent.
const BEND: f32 = 22.0 * PI / 180.0;
const STIFFNESS: f32 = 0.9;
const INFLUENCE: f32 = 2.0;

/// The ahoge in K's frame: a first segment straight up from the top of the head, then each segment turns
/// by `BEND` towards `curl` (a horizontal unit vector). Each joint's +Y bone axis points at the next joint.
fn ahoge(curl: Vec3) -> Vec<Transform> {
    let turn = Quat::from_axis_angle(Vec3::Y.cross(curl).normalize(), BEND);
    let (mut position, mut dir) = (Vec3::new(0.0, 0.12, 0.0), Vec3::Y);
    let mut joints = Vec::with_capacity(JOINTS);
    for j in 0..JOINTS {
        joints.push(Transform::new(position, Quat::from_rotation_arc(Vec3::Y, dir)));
        position += dir * SEGMENT;
        if j + 2 < JOINTS {
            dir = (turn * dir).normalize();
        }
    }
    joints
}

/// Unit direction from the head to the camera at orbit angle `degrees` (0 = front, 90 = character's left).
fn orbit_direction(degrees: f32) -> Vec3 {
    let (s, c) = degrees.to_radians().sin_cos();
    Vec3::new(s, 0.0, c)
}

/// The horizontal direction that appears as screen-left to a camera seeing the head from `from`.
fn screen_left(from: Vec3) -> Vec3 {
    from.cross(Vec3::Y)
}

/// Head pose at time `t`: a 3 cm bob at 1.5 Hz and an 8° yaw sway at 0.5 Hz.
fn head(t: f32) -> Transform {
    let bob = 0.03 * (TAU * 1.5 * t).sin();
    let yaw = 8f32.to_radians() * (TAU * 0.5 * t).sin();
    Transform::new(HEAD + Vec3::Y * bob, Quat::from_rotation_y(yaw))
}

/// What the camera sees of one chain.
struct View {
    /// Tip minus root on screen (right, up), metres at the head's depth.
    screen: [f32; 2],
    /// On-screen polyline length / true polyline length.
    len_ratio: f32,
}

impl View {
    fn angle_from_up(&self) -> f32 {
        self.screen[0].atan2(self.screen[1]).to_degrees()
    }
}

fn look(camera: Vec3, target: Vec3, joints: &[Transform]) -> View {
    let forward = (target - camera).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let depth = (target - camera).dot(forward);
    let project = |p: Vec3| {
        let v = p - camera;
        let s = depth / v.dot(forward);
        glam::Vec2::new(v.dot(right) * s, v.dot(up) * s)
    };
    let screen: Vec<glam::Vec2> = joints.iter().map(|j| project(j.position)).collect();
    let seen: f32 = screen.windows(2).map(|w| (w[1] - w[0]).length()).sum();
    let true_len: f32 = joints.windows(2).map(|w| (w[1].position - w[0].position).length()).sum();
    let tip = screen[JOINTS - 1] - screen[0];
    View { screen: [tip.x, tip.y], len_ratio: seen / true_len }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let params = ChainParams { stiffness: STIFFNESS, ..Default::default() };
    let base = ahoge(Vec3::Z);
    let mut a = Engine::new(EngineSettings::default())?;
    a.create_chain(params, &base)?;
    let mut b = Engine::new(EngineSettings::default())?;
    let chain = b.create_chain(params, &base)?;
    // The base shape (curl +z) is `ahoge(screen_left(orbit_direction(90)))`: the view from the left.
    for degrees in [210.0, 330.0] {
        let from = orbit_direction(degrees);
        b.add_view_shape(chain, from, &ahoge(screen_left(from)), INFLUENCE)?;
    }

    let dt = 1.0 / FPS as f32;
    let orbit_frames = (ORBIT_SECONDS * FPS as f32).round() as u32;
    let (mut joints_a, mut joints_b) = ([Transform::IDENTITY; JOINTS], [Transform::IDENTITY; JOINTS]);
    let (mut us_a, mut us_b) = (Vec::new(), Vec::new());
    let mut csv = String::from("angle_deg,a_screen_x,a_screen_y,b_screen_x,b_screen_y,a_len_ratio,b_len_ratio\n");
    let (mut ratios_a, mut ratios_b) = (Vec::new(), Vec::new());

    println!("ahoge_orbit: {JOINTS}-joint ahoge, stiffness {STIFFNESS}, camera orbit 360° in {ORBIT_SECONDS} s");
    println!("A = no view shapes, B = view shapes from 210° and 330° (influence {INFLUENCE})");
    println!("screen (x right, y up) in cm; angle from screen-up in degrees (+ = right); len = seen / true\n");
    println!(
        "{:>5} | {:>6} {:>6} {:>7} {:>5} | {:>6} {:>6} {:>7} {:>5}",
        "orbit", "A x", "A y", "A ang", "A len", "B x", "B y", "B ang", "B len"
    );
    for frame in 1..=WARMUP_FRAMES + orbit_frames {
        let t = frame as f32 * dt;
        let orbit_frame = frame.saturating_sub(WARMUP_FRAMES);
        let angle = 360.0 * orbit_frame as f32 / orbit_frames as f32;
        let camera = orbit_direction(angle) * CAMERA_RADIUS + Vec3::Y * CAMERA_HEIGHT;
        let k = head(t);

        for (engine, us) in [(&mut a, &mut us_a), (&mut b, &mut us_b)] {
            let start = Instant::now();
            engine.step(dt, camera, k)?;
            us.push(start.elapsed().as_secs_f64() * 1e6);
        }

        if frame < WARMUP_FRAMES {
            continue;
        }
        a.read_world(&mut joints_a)?;
        b.read_world(&mut joints_b)?;
        let (va, vb) = (look(camera, k.position, &joints_a), look(camera, k.position, &joints_b));
        ratios_a.push(va.len_ratio);
        ratios_b.push(vb.len_ratio);
        let [ax, ay] = va.screen;
        let [bx, by] = vb.screen;
        let (ar, br) = (va.len_ratio, vb.len_ratio);
        writeln!(csv, "{angle:.1},{ax:.6},{ay:.6},{bx:.6},{by:.6},{ar:.6},{br:.6}")?;
        if orbit_frame % (orbit_frames / 12) == 0 {
            println!(
                "{angle:>4.0}° | {:>6.2} {:>6.2} {:>7.1} {ar:>5.2} | {:>6.2} {:>6.2} {:>7.1} {br:>5.2}",
                ax * 100.0,
                ay * 100.0,
                va.angle_from_up(),
                bx * 100.0,
                by * 100.0,
                vb.angle_from_up(),
            );
        }
    }

    let mean = |r: &[f32]| r.iter().sum::<f32>() / r.len() as f32;
    let min = |r: &[f32]| r.iter().copied().fold(f32::INFINITY, f32::min);
    println!("\non-screen length ratio over the orbit ({} frames):", ratios_a.len());
    println!("  A (no view shapes):   mean {:.3}, min {:.3}", mean(&ratios_a), min(&ratios_a));
    println!("  B (with view shapes): mean {:.3}, min {:.3}", mean(&ratios_b), min(&ratios_b));
    let median = |us: &mut Vec<f64>| {
        us.sort_by(f64::total_cmp);
        us[us.len() / 2]
    };
    println!(
        "Engine::step, median over {} frames: B {:.1} µs per frame (A, no view shapes: {:.1} µs); \
         {} substeps per frame at {} Hz",
        us_b.len(),
        median(&mut us_b),
        median(&mut us_a),
        b.stats().substeps_last_step,
        b.settings().substep_rate
    );

    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ahoge_orbit.csv");
    std::fs::create_dir_all(path.parent().expect("has a parent"))?;
    std::fs::write(&path, csv)?;
    println!("wrote {}", path.display());
    Ok(())
}
