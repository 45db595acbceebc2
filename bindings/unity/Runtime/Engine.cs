using System;
using System.Collections.Generic;
using UnityEngine;

namespace Kodawari.Unity
{
    /// <summary>The kodawari engine of one character. Put it on the character's root: on enable it gathers the
    /// <see cref="ViewDependentPhysicalObject"/>s below it, creates the native engine and the
    /// <see cref="colliders"/>; at Start it can also pick up the Unity sphere and capsule colliders on the
    /// character's bones (<see cref="autoCollectBoneColliders"/>). Every LateUpdate (after animation) it moves
    /// every collider with its bone in one native call, pushes the chains' anchors, runs one native step with the
    /// camera and the view reference bone, and writes every joint's localRotation. No managed allocation per
    /// frame. Disabling a chain component culls its chain without a rebuild; <see cref="LOD"/> lowers the step rate
    /// of a distant character without a rebuild; bone colliders follow their bones' scale.</summary>
    [DisallowMultipleComponent]
    [DefaultExecutionOrder(10000)]
    [AddComponentMenu("Kodawari/Engine")]
    public sealed class Engine : MonoBehaviour
    {
        [Tooltip("The camera whose view selects the view shapes. Empty: Camera.main.")]
        public Camera targetCamera;

        [Tooltip("The bone view directions are measured from (usually the head). Empty: this transform.")]
        public Transform viewReference;

        [Tooltip("Chains to simulate. Empty: every ViewDependentPhysicalObject below this object, gathered on enable. "
                 + "A chain whose component is disabled is created culled and simulated once enabled.")]
        public List<ViewDependentPhysicalObject> chains = new List<ViewDependentPhysicalObject>();

        [Header("Solver")]
        [Tooltip("World gravity, m/s².")]
        public Vector3 gravity = new Vector3(0f, -9.81f, 0f);

        [Tooltip("Internal fixed steps per simulated second, Hz. Motion does not depend on the frame rate.")]
        [Range(30f, 1000f)] public float substepRate = 240f;

        [Tooltip("Shape-matching + inextensibility passes per internal step.")]
        [Range(1, 64)] public int iterations = 2;

        [Tooltip("Simulated seconds per second; 0 pauses.")]
        [Range(0f, 4f)] public float timeScale = 1f;

        [Tooltip("Most internal steps per frame; time beyond is dropped (a hitch does not explode).")]
        [Range(1, 1000)] public int maxSubsteps = 16;

        [Tooltip("Size of the character relative to the units the chains' parameters are tuned in: multiplies gravity, "
                 + "the teleport distance and the chains' radii (a character scaled by 100 with scale 100 moves like the original).")]
        public float scale = 1f;

        [Tooltip("Chains moving slower than this (m/s, relative to their root) for 0.5 s under a still anchor fall asleep "
                 + "and cost almost nothing until something moves. 0: never sleep.")]
        public float sleepSpeed = 5e-6f;

        [Tooltip("Level of detail: each level halves the internal step rate (not below 30 Hz) and the iterations (not "
                 + "below 1). Scripts set LOD by the character's distance to the camera.")]
        [Range(0, 3)] public int lod = 0;

        [Tooltip("Lanes: chains of equal joint count stepped side by side in SIMD lanes (fastest). Lanes Portable: the "
                 + "same bits without AVX2. Scalar: one chain at a time, the reference solver; differs from Lanes by float "
                 + "rounding only.")]
        public Solver solver = Solver.Lanes;

        [Header("Colliders")]
        [Tooltip("Colliders on the character's bones (head, shoulders, body) that keep the chains out.")]
        public List<BoneCollider> colliders = new List<BoneCollider>();

        [Tooltip("At Start, also create a collider for every enabled, non-trigger SphereCollider and CapsuleCollider "
                 + "on this object and its children (the character's bones), on the layer bit of its Unity layer.")]
        public bool autoCollectBoneColliders = false;

