//! The sketch tool, `kodawari::core::sketch::shape_from_stroke`: a screen-space stroke becomes a chain shape
//! that keeps the root and every segment length and whose projection follows the stroke.

use std::f32::consts::PI;

use glam::{Quat, Vec2, Vec3};
use kodawari::core::sketch::{
    DUPLICATE_PIXELS, ForwardAxis, Projection, StrokeCamera, StrokeInput, StrokeShape, shape_from_stroke,
};
use kodawari::{ErrorKind, Transform};
use proptest::prelude::*;

const VIEWPORT: Vec2 = Vec2::new(800.0, 600.0);
const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);
/// Projected joints must lie this close to the stroke (pixels).
const ON_STROKE_PX: f32 = 0.5;
/// Segment lengths, relative.
const LENGTH_TOL: f32 = 1e-5;

const PERSPECTIVE: Projection = Projection::Perspective { vertical_fov: 0.8 };
const ORTHOGRAPHIC: Projection = Projection::Orthographic { half_height: 0.35 };

/// 8 joints from `root`, each segment 0.04 m, turning by `bend` radians per joint about `axis` from an
/// initial direction `first`; identity-free rotations (each joint twisted differently, bone axis +Y).
fn curled(root: Vec3, first: Vec3, axis: Vec3, bend: f32) -> Vec<Transform> {
    let turn = Quat::from_axis_angle(axis.normalize(), bend);
    let mut dir = first.normalize();
    let mut p = root;
    let mut joints = Vec::new();
    for j in 0..8 {
        let twist = Quat::from_rotation_y(0.3 * j as f32);
        joints.push(Transform::new(p, Quat::from_rotation_arc(Vec3::Y, dir) * twist));
        p += dir * 0.04;
        if j + 2 < 8 {
            dir = (turn * dir).normalize();
        }
    }
    joints
}

/// The chain used as "current shape" in most tests: straight up from the top of the head.
fn straight() -> Vec<Transform> {
    curled(HEAD + Vec3::new(0.0, 0.12, 0.0), Vec3::Y, Vec3::Z, 0.0)
}

/// A reachable target with depth: curls forward (towards +z) and to the side.
fn target() -> Vec<Transform> {
    curled(HEAD + Vec3::new(0.0, 0.12, 0.0), Vec3::new(0.2, 1.0, 0.3), Vec3::new(1.0, 0.0, -0.6), 0.35)
}

fn camera(eye: Vec3, projection: Projection) -> StrokeCamera {
    let look = HEAD + Vec3::new(0.0, 0.2, 0.0);
    StrokeCamera::look_at(eye, look, Vec3::Y, projection, VIEWPORT).expect("a valid camera")
}

/// Cameras around the head, not looking along the chain.
fn cameras() -> Vec<StrokeCamera> {
    let mut out = Vec::new();
    for projection in [PERSPECTIVE, ORTHOGRAPHIC] {
        for eye in [Vec3::new(0.0, 1.8, 1.5), Vec3::new(1.4, 2.2, 0.6), Vec3::new(-0.9, 1.5, -1.2)] {
            out.push(camera(eye, projection));
        }
    }
    // Close and wide: strong perspective, segments nearer the eye look longer than face-on ones.
    out.push(camera(Vec3::new(0.15, 2.0, 0.45), Projection::Perspective { vertical_fov: 1.6 }));
    out
}

fn project_all(camera: &StrokeCamera, joints: &[Transform]) -> Vec<Vec2> {
    joints.iter().map(|j| camera.project(j.position).expect("in front of the camera")).collect()
}

/// `points` with each segment split into `parts` (a denser stroke, as a mouse would give).
fn densify(points: &[Vec2], parts: usize) -> Vec<Vec2> {
    let mut out = vec![points[0]];
    for w in points.windows(2) {
        for k in 1..=parts {
            out.push(w[0].lerp(w[1], k as f32 / parts as f32));
        }
    }
    out
}

fn distance_to_polyline(p: Vec2, line: &[Vec2]) -> f32 {
    line.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let ab = b - a;
            let t =
                if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
            p.distance(a + ab * t)
        })
        .fold(f32::INFINITY, f32::min)
}

fn lengths(joints: &[Transform]) -> Vec<f32> {
    joints.windows(2).map(|w| w[0].position.distance(w[1].position)).collect()
}

fn to_world(anchor: &Transform, joints: &[Transform]) -> Vec<Transform> {
    joints.iter().map(|j| anchor.mul(j)).collect()
}

