using System;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>A collision shape owned by an <see cref="Engine"/>: a non-owning handle, the engine plus the collider's
    /// id, cheap to copy. Its pose is set for all colliders at once, in creation order, by
    /// <see cref="Engine.SetColliderTransforms(ReadOnlySpan{JointTransform})"/>. A destroyed collider's handle throws a
    /// <see cref="KodawariException"/> with <see cref="KodawariStatus.InvalidId"/>, never undefined behaviour.</summary>
    public struct Collider : IEquatable<Collider>
    {
        readonly Engine engine;
        readonly ulong id;

        internal Collider(Engine engine, ulong id)
        {
            this.engine = engine;
            this.id = id;
        }

        /// <summary>The engine that owns the collider (null for a default handle).</summary>
        public Engine Engine { get { return engine; } }

        /// <summary>The native <c>kdw_collider_id</c> (0 is null).</summary>
        public ulong Id { get { return id; } }

        unsafe kdw_engine* Ptr
        {
            get
            {
                if (engine == null) throw new KodawariException(KodawariStatus.InvalidId, "null collider handle");
                return engine.Ptr;
            }
        }

        /// <summary>True if the collider is alive in a live engine.</summary>
        public unsafe bool IsValid
        {
            get
            {
                if (engine == null || engine.IsDisposed) return false;
                uint valid = 0;
                Library.Check(NativeMethods.kdw_collider_is_valid(engine.Ptr, id, &valid));
                return valid != 0;
            }
        }

        /// <summary>Moves the collider to other layers: it affects chains whose collision mask shares a bit.</summary>
        public unsafe void SetLayers(uint layers) { Library.Check(NativeMethods.kdw_collider_set_layers(Ptr, id, layers)); }

        /// <summary>Resizes the collider, keeping its shape: <paramref name="radius"/> and <paramref name="halfHeight"/> in
        /// world units, validated as in <see cref="ColliderDef"/> (e.g. when the bone it follows is scaled). Wakes sleeping
        /// chains.</summary>
        public unsafe void SetSize(float radius, float halfHeight)
        {
            Library.Check(NativeMethods.kdw_collider_set_size(Ptr, id, radius, halfHeight));
        }

        /// <summary>Destroys the collider; later colliders keep their relative order.</summary>
        public unsafe void Destroy() { Library.Check(NativeMethods.kdw_collider_destroy(Ptr, id)); }

        public bool Equals(Collider other) { return engine == other.engine && id == other.id; }
        public override bool Equals(object obj) { return obj is Collider && Equals((Collider)obj); }
        public override int GetHashCode() { return id.GetHashCode(); }
        public override string ToString() { return "Collider(0x" + id.ToString("x") + ")"; }
    }
}