        [Header("Teleports")]
        [Tooltip("An anchor moving farther than this (m) in one frame is carried rigidly instead of whipping the chain.")]
        public float teleportDistance = 1f;

        [Tooltip("An anchor turning more than this (degrees) in one frame is a teleport.")]
        [Range(1f, 180f)] public float teleportAngle = 90f;

        [Tooltip("Also reset the chains to their rest shapes when the character root jumps farther than the teleport distance in one frame.")]
        public bool resetOnTeleport = true;

        [Tooltip("What a teleport does: carry the chains rigidly with their anchors (keeping their motion), or put "
                 + "them back to their rest shapes.")]
        public TeleportMode teleportMode = TeleportMode.CarryShape;

        Kodawari.Engine native;
        ViewDependentPhysicalObject[] active = new ViewDependentPhysicalObject[0];
        Kodawari.ViewDependentPhysicalObject[] chainHandles = new Kodawari.ViewDependentPhysicalObject[0];
        ViewShape[][] viewShapeHandles = new ViewShape[0][];
        Transform[] anchorTransforms = new Transform[0];  // one per chain
        Transform[] jointTransforms = new Transform[0];   // every joint, in the engine's batched order
        JointTransform[] anchors = new JointTransform[0];
        Quat[] localRotations = new Quat[0];
        readonly List<BoneCollider> collectedColliders = new List<BoneCollider>(); // autoCollectBoneColliders, at Start
        readonly List<BoneCollider> activeColliders = new List<BoneCollider>();    // native creation order
        readonly List<Kodawari.Collider> colliderHandles = new List<Kodawari.Collider>(); // one per active collider
        readonly List<Vector3> colliderScales = new List<Vector3>(); // each bone's lossy scale its size was set for
        JointTransform[] colliderPoses = new JointTransform[0];                    // one per active collider, reused
        int[] jointStarts = new int[1];   // chain i's joints are jointTransforms[jointStarts[i] .. jointStarts[i + 1])
        bool[] chainEnabled = new bool[0]; // mirrors each chain component's enabled state (culled chains are not written)
        int appliedLod;
        bool started;
        bool settingsChanged;
        Vector3 lastRootPosition;

        /// <summary>The native engine while enabled (null otherwise), for advanced use.</summary>
        public Kodawari.Engine Native { get { return native; } }

        /// <summary>The level of detail, 0 to 3 (<see cref="lod"/>): set it per character from its distance to the camera.
        /// Applied to the running engine at once through its settings (no rebuild, no allocation); setting the current
        /// value costs nothing.</summary>
        public int LOD
        {
            get { return lod; }
            set
            {
                lod = Mathf.Clamp(value, 0, 3);
                if (native != null && lod != appliedLod)
                {
                    native.Lod = lod;
                    appliedLod = lod;
                }
            }
        }

        /// <summary>Culls (false) or resumes (true) <paramref name="chain"/>'s simulation; called by the chain component's
        /// OnDisable and OnEnable. A culled chain rides rigidly with its anchor and its joints are not written.</summary>
        internal void SetChainEnabled(ViewDependentPhysicalObject chain, bool value)
        {
            if (native == null) return;
            int index = Array.IndexOf(active, chain);
            if (index < 0 || chainEnabled[index] == value) return;
            chainHandles[index].Enabled = value;
            chainEnabled[index] = value;
        }

        void OnEnable()
        {
            try
            {
                Build();
            }
            catch (Exception e)
            {
                Debug.LogException(e, this);
                Teardown();
                enabled = false;
            }
        }

        void Start()
        {
            started = true;
            if (!autoCollectBoneColliders) return;
            CollectBoneColliders(collectedColliders);
            if (native == null) return;
            try
            {
                CreateColliders(collectedColliders);
            }
            catch (Exception e)
            {
                Debug.LogException(e, this);
            }
        }

