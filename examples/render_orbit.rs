//! The view-dependent scene, rendered: a head with an ahoge and a pair of rabbit ears, seen by a camera that
//! orbits it once, without view shapes (left) and with them (right). Software rendering (tiny-skia), no GPU.
//!
//! The ahoge is the one of `examples/ahoge_orbit.rs` (same shape and view-shape layout): it curls forward,
//! so without view shapes it reads as a crescent only from the sides and as a stub from the front and back;
//! with two view shapes it curls towards screen-left from every direction. The ears are two 6-joint chains
//! that stand up and lean back; one view shape seen from the front splays them outwards and bends them
//! towards the camera, so from the front they open into a V instead of two parallel sticks, and they fold
//! back into the base shape as the camera moves round to the side.
//!
//! Conventions as in `ahoge_orbit.rs`: right-handed, Y up; the character faces +z; orbit angle 0° is the
//! camera in front of the face, 90° on the character's left (+x).
//!
//! Run: `cargo run --release --example render_orbit`. Writes `docs/orbit.gif` (both panels, one orbit) and
//! `docs/orbit.png` (a contact sheet at 0°, 90°, 180° and 270°).

mod support;

use std::f32::consts::{PI, TAU};
use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use kodawari::core::sketch::{Projection, StrokeCamera};
use kodawari::{ChainId, ChainParams, Engine, EngineSettings, Transform};
use support::{Canvas, ChainStyle, Head, Panel, draw_scene, rgb};

const FPS: u32 = 60;
const ORBIT_FRAMES: u32 = 360;
/// Frames with the camera held in front before the orbit starts, so the chains settle under gravity.
const WARMUP_FRAMES: u32 = 90;
const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const HEAD_RADIUS: f32 = 0.11;
const CAMERA_RADIUS: f32 = 2.5;
const CAMERA_HEIGHT: f32 = 1.7;
/// What the camera looks at, above the head's centre (so the ears fit).
const LOOK_OFFSET: Vec3 = Vec3::new(0.0, 0.12, 0.0);
/// Vertical field of view: about 0.65 m at the head's distance.
const FOV: f32 = 0.26;

const AHOGE_JOINTS: usize = 8;
const AHOGE_SEGMENT: f32 = 0.025;
const AHOGE_BEND: f32 = 22.0 * PI / 180.0;
const AHOGE_STIFFNESS: f32 = 0.9;
const AHOGE_INFLUENCE: f32 = 2.0;

const EAR_JOINTS: usize = 6;
const EAR_SEGMENT: f32 = 0.035;
const EAR_STIFFNESS: f32 = 0.85;
const EAR_INFLUENCE: f32 = 3.0;

/// GIF: every 6th frame of the orbit (60 frames), 0.1 s each.
const GIF_STRIDE: u32 = 6;
const GIF_PANEL: u32 = 240;
const SHEET_PANEL: u32 = 300;

/// A chain in K's frame: starts at `root` along `first`, each segment turned `bend` radians further about
/// `axis`. Each joint's +Y bone axis points at the next joint.
fn chain(root: Vec3, first: Vec3, axis: Vec3, bend: f32, joints: usize, segment: f32) -> Vec<Transform> {
    let turn = Quat::from_axis_angle(axis.normalize(), bend);
    let (mut position, mut dir) = (root, first.normalize());
    let mut out = Vec::with_capacity(joints);
    for j in 0..joints {
        out.push(Transform::new(position, Quat::from_rotation_arc(Vec3::Y, dir)));
        position += dir * segment;
        if j + 2 < joints {
            dir = (turn * dir).normalize();
        }
    }
    out
}

/// The ahoge of `ahoge_orbit.rs`: straight up from the top of the head, then curling towards `curl`.
fn ahoge(curl: Vec3) -> Vec<Transform> {
    let axis = Vec3::Y.cross(curl).normalize();
    chain(Vec3::new(0.0, 0.12, 0.0), Vec3::Y, axis, AHOGE_BEND, AHOGE_JOINTS, AHOGE_SEGMENT)
}

/// A rabbit ear on side `side` (+1 = the character's left, +x): up and back (base) or, seen from the front,
/// splayed outwards and bent towards the camera.
fn ear(side: f32, from_front: bool) -> Vec<Transform> {
    let root = Vec3::new(side * 0.055, 0.095, -0.01);
    if from_front {
        chain(root, Vec3::new(side * 0.75, 1.0, 0.1), Vec3::new(-1.0, 0.0, 0.0), -0.14, EAR_JOINTS, EAR_SEGMENT)
    } else {
        chain(root, Vec3::new(side * 0.12, 1.0, -0.15), Vec3::new(1.0, 0.0, 0.0), -0.08, EAR_JOINTS, EAR_SEGMENT)
    }
}

