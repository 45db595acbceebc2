using UnityEditor;
using UnityEngine;

namespace Kodawari.Unity.Editor
{
    /// <summary>Inspector of a chain: the default fields plus view-shape capture from the Scene view.</summary>
    [CustomEditor(typeof(ViewDependentPhysicalObject))]
    public sealed class ViewDependentPhysicalObjectEditor : UnityEditor.Editor
    {
        public override void OnInspectorGUI()
        {
            DrawDefaultInspector();
            var chain = (ViewDependentPhysicalObject)target;

            EditorGUILayout.Space();
            EditorGUILayout.LabelField("View shapes", EditorStyles.boldLabel);
            Transform reference = FindViewReference(chain);
            SceneView sceneView = SceneView.lastActiveSceneView;
            if (chain.Anchor == null)
                EditorGUILayout.HelpBox("The chain root needs a parent: it is the anchor the chain hangs from.", MessageType.Warning);
            if (reference == null)
                EditorGUILayout.HelpBox("No Kodawari Engine above this object: add one (Kodawari/Set Up Character…).", MessageType.Warning);
            if (sceneView == null || sceneView.camera == null)
                EditorGUILayout.HelpBox("Open a Scene view to capture view shapes.", MessageType.Info);

            EditorGUILayout.HelpBox("Pose the joints as they should look from the Scene view's camera, then capture: the "
                                    + "direction is the Scene camera seen from the view reference bone.", MessageType.None);
            using (new EditorGUI.DisabledScope(reference == null || chain.Anchor == null || sceneView == null || sceneView.camera == null))
            {
                if (GUILayout.Button("Capture view shape from Scene view"))
                {
                    Undo.RecordObject(chain, "Capture view shape");
                    chain.viewShapes.Add(chain.CaptureViewShape(sceneView.camera.transform.position, reference));
                    EditorUtility.SetDirty(chain);
                }
            }

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

        static Transform FindViewReference(ViewDependentPhysicalObject chain)
        {
            Engine engine = chain.GetComponentInParent<Engine>();
            if (engine == null) return null;
            return engine.viewReference != null ? engine.viewReference : engine.transform;
        }
    }
}