        /// <summary>Appends an entry for every enabled, non-trigger <c>SphereCollider</c> and <c>CapsuleCollider</c> on
        /// this object and its active children (what <see cref="autoCollectBoneColliders"/> picks up at Start).</summary>
        public void CollectBoneColliders(List<BoneCollider> into)
        {
            foreach (SphereCollider sphere in GetComponentsInChildren<SphereCollider>(false))
                if (sphere.enabled && !sphere.isTrigger) into.Add(BoneCollider.From(sphere));
            foreach (CapsuleCollider capsule in GetComponentsInChildren<CapsuleCollider>(false))
                if (capsule.enabled && !capsule.isTrigger) into.Add(BoneCollider.From(capsule));
        }

        /// <summary>Number of colliders the native engine has (serialized and collected), 0 while not running.</summary>
        public int ColliderCount { get { return native != null ? activeColliders.Count : 0; } }

        void CreateColliders(List<BoneCollider> source)
        {
            if (source == null) return;
            foreach (BoneCollider entry in source)
            {
                if (entry == null || entry.bone == null)
                {
                    Debug.LogWarning("Kodawari: a collider without a bone was skipped.", this);
                    continue;
                }
                colliderHandles.Add(native.CreateCollider(entry.CreateDef()));
                colliderScales.Add(entry.bone.lossyScale);
                activeColliders.Add(entry);
            }
            colliderPoses = new JointTransform[activeColliders.Count]; // setup only, reused every frame
        }

        void OnDisable() { Teardown(); }

        void OnDestroy() { Teardown(); }

        void OnValidate() { settingsChanged = true; }

        /// <summary>Rebuilds the native engine from the current components (after adding or removing chains).</summary>
        public void Rebuild()
        {
            Teardown();
            if (isActiveAndEnabled) Build();
        }

        /// <summary>Puts every chain back to its rest shape, at rest (after a cut, a respawn, a teleport).</summary>
        public void ResetChains()
        {
            if (native != null) native.Reset();
        }

        /// <summary>The character was placed somewhere new: the next frame treats every chain's anchor motion as a
        /// teleport (<see cref="teleportMode"/>), however small.</summary>
        public void Teleport()
        {
            if (native != null) native.Teleport();
        }

        EngineDef CreateDef()
        {
            return new EngineDef
            {
                Gravity = gravity.ToKodawari(),
                SubstepRate = substepRate,
                Iterations = iterations,
                TimeScale = timeScale,
                MaxSubsteps = maxSubsteps,
                TeleportDistance = Mathf.Max(teleportDistance, 1e-4f),
                TeleportAngle = Mathf.Max(teleportAngle, 0.01f) * Mathf.Deg2Rad,
                TeleportMode = teleportMode,
                Scale = Mathf.Clamp(scale, 1e-6f, 1e6f),
                SleepSpeed = Mathf.Max(sleepSpeed, 0f),
                Lod = Mathf.Clamp(lod, 0, 3),
            };
        }

