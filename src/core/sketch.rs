//! Sketch shape editing (SPEC 9): one screen-space stroke seen from a camera becomes a chain shape that keeps
//! the chain's root and every segment length, and whose projection follows the stroke.
//!
//! # Conventions
//! - World: right-handed, Y up (the engine's). A [`StrokeCamera`] is a position and a rotation; its screen
//!   right is `rotation * (1, 0, 0)` and its screen up `rotation * (0, 1, 0)`. It looks along
//!   `rotation * (0, 0, -1)` ([`ForwardAxis::NegativeZ`]: OpenGL, glTF, Blender, Godot) or, for hosts that
//!   pass Unity's own numbers unchanged, along `rotation * (0, 0, 1)` ([`ForwardAxis::PositiveZ`]: Unity's
//!   `Camera.transform.position` and `.rotation` as they are).
//! - Pixels: origin at the top-left corner of the viewport, x to the right, y **down**; pixel centres are
//!   not special (the viewport spans `[0, width] x [0, height]`). Pixels are square: the vertical field of
//!   view (or orthographic half-height) sets the scale, the aspect ratio follows from the viewport. (Unity:
//!   `Event.mousePosition` in the scene view is already top-left, y down, in points: multiply by
//!   `EditorGUIUtility.pixelsPerPoint`; `Input.mousePosition` is bottom-left: use `height - y`.)
//!
//! # Algorithm
//! 1. The stroke is cleaned (consecutive points closer than [`DUPLICATE_PIXELS`] are merged; fewer than two
//!    distinct points is an error) and translated so that its first point lies on the projected root: the
//!    root is fixed, so where the stroke starts only says where the chain goes from there.
//! 2. Arc length along the stroke drives the joints. What is left of the stroke is shared among the
//!    remaining segments in proportion to each one's projected length in the current shape (a segment seen
//!    end-on stays end-on: depth is kept where the stroke cannot tell it), none above an estimate of how far
//!    it reaches on screen (its length seen face-on, or its current projected length if longer). A stroke
//!    that is the current shape's projection therefore maps every joint onto its own projection.
//! 3. Joint by joint, root outwards, the ray through the joint's stroke point is intersected with the sphere
//!    of radius `l_j` around the previous (new) joint; of the two intersections the one nearest to the
//!    current joint's depth along the ray wins. If that stroke point is out of reach, the joint stops where
//!    the stroke leaves the sphere's image and the following segments share the rest: a stroke longer than
//!    the chain can reach is followed from its start as far as the chain reaches, every joint on it. Only if
//!    no point is reachable (the previous joint ended off the stroke, or the sphere lies behind a perspective
//!    eye) does the segment keep its current direction's component along the ray and turn the remaining,
//!    sideways part towards the ray.
//! 4. Each joint's rotation is swung (shortest arc) so that its bone axis, taken from the current shape
//!    (`rot_j^-1 * (x_{j+1} - x_j)`; the tip uses its parent segment), follows the new segment: twist is kept.
//!
//! Everything is computed in double precision relative to the root, so segment lengths are kept to float
//! rounding of the output (far below 1e-5 relative) and the root's position is the current root's,
//! expressed in the anchor frame.

use glam::{DQuat, DVec2, DVec3, Mat3, Quat, Vec2, Vec3};

use super::elementary;
use super::error::{Error, Result};
use super::math::{Transform, normalized_direction, normalized_rotation};
use super::shape::Shape;

/// Consecutive stroke points closer than this (pixels) are one point.
pub const DUPLICATE_PIXELS: f32 = 1e-3;

/// Share of a segment's face-on screen length that its share of the stroke never drops below, so that a
/// chain seen exactly end-on still spreads along the stroke.
const MIN_SHARE_OF_FACE_ON: f64 = 0.01;

/// A ray that misses a segment's sphere by less than this fraction of its length only grazes it (rounding).
const GRAZING: f64 = 1e-4;

/// How a camera maps depth to the screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole camera with this vertical field of view, radians, in (0, pi).
    Perspective { vertical_fov: f32 },
    /// Parallel projection; the viewport's height spans `2 * half_height` metres (Unity's orthographic
    /// size is this half-height). > 0.
    Orthographic { half_height: f32 },
}

/// Which local axis a camera looks along (screen right is always local +X and screen up local +Y).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ForwardAxis {
    /// Looks along local -Z: right-handed cameras (OpenGL, glTF, Blender, Godot). The default.
    #[default]
    NegativeZ,
    /// Looks along local +Z: Unity's camera, with Unity's position and rotation passed unchanged.
    PositiveZ,
}

