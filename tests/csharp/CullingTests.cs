// Tests of culling, sleeping, level of detail, batch stepping and collider resizing in the C# layer
// (bindings/csharp/Kodawari), run from Tests.Main: a disabled chain rides rigidly with its anchor and is counted
// by the stats, a damped chain settles and sleeps, Engine.StepMany equals single steps (and rejects repeated or
// null engines without moving any), a grown sphere pushes a draped chain out, and a frame of StepMany plus the
// culling and LOD calls allocates no managed memory.
using System;
using Kodawari;

static class CullingTests
{
    const float Dt = 1f / 60f;

    static void Ensure(bool condition, string what)
    {
        if (!condition) throw new Exception("check failed: " + what);
    }

    static KodawariException ExpectStatus(KodawariStatus status, Action call)
    {
        try
        {
            call();
        }
        catch (KodawariException e)
        {
            Ensure(e.Status == status, "status " + e.Status + " == " + status + " (" + e.Message + ")");
            return e;
        }
        throw new Exception("expected a KodawariException with " + status);
    }

    // ---- small rigid-transform helpers ----

    static Quat Conjugate(Quat q) { return new Quat(-q.X, -q.Y, -q.Z, q.W); }

    static Quat Multiply(Quat a, Quat b)
    {
        return new Quat(a.W * b.X + a.X * b.W + a.Y * b.Z - a.Z * b.Y, a.W * b.Y - a.X * b.Z + a.Y * b.W + a.Z * b.X,
                        a.W * b.Z + a.X * b.Y - a.Y * b.X + a.Z * b.W, a.W * b.W - a.X * b.X - a.Y * b.Y - a.Z * b.Z);
    }

    static Vec3 Rotate(Quat q, Vec3 v)
    {
        Quat p = Multiply(Multiply(q, new Quat(v.X, v.Y, v.Z, 0f)), Conjugate(q));
        return new Vec3(p.X, p.Y, p.Z);
    }

    /// <summary><paramref name="world"/>'s position in the rigid frame <paramref name="frame"/>.</summary>
    static Vec3 PositionIn(JointTransform frame, JointTransform world)
    {
        var offset = new Vec3(world.Position.X - frame.Position.X, world.Position.Y - frame.Position.Y,
                              world.Position.Z - frame.Position.Z);
        return Rotate(Conjugate(frame.Rotation), offset);
    }

    static float Distance(Vec3 a, Vec3 b)
    {
        float x = a.X - b.X, y = a.Y - b.Y, z = a.Z - b.Z;
        return (float)Math.Sqrt(x * x + y * y + z * z);
    }

    /// <summary>A bone swinging sideways, turning about Y and drifting forward: its pose at frame <paramref name="frame"/>.</summary>
    static JointTransform MovingAnchor(int frame)
    {
        float t = frame * Dt;
        float angle = 0.6f * (float)Math.Sin(2f * t);
        return new JointTransform(new Vec3(0.4f * (float)Math.Sin(3f * t), 1.6f + 0.1f * t, 0.2f * t),
                                  new Quat(0f, (float)Math.Sin(0.5f * angle), 0f, (float)Math.Cos(0.5f * angle)));
    }

    static JointTransform[] Hanging(int joints, float x)
    {
        var shape = new JointTransform[joints];
        for (int j = 0; j < joints; j++) shape[j] = new JointTransform(x + 0.01f * j * j, -0.04f * j, 0f);
        return shape;
    }

    // ---- tests ----