        void Build()
        {
            var found = new List<ViewDependentPhysicalObject>();
            if (chains != null && chains.Count > 0)
            {
                foreach (var chain in chains)
                    if (chain != null && chain.gameObject.activeInHierarchy) found.Add(chain);
            }
            else
            {
                found.AddRange(GetComponentsInChildren<ViewDependentPhysicalObject>(false));
            }

            native = new Kodawari.Engine(CreateDef());
            native.Solver = solver;
            appliedLod = Mathf.Clamp(lod, 0, 3);
            var jointList = new List<Transform>();
            var anchorList = new List<Transform>();
            var activeList = new List<ViewDependentPhysicalObject>();
            var handleList = new List<Kodawari.ViewDependentPhysicalObject>();
            var viewHandleList = new List<ViewShape[]>();
            var startList = new List<int> { 0 };
            var enabledList = new List<bool>();
            Transform reference = ViewReference;
            foreach (var chain in found)
            {
                List<Transform> joints = chain.CollectJoints();
                Transform anchor = chain.Anchor;
                if (joints.Count < 2 || anchor == null)
                {
                    Debug.LogWarning("Kodawari: " + chain.name + " needs a parent (its anchor) and at least 2 joints; skipped.", chain);
                    continue;
                }
                var shape = new JointTransform[joints.Count];
                for (int i = 0; i < joints.Count; i++) shape[i] = joints[i].PoseIn(anchor);
                Kodawari.ViewDependentPhysicalObject handle = native.CreateChain(chain.CreateDef(), shape);
                if (!chain.enabled) handle.Enabled = false; // culled until its component is enabled
                var viewHandles = new ViewShape[chain.viewShapes.Count];
                for (int v = 0; v < chain.viewShapes.Count; v++)
                {
                    ViewShapeData view = chain.viewShapes[v];
                    if (view.positions.Length != joints.Count || view.rotations.Length != joints.Count)
                    {
                        Debug.LogWarning("Kodawari: a view shape of " + chain.name + " was captured with another joint count; recapture it.", chain);
                        continue;
                    }
                    var viewJoints = new JointTransform[joints.Count];
                    for (int i = 0; i < joints.Count; i++)
                        viewJoints[i] = new JointTransform(view.positions[i].ToKodawari(), view.rotations[i].ToKodawari());
                    viewHandles[v] = handle.AddViewShape(view.direction.ToKodawari(), viewJoints, Mathf.Max(view.influence, 1e-3f));
                }
                handleList.Add(handle);
                viewHandleList.Add(viewHandles);
                chain.parametersChanged = false;
                activeList.Add(chain);
                anchorList.Add(anchor);
                jointList.AddRange(joints);
                startList.Add(jointList.Count);
                enabledList.Add(chain.enabled);
                chain.owner = this;
            }
            active = activeList.ToArray();
            chainHandles = handleList.ToArray();
            viewShapeHandles = viewHandleList.ToArray();
            anchorTransforms = anchorList.ToArray();
            jointTransforms = jointList.ToArray();
            jointStarts = startList.ToArray();
            chainEnabled = enabledList.ToArray();
            anchors = new JointTransform[anchorTransforms.Length];
            localRotations = new Quat[jointTransforms.Length];
            activeColliders.Clear();
            colliderHandles.Clear();
            colliderScales.Clear();
            CreateColliders(colliders);
            if (started) CreateColliders(collectedColliders);
            settingsChanged = false;
            lastRootPosition = transform.position;
            if (reference == null) Debug.LogWarning("Kodawari: no view reference bone", this);
        }

        void Teardown()
        {
            if (native != null) native.Dispose();
            native = null;
            foreach (var chain in active)
                if (chain != null && chain.owner == this) chain.owner = null;
            activeColliders.Clear();
            colliderHandles.Clear();
            colliderScales.Clear();
        }

        bool AnyChainChanged()
        {
            for (int i = 0; i < active.Length; i++)
                if (active[i].parametersChanged) return true;
            return false;
        }

        Transform ViewReference { get { return viewReference != null ? viewReference : transform; } }

        void LateUpdate()
        {
            if (native == null) return;
            if (settingsChanged || AnyChainChanged()) ApplySettings();

            // Anchors: each chain root's parent.
            for (int i = 0; i < anchorTransforms.Length; i++) anchors[i] = anchorTransforms[i].WorldPose();

            // Colliders follow their bones: every pose in one native call, from the preallocated array; a bone whose
            // lossy scale changed resizes its collider (one compare per collider, a native call only on change).
            if (colliderPoses.Length > 0)
            {
                for (int i = 0; i < colliderPoses.Length; i++)
                {
                    BoneCollider entry = activeColliders[i];
                    colliderPoses[i] = entry.WorldPose();
                    Vector3 lossy = entry.bone.lossyScale;
                    Vector3 last = colliderScales[i];
                    if (lossy.x != last.x || lossy.y != last.y || lossy.z != last.z) ResizeCollider(i, lossy);
                }
                native.SetColliderTransforms(colliderPoses);
            }

            if (resetOnTeleport && (transform.position - lastRootPosition).sqrMagnitude > teleportDistance * teleportDistance)
                native.Reset();
            lastRootPosition = transform.position;

            Camera view = targetCamera != null ? targetCamera : Camera.main;
            Transform reference = ViewReference;
            Vec3 cameraPosition = view != null ? view.transform.position.ToKodawari() : reference.position.ToKodawari();
            // One native call per frame: anchors in, step, local rotations out.
            native.StepAndReadLocalRotations(Time.deltaTime, cameraPosition, reference.WorldPose(), anchors, localRotations);
            // Culled chains (component disabled) are not written: their bones are left to the animation.
            for (int c = 0; c < chainEnabled.Length; c++)
            {
                if (!chainEnabled[c]) continue;
                for (int i = jointStarts[c]; i < jointStarts[c + 1]; i++) jointTransforms[i].localRotation = localRotations[i].ToUnity();
            }
        }

