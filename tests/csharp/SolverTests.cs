// Tests of solver selection in the C# layer (bindings/csharp/Kodawari), run from Tests.Main: Engine.Solver round
// trips and is part of the state hash, an unknown value throws and changes nothing, four equal chains make one lane
// group (EngineStats.LaneChains 4) on the lane solvers and none on the scalar one, both lane solvers give the same
// bits, Library.SimdPath names the kernel, and reading or switching the solver per frame allocates nothing.
using System;
using Kodawari;

static unsafe class SolverTests
{
    const float Dt = 1f / 60f;
    const int Chains = 4, Joints = 8;

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

    /// <summary>An engine on <paramref name="solver"/> with four 8-joint chains standing up from the head, side by side,
    /// of different stiffness: one lane group of 4 on the lane solvers.</summary>
    static Engine Scene(Solver solver)
    {
        var engine = new Engine();
        Ensure(engine.Solver == Solver.Lanes, "the default solver is Lanes");
        engine.Solver = solver;
        Ensure(engine.Solver == solver, "solver round trip " + solver);
        for (int c = 0; c < Chains; c++)
        {
            var shape = new JointTransform[Joints];
            for (int j = 0; j < Joints; j++) shape[j] = new JointTransform(-0.06f + 0.04f * c, 0.1f + 0.05f * j, 0f);
            engine.CreateChain(new ChainDef { Stiffness = 0.3f + 0.2f * c }, shape);
        }
        return engine;
    }

    static JointTransform Head(int frame)
    {
        return new JointTransform(0.1f * (float)Math.Sin(0.2f * frame), 1.6f, 0f);
    }

    static bool SameBits(JointTransform[] a, JointTransform[] b)
    {
        if (a.Length != b.Length) return false;
        fixed (JointTransform* pa = a, pb = b)
        {
            var wa = (uint*)pa;
            var wb = (uint*)pb;
            for (int i = 0; i < a.Length * 7; i++)
                if (wa[i] != wb[i]) return false;
        }
        return true;
    }

    public static void SolverSelection()
    {
        string simd = Library.SimdPath;
        Ensure(simd == "avx512" || simd == "avx2" || simd == "sse2" || simd == "neon" || simd == "scalar", "SIMD path " + simd);
        Ensure(ReferenceEquals(simd, Library.SimdPath), "SIMD path read once");
        Ensure(!Library.PortableDeterminism, "the tests load the default build, without portable-determinism");

        var solvers = new[] { Solver.Lanes, Solver.LanesPortable, Solver.Scalar };
        var expectedLaneChains = new[] { Chains, Chains, 0 };
        var engines = new Engine[solvers.Length];
        try
        {
            for (int i = 0; i < solvers.Length; i++) engines[i] = Scene(solvers[i]);
            Ensure(engines[0].StateHash != engines[1].StateHash && engines[0].StateHash != engines[2].StateHash
                   && engines[1].StateHash != engines[2].StateHash, "the solver is part of the state hash");

            ulong before = engines[0].StateHash;
            var e = ExpectStatus(KodawariStatus.InvalidArgument, () => engines[0].Solver = (Solver)3);
            Ensure(e.NativeMessage.Contains("solver"), "message names the solver: " + e.Message);
            ExpectStatus(KodawariStatus.InvalidArgument, () => engines[0].Solver = (Solver)uint.MaxValue);
            Ensure(engines[0].StateHash == before && engines[0].Solver == Solver.Lanes, "rejected solver changed nothing");

            var camera = new Vec3(0f, 1.7f, 2.5f);
            for (int frame = 0; frame < 60; frame++)
            {
                for (int i = 0; i < engines.Length; i++)
                {
                    engines[i].Step(Dt, camera, Head(frame));
                    EngineStats stats = engines[i].Stats;
                    Ensure(stats.ChainCount == Chains && stats.ChainsAsleep == 0, "four awake chains");
                    Ensure(stats.LaneChains == expectedLaneChains[i],
                           solvers[i] + ": LaneChains " + stats.LaneChains + " == " + expectedLaneChains[i]);
                }
            }
            var worlds = new JointTransform[solvers.Length][];
            for (int i = 0; i < engines.Length; i++)
            {
                worlds[i] = new JointTransform[engines[i].JointCount];
                Ensure(engines[i].ReadWorld(worlds[i]) == Chains * Joints, "read world");
            }
            Ensure(SameBits(worlds[0], worlds[1]), "Lanes and LanesPortable give the same bits");
            Console.WriteLine("     simd path " + simd + "; lane chains " + engines[0].Stats.LaneChains + " / "
                              + engines[1].Stats.LaneChains + " / " + engines[2].Stats.LaneChains + " (lanes / portable / scalar)");
        }
        finally
        {
            foreach (var engine in engines)
                if (engine != null) engine.Dispose();
        }
    }

    public static void SolverCallsAllocateNothing()
    {
        const int frames = 1000;
        using (var engine = Scene(Solver.Lanes))
        {
            var camera = new Vec3(0f, 1.7f, 2.5f);
            int frame = 0, lanes = 0;
            Action oneFrame = () =>
            {
                engine.Solver = frame % 2 == 0 ? Solver.Lanes : Solver.Scalar;
                engine.Step(Dt, camera, Head(frame));
                if (engine.Solver == Solver.Lanes) lanes += engine.Stats.LaneChains;
                if (Library.SimdPath.Length == 0) throw new Exception("empty SIMD path");
                frame++;
            };
            for (int i = 0; i < 100; i++) oneFrame(); // warm-up: JIT, the cached SIMD path
            int gen0 = GC.CollectionCount(0);
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < frames; i++) oneFrame();
            long bytes = GC.GetAllocatedBytesForCurrentThread() - before;
            int collections = GC.CollectionCount(0) - gen0;
            Console.WriteLine("     managed allocation: " + bytes + " bytes over " + frames + " frames of Solver set/get + Step + "
                              + "Stats.LaneChains + SimdPath, " + collections + " gen0 collections");
            Ensure(lanes == Chains * (frames + 100) / 2, "every Lanes frame stepped the four chains in lanes: " + lanes);
            Ensure(bytes == 0, "zero managed bytes per frame, measured " + bytes);
            Ensure(collections == 0, "no garbage collection during the measured frames");
        }
    }
}
