// Copied from bindings/csharp/Kodawari/Sketch.cs by `cargo gen-bindings`. Edit the original: a test fails when this copy is stale.
using System;
using System.Runtime.InteropServices;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>A 2D point, e.g. a pixel position: the layout of <c>kdw_vec2</c> and of Unity's <c>Vector2</c>
    /// (8 bytes).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Vec2 : IEquatable<Vec2>
    {
        public float X;
        public float Y;

        public Vec2(float x, float y)
        {
            X = x;
            Y = y;
        }

        public bool Equals(Vec2 other) { return X == other.X && Y == other.Y; }
        public override bool Equals(object obj) { return obj is Vec2 && Equals((Vec2)obj); }
        public override int GetHashCode() { return X.GetHashCode() ^ (Y.GetHashCode() << 2); }
        public override string ToString() { return "(" + X + ", " + Y + ")"; }
    }

    /// <summary>How a <see cref="StrokeCamera"/> maps depth to the screen (<c>KDW_PROJECTION_*</c>).</summary>
    public enum StrokeProjection : uint
    {
        /// <summary>A pinhole camera; <see cref="StrokeCamera.VerticalFov"/> is used.</summary>
        Perspective = NativeMethods.KDW_PROJECTION_PERSPECTIVE,
        /// <summary>A parallel projection; <see cref="StrokeCamera.OrthographicHalfHeight"/> is used.</summary>
        Orthographic = NativeMethods.KDW_PROJECTION_ORTHOGRAPHIC,
    }

    /// <summary>Which local axis a <see cref="StrokeCamera"/> looks along (<c>KDW_CAMERA_FORWARD_*</c>). Screen
    /// right is always local +X and screen up local +Y.</summary>
    public enum CameraForwardAxis : uint
    {
        /// <summary>Local -Z: right-handed cameras (OpenGL, glTF, Blender, Godot). The default.</summary>
        NegativeZ = NativeMethods.KDW_CAMERA_FORWARD_NEGATIVE_Z,
        /// <summary>Local +Z: Unity's camera, with <c>Camera.transform.position</c> and <c>.rotation</c> passed
        /// unchanged.</summary>
        PositiveZ = NativeMethods.KDW_CAMERA_FORWARD_POSITIVE_Z,
    }

    /// <summary>The camera a stroke was drawn in (<c>kdw_stroke_camera</c>). A new instance holds the library's
    /// defaults (<c>kdw_stroke_camera_default()</c>): at the origin, identity rotation looking along -Z,
    /// perspective with a 60° vertical field of view, 1920 x 1080 pixels, orthographic half-height 5 m.
    /// Pixels have their origin at the viewport's top-left corner, x right, y <b>down</b>; pixels are square.
    /// For a Unity camera use <see cref="FromUnityStyle"/> / <see cref="FromUnityStyleOrthographic"/>.</summary>
    public sealed class StrokeCamera
    {
        internal kdw_stroke_camera Raw;

        public StrokeCamera()
        {
            Library.EnsureCompatible();
            Raw = NativeMethods.kdw_stroke_camera_default();
        }

        /// <summary>A perspective camera given the way Unity gives it: <c>Camera.transform.position</c> and
        /// <c>.rotation</c> unchanged (it looks along local +Z, <see cref="CameraForwardAxis.PositiveZ"/>), the
        /// vertical field of view in <b>radians</b> (<c>Camera.fieldOfView * Mathf.Deg2Rad</c>) and the viewport in
        /// pixels (<c>Camera.pixelWidth</c>, <c>.pixelHeight</c>).</summary>
        public static StrokeCamera FromUnityStyle(Vec3 position, Quat rotation, float verticalFovRadians,
                                                  float viewportWidth, float viewportHeight)
        {
            return new StrokeCamera
            {
                Position = position,
                Rotation = rotation,
                ForwardAxis = CameraForwardAxis.PositiveZ,
                Projection = StrokeProjection.Perspective,
                VerticalFov = verticalFovRadians,
                ViewportWidth = viewportWidth,
                ViewportHeight = viewportHeight,
            };
        }

        /// <summary>An orthographic camera given the way Unity gives it: position and rotation unchanged (looks
        /// along local +Z), <c>Camera.orthographicSize</c> (half the viewport's height in metres) and the viewport
        /// in pixels.</summary>
        public static StrokeCamera FromUnityStyleOrthographic(Vec3 position, Quat rotation, float orthographicSize,
                                                              float viewportWidth, float viewportHeight)
        {
            return new StrokeCamera
            {
                Position = position,
                Rotation = rotation,
                ForwardAxis = CameraForwardAxis.PositiveZ,
                Projection = StrokeProjection.Orthographic,
                OrthographicHalfHeight = orthographicSize,
                ViewportWidth = viewportWidth,
                ViewportHeight = viewportHeight,
            };
        }

        /// <summary>World position: the eye of a perspective camera, the centre of an orthographic one.</summary>
        public Vec3 Position
        {
            get { return new Vec3(Raw.position.x, Raw.position.y, Raw.position.z); }
            set { Raw.position.x = value.X; Raw.position.y = value.Y; Raw.position.z = value.Z; }
        }

        /// <summary>World rotation (need not be unit). Screen right is <c>rotation * (1, 0, 0)</c>, screen up
        /// <c>rotation * (0, 1, 0)</c>.</summary>
        public Quat Rotation
        {
            get { return new Quat(Raw.rotation.x, Raw.rotation.y, Raw.rotation.z, Raw.rotation.w); }
            set { Raw.rotation.x = value.X; Raw.rotation.y = value.Y; Raw.rotation.z = value.Z; Raw.rotation.w = value.W; }
        }

        /// <summary>Perspective (default) or orthographic.</summary>
        public StrokeProjection Projection { get { return (StrokeProjection)Raw.projection; } set { Raw.projection = (uint)value; } }

        /// <summary>The local axis the camera looks along: -Z (default) or +Z (Unity).</summary>
        public CameraForwardAxis ForwardAxis { get { return (CameraForwardAxis)Raw.forward_axis; } set { Raw.forward_axis = (uint)value; } }

        /// <summary>Vertical field of view, radians, in (0, pi) (perspective only). Default pi/3.</summary>
        public float VerticalFov { get { return Raw.vertical_fov; } set { Raw.vertical_fov = value; } }

        /// <summary>Half the viewport's height in metres, &gt; 0 (orthographic only; Unity's
        /// <c>orthographicSize</c>). Default 5.</summary>
        public float OrthographicHalfHeight { get { return Raw.orthographic_half_height; } set { Raw.orthographic_half_height = value; } }

        /// <summary>Viewport width in pixels, &gt; 0. Default 1920.</summary>
        public float ViewportWidth { get { return Raw.viewport_width; } set { Raw.viewport_width = value; } }

        /// <summary>Viewport height in pixels, &gt; 0. Default 1080.</summary>
        public float ViewportHeight { get { return Raw.viewport_height; } set { Raw.viewport_height = value; } }

        /// <summary>The pixel of a world point (origin top-left, y down). Throws <see cref="KodawariException"/>
        /// (<see cref="KodawariStatus.InvalidArgument"/>) for a point on or behind the plane of a perspective camera's
        /// eye or an invalid camera.</summary>
        public Vec2 Project(Vec3 point) { return Sketch.Project(this, point); }

        /// <summary>As <see cref="Project"/>, but returns false instead of throwing (e.g. to draw a chain that is
        /// partly behind the camera).</summary>
        public bool TryProject(Vec3 point, out Vec2 pixel) { return Sketch.TryProject(this, point, out pixel); }
    }

    /// <summary>The sketch tool (<c>kdw_shape_from_stroke</c>): a screen-space stroke drawn over a chain becomes a
    /// new shape for the chain, seen from that camera. Pure functions: no engine needed. Not per-frame code: each
    /// call is one native call, allocation-free apart from exceptions.</summary>
    public static unsafe class Sketch
    {
        /// <summary>The pixel of <paramref name="point"/> (world) through <paramref name="camera"/>: origin top-left,
        /// y down. Throws <see cref="KodawariException"/> (<see cref="KodawariStatus.InvalidArgument"/>) for a point
        /// on or behind the plane of a perspective camera's eye, or an invalid camera.</summary>
        public static Vec2 Project(StrokeCamera camera, Vec3 point)
        {
            if (camera == null) throw new ArgumentNullException("camera");
            Library.EnsureCompatible();
            kdw_stroke_camera raw = camera.Raw;
            Vec2 pixel;
            Library.Check(NativeMethods.kdw_stroke_camera_project(&raw, (kdw_vec3*)&point, (kdw_vec2*)&pixel));
            return pixel;
        }

        /// <summary>As <see cref="Project"/>, returning false instead of throwing.</summary>
        public static bool TryProject(StrokeCamera camera, Vec3 point, out Vec2 pixel)
        {
            if (camera == null) throw new ArgumentNullException("camera");
            Library.EnsureCompatible();
            kdw_stroke_camera raw = camera.Raw;
            Vec2 result;
            if (NativeMethods.kdw_stroke_camera_project(&raw, (kdw_vec3*)&point, (kdw_vec2*)&result) != NativeMethods.KDW_STATUS_OK)
            {
                pixel = default(Vec2);
                return false;
            }
            pixel = result;
            return true;
        }

        /// <summary>A new shape for a chain whose projection through <paramref name="camera"/> follows a stroke.
        /// <para>Inputs, all world space: the chain as it is now (<paramref name="currentWorldJoints"/>, at least 2,
        /// root first), its anchor bone (<paramref name="anchorWorld"/>: the frame of the result), the view reference
        /// joint K (<paramref name="viewReferenceWorld"/>), and the stroke (<paramref name="strokePixels"/>, root to
        /// tip, pixels with the origin top-left and y down, at least 2 distinct points; consecutive duplicates are
        /// ignored).</para>
        /// <para>Writes one transform per joint in the anchor frame to <paramref name="outAnchorJoints"/> (at least as
        /// long as the chain) and the unit direction from K to the camera in K's frame to
        /// <paramref name="viewDirection"/>: pass both to <see cref="ViewDependentPhysicalObject.AddViewShape"/>. The
        /// result keeps the root's position and every segment length; the stroke is moved to start at the projected
        /// root; arc length along the stroke places the joints; depth is kept from the current shape where the stroke
        /// cannot tell it; a stroke longer than the chain is followed from its start as far as the chain reaches.
        /// Rotations are swung to the new segments, keeping their twist.</para>
        /// <para>Throws <see cref="KodawariException"/>: <see cref="KodawariStatus.InvalidArgument"/> for fewer than 2
        /// distinct stroke points, fewer than 2 joints, a zero-length segment, a non-finite value or null rotation,
        /// an invalid camera, or a root behind a perspective camera; <see cref="KodawariStatus.BufferTooSmall"/> when
        /// <paramref name="outAnchorJoints"/> is shorter than the chain. Nothing is written on failure.</para></summary>
        public static void ShapeFromStroke(StrokeCamera camera, ReadOnlySpan<JointTransform> currentWorldJoints,
                                           JointTransform anchorWorld, JointTransform viewReferenceWorld,
                                           ReadOnlySpan<Vec2> strokePixels, Span<JointTransform> outAnchorJoints,
                                           out Vec3 viewDirection)
        {
            if (camera == null) throw new ArgumentNullException("camera");
            Library.EnsureCompatible();
            kdw_stroke_camera raw = camera.Raw;
            // Empty spans pin to null: give the library a valid address so it reports the count, not a null pointer.
            JointTransform noJoint;
            Vec2 noPoint;
            Vec3 direction;
            fixed (JointTransform* current = &MemoryMarshal.GetReference(currentWorldJoints))
            fixed (Vec2* stroke = &MemoryMarshal.GetReference(strokePixels))
            fixed (JointTransform* output = &MemoryMarshal.GetReference(outAnchorJoints))
            {
                Library.Check(NativeMethods.kdw_shape_from_stroke(&raw,
                    (kdw_transform*)(current != null ? current : &noJoint), Engine.Count(currentWorldJoints.Length),
                    (kdw_transform*)&anchorWorld, (kdw_transform*)&viewReferenceWorld,
                    (kdw_vec2*)(stroke != null ? stroke : &noPoint), Engine.Count(strokePixels.Length),
                    (kdw_transform*)(output != null ? output : &noJoint), Engine.Count(outAnchorJoints.Length),
                    (kdw_vec3*)&direction));
            }
            viewDirection = direction;
        }
    }
}
