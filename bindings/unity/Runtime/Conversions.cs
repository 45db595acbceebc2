using UnityEngine;

namespace Kodawari.Unity
{
    /// <summary>Unity math types to and from the kodawari layout-compatible structs (same memory layout:
    /// <c>Vector3</c> = <c>Vec3</c>, <c>Vector3</c> + <c>Quaternion</c> = <c>JointTransform</c>).</summary>
    public static class Conversions
    {
        public static Vec3 ToKodawari(this Vector3 v) { return new Vec3(v.x, v.y, v.z); }

        public static Quat ToKodawari(this Quaternion q) { return new Quat(q.x, q.y, q.z, q.w); }

        public static Vector3 ToUnity(this Vec3 v) { return new Vector3(v.X, v.Y, v.Z); }

        public static Quaternion ToUnity(this Quat q) { return new Quaternion(q.X, q.Y, q.Z, q.W); }

        public static Vec2 ToKodawari(this Vector2 v) { return new Vec2(v.x, v.y); }

        public static Vector2 ToUnity(this Vec2 v) { return new Vector2(v.X, v.Y); }

        /// <summary>The sketch tool's camera for a Unity camera: its transform's position and rotation unchanged
        /// (Unity cameras look along +Z), the vertical field of view in radians or the orthographic size, and the
        /// viewport in pixels (<c>pixelWidth</c> x <c>pixelHeight</c>). Stroke pixels are then top-left, y down:
        /// <c>(x, pixelHeight - y)</c> of Unity's bottom-left screen coordinates.</summary>
        public static StrokeCamera ToStrokeCamera(this Camera camera)
        {
            Transform t = camera.transform;
            return camera.orthographic
                ? StrokeCamera.FromUnityStyleOrthographic(t.position.ToKodawari(), t.rotation.ToKodawari(),
                                                          camera.orthographicSize, camera.pixelWidth, camera.pixelHeight)
                : StrokeCamera.FromUnityStyle(t.position.ToKodawari(), t.rotation.ToKodawari(),
                                              camera.fieldOfView * Mathf.Deg2Rad, camera.pixelWidth, camera.pixelHeight);
        }

        /// <summary>Unity screen coordinates (origin bottom-left, pixels: <c>Input.mousePosition</c>,
        /// <c>HandleUtility.GUIPointToScreenPixelCoordinate</c>) to the sketch tool's pixels (origin top-left, y
        /// down) of <paramref name="camera"/>.</summary>
        public static Vec2 ScreenToStrokePixel(this Camera camera, Vector2 screen)
        {
            return new Vec2(screen.x, camera.pixelHeight - screen.y);
        }

        /// <summary>A transform's world pose (position and rotation; scale is not part of a pose).</summary>
        public static JointTransform WorldPose(this Transform t)
        {
            return new JointTransform(t.position.ToKodawari(), t.rotation.ToKodawari());
        }

        /// <summary><paramref name="t"/>'s pose in the rigid frame of <paramref name="frame"/> (scale ignored, as the
        /// engine's anchor frames are rigid).</summary>
        public static JointTransform PoseIn(this Transform t, Transform frame)
        {
            Quaternion inverse = Quaternion.Inverse(frame.rotation);
            Vector3 position = inverse * (t.position - frame.position);
            return new JointTransform(position.ToKodawari(), (inverse * t.rotation).ToKodawari());
        }
    }
}