/// The camera a stroke was drawn in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokeCamera {
    /// World position (the eye of a perspective camera; the centre of an orthographic camera's plane).
    pub position: Vec3,
    /// World rotation (need not be unit; normalised on use).
    pub rotation: Quat,
    pub forward_axis: ForwardAxis,
    pub projection: Projection,
    /// Viewport width and height in pixels, > 0.
    pub viewport: Vec2,
}

impl StrokeCamera {
    /// A camera at `position` looking at `target`, screen-up as close to `up` as possible, looking along
    /// its local -Z ([`ForwardAxis::NegativeZ`]). `None` if `target == position` or `up` is parallel to the
    /// view direction.
    pub fn look_at(position: Vec3, target: Vec3, up: Vec3, projection: Projection, viewport: Vec2) -> Option<Self> {
        let forward = normalized_direction(target - position)?;
        let right = normalized_direction(forward.cross(up))?;
        let up = right.cross(forward);
        let rotation = Quat::from_mat3(&Mat3::from_cols(right, up, -forward)).normalize();
        Some(Self { position, rotation, forward_axis: ForwardAxis::NegativeZ, projection, viewport })
    }

    /// Checks every value: finite position, non-null rotation, field of view in (0, pi) or positive
    /// half-height, positive viewport.
    pub fn validate(&self) -> Result<()> {
        if !self.position.is_finite() {
            return Err(Error::invalid_argument("camera position is not finite"));
        }
        if normalized_rotation(self.rotation).is_none() {
            return Err(Error::invalid_argument("camera rotation is null or not finite"));
        }
        match self.projection {
            Projection::Perspective { vertical_fov } => {
                if !(vertical_fov > 0.0 && vertical_fov < std::f32::consts::PI) {
                    return Err(Error::invalid_argument(format!(
                        "camera vertical field of view must be in (0, pi) radians, got {vertical_fov}"
                    )));
                }
            }
            Projection::Orthographic { half_height } => {
                if !(half_height > 0.0 && half_height.is_finite()) {
                    return Err(Error::invalid_argument(format!(
                        "camera orthographic half-height must be finite and > 0, got {half_height}"
                    )));
                }
            }
        }
        let Vec2 { x: width, y: height } = self.viewport;
        if !(width > 0.0 && width.is_finite() && height > 0.0 && height.is_finite()) {
            return Err(Error::invalid_argument(format!(
                "camera viewport must be finite and > 0 pixels, got {width} x {height}"
            )));
        }
        Ok(())
    }

    /// Unit world direction the camera looks along.
    pub fn forward(&self) -> Vec3 {
        self.lens(Vec3::ZERO).forward.as_vec3()
    }

    /// Pixel position of world point `p` (origin top-left, y down); `None` for a point on or behind the
    /// plane of a perspective camera's eye, or for an invalid camera.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        self.validate().ok()?;
        self.lens(Vec3::ZERO).project(p.as_dvec3()).map(|v| v.as_vec2())
    }

    /// The world ray `(origin, unit direction)` through pixel `pixel`; `None` for an invalid camera or a
    /// non-finite pixel.
    pub fn ray(&self, pixel: Vec2) -> Option<(Vec3, Vec3)> {
        self.validate().ok()?;
        if !pixel.is_finite() {
            return None;
        }
        let (origin, dir) = self.lens(Vec3::ZERO).ray(pixel.as_dvec2());
        Some((origin.as_vec3(), dir.as_vec3()))
    }

    /// The camera in double precision, with world positions taken relative to `origin`.
    fn lens(&self, origin: Vec3) -> Lens {
        // Unit in double precision too: a basis off unit length by float rounding (1e-7) would put ray-sphere
        // hits 1e-3 px off the stroke.
        let rotation = normalized_rotation(self.rotation).unwrap_or(Quat::IDENTITY).as_dquat().normalize();
        let forward_local = match self.forward_axis {
            ForwardAxis::NegativeZ => DVec3::NEG_Z,
            ForwardAxis::PositiveZ => DVec3::Z,
        };
        let (perspective, scale) = match self.projection {
            Projection::Perspective { vertical_fov } => (true, elementary::tan_f64(0.5 * vertical_fov as f64)),
            Projection::Orthographic { half_height } => (false, half_height as f64),
        };
        Lens {
            eye: self.position.as_dvec3() - origin.as_dvec3(),
            right: rotation * DVec3::X,
            up: rotation * DVec3::Y,
            forward: rotation * forward_local,
            perspective,
            scale,
            half_width: 0.5 * self.viewport.x as f64,
            half_height: 0.5 * self.viewport.y as f64,
        }
    }
}