    public static void DisabledChainRidesWithItsAnchor()
    {
        using (var engine = new Engine())
        {
            var def = new ChainDef { Stiffness = 0.3f, Anchor = AnchorSource.Own };
            var culled = engine.CreateChain(def, Hanging(6, 0f));
            var active = engine.CreateChain(def, Hanging(6, 0.1f));
            Ensure(culled.Enabled && active.Enabled && !culled.IsAsleep, "chains start enabled and awake");
            var camera = new Vec3(0f, 1.7f, 2.5f);
            var anchors = new JointTransform[2];
            int frame = 0;
            for (; frame < 30; frame++)
            {
                anchors[0] = anchors[1] = MovingAnchor(frame);
                engine.SetAnchors(anchors);
                engine.Step(Dt, camera, MovingAnchor(frame));
            }
            Ensure(culled.KineticEnergy > 1e-3f, "swinging when culled");

            culled.Enabled = false;
            Ensure(!culled.Enabled && active.Enabled, "only the culled chain is disabled");
            var frozen = new JointTransform[6];
            var world = new JointTransform[6];
            culled.ReadWorld(frozen);
            var frozenRelative = new Vec3[6];
            for (int j = 0; j < 6; j++) frozenRelative[j] = PositionIn(MovingAnchor(frame - 1), frozen[j]);
            float worst = 0f;
            for (int end = frame + 60; frame < end; frame++)
            {
                anchors[0] = anchors[1] = MovingAnchor(frame);
                engine.SetAnchors(anchors);
                engine.Step(Dt, camera, MovingAnchor(frame));
                Ensure(culled.ReadWorld(world) == 6, "six joints");
                for (int j = 0; j < 6; j++) worst = Math.Max(worst, Distance(PositionIn(MovingAnchor(frame), world[j]), frozenRelative[j]));
                Ensure(engine.Stats.ChainsAsleep == 1, "the culled chain is counted as costing nothing");
                Ensure(!active.IsAsleep, "the other chain swings");
            }
            Console.WriteLine("     culled for 1 s while its anchor moved " + Distance(MovingAnchor(frame - 1).Position, MovingAnchor(29).Position)
                              + " m: pose relative to the anchor kept within " + worst + " m");
            Ensure(worst < 2e-6f, "rides rigidly with its anchor: " + worst);
            culled.Enabled = true;
            Ensure(culled.Enabled, "enabled again");
            engine.SetAnchors(anchors);
            engine.Step(Dt, camera, MovingAnchor(frame));
            Ensure(engine.Stats.ChainsAsleep == 0, "simulated again");
            culled.Destroy();
            ExpectStatus(KodawariStatus.InvalidId, () => culled.Enabled = false);
            ExpectStatus(KodawariStatus.InvalidId, () => { bool unused = culled.IsAsleep; });
        }
    }

    public static void SettledChainSleepsAndLod()
    {
        var def = new EngineDef();
        Ensure(def.SleepSpeed == 5e-6f && def.Lod == 0, "sleep and LOD defaults");
        using (var sleeper = new Engine(def))
        using (var awake = new Engine(new EngineDef { SleepSpeed = 0f }))
        {
            Ensure(awake.Def.SleepSpeed == 0f, "sleep speed round trip");
            var chainDef = new ChainDef { Stiffness = 0.9f, Damping = 5f };
            var a = sleeper.CreateChain(chainDef, Hanging(6, 0f));
            var b = awake.CreateChain(chainDef, Hanging(6, 0f));
            var head = new JointTransform(0f, 1.6f, 0f);
            var camera = new Vec3(0f, 1.7f, 2.5f);
            int fellAsleep = -1;
            for (int frame = 0; frame < 300; frame++)
            {
                sleeper.Step(Dt, camera, head);
                awake.Step(Dt, camera, head);
                if (fellAsleep < 0 && a.IsAsleep) fellAsleep = frame;
                Ensure(!b.IsAsleep, "sleep speed 0 never sleeps");
            }
            Console.WriteLine("     damping 5: asleep after " + ((fellAsleep + 1) * Dt) + " s");
            Ensure(fellAsleep > 0 && a.IsAsleep && sleeper.Stats.ChainsAsleep == 1 && awake.Stats.ChainsAsleep == 0, "settled chain sleeps");
            sleeper.Step(Dt, camera, new JointTransform(0.05f, 1.6f, 0f));
            Ensure(!a.IsAsleep && sleeper.Stats.ChainsAsleep == 0, "a moving anchor wakes it");

            Ensure(sleeper.Lod == 0, "LOD 0");
            sleeper.Lod = 3;
            Ensure(sleeper.Lod == 3 && sleeper.Def.Lod == 3, "LOD set through the engine");
            sleeper.Step(Dt, camera, head);
            Ensure(sleeper.Stats.SubstepsLastStep <= 1, "LOD 3 steps at 30 Hz");
            ulong hash = sleeper.StateHash;
            ExpectStatus(KodawariStatus.InvalidArgument, () => sleeper.Lod = 4);
            ExpectStatus(KodawariStatus.InvalidArgument, () => sleeper.Def = new EngineDef { SleepSpeed = -1f });
            Ensure(sleeper.StateHash == hash && sleeper.Lod == 3, "rejected settings change nothing");
        }
    }

