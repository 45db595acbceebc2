using System;
using System.Runtime.InteropServices;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>A chain (hair strand, ear, tail): a non-owning handle, the engine plus the chain's id. Cheap to
    /// copy. Every call validates the id natively: a destroyed chain's handle throws a
    /// <see cref="KodawariException"/> with <see cref="KodawariStatus.InvalidId"/>, never undefined behaviour.</summary>
    public struct ViewDependentPhysicalObject : IEquatable<ViewDependentPhysicalObject>
    {
        readonly Engine engine;
        readonly ulong id;

        internal ViewDependentPhysicalObject(Engine engine, ulong id)
        {
            this.engine = engine;
            this.id = id;
        }

        /// <summary>The engine that owns the chain (null for a default handle).</summary>
        public Engine Engine { get { return engine; } }

        /// <summary>The native <c>kdw_chain_id</c> (0 is null).</summary>
        public ulong Id { get { return id; } }

        unsafe kdw_engine* Ptr
        {
            get
            {
                if (engine == null) throw new KodawariException(KodawariStatus.InvalidId, "null chain handle");
                return engine.Ptr;
            }
        }

        /// <summary>True if the chain is alive in a live engine.</summary>
        public unsafe bool IsValid
        {
            get
            {
                if (engine == null || engine.IsDisposed) return false;
                uint valid = 0;
                Library.Check(NativeMethods.kdw_chain_is_valid(engine.Ptr, id, &valid));
                return valid != 0;
            }
        }

        /// <summary>Destroys the chain and its view shapes; later chains keep their relative order.</summary>
        public unsafe void Destroy() { Library.Check(NativeMethods.kdw_chain_destroy(Ptr, id)); }

        /// <summary>The chain's parameters (validated as a whole on set; takes effect at the next step).</summary>
        public unsafe ChainDef Def
        {
            get
            {
                kdw_chain_def raw;
                Library.Check(NativeMethods.kdw_chain_get_def(Ptr, id, &raw));
                return new ChainDef(raw);
            }
            set
            {
                if (value == null) throw new ArgumentNullException("value");
                kdw_chain_def raw = value.Raw;
                Library.Check(NativeMethods.kdw_chain_set_def(Ptr, id, &raw));
            }
        }

        /// <summary>Number of joints.</summary>
        public unsafe int JointCount
        {
            get
            {
                uint count = 0;
                Library.Check(NativeMethods.kdw_chain_joint_count(Ptr, id, &count));
                return (int)count;
            }
        }

        /// <summary>Replaces the base shape (same joint count), e.g. for animated hair; blended in without
        /// injecting momentum.</summary>
        public unsafe void SetBaseShape(ReadOnlySpan<JointTransform> joints)
        {
            fixed (JointTransform* p = &MemoryMarshal.GetReference(joints))
                Library.Check(NativeMethods.kdw_chain_set_base_shape(Ptr, id, (kdw_transform*)p, Engine.Count(joints.Length)));
        }

        /// <summary>Puts the chain back to its current rest shape, at rest, at the next step.</summary>
        public unsafe void Reset() { Library.Check(NativeMethods.kdw_chain_reset(Ptr, id)); }

        /// <summary>Treats the anchor's motion in the next step as a teleport (the engine's
        /// <see cref="EngineDef.TeleportMode"/>), however small.</summary>
        public unsafe void Teleport() { Library.Check(NativeMethods.kdw_chain_teleport(Ptr, id)); }

        /// <summary>Whether the chain is simulated (default true). A disabled (culled) chain costs nothing: it rides
        /// rigidly with its anchor in its last pose, and enabled again carries on from there.</summary>
        public unsafe bool Enabled
        {
            get
            {
                uint enabled = 0;
                Library.Check(NativeMethods.kdw_chain_is_enabled(Ptr, id, &enabled));
                return enabled != 0;
            }
            set { Library.Check(NativeMethods.kdw_chain_set_enabled(Ptr, id, value ? 1u : 0u)); }
        }

        /// <summary>True if the chain slept through the last step: its anchor, rest shape and nearby colliders were still
        /// and its motion had died out (<see cref="EngineDef.SleepSpeed"/>).</summary>
        public unsafe bool IsAsleep
        {
            get
            {
                uint asleep = 0;
                Library.Check(NativeMethods.kdw_chain_is_asleep(Ptr, id, &asleep));
                return asleep != 0;
            }
        }

        /// <summary>Per-joint collision radii in character units (x the engine's scale m), each in [0, 1e6]: one per joint,
        /// or none (an empty span) to go back to <see cref="ChainDef.Radius"/> for every joint.</summary>
        public unsafe void SetJointRadii(ReadOnlySpan<float> radii)
        {
            float none;
            fixed (float* p = &MemoryMarshal.GetReference(radii))
                Library.Check(NativeMethods.kdw_chain_set_joint_radii(Ptr, id, p != null ? p : &none, Engine.Count(radii.Length)));
        }

        /// <summary>This chain's world transforms (root to tip). Returns how many were written.</summary>
        public unsafe int ReadWorld(Span<JointTransform> output)
        {
            uint written = 0;
            fixed (JointTransform* p = &MemoryMarshal.GetReference(output))
                Library.Check(NativeMethods.kdw_chain_read_world(Ptr, id, (kdw_transform*)p, Engine.Count(output.Length), &written));
            return (int)written;
        }

        /// <summary>The rest shape the chain is currently pulled towards (anchor frame).</summary>
        public unsafe int ReadRestShape(Span<JointTransform> output)
        {
            uint written = 0;
            fixed (JointTransform* p = &MemoryMarshal.GetReference(output))
                Library.Check(NativeMethods.kdw_chain_read_rest_shape(Ptr, id, (kdw_transform*)p, Engine.Count(output.Length), &written));
            return (int)written;
        }

        /// <summary>Kinetic energy of the dynamic joints, J.</summary>
        public unsafe float KineticEnergy
        {
            get
            {
                float energy = 0f;
                Library.Check(NativeMethods.kdw_chain_kinetic_energy(Ptr, id, &energy));
                return energy;
            }
        }

        /// <summary>Adds a view shape: seen from <paramref name="direction"/> (view reference frame, non-zero) the rest
        /// shape becomes <paramref name="joints"/> (anchor frame, one per joint; only bends and orientations are
        /// used). <paramref name="influence"/> &gt; 0 narrows (large) or widens (small) its cone.</summary>
        public unsafe ViewShape AddViewShape(Vec3 direction, ReadOnlySpan<JointTransform> joints, float influence)
        {
            ulong shape = 0;
            fixed (JointTransform* p = &MemoryMarshal.GetReference(joints))
                Library.Check(NativeMethods.kdw_chain_add_view_shape(Ptr, id, (kdw_vec3*)&direction, (kdw_transform*)p,
                    Engine.Count(joints.Length), influence, &shape));
            return new ViewShape(engine, shape);
        }

        /// <summary>Number of view shapes.</summary>
        public unsafe int ViewShapeCount
        {
            get
            {
                uint count = 0;
                Library.Check(NativeMethods.kdw_chain_view_shape_count(Ptr, id, &count));
                return (int)count;
            }
        }

        /// <summary>The weights of the chain's last blend (updated by every step): <c>output[0]</c> is the base
        /// shape's, then one per view shape in the order they were added. They are &gt;= 0 and sum to 1.
        /// <paramref name="output"/> needs at least <c>1 + </c><see cref="ViewShapeCount"/> entries (else
        /// <see cref="KodawariStatus.BufferTooSmall"/>). Returns how many were written. Allocation-free.</summary>
        public unsafe int ReadWeights(Span<float> output)
        {
            float none;
            uint written = 0;
            fixed (float* p = &MemoryMarshal.GetReference(output))
                Library.Check(NativeMethods.kdw_chain_read_weights(Ptr, id, p != null ? p : &none, Engine.Count(output.Length), &written));
            return (int)written;
        }

        public bool Equals(ViewDependentPhysicalObject other) { return engine == other.engine && id == other.id; }
        public override bool Equals(object obj) { return obj is ViewDependentPhysicalObject && Equals((ViewDependentPhysicalObject)obj); }
        public override int GetHashCode() { return id.GetHashCode(); }
        public override string ToString() { return "ViewDependentPhysicalObject(0x" + id.ToString("x") + ")"; }
    }

    /// <summary>A view shape of a chain: (direction in the view reference frame, shape, influence). A non-owning
    /// handle like <see cref="ViewDependentPhysicalObject"/>.</summary>
    public struct ViewShape : IEquatable<ViewShape>
    {
        readonly Engine engine;
        readonly ulong id;

        internal ViewShape(Engine engine, ulong id)
        {
            this.engine = engine;
            this.id = id;
        }

        public Engine Engine { get { return engine; } }

        /// <summary>The native <c>kdw_view_shape_id</c> (0 is null).</summary>
        public ulong Id { get { return id; } }

        unsafe kdw_engine* Ptr
        {
            get
            {
                if (engine == null) throw new KodawariException(KodawariStatus.InvalidId, "null view shape handle");
                return engine.Ptr;
            }
        }

        /// <summary>True if the view shape is alive in a live engine.</summary>
        public unsafe bool IsValid
        {
            get
            {
                if (engine == null || engine.IsDisposed) return false;
                uint valid = 0;
                Library.Check(NativeMethods.kdw_view_shape_is_valid(engine.Ptr, id, &valid));
                return valid != 0;
            }
        }

        /// <summary>Sets the influence (&gt; 0).</summary>
        public unsafe void SetInfluence(float influence)
        {
            Library.Check(NativeMethods.kdw_view_shape_set_influence(Ptr, id, influence));
        }

        /// <summary>Sets the direction (view reference frame, non-zero).</summary>
        public unsafe void SetDirection(Vec3 direction)
        {
            Library.Check(NativeMethods.kdw_view_shape_set_direction(Ptr, id, (kdw_vec3*)&direction));
        }

        /// <summary>Replaces the joints (as many as the chain has).</summary>
        public unsafe void SetJoints(ReadOnlySpan<JointTransform> joints)
        {
            fixed (JointTransform* p = &MemoryMarshal.GetReference(joints))
                Library.Check(NativeMethods.kdw_view_shape_set_joints(Ptr, id, (kdw_transform*)p, Engine.Count(joints.Length)));
        }

        /// <summary>Removes the view shape from its chain.</summary>
        public unsafe void Remove() { Library.Check(NativeMethods.kdw_view_shape_remove(Ptr, id)); }

        public bool Equals(ViewShape other) { return engine == other.engine && id == other.id; }
        public override bool Equals(object obj) { return obj is ViewShape && Equals((ViewShape)obj); }
        public override int GetHashCode() { return id.GetHashCode(); }
        public override string ToString() { return "ViewShape(0x" + id.ToString("x") + ")"; }
    }
}
