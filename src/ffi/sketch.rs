//! `kdw_shape_from_stroke`: the sketch tool as a pure function (no engine): one screen-space stroke seen
//! from a camera becomes a chain shape, ready for `kdw_chain_add_view_shape`.

use glam::{Vec2, Vec3};

use super::chain::joints_from;
use super::guard::{check_out, check_struct_size, guard, read, slice, slice_mut, write};
use super::status::{FfiError, FfiResult, KDW_STATUS_BUFFER_TOO_SMALL, KDW_STATUS_INVALID_ARGUMENT, kdw_status};
use super::types::{kdw_quat, kdw_transform, kdw_vec3};
use crate::core::sketch::{ForwardAxis, Projection, StrokeCamera, StrokeInput, shape_from_stroke};

/// A 2D point, e.g. a pixel position: the layout of Unity's `Vector2`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct kdw_vec2 {
    pub x: f32,
    pub y: f32,
}

impl From<kdw_vec2> for Vec2 {
    fn from(v: kdw_vec2) -> Self {
        Vec2::new(v.x, v.y)
    }
}

impl From<Vec2> for kdw_vec2 {
    fn from(v: Vec2) -> Self {
        Self { x: v.x, y: v.y }
    }
}

/// `kdw_stroke_camera.projection`: a pinhole camera; `vertical_fov` is used.
pub const KDW_PROJECTION_PERSPECTIVE: u32 = 0;
/// `kdw_stroke_camera.projection`: a parallel projection; `orthographic_half_height` is used.
pub const KDW_PROJECTION_ORTHOGRAPHIC: u32 = 1;

/// `kdw_stroke_camera.forward_axis`: the camera looks along its local -Z (right-handed, Y up: OpenGL, glTF,
/// Blender, Godot).
pub const KDW_CAMERA_FORWARD_NEGATIVE_Z: u32 = 0;
/// `kdw_stroke_camera.forward_axis`: the camera looks along its local +Z (Unity: pass
/// `Camera.transform.position` and `.rotation` unchanged).
pub const KDW_CAMERA_FORWARD_POSITIVE_Z: u32 = 1;

/// The camera a stroke was drawn in; obtain defaults from `kdw_stroke_camera_default()`.
///
/// Screen right is `rotation * (1, 0, 0)`, screen up `rotation * (0, 1, 0)`, and the camera looks along
/// `rotation * (0, 0, -1)` or `rotation * (0, 0, 1)` (`forward_axis`). Pixels have their origin at the
/// viewport's top-left corner, x right, y **down**; pixels are square (the aspect ratio follows from the
/// viewport size).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct kdw_stroke_camera {
    /// `sizeof(kdw_stroke_camera)`.
    pub struct_size: u32,
    /// World position: the eye of a perspective camera, the centre of an orthographic one. Default origin.
    pub position: kdw_vec3,
    /// World rotation (need not be unit). Default identity.
    pub rotation: kdw_quat,
    /// `KDW_PROJECTION_PERSPECTIVE` (default) or `KDW_PROJECTION_ORTHOGRAPHIC`.
    pub projection: u32,
    /// `KDW_CAMERA_FORWARD_NEGATIVE_Z` (default) or `KDW_CAMERA_FORWARD_POSITIVE_Z`.
    pub forward_axis: u32,
    /// Vertical field of view, radians, in (0, pi) (perspective only). Default pi/3 (60°, Unity's default).
    pub vertical_fov: f32,
    /// Half the viewport's height in metres, > 0 (orthographic only; Unity's `orthographicSize`). Default 5.
    pub orthographic_half_height: f32,
    /// Viewport width in pixels, > 0. Default 1920.
    pub viewport_width: f32,
    /// Viewport height in pixels, > 0. Default 1080.
    pub viewport_height: f32,
}

impl TryFrom<&kdw_stroke_camera> for StrokeCamera {
    type Error = FfiError;
    fn try_from(c: &kdw_stroke_camera) -> FfiResult<Self> {
        check_struct_size::<kdw_stroke_camera>(c.struct_size, "kdw_stroke_camera")?;
        let invalid = |message: String| FfiError::new(KDW_STATUS_INVALID_ARGUMENT, message);
        let projection = match c.projection {
            KDW_PROJECTION_PERSPECTIVE => Projection::Perspective { vertical_fov: c.vertical_fov },
            KDW_PROJECTION_ORTHOGRAPHIC => Projection::Orthographic { half_height: c.orthographic_half_height },
            other => return Err(invalid(format!("unknown camera projection {other}"))),
        };
        let forward_axis = match c.forward_axis {
            KDW_CAMERA_FORWARD_NEGATIVE_Z => ForwardAxis::NegativeZ,
            KDW_CAMERA_FORWARD_POSITIVE_Z => ForwardAxis::PositiveZ,
            other => return Err(invalid(format!("unknown camera forward axis {other}"))),
        };
        let camera = StrokeCamera {
            position: c.position.into(),
            rotation: c.rotation.into(),
            forward_axis,
            projection,
            viewport: Vec2::new(c.viewport_width, c.viewport_height),
        };
        camera.validate()?;
        Ok(camera)
    }
}

/// Default stroke camera: at the origin, identity rotation (looking along -Z), perspective with a 60°
/// vertical field of view, 1920 x 1080 pixels (orthographic half-height 5 m if switched to orthographic).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_stroke_camera_default() -> kdw_stroke_camera {
    kdw_stroke_camera {
        struct_size: size_of::<kdw_stroke_camera>() as u32,
        position: kdw_vec3::default(),
        rotation: kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
        projection: KDW_PROJECTION_PERSPECTIVE,
        forward_axis: KDW_CAMERA_FORWARD_NEGATIVE_Z,
        vertical_fov: std::f32::consts::FRAC_PI_3,
        orthographic_half_height: 5.0,
        viewport_width: 1920.0,
        viewport_height: 1080.0,
    }
}

