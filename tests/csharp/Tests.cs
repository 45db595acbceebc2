// C# binding tests, compiled with `mcs -unsafe` together with bindings/csharp/NativeMethods.g.cs and
// bindings/csharp/Kodawari/*.cs, run with `mono` against the real libkodawari.so (tests/csharp_bindings.rs).
// Prints "N passed, M failed" last; the exit code is the number of failures.
using System;
using System.Collections.Generic;
using System.Diagnostics;
using Kodawari;
using Kodawari.Native;

static unsafe class Tests
{
    static int passed, failed;

    static int Main()
    {
        Console.WriteLine("kodawari " + Library.Version + ", ABI " + Library.AbiVersion + ", SIMD " + Library.SimdPath + ", runtime "
                          + (Type.GetType("Mono.Runtime") != null ? "Mono" : ".NET"));
        Run("abi_and_struct_sizes", AbiAndStructSizes);
        Run("life_cycle", LifeCycle);
        Run("defs_default_through_native", DefsDefaultThroughNative);
        Run("error_maps_to_exception_and_leaves_state", ErrorMapsToException);
        Run("stale_and_foreign_ids", StaleAndForeignIds);
        Run("quickstart_orbit_matches_direct_calls", QuickstartOrbitMatchesDirectCalls);
        Run("own_anchors_and_local_rotations", OwnAnchorsAndLocalRotations);
        Run("zero_managed_allocation_per_frame", ZeroManagedAllocationPerFrame);
        Run("per_call_overhead_vs_direct", PerCallOverhead);
        Run("stroke_camera_defaults_and_projection", SketchTests.CameraDefaultsAndProjection);
        Run("shape_from_stroke_follows_reachable_stroke", SketchTests.ShapeFromStrokeFollowsReachableStroke);
        Run("shape_from_stroke_round_trip", SketchTests.ShapeFromStrokeRoundTrip);
        Run("shape_from_stroke_errors", SketchTests.ShapeFromStrokeErrors);
        Run("sketched_view_shape_drives_the_chain", SketchTests.SketchedViewShapeDrivesTheChain);
        Run("weights_follow_the_camera", SketchTests.WeightsFollowTheCamera);
        Run("colliders_keep_the_chain_out", ColliderTests.CollidersKeepTheChainOut);
        Run("collider_update_allocates_nothing", ColliderTests.ColliderUpdateAllocatesNothing);
        Run("teleports_and_scale", ColliderTests.TeleportsAndScale);
        Run("disabled_chain_rides_with_its_anchor", CullingTests.DisabledChainRidesWithItsAnchor);
        Run("settled_chain_sleeps_and_lod", CullingTests.SettledChainSleepsAndLod);
        Run("step_many_equals_single_steps", CullingTests.StepManyEqualsSingleSteps);
        Run("collider_set_size_pushes_the_chain_out", CullingTests.ColliderSetSizePushesTheChainOut);
        Run("batch_and_culling_allocate_nothing", CullingTests.BatchAndCullingAllocateNothing);
        Run("solver_selection", SolverTests.SolverSelection);
        Run("solver_calls_allocate_nothing", SolverTests.SolverCallsAllocateNothing);
        Run("readme_snippet", ReadmeSnippet.Run);
        Console.WriteLine(passed + " passed, " + failed + " failed");
        return failed;
    }

    static void Run(string name, Action test)
    {
        try
        {
            test();
            passed++;
            Console.WriteLine("ok   " + name);
        }
        catch (Exception e)
        {
            failed++;
            Console.WriteLine("FAIL " + name + ": " + e);
        }
    }

    static void Ensure(bool condition, string what)
    {
        if (!condition) throw new Exception("check failed: " + what);
    }

    static T Expect<T>(Action call) where T : Exception
    {
        try
        {
            call();
        }
        catch (T e)
        {
            return e;
        }
        throw new Exception("expected " + typeof(T).Name);
    }