    static Engine[] Scenes(int count)
    {
        var engines = new Engine[count];
        for (int i = 0; i < count; i++)
        {
            engines[i] = new Engine();
            var chain = engines[i].CreateChain(new ChainDef { Stiffness = 0.3f + 0.15f * (i % 4), Damping = 1f + 0.1f * i }, Hanging(6, 0f));
            chain.AddViewShape(new Vec3(1f, 0f, 0f), Hanging(6, 0.02f), 1f);
        }
        return engines;
    }

    static Vec3 FillHeads(JointTransform[] heads, int frame)
    {
        for (int i = 0; i < heads.Length; i++)
            heads[i] = new JointTransform(i + 0.1f * (float)Math.Sin(0.2f * frame), 1.6f, 0f);
        float angle = 6.2831853f * frame / 240f;
        return new Vec3(2.5f * (float)Math.Sin(angle), 1.7f, 2.5f * (float)Math.Cos(angle));
    }

    public static void StepManyEqualsSingleSteps()
    {
        const int count = 4;
        Engine[] batched = Scenes(count), single = Scenes(count);
        try
        {
            var heads = new JointTransform[count];
            for (int frame = 0; frame < 90; frame++)
            {
                Vec3 camera = FillHeads(heads, frame);
                Engine.StepMany(batched, Dt, camera, heads);
                for (int i = 0; i < count; i++) single[i].Step(Dt, camera, heads[i]);
            }
            var hashes = new ulong[count];
            for (int i = 0; i < count; i++)
            {
                hashes[i] = batched[i].StateHash;
                Ensure(hashes[i] == single[i].StateHash, "engine " + i + ": batch step == single steps");
                if (i > 0) Ensure(hashes[i] != hashes[i - 1], "four different scenes");
            }

            Vec3 next = FillHeads(heads, 90);
            ExpectStatus(KodawariStatus.InvalidArgument,
                () => Engine.StepMany(new[] { batched[0], batched[1], batched[2], batched[0] }, Dt, next, heads));
            ExpectStatus(KodawariStatus.NullPointer,
                () => Engine.StepMany(new[] { batched[0], null, batched[2], batched[3] }, Dt, next, heads));
            ExpectStatus(KodawariStatus.InvalidArgument, () => Engine.StepMany(batched, Dt, next, new JointTransform[3]));
            ExpectStatus(KodawariStatus.InvalidArgument, () => Engine.StepMany(batched, float.NaN, next, heads));
            for (int i = 0; i < count; i++) Ensure(batched[i].StateHash == hashes[i], "rejected batch moved nothing");

            Engine.StepMany(new Engine[0], Dt, next, new JointTransform[0]);
            Engine.StepMany(new ReadOnlySpan<Engine>(batched, 0, 2), Dt, next, new ReadOnlySpan<JointTransform>(heads, 0, 2));
            Ensure(batched[1].StateHash != hashes[1] && batched[2].StateHash == hashes[2], "a prefix steps only its engines");
            var disposed = new Engine();
            disposed.Dispose();
            Expect<ObjectDisposedException>(() => Engine.StepMany(new[] { disposed }, Dt, next, new JointTransform[1]));

            // More engines than the stack scratch holds.
            Engine[] many = Scenes(70);
            try
            {
                var manyHeads = new JointTransform[many.Length];
                FillHeads(manyHeads, 0);
                Engine.StepMany(many, Dt, next, manyHeads);
                Ensure(many[69].Stats.SubstepsTotal > 0 && many[0].Stats.SubstepsTotal > 0, "70 engines stepped");
            }
            finally
            {
                foreach (var engine in many) engine.Dispose();
            }
        }
        finally
        {
            foreach (var engine in batched) engine.Dispose();
            foreach (var engine in single) engine.Dispose();
        }
    }

    static void Expect<T>(Action call) where T : Exception
    {
        try
        {
            call();
        }
        catch (T)
        {
            return;
        }
        throw new Exception("expected " + typeof(T).Name);
    }

