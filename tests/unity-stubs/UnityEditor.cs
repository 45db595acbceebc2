// Compile-only stand-in for the part of the UnityEditor API the kodawari Unity package's editor scripts use:
// real namespaces, type names and signatures (Unity scripting reference), no behaviour.
#pragma warning disable 0067
using System;
using UnityEngine;
using Object = UnityEngine.Object;

namespace UnityEditor
{
    public class Editor : ScriptableObject
    {
        public Object target { get { throw null; } set { } }
        public Object[] targets { get { throw null; } }
        public SerializedObject serializedObject { get { throw null; } }
        public virtual void OnInspectorGUI() { }
        public bool DrawDefaultInspector() { throw null; }
        public void Repaint() { }
    }

    public class SerializedObject
    {
        public bool ApplyModifiedProperties() { throw null; }
        public void Update() { }
    }

    [AttributeUsage(AttributeTargets.Class, AllowMultiple = true, Inherited = false)]
    public class CustomEditor : Attribute
    {
        public CustomEditor(Type inspectedType) { }
        public CustomEditor(Type inspectedType, bool editorForChildClasses) { }
    }

    [AttributeUsage(AttributeTargets.Method, AllowMultiple = true)]
    public sealed class MenuItem : Attribute
    {
        public MenuItem(string itemName) { }
        public MenuItem(string itemName, bool isValidateFunction) { }
        public MenuItem(string itemName, bool isValidateFunction, int priority) { }
    }

    public class EditorWindow : ScriptableObject
    {
        public GUIContent titleContent { get { throw null; } set { } }
        public static T GetWindow<T>() where T : EditorWindow { throw null; }
        public static T GetWindow<T>(string title) where T : EditorWindow { throw null; }
        public void Show() { }
        public void Close() { }
        public void Repaint() { }
    }

    public class SceneView : EditorWindow
    {
        public static SceneView lastActiveSceneView { get { throw null; } }
        public Camera camera { get { throw null; } }
        public static event Action<SceneView> duringSceneGui;
        public static void RepaintAll() { }
    }

    public sealed class HandleUtility
    {
        public static void AddDefaultControl(int controlId) { }
        public static Vector2 GUIPointToScreenPixelCoordinate(Vector2 guiPoint) { throw null; }
        public static Ray GUIPointToWorldRay(Vector2 position) { throw null; }
    }

    public sealed class Handles
    {
        public static Color color { get { throw null; } set { } }
        public static void DrawAAPolyLine(float width, params Vector3[] points) { }
        public static void Label(Vector3 position, string text) { }
    }

    [Flags]
    public enum GizmoType
    {
        Pickable = 1,
        NotInSelectionHierarchy = 2,
        Selected = 4,
        Active = 8,
        InSelectionHierarchy = 16,
        NonSelected = 32,
    }

    [AttributeUsage(AttributeTargets.Method)]
    public sealed class DrawGizmo : Attribute
    {
        public DrawGizmo(GizmoType gizmo) { }
        public DrawGizmo(GizmoType gizmo, Type drawnGizmoType) { }
    }

    public class Selection
    {
        public static Transform activeTransform { get { throw null; } set { } }
        public static Transform[] transforms { get { throw null; } }
        public static GameObject activeGameObject { get { throw null; } set { } }
    }

    public class Undo
    {
        public static void RecordObject(Object objectToUndo, string name) { }
        public static void RecordObjects(Object[] objectsToUndo, string name) { }
        public static T AddComponent<T>(GameObject gameObject) where T : Component { throw null; }
        public static void RegisterCreatedObjectUndo(Object objectToUndo, string name) { }
        public static void SetCurrentGroupName(string name) { }
        public static int GetCurrentGroup() { throw null; }
        public static void CollapseUndoOperations(int groupIndex) { }
        public static void IncrementCurrentGroup() { }
    }

    public sealed class EditorUtility
    {
        public static void SetDirty(Object target) { }
        public static bool DisplayDialog(string title, string message, string ok) { throw null; }
    }

    public enum MessageType
    {
        None = 0,
        Info = 1,
        Warning = 2,
        Error = 3,
    }

    public sealed class EditorStyles
    {
        public static GUIStyle boldLabel { get { throw null; } }
    }

    public sealed class EditorGUI
    {
        public struct DisabledScope : IDisposable
        {
            public DisabledScope(bool disabled) { }
            public void Dispose() { }
        }
    }

    public sealed class EditorGUILayout
    {
        public static Object ObjectField(string label, Object obj, Type objType, bool allowSceneObjects, params GUILayoutOption[] options) { throw null; }
        public static void LabelField(string label, params GUILayoutOption[] options) { }
        public static void LabelField(string label, GUIStyle style, params GUILayoutOption[] options) { }
        public static void HelpBox(string message, MessageType type) { }
        public static bool Toggle(string label, bool value, params GUILayoutOption[] options) { throw null; }
        public static void Space() { }
        public static void BeginHorizontal(params GUILayoutOption[] options) { }
        public static void EndHorizontal() { }
    }
}
