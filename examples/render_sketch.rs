//! The sketch tool, rendered: one stroke drawn over the front view becomes the chain's new shape
//! (`kodawari::core::sketch::shape_from_stroke`), shown from the stroke's camera and from a second camera at
//! 90° to show that depth stays plausible (taken from the current shape where the stroke cannot tell it).
//!
//! Run: `cargo run --release --example render_sketch`. Writes `docs/sketch.png`.

mod support;

use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use kodawari::Transform;
use kodawari::core::sketch::{Projection, StrokeCamera, StrokeInput, shape_from_stroke};
use support::{Canvas, ChainStyle, Head, Panel, draw_scene, rgb};

const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
const HEAD_RADIUS: f32 = 0.11;
const PANEL: u32 = 420;
const JOINTS: usize = 8;
const SEGMENT: f32 = 0.03;

/// The current shape (world space): up from the top of the head, leaning back and curving further back.
fn current_shape() -> Vec<Transform> {
    let turn = Quat::from_axis_angle(Vec3::X, -0.12);
    let mut dir = Vec3::new(0.1, 1.0, -0.35).normalize();
    let mut p = HEAD + Vec3::new(0.0, 0.12, 0.0);
    let mut joints = Vec::new();
    for j in 0..JOINTS {
        joints.push(Transform::new(p, Quat::from_rotation_arc(Vec3::Y, dir)));
        p += dir * SEGMENT;
        if j + 2 < JOINTS {
            dir = (turn * dir).normalize();
        }
    }
    joints
}

fn camera_at(degrees: f32) -> StrokeCamera {
    let (s, c) = degrees.to_radians().sin_cos();
    let eye = HEAD + Vec3::new(1.3 * s, 0.15, 1.3 * c);
    let look = HEAD + Vec3::new(0.0, 0.11, 0.0);
    StrokeCamera::look_at(eye, look, Vec3::Y, Projection::Perspective { vertical_fov: 0.36 }, Vec2::splat(PANEL as f32))
        .expect("camera")
}

/// The stroke: a hook up and over to screen-right, as a mouse would give it (a cubic Bézier, 40 points),
/// starting 25 px off the projected root (the sketch moves it onto the root).
fn stroke(root: Vec2) -> Vec<Vec2> {
    let start = root + Vec2::new(24.0, 6.0);
    let (p0, p1, p2, p3) =
        (start, start + Vec2::new(-10.0, -95.0), start + Vec2::new(85.0, -120.0), start + Vec2::new(80.0, -55.0));
    (0..40)
        .map(|k| {
            let t = k as f32 / 39.0;
            let u = 1.0 - t;
            p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t)
        })
        .collect()
}

