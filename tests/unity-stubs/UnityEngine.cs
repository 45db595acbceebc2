// Compile-only stand-in for the part of the UnityEngine API the kodawari Unity package uses: real namespaces,
// type names and signatures (Unity scripting reference), no behaviour. Used by tests/unity_compile.rs.
#pragma warning disable 0660, 0661, 0067
using System;
using System.Collections;

namespace UnityEngine
{
    public class Object
    {
        public string name { get { throw null; } set { } }
        public int GetInstanceID() { throw null; }
        public static implicit operator bool(Object exists) { throw null; }
        public static bool operator ==(Object x, Object y) { throw null; }
        public static bool operator !=(Object x, Object y) { throw null; }
        public static void Destroy(Object obj) { }
        public static void DestroyImmediate(Object obj) { }
    }

    public class Component : Object
    {
        public Transform transform { get { throw null; } }
        public GameObject gameObject { get { throw null; } }
        public T GetComponent<T>() { throw null; }
        public T GetComponentInParent<T>() { throw null; }
        public T GetComponentInChildren<T>() { throw null; }
        public T[] GetComponentsInChildren<T>(bool includeInactive) { throw null; }
        public T[] GetComponentsInChildren<T>() { throw null; }
    }

    public class Behaviour : Component
    {
        public bool enabled { get { throw null; } set { } }
        public bool isActiveAndEnabled { get { throw null; } }
    }

    public class MonoBehaviour : Behaviour { }

    public class ScriptableObject : Object { }

    public sealed class GameObject : Object
    {
        public Transform transform { get { throw null; } }
        public int layer { get { throw null; } set { } }
        public bool activeSelf { get { throw null; } }
        public bool activeInHierarchy { get { throw null; } }
        public T GetComponent<T>() { throw null; }
        public T AddComponent<T>() where T : Component { throw null; }
    }

    public class Collider : Component
    {
        public bool enabled { get { throw null; } set { } }
        public bool isTrigger { get { throw null; } set { } }
    }

    public class SphereCollider : Collider
    {
        public Vector3 center { get { throw null; } set { } }
        public float radius { get { throw null; } set { } }
    }

    public class CapsuleCollider : Collider
    {
        public Vector3 center { get { throw null; } set { } }
        public float radius { get { throw null; } set { } }
        public float height { get { throw null; } set { } }
        public int direction { get { throw null; } set { } }
    }

    public class Transform : Component, IEnumerable
    {
        public Vector3 position { get { throw null; } set { } }
        public Quaternion rotation { get { throw null; } set { } }
        public Vector3 localPosition { get { throw null; } set { } }
        public Quaternion localRotation { get { throw null; } set { } }
        public Vector3 lossyScale { get { throw null; } }
        public Transform parent { get { throw null; } set { } }
        public int childCount { get { throw null; } }
        public Transform GetChild(int index) { throw null; }
        public bool IsChildOf(Transform parent) { throw null; }
        public Vector3 InverseTransformPoint(Vector3 position) { throw null; }
        public Vector3 InverseTransformDirection(Vector3 direction) { throw null; }
        public Vector3 TransformPoint(Vector3 position) { throw null; }
        public IEnumerator GetEnumerator() { throw null; }
    }

    public sealed class Camera : Behaviour
    {
        public static Camera main { get { throw null; } }
        public static Camera current { get { throw null; } }
        public float fieldOfView { get { throw null; } set { } }
        public bool orthographic { get { throw null; } set { } }
        public float orthographicSize { get { throw null; } set { } }
        public float nearClipPlane { get { throw null; } set { } }
        public int pixelWidth { get { throw null; } }
        public int pixelHeight { get { throw null; } }
    }

    public struct Ray
    {
        public Ray(Vector3 origin, Vector3 direction) { throw null; }
        public Vector3 origin { get { throw null; } set { } }
        public Vector3 direction { get { throw null; } set { } }
        public Vector3 GetPoint(float distance) { throw null; }
    }