/// A camera in double precision, positions relative to some origin (the chain's root).
struct Lens {
    eye: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    perspective: bool,
    /// tan(fov / 2) for perspective, the half-height in metres for orthographic.
    scale: f64,
    half_width: f64,
    half_height: f64,
}

impl Lens {
    /// Pixel of `p`, or `None` on or behind a perspective eye's plane.
    fn project(&self, p: DVec3) -> Option<DVec2> {
        let v = p - self.eye;
        let (x, y) = (v.dot(self.right), v.dot(self.up));
        let (nx, ny) = if self.perspective {
            let depth = v.dot(self.forward);
            // In front by more than rounding: a point on the eye's plane has no image.
            if depth.is_nan() || depth <= 1e-12 * v.length() {
                return None;
            }
            (x / (depth * self.scale), y / (depth * self.scale))
        } else {
            (x / self.scale, y / self.scale)
        };
        let pixel = DVec2::new(self.half_width + nx * self.half_height, self.half_height - ny * self.half_height);
        pixel.is_finite().then_some(pixel)
    }

    /// `(origin, unit direction)` of the ray through `pixel`.
    fn ray(&self, pixel: DVec2) -> (DVec3, DVec3) {
        let nx = (pixel.x - self.half_width) / self.half_height;
        let ny = (self.half_height - pixel.y) / self.half_height;
        if self.perspective {
            let dir = self.forward + (self.right * nx + self.up * ny) * self.scale;
            (self.eye, dir.normalize())
        } else {
            (self.eye + (self.right * nx + self.up * ny) * self.scale, self.forward)
        }
    }

    /// Pixels per metre for a short segment at `p`, face-on (unchanged depth); `None` behind the eye.
    fn pixels_per_metre(&self, p: DVec3) -> Option<f64> {
        if self.perspective {
            let depth = (p - self.eye).dot(self.forward);
            (depth > 1e-12 * (p - self.eye).length()).then(|| self.half_height / (depth * self.scale))
        } else {
            Some(self.half_height / self.scale)
        }
    }
}

/// Everything [`shape_from_stroke`] needs, all in world space.
#[derive(Clone, Copy, Debug)]
pub struct StrokeInput<'a> {
    /// The camera the stroke was drawn in.
    pub camera: StrokeCamera,
    /// The chain as it is now, world space, root first (`n >= 2`, no zero-length segment).
    pub current_world_joints: &'a [Transform],
    /// The chain's anchor (the bone it hangs from) in world space: the frame of the result.
    pub anchor_world: Transform,
    /// The view reference joint K in world space: the frame of the returned view direction.
    pub view_reference_world: Transform,
    /// The stroke, root to tip, in pixels (origin top-left, y down). At least 2 distinct points.
    pub stroke_pixels: &'a [Vec2],
}

/// The result of [`shape_from_stroke`]: ready for `Engine::add_view_shape(chain, view_direction,
/// &anchor_joints, influence)`.
#[derive(Clone, Debug, PartialEq)]
pub struct StrokeShape {
    /// The new shape in the anchor frame, as many joints as the input.
    pub anchor_joints: Vec<Transform>,
    /// Unit direction from K to the camera in K's frame: `normalize(K_rot^-1 * (camera - K_pos))`. A camera
    /// standing exactly at K uses the opposite of its forward direction instead.
    pub view_direction: Vec3,
}

fn checked_transform(t: &Transform, what: &str) -> Result<(DVec3, DQuat)> {
    let rotation = normalized_rotation(t.rotation)
        .ok_or_else(|| Error::invalid_argument(format!("{what} rotation is null or not finite")))?;
    if !t.position.is_finite() {
        return Err(Error::invalid_argument(format!("{what} position is not finite")));
    }
    Ok((t.position.as_dvec3(), rotation.as_dquat()))
}

