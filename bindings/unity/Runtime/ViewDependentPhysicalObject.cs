using System;
using System.Collections.Generic;
using UnityEngine;

namespace Kodawari.Unity
{
    /// <summary>One view shape of a chain: when the camera sees the view reference bone from
    /// <see cref="direction"/>, the chain's rest shape becomes <see cref="positions"/>/<see cref="rotations"/>.</summary>
    [Serializable]
    public class ViewShapeData
    {
        [Tooltip("Direction from the view reference bone to the camera, in the bone's local frame.")]
        public Vector3 direction = Vector3.forward;

        [Tooltip("Narrows (large) or widens (small) the cone of camera directions this shape acts in.")]
        [Range(0.1f, 20f)]
        public float influence = 1f;

        [Tooltip("Joint positions captured in the anchor frame (the chain root's parent), root first.")]
        public Vector3[] positions = new Vector3[0];

        [Tooltip("Joint rotations captured in the anchor frame, root first.")]
        public Quaternion[] rotations = new Quaternion[0];
    }

    /// <summary>A physical joint chain (hair strand, ear, ribbon, tail) simulated by the <see cref="Engine"/> on an
    /// ancestor. Put it on the chain's root joint; its parent is the chain's anchor. Disabling the component at run
    /// time culls the chain (<c>kdw_chain_set_enabled</c>): it is no longer simulated nor written, costs nothing, and
    /// enabled again carries on from its last pose; nothing is rebuilt.</summary>
    [DisallowMultipleComponent]
    [AddComponentMenu("Kodawari/View Dependent Physical Object")]
    public sealed class ViewDependentPhysicalObject : MonoBehaviour
    {
        [Tooltip("The chain's root joint (defaults to this transform). Its parent is the anchor.")]
        public Transform root;

        [Tooltip("Explicit joints, root first, each a child of the previous. Empty: follow the single-child "
                 + "hierarchy below the root.")]
        public List<Transform> explicitJoints = new List<Transform>();

        [Header("Physics")]
        [Tooltip("Pull towards the rest shape: 0 limp, 1 rigid. Independent of substep rate and iterations.")]
        [Range(0f, 1f)] public float stiffness = 0.5f;

        [Tooltip("Velocity damping per second, 1/s.")]
        [Range(0f, 50f)] public float damping = 1f;

        [Tooltip("Share of the motion caused by a changing rest shape (view blending) that is not turned into velocity.")]
        [Range(0f, 1f)] public float momentumSuppression = 1f;

        [Tooltip("Mass per joint, kg.")]
        public float mass = 1f;

        [Tooltip("Joint radius, m.")]
        public float radius = 0.02f;

        [Tooltip("Multiplier on the engine's gravity.")]
        [Range(-10f, 10f)] public float gravityScale = 1f;

        [Header("Collisions")]
        [Tooltip("Collider layer bits this chain collides with (-1: all; 0: none, and no collision cost).")]
        public int collisionMask = -1;

        [Tooltip("Coulomb friction against colliders: 0 slides freely, 1 and more sticks.")]
        [Range(0f, 10f)] public float friction = 0.3f;

        [Header("View shapes")]
        public List<ViewShapeData> viewShapes = new List<ViewShapeData>();

        [NonSerialized] internal bool parametersChanged;
        [NonSerialized] internal Engine owner; // the Engine simulating this chain while it runs, else null

        void OnEnable()
        {
            if (owner != null) owner.SetChainEnabled(this, true);
        }

        void OnDisable()
        {
            if (owner != null) owner.SetChainEnabled(this, false);
        }

        /// <summary>The anchor: the root joint's parent (the bone the chain hangs from).</summary>
        public Transform Anchor { get { return Root.parent; } }

        public Transform Root { get { return root != null ? root : transform; } }

        /// <summary>The joints, root first: <see cref="explicitJoints"/> or the single-child hierarchy from the
        /// root down (stops at the first joint with no child or several children). Allocates: setup only.</summary>
        public List<Transform> CollectJoints()
        {
            var joints = new List<Transform>();
            if (explicitJoints != null && explicitJoints.Count > 0)
            {
                foreach (var joint in explicitJoints)
                    if (joint != null) joints.Add(joint);
                return joints;
            }
            Transform current = Root;
            joints.Add(current);
            while (current.childCount == 1)
            {
                current = current.GetChild(0);
                joints.Add(current);
            }
            return joints;
        }

        /// <summary>The chain parameters as the native engine takes them.</summary>
        public ChainDef CreateDef()
        {
            return new ChainDef
            {
                Stiffness = stiffness,
                Damping = damping,
                MomentumSuppression = momentumSuppression,
                Mass = mass,
                Radius = radius,
                GravityScale = gravityScale,
                Anchor = AnchorSource.Own,
                CollisionMask = unchecked((uint)collisionMask),
                Friction = friction,
            };
        }

