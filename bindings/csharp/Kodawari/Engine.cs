using System;
using System.Runtime.InteropServices;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>Owns a native <c>kdw_engine</c>. If Dispose is forgotten the SafeHandle's finalizer destroys it.</summary>
    sealed unsafe class EngineHandle : SafeHandle
    {
        EngineHandle() : base(IntPtr.Zero, true) { }

        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }

        internal static EngineHandle Create(kdw_engine_def* def)
        {
            var owner = new EngineHandle();
            kdw_engine* engine = null;
            Library.Check(NativeMethods.kdw_engine_create(def, &engine));
            owner.SetHandle((IntPtr)engine);
            return owner;
        }

        protected override bool ReleaseHandle()
        {
            return NativeMethods.kdw_engine_destroy((kdw_engine*)handle) == NativeMethods.KDW_STATUS_OK;
        }
    }

    /// <summary>One per character: owns chains (<see cref="ViewDependentPhysicalObject"/>), their view shapes,
    /// colliders (<see cref="Collider"/>), gravity and solver settings. One <see cref="Step(float, Vec3, JointTransform)"/> advances all chains.
    /// Use from one thread at a time. The per-frame calls (SetAnchors, SetColliderTransforms, Step, ReadWorld,
    /// ReadLocalRotations) allocate no managed memory.</summary>
    public sealed unsafe class Engine : IDisposable
    {
        readonly EngineHandle owner;
        // Cached raw pointer for the per-frame calls (no SafeHandle ref counting per call); null once disposed.
        kdw_engine* native;

        /// <summary>Creates an engine with default settings.</summary>
        public Engine() : this(null) { }

        /// <summary>Creates an engine. Throws a <see cref="KodawariException"/> if the loaded native library has
        /// another ABI version or the settings are invalid.</summary>
        public Engine(EngineDef def)
        {
            Library.EnsureCompatible();
            kdw_engine_def raw = def != null ? def.Raw : NativeMethods.kdw_engine_def_default();
            owner = EngineHandle.Create(&raw);
            native = (kdw_engine*)owner.DangerousGetHandle();
        }

        /// <summary>True once disposed; every other call then throws ObjectDisposedException.</summary>
        public bool IsDisposed { get { return native == null; } }

        /// <summary>The native pointer, for callers that use the generated NativeMethods directly (Burst jobs).</summary>
        public IntPtr NativePointer { get { return (IntPtr)Ptr; } }

        internal kdw_engine* Ptr
        {
            get
            {
                if (native == null) throw new ObjectDisposedException("Kodawari.Engine");
                return native;
            }
        }

        /// <summary>Destroys the native engine and every chain and view shape it owns.</summary>
        public void Dispose()
        {
            native = null;
            owner.Dispose();
        }

        // ---- settings ----

        /// <summary>All settings at once (validated as a whole; nothing changes on error).</summary>
        public EngineDef Def
        {
            get
            {
                kdw_engine_def raw;
                Library.Check(NativeMethods.kdw_engine_get_def(Ptr, &raw));
                return new EngineDef(raw);
            }
            set
            {
                if (value == null) throw new ArgumentNullException("value");
                kdw_engine_def raw = value.Raw;
                Library.Check(NativeMethods.kdw_engine_set_def(Ptr, &raw));
            }
        }

        /// <summary>World gravity, m/s².</summary>
        public Vec3 Gravity
        {
            get { return Def.Gravity; }
            set { Library.Check(NativeMethods.kdw_engine_set_gravity(Ptr, (kdw_vec3*)&value)); }
        }

        /// <summary>The solver for the engine's chains (<see cref="Kodawari.Solver.Lanes"/> by default):
        /// the solvers agree up to float rounding, and the choice is part of <see cref="StateHash"/>. Setting a value
        /// outside <see cref="Kodawari.Solver"/> throws (<see cref="KodawariStatus.InvalidArgument"/>) and changes
        /// nothing. Allocation-free.</summary>
        public Solver Solver
        {
            get
            {
                uint solver = 0;
                Library.Check(NativeMethods.kdw_engine_get_solver(Ptr, &solver));
                return (Solver)solver;
            }
            set { Library.Check(NativeMethods.kdw_engine_set_solver(Ptr, (uint)value)); }
        }

        /// <summary>The level of detail (<see cref="EngineDef.Lod"/>, 0 to 3), read and written through the engine's
        /// settings without allocating: e.g. set per character by its distance to the camera. Setting it wakes every
        /// chain; set it only when it changes.</summary>
        public int Lod
        {
            get
            {
                kdw_engine_def raw;
                Library.Check(NativeMethods.kdw_engine_get_def(Ptr, &raw));
                return (int)raw.lod;
            }
            set
            {
                kdw_engine_def raw;
                Library.Check(NativeMethods.kdw_engine_get_def(Ptr, &raw));
                raw.lod = unchecked((uint)value);
                Library.Check(NativeMethods.kdw_engine_set_def(Ptr, &raw));
            }
        }

        // ---- chains ----

        /// <summary>Creates a chain from its base shape: at least 2 joints in the anchor frame, root first.</summary>
        public ViewDependentPhysicalObject CreateChain(ChainDef def, ReadOnlySpan<JointTransform> baseJoints)
        {
            fixed (JointTransform* joints = &MemoryMarshal.GetReference(baseJoints))
                return CreateChain(def, joints, baseJoints.Length);
        }

        /// <summary>Creates a chain from <paramref name="count"/> base joints at <paramref name="baseJoints"/>.</summary>
        public ViewDependentPhysicalObject CreateChain(ChainDef def, JointTransform* baseJoints, int count)
        {
            kdw_chain_def raw = def != null ? def.Raw : NativeMethods.kdw_chain_def_default();
            ulong id = 0;
            Library.Check(NativeMethods.kdw_chain_create(Ptr, &raw, (kdw_transform*)baseJoints, Count(count), &id));
            return new ViewDependentPhysicalObject(this, id);
        }

        /// <summary>Number of chains.</summary>
        public int ChainCount
        {
            get
            {
                uint count = 0;
                Library.Check(NativeMethods.kdw_engine_chain_count(Ptr, &count));
                return (int)count;
            }
        }

        /// <summary>Total joints of all chains: the length <see cref="ReadWorld(Span{JointTransform})"/> needs.</summary>
        public int JointCount
        {
            get
            {
                uint count = 0;
                Library.Check(NativeMethods.kdw_engine_joint_count(Ptr, &count));
                return (int)count;
            }
        }

        /// <summary>The chains in creation order: the order of every batched call. Allocates the array.</summary>
        public ViewDependentPhysicalObject[] GetChains()
        {
            int count = ChainCount;
            var ids = new ulong[Math.Max(count, 1)];
            uint written = 0;
            fixed (ulong* p = ids)
                Library.Check(NativeMethods.kdw_engine_get_chain_ids(Ptr, p, (uint)ids.Length, &written));
            var chains = new ViewDependentPhysicalObject[written];
            for (int i = 0; i < written; i++) chains[i] = new ViewDependentPhysicalObject(this, ids[i]);
            return chains;
        }

        // ---- colliders ----

        /// <summary>Creates a collider (chains whose collision mask shares a bit with its layers are kept out of it, or
        /// inside it). It comes last in the order of <see cref="SetColliderTransforms(ReadOnlySpan{JointTransform})"/>.</summary>
        public Collider CreateCollider(ColliderDef def)
        {
            kdw_collider_def raw = def != null ? def.Raw : NativeMethods.kdw_collider_def_default();
            ulong id = 0;
            Library.Check(NativeMethods.kdw_collider_create(Ptr, &raw, &id));
            return new Collider(this, id);
        }

        /// <summary>Number of colliders.</summary>
        public int ColliderCount
        {
            get
            {
                uint count = 0;
                Library.Check(NativeMethods.kdw_engine_collider_count(Ptr, &count));
                return (int)count;
            }
        }

        /// <summary>The colliders in creation order: the order of <see cref="SetColliderTransforms(ReadOnlySpan{JointTransform})"/>.
        /// Allocates the array.</summary>
        public Collider[] GetColliders()
        {
            int count = ColliderCount;
            var ids = new ulong[Math.Max(count, 1)];
            uint written = 0;
            fixed (ulong* p = ids)
                Library.Check(NativeMethods.kdw_engine_get_collider_ids(Ptr, p, (uint)ids.Length, &written));
            var colliders = new Collider[written];
            for (int i = 0; i < written; i++) colliders[i] = new Collider(this, ids[i]);
            return colliders;
        }

        /// <summary>Every collider's world pose for the next step, in ONE native call: one entry per collider in creation
        /// order (<see cref="GetColliders"/>). The step sweeps each collider from its last pose to this one.</summary>
        public void SetColliderTransforms(ReadOnlySpan<JointTransform> poses)
        {
            fixed (JointTransform* p = &MemoryMarshal.GetReference(poses))
                SetColliderTransforms(p, poses.Length);
        }

        /// <summary>Pointer form of <see cref="SetColliderTransforms(ReadOnlySpan{JointTransform})"/>.</summary>
        public void SetColliderTransforms(JointTransform* poses, int count)
        {
            JointTransform none;
            if (poses == null && count == 0) poses = &none;
            Library.Check(NativeMethods.kdw_engine_set_collider_transforms(Ptr, (kdw_transform*)poses, Count(count)));
        }

        // ---- per frame ----

        /// <summary>Sets every chain's anchor for the next step, world space: one entry per chain in creation order
        /// (entries of chains anchored to the view reference are checked but unused).</summary>
        public void SetAnchors(ReadOnlySpan<JointTransform> anchors)
        {
            fixed (JointTransform* p = &MemoryMarshal.GetReference(anchors))
                SetAnchors(p, anchors.Length);
        }

        /// <summary>Pointer form of <see cref="SetAnchors(ReadOnlySpan{JointTransform})"/> (NativeArray, stackalloc).</summary>
        public void SetAnchors(JointTransform* anchors, int count)
        {
            JointTransform none;
            if (anchors == null && count == 0) anchors = &none;
            Library.Check(NativeMethods.kdw_engine_set_anchors(Ptr, (kdw_transform*)anchors, Count(count)));
        }

        /// <summary>Advances every chain by <paramref name="dt"/> seconds (finite, &gt;= 0). The camera position
        /// and the view reference joint K (e.g. the head) are in world space.</summary>
        public void Step(float dt, Vec3 cameraPosition, JointTransform viewReference)
        {
            Library.Check(NativeMethods.kdw_engine_step(Ptr, dt, (kdw_vec3*)&cameraPosition, (kdw_transform*)&viewReference));
        }

        /// <summary>World transforms of every joint of every chain (chains in creation order, root to tip), at the
        /// time of the last step's call. <paramref name="output"/> needs at least <see cref="JointCount"/> entries.
        /// Returns how many were written.</summary>
        public int ReadWorld(Span<JointTransform> output)
        {
            fixed (JointTransform* p = &MemoryMarshal.GetReference(output))
                return ReadWorld(p, output.Length);
        }

        /// <summary>Pointer form of <see cref="ReadWorld(Span{JointTransform})"/>.</summary>
        public int ReadWorld(JointTransform* output, int capacity)
        {
            JointTransform none;
            if (output == null && capacity == 0) output = &none;
            uint written = 0;
            Library.Check(NativeMethods.kdw_engine_read_world(Ptr, (kdw_transform*)output, Count(capacity), &written));
            return (int)written;
        }

        /// <summary>Each joint's rotation relative to its parent joint (joint 0: to its anchor), in the order of
        /// ReadWorld: what Unity writes to <c>Transform.localRotation</c>. Returns how many were written.</summary>
        public int ReadLocalRotations(Span<Quat> output)
        {
            fixed (Quat* p = &MemoryMarshal.GetReference(output))
                return ReadLocalRotations(p, output.Length);
        }

        /// <summary>Pointer form of <see cref="ReadLocalRotations(Span{Quat})"/>.</summary>
        public int ReadLocalRotations(Quat* output, int capacity)
        {
            Quat none;
            if (output == null && capacity == 0) output = &none;
            uint written = 0;
            Library.Check(NativeMethods.kdw_engine_read_local_rotations(Ptr, (kdw_quat*)output, Count(capacity), &written));
            return (int)written;
        }

        /// <summary>A whole frame in ONE native call: sets the anchors (one per chain, creation order), steps, and
        /// writes every joint's local rotation (what Unity assigns to <c>Transform.localRotation</c>) into
        /// <paramref name="localRotations"/>, which needs at least <see cref="JointCount"/> entries. Nothing changes
        /// unless every input is valid. Returns how many rotations were written.</summary>
        public int StepAndReadLocalRotations(float dt, Vec3 cameraPosition, JointTransform viewReference,
                                             ReadOnlySpan<JointTransform> anchors, Span<Quat> localRotations)
        {
            fixed (JointTransform* a = &MemoryMarshal.GetReference(anchors))
            fixed (Quat* r = &MemoryMarshal.GetReference(localRotations))
                return StepAndReadLocalRotations(dt, cameraPosition, viewReference, a, anchors.Length, r, localRotations.Length);
        }

        /// <summary>Pointer form of <see cref="StepAndReadLocalRotations(float, Vec3, JointTransform, ReadOnlySpan{JointTransform}, Span{Quat})"/>.</summary>
        public int StepAndReadLocalRotations(float dt, Vec3 cameraPosition, JointTransform viewReference,
                                             JointTransform* anchors, int anchorCount, Quat* localRotations, int capacity)
        {
            JointTransform noAnchor;
            Quat noRotation;
            if (anchors == null && anchorCount == 0) anchors = &noAnchor;
            if (localRotations == null && capacity == 0) localRotations = &noRotation;
            uint written = 0;
            Library.Check(NativeMethods.kdw_engine_step_and_read(Ptr, dt, (kdw_vec3*)&cameraPosition, (kdw_transform*)&viewReference,
                (kdw_transform*)anchors, Count(anchorCount), (kdw_quat*)localRotations, Count(capacity), &written));
            return (int)written;
        }

        // Handle scratch of StepMany beyond StackHandles engines: grown once per thread, then reused.
        [ThreadStatic] static IntPtr[] manyHandles;
        const int StackHandles = 64;

        /// <summary>Steps several distinct engines by <paramref name="dt"/> with one camera, <c>engines[i]</c> with its view
        /// reference <c>viewReferences[i]</c> (as <see cref="Step(float, Vec3, JointTransform)"/> each), in ONE native
        /// call: in parallel when the native library is built with its <c>parallel</c> feature. Every handle and input
        /// is checked before any engine moves: a null entry (<see cref="KodawariStatus.NullPointer"/>), an engine given
        /// twice or a bad input (<see cref="KodawariStatus.InvalidArgument"/>) fails the whole call and changes nothing.
        /// The two spans must have the same length (an <c>Engine[]</c> and a <c>JointTransform[]</c> convert). No
        /// managed allocation (beyond 64 engines, once per thread).</summary>
        public static void StepMany(ReadOnlySpan<Engine> engines, float dt, Vec3 cameraPosition,
                                    ReadOnlySpan<JointTransform> viewReferences)
        {
            if (engines.Length != viewReferences.Length)
                throw new KodawariException(KodawariStatus.InvalidArgument,
                    "StepMany: " + engines.Length + " engines but " + viewReferences.Length + " view references");
            int count = engines.Length;
            IntPtr* stack = stackalloc IntPtr[StackHandles];
            IntPtr[] heap = null;
            if (count > StackHandles)
            {
                heap = manyHandles;
                if (heap == null || heap.Length < count) manyHandles = heap = new IntPtr[count];
            }
            fixed (IntPtr* pinned = heap)
            fixed (JointTransform* references = &MemoryMarshal.GetReference(viewReferences))
            {
                IntPtr* handles = heap != null ? pinned : stack;
                for (int i = 0; i < count; i++)
                    handles[i] = engines[i] != null ? (IntPtr)engines[i].Ptr : IntPtr.Zero;
                JointTransform noReference;
                Library.Check(NativeMethods.kdw_engines_step((kdw_engine**)handles, (uint)count, dt, (kdw_vec3*)&cameraPosition,
                    (kdw_transform*)(references != null ? references : &noReference)));
            }
        }

        // ---- state ----

        /// <summary>Puts every chain back to its rest shape, at rest, at the next step (after a teleport, a cut).</summary>
        public void Reset() { Library.Check(NativeMethods.kdw_engine_reset(Ptr)); }

        /// <summary>Every chain treats its anchor's motion in the next step as a teleport (<see cref="EngineDef.TeleportMode"/>),
        /// however small: call it when the character is placed somewhere new.</summary>
        public void Teleport() { Library.Check(NativeMethods.kdw_engine_teleport(Ptr)); }

        /// <summary>A hash of everything that determines future results (determinism checks).</summary>
        public ulong StateHash
        {
            get
            {
                ulong hash = 0;
                Library.Check(NativeMethods.kdw_engine_state_hash(Ptr, &hash));
                return hash;
            }
        }

        /// <summary>Counters: chains, joints, substeps run, time dropped, chains asleep, chains on the lane solver.</summary>
        public EngineStats Stats
        {
            get
            {
                kdw_engine_stats raw;
                raw.struct_size = (uint)sizeof(kdw_engine_stats);
                Library.Check(NativeMethods.kdw_engine_get_stats(Ptr, &raw));
                return new EngineStats
                {
                    ChainCount = (int)raw.chain_count,
                    JointCount = (int)raw.joint_count,
                    SubstepsLastStep = (int)raw.substeps_last_step,
                    ChainsAsleep = (int)raw.chains_asleep,
                    LaneChains = (int)raw.lane_chains,
                    SubstepsTotal = (long)raw.substeps_total,
                    SolverFallbacks = (long)raw.solver_fallbacks,
                    TimeDropped = raw.time_dropped,
                    SimulatedTime = raw.simulated_time,
                    ColliderCount = (int)raw.collider_count,
                    ContactPairsTested = (long)raw.contact_pairs_tested,
                };
            }
        }

        internal static uint Count(int count)
        {
            if (count < 0) throw new ArgumentOutOfRangeException("count", "must be >= 0");
            return (uint)count;
        }
    }
}