fn positions(joints: &[Transform]) -> Vec<Vec3> {
    joints.iter().map(|j| j.position).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let head = Transform::new(HEAD, Quat::IDENTITY);
    let current = current_shape();
    let front = camera_at(0.0);
    let side = camera_at(90.0);
    let root_pixel = front.project(current[0].position).expect("root in view");
    let stroke_pixels = stroke(root_pixel);

    // The chain hangs from the head (its anchor) and the head is the view reference joint.
    let sketched = shape_from_stroke(&StrokeInput {
        camera: front,
        current_world_joints: &current,
        anchor_world: head,
        view_reference_world: head,
        stroke_pixels: &stroke_pixels,
    })?;
    let after: Vec<Transform> = sketched.anchor_joints.iter().map(|j| head.mul(j)).collect();

    let stroke_length: f32 = stroke_pixels.windows(2).map(|w| w[0].distance(w[1])).sum();
    let worst_length = current
        .windows(2)
        .zip(after.windows(2))
        .map(|(a, b)| {
            let (la, lb) = (a[0].position.distance(a[1].position), b[0].position.distance(b[1].position));
            ((lb - la) / la).abs()
        })
        .fold(0.0f32, f32::max);
    let offset = stroke_pixels[0] - root_pixel;
    let moved = |p: Vec2| p - offset;
    let worst_off_stroke = after
        .iter()
        .map(|j| {
            let pixel = front.project(j.position).expect("in view");
            stroke_pixels
                .windows(2)
                .map(|w| {
                    let (a, b) = (moved(w[0]), moved(w[1]));
                    let t = ((pixel - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    pixel.distance(a + (b - a) * t)
                })
                .fold(f32::INFINITY, f32::min)
        })
        .fold(0.0f32, f32::max);
    let depth = |joints: &[Transform]| {
        let (min, max) = joints
            .iter()
            .map(|j| j.position.z)
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), z| (lo.min(z), hi.max(z)));
        (max - min) * 100.0
    };
    println!(
        "render_sketch: an {JOINTS}-joint chain, a {}-point stroke ({stroke_length:.0} px) over the front view",
        stroke_pixels.len()
    );
    println!("  stroke started {:.1} px off the projected root: moved onto it", offset.length());
    println!("  joints off the stroke (front view): at most {worst_off_stroke:.3} px");
    println!("  segment lengths: worst relative change {worst_length:.1e}");
    println!("  depth extent (z, cm): before {:.1}, after {:.1}", depth(&current), depth(&after));
    let d = sketched.view_direction;
    println!("  view direction for kdw_chain_add_view_shape: ({:.3}, {:.3}, {:.3})", d.x, d.y, d.z);

    let before_style = ChainStyle {
        color: rgb(150, 156, 170),
        width: 0.009,
        joint: rgb(120, 126, 140),
        joint_size: 0.012,
        stripe: None,
    };
    let after_style =
        ChainStyle { color: rgb(92, 60, 48), width: 0.010, joint: rgb(128, 90, 70), joint_size: 0.014, stripe: None };
    let stroke_colour = rgb(232, 88, 40);
    let head_shape = Head { pose: head, radius: HEAD_RADIUS };
    let label_height = 26.0;
    let mut canvas = Canvas::new(2 * PANEL, PANEL + 2 * label_height as u32);
    let ink = support::color(support::INK);

    for (column, (camera, title)) in
        [(front, "stroke drawn here (front)"), (side, "seen from 90° (side)")].into_iter().enumerate()
    {
        let mut panel_canvas = Canvas::new(PANEL, PANEL);
        let panel = Panel { camera, origin: Vec2::ZERO };
        draw_scene(&mut panel_canvas, &panel, Some(&head_shape), &[(positions(&current), before_style)]);
        draw_scene(&mut panel_canvas, &panel, None, &[(positions(&after), after_style)]);
        if column == 0 {
            // The stroke as drawn (dashed: where the hand put it) and as used, moved onto the root (solid).
            panel_canvas.dashed(&stroke_pixels, 2.0, 6.0, 4.0, stroke_colour);
            let used: Vec<Vec2> = stroke_pixels.iter().map(|p| moved(*p)).collect();
            panel_canvas.polyline(&used, 2.5, stroke_colour);
        }
        let x = column as f32 * PANEL as f32;
        canvas.paste(&panel_canvas, x as i32, label_height as i32);
        canvas.text_centred(x + 0.5 * PANEL as f32, 6.0, 2.0, title, ink);
    }
    canvas.rect(PANEL as f32 - 1.0, label_height, 2.0, PANEL as f32, rgb(170, 176, 190));

    // Legend.
    let y = PANEL as f32 + label_height + 8.0;
    let mut x = 20.0;
    for (name, colour) in
        [("before", before_style.color), ("stroke (dashed: as drawn)", stroke_colour), ("after", after_style.color)]
    {
        canvas.line(Vec2::new(x, y + 6.0), Vec2::new(x + 26.0, y + 6.0), 5.0, colour);
        x += 34.0;
        x += canvas.text(x, y, 2.0, name, ink) + 28.0;
    }

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs").join("sketch.png");
    canvas.save_png(&path)?;
    println!("wrote {} (left: the stroke's camera, right: a camera at 90°)", path.display());
    Ok(())
}