        /// <summary>Captures the current joint poses as a view shape seen from <paramref name="cameraPosition"/>;
        /// the direction is measured in <paramref name="viewReference"/>'s frame (the editor's capture button).</summary>
        public ViewShapeData CaptureViewShape(Vector3 cameraPosition, Transform viewReference)
        {
            return CaptureViewShapeFromDirection(
                (Quaternion.Inverse(viewReference.rotation) * (cameraPosition - viewReference.position)).normalized);
        }

        /// <summary>Captures the current joint poses as a view shape for <paramref name="viewDirection"/> (from the
        /// view reference bone to the camera, in the bone's frame), e.g. the direction
        /// <see cref="ShapeFromStroke"/> returned.</summary>
        public ViewShapeData CaptureViewShapeFromDirection(Vector3 viewDirection)
        {
            var joints = CollectJoints();
            var shape = new ViewShapeData
            {
                direction = viewDirection,
                influence = 1f,
                positions = new Vector3[joints.Count],
                rotations = new Quaternion[joints.Count],
            };
            Transform anchor = Anchor;
            for (int i = 0; i < joints.Count; i++)
            {
                JointTransform pose = joints[i].PoseIn(anchor);
                shape.positions[i] = pose.Position.ToUnity();
                shape.rotations[i] = pose.Rotation.ToUnity();
            }
            return shape;
        }

        /// <summary>The <see cref="Engine"/> above this chain, or null.</summary>
        public Engine FindEngine() { return GetComponentInParent<Engine>(); }

        /// <summary>The bone view directions are measured from: the <see cref="Engine"/>'s view reference (or the
        /// Engine's own transform); null without an Engine above this chain.</summary>
        public Transform FindViewReference()
        {
            Engine engine = FindEngine();
            if (engine == null) return null;
            return engine.viewReference != null ? engine.viewReference : engine.transform;
        }

        /// <summary>The sketch tool (<see cref="Kodawari.Sketch.ShapeFromStroke"/>): the shape this chain takes so that,
        /// seen through <paramref name="camera"/>, it follows <paramref name="strokePixels"/> (root to tip, pixels with
        /// the origin at the top-left of the camera's viewport, y down; see
        /// <see cref="Conversions.ScreenToStrokePixel"/>). Returns one pose per joint in the anchor frame (pass them to
        /// <see cref="ApplyAnchorPose"/>) and the direction from the view reference bone to the camera in the bone's
        /// frame. The root stays, every segment keeps its length. Throws <see cref="KodawariException"/> for a stroke
        /// of fewer than 2 distinct points or a root behind the camera, InvalidOperationException without an anchor,
        /// 2 joints or an Engine above.</summary>
        public JointTransform[] ShapeFromStroke(Camera camera, IList<Vector2> strokePixels, out Vector3 viewDirection)
        {
            if (camera == null) throw new ArgumentNullException("camera");
            if (strokePixels == null) throw new ArgumentNullException("strokePixels");
            List<Transform> joints = CollectJoints();
            Transform anchor = Anchor;
            Transform reference = FindViewReference();
            if (anchor == null || joints.Count < 2)
                throw new InvalidOperationException(name + ": the chain needs a parent (its anchor) and at least 2 joints");
            if (reference == null)
                throw new InvalidOperationException(name + ": no Kodawari Engine above the chain (its view reference bone)");

            var current = new JointTransform[joints.Count];
            for (int i = 0; i < joints.Count; i++) current[i] = joints[i].WorldPose();
            var stroke = new Vec2[strokePixels.Count];
            for (int i = 0; i < stroke.Length; i++) stroke[i] = strokePixels[i].ToKodawari();
            var result = new JointTransform[joints.Count];
            Vec3 direction;
            Kodawari.Sketch.ShapeFromStroke(camera.ToStrokeCamera(), current, anchor.WorldPose(), reference.WorldPose(),
                                            stroke, result, out direction);
            viewDirection = direction.ToUnity();
            return result;
        }

        /// <summary>Poses the joints as <paramref name="anchorJoints"/> (anchor frame, root first, e.g. from
        /// <see cref="ShapeFromStroke"/>) by setting local rotations only, root to tip: the hierarchy keeps its
        /// bone lengths and every child follows. Record the joints for Undo first in the editor.</summary>
        public void ApplyAnchorPose(IList<JointTransform> anchorJoints)
        {
            List<Transform> joints = CollectJoints();
            Transform anchor = Anchor;
            if (anchor == null) return;
            for (int i = 0; i < joints.Count && i < anchorJoints.Count; i++)
            {
                Quaternion world = anchor.rotation * anchorJoints[i].Rotation.ToUnity();
                Transform parent = joints[i].parent;
                joints[i].localRotation = parent != null ? Quaternion.Inverse(parent.rotation) * world : world;
            }
        }

        // ---- gizmos ----

        static readonly Color ChainColor = new Color(1f, 0.55f, 0.1f, 1f);
        static readonly Color ViewColor = new Color(0.2f, 0.8f, 1f, 1f);
        float[] gizmoWeights = new float[0];