/// Projects a world point to pixels (origin top-left, y down), e.g. to draw a chain under the stroke.
/// `KDW_STATUS_INVALID_ARGUMENT` for a point on or behind the plane of a perspective camera's eye.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_stroke_camera_project(
    camera: *const kdw_stroke_camera,
    point: *const kdw_vec3,
    out_pixel: *mut kdw_vec2,
) -> kdw_status {
    guard(|| {
        check_out(out_pixel, "out_pixel")?;
        // SAFETY: the caller passes a readable kdw_stroke_camera.
        let camera = StrokeCamera::try_from(unsafe { read(camera, "camera") }?)?;
        // SAFETY: the caller passes a readable kdw_vec3.
        let point = Vec3::from(*unsafe { read(point, "point") }?);
        if !point.is_finite() {
            return Err(FfiError::new(KDW_STATUS_INVALID_ARGUMENT, "point is not finite"));
        }
        let pixel = camera.project(point).ok_or_else(|| {
            FfiError::new(KDW_STATUS_INVALID_ARGUMENT, "the point is on or behind the plane of the camera's eye")
        })?;
        // SAFETY: checked by check_out.
        unsafe { write(out_pixel, pixel.into()) };
        Ok(())
    })
}

/// The sketch tool: a new shape for a chain whose projection through `camera` follows a stroke.
///
/// Inputs, all world space: the chain as it is now (`current_world_joints`, `joint_count >= 2`, root first),
/// its anchor bone (`anchor_world`: the frame of the result), the view reference joint K
/// (`view_reference_world`), and the stroke (`stroke_pixels`, root to tip, pixels with the origin top-left
/// and y down, at least 2 distinct points; consecutive duplicates are ignored).
///
/// Writes `joint_count` transforms in the anchor frame to `out_anchor_joints` (`capacity >= joint_count`,
/// else `KDW_STATUS_BUFFER_TOO_SMALL`) and the unit direction from K to the camera in K's frame to
/// `*out_view_direction`: pass both to `kdw_chain_add_view_shape`. The result keeps the root's position and
/// every segment length; the stroke is translated so it starts at the projected root. Arc length along the
/// stroke places the joints (shared by the segments in proportion to their current projected lengths);
/// each joint lies on the ray through its stroke point, at the depth nearest to the current shape's where
/// the ray allows two. A stroke longer than the chain can reach is followed from its start as far as the
/// chain reaches. Rotations are swung to the new segments, keeping their twist.
///
/// `KDW_STATUS_INVALID_ARGUMENT`: fewer than 2 distinct stroke points, fewer than 2 joints, a zero-length
/// segment, a non-finite value or null rotation, an invalid camera, or a root behind a perspective camera.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn kdw_shape_from_stroke(
    camera: *const kdw_stroke_camera,
    current_world_joints: *const kdw_transform,
    joint_count: u32,
    anchor_world: *const kdw_transform,
    view_reference_world: *const kdw_transform,
    stroke_pixels: *const kdw_vec2,
    point_count: u32,
    out_anchor_joints: *mut kdw_transform,
    capacity: u32,
    out_view_direction: *mut kdw_vec3,
) -> kdw_status {
    guard(|| {
        check_out(out_view_direction, "out_view_direction")?;
        // SAFETY: the caller passes `capacity` writable transforms at `out_anchor_joints`.
        let out = unsafe { slice_mut(out_anchor_joints, capacity, "out_anchor_joints") }?;
        if capacity < joint_count {
            return Err(FfiError::new(
                KDW_STATUS_BUFFER_TOO_SMALL,
                format!("out_anchor_joints holds {capacity} transforms, the chain has {joint_count}"),
            ));
        }
        // SAFETY: the caller passes a readable kdw_stroke_camera.
        let camera = StrokeCamera::try_from(unsafe { read(camera, "camera") }?)?;
        // SAFETY: the caller passes `joint_count` readable transforms.
        let joints = joints_from(unsafe { slice(current_world_joints, joint_count, "current_world_joints") }?);
        // SAFETY: the caller passes readable transforms.
        let anchor = unsafe { read(anchor_world, "anchor_world") }?;
        // SAFETY: as above.
        let reference = unsafe { read(view_reference_world, "view_reference_world") }?;
        // SAFETY: the caller passes `point_count` readable points.
        let points = unsafe { slice(stroke_pixels, point_count, "stroke_pixels") }?;
        let stroke: Vec<Vec2> = points.iter().map(|p| (*p).into()).collect();
        let shape = shape_from_stroke(&StrokeInput {
            camera,
            current_world_joints: &joints,
            anchor_world: (*anchor).into(),
            view_reference_world: (*reference).into(),
            stroke_pixels: &stroke,
        })?;
        for (slot, joint) in out.iter_mut().zip(&shape.anchor_joints) {
            *slot = (*joint).into();
        }
        // SAFETY: checked by check_out.
        unsafe { write(out_view_direction, shape.view_direction.into()) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_struct_is_padding_free() {
        assert_eq!(size_of::<kdw_vec2>(), 8);
        assert_eq!(size_of::<kdw_stroke_camera>(), 4 + 12 + 16 + 2 * 4 + 4 * 4);
    }

    #[test]
    fn default_camera_is_valid() {
        let c = kdw_stroke_camera_default();
        assert!(StrokeCamera::try_from(&c).is_ok());
    }
}