    public static void ColliderSetSizePushesTheChainOut()
    {
        using (var engine = new Engine())
        {
            var level = new JointTransform[8];
            for (int j = 0; j < 8; j++) level[j] = new JointTransform(0.05f * j, 0f, 0f);
            var chain = engine.CreateChain(new ChainDef { Stiffness = 0.02f, Damping = 3f }, level);
            chain.SetJointRadii(new float[8]);
            var centre = new Vec3(0.2f, 0.82f, 0f);
            Collider ball = engine.CreateCollider(ColliderDef.Sphere(0.1f, new JointTransform(centre, Quat.Identity)));
            var anchor = new JointTransform(0f, 1f, 0f);
            var camera = new Vec3(0f, 1f, 3f);
            var world = new JointTransform[8];
            Func<float> settle = () =>
            {
                float closest = 0f;
                for (int frame = 0; frame < 120; frame++)
                {
                    engine.Step(Dt, camera, anchor);
                    chain.ReadWorld(world);
                    closest = float.MaxValue;
                    foreach (var joint in world) closest = Math.Min(closest, Distance(joint.Position, centre));
                }
                return closest;
            };
            float small = settle();
            ulong hash = engine.StateHash;
            ExpectStatus(KodawariStatus.InvalidArgument, () => ball.SetSize(-0.1f, 0f));
            ExpectStatus(KodawariStatus.InvalidArgument, () => ball.SetSize(float.PositiveInfinity, 0f));
            Ensure(engine.StateHash == hash, "rejected sizes change nothing");
            ball.SetSize(0.15f, 0f);
            float large = settle();
            Console.WriteLine("     ball radius 0.10 -> 0.15: closest joint " + small + " -> " + large + " m from its centre");
            Ensure(small >= 0.1f - 1e-4f && small < 0.1f + 3.5e-3f, "rests on the small ball: " + small);
            Ensure(large >= 0.15f - 1e-4f && large < 0.15f + 5e-3f, "pushed out to the grown ball: " + large);
            ball.Destroy();
            ExpectStatus(KodawariStatus.InvalidId, () => ball.SetSize(0.1f, 0f));
        }
    }

    public static void BatchAndCullingAllocateNothing()
    {
        const int frames = 1000;
        Engine[] engines = Scenes(4);
        try
        {
            var heads = new JointTransform[engines.Length];
            var chain = engines[1].GetChains()[0];
            var ball = engines[2].CreateCollider(ColliderDef.Sphere(0.05f, new JointTransform(5f, 0f, 0f)));
            var poses = new[] { new JointTransform(5f, 0f, 0f) };
            int frame = 0;
            Action oneFrame = null;
            oneFrame = () =>
            {
                Vec3 camera = FillHeads(heads, frame);
                chain.Enabled = frame % 50 < 25; // culled half the time
                if (frame % 100 == 0) engines[3].Lod = (engines[3].Lod + 1) % 4;
                if (frame % 10 == 0) ball.SetSize(0.05f + 0.001f * (frame % 7), 0f);
                engines[2].SetColliderTransforms(poses);
                Engine.StepMany(engines, Dt, camera, heads);
                bool asleep = chain.IsAsleep;
                int idle = engines[1].Stats.ChainsAsleep;
                if (asleep && idle == 0) throw new Exception("an asleep chain must be counted");
                frame++;
            };
            for (int i = 0; i < 100; i++) oneFrame(); // warm-up: JIT, thread statics
            int gen0 = GC.CollectionCount(0);
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < frames; i++) oneFrame();
            long bytes = GC.GetAllocatedBytesForCurrentThread() - before;
            int collections = GC.CollectionCount(0) - gen0;
            Console.WriteLine("     managed allocation: " + bytes + " bytes over " + frames + " frames of StepMany (4 engines) + "
                              + "Enabled/IsAsleep/Lod/SetSize, " + collections + " gen0 collections");
            Ensure(bytes == 0, "zero managed bytes per frame, measured " + bytes);
            Ensure(collections == 0, "no garbage collection during the measured frames");
        }
        finally
        {
            foreach (var engine in engines) engine.Dispose();
        }
    }
}
