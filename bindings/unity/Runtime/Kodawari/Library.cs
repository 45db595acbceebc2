// Copied from bindings/csharp/Kodawari/Library.cs by `cargo gen-bindings`. Edit the original: a test fails when this copy is stale.
using System;
using System.Runtime.InteropServices;
using System.Text;
using Kodawari.Native;

namespace Kodawari
{
    /// <summary>Library-wide queries and the ABI check every <see cref="Engine"/> runs before its first call.</summary>
    public static unsafe class Library
    {
        /// <summary>The ABI version these bindings were generated against (<c>KDW_ABI_VERSION</c>).</summary>
        public const uint ExpectedAbiVersion = NativeMethods.KDW_ABI_VERSION;

        static volatile bool verified;

        // Error path only: grown on demand, reused afterwards. Per thread, like the native message.
        [ThreadStatic] static byte[] messageBuffer;

        /// <summary>The ABI version of the loaded native library.</summary>
        public static uint AbiVersion { get { return NativeMethods.kdw_abi_version(); } }

        /// <summary>The loaded native library's version, e.g. "0.1.0".</summary>
        public static string Version { get { return Utf8(NativeMethods.kdw_version_string()); } }

        static string simdPath;

        /// <summary>The instruction set the lane solver's kernel runs with on this CPU: "avx512", "avx2", "sse2" (the portable
        /// x86-64 kernel), "neon" or "scalar". Read once, then cached.</summary>
        public static string SimdPath
        {
            get
            {
                if (simdPath == null) simdPath = Utf8(NativeMethods.kdw_simd_path());
                return simdPath;
            }
        }

        /// <summary>Whether the loaded native library was built with <c>portable-determinism</c>: the same bits on
        /// x86-64 and aarch64 (replays, lockstep). Check it on every peer that must agree.</summary>
        public static bool PortableDeterminism { get { return NativeMethods.kdw_portable_determinism() != 0; } }

        /// <summary>Throws when the loaded library does not match these bindings: a different ABI version, or
        /// struct layouts that differ from the C ABI's (28-byte transforms). Cheap after the first success;
        /// <see cref="Engine"/> calls it before creating anything.</summary>
        public static void EnsureCompatible()
        {
            if (verified) return;
            CheckLayouts();
            CheckAbi(NativeMethods.kdw_abi_version(), ExpectedAbiVersion);
            verified = true;
        }

        internal static void CheckAbi(uint loaded, uint expected)
        {
            if (loaded != expected)
                throw new KodawariException(KodawariStatus.AbiMismatch,
                    "ABI mismatch: the native library has ABI version " + loaded + ", these bindings expect "
                    + expected + ". Use the kodawari native library these bindings were generated with.");
        }

        static void CheckLayouts()
        {
            CheckSize("kdw_vec3", sizeof(kdw_vec3), Marshal.SizeOf(typeof(kdw_vec3)), 12);
            CheckSize("kdw_quat", sizeof(kdw_quat), Marshal.SizeOf(typeof(kdw_quat)), 16);
            CheckSize("kdw_transform", sizeof(kdw_transform), Marshal.SizeOf(typeof(kdw_transform)), 28);
            CheckSize("Vec3", sizeof(Vec3), Marshal.SizeOf(typeof(Vec3)), 12);
            CheckSize("Quat", sizeof(Quat), Marshal.SizeOf(typeof(Quat)), 16);
            CheckSize("JointTransform", sizeof(JointTransform), Marshal.SizeOf(typeof(JointTransform)), 28);
            CheckSize("Vec2", sizeof(Vec2), Marshal.SizeOf(typeof(Vec2)), 8);
            CheckSize("kdw_stroke_camera", sizeof(kdw_stroke_camera), Marshal.SizeOf(typeof(kdw_stroke_camera)), 56);
            CheckSize("kdw_collider_def", sizeof(kdw_collider_def), Marshal.SizeOf(typeof(kdw_collider_def)), 48);
        }

        internal static void CheckSize(string name, int unmanaged, int marshalled, int expected)
        {
            if (unmanaged != expected || marshalled != expected)
                throw new KodawariException(KodawariStatus.AbiMismatch,
                    name + " is " + unmanaged + " bytes (marshalled " + marshalled + "), the C ABI needs " + expected);
        }

        /// <summary>The static description of a status ("unknown status" for values the library never returns).</summary>
        public static string StatusString(KodawariStatus status)
        {
            try
            {
                return Utf8(NativeMethods.kdw_status_str((int)status));
            }
            catch (DllNotFoundException)
            {
                return status.ToString();
            }
        }

        /// <summary>This thread's message about its last failed native call ("" if none).</summary>
        public static string LastErrorMessage()
        {
            uint length = 0;
            if (NativeMethods.kdw_last_error_message(null, 0, &length) != NativeMethods.KDW_STATUS_OK) return string.Empty;
            byte[] buffer = messageBuffer;
            if (buffer == null || buffer.Length < length + 1)
            {
                buffer = new byte[Math.Max(256, (int)length + 1)];
                messageBuffer = buffer;
            }
            fixed (byte* p = buffer)
            {
                NativeMethods.kdw_last_error_message(p, (uint)buffer.Length, &length);
                return Encoding.UTF8.GetString(buffer, 0, (int)Math.Min(length, (uint)buffer.Length - 1));
            }
        }

        /// <summary>Throws a <see cref="KodawariException"/> unless <paramref name="status"/> is OK. Allocation-free
        /// on success: this is the per-frame path.</summary>
        internal static void Check(int status)
        {
            if (status != NativeMethods.KDW_STATUS_OK) Throw(status);
        }

        static void Throw(int status)
        {
            throw new KodawariException((KodawariStatus)status, LastErrorMessage());
        }

        static string Utf8(byte* text)
        {
            if (text == null) return string.Empty;
            int length = 0;
            while (text[length] != 0) length++;
            return Encoding.UTF8.GetString(text, length);
        }
    }
}