fn sketch(camera: StrokeCamera, current: &[Transform], anchor: Transform, stroke: &[Vec2]) -> StrokeShape {
    shape_from_stroke(&StrokeInput {
        camera,
        current_world_joints: current,
        anchor_world: anchor,
        view_reference_world: Transform::new(HEAD, Quat::IDENTITY),
        stroke_pixels: stroke,
    })
    .unwrap_or_else(|e| panic!("shape_from_stroke failed: {e}"))
}

/// Lengths kept to LENGTH_TOL relative, everything finite and unit.
fn assert_lengths_kept(current: &[Transform], result: &[Transform]) {
    assert_eq!(current.len(), result.len());
    for (j, (a, b)) in lengths(current).iter().zip(lengths(result)).enumerate() {
        assert!(((b - a) / a).abs() <= LENGTH_TOL, "segment {j}: {b} vs {a}");
    }
    for joint in result {
        assert!(joint.is_finite(), "{joint:?}");
        assert!((joint.rotation.length() - 1.0).abs() < 1e-5);
    }
}

fn assert_on_stroke(camera: &StrokeCamera, world: &[Transform], stroke: &[Vec2], what: &str) {
    for (j, joint) in world.iter().enumerate() {
        let pixel = camera.project(joint.position).unwrap_or_else(|| panic!("{what}: joint {j} behind the camera"));
        let d = distance_to_polyline(pixel, stroke);
        assert!(d <= ON_STROKE_PX, "{what}: joint {j} is {d} px from the stroke");
    }
}

#[test]
fn fitting_strokes_are_followed_from_perspective_and_orthographic_cameras() {
    let current = straight();
    let goal = target();
    for (i, camera) in cameras().into_iter().enumerate() {
        let stroke = densify(&project_all(&camera, &goal), 4);
        let shape = sketch(camera, &current, Transform::IDENTITY, &stroke);
        assert_lengths_kept(&current, &shape.anchor_joints);
        assert_eq!(shape.anchor_joints[0].position, current[0].position, "camera {i}: root moved");
        assert_on_stroke(&camera, &shape.anchor_joints, &stroke, &format!("camera {i}"));
        // The chain used the stroke: its tip is well beyond the root on screen.
        let tip = camera.project(shape.anchor_joints[7].position).unwrap();
        let root = camera.project(current[0].position).unwrap();
        let goal_tip = *stroke.last().unwrap();
        assert!(tip.distance(root) > 0.5 * goal_tip.distance(root), "camera {i}");
    }
}

#[test]
fn round_trip_reproduces_the_shape_and_its_projection() {
    let goal = target();
    for (i, camera) in cameras().into_iter().enumerate() {
        let projected = project_all(&camera, &goal);
        let shape = sketch(camera, &goal, Transform::IDENTITY, &projected);
        let again = project_all(&camera, &shape.anchor_joints);
        for (j, (a, b)) in again.iter().zip(&projected).enumerate() {
            assert!(a.distance(*b) < 0.01, "camera {i}, joint {j}: {a} vs {b}");
        }
        // In 3D too, up to the depth of segments seen face-on, which rounding of the stroke's pixels moves by
        // sqrt(2 l * error): 0.1 mm here.
        for (j, (a, b)) in shape.anchor_joints.iter().zip(&goal).enumerate() {
            assert!(a.position.distance(b.position) < 2e-4, "camera {i}, joint {j}: {a:?} vs {b:?}");
            let same = a.rotation.dot(b.rotation).abs();
            assert!(same > 1.0 - 1e-5, "camera {i}, joint {j}: rotation changed ({same})");
        }
    }
}

#[test]
fn rotations_are_swung_onto_the_new_segments_keeping_twist() {
    let current = straight();
    let camera = camera(Vec3::new(0.0, 1.8, 1.5), PERSPECTIVE);
    let stroke = densify(&project_all(&camera, &target()), 3);
    let result = sketch(camera, &current, Transform::IDENTITY, &stroke).anchor_joints;
    for j in 0..8 {
        let s = j.min(6);
        let old_dir = (current[s + 1].position - current[s].position).normalize();
        let new_dir = (result[s + 1].position - result[s].position).normalize();
        let axis = current[j].rotation.inverse() * old_dir;
        assert!((result[j].rotation * axis - new_dir).length() < 1e-5, "joint {j}: bone axis off its segment");
        let expected = Quat::from_rotation_arc(old_dir, new_dir) * current[j].rotation;
        assert!(result[j].rotation.dot(expected).abs() > 1.0 - 1e-6, "joint {j}: not the shortest swing");
    }
}

