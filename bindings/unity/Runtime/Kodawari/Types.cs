// Copied from bindings/csharp/Kodawari/Types.cs by `cargo gen-bindings`. Edit the original: a test fails when this copy is stale.
using System;
using System.Runtime.InteropServices;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>A 3D vector: the layout of <c>kdw_vec3</c> and of Unity's <c>Vector3</c> (12 bytes).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Vec3 : IEquatable<Vec3>
    {
        public float X;
        public float Y;
        public float Z;

        public Vec3(float x, float y, float z)
        {
            X = x;
            Y = y;
            Z = z;
        }

        public bool Equals(Vec3 other) { return X == other.X && Y == other.Y && Z == other.Z; }
        public override bool Equals(object obj) { return obj is Vec3 && Equals((Vec3)obj); }
        public override int GetHashCode() { return X.GetHashCode() ^ (Y.GetHashCode() << 2) ^ (Z.GetHashCode() >> 2); }
        public override string ToString() { return "(" + X + ", " + Y + ", " + Z + ")"; }
    }

    /// <summary>A rotation quaternion (x, y, z, w): the layout of <c>kdw_quat</c> and of Unity's <c>Quaternion</c>
    /// (16 bytes). Need not be unit; a null quaternion is rejected by the engine.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Quat : IEquatable<Quat>
    {
        public float X;
        public float Y;
        public float Z;
        public float W;

        public Quat(float x, float y, float z, float w)
        {
            X = x;
            Y = y;
            Z = z;
            W = w;
        }

        public static Quat Identity { get { return new Quat(0f, 0f, 0f, 1f); } }

        public bool Equals(Quat other) { return X == other.X && Y == other.Y && Z == other.Z && W == other.W; }
        public override bool Equals(object obj) { return obj is Quat && Equals((Quat)obj); }
        public override int GetHashCode() { return X.GetHashCode() ^ (Y.GetHashCode() << 2) ^ (Z.GetHashCode() >> 2) ^ (W.GetHashCode() >> 1); }
        public override string ToString() { return "(" + X + ", " + Y + ", " + Z + ", " + W + ")"; }
    }

    /// <summary>Position + rotation: the layout of <c>kdw_transform</c>, a Unity <c>Vector3</c> followed by a
    /// <c>Quaternion</c> (28 bytes). Named so it does not collide with <c>UnityEngine.Transform</c>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct JointTransform : IEquatable<JointTransform>
    {
        public Vec3 Position;
        public Quat Rotation;

        public JointTransform(Vec3 position, Quat rotation)
        {
            Position = position;
            Rotation = rotation;
        }

        public JointTransform(float x, float y, float z)
        {
            Position = new Vec3(x, y, z);
            Rotation = Quat.Identity;
        }

        public bool Equals(JointTransform other) { return Position.Equals(other.Position) && Rotation.Equals(other.Rotation); }
        public override bool Equals(object obj) { return obj is JointTransform && Equals((JointTransform)obj); }
        public override int GetHashCode() { return Position.GetHashCode() ^ (Rotation.GetHashCode() << 1); }
        public override string ToString() { return "{" + Position + ", " + Rotation + "}"; }
    }

    /// <summary>The status codes of the C API (<c>KDW_STATUS_*</c>). A value the library may add later is still
    /// representable: it is an <c>int</c> underneath.</summary>
    public enum KodawariStatus
    {
        Ok = NativeMethods.KDW_STATUS_OK,
        NullPointer = NativeMethods.KDW_STATUS_NULL_POINTER,
        InvalidId = NativeMethods.KDW_STATUS_INVALID_ID,
        InvalidArgument = NativeMethods.KDW_STATUS_INVALID_ARGUMENT,
        BufferTooSmall = NativeMethods.KDW_STATUS_BUFFER_TOO_SMALL,
        CapacityExceeded = NativeMethods.KDW_STATUS_CAPACITY_EXCEEDED,
        StructSizeMismatch = NativeMethods.KDW_STATUS_STRUCT_SIZE_MISMATCH,
        /// <summary>The loaded library's ABI differs from these bindings' (reported by the bindings, never by the library).</summary>
        AbiMismatch = NativeMethods.KDW_STATUS_ABI_MISMATCH,
        Panic = NativeMethods.KDW_STATUS_PANIC,
    }

    /// <summary>Where a chain's anchor (the kinematic bone it hangs from) comes from.</summary>
    public enum AnchorSource : uint
    {
        /// <summary>The view reference joint K given with each <see cref="Engine.Step(float, Vec3, JointTransform)"/>.</summary>
        ViewReference = NativeMethods.KDW_ANCHOR_VIEW_REFERENCE,
        /// <summary>The chain's own entry in <see cref="Engine.SetAnchors(ReadOnlySpan{JointTransform})"/>.</summary>
        Own = NativeMethods.KDW_ANCHOR_OWN,
    }

    /// <summary>What a teleport (an anchor jump beyond the engine's thresholds, or <see cref="Engine.Teleport"/>) does to
    /// a chain.</summary>
    public enum TeleportMode : uint
    {
        /// <summary>Moves the chain rigidly with its anchor, keeping its shape and adding no energy.</summary>
        CarryShape = NativeMethods.KDW_TELEPORT_CARRY_SHAPE,
        /// <summary>Puts the chain back to its rest shape under the new anchor, at rest.</summary>
        Reset = NativeMethods.KDW_TELEPORT_RESET,
    }

    /// <summary>Which solver steps an engine's chains (<c>KDW_SOLVER_*</c>, <see cref="Engine.Solver"/>).
    /// They agree up to float rounding; a chain's bits never depend on its lane, its group or the kernel copy.</summary>
    public enum Solver : uint
    {
        /// <summary>Chains of equal joint count side by side in SIMD lanes (the default; contacts lane by lane). The
        /// last 1 or 2 chains of a joint count after its groups of 16 or 8 (too few for a group) take the scalar solver.</summary>
        Lanes = NativeMethods.KDW_SOLVER_LANES,
        /// <summary><see cref="Lanes"/> with the portable kernel copy whatever the CPU has: the same bits, slower (for
        /// determinism checks).</summary>
        LanesPortable = NativeMethods.KDW_SOLVER_LANES_PORTABLE,
        /// <summary>One chain at a time: the reference implementation.</summary>
        Scalar = NativeMethods.KDW_SOLVER_SCALAR,
    }

    /// <summary>The shape of a <see cref="Collider"/> (<c>KDW_COLLIDER_*</c>).</summary>
    public enum ColliderShape : uint
    {
        /// <summary>Keeps particles outside a ball of <see cref="ColliderDef.Radius"/>.</summary>
        Sphere = NativeMethods.KDW_COLLIDER_SPHERE,
        /// <summary>Keeps particles outside a capsule along the collider's local Y axis.</summary>
        Capsule = NativeMethods.KDW_COLLIDER_CAPSULE,
        /// <summary>Keeps particles on the local +Y side of the plane through the collider's origin.</summary>
        Plane = NativeMethods.KDW_COLLIDER_PLANE,
        /// <summary>Keeps particles inside a ball (radius &gt; 0).</summary>
        InsideSphere = NativeMethods.KDW_COLLIDER_INSIDE_SPHERE,
        /// <summary>Keeps particles inside a capsule (radius &gt; 0).</summary>
        InsideCapsule = NativeMethods.KDW_COLLIDER_INSIDE_CAPSULE,
    }

    /// <summary>Counters for profiling overlays (<c>kdw_engine_stats</c>).</summary>
    public struct EngineStats
    {
        public int ChainCount;
        public int JointCount;
        /// <summary>Internal steps run by the last step.</summary>
        public int SubstepsLastStep;
        /// <summary>Chains that cost nothing in the last step (sleeping or disabled).</summary>
        public int ChainsAsleep;
        /// <summary>Chains the lane solver stepped in the last step; the others ran on the scalar solver or were asleep
        /// or disabled. 0 on <see cref="Solver.Scalar"/>.</summary>
        public int LaneChains;
        public long SubstepsTotal;
        /// <summary>Internal steps where the direct inextensibility solve failed (or was skipped for a chain whose first solves keep failing it) and a fallback ran.</summary>
        public long SolverFallbacks;
        /// <summary>Simulated seconds dropped because a step needed more than MaxSubsteps.</summary>
        public double TimeDropped;
        /// <summary>Simulated seconds advanced in total.</summary>
        public double SimulatedTime;
        public int ColliderCount;
        /// <summary>(segment or particle, collider) pairs the contact pass tested in total.</summary>
        public long ContactPairsTested;
    }
}