fn orbit_direction(degrees: f32) -> Vec3 {
    let (s, c) = degrees.to_radians().sin_cos();
    Vec3::new(s, 0.0, c)
}

fn screen_left(from: Vec3) -> Vec3 {
    from.cross(Vec3::Y)
}

/// Head pose at time `t`: a 3 cm bob at 1.5 Hz and an 8° yaw sway at 0.5 Hz (as in `ahoge_orbit.rs`).
fn head(t: f32) -> Transform {
    let bob = 0.03 * (TAU * 1.5 * t).sin();
    let yaw = 8f32.to_radians() * (TAU * 0.5 * t).sin();
    Transform::new(HEAD + Vec3::Y * bob, Quat::from_rotation_y(yaw))
}

struct Scene {
    engine: Engine,
    chains: Vec<ChainId>,
}

fn scene(with_view_shapes: bool) -> Result<Scene, kodawari::Error> {
    let mut engine = Engine::new(EngineSettings::default())?;
    let hair = ChainParams { stiffness: AHOGE_STIFFNESS, ..Default::default() };
    let ears = ChainParams { stiffness: EAR_STIFFNESS, ..Default::default() };
    let ahoge_id = engine.create_chain(hair, &ahoge(Vec3::Z))?;
    let left = engine.create_chain(ears, &ear(1.0, false))?;
    let right = engine.create_chain(ears, &ear(-1.0, false))?;
    if with_view_shapes {
        // The ahoge layout of ahoge_orbit.rs: the base is "curl towards screen-left" seen from 90°; view
        // shapes say the same from 210° and 330°.
        for degrees in [210.0, 330.0] {
            let from = orbit_direction(degrees);
            engine.add_view_shape(ahoge_id, from, &ahoge(screen_left(from)), AHOGE_INFLUENCE)?;
        }
        // Ears: splayed towards the camera when seen from the front.
        let front = Vec3::new(0.0, 0.04, 1.0);
        engine.add_view_shape(left, front, &ear(1.0, true), EAR_INFLUENCE)?;
        engine.add_view_shape(right, front, &ear(-1.0, true), EAR_INFLUENCE)?;
    }
    Ok(Scene { engine, chains: vec![ahoge_id, left, right] })
}

/// One frame of one scene: the head pose and each chain's world joint positions.
#[derive(Clone)]
struct Snapshot {
    head: Transform,
    camera: Vec3,
    chains: Vec<Vec<Vec3>>,
}

fn snapshot(scene: &Scene, head: Transform, camera: Vec3) -> Result<Snapshot, kodawari::Error> {
    let mut chains = Vec::new();
    for id in &scene.chains {
        let mut joints = vec![Transform::IDENTITY; scene.engine.chain_joint_count(*id)?];
        scene.engine.read_chain_world(*id, &mut joints)?;
        chains.push(joints.iter().map(|j| j.position).collect());
    }
    Ok(Snapshot { head, camera, chains })
}