    static KodawariException ExpectStatus(KodawariStatus status, Action call)
    {
        var e = Expect<KodawariException>(call);
        Ensure(e.Status == status, "status " + e.Status + " == " + status + " (" + e.Message + ")");
        return e;
    }

    // ---- scenes ----

    const int Joints = 6;

    static void QuickstartShapes(JointTransform[] baseShape, JointTransform[] left, JointTransform[] right)
    {
        for (int i = 0; i < Joints; ++i)
        {
            float t = i;
            baseShape[i] = new JointTransform(0.0f, 0.12f + 0.03f * t, 0.0f);
            left[i] = new JointTransform(-0.01f * t * t, 0.12f + 0.025f * t, 0.0f);
            right[i] = new JointTransform(0.01f * t * t, 0.12f + 0.025f * t, 0.0f);
        }
    }

    static Vec3 OrbitCamera(int frame)
    {
        // Same float arithmetic as examples/c/quickstart.c.
        float angle = 6.2831853f * (float)frame / 240.0f;
        return new Vec3(2.5f * (float)Math.Sin(angle), 1.7f, 2.5f * (float)Math.Cos(angle));
    }

    static JointTransform[] StraightChain(int joints, float x)
    {
        var shape = new JointTransform[joints];
        for (int j = 0; j < joints; j++) shape[j] = new JointTransform(x, -0.05f * j, 0f);
        return shape;
    }

    // ---- tests ----

    static void AbiAndStructSizes()
    {
        Library.EnsureCompatible();
        Ensure(Library.AbiVersion == NativeMethods.KDW_ABI_VERSION, "loaded ABI == generated KDW_ABI_VERSION");
        Ensure(sizeof(kdw_transform) == 28 && System.Runtime.InteropServices.Marshal.SizeOf(typeof(kdw_transform)) == 28,
               "kdw_transform is 28 bytes");
        Ensure(sizeof(JointTransform) == 28 && sizeof(Vec3) == 12 && sizeof(Quat) == 16, "public structs match");
        Ensure(sizeof(kdw_engine_def) == 56 && sizeof(kdw_chain_def) == 40 && sizeof(kdw_engine_stats) == 72
               && sizeof(kdw_collider_def) == 48, "def struct sizes match the C header");
        var mismatch = ExpectStatus(KodawariStatus.AbiMismatch, () => Library.CheckAbi(NativeMethods.KDW_ABI_VERSION + 1, NativeMethods.KDW_ABI_VERSION));
        Ensure(mismatch.Message.Contains("ABI"), "ABI mismatch message: " + mismatch.Message);
        ExpectStatus(KodawariStatus.AbiMismatch, () => Library.CheckSize("kdw_transform", 32, 32, 28));
        Ensure(Library.StatusString(KodawariStatus.InvalidId).Contains("invalid id"), "status string");
        Ensure(Library.StatusString((KodawariStatus)(-12345)) == "unknown status", "unknown status string");
    }

    static void LifeCycle()
    {
        var engine = new Engine();
        Ensure(!engine.IsDisposed && engine.NativePointer != IntPtr.Zero, "created");
        var chain = engine.CreateChain(new ChainDef(), StraightChain(4, 0f));
        Ensure(engine.ChainCount == 1 && engine.JointCount == 4 && chain.JointCount == 4, "counts");
        Ensure(chain.IsValid, "chain valid");
        var chains = engine.GetChains();
        Ensure(chains.Length == 1 && chains[0].Equals(chain), "chain ids in creation order");
        var stats = engine.Stats;
        Ensure(stats.ChainCount == 1 && stats.JointCount == 4, "stats");
        engine.Dispose();
        Ensure(engine.IsDisposed, "disposed");
        engine.Dispose(); // idempotent
        Ensure(!chain.IsValid, "chain of a disposed engine is invalid");
        Expect<ObjectDisposedException>(() => engine.Step(0.01f, new Vec3(), new JointTransform()));
        Expect<ObjectDisposedException>(() => chain.Reset());
        using (var scoped = new Engine(new EngineDef { SubstepRate = 120f, Iterations = 3 }))
        {
            Ensure(scoped.Def.SubstepRate == 120f && scoped.Def.Iterations == 3, "def round trip");
        }
        // Forgotten engines are destroyed by the SafeHandle's finalizer (must not crash).
        for (int i = 0; i < 10; i++) new Engine().CreateChain(null, StraightChain(3, 0f));
        GC.Collect();
        GC.WaitForPendingFinalizers();
        GC.Collect();
    }

