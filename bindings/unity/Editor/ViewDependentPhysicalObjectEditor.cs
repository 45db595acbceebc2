using System;
using System.Collections.Generic;
using UnityEditor;
using UnityEngine;

namespace Kodawari.Unity.Editor
{
    /// <summary>Inspector of a chain: the default fields, view-shape capture from the Scene view, and the sketch
    /// tool (draw a stroke over the chain in the Scene view; the chain takes that shape).</summary>
    [CustomEditor(typeof(ViewDependentPhysicalObject))]
    public sealed class ViewDependentPhysicalObjectEditor : UnityEditor.Editor
    {
        static readonly Color StrokeColor = new Color(1f, 0.3f, 0.7f, 1f);

        bool sketching;
        // The stroke being drawn: pixels for the library (top-left origin, y down), world points to draw it.
        readonly List<Vector2> strokePixels = new List<Vector2>();
        readonly List<Vector3> strokeWorld = new List<Vector3>();
        float strokeDepth;
        bool hasSketch;
        Vector3 sketchDirection;
        string sketchError;

        void OnDisable() { SetSketching(false); }

        void SetSketching(bool on)
        {
            if (on == sketching) return;
            sketching = on;
            SceneView.duringSceneGui -= OnSceneViewGUI;
            if (on) SceneView.duringSceneGui += OnSceneViewGUI;
            strokePixels.Clear();
            strokeWorld.Clear();
            SceneView.RepaintAll();
        }

        public override void OnInspectorGUI()
        {
            DrawDefaultInspector();
            var chain = (ViewDependentPhysicalObject)target;

            EditorGUILayout.Space();
            EditorGUILayout.LabelField("View shapes", EditorStyles.boldLabel);
            Transform reference = chain.FindViewReference();
            SceneView sceneView = SceneView.lastActiveSceneView;
            if (chain.Anchor == null)
                EditorGUILayout.HelpBox("The chain root needs a parent: it is the anchor the chain hangs from.", MessageType.Warning);
            if (reference == null)
                EditorGUILayout.HelpBox("No Kodawari Engine above this object: add one (Kodawari/Set Up Character…).", MessageType.Warning);
            if (sceneView == null || sceneView.camera == null)
                EditorGUILayout.HelpBox("Open a Scene view to capture view shapes.", MessageType.Info);

            EditorGUILayout.HelpBox("Pose the joints as they should look from the Scene view's camera, then capture: the "
                                    + "direction is the Scene camera seen from the view reference bone.", MessageType.None);
            bool ready = reference != null && chain.Anchor != null;
            using (new EditorGUI.DisabledScope(!ready || sceneView == null || sceneView.camera == null))
            {
                if (GUILayout.Button("Capture view shape from Scene view"))
                {
                    Undo.RecordObject(chain, "Capture view shape");
                    chain.viewShapes.Add(chain.CaptureViewShape(sceneView.camera.transform.position, reference));
                    EditorUtility.SetDirty(chain);
                }
            }

            // ---- sketch tool ----
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Sketch", EditorStyles.boldLabel);
            using (new EditorGUI.DisabledScope(!ready))
            {
                bool on = EditorGUILayout.Toggle("Sketch in Scene view", sketching);
                if (on != sketching) SetSketching(on);
            }
            if (!ready && sketching) SetSketching(false);
            if (sketching)
                EditorGUILayout.HelpBox("Drag in the Scene view from the chain's root towards its tip: the chain takes the "
                                        + "shape of the stroke as seen from that view (root kept, lengths kept, undoable). "
                                        + "Alt-drag still orbits. Then add the pose as a view shape for this view.",
                                        MessageType.Info);
            if (sketching && Application.isPlaying)
                EditorGUILayout.HelpBox("While playing, the Engine moves the joints every frame: sketch in Edit mode.", MessageType.Warning);
            if (!string.IsNullOrEmpty(sketchError)) EditorGUILayout.HelpBox(sketchError, MessageType.Warning);
            if (hasSketch)
                EditorGUILayout.LabelField("Last stroke seen from " + sketchDirection.ToString("F2") + " (view reference frame)");
            using (new EditorGUI.DisabledScope(!ready || !hasSketch))
            {
                if (GUILayout.Button("Add view shape from this view"))
                {
                    Undo.RecordObject(chain, "Add view shape from sketch");
                    chain.viewShapes.Add(chain.CaptureViewShapeFromDirection(sketchDirection));
                    EditorUtility.SetDirty(chain);
                }
            }

            // ---- the list ----
            EditorGUILayout.Space();
            for (int i = 0; i < chain.viewShapes.Count; i++)
            {
                ViewShapeData shape = chain.viewShapes[i];
                EditorGUILayout.BeginHorizontal();
                EditorGUILayout.LabelField("#" + i + "  from " + shape.direction.ToString("F2") + ", " + shape.positions.Length + " joints");
                if (GUILayout.Button("Pose", GUILayout.Width(50f)))
                {
                    var joints = chain.CollectJoints();
                    Undo.RecordObjects(joints.ToArray(), "Pose joints as view shape");
                    chain.ApplyPose(shape);
                }
                if (GUILayout.Button("Remove", GUILayout.Width(70f)))
                {
                    Undo.RecordObject(chain, "Remove view shape");
                    chain.viewShapes.RemoveAt(i);
                    EditorUtility.SetDirty(chain);
                    EditorGUILayout.EndHorizontal();
                    break;
                }
                EditorGUILayout.EndHorizontal();
            }
        }

