// Copied from bindings/csharp/Kodawari/KodawariException.cs by `cargo gen-bindings`. Edit the original: a test fails when this copy is stale.
using System;

namespace Kodawari
{
    /// <summary>A failed kodawari call: the C status and this thread's message from
    /// <c>kdw_last_error_message</c>. The engine's state is unchanged by the failed call.</summary>
    public sealed class KodawariException : Exception
    {
        /// <summary>The <c>KDW_STATUS_*</c> value the call returned.</summary>
        public KodawariStatus Status { get; private set; }

        /// <summary>The library's detail message (may be empty, e.g. for errors detected in C#).</summary>
        public string NativeMessage { get; private set; }

        public KodawariException(KodawariStatus status, string nativeMessage)
            : base(Format(status, nativeMessage))
        {
            Status = status;
            NativeMessage = nativeMessage ?? string.Empty;
        }

        static string Format(KodawariStatus status, string nativeMessage)
        {
            string name = Library.StatusString(status);
            return string.IsNullOrEmpty(nativeMessage)
                ? "kodawari: " + name + " (" + (int)status + ")"
                : "kodawari: " + name + " (" + (int)status + "): " + nativeMessage;
        }
    }
}
