using System.Collections.Generic;
using UnityEditor;
using UnityEngine;

namespace Kodawari.Unity.Editor
{
    /// <summary>Kodawari/Set Up Character…: picks the model root, the view reference bone and the chain roots,
    /// then adds and wires an <see cref="Engine"/> and one <see cref="ViewDependentPhysicalObject"/> per chain
    /// (one undo step).</summary>
    public sealed class SetUpCharacterWindow : EditorWindow
    {
        Transform modelRoot;
        Transform viewReference;
        readonly List<Transform> chainRoots = new List<Transform>();

        [MenuItem("Kodawari/Set Up Character…")]
        public static void Open()
        {
            var window = GetWindow<SetUpCharacterWindow>("Kodawari Setup");
            if (window.modelRoot == null) window.modelRoot = Selection.activeTransform;
            window.Show();
        }

        void OnGUI()
        {
            EditorGUILayout.HelpBox("1. The model root gets the Engine.\n2. The view reference bone (usually the head) is the "
                                    + "joint view directions are measured from.\n3. Each chain root (first joint of a hair "
                                    + "strand, ear, tail) gets a ViewDependentPhysicalObject; its parent is the anchor.",
                                    MessageType.Info);
            modelRoot = (Transform)EditorGUILayout.ObjectField("Model root", modelRoot, typeof(Transform), true);
            viewReference = (Transform)EditorGUILayout.ObjectField("View reference bone", viewReference, typeof(Transform), true);

            EditorGUILayout.LabelField("Chain roots", EditorStyles.boldLabel);
            for (int i = 0; i < chainRoots.Count; i++)
            {
                EditorGUILayout.BeginHorizontal();
                chainRoots[i] = (Transform)EditorGUILayout.ObjectField("Chain " + (i + 1), chainRoots[i], typeof(Transform), true);
                if (GUILayout.Button("-", GUILayout.Width(24f)))
                {
                    chainRoots.RemoveAt(i);
                    EditorGUILayout.EndHorizontal();
                    break;
                }
                EditorGUILayout.EndHorizontal();
            }
            EditorGUILayout.BeginHorizontal();
            if (GUILayout.Button("Add chain root")) chainRoots.Add(null);
            if (GUILayout.Button("Add selected"))
            {
                foreach (Transform selected in Selection.transforms)
                    if (!chainRoots.Contains(selected)) chainRoots.Add(selected);
            }
            EditorGUILayout.EndHorizontal();

            string problem = Validate();
            if (problem != null) EditorGUILayout.HelpBox(problem, MessageType.Warning);
            using (new EditorGUI.DisabledScope(problem != null))
            {
                if (GUILayout.Button("Set Up")) SetUp(modelRoot, viewReference, chainRoots);
            }
        }

        string Validate()
        {
            if (modelRoot == null) return "Pick the model root.";
            if (viewReference == null) return "Pick the view reference bone (e.g. the head).";
            if (!viewReference.IsChildOf(modelRoot)) return "The view reference bone must be inside the model.";
            int count = 0;
            foreach (Transform root in chainRoots)
            {
                if (root == null) continue;
                if (!root.IsChildOf(modelRoot) || root == modelRoot) return root.name + " is not inside the model.";
                if (root.parent == null || root.childCount == 0) return root.name + " needs a parent (anchor) and a child joint.";
                count++;
            }
            return count == 0 ? "Add at least one chain root." : null;
        }

        /// <summary>Adds (or reuses) the components and wires them, as one undo step.</summary>
        public static Engine SetUp(Transform modelRoot, Transform viewReference, IList<Transform> chainRoots)
        {
            Undo.SetCurrentGroupName("Set Up Kodawari Character");
            int group = Undo.GetCurrentGroup();

            Engine engine = modelRoot.GetComponent<Engine>();
            if (engine == null) engine = Undo.AddComponent<Engine>(modelRoot.gameObject);
            Undo.RecordObject(engine, "Set Up Kodawari Character");
            engine.viewReference = viewReference;
            engine.chains.Clear();

            foreach (Transform root in chainRoots)
            {
                if (root == null) continue;
                ViewDependentPhysicalObject chain = root.GetComponent<ViewDependentPhysicalObject>();
                if (chain == null) chain = Undo.AddComponent<ViewDependentPhysicalObject>(root.gameObject);
                Undo.RecordObject(chain, "Set Up Kodawari Character");
                chain.root = root;
                engine.chains.Add(chain);
                EditorUtility.SetDirty(chain);
            }
            EditorUtility.SetDirty(engine);
            Undo.CollapseUndoOperations(group);
            return engine;
        }
    }
}
