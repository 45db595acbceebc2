// C# tests of the sketch wrapper (Kodawari.Sketch, Kodawari.StrokeCamera) and of
// ViewDependentPhysicalObject.ReadWeights, run from Tests.Main. Cameras are given the way Unity gives them
// (looking along local +Z, StrokeCamera.FromUnityStyle*) and the C way (-Z); strokes are made by projecting
// a known, reachable shape through the same camera.
using System;
using Kodawari;

static class SketchTests
{
    const int Joints = 8;
    const float Segment = 0.04f;
    const double OnStrokePixels = 0.5;
    const double LengthTolerance = 1e-5;

    static readonly Vec3 HeadPosition = new Vec3(0f, 1.6f, 0f);

    // ---- helpers ----

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
        throw new Exception("expected KodawariException " + status);
    }

    static Vec3 Add(Vec3 a, Vec3 b) { return new Vec3(a.X + b.X, a.Y + b.Y, a.Z + b.Z); }
    static Vec3 Sub(Vec3 a, Vec3 b) { return new Vec3(a.X - b.X, a.Y - b.Y, a.Z - b.Z); }
    static Vec3 Scale(Vec3 a, float s) { return new Vec3(a.X * s, a.Y * s, a.Z * s); }
    static double Length(Vec3 a) { return Math.Sqrt((double)a.X * a.X + (double)a.Y * a.Y + (double)a.Z * a.Z); }
    static double Distance(Vec3 a, Vec3 b) { return Length(Sub(a, b)); }
    static Vec3 Normalize(Vec3 a) { return Scale(a, (float)(1.0 / Length(a))); }

    static Quat Mul(Quat a, Quat b)
    {
        return new Quat(a.W * b.X + a.X * b.W + a.Y * b.Z - a.Z * b.Y, a.W * b.Y - a.X * b.Z + a.Y * b.W + a.Z * b.X,
                        a.W * b.Z + a.X * b.Y - a.Y * b.X + a.Z * b.W, a.W * b.W - a.X * b.X - a.Y * b.Y - a.Z * b.Z);
    }

    static Quat Conjugate(Quat q) { return new Quat(-q.X, -q.Y, -q.Z, q.W); }

    static Quat AxisAngle(Vec3 axis, float angle)
    {
        Vec3 n = Normalize(axis);
        float s = (float)Math.Sin(0.5 * angle);
        return new Quat(n.X * s, n.Y * s, n.Z * s, (float)Math.Cos(0.5 * angle));
    }

    static Vec3 Rotate(Quat q, Vec3 v)
    {
        var u = new Vec3(q.X, q.Y, q.Z);
        var uv = new Vec3(u.Y * v.Z - u.Z * v.Y, u.Z * v.X - u.X * v.Z, u.X * v.Y - u.Y * v.X);
        Vec3 t = Scale(uv, 2f);
        var ut = new Vec3(u.Y * t.Z - u.Z * t.Y, u.Z * t.X - u.X * t.Z, u.X * t.Y - u.Y * t.X);
        return Add(Add(v, Scale(t, q.W)), ut);
    }

    // ---- scene ----

    /// 8 joints from the top of the head, Segment apart, first along `first`, each next one turned by `bend`
    /// about `axis`; rotations carry a twist that changes along the chain.
    static JointTransform[] Curled(Vec3 first, Vec3 axis, float bend)
    {
        var joints = new JointTransform[Joints];
        Quat turn = AxisAngle(axis, bend);
        Vec3 dir = Normalize(first);
        Vec3 p = Add(HeadPosition, new Vec3(0f, 0.12f, 0f));
        for (int j = 0; j < Joints; j++)
        {
            joints[j] = new JointTransform(p, AxisAngle(new Vec3(0f, 1f, 0f), 0.3f * j));
            p = Add(p, Scale(dir, Segment));
            if (j + 2 < Joints) dir = Normalize(Rotate(turn, dir));
        }
        return joints;
    }

    static JointTransform[] Straight() { return Curled(new Vec3(0f, 1f, 0f), new Vec3(0f, 0f, 1f), 0f); }

    static JointTransform[] Target() { return Curled(new Vec3(0.2f, 1f, 0.3f), new Vec3(1f, 0f, -0.6f), 0.35f); }

    /// The head, turned a little: the anchor and view reference of the chain (a non-identity frame).
    static JointTransform Head() { return new JointTransform(HeadPosition, AxisAngle(new Vec3(0.3f, 1f, -0.2f), 0.4f)); }

    /// Camera i of 8: 0-2 perspective and 3-5 orthographic given Unity-style (looking along local +Z), 6-7 the
    /// default C convention (-Z), perspective and orthographic. Each looks at a point above the head from 1.5 m.
    static StrokeCamera CameraAt(int i)
    {
        float[] yaw = { 0f, 1.2f, -2.4f };
        float[] pitch = { 0.1f, 0.5f, -0.2f };
        Vec3 centre = Add(HeadPosition, new Vec3(0f, 0.2f, 0f));
        Quat q = Mul(AxisAngle(new Vec3(0f, 1f, 0f), yaw[i % 3]), AxisAngle(new Vec3(1f, 0f, 0f), pitch[i % 3]));
        if (i < 6)
        {
            // Unity: the camera looks along rotation * (0, 0, 1).
            Vec3 position = Sub(centre, Rotate(q, new Vec3(0f, 0f, 1.5f)));
            return i < 3
                ? StrokeCamera.FromUnityStyle(position, q, 0.8f, 800f, 600f)
                : StrokeCamera.FromUnityStyleOrthographic(position, q, 0.35f, 800f, 600f);
        }
        var camera = new StrokeCamera
        {
            Position = Add(centre, Rotate(q, new Vec3(0f, 0f, 1.5f))),
            Rotation = q,
            VerticalFov = 0.8f,
            OrthographicHalfHeight = 0.35f,
            ViewportWidth = 800f,
            ViewportHeight = 600f,
        };
        if (i == 7) camera.Projection = StrokeProjection.Orthographic;
        return camera;
    }

    const int Cameras = 8;

    static Vec2[] Project(StrokeCamera camera, JointTransform[] joints)
    {
        var pixels = new Vec2[joints.Length];
        for (int j = 0; j < joints.Length; j++) pixels[j] = camera.Project(joints[j].Position);
        return pixels;
    }

    /// `points` with every segment split in `parts`.
    static Vec2[] Densify(Vec2[] points, int parts)
    {
        var output = new Vec2[(points.Length - 1) * parts + 1];
        int written = 0;
        output[written++] = points[0];
        for (int i = 0; i + 1 < points.Length; i++)
            for (int k = 1; k <= parts; k++)
            {
                float t = (float)k / parts;
                output[written++] = new Vec2(points[i].X + (points[i + 1].X - points[i].X) * t,
                                             points[i].Y + (points[i + 1].Y - points[i].Y) * t);
            }
        return output;
    }

    static double DistanceToPolyline(Vec2 p, Vec2[] line)
    {
        double best = double.PositiveInfinity;
        for (int i = 0; i + 1 < line.Length; i++)
        {
            double ax = line[i].X, ay = line[i].Y;
            double bx = line[i + 1].X - ax, by = line[i + 1].Y - ay;
            double length2 = bx * bx + by * by;
            double t = length2 > 0.0 ? ((p.X - ax) * bx + (p.Y - ay) * by) / length2 : 0.0;
            t = Math.Max(0.0, Math.Min(1.0, t));
            double dx = p.X - (ax + bx * t), dy = p.Y - (ay + by * t);
            best = Math.Min(best, Math.Sqrt(dx * dx + dy * dy));
        }
        return best;
    }

    static Vec3 ToWorld(JointTransform frame, Vec3 local) { return Add(frame.Position, Rotate(frame.Rotation, local)); }

    // ---- tests ----

    /// The camera conventions: the default looks along -Z, Unity-style along +Z; y grows downwards.
    public static void CameraDefaultsAndProjection()
    {
        var camera = new StrokeCamera();
        Ensure(camera.Projection == StrokeProjection.Perspective && camera.ForwardAxis == CameraForwardAxis.NegativeZ,
               "default perspective, looking along -Z");
        Ensure(Math.Abs(camera.VerticalFov - 1.04719755f) < 1e-6 && camera.ViewportWidth == 1920f && camera.ViewportHeight == 1080f
               && camera.OrthographicHalfHeight == 5f && camera.Rotation.Equals(Quat.Identity), "defaults from kdw_stroke_camera_default");
        Vec2 centre = camera.Project(new Vec3(0f, 0f, -2f));
        Ensure(Math.Abs(centre.X - 960f) < 1e-3 && Math.Abs(centre.Y - 540f) < 1e-3, "straight ahead is the centre: " + centre);
        Ensure(camera.Project(new Vec3(0f, 0.5f, -2f)).Y < 540f, "up is smaller y");
        Ensure(camera.Project(new Vec3(0.5f, 0f, -2f)).X > 960f, "right is larger x");
        Vec2 unused;
        Ensure(!camera.TryProject(new Vec3(0f, 0f, 2f), out unused), "behind the eye has no pixel");
        ExpectStatus(KodawariStatus.InvalidArgument, () => camera.Project(new Vec3(0f, 0f, 2f)));

        // Unity: transform.position / rotation as they are, looking along +Z; 60° in radians.
        var unity = StrokeCamera.FromUnityStyle(new Vec3(0f, 1f, -3f), Quat.Identity, 60f * (float)Math.PI / 180f, 1280f, 720f);
        Ensure(unity.ForwardAxis == CameraForwardAxis.PositiveZ, "Unity cameras look along +Z");
        Vec2 ahead = unity.Project(new Vec3(0f, 1f, 0f));
        Ensure(Math.Abs(ahead.X - 640f) < 1e-3 && Math.Abs(ahead.Y - 360f) < 1e-3, "Unity camera centre: " + ahead);
        Ensure(unity.Project(new Vec3(0.5f, 1f, 0f)).X > 640f, "Unity: +X is screen right");
        // 30° half-angle: a point 1 m off axis at depth sqrt(3) m is at the top edge.
        Vec2 top = unity.Project(new Vec3(0f, 2f, (float)Math.Sqrt(3.0) - 3f));
        Ensure(Math.Abs(top.Y) < 1e-2, "vertical field of view in radians: " + top);

        var ortho = StrokeCamera.FromUnityStyleOrthographic(new Vec3(0f, 0f, -10f), Quat.Identity, 2f, 400f, 200f);
        Ensure(ortho.Projection == StrokeProjection.Orthographic && ortho.OrthographicHalfHeight == 2f, "orthographic size");
        Vec2 edge = ortho.Project(new Vec3(0f, -2f, 50f));
        Ensure(Math.Abs(edge.X - 200f) < 1e-3 && Math.Abs(edge.Y - 200f) < 1e-3, "orthographic: half-height 2 m is the bottom edge: " + edge);
        ExpectStatus(KodawariStatus.InvalidArgument, () => StrokeCamera.FromUnityStyle(new Vec3(0f, 0f, 0f), Quat.Identity, 0f, 800f, 600f)
            .Project(new Vec3(0f, 0f, 1f)));
    }

    /// A stroke made by projecting a reachable shape: every joint of the result lies on it (0.5 px), segment
    /// lengths are kept (1e-5), the root does not move, the view direction is the head-to-camera one.
    public static void ShapeFromStrokeFollowsReachableStroke()
    {
        JointTransform[] current = Straight();
        JointTransform[] target = Target();
        JointTransform head = Head();
        var result = new JointTransform[Joints];
        for (int i = 0; i < Cameras; i++)
        {
            StrokeCamera camera = CameraAt(i);
            Vec2[] stroke = Densify(Project(camera, target), 4);
            Vec3 direction;
            Sketch.ShapeFromStroke(camera, current, head, head, stroke, result, out direction);

            var world = new Vec3[Joints];
            for (int j = 0; j < Joints; j++) world[j] = ToWorld(head, result[j].Position);
            Ensure(Distance(world[0], current[0].Position) < 1e-5, "camera " + i + ": root unchanged, off by " + Distance(world[0], current[0].Position));
            for (int j = 0; j + 1 < Joints; j++)
            {
                double before = Distance(current[j].Position, current[j + 1].Position);
                double after = Distance(result[j].Position, result[j + 1].Position); // anchor frame: rigid
                Ensure(Math.Abs(after - before) / before <= LengthTolerance,
                       "camera " + i + ", segment " + j + ": length " + after + " vs " + before);
            }
            for (int j = 0; j < Joints; j++)
            {
                double off = DistanceToPolyline(camera.Project(world[j]), stroke);
                Ensure(off <= OnStrokePixels, "camera " + i + ", joint " + j + ": " + off.ToString("F3") + " px from the stroke");
                Quat r = result[j].Rotation;
                double norm = Math.Sqrt((double)r.X * r.X + (double)r.Y * r.Y + (double)r.Z * r.Z + (double)r.W * r.W);
                Ensure(Math.Abs(norm - 1.0) < 1e-4, "unit rotations");
            }
            // The stroke fits (it is a reachable shape's projection): the tip lands on its end. (Only on screen:
            // depth along the rays is taken from the current shape, so the 3D shape need not be the target.)
            Vec2 tip = camera.Project(world[Joints - 1]), end = stroke[stroke.Length - 1];
            double tipOff = Math.Sqrt((tip.X - end.X) * (tip.X - end.X) + (tip.Y - end.Y) * (tip.Y - end.Y));
            Ensure(tipOff <= OnStrokePixels, "camera " + i + ": tip " + tipOff.ToString("F3") + " px from the stroke's end");
            Vec3 expected = Normalize(Rotate(Conjugate(head.Rotation), Sub(camera.Position, head.Position)));
            Ensure(Distance(direction, expected) < 1e-5, "camera " + i + ": view direction " + direction + " vs " + expected);
        }
    }

    /// The stroke that is the chain's own projection gives the chain back (the tool is a no-op on a trace).
    public static void ShapeFromStrokeRoundTrip()
    {
        JointTransform[] target = Target();
        var identity = new JointTransform(0f, 0f, 0f);
        var head = new JointTransform(HeadPosition, Quat.Identity);
        var result = new JointTransform[Joints];
        for (int i = 0; i < Cameras; i++)
        {
            StrokeCamera camera = CameraAt(i);
            Vec3 direction;
            Sketch.ShapeFromStroke(camera, target, identity, head, Project(camera, target), result, out direction);
            for (int j = 0; j < Joints; j++)
                Ensure(Distance(result[j].Position, target[j].Position) < 2e-4, "camera " + i + ", joint " + j + " moved");
        }
    }

    /// Bad input throws KodawariException, writes nothing.
    public static void ShapeFromStrokeErrors()
    {
        JointTransform[] current = Straight();
        JointTransform head = Head();
        StrokeCamera camera = CameraAt(0);
        Vec2 root = camera.Project(current[0].Position);
        var output = new JointTransform[Joints];
        Vec3 direction;
        var e = ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(camera, current, head, head, new[] { root }, output, out direction));
        Ensure(e.NativeMessage.Contains("stroke"), "the message names the stroke: " + e.NativeMessage);
        ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(camera, current, head, head, new[] { root, root, root }, output, out direction));
        ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(camera, current, head, head, new Vec2[0], output, out direction));
        Vec2[] stroke = { root, new Vec2(root.X + 40f, root.Y - 60f) };
        ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(camera, new JointTransform[] { current[0] }, head, head, stroke, output, out direction));
        ExpectStatus(KodawariStatus.BufferTooSmall,
            () => Sketch.ShapeFromStroke(camera, current, head, head, stroke, new JointTransform[Joints - 1], out direction));
        var broken = new JointTransform[Joints];
        Array.Copy(current, broken, Joints);
        broken[3].Position.X = float.NaN;
        ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(camera, broken, head, head, stroke, output, out direction));
        // The chain behind a perspective camera: looking away from it.
        StrokeCamera away = StrokeCamera.FromUnityStyle(Add(current[0].Position, new Vec3(0f, 0f, 1f)), Quat.Identity, 1f, 800f, 600f);
        ExpectStatus(KodawariStatus.InvalidArgument,
            () => Sketch.ShapeFromStroke(away, current, head, head, stroke, output, out direction));
        for (int j = 0; j < Joints; j++) Ensure(output[j].Equals(default(JointTransform)), "nothing written on failure");
        Ensure(Library.LastErrorMessage().Length > 0, "a native message");
        ExpectStatus(KodawariStatus.InvalidArgument, () => Sketch.ShapeFromStroke(new StrokeCamera { ViewportWidth = 0f },
            current, head, head, stroke, output, out direction));
        try
        {
            Sketch.ShapeFromStroke(null, current, head, head, stroke, output, out direction);
            throw new Exception("expected ArgumentNullException");
        }
        catch (ArgumentNullException)
        {
        }
    }

    /// The sketch result fed to a chain as a view shape: seen from that camera, the rest shape becomes it.
    public static void SketchedViewShapeDrivesTheChain()
    {
        JointTransform[] current = Straight();
        var head = new JointTransform(HeadPosition, Quat.Identity);
        StrokeCamera camera = CameraAt(1);
        var shape = new JointTransform[Joints];
        Vec3 direction;
        Sketch.ShapeFromStroke(camera, current, head, head, Densify(Project(camera, Target()), 4), shape, out direction);
        using (var engine = new Engine())
        {
            var baseShape = new JointTransform[Joints];
            for (int j = 0; j < Joints; j++) baseShape[j] = new JointTransform(Sub(current[j].Position, HeadPosition), current[j].Rotation);
            ViewDependentPhysicalObject chain = engine.CreateChain(new ChainDef { Stiffness = 1f }, baseShape);
            chain.AddViewShape(direction, shape, 1f);
            engine.Step(1f / 60f, camera.Position, head);
            var weights = new float[2];
            Ensure(chain.ReadWeights(weights) == 2, "two weights");
            Ensure(Math.Abs(weights[1] - 1f) < 1e-5, "seen from the stroke's camera, the sketched shape has all the weight: " + weights[1]);
            var rest = new JointTransform[Joints];
            chain.ReadRestShape(rest);
            for (int j = 0; j < Joints; j++)
                Ensure(Distance(rest[j].Position, shape[j].Position) < 1e-4, "rest shape is the sketched shape at joint " + j);
        }
    }

    /// ReadWeights: base first, then one per view shape; >= 0, sum 1, following the camera (SPEC 3.2).
    public static void WeightsFollowTheCamera()
    {
        using (var engine = new Engine())
        {
            var baseShape = new JointTransform[6];
            var left = new JointTransform[6];
            var right = new JointTransform[6];
            for (int i = 0; i < 6; i++)
            {
                baseShape[i] = new JointTransform(0f, 0.12f + 0.03f * i, 0f);
                left[i] = new JointTransform(-0.01f * i * i, 0.12f + 0.025f * i, 0f);
                right[i] = new JointTransform(0.01f * i * i, 0.12f + 0.025f * i, 0f);
            }
            ViewDependentPhysicalObject chain = engine.CreateChain(null, baseShape);
            chain.AddViewShape(new Vec3(-1f, 0f, 0f), left, 1f);
            chain.AddViewShape(new Vec3(2f, 0f, 0f), right, 2f); // need not be unit
            var head = new JointTransform(HeadPosition, Quat.Identity);
            var weights = new float[4];
            weights[3] = -7f;

            // Orbit: at every angle the weights are the SPEC 3.2 formula's and sum to 1.
            for (int frame = 0; frame < 48; frame++)
            {
                double angle = 2.0 * Math.PI * frame / 48.0;
                var d = new Vec3((float)Math.Sin(angle), 0f, (float)Math.Cos(angle));
                engine.Step(1f / 60f, Add(HeadPosition, Scale(d, 2.5f)), head);
                Ensure(chain.ReadWeights(weights) == 3, "1 + view shape count written");
                Ensure(weights[3] == -7f, "nothing beyond");
                double wl = Math.Pow((-d.X + 1.0) / 2.0, 1.0), wr = Math.Pow((d.X + 1.0) / 2.0, 2.0);
                double s = wl + wr;
                if (s >= 1.0) { wl /= s; wr /= s; s = 1.0; }
                double[] expected = { 1.0 - s, wl, wr };
                float sum = 0f;
                for (int k = 0; k < 3; k++)
                {
                    Ensure(weights[k] >= 0f, "non-negative");
                    Ensure(Math.Abs(weights[k] - expected[k]) < 1e-4, "frame " + frame + ", weight " + k + ": " + weights[k] + " vs " + expected[k]);
                    sum += weights[k];
                }
                Ensure(Math.Abs(sum - 1f) < 1e-5, "weights sum to 1: " + sum);
            }

            engine.Step(1f / 60f, new Vec3(-2.5f, 1.6f, 0f), head);
            chain.ReadWeights(weights);
            Ensure(weights[1] > 0.99f && weights[2] < 0.01f, "seen from the left, the left shape");
            engine.Step(1f / 60f, new Vec3(2.5f, 1.6f, 0f), head);
            chain.ReadWeights(weights);
            Ensure(weights[2] > 0.99f && weights[1] < 0.01f, "seen from the right, the right shape");

            ulong hash = engine.StateHash;
            ExpectStatus(KodawariStatus.BufferTooSmall, () => chain.ReadWeights(new float[2]));
            ExpectStatus(KodawariStatus.BufferTooSmall, () => chain.ReadWeights(new float[0]));
            Ensure(engine.StateHash == hash, "state unchanged");

            // Allocation-free, like the other per-frame reads.
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < 100; i++) chain.ReadWeights(weights);
            Ensure(GC.GetAllocatedBytesForCurrentThread() - before == 0, "ReadWeights allocates nothing");

            ViewDependentPhysicalObject only = engine.CreateChain(null, baseShape);
            engine.Step(1f / 60f, new Vec3(-2.5f, 1.6f, 0f), head);
            Ensure(only.ReadWeights(weights) == 1 && weights[0] == 1f, "no view shapes: the base has weight 1");
            only.Destroy();
            ExpectStatus(KodawariStatus.InvalidId, () => only.ReadWeights(weights));
        }
    }
}
