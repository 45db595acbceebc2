using System;
using UnityEngine;

namespace Kodawari.Unity
{
    /// <summary>A kodawari collider attached to a bone, described the way Unity's <c>SphereCollider</c> and
    /// <c>CapsuleCollider</c> are (a centre and sizes in the bone's local space, a capsule axis). The
    /// <see cref="Engine"/> creates it when it builds and moves it with the bone every frame. Sizes are multiplied by the
    /// bone's largest lossy scale component, and follow it when the bone's scale changes.</summary>
    [Serializable]
    public class BoneCollider
    {
        [Tooltip("The bone the collider moves with.")]
        public Transform bone;

        [Tooltip("Sphere, capsule, plane (solid below the local up axis), or inside sphere / capsule (keeps chains in).")]
        public ColliderShape shape = ColliderShape.Sphere;

        [Tooltip("Centre in the bone's local space.")]
        public Vector3 center = Vector3.zero;

        [Tooltip("Radius in the bone's local space (times the bone's largest lossy scale component).")]
        public float radius = 0.05f;

        [Tooltip("Capsules: total height in the bone's local space, tips included, like CapsuleCollider.height.")]
        public float height = 0f;

        [Tooltip("Capsule axis and plane normal in the bone's space: 0 = X, 1 = Y, 2 = Z, like CapsuleCollider.direction.")]
        [Range(0, 2)] public int direction = 1;

        [Tooltip("Layer bits: chains whose collision mask shares a bit collide with it.")]
        public int layers = 1;

        // Rotations taking the kodawari collider's local Y (its capsule axis) onto the bone's X, Y or Z axis.
        static readonly Quaternion YToX = new Quaternion(0f, 0f, -0.70710678f, 0.70710678f);
        static readonly Quaternion YToZ = new Quaternion(0.70710678f, 0f, 0f, 0.70710678f);

        /// <summary>The entry for a Unity <c>SphereCollider</c>: same bone, centre and radius; on the layer bit of its
        /// GameObject's Unity layer.</summary>
        public static BoneCollider From(SphereCollider source)
        {
            return new BoneCollider
            {
                bone = source.transform,
                shape = ColliderShape.Sphere,
                center = source.center,
                radius = source.radius,
                layers = 1 << source.gameObject.layer,
            };
        }

        /// <summary>The entry for a Unity <c>CapsuleCollider</c>: same bone, centre, radius, height and axis.</summary>
        public static BoneCollider From(CapsuleCollider source)
        {
            return new BoneCollider
            {
                bone = source.transform,
                shape = ColliderShape.Capsule,
                center = source.center,
                radius = source.radius,
                height = source.height,
                direction = source.direction,
                layers = 1 << source.gameObject.layer,
            };
        }

        /// <summary>The native collider description at the bone's current pose and scale: radius times the largest
        /// lossy scale component; a capsule's half height is what lies between its two hemispheres,
        /// <c>max(0, height / 2 - radius)</c>.</summary>
        public ColliderDef CreateDef()
        {
            Vector3 lossy = bone.lossyScale;
            float scale = Mathf.Max(Mathf.Abs(lossy.x), Mathf.Max(Mathf.Abs(lossy.y), Mathf.Abs(lossy.z)));
            var def = new ColliderDef
            {
                Shape = shape,
                Radius = Mathf.Max(radius, 0f) * scale,
                HalfHeight = Mathf.Max(0f, 0.5f * height - radius) * scale,
                Transform = WorldPose(),
                Layers = unchecked((uint)layers),
            };
            return def;
        }

        /// <summary>The world radius and half height for a bone of lossy scale <paramref name="lossy"/> (as
        /// <see cref="CreateDef"/>); false when the native engine would reject them (not finite, an inside shape without
        /// a radius, a capsule of size 0), so the collider keeps its last size. Allocation-free.</summary>
        public bool SizeAt(Vector3 lossy, out float worldRadius, out float worldHalfHeight)
        {
            float scale = Mathf.Max(Mathf.Abs(lossy.x), Mathf.Max(Mathf.Abs(lossy.y), Mathf.Abs(lossy.z)));
            worldRadius = Mathf.Max(radius, 0f) * scale;
            worldHalfHeight = Mathf.Max(0f, 0.5f * height - radius) * scale;
            if (float.IsNaN(worldRadius) || float.IsInfinity(worldRadius) || float.IsNaN(worldHalfHeight)
                || float.IsInfinity(worldHalfHeight) || worldRadius > 1e6f || worldHalfHeight > 1e6f)
                return false;
            if ((shape == ColliderShape.InsideSphere || shape == ColliderShape.InsideCapsule) && worldRadius <= 0f) return false;
            if (shape == ColliderShape.Capsule && worldRadius <= 0f && worldHalfHeight <= 0f) return false;
            return true;
        }

        /// <summary>The collider's world pose: the bone's transform of <see cref="center"/>, rotated so that the
        /// kodawari collider's local Y lies along the bone's <see cref="direction"/> axis. Allocation-free.</summary>
        public JointTransform WorldPose()
        {
            Quaternion axis = direction == 0 ? YToX : direction == 2 ? YToZ : Quaternion.identity;
            return new JointTransform(bone.TransformPoint(center).ToKodawari(), (bone.rotation * axis).ToKodawari());
        }
    }
}