        /// <summary>The weights the gizmos show, base shape first then one per entry of <see cref="viewShapes"/>
        /// (the array is reused). While playing: the engine's last blend (<c>ReadWeights</c>), and
        /// <paramref name="live"/> is true. Otherwise a preview: the engine's weight formula (SPEC 3.2,
        /// <c>((dot(d_i, d) + 1) / 2)^influence</c>, normalised when they sum past 1) for a camera at
        /// <paramref name="viewerPosition"/>.</summary>
        public float[] GizmoWeights(Vector3 viewerPosition, out bool live)
        {
            int count = 1 + viewShapes.Count;
            if (gizmoWeights.Length != count) gizmoWeights = new float[count];
            Engine engine = FindEngine();
            live = Application.isPlaying && engine != null && engine.TryReadWeights(this, gizmoWeights);
            if (live) return gizmoWeights;

            Transform reference = FindViewReference();
            Vector3 d = reference != null
                ? (Quaternion.Inverse(reference.rotation) * (viewerPosition - reference.position)).normalized
                : Vector3.zero;
            float sum = 0f;
            for (int v = 0; v < viewShapes.Count; v++)
            {
                ViewShapeData shape = viewShapes[v];
                float w = d.sqrMagnitude > 0f && shape.direction.sqrMagnitude > 0f
                    ? Mathf.Pow(Mathf.Clamp01((Vector3.Dot(shape.direction.normalized, d) + 1f) * 0.5f), Mathf.Max(shape.influence, 1e-3f))
                    : 0f;
                gizmoWeights[1 + v] = w;
                sum += w;
            }
            if (sum > 1f)
            {
                for (int v = 1; v < count; v++) gizmoWeights[v] /= sum;
                sum = 1f;
            }
            gizmoWeights[0] = 1f - sum;
            return gizmoWeights;
        }

        /// <summary>The size of the view gizmo: a third of the chain's length (at least 5 cm).</summary>
        public float GizmoSize()
        {
            List<Transform> joints = CollectJoints();
            float length = 0f;
            for (int i = 1; i < joints.Count; i++) length += (joints[i].position - joints[i - 1].position).magnitude;
            return Mathf.Max(length / 3f, 0.05f);
        }

        /// <summary>The chain (lines between joints) and, at the view reference bone, a sphere with one arrow per view
        /// shape: its direction, its length scaled by its weight (live while playing, a preview for the camera
        /// drawing the gizmo otherwise). The editor adds a label with the weights.</summary>
        void OnDrawGizmosSelected()
        {
            List<Transform> joints = CollectJoints();
            Gizmos.color = ChainColor;
            for (int i = 0; i < joints.Count; i++)
            {
                if (i > 0) Gizmos.DrawLine(joints[i - 1].position, joints[i].position);
                Gizmos.DrawWireSphere(joints[i].position, Mathf.Max(radius, 0.002f));
            }

            Transform reference = FindViewReference();
            if (reference == null) return;
            float size = GizmoSize();
            Camera viewer = Camera.current;
            bool live;
            float[] weights = GizmoWeights(viewer != null ? viewer.transform.position : reference.position, out live);
            Gizmos.color = ViewColor;
            Gizmos.DrawWireSphere(reference.position, 0.15f * size);
            for (int v = 0; v < viewShapes.Count; v++)
            {
                if (viewShapes[v].direction.sqrMagnitude <= 0f) continue;
                Vector3 direction = (reference.rotation * viewShapes[v].direction).normalized;
                Vector3 from = reference.position + direction * (0.15f * size);
                DrawArrow(from, direction * (size * weights[1 + v]));
            }
        }

        static void DrawArrow(Vector3 from, Vector3 vector)
        {
            float length = vector.magnitude;
            if (length < 1e-5f)
            {
                Gizmos.DrawWireSphere(from, 0.01f);
                return;
            }
            Vector3 to = from + vector;
            Vector3 direction = vector / length;
            Vector3 side = Vector3.Cross(direction, Mathf.Abs(direction.y) < 0.9f ? Vector3.up : Vector3.right).normalized;
            Vector3 other = Vector3.Cross(direction, side);
            float head = Mathf.Min(0.25f * length, 0.05f);
            Gizmos.DrawLine(from, to);
            Gizmos.DrawLine(to, to - direction * head + side * (0.5f * head));
            Gizmos.DrawLine(to, to - direction * head - side * (0.5f * head));
            Gizmos.DrawLine(to, to - direction * head + other * (0.5f * head));
            Gizmos.DrawLine(to, to - direction * head - other * (0.5f * head));
        }

        /// <summary>Poses the joints as <paramref name="shape"/> (editor preview).</summary>
        public void ApplyPose(ViewShapeData shape)
        {
            var joints = CollectJoints();
            Transform anchor = Anchor;
            for (int i = 0; i < joints.Count && i < shape.positions.Length && i < shape.rotations.Length; i++)
            {
                joints[i].position = anchor.position + anchor.rotation * shape.positions[i];
                joints[i].rotation = anchor.rotation * shape.rotations[i];
            }
        }

        void OnValidate()
        {
            mass = Mathf.Max(mass, 1e-4f);
            radius = Mathf.Max(radius, 0f);
            friction = Mathf.Clamp(friction, 0f, 10f);
            parametersChanged = true;
        }
    }
}