    public struct Vector2 : IEquatable<Vector2>
    {
        public float x;
        public float y;
        public Vector2(float x, float y) { this.x = x; this.y = y; }
        public float magnitude { get { throw null; } }
        public float sqrMagnitude { get { throw null; } }
        public static Vector2 operator +(Vector2 a, Vector2 b) { throw null; }
        public static Vector2 operator -(Vector2 a, Vector2 b) { throw null; }
        public static bool operator ==(Vector2 lhs, Vector2 rhs) { throw null; }
        public static bool operator !=(Vector2 lhs, Vector2 rhs) { throw null; }
        public bool Equals(Vector2 other) { throw null; }
        public override bool Equals(object other) { throw null; }
        public override int GetHashCode() { throw null; }
        public override string ToString() { throw null; }
    }

    public struct Color : IEquatable<Color>
    {
        public float r;
        public float g;
        public float b;
        public float a;
        public Color(float r, float g, float b, float a) { this.r = r; this.g = g; this.b = b; this.a = a; }
        public Color(float r, float g, float b) { this.r = r; this.g = g; this.b = b; this.a = 1f; }
        public static Color white { get { throw null; } }
        public bool Equals(Color other) { throw null; }
        public override bool Equals(object other) { throw null; }
        public override int GetHashCode() { throw null; }
    }

    public sealed class Gizmos
    {
        public static Color color { get { throw null; } set { } }
        public static void DrawLine(Vector3 from, Vector3 to) { }
        public static void DrawWireSphere(Vector3 center, float radius) { }
        public static void DrawSphere(Vector3 center, float radius) { }
    }

    public enum EventType
    {
        MouseDown = 0,
        MouseUp = 1,
        MouseMove = 2,
        MouseDrag = 3,
        KeyDown = 4,
        KeyUp = 5,
        ScrollWheel = 6,
        Repaint = 7,
        Layout = 8,
        Used = 12,
    }

    public enum FocusType
    {
        Keyboard = 1,
        Passive = 2,
    }

    public sealed class Event
    {
        public static Event current { get { throw null; } set { } }
        public EventType type { get { throw null; } set { } }
        public int button { get { throw null; } set { } }
        public bool alt { get { throw null; } }
        public Vector2 mousePosition { get { throw null; } set { } }
        public EventType GetTypeForControl(int controlID) { throw null; }
        public void Use() { }
    }

    public class GUIUtility
    {
        public static int hotControl { get { throw null; } set { } }
        public static int GetControlID(FocusType focus) { throw null; }
    }

    public struct Vector3 : IEquatable<Vector3>
    {
        public float x;
        public float y;
        public float z;
        public Vector3(float x, float y, float z) { this.x = x; this.y = y; this.z = z; }
        public static Vector3 zero { get { throw null; } }
        public static Vector3 one { get { throw null; } }
        public static Vector3 up { get { throw null; } }
        public static Vector3 forward { get { throw null; } }
        public static Vector3 right { get { throw null; } }
        public static Vector3 Cross(Vector3 lhs, Vector3 rhs) { throw null; }
        public Vector3 normalized { get { throw null; } }
        public float magnitude { get { throw null; } }
        public float sqrMagnitude { get { throw null; } }
        public static float Dot(Vector3 lhs, Vector3 rhs) { throw null; }
        public static Vector3 operator +(Vector3 a, Vector3 b) { throw null; }
        public static Vector3 operator -(Vector3 a, Vector3 b) { throw null; }
        public static Vector3 operator -(Vector3 a) { throw null; }
        public static Vector3 operator *(Vector3 a, float d) { throw null; }
        public static Vector3 operator *(float d, Vector3 a) { throw null; }
        public static Vector3 operator /(Vector3 a, float d) { throw null; }
        public static bool operator ==(Vector3 lhs, Vector3 rhs) { throw null; }
        public static bool operator !=(Vector3 lhs, Vector3 rhs) { throw null; }
        public bool Equals(Vector3 other) { throw null; }
        public override bool Equals(object other) { throw null; }
        public override int GetHashCode() { throw null; }
        public override string ToString() { throw null; }
        public string ToString(string format) { throw null; }
    }