/// Renders one panel of `size` pixels: the scene, a title on top, the orbit angle at the bottom.
fn render_panel(shot: &Snapshot, size: u32, title: &str, degrees: f32) -> Canvas {
    let mut canvas = Canvas::new(size, size);
    let look = HEAD + LOOK_OFFSET;
    let camera = StrokeCamera::look_at(
        shot.camera,
        look,
        Vec3::Y,
        Projection::Perspective { vertical_fov: FOV },
        Vec2::splat(size as f32),
    )
    .expect("camera");
    let panel = Panel { camera, origin: Vec2::ZERO };
    let hair =
        ChainStyle { color: rgb(92, 60, 48), width: 0.014, joint: rgb(128, 90, 70), joint_size: 0.018, stripe: None };
    let ear = ChainStyle {
        color: rgb(255, 255, 255),
        width: 0.03,
        joint: rgb(226, 120, 150),
        joint_size: 0.012,
        stripe: Some((rgb(246, 178, 196), 0.45)),
    };
    let styles = [hair, ear, ear];
    let chains: Vec<(Vec<Vec3>, ChainStyle)> = shot.chains.iter().cloned().zip(styles).collect();
    let head = Head { pose: shot.head, radius: HEAD_RADIUS };
    draw_scene(&mut canvas, &panel, Some(&head), &chains);

    let scale = (size as f32 / 120.0).floor().max(1.0);
    canvas.text_centred(size as f32 * 0.5, 6.0, scale, title, support::color(support::INK));
    let label = format!("CAMERA {:03.0}°", degrees.rem_euclid(360.0));
    canvas.text(6.0, size as f32 - 6.0 - 7.0 * scale, scale, &label, support::color(support::GREY));
    // A small top view: the head and where the camera is (orbit angle 0 = in front, below the dot).
    let r = 7.0 * scale;
    let c = Vec2::new(size as f32 - 6.0 - r, size as f32 - 6.0 - r);
    canvas.circle(c, r, rgb(208, 214, 226));
    canvas.circle(c, 1.5 * scale, support::color(support::INK));
    let (s, co) = degrees.to_radians().sin_cos();
    canvas.circle(c + Vec2::new(s, co) * r * 0.8, 1.5 * scale, rgb(214, 80, 60));
    canvas
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut plain = scene(false)?;
    let mut shaped = scene(true)?;
    let dt = 1.0 / FPS as f32;
    let mut gif_frames = Vec::new();
    let mut sheet: Vec<(f32, Snapshot, Snapshot)> = Vec::new();
    let mut ear_spread = Vec::new();

    println!("render_orbit: a head with an ahoge (8 joints) and rabbit ears (2 x 6 joints), camera orbit 360°");
    println!("left: no view shapes; right: ahoge view shapes from 210° and 330°, ear view shapes from the front");
    for frame in 1..=WARMUP_FRAMES + ORBIT_FRAMES {
        let t = frame as f32 * dt;
        let orbit_frame = frame.saturating_sub(WARMUP_FRAMES);
        let degrees = 360.0 * orbit_frame as f32 / ORBIT_FRAMES as f32;
        let camera = orbit_direction(degrees) * CAMERA_RADIUS + Vec3::Y * CAMERA_HEIGHT;
        let k = head(t);
        plain.engine.step(dt, camera, k)?;
        shaped.engine.step(dt, camera, k)?;
        if frame < WARMUP_FRAMES || orbit_frame >= ORBIT_FRAMES {
            continue;
        }
        let (a, b) = (snapshot(&plain, k, camera)?, snapshot(&shaped, k, camera)?);
        if orbit_frame % 90 == 0 {
            // Ear tips' distance apart, seen from the camera (cm at the head's depth): how open the V is.
            let spread = |s: &Snapshot| {
                let right = Vec3::Y.cross(k.position - camera).normalize();
                (s.chains[1][EAR_JOINTS - 1] - s.chains[2][EAR_JOINTS - 1]).dot(right).abs() * 100.0
            };
            ear_spread.push((degrees, spread(&a), spread(&b)));
            sheet.push((degrees, a.clone(), b.clone()));
        }
        if orbit_frame % GIF_STRIDE == 0 {
            let mut canvas = Canvas::new(2 * GIF_PANEL, GIF_PANEL);
            canvas.paste(&render_panel(&a, GIF_PANEL, "without view shapes", degrees), 0, 0);
            canvas.paste(&render_panel(&b, GIF_PANEL, "with view shapes", degrees), GIF_PANEL as i32, 0);
            canvas.rect(GIF_PANEL as f32 - 1.0, 0.0, 2.0, GIF_PANEL as f32, rgb(170, 176, 190));
            gif_frames.push(canvas.rgba());
        }
    }

    println!("\near tips apart on screen (cm), the V the ears open towards the camera:");
    println!("{:>7} | {:>9} | {:>9}", "camera", "without", "with");
    for (degrees, a, b) in &ear_spread {
        println!("{degrees:>6.0}° | {a:>9.1} | {b:>9.1}");
    }

    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    let gif_path = docs.join("orbit.gif");
    support::save_gif(&gif_path, 2 * GIF_PANEL, GIF_PANEL, &gif_frames, (100 * GIF_STRIDE / FPS) as u16)?;

    let mut contact = Canvas::new(4 * SHEET_PANEL, 2 * SHEET_PANEL);
    for (column, (degrees, a, b)) in sheet.iter().enumerate() {
        let x = (column as u32 * SHEET_PANEL) as i32;
        contact.paste(&render_panel(a, SHEET_PANEL, "without view shapes", *degrees), x, 0);
        contact.paste(&render_panel(b, SHEET_PANEL, "with view shapes", *degrees), x, SHEET_PANEL as i32);
    }
    for column in 1..4 {
        contact.rect((column * SHEET_PANEL) as f32 - 1.0, 0.0, 2.0, 2.0 * SHEET_PANEL as f32, rgb(170, 176, 190));
    }
    contact.rect(0.0, SHEET_PANEL as f32 - 1.0, 4.0 * SHEET_PANEL as f32, 2.0, rgb(170, 176, 190));
    let png_path = docs.join("orbit.png");
    contact.save_png(&png_path)?;

    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len() / 1024).unwrap_or(0);
    println!(
        "\nwrote {} ({} frames, {}x{}, {} KiB)",
        gif_path.display(),
        gif_frames.len(),
        2 * GIF_PANEL,
        GIF_PANEL,
        size(&gif_path)
    );
    println!(
        "wrote {} (top: without view shapes, bottom: with; camera at 0°, 90°, 180°, 270°; {} KiB)",
        png_path.display(),
        size(&png_path)
    );
    Ok(())
}