#[test]
fn the_result_is_in_the_anchor_frame_and_the_view_direction_in_the_reference_frame() {
    let current = straight();
    let camera = camera(Vec3::new(1.4, 2.2, 0.6), PERSPECTIVE);
    let stroke = densify(&project_all(&camera, &target()), 2);
    let world = sketch(camera, &current, Transform::IDENTITY, &stroke);

    let anchor =
        Transform::new(HEAD + Vec3::new(0.01, 0.05, -0.02), Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 0.2));
    let reference = Transform::new(Vec3::new(0.3, 1.5, -0.2), Quat::from_rotation_y(1.1));
    let local = shape_from_stroke(&StrokeInput {
        camera,
        current_world_joints: &current,
        anchor_world: anchor,
        view_reference_world: reference,
        stroke_pixels: &stroke,
    })
    .unwrap();
    let back = to_world(&anchor, &local.anchor_joints);
    for (a, b) in back.iter().zip(&world.anchor_joints) {
        assert!(a.position.distance(b.position) < 1e-6, "{a:?} vs {b:?}");
        assert!(a.rotation.dot(b.rotation).abs() > 1.0 - 1e-6);
    }
    assert!(local.anchor_joints[0].position.distance(anchor.inverse_transform_point(current[0].position)) < 1e-7);
    assert_lengths_kept(&current, &local.anchor_joints);
    let expected = (reference.rotation.inverse() * (camera.position - reference.position)).normalize();
    assert!((local.view_direction - expected).length() < 1e-6);
    // With the identity reference at the head: the direction from the head to the camera.
    assert!((world.view_direction - (camera.position - HEAD).normalize()).length() < 1e-6);
}

#[test]
fn duplicate_points_are_ignored() {
    let current = straight();
    let camera = camera(Vec3::new(0.0, 1.8, 1.5), ORTHOGRAPHIC);
    let stroke = densify(&project_all(&camera, &target()), 2);
    let tripled: Vec<Vec2> = stroke.iter().flat_map(|p| [*p, *p, *p + Vec2::splat(DUPLICATE_PIXELS * 0.25)]).collect();
    let a = sketch(camera, &current, Transform::IDENTITY, &stroke);
    let b = sketch(camera, &current, Transform::IDENTITY, &tripled);
    for (x, y) in a.anchor_joints.iter().zip(&b.anchor_joints) {
        assert!(x.position.distance(y.position) < 1e-6);
    }
}

#[test]
fn strokes_without_two_distinct_points_are_rejected() {
    let current = straight();
    let camera = camera(Vec3::new(0.0, 1.8, 1.5), PERSPECTIVE);
    let p = Vec2::new(400.0, 300.0);
    for stroke in [vec![], vec![p], vec![p, p, p + Vec2::splat(1e-4)]] {
        let error = shape_from_stroke(&StrokeInput {
            camera,
            current_world_joints: &current,
            anchor_world: Transform::IDENTITY,
            view_reference_world: Transform::IDENTITY,
            stroke_pixels: &stroke,
        })
        .unwrap_err();
        assert_eq!(error.kind, ErrorKind::InvalidArgument);
        assert!(error.message.contains("at least 2 distinct points"), "{}", error.message);
    }
}

#[test]
fn a_stroke_away_from_the_root_is_moved_to_start_there() {
    let current = straight();
    let camera = camera(Vec3::new(-0.9, 1.5, -1.2), PERSPECTIVE);
    let stroke = densify(&project_all(&camera, &target()), 2);
    let moved: Vec<Vec2> = stroke.iter().map(|p| *p + Vec2::new(-120.0, 45.0)).collect();
    let a = sketch(camera, &current, Transform::IDENTITY, &stroke);
    let b = sketch(camera, &current, Transform::IDENTITY, &moved);
    for (x, y) in a.anchor_joints.iter().zip(&b.anchor_joints) {
        assert!(x.position.distance(y.position) < 1e-5, "{x:?} vs {y:?}");
    }
}