        void ResizeCollider(int index, Vector3 lossy)
        {
            float radius, halfHeight;
            if (activeColliders[index].SizeAt(lossy, out radius, out halfHeight))
            {
                colliderHandles[index].SetSize(radius, halfHeight);
                colliderScales[index] = lossy;
            }
        }

        void ApplySettings()
        {
            if (settingsChanged)
            {
                settingsChanged = false;
                native.Def = CreateDef();
                native.Solver = solver;
                appliedLod = Mathf.Clamp(lod, 0, 3);
                // Sizes edited in the inspector: re-upload every collider's size at its bone's current scale.
                for (int i = 0; i < colliderScales.Count; i++) ResizeCollider(i, activeColliders[i].bone.lossyScale);
            }
            // Per-chain edits (inspector sliders, MarkSettingsChanged): parameters and view shape influences.
            for (int i = 0; i < active.Length; i++)
            {
                ViewDependentPhysicalObject chain = active[i];
                if (!chain.parametersChanged) continue;
                chain.parametersChanged = false;
                chainHandles[i].Def = chain.CreateDef();
                ViewShape[] views = viewShapeHandles[i];
                for (int v = 0; v < views.Length && v < chain.viewShapes.Count; v++)
                {
                    if (views[v].Engine == null) continue; // skipped at build (joint count mismatch)
                    views[v].SetInfluence(Mathf.Max(chain.viewShapes[v].influence, 1e-3f));
                    if (chain.viewShapes[v].direction.sqrMagnitude > 0f) views[v].SetDirection(chain.viewShapes[v].direction.ToKodawari());
                }
            }
        }

        float[] weightScratch = new float[0];

        /// <summary>The weights of <paramref name="chain"/>'s last blend (<c>ReadWeights</c>): <c>weights[0]</c> the base
        /// shape's, then <c>weights[1 + v]</c> for <c>chain.viewShapes[v]</c> (0 for a view shape skipped at build).
        /// <paramref name="weights"/> needs <c>1 + chain.viewShapes.Count</c> entries. False while the engine is not
        /// running or the chain is not part of it. No allocation after the first call.</summary>
        public bool TryReadWeights(ViewDependentPhysicalObject chain, float[] weights)
        {
            if (native == null || chain == null || weights == null) return false;
            int index = Array.IndexOf(active, chain);
            if (index < 0) return false;
            ViewShape[] views = viewShapeHandles[index];
            if (weights.Length < 1 + views.Length) return false;
            if (weightScratch.Length < 1 + views.Length) weightScratch = new float[1 + views.Length];
            int written = chainHandles[index].ReadWeights(weightScratch);
            weights[0] = weightScratch[0];
            int next = 1;
            for (int v = 0; v < views.Length; v++)
                weights[1 + v] = views[v].Engine != null && next < written ? weightScratch[next++] : 0f;
            for (int k = 1 + views.Length; k < weights.Length; k++) weights[k] = 0f; // added since the build
            return true;
        }

        /// <summary>Marks settings and chain parameters for upload at the next LateUpdate (after changing fields
        /// from a script at run time).</summary>
        public void MarkSettingsChanged()
        {
            settingsChanged = true;
            foreach (var chain in active) chain.parametersChanged = true;
        }
    }
}
