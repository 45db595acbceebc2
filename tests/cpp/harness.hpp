// Tiny test harness shared by the C++ binding tests (tests/cpp/*.cpp): counters, CHECK macros and the
// quick-start scene (examples/c/quickstart.c) with a plain-C reference run. Uses no exceptions, so that
// the KODAWARI_NO_EXCEPTIONS translation unit (built with -fno-exceptions) can include it too.
#ifndef KODAWARI_TEST_HARNESS_HPP
#define KODAWARI_TEST_HARNESS_HPP

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "kodawari.h"

namespace harness {

struct Counters {
    int passed = 0;
    int failed = 0;
    bool current_failed = false;
    int engine_destroy_calls = 0;           // counted by the kdw_engine_destroy wrapper in test_kodawari.cpp
    kdw_engine* last_destroyed = nullptr;
    uint32_t fake_abi_version = 0;          // when non-zero, kdw_abi_version() returns it (test_kodawari.cpp)
};

// One instance for the whole program (an inline function's static is shared by every translation unit).
inline Counters& counters() {
    static Counters instance;
    return instance;
}

inline void fail(const char* file, int line, const char* what) {
    std::printf("    %s:%d: %s\n", file, line, what);
    counters().current_failed = true;
}

inline void run(const char* name, void (*test)()) {
    counters().current_failed = false;
    test();
    if (counters().current_failed) {
        ++counters().failed;
        std::printf("FAIL %s\n", name);
    } else {
        ++counters().passed;
        std::printf("ok   %s\n", name);
    }
}

// ---- The quick-start scene: a 6-joint ahoge on the head with two view shapes, the camera orbiting ----

constexpr uint32_t kJoints = 6;
constexpr int kFrames = 241;  // frames 0..240 at 1/60 s: one full orbit
constexpr float kDt = 1.0f / 60.0f;

struct Scene {
    kdw_transform base[kJoints];
    kdw_transform left[kJoints];
    kdw_transform right[kJoints];
    kdw_vec3 from_left{-1.0f, 0.0f, 0.0f};
    kdw_vec3 from_right{1.0f, 0.0f, 0.0f};
    kdw_transform head{{0.0f, 1.6f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}};
    float stiffness = 0.9f;
};

inline Scene ahoge_scene() {
    Scene scene;
    const kdw_quat identity{0.0f, 0.0f, 0.0f, 1.0f};
    for (uint32_t i = 0; i < kJoints; ++i) {
        const float t = static_cast<float>(i);
        scene.base[i] = kdw_transform{{0.0f, 0.12f + 0.03f * t, 0.0f}, identity};
        scene.left[i] = kdw_transform{{-0.01f * t * t, 0.12f + 0.025f * t, 0.0f}, identity};
        scene.right[i] = kdw_transform{{0.01f * t * t, 0.12f + 0.025f * t, 0.0f}, identity};
    }
    return scene;
}

inline kdw_vec3 orbit_camera(int frame) {
    const float angle = 6.2831853f * static_cast<float>(frame) / 240.0f;
    return kdw_vec3{2.5f * std::sin(angle), 1.7f, 2.5f * std::cos(angle)};
}

// What a run of the scene produced: every frame's world transforms, the final local rotations and rest
// shape, and the final state hash.
struct OrbitRun {
    std::vector<kdw_transform> frames;  // kFrames * kJoints
    std::vector<kdw_quat> local_rotations;
    std::vector<kdw_transform> rest_shape;
    uint64_t hash = 0;
    bool ok = false;
};

// The scene through the plain C API: the reference the C++ binding must reproduce bit for bit.
inline OrbitRun c_reference_orbit() {
    OrbitRun run;
    const Scene scene = ahoge_scene();
    const kdw_engine_def engine_def = kdw_engine_def_default();
    kdw_engine* engine = nullptr;
    if (kdw_engine_create(&engine_def, &engine) != KDW_STATUS_OK) return run;
    kdw_chain_def chain_def = kdw_chain_def_default();
    chain_def.stiffness = scene.stiffness;
    kdw_chain_id chain = 0;
    kdw_view_shape_id left = 0, right = 0;
    bool ok = kdw_chain_create(engine, &chain_def, scene.base, kJoints, &chain) == KDW_STATUS_OK &&
              kdw_chain_add_view_shape(engine, chain, &scene.from_left, scene.left, kJoints, 1.0f, &left) ==
                  KDW_STATUS_OK &&
              kdw_chain_add_view_shape(engine, chain, &scene.from_right, scene.right, kJoints, 1.0f, &right) ==
                  KDW_STATUS_OK;
    run.frames.resize(static_cast<size_t>(kFrames) * kJoints);
    uint32_t written = 0;
    for (int frame = 0; ok && frame < kFrames; ++frame) {
        const kdw_vec3 camera = orbit_camera(frame);
        ok = kdw_engine_step(engine, kDt, &camera, &scene.head) == KDW_STATUS_OK &&
             kdw_engine_read_world(engine, &run.frames[static_cast<size_t>(frame) * kJoints], kJoints, &written) ==
                 KDW_STATUS_OK &&
             written == kJoints;
    }
    run.local_rotations.resize(kJoints);
    run.rest_shape.resize(kJoints);
    ok = ok && kdw_engine_read_local_rotations(engine, run.local_rotations.data(), kJoints, &written) ==
                   KDW_STATUS_OK;
    ok = ok && kdw_chain_read_rest_shape(engine, chain, run.rest_shape.data(), kJoints, &written) == KDW_STATUS_OK;
    ok = ok && kdw_engine_state_hash(engine, &run.hash) == KDW_STATUS_OK;
    run.ok = kdw_engine_destroy(engine) == KDW_STATUS_OK && ok;
    return run;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

}  // namespace harness

// Records a failure and leaves the current test function.
#define CHECK(condition)                                        \
    do {                                                        \
        if (!(condition)) {                                     \
            harness::fail(__FILE__, __LINE__, "CHECK(" #condition ")"); \
            return;                                             \
        }                                                       \
    } while (0)

#endif  // KODAWARI_TEST_HARNESS_HPP