    static void DefsDefaultThroughNative()
    {
        var native = NativeMethods.kdw_engine_def_default();
        var def = new EngineDef();
        Ensure(def.SubstepRate == native.substep_rate && def.Iterations == (int)native.iterations
               && def.Gravity.Y == native.gravity.y && def.MaxSubsteps == (int)native.max_substeps, "engine def defaults");
        Ensure(def.Raw.struct_size == (uint)sizeof(kdw_engine_def), "struct_size set by the library");
        var chainNative = NativeMethods.kdw_chain_def_default();
        var chainDef = new ChainDef();
        Ensure(chainDef.Stiffness == chainNative.stiffness && chainDef.Damping == chainNative.damping
               && chainDef.Anchor == AnchorSource.ViewReference, "chain def defaults");
        Ensure(chainDef.CollisionMask == chainNative.collision_mask && chainDef.Friction == chainNative.friction
               && def.Scale == native.scale && def.TeleportMode == (TeleportMode)native.teleport_mode, "new def fields");
        var colliderNative = NativeMethods.kdw_collider_def_default();
        var colliderDef = new ColliderDef();
        Ensure(colliderDef.Shape == ColliderShape.Sphere && colliderDef.Radius == colliderNative.radius
               && colliderDef.Layers == colliderNative.layers && colliderDef.Transform.Rotation.W == colliderNative.transform.rotation.w
               && colliderDef.Raw.struct_size == (uint)sizeof(kdw_collider_def), "collider def defaults");
        using (var engine = new Engine())
        {
            engine.Gravity = new Vec3(0f, -1.62f, 0f);
            Ensure(engine.Gravity.Y == -1.62f, "gravity");
            var chain = engine.CreateChain(new ChainDef { Stiffness = 0.25f, Anchor = AnchorSource.Own }, StraightChain(3, 0f));
            Ensure(chain.Def.Stiffness == 0.25f && chain.Def.Anchor == AnchorSource.Own, "chain def round trip");
            var changed = chain.Def;
            changed.Damping = 3f;
            chain.Def = changed;
            Ensure(chain.Def.Damping == 3f, "chain def set");
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.Def = new EngineDef { SubstepRate = 1f });
        }
    }

    static void ErrorMapsToException()
    {
        using (var engine = new Engine())
        {
            var chain = engine.CreateChain(null, StraightChain(5, 0f));
            engine.Step(1f / 60f, new Vec3(0f, 0f, 3f), new JointTransform(0f, 1f, 0f));
            ulong before = engine.StateHash;

            var e = ExpectStatus(KodawariStatus.InvalidArgument, () => engine.CreateChain(null, StraightChain(1, 0f)));
            Ensure(e.NativeMessage.Length > 0 && e.Message.Contains(e.NativeMessage), "native message carried: " + e.Message);
            Console.WriteLine("     n=1 chain: " + e.Message);
            Ensure(engine.StateHash == before, "state unchanged after the rejected chain");

            var nan = ExpectStatus(KodawariStatus.InvalidArgument, () => engine.Step(float.NaN, new Vec3(0f, 0f, 3f), new JointTransform(0f, 1f, 0f)));
            Console.WriteLine("     NaN dt: " + nan.Message);
            Ensure(engine.StateHash == before, "state unchanged after NaN dt");

            ExpectStatus(KodawariStatus.InvalidArgument,
                () => engine.Step(1f / 60f, new Vec3(0f, 0f, 3f), new JointTransform(new Vec3(0f, 1f, 0f), new Quat(0f, 0f, 0f, 0f))));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.SetAnchors(new JointTransform[3]));
            ExpectStatus(KodawariStatus.BufferTooSmall, () => engine.ReadWorld(new JointTransform[2]));
            ExpectStatus(KodawariStatus.BufferTooSmall, () => engine.ReadLocalRotations(new Quat[0]));
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.AddViewShape(new Vec3(), StraightChain(5, 0f), 1f));
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.SetBaseShape(StraightChain(4, 0f)));
            Ensure(engine.StateHash == before, "state unchanged after every rejected call");
            Ensure(Library.LastErrorMessage().Length > 0, "last error message readable");
        }
    }

    static void StaleAndForeignIds()
    {
        using (var a = new Engine())
        using (var b = new Engine())
        {
            var chain = a.CreateChain(null, StraightChain(4, 0f));
            var other = a.CreateChain(null, StraightChain(4, 1f));
            var shape = chain.AddViewShape(new Vec3(1f, 0f, 0f), StraightChain(4, 0f), 2f);
            shape.SetInfluence(3f);
            Ensure(chain.ViewShapeCount == 1 && shape.IsValid, "view shape added");
            shape.Remove();
            Ensure(!shape.IsValid && chain.ViewShapeCount == 0, "removed view shape is stale");
            ExpectStatus(KodawariStatus.InvalidId, () => shape.SetInfluence(1f));
            ExpectStatus(KodawariStatus.InvalidId, () => shape.Remove());

            ulong hash = a.StateHash;
            chain.Destroy();
            Ensure(!chain.IsValid && other.IsValid, "destroyed chain is stale, the other lives");
            ExpectStatus(KodawariStatus.InvalidId, () => chain.Reset());
            ExpectStatus(KodawariStatus.InvalidId, () => chain.Destroy());
            var stale = ExpectStatus(KodawariStatus.InvalidId, () => { var unused = chain.JointCount; });
            Console.WriteLine("     stale id: " + stale.Message);
            Ensure(a.StateHash != hash, "destroy changed the state");

            // A new chain in the freed slot gets a new generation: the old handle stays stale.
            var reused = a.CreateChain(null, StraightChain(4, 2f));
            Ensure(reused.Id != chain.Id && !chain.IsValid, "generation bumped");
            // An id of engine a used on engine b.
            var foreign = new ViewDependentPhysicalObject(b, other.Id);
            Ensure(!foreign.IsValid, "foreign id invalid");
            ExpectStatus(KodawariStatus.InvalidId, () => foreign.Reset());
            ExpectStatus(KodawariStatus.InvalidId, () => default(ViewDependentPhysicalObject).Reset());
            ExpectStatus(KodawariStatus.InvalidId, () => new ViewDependentPhysicalObject(a, 0).Reset());
        }
    }

    /// The scene of examples/c/quickstart.c, once through the generated NativeMethods (the reference, the same
    /// calls the C program makes) and once through the hand-written layer: equal final state hashes.
    static void QuickstartOrbitMatchesDirectCalls()
    {
        var baseShape = new JointTransform[Joints];
        var left = new JointTransform[Joints];
        var right = new JointTransform[Joints];
        QuickstartShapes(baseShape, left, right);

        ulong reference;
        kdw_transform referenceTip;
        {
            Ensure(NativeMethods.kdw_abi_version() == NativeMethods.KDW_ABI_VERSION, "abi");
            kdw_engine_def engineDef = NativeMethods.kdw_engine_def_default();
            kdw_engine* engine = null;
            Ensure(NativeMethods.kdw_engine_create(&engineDef, &engine) == NativeMethods.KDW_STATUS_OK, "create");
            kdw_chain_def chainDef = NativeMethods.kdw_chain_def_default();
            chainDef.stiffness = 0.9f;
            ulong ahoge = 0, shapeLeft = 0, shapeRight = 0;
            kdw_vec3 fromLeft = new kdw_vec3 { x = -1f }, fromRight = new kdw_vec3 { x = 1f };
            fixed (JointTransform* b = baseShape, l = left, r = right)
            {
                Ensure(NativeMethods.kdw_chain_create(engine, &chainDef, (kdw_transform*)b, Joints, &ahoge) == 0, "chain");
                Ensure(NativeMethods.kdw_chain_add_view_shape(engine, ahoge, &fromLeft, (kdw_transform*)l, Joints, 1f, &shapeLeft) == 0, "left");
                Ensure(NativeMethods.kdw_chain_add_view_shape(engine, ahoge, &fromRight, (kdw_transform*)r, Joints, 1f, &shapeRight) == 0, "right");
            }
            kdw_transform head = new kdw_transform();
            head.position.y = 1.6f;
            head.rotation.w = 1f;
            kdw_transform* joints = stackalloc kdw_transform[Joints];
            uint written = 0;
            for (int frame = 0; frame <= 240; ++frame)
            {
                Vec3 c = OrbitCamera(frame);
                kdw_vec3 camera = new kdw_vec3 { x = c.X, y = c.Y, z = c.Z };
                Ensure(NativeMethods.kdw_engine_step(engine, 1.0f / 60.0f, &camera, &head) == 0, "step");
                Ensure(NativeMethods.kdw_engine_read_world(engine, joints, Joints, &written) == 0, "read");
            }
            referenceTip = joints[Joints - 1];
            Ensure(NativeMethods.kdw_engine_state_hash(engine, &reference) == 0, "hash");
            Ensure(NativeMethods.kdw_engine_destroy(engine) == 0, "destroy");
        }

        ulong layered;
        JointTransform tip;
        using (var engine = new Engine(new EngineDef()))
        {
            var ahoge = engine.CreateChain(new ChainDef { Stiffness = 0.9f }, baseShape);
            ahoge.AddViewShape(new Vec3(-1f, 0f, 0f), left, 1f);
            ahoge.AddViewShape(new Vec3(1f, 0f, 0f), right, 1f);
            var head = new JointTransform(0f, 1.6f, 0f);
            var joints = new JointTransform[Joints];
            for (int frame = 0; frame <= 240; ++frame)
            {
                engine.Step(1.0f / 60.0f, OrbitCamera(frame), head);
                Ensure(engine.ReadWorld(joints) == Joints, "read world");
            }
            tip = joints[Joints - 1];
            layered = engine.StateHash;
        }
        Console.WriteLine("     quickstart orbit: state hash direct 0x" + reference.ToString("x16") + ", C# layer 0x"
                          + layered.ToString("x16") + ", tip " + tip.Position);
        Ensure(reference == layered, "equal state hashes");
        Ensure(tip.Position.X == referenceTip.position.x && tip.Position.Y == referenceTip.position.y
               && tip.Position.Z == referenceTip.position.z, "equal tips");
    }

    static void OwnAnchorsAndLocalRotations()
    {
        using (var engine = new Engine())
        {
            const int chains = 3, joints = 5;
            for (int c = 0; c < chains; c++)
                engine.CreateChain(new ChainDef { Anchor = AnchorSource.Own }, StraightChain(joints, 0f));
            var anchors = new JointTransform[chains];
            var world = new JointTransform[chains * joints];
            var local = new Quat[chains * joints];
            for (int frame = 0; frame < 60; frame++)
            {
                for (int c = 0; c < chains; c++)
                    anchors[c] = new JointTransform(c + 0.2f * (float)Math.Sin(frame * 0.1), 1f, 0f);
                engine.SetAnchors(anchors);
                engine.Step(1f / 60f, new Vec3(0f, 1f, 3f), new JointTransform(0f, 1.5f, 0f));
                Ensure(engine.ReadWorld(world) == chains * joints, "world count");
                Ensure(engine.ReadLocalRotations(local) == chains * joints, "local count");
            }
            for (int i = 0; i < world.Length; i++)
            {
                var p = world[i].Position;
                var q = local[i];
                Ensure(!float.IsNaN(p.X + p.Y + p.Z + q.X + q.Y + q.Z + q.W), "finite output");
                float n = q.X * q.X + q.Y * q.Y + q.Z * q.Z + q.W * q.W;
                Ensure(Math.Abs(n - 1f) < 1e-4f, "unit local rotation");
            }
            Ensure(Math.Abs(world[joints].Position.X - anchors[1].Position.X) < 1e-4f, "chain 1 root follows its own anchor");
            // The one-call frame gives what the three calls give, bit for bit.
            using (var twin = new Engine())
            {
                for (int c = 0; c < chains; c++)
                    twin.CreateChain(new ChainDef { Anchor = AnchorSource.Own }, StraightChain(joints, 0f));
                var twinLocal = new Quat[chains * joints];
                for (int frame = 0; frame < 60; frame++)
                {
                    for (int c = 0; c < chains; c++)
                        anchors[c] = new JointTransform(c + 0.2f * (float)Math.Sin(frame * 0.1), 1f, 0f);
                    Ensure(twin.StepAndReadLocalRotations(1f / 60f, new Vec3(0f, 1f, 3f), new JointTransform(0f, 1.5f, 0f),
                                                          anchors, twinLocal) == chains * joints, "one-call count");
                }
                Ensure(twin.StateHash == engine.StateHash, "one-call frame equals separate calls");
                for (int i = 0; i < local.Length; i++)
                    Ensure(local[i].X == twinLocal[i].X && local[i].W == twinLocal[i].W, "same local rotations");
                ExpectStatus(KodawariStatus.BufferTooSmall, () => twin.StepAndReadLocalRotations(1f / 60f, new Vec3(0f, 1f, 3f),
                    new JointTransform(0f, 1.5f, 0f), anchors, new Quat[1]));
            }
            // Pointer overloads (NativeArray / stackalloc users).
            JointTransform* stackAnchors = stackalloc JointTransform[chains];
            for (int c = 0; c < chains; c++) stackAnchors[c] = anchors[c];
            engine.SetAnchors(stackAnchors, chains);
            JointTransform* stackWorld = stackalloc JointTransform[chains * joints];
            Ensure(engine.ReadWorld(stackWorld, chains * joints) == chains * joints, "pointer read");
        }
    }

    // ---- per-frame allocation and overhead ----

    sealed class FrameScene : IDisposable
    {
        public readonly Engine Engine;
        public readonly JointTransform[] Anchors;
        public readonly JointTransform[] World;
        public readonly Quat[] Local;
        public int Frame;

        public FrameScene(int chains, int joints)
        {
            Engine = new Engine();
            var def = new ChainDef { Anchor = AnchorSource.Own };
            for (int c = 0; c < chains; c++)
            {
                var shape = StraightChain(joints, 0f);
                var chain = Engine.CreateChain(def, shape);
                if (c % 2 == 0)
                {
                    for (int j = 0; j < joints; j++) shape[j].Position.X = 0.01f * j * j;
                    chain.AddViewShape(new Vec3(1f, 0f, 0f), shape, 1f);
                }
            }
            Anchors = new JointTransform[chains];
            World = new JointTransform[chains * joints];
            Local = new Quat[chains * joints];
        }

        public Vec3 NextInputs()
        {
            float t = Frame++ / 60f;
            for (int c = 0; c < Anchors.Length; c++)
            {
                Anchors[c].Position = new Vec3(0.1f * c + 0.2f * (float)Math.Sin(6.2831853f * t), 1f, 0f);
                Anchors[c].Rotation = Quat.Identity;
            }
            return new Vec3(2.5f * (float)Math.Sin(t), 1.7f, 2.5f * (float)Math.Cos(t));
        }

        /// One frame through the C# layer: the Unity path (one native call) plus a world read-back.
        public void LayerFrame(JointTransform head)
        {
            Vec3 camera = NextInputs();
            Engine.StepAndReadLocalRotations(1f / 60f, camera, head, Anchors, Local);
            Engine.ReadWorld(World);
        }

        /// The same frame calling the generated NativeMethods directly.
        public void DirectFrame(kdw_engine* engine, kdw_transform* head)
        {
            Vec3 camera = NextInputs();
            uint written;
            fixed (JointTransform* anchors = Anchors)
            fixed (JointTransform* world = World)
            fixed (Quat* local = Local)
            {
                if (NativeMethods.kdw_engine_set_anchors(engine, (kdw_transform*)anchors, (uint)Anchors.Length) != 0
                    || NativeMethods.kdw_engine_step(engine, 1f / 60f, (kdw_vec3*)&camera, head) != 0
                    || NativeMethods.kdw_engine_read_world(engine, (kdw_transform*)world, (uint)World.Length, &written) != 0
                    || NativeMethods.kdw_engine_read_local_rotations(engine, (kdw_quat*)local, (uint)Local.Length, &written) != 0)
                    throw new Exception("direct frame failed");
            }
        }

        public void Dispose() { Engine.Dispose(); }
    }

    static void ZeroManagedAllocationPerFrame()
    {
        // Mono implements GC.GetAllocatedBytesForCurrentThread (exact per-thread byte counter), so it is used
        // directly; GC.CollectionCount(0) is checked too.
        const int frames = 1000;
        using (var scene = new FrameScene(10, 8))
        {
            var head = new JointTransform(0f, 1.6f, 0f);
            for (int i = 0; i < 100; i++) scene.LayerFrame(head); // warm-up: JIT, static ctors
            int gen0 = GC.CollectionCount(0);
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < frames; i++) scene.LayerFrame(head);
            long after = GC.GetAllocatedBytesForCurrentThread();
            int collections = GC.CollectionCount(0) - gen0;
            long bytes = after - before;
            Console.WriteLine("     managed allocation: " + bytes + " bytes over " + frames + " frames of SetAnchors+Step+"
                              + "ReadWorld+ReadLocalRotations (10 chains x 8 joints) = " + ((double)bytes / frames)
                              + " bytes/frame, " + collections + " gen0 collections [GC.GetAllocatedBytesForCurrentThread]");

            // Positive control: the counter does see a small per-frame allocation.
            object sink = null;
            long controlBefore = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < frames; i++)
            {
                scene.LayerFrame(head);
                sink = new int[1];
            }
            long control = GC.GetAllocatedBytesForCurrentThread() - controlBefore;
            Console.WriteLine("     control (one int[1] per frame): " + control + " bytes" + (sink != null ? "" : "?"));
            Ensure(control >= frames * 4, "the allocation counter works");
            Ensure(bytes == 0, "zero managed bytes per frame, measured " + bytes);
            Ensure(collections == 0, "no garbage collection during the measured frames");
        }
    }

    static void PerCallOverhead()
    {
        const int chains = 100, joints = 8, frames = 2000, rounds = 3;
        var ratios = new List<double>();
        var layerTimes = new List<double>();
        var directTimes = new List<double>();
        var head = new JointTransform(0f, 1.6f, 0f);
        kdw_transform headRaw = *(kdw_transform*)&head;
        for (int round = 0; round < rounds; round++)
        {
            double layer, direct;
            using (var scene = new FrameScene(chains, joints))
            {
                scene.LayerFrame(head); // JIT
                var watch = Stopwatch.StartNew();
                for (int i = 0; i < frames; i++) scene.LayerFrame(head);
                layer = watch.Elapsed.TotalMilliseconds;
            }
            using (var scene = new FrameScene(chains, joints))
            {
                kdw_engine* engine = (kdw_engine*)scene.Engine.NativePointer;
                scene.DirectFrame(engine, &headRaw);
                var watch = Stopwatch.StartNew();
                for (int i = 0; i < frames; i++) scene.DirectFrame(engine, &headRaw);
                direct = watch.Elapsed.TotalMilliseconds;
            }
            layerTimes.Add(layer);
            directTimes.Add(direct);
            ratios.Add(layer / direct);
        }
        ratios.Sort();
        layerTimes.Sort();
        directTimes.Sort();
        double median = ratios[rounds / 2];
        Console.WriteLine("     overhead: " + chains + " chains x " + joints + " joints, " + frames + " frames, " + rounds
                          + " rounds: C# layer median " + layerTimes[rounds / 2].ToString("F1") + " ms, direct NativeMethods median "
                          + directTimes[rounds / 2].ToString("F1") + " ms, median ratio layer/direct = " + median.ToString("F4"));
        // Reported, not asserted tightly (timing on a shared machine): only a gross regression fails.
        Ensure(median < 2.0, "the C# layer costs less than twice the direct calls");

        // The wrapper cost alone: dt = 0 steps change nothing, so a frame is the four calls and the copies.
        // Alternating rounds, medians.
        const int callFrames = 20000, callRounds = 5;
        var layerCalls = new List<double>();
        var directCalls = new List<double>();
        using (var scene = new FrameScene(chains, joints))
        {
            var camera = new Vec3(0f, 1.7f, 2.5f);
            scene.NextInputs();
            kdw_engine* engine = (kdw_engine*)scene.Engine.NativePointer;
            for (int round = 0; round < callRounds; round++)
            {
                var watch = Stopwatch.StartNew();
                for (int i = 0; i < callFrames; i++)
                {
                    scene.Engine.SetAnchors(scene.Anchors);
                    scene.Engine.Step(0f, camera, head);
                    scene.Engine.ReadWorld(scene.World);
                    scene.Engine.ReadLocalRotations(scene.Local);
                }
                layerCalls.Add(watch.Elapsed.TotalMilliseconds * 1e6 / callFrames);
                uint written;
                watch = Stopwatch.StartNew();
                for (int i = 0; i < callFrames; i++)
                {
                    fixed (JointTransform* anchors = scene.Anchors)
                    fixed (JointTransform* world = scene.World)
                    fixed (Quat* local = scene.Local)
                    {
                        NativeMethods.kdw_engine_set_anchors(engine, (kdw_transform*)anchors, (uint)scene.Anchors.Length);
                        NativeMethods.kdw_engine_step(engine, 0f, (kdw_vec3*)&camera, &headRaw);
                        NativeMethods.kdw_engine_read_world(engine, (kdw_transform*)world, (uint)scene.World.Length, &written);
                        NativeMethods.kdw_engine_read_local_rotations(engine, (kdw_quat*)local, (uint)scene.Local.Length, &written);
                    }
                }
                directCalls.Add(watch.Elapsed.TotalMilliseconds * 1e6 / callFrames);
            }
        }
        layerCalls.Sort();
        directCalls.Sort();
        double layerCall = layerCalls[callRounds / 2], directCall = directCalls[callRounds / 2];
        Console.WriteLine("     call-only frame (dt = 0, 4 calls, 800 joints copied), median of " + callRounds + " rounds: C# layer "
                          + layerCall.ToString("F0") + " ns, direct " + directCall.ToString("F0") + " ns, difference "
                          + ((layerCall - directCall) / 4).ToString("F0") + " ns per call");
    }
}