    public struct Quaternion : IEquatable<Quaternion>
    {
        public float x;
        public float y;
        public float z;
        public float w;
        public Quaternion(float x, float y, float z, float w) { this.x = x; this.y = y; this.z = z; this.w = w; }
        public static Quaternion identity { get { throw null; } }
        public static Quaternion Inverse(Quaternion rotation) { throw null; }
        public static Quaternion LookRotation(Vector3 forward) { throw null; }
        public static Quaternion operator *(Quaternion lhs, Quaternion rhs) { throw null; }
        public static Vector3 operator *(Quaternion rotation, Vector3 point) { throw null; }
        public static bool operator ==(Quaternion lhs, Quaternion rhs) { throw null; }
        public static bool operator !=(Quaternion lhs, Quaternion rhs) { throw null; }
        public bool Equals(Quaternion other) { throw null; }
        public override bool Equals(object other) { throw null; }
        public override int GetHashCode() { throw null; }
    }

    public struct Mathf
    {
        public const float PI = 3.14159274F;
        public const float Deg2Rad = 0.0174532924F;
        public const float Rad2Deg = 57.29578F;
        public static float Max(float a, float b) { throw null; }
        public static int Max(int a, int b) { throw null; }
        public static float Min(float a, float b) { throw null; }
        public static float Clamp(float value, float min, float max) { throw null; }
        public static int Clamp(int value, int min, int max) { throw null; }
        public static float Clamp01(float value) { throw null; }
        public static float Abs(float f) { throw null; }
        public static float Pow(float f, float p) { throw null; }
    }

    public class Time
    {
        public static float deltaTime { get { throw null; } }
        public static float time { get { throw null; } }
    }

    public class Application
    {
        public static bool isPlaying { get { throw null; } }
    }

    public class Debug
    {
        public static void Log(object message) { }
        public static void Log(object message, Object context) { }
        public static void LogWarning(object message) { }
        public static void LogWarning(object message, Object context) { }
        public static void LogError(object message) { }
        public static void LogError(object message, Object context) { }
        public static void LogException(Exception exception) { }
        public static void LogException(Exception exception, Object context) { }
    }

    public sealed class GUILayoutOption { }

    public class GUIStyle { }

    public class GUIContent
    {
        public GUIContent(string text) { }
    }

    public class GUILayout
    {
        public static bool Button(string text, params GUILayoutOption[] options) { throw null; }
        public static GUILayoutOption Width(float width) { throw null; }
    }

    // ---- attributes ----

    public abstract class PropertyAttribute : Attribute { }

    [AttributeUsage(AttributeTargets.Field, Inherited = true, AllowMultiple = false)]
    public sealed class RangeAttribute : PropertyAttribute
    {
        public RangeAttribute(float min, float max) { }
    }

    [AttributeUsage(AttributeTargets.Field, Inherited = true, AllowMultiple = false)]
    public class TooltipAttribute : PropertyAttribute
    {
        public TooltipAttribute(string tooltip) { }
    }

    [AttributeUsage(AttributeTargets.Field, Inherited = true, AllowMultiple = true)]
    public class HeaderAttribute : PropertyAttribute
    {
        public HeaderAttribute(string header) { }
    }

    [AttributeUsage(AttributeTargets.Field, Inherited = true, AllowMultiple = false)]
    public sealed class SerializeField : Attribute { }

    [AttributeUsage(AttributeTargets.Field, Inherited = true, AllowMultiple = false)]
    public class HideInInspector : Attribute { }

    [AttributeUsage(AttributeTargets.Class, Inherited = false, AllowMultiple = false)]
    public sealed class DisallowMultipleComponent : Attribute { }

    [AttributeUsage(AttributeTargets.Class, Inherited = false, AllowMultiple = false)]
    public sealed class AddComponentMenu : Attribute
    {
        public AddComponentMenu(string menuName) { }
    }

    [AttributeUsage(AttributeTargets.Class, Inherited = false, AllowMultiple = false)]
    public class DefaultExecutionOrder : Attribute
    {
        public DefaultExecutionOrder(int order) { }
    }
}