/// The stroke without consecutive duplicates, in double precision.
fn clean_stroke(points: &[Vec2]) -> Result<Vec<DVec2>> {
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::invalid_argument(format!("stroke point {i} is not finite")));
    }
    let mut out: Vec<DVec2> = Vec::with_capacity(points.len());
    for p in points {
        let p = p.as_dvec2();
        if out.last().is_none_or(|last| last.distance(p) > DUPLICATE_PIXELS as f64) {
            out.push(p);
        }
    }
    if out.len() < 2 {
        return Err(Error::invalid_argument(format!(
            "a stroke needs at least 2 distinct points (more than {DUPLICATE_PIXELS} px apart); got {} point(s), \
             {} distinct",
            points.len(),
            out.len()
        )));
    }
    Ok(out)
}

/// A polyline with its cumulative arc length, sampled by arc length.
struct Polyline {
    points: Vec<DVec2>,
    cumulative: Vec<f64>,
}

impl Polyline {
    fn new(points: Vec<DVec2>) -> Self {
        let mut cumulative = Vec::with_capacity(points.len());
        let mut total = 0.0;
        cumulative.push(0.0);
        for w in points.windows(2) {
            total += w[0].distance(w[1]);
            cumulative.push(total);
        }
        Self { points, cumulative }
    }

    fn length(&self) -> f64 {
        *self.cumulative.last().expect("at least 2 points")
    }

    /// The point at arc length `s`, clamped to the ends.
    fn at(&self, s: f64) -> DVec2 {
        if s <= 0.0 {
            return self.points[0];
        }
        if s >= self.length() {
            return *self.points.last().expect("at least 2 points");
        }
        // First vertex at or beyond s; s > 0, so k >= 1.
        let k = self.cumulative.partition_point(|&c| c < s);
        let (a, b) = (self.cumulative[k - 1], self.cumulative[k]);
        let t = if b > a { (s - a) / (b - a) } else { 0.0 };
        self.points[k - 1].lerp(self.points[k], t)
    }
}

/// Shares `total` among segments in proportion to `preferred`, none above its `cap` (water filling); when
/// `total` exceeds the caps' sum, every segment gets its cap.
fn share(total: f64, preferred: &[f64], caps: &[f64]) -> Vec<f64> {
    let cap_sum: f64 = caps.iter().sum();
    if total >= cap_sum {
        return caps.to_vec();
    }
    let mut capped = vec![false; preferred.len()];
    loop {
        let fixed: f64 = caps.iter().zip(&capped).filter(|(_, c)| **c).map(|(cap, _)| cap).sum();
        let free: f64 = preferred.iter().zip(&capped).filter(|(_, c)| !**c).map(|(p, _)| p).sum();
        let scale = if free > 0.0 { ((total - fixed) / free).max(0.0) } else { 0.0 };
        let mut changed = false;
        for j in 0..preferred.len() {
            if !capped[j] && preferred[j] * scale > caps[j] {
                capped[j] = true;
                changed = true;
            }
        }
        if !changed {
            return preferred
                .iter()
                .zip(caps)
                .zip(&capped)
                .map(|((p, cap), c)| if *c { *cap } else { p * scale })
                .collect();
        }
    }
}

/// The furthest arc length in `[from, to]` up to which the stroke stays reachable (`place` succeeds), with
/// its placement: the stroke is walked from `from` until `place` first fails, and that crossing is bisected.
/// `(to, None)` when even `from` is out of reach.
fn last_reachable(from: f64, to: f64, place: &dyn Fn(f64) -> Option<DVec3>) -> (f64, Option<DVec3>) {
    const WALK: usize = 32;
    const BISECT: usize = 48;
    let Some(mut best) = place(from) else {
        return (to, None);
    };
    let (mut lo, mut hi) = (from, to);
    for k in 1..=WALK {
        let s = from + (to - from) * k as f64 / WALK as f64;
        match place(s) {
            Some(d) => (lo, best) = (s, d),
            None => {
                hi = s;
                break;
            }
        }
    }
    for _ in 0..BISECT {
        let mid = 0.5 * (lo + hi);
        match place(mid) {
            Some(d) => (lo, best) = (mid, d),
            None => hi = mid,
        }
    }
    (lo, Some(best))
}

/// The ray parameters where `origin + t * dir` (unit `dir`) is `radius` from `centre`, if any.
fn ray_sphere(origin: DVec3, dir: DVec3, centre: DVec3, radius: f64) -> Option<(f64, f64)> {
    let m = origin - centre;
    let b = m.dot(dir);
    let c = m.length_squared() - radius * radius;
    let disc = b * b - c;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    Some((-b - root, -b + root))
}