#[test]
fn a_camera_looking_down_the_chain_gives_a_finite_shape() {
    let current = straight();
    let root = current[0].position;
    for projection in [PERSPECTIVE, ORTHOGRAPHIC] {
        for eye in [root + Vec3::Y * 1.5, root - Vec3::Y * 1.0] {
            let camera = StrokeCamera::look_at(eye, root, Vec3::Z, projection, VIEWPORT).unwrap();
            let start = camera.project(root).unwrap();
            // The chain projects to (nearly) one point; strokes sideways, tiny, and along the old projection.
            for stroke in [
                vec![start, start + Vec2::new(60.0, 10.0), start + Vec2::new(90.0, 60.0)],
                vec![start, start + Vec2::new(0.5, 0.0)],
                vec![start, start + Vec2::new(3000.0, 0.0)],
            ] {
                let shape = sketch(camera, &current, Transform::IDENTITY, &stroke);
                assert_lengths_kept(&current, &shape.anchor_joints);
                assert_eq!(shape.anchor_joints[0].position, root);
                assert!(shape.view_direction.is_finite());
            }
        }
    }
}

#[test]
fn a_stroke_longer_than_the_chain_is_followed_from_its_start() {
    let current = straight();
    let camera = camera(Vec3::new(0.0, 1.8, 1.5), PERSPECTIVE);
    let start = camera.project(current[0].position).unwrap();
    let stroke = vec![start, start + Vec2::new(900.0, -50.0), start + Vec2::new(900.0, -900.0)];
    let shape = sketch(camera, &current, Transform::IDENTITY, &stroke);
    assert_lengths_kept(&current, &shape.anchor_joints);
    assert_on_stroke(&camera, &shape.anchor_joints, &stroke, "long stroke");
    let tip = camera.project(shape.anchor_joints[7].position).unwrap();
    assert!(tip.distance(*stroke.last().unwrap()) > 100.0, "the tip cannot reach the end");
}

#[test]
fn unity_cameras_look_along_positive_z() {
    // A +Z camera with rotation r sees the mirror image (x -> width - x) of a -Z camera with r * Ry(pi).
    let r = Quat::from_euler(glam::EulerRot::YXZ, -0.2, 0.2, 0.0);
    let unity = StrokeCamera {
        position: Vec3::new(0.3, 1.9, -1.4),
        rotation: r,
        forward_axis: ForwardAxis::PositiveZ,
        projection: PERSPECTIVE,
        viewport: VIEWPORT,
    };
    let gl = StrokeCamera { rotation: r * Quat::from_rotation_y(PI), forward_axis: ForwardAxis::NegativeZ, ..unity };
    assert!((unity.forward() - r * Vec3::Z).length() < 1e-6);
    let current = straight();
    for joint in target() {
        let (a, b) = (unity.project(joint.position).unwrap(), gl.project(joint.position).unwrap());
        assert!((a.x - (VIEWPORT.x - b.x)).abs() < 1e-3 && (a.y - b.y).abs() < 1e-3);
    }
    let stroke = densify(&project_all(&unity, &target()), 2);
    let mirrored: Vec<Vec2> = stroke.iter().map(|p| Vec2::new(VIEWPORT.x - p.x, p.y)).collect();
    let a = sketch(unity, &current, Transform::IDENTITY, &stroke);
    let b = sketch(gl, &current, Transform::IDENTITY, &mirrored);
    for (x, y) in a.anchor_joints.iter().zip(&b.anchor_joints) {
        assert!(x.position.distance(y.position) < 1e-5);
    }
    assert_on_stroke(&unity, &a.anchor_joints, &stroke, "unity camera");
}

