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
    /// ancestor. Put it on the chain's root joint; its parent is the chain's anchor.</summary>
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

        [Header("View shapes")]
        public List<ViewShapeData> viewShapes = new List<ViewShapeData>();

        [NonSerialized] internal bool parametersChanged;

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
            };
        }

        /// <summary>Captures the current joint poses as a view shape seen from <paramref name="cameraPosition"/>;
        /// the direction is measured in <paramref name="viewReference"/>'s frame (the editor's capture button).</summary>
        public ViewShapeData CaptureViewShape(Vector3 cameraPosition, Transform viewReference)
        {
            var joints = CollectJoints();
            var shape = new ViewShapeData
            {
                direction = (Quaternion.Inverse(viewReference.rotation) * (cameraPosition - viewReference.position)).normalized,
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
            parametersChanged = true;
        }
    }
}
