// The C# snippet of bindings/csharp/README.md (between the markers, dedented), compiled and run by
// tests/csharp_bindings.rs, which also checks that the README shows exactly this text.
using System;
using Kodawari;

static class ReadmeSnippet
{
    public static void Run()
    {
        // --- README snippet begin ---
        using (var engine = new Engine(new EngineDef { SubstepRate = 240f }))
        {
            // An ahoge standing on the head (the view reference joint), in the head's frame.
            var baseShape = new JointTransform[6];
            var fromLeft = new JointTransform[6];
            for (int i = 0; i < 6; i++)
            {
                baseShape[i] = new JointTransform(0f, 0.12f + 0.03f * i, 0f);
                fromLeft[i] = new JointTransform(-0.01f * i * i, 0.12f + 0.025f * i, 0f);
            }
            ViewDependentPhysicalObject ahoge = engine.CreateChain(new ChainDef { Stiffness = 0.9f }, baseShape);
            ahoge.AddViewShape(new Vec3(-1f, 0f, 0f), fromLeft, 1f); // seen from the left, it curls left

            var head = new JointTransform(0f, 1.6f, 0f);
            var joints = new JointTransform[engine.JointCount];   // allocate once ...
            for (int frame = 0; frame < 120; frame++)              // ... then no allocation per frame
            {
                float angle = 2f * (float)Math.PI * frame / 120f;
                var camera = new Vec3(2.5f * (float)Math.Sin(angle), 1.7f, 2.5f * (float)Math.Cos(angle));
                engine.Step(1f / 60f, camera, head);
                engine.ReadWorld(joints);
            }
            Console.WriteLine("ahoge tip at " + joints[joints.Length - 1].Position);
        }
        // --- README snippet end ---
    }
}