#[test]
fn invalid_input_is_rejected() {
    let current = straight();
    let good_camera = camera(Vec3::new(0.0, 1.8, 1.5), PERSPECTIVE);
    let stroke = densify(&project_all(&good_camera, &target()), 1);
    let run = |camera: StrokeCamera, joints: &[Transform], anchor: Transform, reference: Transform, stroke: &[Vec2]| {
        shape_from_stroke(&StrokeInput {
            camera,
            current_world_joints: joints,
            anchor_world: anchor,
            view_reference_world: reference,
            stroke_pixels: stroke,
        })
    };
    let id = Transform::IDENTITY;
    assert!(run(good_camera, &current, id, id, &stroke).is_ok());
    let nan = f32::NAN;
    let mut bad_cameras = vec![
        StrokeCamera { position: Vec3::new(nan, 0.0, 0.0), ..good_camera },
        StrokeCamera { rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), ..good_camera },
        StrokeCamera { projection: Projection::Perspective { vertical_fov: 0.0 }, ..good_camera },
        StrokeCamera { projection: Projection::Perspective { vertical_fov: PI }, ..good_camera },
        StrokeCamera { projection: Projection::Perspective { vertical_fov: nan }, ..good_camera },
        StrokeCamera { projection: Projection::Orthographic { half_height: -1.0 }, ..good_camera },
        StrokeCamera { projection: Projection::Orthographic { half_height: f32::INFINITY }, ..good_camera },
        StrokeCamera { viewport: Vec2::new(0.0, 600.0), ..good_camera },
        StrokeCamera { viewport: Vec2::new(800.0, f32::INFINITY), ..good_camera },
    ];
    // A perspective camera behind which the root lies.
    bad_cameras.push(
        StrokeCamera::look_at(Vec3::new(0.0, 1.8, -1.0), Vec3::new(0.0, 1.8, -3.0), Vec3::Y, PERSPECTIVE, VIEWPORT)
            .unwrap(),
    );
    for camera in bad_cameras {
        let error = run(camera, &current, id, id, &stroke).unwrap_err();
        assert_eq!(error.kind, ErrorKind::InvalidArgument, "{camera:?}");
    }
    let mut nan_joint = current.clone();
    nan_joint[3].position.x = nan;
    let mut zero_segment = current.clone();
    zero_segment[4].position = zero_segment[3].position;
    let nan_stroke: Vec<Vec2> =
        stroke.iter().enumerate().map(|(i, p)| if i == 2 { Vec2::new(p.x, nan) } else { *p }).collect();
    let inf_stroke = vec![stroke[0], Vec2::new(f32::INFINITY, 0.0)];
    let bad_transform = Transform::new(Vec3::new(0.0, f32::INFINITY, 0.0), Quat::IDENTITY);
    let null_rotation = Transform::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0));
    let errors = [
        run(good_camera, &current[..1], id, id, &stroke),
        run(good_camera, &nan_joint, id, id, &stroke),
        run(good_camera, &zero_segment, id, id, &stroke),
        run(good_camera, &current, bad_transform, id, &stroke),
        run(good_camera, &current, null_rotation, id, &stroke),
        run(good_camera, &current, id, bad_transform, &stroke),
        run(good_camera, &current, id, null_rotation, &stroke),
        run(good_camera, &current, id, id, &nan_stroke),
        run(good_camera, &current, id, id, &inf_stroke),
    ];
    for (i, result) in errors.into_iter().enumerate() {
        assert_eq!(result.unwrap_err().kind, ErrorKind::InvalidArgument, "case {i}");
    }
}

#[test]
fn a_camera_at_the_view_reference_uses_its_forward_direction() {
    let current = straight();
    let camera = StrokeCamera::look_at(HEAD, current[0].position, Vec3::Z, ORTHOGRAPHIC, VIEWPORT).unwrap();
    let start = camera.project(current[0].position).unwrap();
    let shape = sketch(camera, &current, Transform::IDENTITY, &[start, start + Vec2::new(50.0, 0.0)]);
    assert!((shape.view_direction + camera.forward()).length() < 1e-6);
    assert_lengths_kept(&current, &shape.anchor_joints);
}

/// Random cameras around the chain and random strokes from the projected root: always finite, lengths
/// kept, root fixed, every joint on the stroke.
fn arb_case() -> impl Strategy<Value = (f32, f32, f32, bool, Vec<(f32, f32)>)> {
    (
        0.0f32..std::f32::consts::TAU,
        -1.2f32..1.2,
        0.8f32..3.0,
        any::<bool>(),
        prop::collection::vec((-60.0f32..60.0, -60.0f32..60.0), 1..12),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn random_strokes_give_valid_shapes((yaw, pitch, distance, ortho, steps) in arb_case()) {
        let current = target();
        let centre = HEAD + Vec3::new(0.0, 0.2, 0.0);
        let eye = centre + Vec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos()) * distance;
        let projection = if ortho { ORTHOGRAPHIC } else { PERSPECTIVE };
        let camera = StrokeCamera::look_at(eye, centre, Vec3::Y, projection, VIEWPORT).unwrap();
        let mut stroke = vec![camera.project(current[0].position).unwrap()];
        for (dx, dy) in steps {
            let last = *stroke.last().unwrap();
            stroke.push(last + Vec2::new(dx, dy));
        }
        prop_assume!(stroke.windows(2).any(|w| w[0].distance(w[1]) > 0.01));
        let shape = sketch(camera, &current, Transform::IDENTITY, &stroke);
        assert_lengths_kept(&current, &shape.anchor_joints);
        prop_assert_eq!(shape.anchor_joints[0].position, current[0].position);
        assert_on_stroke(&camera, &shape.anchor_joints, &stroke, "random");
    }
}
