using System;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>Engine settings. A new instance holds the library's defaults (<c>kdw_engine_def_default()</c>),
    /// so a default can never be forgotten: <c>new EngineDef { SubstepRate = 120f }</c>.</summary>
    public sealed class EngineDef
    {
        internal kdw_engine_def Raw;

        public EngineDef()
        {
            Library.EnsureCompatible();
            Raw = NativeMethods.kdw_engine_def_default();
        }

        internal EngineDef(kdw_engine_def raw) { Raw = raw; }

        /// <summary>World gravity, m/s². Default (0, -9.81, 0).</summary>
        public Vec3 Gravity
        {
            get { return new Vec3(Raw.gravity.x, Raw.gravity.y, Raw.gravity.z); }
            set { Raw.gravity.x = value.X; Raw.gravity.y = value.Y; Raw.gravity.z = value.Z; }
        }

        /// <summary>Internal fixed steps per simulated second, Hz, in [30, 10000]. Default 240.</summary>
        public float SubstepRate { get { return Raw.substep_rate; } set { Raw.substep_rate = value; } }

        /// <summary>Most internal steps per step call, in [1, 1000]; time beyond is dropped and counted. Default 16.</summary>
        public int MaxSubsteps { get { return (int)Raw.max_substeps; } set { Raw.max_substeps = (uint)value; } }

        /// <summary>Shape-matching + inextensibility passes per internal step, in [1, 64]. Default 2.</summary>
        public int Iterations { get { return (int)Raw.iterations; } set { Raw.iterations = (uint)value; } }

        /// <summary>Simulated seconds per second of dt, in [0, 100]; 0 pauses. Default 1.</summary>
        public float TimeScale { get { return Raw.time_scale; } set { Raw.time_scale = value; } }

        /// <summary>An anchor moving farther than this (character units, x <see cref="Scale"/> m) in one step is a
        /// teleport. <c>float.MaxValue</c> disables. Default 1.</summary>
        public float TeleportDistance { get { return Raw.teleport_distance; } set { Raw.teleport_distance = value; } }

        /// <summary>An anchor turning more than this (radians) in one step is a teleport. Default pi/2.</summary>
        public float TeleportAngle { get { return Raw.teleport_angle; } set { Raw.teleport_angle = value; } }

        /// <summary>What a teleport does to a chain. Default <see cref="Kodawari.TeleportMode.CarryShape"/>.</summary>
        public TeleportMode TeleportMode { get { return (TeleportMode)Raw.teleport_mode; } set { Raw.teleport_mode = (uint)value; } }

        /// <summary>A chain whose joints all move slower than this relative to its root (character units/s, x
        /// <see cref="Scale"/>) for 0.5 s, under a still anchor, rest shape and nearby colliders, sleeps (costs almost
        /// nothing) until one of them changes. In [0, 1e6]; 0 never sleeps. Default 5e-6.</summary>
        public float SleepSpeed { get { return Raw.sleep_speed; } set { Raw.sleep_speed = value; } }

        /// <summary>Level of detail for distant characters, in [0, 3]: each level halves the internal step rate (not
        /// below 30 Hz) and the iterations (not below 1). Default 0.</summary>
        public int Lod { get { return (int)Raw.lod; } set { Raw.lod = unchecked((uint)value); } }

        /// <summary>Size of the character relative to the units its parameters are tuned in, in [1e-6, 1e6]: multiplies
        /// gravity, the teleport distance and chain/joint radii (a character scaled by 100 with scale 100 moves like the
        /// unscaled one). Transforms and collider sizes stay world units. Default 1.</summary>
        public float Scale { get { return Raw.scale; } set { Raw.scale = value; } }
    }

    /// <summary>Chain parameters. A new instance holds the library's defaults (<c>kdw_chain_def_default()</c>).</summary>
    public sealed class ChainDef
    {
        internal kdw_chain_def Raw;

        public ChainDef()
        {
            Library.EnsureCompatible();
            Raw = NativeMethods.kdw_chain_def_default();
        }

        internal ChainDef(kdw_chain_def raw) { Raw = raw; }

        /// <summary>Pull towards the rest shape in [0, 1]: 0 limp, 1 rigid. Default 0.5.</summary>
        public float Stiffness { get { return Raw.stiffness; } set { Raw.stiffness = value; } }

        /// <summary>Velocity damping per second, 1/s, in [0, 1000]. Default 1.</summary>
        public float Damping { get { return Raw.damping; } set { Raw.damping = value; } }

        /// <summary>Share of the motion caused by a changing rest shape that is not turned into velocity, [0, 1].
        /// Default 1.</summary>
        public float MomentumSuppression { get { return Raw.momentum_suppression; } set { Raw.momentum_suppression = value; } }

        /// <summary>Mass per particle, kg, &gt; 0. Default 1.</summary>
        public float Mass { get { return Raw.mass; } set { Raw.mass = value; } }

        /// <summary>Particle radius in character units (x the engine's scale m), in [0, 1e6]: every joint's collision
        /// radius unless <see cref="ViewDependentPhysicalObject.SetJointRadii"/> set them. Default 0.02.</summary>
        public float Radius { get { return Raw.radius; } set { Raw.radius = value; } }

        /// <summary>Multiplier on the engine's gravity, in [-100, 100]. Default 1.</summary>
        public float GravityScale { get { return Raw.gravity_scale; } set { Raw.gravity_scale = value; } }

        /// <summary>Where the chain's anchor comes from. Default <see cref="AnchorSource.ViewReference"/>.</summary>
        public AnchorSource Anchor { get { return (AnchorSource)Raw.anchor; } set { Raw.anchor = (uint)value; } }

        /// <summary>Collision layers the chain collides with: a collider whose <see cref="ColliderDef.Layers"/> share a
        /// bit. 0: no collisions and no collision cost. Default all layers (0xFFFFFFFF).</summary>
        public uint CollisionMask { get { return Raw.collision_mask; } set { Raw.collision_mask = value; } }

        /// <summary>Coulomb friction against colliders, in [0, 10]. Default 0.3.</summary>
        public float Friction { get { return Raw.friction; } set { Raw.friction = value; } }
    }

    /// <summary>A collider's shape, size, initial pose and layers. A new instance holds the library's defaults
    /// (<c>kdw_collider_def_default()</c>: a 0.1 m sphere at the origin on layer 1). Sizes and poses are world units.</summary>
    public sealed class ColliderDef
    {
        internal kdw_collider_def Raw;

        public ColliderDef()
        {
            Library.EnsureCompatible();
            Raw = NativeMethods.kdw_collider_def_default();
        }

        /// <summary>A sphere of <paramref name="radius"/> at <paramref name="pose"/>.</summary>
        public static ColliderDef Sphere(float radius, JointTransform pose)
        {
            return new ColliderDef { Shape = ColliderShape.Sphere, Radius = radius, Transform = pose };
        }

        /// <summary>A capsule: <paramref name="radius"/> around the segment from -<paramref name="halfHeight"/> to
        /// +<paramref name="halfHeight"/> on <paramref name="pose"/>'s local Y axis.</summary>
        public static ColliderDef Capsule(float radius, float halfHeight, JointTransform pose)
        {
            return new ColliderDef { Shape = ColliderShape.Capsule, Radius = radius, HalfHeight = halfHeight, Transform = pose };
        }

        /// <summary>The shape. Default <see cref="ColliderShape.Sphere"/>.</summary>
        public ColliderShape Shape { get { return (ColliderShape)Raw.shape; } set { Raw.shape = (uint)value; } }

        /// <summary>Sphere and capsule radius, m, in [0, 1e6]; &gt; 0 for inside shapes. Default 0.1.</summary>
        public float Radius { get { return Raw.radius; } set { Raw.radius = value; } }

        /// <summary>Capsule half length of the axis, m, in [0, 1e6]. Default 0.</summary>
        public float HalfHeight { get { return Raw.half_height; } set { Raw.half_height = value; } }

        /// <summary>Initial world pose; <see cref="Engine.SetColliderTransforms(ReadOnlySpan{JointTransform})"/> moves it.</summary>
        public unsafe JointTransform Transform
        {
            get { kdw_transform t = Raw.transform; return *(JointTransform*)&t; }
            set { Raw.transform = *(kdw_transform*)&value; }
        }

        /// <summary>Layers the collider is on: it affects chains whose collision mask shares a bit. Default 1.</summary>
        public uint Layers { get { return Raw.layers; } set { Raw.layers = value; } }
    }
}
