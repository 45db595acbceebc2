#!/usr/bin/env bash
# The aarch64 build, linted and tested on this x86-64 machine: clippy for the aarch64 target, then the Rust
# tests cross-compiled and run under qemu-user (the lane solver's portable kernel, the scalar solver on glam's
# scalar code, no AVX2 screen). The C, C++ and C# harnesses build with the host's compilers and stay on x86-64.
# Installs the target's standard library (rustup) and the cross linker and qemu (Debian packages) when missing.
#
#   tools/test_aarch64.sh            # what .ci/run runs
#   tools/test_aarch64.sh --test lanes   # extra arguments go to `cargo test` instead of the default set
set -euo pipefail
cd "$(dirname "$0")/.."

target=aarch64-unknown-linux-gnu
rustup target list --installed | grep -qx "$target" || rustup target add "$target"
missing=()
command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 || missing+=(gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v qemu-aarch64 >/dev/null 2>&1 || missing+=(qemu-user)
if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu"
# Its own target directory: the x86-64 build's stays warm.
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target/aarch64}
# Without the release profile's whole-program optimisation, which only saves time at run time and changes no
# result (no float operation is fused or reordered across crates), the test binaries link in a fraction of it.
export CARGO_PROFILE_RELEASE_LTO=${CARGO_PROFILE_RELEASE_LTO:-false}

cargo clippy --target "$target" --all-targets --features parallel,peers -- -D warnings
if [ $# -gt 0 ]; then
    exec cargo test --release --target "$target" "$@"
fi
# Release: the physics tests run hundreds of thousands of substeps, slow enough under emulation.
tests=(lanes engine physics reference skipping collisions character sketch no_alloc no_alloc_changes stress
    ffi_bad_input ffi_batch ffi_fuzz exports header)
cargo test --release --target "$target" --lib "${tests[@]/#/--test=}"
