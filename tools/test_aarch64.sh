#!/usr/bin/env bash
# The aarch64 build, linted and tested on this x86-64 machine: clippy for the aarch64 target, the Rust tests
# cross-compiled and run under qemu-user (the lane solver's portable kernel, the scalar solver on glam's scalar
# code, no AVX2 screen), then the C and C++ harnesses built with the cross compilers against the aarch64 shared
# library and run there too. The C# tests (Mono) and valgrind stay on x86-64. Installs the target's standard
# library (rustup) and the cross compilers and qemu (Debian packages) when missing.
#
#   tools/test_aarch64.sh                # what .ci/run runs
#   tools/test_aarch64.sh --test lanes   # extra arguments go to `cargo test` instead, and nothing else runs
set -euo pipefail
cd "$(dirname "$0")/.."

target=aarch64-unknown-linux-gnu
rustup target list --installed | grep -qx "$target" || rustup target add "$target"
missing=()
command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 || missing+=(gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v aarch64-linux-gnu-g++ >/dev/null 2>&1 || missing+=(g++-aarch64-linux-gnu)
command -v qemu-aarch64 >/dev/null 2>&1 || missing+=(qemu-user)
if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
qemu=(qemu-aarch64 -L /usr/aarch64-linux-gnu)
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="${qemu[*]}"
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

# The harnesses with the flags of tests/c_harness.rs and tests/cpp_bindings.rs; each ends on `N passed, 0 failed`.
cargo build --release --target "$target" --lib
lib=$(cd "$CARGO_TARGET_DIR/$target/release" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { "${qemu[@]}" "$@" | tee "$out/log"; tail -1 "$out/log" | grep -Eq '^[1-9][0-9]* passed, 0 failed$'; }
aarch64-linux-gnu-gcc -std=c11 -Wall -Wextra -Wpedantic -Werror -O1 -g -I include -I tests/c tests/c/*.c \
    -o "$out/c_harness" -L "$lib" -Wl,-rpath,"$lib" -lkodawari -lm
run "$out/c_harness"
cxx=(aarch64-linux-gnu-g++ -std=c++17 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Werror -g
    -I include -I bindings/cpp)
"${cxx[@]}" -c tests/cpp/test_kodawari.cpp -o "$out/test_kodawari.o"
"${cxx[@]}" -DKODAWARI_NO_EXCEPTIONS -fno-exceptions -c tests/cpp/test_no_exceptions.cpp -o "$out/test_no_exceptions.o"
aarch64-linux-gnu-g++ "$out/test_kodawari.o" "$out/test_no_exceptions.o" -o "$out/cpp_harness" \
    -L "$lib" -Wl,-rpath,"$lib" -lkodawari -ldl
run "$out/cpp_harness"
echo "aarch64: the C and C++ harnesses passed"

# `portable-determinism`: the x86-64 and aarch64 builds with it compute the same bits. The engine's state hash
# after the same scene runs, on both.
cargo build --release --target "$target" --example scene_cost --features portable-determinism
x86_dir=$CARGO_TARGET_DIR/x86-portable
CARGO_TARGET_DIR=$x86_dir cargo build --release --example scene_cost --features portable-determinism
runs=("20 100x16 lanes" "20 100x16 scalar" "20 100x16 views" "10 100x16 colliders" "20 100x16 limp" "20 100x16 lod1"
    "20 100x16 lod2" "20 ragged views" "10 ragged colliders" "4 1x1000 colliders")
for scene in "${runs[@]}"; do
    # shellcheck disable=SC2086 # the words of a scene are the example's arguments
    arm=$("${qemu[@]}" "$lib/examples/scene_cost" $scene | sed -n 1p)
    # shellcheck disable=SC2086
    x86=$("$x86_dir/release/examples/scene_cost" $scene | sed -n 1p)
    echo "scene_cost $scene: aarch64 $arm, x86-64 $x86"
    [ "$arm" = "$x86" ] || { echo "portable-determinism: x86-64 and aarch64 differ on $scene" >&2; exit 1; }
done
echo "aarch64: the same state hashes as x86-64 with portable-determinism on ${#runs[@]} scene runs"