        // ---- Scene view: capture the stroke ----

        void OnSceneViewGUI(SceneView view)
        {
            var chain = target as ViewDependentPhysicalObject;
            Camera camera = view.camera;
            if (chain == null || camera == null) return;
            Event e = Event.current;
            // Our control takes the mouse when no handle does, so plain drags draw instead of selecting.
            int id = GUIUtility.GetControlID(FocusType.Passive);
            if (e.type == EventType.Layout)
            {
                HandleUtility.AddDefaultControl(id);
                return;
            }
            switch (e.GetTypeForControl(id))
            {
                case EventType.MouseDown:
                    if (e.button != 0 || e.alt) break;
                    GUIUtility.hotControl = id;
                    strokePixels.Clear();
                    strokeWorld.Clear();
                    Transform root = chain.Root;
                    strokeDepth = Mathf.Max((root.position - camera.transform.position).magnitude, camera.nearClipPlane * 2f);
                    AddStrokePoint(camera, e.mousePosition);
                    e.Use();
                    break;
                case EventType.MouseDrag:
                    if (GUIUtility.hotControl != id) break;
                    AddStrokePoint(camera, e.mousePosition);
                    e.Use();
                    view.Repaint();
                    break;
                case EventType.MouseUp:
                    if (GUIUtility.hotControl != id) break;
                    GUIUtility.hotControl = 0;
                    AddStrokePoint(camera, e.mousePosition);
                    e.Use();
                    ApplyStroke(chain, camera);
                    strokePixels.Clear();
                    strokeWorld.Clear();
                    view.Repaint();
                    break;
                case EventType.Repaint:
                    if (strokeWorld.Count < 2) break;
                    Handles.color = StrokeColor;
                    Handles.DrawAAPolyLine(4f, strokeWorld.ToArray());
                    break;
            }
        }

        void AddStrokePoint(Camera camera, Vector2 guiPoint)
        {
            // GUI points (top-left, points) -> screen pixels (bottom-left) -> the library's pixels (top-left, y down).
            Vector2 screen = HandleUtility.GUIPointToScreenPixelCoordinate(guiPoint);
            Vector2 pixel = camera.ScreenToStrokePixel(screen).ToUnity();
            if (strokePixels.Count > 0 && (strokePixels[strokePixels.Count - 1] - pixel).sqrMagnitude < 1f) return;
            strokePixels.Add(pixel);
            strokeWorld.Add(HandleUtility.GUIPointToWorldRay(guiPoint).GetPoint(strokeDepth));
        }

        void ApplyStroke(ViewDependentPhysicalObject chain, Camera camera)
        {
            if (strokePixels.Count < 2) return; // a click, not a stroke
            Vector3 direction;
            JointTransform[] shape;
            try
            {
                shape = chain.ShapeFromStroke(camera, strokePixels, out direction);
            }
            catch (Exception error)
            {
                if (!(error is KodawariException) && !(error is InvalidOperationException)) throw;
                sketchError = "The stroke could not shape the chain: " + error.Message;
                Repaint();
                return;
            }
            List<Transform> joints = chain.CollectJoints();
            Undo.RecordObjects(joints.ToArray(), "Sketch chain shape");
            chain.ApplyAnchorPose(shape);
            sketchError = null;
            hasSketch = true;
            sketchDirection = direction;
            Repaint();
        }

        // ---- gizmo labels (the lines and arrows are the component's OnDrawGizmosSelected) ----

        [DrawGizmo(GizmoType.Selected | GizmoType.Active)]
        static void DrawWeightLabels(ViewDependentPhysicalObject chain, GizmoType gizmoType)
        {
            Transform reference = chain.FindViewReference();
            if (reference == null) return;
            Camera viewer = Camera.current;
            bool live;
            float[] weights = chain.GizmoWeights(viewer != null ? viewer.transform.position : reference.position, out live);
            float size = chain.GizmoSize();
            Handles.color = Color.white;
            string text = (live ? "weights: base " : "weights from this view: base ") + weights[0].ToString("F2");
            for (int v = 0; v < chain.viewShapes.Count; v++)
            {
                text += ", #" + v + " " + weights[1 + v].ToString("F2");
                if (chain.viewShapes[v].direction.sqrMagnitude <= 0f) continue;
                Vector3 direction = (reference.rotation * chain.viewShapes[v].direction).normalized;
                Handles.Label(reference.position + direction * (size * (0.15f + weights[1 + v]) + 0.01f), "#" + v);
            }
            Handles.Label(reference.position + reference.rotation * Vector3.up * (0.2f * size), text);
        }
    }
}
