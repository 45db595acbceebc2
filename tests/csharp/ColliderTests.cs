// Tests of the collider, joint radius, teleport and scale API of the C# layer (bindings/csharp/Kodawari), run
// from Tests.Main: a limp chain draped over a sphere collider stays outside it, the per-frame collider update is
// one allocation-free call, wrong ids and values throw without changing the engine, teleports keep energy (carry)
// or equal a reset (reset mode), and scale is validated.
using System;
using Kodawari;

static class ColliderTests
{
    const int Joints = 8;
    const float BallRadius = 0.1f;

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
            Ensure(e.NativeMessage.Length > 0, "a native message comes with " + status);
            return e;
        }
        throw new Exception("expected a KodawariException with " + status);
    }

    static float Distance(Vec3 a, Vec3 b)
    {
        float x = a.X - b.X, y = a.Y - b.Y, z = a.Z - b.Z;
        return (float)Math.Sqrt(x * x + y * y + z * z);
    }

    static JointTransform[] Level()
    {
        var joints = new JointTransform[Joints];
        for (int j = 0; j < Joints; j++) joints[j] = new JointTransform(0.05f * j, 0f, 0f);
        return joints;
    }

    static float Closest(ViewDependentPhysicalObject chain, JointTransform[] world, Vec3 centre)
    {
        Ensure(chain.ReadWorld(world) == Joints, "one transform per joint");
        float closest = float.MaxValue;
        foreach (var joint in world) closest = Math.Min(closest, Distance(joint.Position, centre));
        return closest;
    }

    public static void CollidersKeepTheChainOut()
    {
        using (var engine = new Engine())
        {
            var chain = engine.CreateChain(new ChainDef { Stiffness = 0.02f, Damping = 3f, CollisionMask = 0x2u, Friction = 0.5f }, Level());
            Ensure(chain.Def.CollisionMask == 0x2u && chain.Def.Friction == 0.5f, "collision mask and friction round trip");
            chain.SetJointRadii(new float[Joints]); // the joints themselves must stay out
            var centre = new Vec3(0.2f, 0.82f, 0f);
            var ballDef = ColliderDef.Sphere(BallRadius, new JointTransform(centre, Quat.Identity));
            ballDef.Layers = 0x2u;
            Collider ball = engine.CreateCollider(ballDef);
            Collider far = engine.CreateCollider(ColliderDef.Capsule(0.05f, 0.1f, new JointTransform(5f, 0f, 0f)));
            Ensure(ball.IsValid && far.IsValid && !ball.Equals(far) && engine.ColliderCount == 2, "two colliders");
            Collider[] listed = engine.GetColliders();
            Ensure(listed.Length == 2 && listed[0].Equals(ball) && listed[1].Equals(far), "colliders in creation order");

            var anchor = new JointTransform(0f, 1f, 0f);
            var camera = new Vec3(0f, 1f, 3f);
            var poses = new[] { new JointTransform(centre, Quat.Identity), new JointTransform(5f, 0f, 0f) };
            var world = new JointTransform[Joints];
            float closest = 0f;
            for (int frame = 0; frame < 120; frame++)
            {
                engine.SetColliderTransforms(poses);
                engine.Step(1f / 60f, camera, anchor);
                closest = Closest(chain, world, centre);
                Ensure(closest >= BallRadius - 1e-4f, "frame " + frame + ": a joint " + closest + " m from the ball's centre");
            }
            // Segments collide too: resting joints may sit up to sqrt(0.1^2 + 0.025^2) - 0.1 = 3.1 mm out.
            Ensure(closest < BallRadius + 3.5e-3f, "the chain rests on the ball: " + closest);
            EngineStats stats = engine.Stats;
            Ensure(stats.ColliderCount == 2 && stats.ContactPairsTested > 0, "stats count colliders and contact tests");

            ulong before = engine.StateHash;
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.SetColliderTransforms(new JointTransform[1]));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.SetColliderTransforms(new JointTransform[3]));
            var broken = (JointTransform[])poses.Clone();
            broken[1].Position.Y = float.NaN;
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.SetColliderTransforms(broken));
            broken[1] = new JointTransform(new Vec3(5f, 0f, 0f), new Quat(0f, 0f, 0f, 0f));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.SetColliderTransforms(broken));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.CreateCollider(ColliderDef.Capsule(0f, 0f, anchor)));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.CreateCollider(ColliderDef.Sphere(-0.1f, anchor)));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.CreateCollider(new ColliderDef { Shape = ColliderShape.InsideSphere, Radius = 0f }));
            ExpectStatus(KodawariStatus.InvalidArgument, () => engine.CreateCollider(new ColliderDef { Shape = (ColliderShape)7 }));
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.SetJointRadii(new float[Joints - 1]));
            var nanRadii = new float[Joints];
            nanRadii[3] = float.NaN;
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.SetJointRadii(nanRadii));
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.Def = new ChainDef { Friction = 11f });
            ExpectStatus(KodawariStatus.InvalidArgument, () => chain.Def = new ChainDef { Friction = float.NaN });
            Ensure(engine.StateHash == before, "rejected calls leave the engine as it was");

            // Off the chain's layers, the ball no longer holds it.
            ball.SetLayers(0x4u);
            float lowest = float.MaxValue;
            for (int frame = 0; frame < 60; frame++)
            {
                engine.Step(1f / 60f, camera, anchor);
                lowest = Math.Min(lowest, Closest(chain, world, centre));
            }
            Ensure(lowest < BallRadius - 0.02f, "the chain falls through a ball on other layers: " + lowest);

            far.Destroy();
            Ensure(!far.IsValid && engine.ColliderCount == 1, "destroyed collider is stale");
            ExpectStatus(KodawariStatus.InvalidId, () => far.SetLayers(1u));
            ExpectStatus(KodawariStatus.InvalidId, () => far.Destroy());
            ExpectStatus(KodawariStatus.InvalidId, () => default(Collider).Destroy());
            // A collider id is no chain id and vice versa.
            ExpectStatus(KodawariStatus.InvalidId, () => new ViewDependentPhysicalObject(engine, ball.Id).Teleport());
            ExpectStatus(KodawariStatus.InvalidId, () => new Collider(engine, chain.Id).Destroy());
            using (var stranger = new Engine())
                ExpectStatus(KodawariStatus.InvalidId, () => new Collider(stranger, ball.Id).SetLayers(1u));
            ball.Destroy();
            Ensure(engine.ColliderCount == 0 && engine.GetColliders().Length == 0, "no colliders left");
            engine.SetColliderTransforms(new JointTransform[0]);
            chain.SetJointRadii(new float[0]); // back to ChainDef.Radius
        }
    }

    public static void ColliderUpdateAllocatesNothing()
    {
        using (var engine = new Engine())
        {
            engine.CreateChain(null, Level());
            var poses = new JointTransform[16];
            for (int c = 0; c < poses.Length; c++) engine.CreateCollider(ColliderDef.Sphere(0.05f, new JointTransform(0.1f * c, 0.5f, 0f)));
            var head = new JointTransform(0f, 1f, 0f);
            var camera = new Vec3(0f, 1f, 3f);
            for (int frame = 0; frame < 1100; frame++)
            {
                if (frame == 100) Measure.Start();
                for (int c = 0; c < poses.Length; c++) poses[c] = new JointTransform(0.1f * c, 0.5f + 0.001f * (frame % 50), 0f);
                engine.SetColliderTransforms(poses);
                engine.Step(1f / 60f, camera, head);
            }
            long bytes = Measure.Stop();
            Console.WriteLine("     collider update: " + bytes + " managed bytes over 1000 frames of SetColliderTransforms(16)+Step");
            Ensure(bytes == 0, "zero managed bytes per frame, measured " + bytes);
        }
    }

    static class Measure
    {
        static long start;
        public static void Start() { start = GC.GetAllocatedBytesForCurrentThread(); }
        public static long Stop() { return GC.GetAllocatedBytesForCurrentThread() - start; }
    }

    static JointTransform Head(int frame, float jumpX)
    {
        int swing = frame < 15 ? frame : 14; // swings, then holds still while the chain keeps moving
        return new JointTransform(0.1f * (float)Math.Sin(0.4f * swing) + (frame >= 20 ? jumpX : 0f), 1.6f, 0f);
    }

    public static void TeleportsAndScale()
    {
        var hanging = new JointTransform[6];
        for (int j = 0; j < hanging.Length; j++) hanging[j] = new JointTransform(0.08f, -0.04f * j, 0.02f);
        // Carry mode: a 100 m jump with Teleport() keeps the chain's energy; the same jump without it whips it.
        var carry = new EngineDef { TeleportDistance = float.MaxValue };
        Ensure(carry.TeleportMode == TeleportMode.CarryShape && carry.Scale == 1f, "defaults: carry shape, scale 1");
        using (var jumper = new Engine(carry))
        using (var still = new Engine(carry))
        using (var whipped = new Engine(carry))
        {
            var a = jumper.CreateChain(null, hanging);
            var b = still.CreateChain(null, hanging);
            var c = whipped.CreateChain(null, hanging);
            for (int frame = 0; frame < 40; frame++)
            {
                if (frame == 20) jumper.Teleport();
                var camera = new Vec3(frame >= 20 ? 100f : 0f, 1.7f, 3f);
                jumper.Step(1f / 60f, camera, Head(frame, 100f));
                still.Step(1f / 60f, new Vec3(0f, 1.7f, 3f), Head(frame, 0f));
                whipped.Step(1f / 60f, camera, Head(frame, 100f));
                if (frame < 20) continue;
                float expected = b.KineticEnergy;
                Ensure(Math.Abs(a.KineticEnergy - expected) <= 1e-3f * expected + 1e-7f,
                       "frame " + frame + ": carried energy " + a.KineticEnergy + " vs " + expected);
                if (frame == 20)
                {
                    Ensure(expected > 1e-6f, "the chain was still moving: the comparison means something");
                    Ensure(c.KineticEnergy > 1000f * expected, "without Teleport() the jump whips the chain");
                }
            }
        }
        // Reset mode: Teleport() does what Reset() does at the same step.
        var resetMode = new EngineDef { TeleportDistance = float.MaxValue, TeleportMode = TeleportMode.Reset };
        using (var teleported = new Engine(resetMode))
        using (var reset = new Engine(resetMode))
        {
            Ensure(teleported.Def.TeleportMode == TeleportMode.Reset, "teleport mode round trip");
            var a = teleported.CreateChain(null, hanging);
            var b = reset.CreateChain(null, hanging);
            for (int frame = 0; frame < 40; frame++)
            {
                if (frame == 20)
                {
                    teleported.Teleport();
                    reset.Reset();
                }
                if (frame == 30)
                {
                    a.Teleport();
                    b.Reset();
                }
                var camera = new Vec3(0f, 1.7f, 3f);
                teleported.Step(1f / 60f, camera, Head(frame, 2f));
                reset.Step(1f / 60f, camera, Head(frame, 2f));
                Ensure(teleported.StateHash == reset.StateHash, "frame " + frame + ": teleport (reset mode) == reset");
            }
        }
        // Scale: validated, stored.
        foreach (float bad in new[] { 0f, -1f, 1e7f, float.NaN, float.PositiveInfinity })
            ExpectStatus(KodawariStatus.InvalidArgument, () => new Engine(new EngineDef { Scale = bad }));
        ExpectStatus(KodawariStatus.InvalidArgument, () => new Engine(new EngineDef { TeleportMode = (TeleportMode)2 }));
        using (var large = new Engine(new EngineDef { Scale = 100f }))
        {
            Ensure(large.Def.Scale == 100f, "scale round trip");
            ExpectStatus(KodawariStatus.InvalidArgument, () => large.Def = new EngineDef { Scale = float.NaN });
            Ensure(large.Def.Scale == 100f, "a rejected def changes nothing");
        }
    }
}