/// A chain shape, in the anchor frame, whose projection through `input.camera` follows the stroke; see the
/// module documentation for the conventions and the algorithm.
///
/// Errors (`InvalidArgument`): fewer than 2 joints, a zero-length segment, anything non-finite or a null
/// rotation, an invalid camera, fewer than 2 distinct stroke points, or a root on or behind the plane of a
/// perspective camera's eye.
pub fn shape_from_stroke(input: &StrokeInput) -> Result<StrokeShape> {
    let camera = &input.camera;
    camera.validate()?;
    let current = Shape::from_joints(input.current_world_joints)?;
    let (anchor_position, anchor_rotation) = checked_transform(&input.anchor_world, "anchor")?;
    let (reference_position, reference_rotation) = checked_transform(&input.view_reference_world, "view reference")?;
    let stroke = clean_stroke(input.stroke_pixels)?;

    let n = current.len();
    let root = current.positions[0];
    // Root-relative, double precision: lengths survive intact at any distance from the world origin.
    let x: Vec<DVec3> = current.positions.iter().map(|p| p.as_dvec3() - root.as_dvec3()).collect();
    let lengths: Vec<f64> = x.windows(2).map(|w| w[0].distance(w[1])).collect();
    let directions: Vec<DVec3> = x.windows(2).zip(&lengths).map(|(w, l)| (w[1] - w[0]) / l).collect();
    let lens = camera.lens(root);

    let Some(root_pixel) = lens.project(DVec3::ZERO) else {
        return Err(Error::invalid_argument(
            "the chain's root is on or behind the plane of the perspective camera's eye: a stroke cannot place it",
        ));
    };
    // The root stays where it is: the stroke is moved to start there.
    let offset = root_pixel - stroke[0];
    let stroke = Polyline::new(stroke.into_iter().map(|p| p + offset).collect());

    // The current shape on screen: each segment's projected and face-on lengths, in pixels.
    let root_ppm = lens.pixels_per_metre(DVec3::ZERO).expect("the root projects");
    let projected: Vec<Option<DVec2>> = x.iter().map(|p| lens.project(*p)).collect();
    let mut face_on = Vec::with_capacity(n - 1);
    let mut seen = Vec::with_capacity(n - 1);
    for j in 0..n - 1 {
        let full = lengths[j] * lens.pixels_per_metre(x[j]).unwrap_or(root_ppm);
        let on_screen = match (projected[j], projected[j + 1]) {
            (Some(a), Some(b)) => a.distance(b),
            _ => full,
        };
        face_on.push(full);
        seen.push(on_screen);
    }
    let preferred: Vec<f64> = seen.iter().zip(&face_on).map(|(s, f)| s.max(MIN_SHARE_OF_FACE_ON * f)).collect();
    let caps: Vec<f64> = seen.iter().zip(&face_on).map(|(s, f)| s.max(*f)).collect();

    // Joint by joint: share what is left of the stroke among the remaining segments (the next one's cap
    // measured where its new start really is), then cast the ray through the stroke point.
    let mut new_x = vec![DVec3::ZERO; n];
    let mut arc = 0.0;
    for j in 0..n - 1 {
        let p = new_x[j];
        let remaining = (stroke.length() - arc).max(0.0);
        let shares = share(remaining, &preferred[j..], &caps[j..]);
        // The last joint aims exactly at the stroke's end when the stroke fits.
        let wanted = if j == n - 2 && remaining <= caps[j] { stroke.length() } else { arc + shares[0] };

        // The new joint on the ray through the stroke point at arc length `s`, if the ray meets the sphere of
        // radius l_j around p (in front of a perspective eye): the intersection nearest the current depth.
        let target = x[j + 1];
        let place = |s: f64| -> Option<DVec3> {
            let (origin, dir) = lens.ray(stroke.at(s));
            let target_t = (target - origin).dot(dir);
            let in_front = |t: f64| !lens.perspective || t > 0.0;
            let t = ray_sphere(origin, dir, p, lengths[j]).and_then(|(t0, t1)| match (in_front(t0), in_front(t1)) {
                (true, true) => Some(if (t0 - target_t).abs() <= (t1 - target_t).abs() { t0 } else { t1 }),
                (false, true) => Some(t1),
                (true, false) => Some(t0),
                (false, false) => None,
            })?;
            (origin + dir * t - p).try_normalize()
        };
        // The shares are planned with estimated reaches; where the wanted point is out of reach, the joint
        // stops where the stroke leaves the sphere's image, and later segments take over the rest.
        let (reached, segment) = match place(wanted) {
            Some(d) => (wanted, Some(d)),
            None => last_reachable(arc, wanted, &place),
        };
        let segment = segment.unwrap_or_else(|| {
            // Out of reach even at the start (the previous joint is off the stroke, or the sphere lies behind
            // the eye): keep the current direction's component along the ray, turn the rest sideways
            // towards the ray (within the plane through the eye, p and the ray, which projects onto the line
            // from p's pixel through the stroke point). A ray that only just misses (rounding) gets the
            // sphere's point nearest to it.
            let (origin, dir) = lens.ray(stroke.at(wanted));
            let to_ray = origin + dir * (p - origin).dot(dir) - p;
            let grazing = to_ray.length() <= lengths[j] * (1.0 + GRAZING);
            let along = if grazing { 0.0 } else { directions[j].dot(dir).clamp(-1.0, 1.0) };
            match to_ray.try_normalize() {
                Some(side) => (side * (1.0 - along * along).sqrt() + dir * along).normalize(),
                None => directions[j],
            }
        });
        arc = reached;
        new_x[j + 1] = p + segment * lengths[j];
    }

    // Rotations: swing each joint so its bone axis follows its new segment (the tip follows its parent's).
    let mut world_rotations = Vec::with_capacity(n);
    for j in 0..n {
        let s = j.min(n - 2);
        let new_dir = (new_x[s + 1] - new_x[s]) / lengths[s];
        let swing = DQuat::from_rotation_arc(directions[s], new_dir.normalize());
        world_rotations.push((swing * current.orientations[j].as_dquat()).normalize());
    }

    let anchor_inverse = anchor_rotation.inverse();
    let root_in_anchor = root.as_dvec3() - anchor_position;
    let anchor_joints = new_x
        .iter()
        .zip(&world_rotations)
        .map(|(p, q)| {
            let position = anchor_inverse * (root_in_anchor + *p);
            Transform::new(position.as_vec3(), (anchor_inverse * *q).normalize().as_quat())
        })
        .collect();

    let to_camera = reference_rotation.inverse() * (camera.position.as_dvec3() - reference_position);
    let view_direction = to_camera
        .try_normalize()
        .unwrap_or_else(|| (reference_rotation.inverse() * -lens.forward).normalize())
        .as_vec3();
    Ok(StrokeShape { anchor_joints, view_direction })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn share_respects_caps_and_total() {
        let s = share(10.0, &[1.0, 1.0, 2.0], &[10.0, 10.0, 10.0]);
        assert!((s[0] - 2.5).abs() < 1e-12 && (s[2] - 5.0).abs() < 1e-12);
        let s = share(10.0, &[1.0, 1.0, 8.0], &[10.0, 10.0, 4.0]);
        assert!((s[2] - 4.0).abs() < 1e-12 && (s[0] - 3.0).abs() < 1e-12 && (s[1] - 3.0).abs() < 1e-12);
        assert_eq!(share(100.0, &[1.0, 1.0], &[3.0, 4.0]), vec![3.0, 4.0]);
    }

    #[test]
    fn polyline_samples_by_arc_length() {
        let line = Polyline::new(vec![DVec2::ZERO, DVec2::new(3.0, 0.0), DVec2::new(3.0, 4.0)]);
        assert_eq!(line.length(), 7.0);
        assert_eq!(line.at(5.0), DVec2::new(3.0, 2.0));
        assert_eq!(line.at(-1.0), DVec2::ZERO);
        assert_eq!(line.at(9.0), DVec2::new(3.0, 4.0));
    }

    #[test]
    fn project_and_ray_agree() {
        for projection in [Projection::Perspective { vertical_fov: 0.9 }, Projection::Orthographic { half_height: 0.7 }]
        {
            let camera = StrokeCamera::look_at(
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::ZERO,
                Vec3::Y,
                projection,
                Vec2::new(640.0, 480.0),
            )
            .unwrap();
            let p = Vec3::new(0.2, -0.1, 0.3);
            let pixel = camera.project(p).unwrap();
            let (origin, dir) = camera.ray(pixel).unwrap();
            let closest = origin + dir * (p - origin).dot(dir);
            assert!((closest - p).length() < 1e-5, "{projection:?}");
            // The target projects to the centre; screen y grows downwards.
            assert!((camera.project(Vec3::ZERO).unwrap() - Vec2::new(320.0, 240.0)).length() < 1e-3);
            assert!(camera.project(Vec3::new(0.0, 0.1, 0.0)).unwrap().y < 240.0);
        }
    }
}
