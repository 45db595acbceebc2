// Tests of the C++ binding bindings/cpp/kodawari.hpp (exceptions mode), linked dynamically against
// libkodawari.so together with test_no_exceptions.cpp (the KODAWARI_NO_EXCEPTIONS mode, built with
// -fno-exceptions). Built and run by tests/cpp_bindings.rs (`cargo test --test cpp_bindings`).
// The last line printed is "N passed, M failed"; the exit status is non-zero on any failure.

#include <dlfcn.h>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "harness.hpp"
#include "kodawari.hpp"

// Counts every kdw_engine_destroy the binding makes, then forwards to the library's. The executable's
// definition takes precedence over the shared library's (ELF symbol interposition), so the destructor's
// calls land here and "destroyed exactly once" can be checked exactly.
extern "C" kdw_status kdw_engine_destroy(kdw_engine* engine) {
    using Destroy = kdw_status (*)(kdw_engine*);
    static const Destroy library_destroy = reinterpret_cast<Destroy>(dlsym(RTLD_NEXT, "kdw_engine_destroy"));
    ++harness::counters().engine_destroy_calls;
    harness::counters().last_destroyed = engine;
    return library_destroy != nullptr ? library_destroy(engine) : KDW_STATUS_PANIC;
}

// Lets a test pretend the loaded library has another ABI version.
extern "C" uint32_t kdw_abi_version(void) {
    using Version = uint32_t (*)(void);
    static const Version library_version = reinterpret_cast<Version>(dlsym(RTLD_NEXT, "kdw_abi_version"));
    if (harness::counters().fake_abi_version != 0) return harness::counters().fake_abi_version;
    return library_version != nullptr ? library_version() : 0;
}

void run_no_exception_tests();  // test_no_exceptions.cpp

namespace {

using kodawari::ChainDef;
using kodawari::Collider;
using kodawari::ColliderDef;
using kodawari::Engine;
using kodawari::EngineDef;
using kodawari::Transform;
using kodawari::ViewDependentPhysicalObject;
using kodawari::ViewShape;

// `expression` must throw kodawari::Error with `expected` status and a non-empty message.
#define CHECK_THROWS(expression, expected)                                         \
    do {                                                                           \
        kdw_status thrown = KDW_STATUS_OK;                                         \
        std::string message;                                                       \
        try {                                                                      \
            (void)(expression);                                                    \
        } catch (const kodawari::Error& error) {                                   \
            thrown = error.status();                                               \
            message = error.message();                                             \
        }                                                                          \
        CHECK(thrown == (expected));                                               \
        CHECK(!message.empty());                                                   \
    } while (0)

// Same methods, plain values: in exceptions mode fallible calls return T / void.
static_assert(std::is_same_v<decltype(std::declval<Engine&>().chainCount()), uint32_t>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().step(0.0f, {}, {})), void>);
static_assert(std::is_same_v<kodawari::Ret<ViewShape>, ViewShape>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().solver()), kodawari::Solver>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().setSolver(kodawari::Solver::Scalar)), void>);
static_assert(std::is_same_v<std::underlying_type_t<kodawari::Solver>, uint32_t>);

// Ownership: move-only engine, cheap copyable handles.
static_assert(!std::is_copy_constructible_v<Engine> && !std::is_copy_assignable_v<Engine>);
static_assert(std::is_nothrow_move_constructible_v<Engine> && std::is_nothrow_move_assignable_v<Engine>);
static_assert(std::is_nothrow_destructible_v<Engine>);
static_assert(std::is_constructible_v<bool, Engine> && !std::is_convertible_v<Engine, bool>);
static_assert(std::is_trivially_copyable_v<ViewDependentPhysicalObject> && std::is_trivially_copyable_v<ViewShape>);
static_assert(std::is_trivially_copyable_v<Collider> && std::is_same_v<kodawari::Ret<Collider>, Collider>);
static_assert(std::is_base_of_v<kdw_collider_def, ColliderDef> && sizeof(ColliderDef) == sizeof(kdw_collider_def));
static_assert(std::is_base_of_v<std::runtime_error, kodawari::Error>);
static_assert(std::is_base_of_v<kdw_engine_def, EngineDef> && sizeof(EngineDef) == sizeof(kdw_engine_def));
static_assert(std::is_base_of_v<kdw_chain_def, ChainDef> && sizeof(ChainDef) == sizeof(kdw_chain_def));

ChainDef ahoge_def(const harness::Scene& scene) {
    ChainDef def;
    def.stiffness = scene.stiffness;
    return def;
}

void test_defaults_and_versions() {
    const EngineDef engine_def;
    const kdw_engine_def c_engine_def = kdw_engine_def_default();
    CHECK(std::memcmp(&engine_def, &c_engine_def, sizeof c_engine_def) == 0);
    const ChainDef chain_def;
    const kdw_chain_def c_chain_def = kdw_chain_def_default();
    CHECK(std::memcmp(&chain_def, &c_chain_def, sizeof c_chain_def) == 0);
    CHECK(chain_def.struct_size == sizeof(kdw_chain_def));
    const ColliderDef collider_def;
    const kdw_collider_def c_collider_def = kdw_collider_def_default();
    CHECK(std::memcmp(&collider_def, &c_collider_def, sizeof c_collider_def) == 0);
    const ColliderDef capsule = ColliderDef::capsule(0.05f, 0.2f, Transform{{1.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f, 1.0f}});
    CHECK(capsule.shape == KDW_COLLIDER_CAPSULE && capsule.radius == 0.05f && capsule.half_height == 0.2f);
    CHECK(capsule.transform.position.z == 3.0f && capsule.layers == c_collider_def.layers);
    CHECK(engine_def.teleport_mode == KDW_TELEPORT_CARRY_SHAPE && engine_def.scale == 1.0f);
    CHECK(chain_def.collision_mask == 0xFFFFFFFFu && chain_def.friction == 0.3f);
    CHECK(kodawari::abiVersion() == KDW_ABI_VERSION);
    CHECK(std::string(kodawari::versionString()).size() > 0);
    const std::string simd = kodawari::simdPath();
    CHECK(simd == "avx512" || simd == "avx2" || simd == "sse2" || simd == "neon" || simd == "scalar");
    CHECK(!kodawari::portableDeterminism()); // the harness links the default build (tests/common/native.rs)
    CHECK(std::string(kodawari::statusString(KDW_STATUS_INVALID_ID)) == kdw_status_str(KDW_STATUS_INVALID_ID));
}

void test_abi_mismatch_refuses_to_create() {
    const int destroys_before = harness::counters().engine_destroy_calls;
    harness::counters().fake_abi_version = KDW_ABI_VERSION + 1;
    bool threw = false;
    try {
        Engine engine{EngineDef()};
    } catch (const kodawari::Error& error) {
        threw = error.status() == kodawari::kStatusAbiMismatch && !error.message().empty();
    }
    harness::counters().fake_abi_version = 0;
    CHECK(threw);
    CHECK(harness::counters().engine_destroy_calls == destroys_before);  // nothing was created
    CHECK(Engine::create());
}

void test_life_cycle() {
    const harness::Scene scene = harness::ahoge_scene();
    const int destroys_before = harness::counters().engine_destroy_calls;
    kdw_engine* raw = nullptr;
    {
        Engine engine{EngineDef()};
        raw = engine.handle();
        CHECK(engine && raw != nullptr);
        CHECK(engine.chainCount() == 0 && engine.jointCount() == 0);

        ViewDependentPhysicalObject ahoge = engine.createChain(ahoge_def(scene), scene.base);  // C array
        CHECK(ahoge.isValid() && ahoge.engine() == raw && ahoge.id() != 0);
        CHECK(engine.chain(ahoge.id()) == ahoge);
        CHECK(ahoge.jointCount() == harness::kJoints && engine.jointCount() == harness::kJoints);
        CHECK(ahoge.def().stiffness == scene.stiffness);

        const std::vector<Transform> tail_shape(scene.base, scene.base + harness::kJoints);  // std::vector
        ViewDependentPhysicalObject tail = engine.createChain(ChainDef(), tail_shape);
        CHECK(tail != ahoge && tail.isValid());
        CHECK(engine.chainCount() == 2 && engine.jointCount() == 2 * harness::kJoints);
        std::vector<kodawari::ChainId> ids;
        engine.chainIds(ids);
        CHECK(ids.size() == 2 && ids[0] == ahoge.id() && ids[1] == tail.id());
        std::array<kodawari::ChainId, 4> id_buffer{};
        CHECK(engine.chainIds(id_buffer.data(), 4) == 2 && id_buffer[1] == tail.id());

        ViewShape left = ahoge.addViewShape(scene.from_left, scene.left, 1.0f);
        ViewShape right = ahoge.addViewShape(scene.from_right, scene.right, harness::kJoints, 1.0f);  // pointer
        CHECK(left != right && ahoge.viewShapeCount() == 2 && tail.viewShapeCount() == 0);
        left.setInfluence(2.0f);
        left.setDirection(kodawari::Vec3{-1.0f, 0.2f, 0.0f});
        right.setJoints(scene.right);

        // Settings round trips.
        EngineDef engine_def = engine.def();
        engine_def.iterations = 4;
        engine.setDef(engine_def);
        CHECK(engine.def().iterations == 4);
        engine.setGravity({0.0f, -3.0f, 0.0f});
        CHECK(engine.gravity().y == -3.0f);
        ChainDef tail_def = tail.def();
        tail_def.anchor = KDW_ANCHOR_OWN;
        tail_def.damping = 2.0f;
        tail.setDef(tail_def);
        CHECK(tail.def().anchor == KDW_ANCHOR_OWN && tail.def().damping == 2.0f);

        // A few frames, anchors included; read-backs into reused vectors.
        const std::array<Transform, 2> anchors{scene.head, Transform{{0.3f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}}};
        std::vector<Transform> world, rest;
        std::vector<kodawari::Quat> local;
        for (int frame = 0; frame < 10; ++frame) {
            engine.setAnchors(anchors);
            engine.step(harness::kDt, harness::orbit_camera(frame), scene.head);
            engine.readWorld(world);
            engine.readLocalRotations(local);
        }
        CHECK(world.size() == 2 * harness::kJoints && local.size() == world.size());
        CHECK(std::isfinite(world.back().position.x) && std::fabs(world.back().position.x - 0.3f) < 0.5f);
        std::vector<Transform> tail_world;
        tail.readWorld(tail_world);
        CHECK(tail_world.size() == harness::kJoints);
        CHECK(std::memcmp(tail_world.data(), &world[harness::kJoints], harness::kJoints * sizeof(Transform)) == 0);
        ahoge.readRestShape(rest);
        CHECK(rest.size() == harness::kJoints);
        Transform rest_buffer[harness::kJoints];
        CHECK(ahoge.readRestShape(rest_buffer, harness::kJoints) == harness::kJoints);
        CHECK(ahoge.kineticEnergy() >= 0.0f);
        const kodawari::EngineStats stats = engine.stats();
        CHECK(stats.chain_count == 2 && stats.joint_count == 2 * harness::kJoints && stats.substeps_total > 0);
        // The one-call frame: same rotations as the three calls would give from here on.
        {
            std::vector<kodawari::Quat> one_call(local.size());
            const uint64_t before = engine.stateHash();
            CHECK(engine.stepAndReadLocalRotations(harness::kDt, harness::orbit_camera(10), scene.head, anchors.data(),
                                                   2, one_call.data(), static_cast<uint32_t>(one_call.size())) ==
                  local.size());
            CHECK(engine.stateHash() != before);
            CHECK_THROWS(engine.stepAndReadLocalRotations(harness::kDt, harness::orbit_camera(11), scene.head,
                                                          anchors.data(), 2, one_call.data(), 1),
                         KDW_STATUS_BUFFER_TOO_SMALL);
            engine.readLocalRotations(local);
            CHECK(std::memcmp(local.data(), one_call.data(), local.size() * sizeof(kodawari::Quat)) == 0);
        }

        ahoge.setBaseShape(scene.left);
        ahoge.reset();
        engine.reset();
        right.remove();
        CHECK(ahoge.viewShapeCount() == 1);
        tail.destroy();
        CHECK(!tail.isValid() && engine.chainCount() == 1);
        CHECK(harness::counters().engine_destroy_calls == destroys_before);
    }
    CHECK(harness::counters().engine_destroy_calls == destroys_before + 1);
    CHECK(harness::counters().last_destroyed == raw);
}

void test_moves_destroy_exactly_once() {
    const harness::Scene scene = harness::ahoge_scene();
    const int before = harness::counters().engine_destroy_calls;
    kdw_engine* raw = nullptr;
    {
        Engine a{EngineDef()};
        raw = a.handle();
        const ViewDependentPhysicalObject ahoge = a.createChain(ahoge_def(scene), scene.base);

        Engine b(std::move(a));  // move construction
        CHECK(!a && a.handle() == nullptr && b && b.handle() == raw);
        CHECK(ahoge.isValid());  // handles hold the C engine, not the C++ object

        Engine c;
        CHECK(!c && c.handle() == nullptr);
        c = std::move(b);  // move assignment into an empty engine
        CHECK(!b && c.handle() == raw);
        c.step(harness::kDt, harness::orbit_camera(0), scene.head);
        CHECK(harness::counters().engine_destroy_calls == before);

        Engine d{EngineDef()};
        kdw_engine* const raw_d = d.handle();
        d = std::move(c);  // the engine d owned is destroyed, once
        CHECK(harness::counters().engine_destroy_calls == before + 1 && harness::counters().last_destroyed == raw_d);
        CHECK(!c && d.handle() == raw && ahoge.jointCount() == harness::kJoints);

        Engine& alias = d;
        d = std::move(alias);  // self-move keeps the engine
        CHECK(d.handle() == raw && harness::counters().engine_destroy_calls == before + 1);

        // release() hands the C handle over; adopting it again gives it back to RAII.
        kdw_engine* const released = d.release();
        CHECK(!d && released == raw);
        Engine adopted(released);
        CHECK(adopted.handle() == raw && ahoge.isValid());
    }
    // a, b, c, d were emptied by moves: only `adopted` destroyed the engine.
    CHECK(harness::counters().engine_destroy_calls == before + 2);
    CHECK(harness::counters().last_destroyed == raw);
}

void test_invalid_calls_throw_and_leave_state_unchanged() {
    const harness::Scene scene = harness::ahoge_scene();
    Engine engine{EngineDef()};
    const ViewDependentPhysicalObject ahoge = engine.createChain(ahoge_def(scene), scene.base);
    const ViewShape left = ahoge.addViewShape(scene.from_left, scene.left, 1.0f);
    for (int frame = 0; frame < 30; ++frame) engine.step(harness::kDt, harness::orbit_camera(frame), scene.head);
    const uint64_t before = engine.stateHash();

    ChainDef too_stiff = ahoge.def();
    too_stiff.stiffness = 2.0f;
    CHECK_THROWS(ahoge.setDef(too_stiff), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.stateHash() == before && ahoge.def().stiffness == scene.stiffness);

    CHECK_THROWS(engine.step(std::numeric_limits<float>::quiet_NaN(), harness::orbit_camera(30), scene.head),
                 KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(engine.step(-1.0f, harness::orbit_camera(30), scene.head), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.stateHash() == before);

    EngineDef no_iterations;
    no_iterations.iterations = 0;
    CHECK_THROWS(engine.setDef(no_iterations), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(Engine{no_iterations}, KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(engine.createChain(ChainDef(), scene.base, 1), KDW_STATUS_INVALID_ARGUMENT);  // n < 2
    CHECK_THROWS(left.setInfluence(0.0f), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(left.setDirection(kodawari::Vec3{0.0f, 0.0f, 0.0f}), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(ahoge.setBaseShape(scene.base, 3), KDW_STATUS_INVALID_ARGUMENT);  // wrong joint count
    ChainDef wrong_size;
    wrong_size.struct_size = 4;
    CHECK_THROWS(ahoge.setDef(wrong_size), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    Transform small[2];
    CHECK_THROWS(engine.readWorld(small, 2), KDW_STATUS_BUFFER_TOO_SMALL);
    CHECK_THROWS(engine.setAnchors(nullptr, 0), KDW_STATUS_INVALID_ARGUMENT);  // one anchor per chain
    CHECK(engine.stateHash() == before && engine.chainCount() == 1 && ahoge.viewShapeCount() == 1);

    // The error carries status and message; what() says both.
    try {
        ahoge.setDef(too_stiff);
        CHECK(false);
    } catch (const std::runtime_error& error) {
        const auto& kodawari_error = dynamic_cast<const kodawari::Error&>(error);
        CHECK(kodawari_error.status() == KDW_STATUS_INVALID_ARGUMENT);
        CHECK(std::string(error.what()).find(kodawari_error.message()) != std::string::npos);
        CHECK(std::string(error.what()).find(kdw_status_str(KDW_STATUS_INVALID_ARGUMENT)) == 0);
    }

    // Result::value() on a failure throws the same Error in exceptions mode.
    const kodawari::Result<int> failed(kodawari::Status(KDW_STATUS_INVALID_ID, "gone"));
    CHECK(!failed.ok() && failed.valueOr(7) == 7);
    CHECK_THROWS(failed.value(), KDW_STATUS_INVALID_ID);

    // An empty (moved-from or default) engine reports a null pointer instead of crashing.
    Engine empty;
    CHECK_THROWS(empty.chainCount(), KDW_STATUS_NULL_POINTER);
}

void test_orbit_scene_matches_plain_c() {
    const harness::OrbitRun reference = harness::c_reference_orbit();
    CHECK(reference.ok);

    const harness::Scene scene = harness::ahoge_scene();
    Engine engine = Engine::create();
    const ViewDependentPhysicalObject ahoge = engine.createChain(ahoge_def(scene), scene.base);
    const ViewShape left = ahoge.addViewShape(scene.from_left, scene.left, 1.0f);
    const ViewShape right = ahoge.addViewShape(scene.from_right, scene.right, 1.0f);
    CHECK(left != right);

    std::vector<Transform> frames;
    std::vector<Transform> joints(harness::kJoints);
    const Transform* const storage = joints.data();
    for (int frame = 0; frame < harness::kFrames; ++frame) {
        engine.step(harness::kDt, harness::orbit_camera(frame), scene.head);
        engine.readWorld(joints);
        CHECK(joints.data() == storage);  // the vector already had the size: no reallocation
        frames.insert(frames.end(), joints.begin(), joints.end());
    }
    std::vector<kodawari::Quat> local;
    engine.readLocalRotations(local);
    std::vector<Transform> rest;
    ahoge.readRestShape(rest);

    CHECK(engine.stateHash() == reference.hash);
    CHECK(harness::same_bits(frames, reference.frames));
    CHECK(harness::same_bits(local, reference.local_rotations));
    CHECK(harness::same_bits(rest, reference.rest_shape));
    // The scene did something: seen from the side (frame 60) the tip leans away from the base shape.
    CHECK(std::fabs(frames[60 * harness::kJoints + harness::kJoints - 1].position.x) > 1e-3f);
    std::printf("     orbit: state hash %016llx, C++ == C bit for bit\n", static_cast<unsigned long long>(reference.hash));
}

void test_removed_and_destroyed_handles() {
    const harness::Scene scene = harness::ahoge_scene();
    Engine engine{EngineDef()};
    const ViewDependentPhysicalObject ahoge = engine.createChain(ahoge_def(scene), scene.base);
    const ViewDependentPhysicalObject other = engine.createChain(ChainDef(), scene.base);
    const ViewShape left = ahoge.addViewShape(scene.from_left, scene.left, 1.0f);
    const ViewShape right = ahoge.addViewShape(scene.from_right, scene.right, 1.0f);
    const ViewShape left_copy = left;
    CHECK(left_copy == left);
    CHECK(left.isValid() && right.isValid());

    left.remove();
    CHECK(!left.isValid() && !left_copy.isValid() && right.isValid());
    CHECK(ahoge.viewShapeCount() == 1);
    CHECK_THROWS(left.setInfluence(2.0f), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(left_copy.remove(), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(left.setJoints(scene.left), KDW_STATUS_INVALID_ID);
    right.setInfluence(2.0f);  // the other view shape is untouched

    const ViewDependentPhysicalObject ahoge_copy = ahoge;
    ahoge.destroy();
    CHECK(!ahoge.isValid() && !ahoge_copy.isValid() && other.isValid());
    CHECK(engine.chainCount() == 1 && engine.chain(other.id()) == other);
    CHECK_THROWS(ahoge_copy.jointCount(), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(ahoge.def(), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(ahoge.kineticEnergy(), KDW_STATUS_INVALID_ID);
    std::vector<Transform> world;
    CHECK_THROWS(ahoge.readWorld(world), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(ahoge.addViewShape(scene.from_left, scene.left, 1.0f), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(ahoge.destroy(), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(right.setInfluence(1.0f), KDW_STATUS_INVALID_ID);  // died with its chain

    // Null handles and ids of another engine are rejected the same way.
    CHECK(!ViewDependentPhysicalObject().isValid());
    CHECK_THROWS(engine.chain(0).jointCount(), KDW_STATUS_INVALID_ID);
    Engine stranger{EngineDef()};
    CHECK(!stranger.chain(other.id()).isValid());
    CHECK_THROWS(stranger.chain(other.id()).reset(), KDW_STATUS_INVALID_ID);
    other.reset();
}

// The sketch tool: a stroke drawn over a side view becomes a length-keeping shape on that stroke, which
// then serves as a view shape; a one-point stroke is an error.
void test_shape_from_stroke() {
    const kodawari::Vec3 head{0.0f, 1.6f, 0.0f};
    const Transform head_pose{head, {0.0f, 0.0f, 0.0f, 1.0f}};
    constexpr uint32_t kCount = 6;
    std::array<Transform, kCount> current{};  // straight up from the head, world space
    std::array<Transform, kCount> goal{};     // bending towards +x and the camera (+z)
    std::array<Transform, kCount> base{};     // `current` in the head's frame
    for (uint32_t j = 0; j < kCount; ++j) {
        const float t = static_cast<float>(j);
        current[j] = Transform{{0.0f, 1.72f + 0.04f * t, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}};
        const float angle = 0.25f * t;
        goal[j] = Transform{{0.04f * t * std::sin(angle), 1.72f + 0.04f * t * std::cos(angle), 0.01f * t},
                            {0.0f, 0.0f, 0.0f, 1.0f}};
        base[j] = current[j];
        base[j].position.y -= head.y;
    }

    kodawari::StrokeCamera camera;  // 3/4 view from the front right, looking along -z after a yaw
    const float yaw = 0.5f;
    camera.rotation = kodawari::Quat{0.0f, std::sin(0.5f * yaw), 0.0f, std::cos(0.5f * yaw)};
    camera.position = kodawari::Vec3{1.2f * std::sin(yaw), 1.8f, 1.2f * std::cos(yaw)};
    camera.viewport_width = 640.0f;
    camera.viewport_height = 480.0f;
    CHECK(camera.struct_size == sizeof(kdw_stroke_camera));

    std::vector<kodawari::Vec2> stroke;
    for (const Transform& joint : goal) stroke.push_back(camera.project(joint.position));
    const kodawari::StrokeShape shape = kodawari::shapeFromStroke(camera, current, head_pose, head_pose, stroke);
    CHECK(shape.joints.size() == kCount);
    const auto distance = [](const kodawari::Vec3& a, const kodawari::Vec3& b) {
        return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
    };
    CHECK(distance(shape.joints[0].position, base[0].position) < 1e-6f);  // the root stays
    for (uint32_t j = 0; j + 1 < kCount; ++j) {
        const float length = distance(shape.joints[j].position, shape.joints[j + 1].position);
        CHECK(std::fabs(length - 0.04f) < 0.04f * 1e-5f);
    }
    const auto off_stroke = [&stroke](const kodawari::Vec2& p) {
        float best = std::numeric_limits<float>::infinity();
        for (std::size_t i = 0; i + 1 < stroke.size(); ++i) {
            const float ax = stroke[i].x, ay = stroke[i].y;
            const float bx = stroke[i + 1].x - ax, by = stroke[i + 1].y - ay;
            const float t = std::fmin(1.0f, std::fmax(0.0f, ((p.x - ax) * bx + (p.y - ay) * by) / (bx * bx + by * by)));
            best = std::fmin(best, std::hypot(p.x - ax - bx * t, p.y - ay - by * t));
        }
        return best;
    };
    for (uint32_t j = 0; j < kCount; ++j) {  // every joint is seen on the stroke
        kodawari::Vec3 world = shape.joints[j].position;
        world.y += head.y;
        CHECK(off_stroke(camera.project(world)) < 0.5f);
    }

    // Seen from that camera, the sketched view shape is the rest shape.
    Engine engine{EngineDef()};
    const ViewDependentPhysicalObject chain = engine.createChain(ChainDef(), base);
    const ViewShape sketched = chain.addViewShape(shape, 1.0f);
    CHECK(sketched.isValid());
    engine.step(1.0f / 60.0f, camera.position, head_pose);
    std::vector<Transform> rest;
    chain.readRestShape(rest);
    for (uint32_t j = 0; j < kCount; ++j) CHECK(distance(rest[j].position, shape.joints[j].position) < 1e-5f);

    const std::vector<kodawari::Vec2> one_point(1, stroke[0]);
    CHECK_THROWS(kodawari::shapeFromStroke(camera, current, head_pose, head_pose, one_point),
                 KDW_STATUS_INVALID_ARGUMENT);
    kodawari::StrokeCamera behind = camera;
    behind.position = kodawari::Vec3{0.0f, 1.8f, -1.0f};  // looking away from the chain
    behind.rotation = kodawari::Quat{0.0f, 0.0f, 0.0f, 1.0f};
    CHECK_THROWS(behind.project(current[0].position), KDW_STATUS_INVALID_ARGUMENT);
}

float distance(const kodawari::Vec3& a, const kodawari::Vec3& b) {
    return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

const kodawari::Quat kIdentity{0.0f, 0.0f, 0.0f, 1.0f};

// Colliders through the RAII layer: a limp chain (joint radii 0) draped over a ball stays outside it every
// frame while the ball's pose is set in one batched call; rejected inputs throw and change nothing; a ball
// moved off the chain's layers lets it fall through; destroyed and wrong-kind ids throw INVALID_ID.
void test_colliders_and_joint_radii() {
    Engine engine{EngineDef()};
    std::vector<Transform> level;
    for (int j = 0; j < 8; ++j) level.push_back(Transform{{0.05f * static_cast<float>(j), 0.0f, 0.0f}, kIdentity});
    ChainDef def;
    def.stiffness = 0.02f;
    def.damping = 3.0f;
    def.collision_mask = 0x2u;
    def.friction = 0.5f;
    const ViewDependentPhysicalObject chain = engine.createChain(def, level);
    CHECK(chain.def().collision_mask == 0x2u && chain.def().friction == 0.5f);
    const std::vector<float> zero_radii(8, 0.0f);
    chain.setJointRadii(zero_radii);

    const kodawari::Vec3 centre{0.2f, 0.82f, 0.0f};
    ColliderDef ball_def = ColliderDef::sphere(0.1f, Transform{centre, kIdentity});
    ball_def.layers = 0x2u;
    const Collider ball = engine.createCollider(ball_def);
    const Collider far = engine.createCollider(ColliderDef::capsule(0.05f, 0.1f, Transform{{5.0f, 0.0f, 0.0f}, kIdentity}));
    CHECK(ball.isValid() && far.isValid() && ball != far && ball.engine() == engine.handle());
    CHECK(engine.colliderCount() == 2 && engine.collider(ball.id()) == ball);
    std::vector<kodawari::ColliderId> ids;
    engine.colliderIds(ids);
    CHECK(ids.size() == 2 && ids[0] == ball.id() && ids[1] == far.id());
    std::array<kodawari::ColliderId, 4> id_buffer{};
    CHECK(engine.colliderIds(id_buffer.data(), 4) == 2 && id_buffer[1] == far.id());

    const Transform anchor{{0.0f, 1.0f, 0.0f}, kIdentity};
    const kodawari::Vec3 camera{0.0f, 1.0f, 3.0f};
    const std::array<Transform, 2> poses{Transform{centre, kIdentity}, Transform{{5.0f, 0.0f, 0.0f}, kIdentity}};
    std::vector<Transform> world;
    float closest = 1e30f;
    for (int frame = 0; frame < 120; ++frame) {
        engine.setColliderTransforms(poses);
        engine.step(harness::kDt, camera, anchor);
        chain.readWorld(world);
        closest = 1e30f;
        for (const Transform& joint : world) closest = std::fmin(closest, distance(joint.position, centre));
        CHECK(closest >= 0.1f - 1e-4f);
    }
    CHECK(closest < 0.1f + 3.5e-3f);  // resting on the ball (segments collide too: joints up to 3.1 mm out)
    CHECK(engine.stats().collider_count == 2 && engine.stats().contact_pairs_tested > 0);

    const uint64_t before = engine.stateHash();
    CHECK_THROWS(engine.setColliderTransforms(poses.data(), 1), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(engine.setColliderTransforms(nullptr, 2), KDW_STATUS_NULL_POINTER);
    std::array<Transform, 2> broken = poses;
    broken[1].position.y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS(engine.setColliderTransforms(broken), KDW_STATUS_INVALID_ARGUMENT);
    broken[1] = Transform{{5.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 0.0f}};
    CHECK_THROWS(engine.setColliderTransforms(broken), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(engine.createCollider(ColliderDef::capsule(0.0f, 0.0f, anchor)), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(engine.createCollider(ColliderDef::sphere(-1.0f, anchor)), KDW_STATUS_INVALID_ARGUMENT);
    ColliderDef unknown_shape = ball_def;
    unknown_shape.shape = 99;
    CHECK_THROWS(engine.createCollider(unknown_shape), KDW_STATUS_INVALID_ARGUMENT);
    ColliderDef wrong_size;
    wrong_size.struct_size = 4;
    CHECK_THROWS(engine.createCollider(wrong_size), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    CHECK_THROWS(chain.setJointRadii(zero_radii.data(), 7), KDW_STATUS_INVALID_ARGUMENT);
    const std::vector<float> nan_radii(8, std::numeric_limits<float>::quiet_NaN());
    CHECK_THROWS(chain.setJointRadii(nan_radii), KDW_STATUS_INVALID_ARGUMENT);
    ChainDef bad_friction = chain.def();
    bad_friction.friction = 11.0f;
    CHECK_THROWS(chain.setDef(bad_friction), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.stateHash() == before && engine.colliderCount() == 2);

    // Off the chain's layers, the ball no longer holds it.
    ball.setLayers(0x4u);
    float lowest = 1e30f;
    for (int frame = 0; frame < 60; ++frame) {
        engine.step(harness::kDt, camera, anchor);
        chain.readWorld(world);
        for (const Transform& joint : world) lowest = std::fmin(lowest, distance(joint.position, centre));
    }
    CHECK(lowest < 0.1f - 0.02f);

    far.destroy();
    CHECK(!far.isValid() && engine.colliderCount() == 1);
    CHECK_THROWS(far.setLayers(1u), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(engine.destroyCollider(far), KDW_STATUS_INVALID_ID);
    CHECK_THROWS(engine.collider(chain.id()).destroy(), KDW_STATUS_INVALID_ID);  // a chain id is no collider id
    CHECK_THROWS(engine.chain(ball.id()).teleport(), KDW_STATUS_INVALID_ID);     // and vice versa
    CHECK(!Collider().isValid());
    Engine stranger{EngineDef()};
    CHECK(!stranger.collider(ball.id()).isValid());
    CHECK_THROWS(stranger.destroyCollider(ball), KDW_STATUS_INVALID_ID);
    engine.destroyCollider(ball);
    CHECK(engine.colliderCount() == 0 && !ball.isValid());
    engine.setColliderTransforms(nullptr, 0);  // zero colliders, zero poses
    chain.setJointRadii({});                   // back to the def's radius
}

// Teleports and scale through the RAII layer: in KDW_TELEPORT_RESET mode Engine::teleport and
// ViewDependentPhysicalObject::teleport do exactly what reset does at the same step (equal state hashes); in
// carry mode a 100 m jump with Engine::teleport keeps every chain's energy; scale is validated.
void test_teleports_and_scale() {
    const harness::Scene scene = harness::ahoge_scene();
    EngineDef reset_mode;
    reset_mode.teleport_mode = KDW_TELEPORT_RESET;
    reset_mode.teleport_distance = std::numeric_limits<float>::max();  // only explicit teleports
    Engine teleported{reset_mode}, reset{reset_mode};
    const ViewDependentPhysicalObject a = teleported.createChain(ChainDef(), scene.base);
    const ViewDependentPhysicalObject b = reset.createChain(ChainDef(), scene.base);
    EngineDef carry_mode;
    carry_mode.teleport_distance = std::numeric_limits<float>::max();
    Engine jumper{carry_mode}, still{carry_mode};
    const ViewDependentPhysicalObject carried = jumper.createChain(ChainDef(), scene.base);
    const ViewDependentPhysicalObject reference = still.createChain(ChainDef(), scene.base);
    CHECK(teleported.def().teleport_mode == KDW_TELEPORT_RESET);

    for (int frame = 0; frame < 40; ++frame) {
        const int swing = frame < 15 ? frame : 14;
        Transform head{{0.1f * std::sin(0.4f * static_cast<float>(swing)), 1.6f, 0.0f}, kIdentity};
        kodawari::Vec3 camera = harness::orbit_camera(0);
        if (frame == 20) {
            teleported.teleport();
            reset.reset();
            jumper.teleport();
        }
        if (frame == 30) {
            a.teleport();
            b.reset();
        }
        teleported.step(harness::kDt, camera, head);
        reset.step(harness::kDt, camera, head);
        still.step(harness::kDt, camera, head);
        if (frame >= 20) {
            head.position.x += 100.0f;
            camera.x += 100.0f;
        }
        jumper.step(harness::kDt, camera, head);
        CHECK(teleported.stateHash() == reset.stateHash());
        if (frame >= 20) {
            const float expected = reference.kineticEnergy();
            CHECK(std::fabs(carried.kineticEnergy() - expected) <= 1e-3f * expected + 1e-7f);
        }
        if (frame == 20) CHECK(reference.kineticEnergy() > 1e-6f);  // still swinging: the comparison means something
    }

    EngineDef bad = carry_mode;
    bad.scale = 0.0f;
    CHECK_THROWS(jumper.setDef(bad), KDW_STATUS_INVALID_ARGUMENT);
    bad.scale = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS(Engine{bad}, KDW_STATUS_INVALID_ARGUMENT);
    bad.scale = 1e7f;
    CHECK_THROWS(jumper.setDef(bad), KDW_STATUS_INVALID_ARGUMENT);
    bad = carry_mode;
    bad.teleport_mode = 2;
    CHECK_THROWS(jumper.setDef(bad), KDW_STATUS_INVALID_ARGUMENT);
    EngineDef large = carry_mode;
    large.scale = 100.0f;
    jumper.setDef(large);
    CHECK(jumper.def().scale == 100.0f);
}

// ---- culling, sleeping, batch stepping, collider resizing ----

kodawari::Quat conjugate(const kodawari::Quat& q) { return {-q.x, -q.y, -q.z, q.w}; }

kodawari::Quat multiply(const kodawari::Quat& a, const kodawari::Quat& b) {
    return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

kodawari::Vec3 rotate(const kodawari::Quat& q, const kodawari::Vec3& v) {
    const kodawari::Quat p = multiply(multiply(q, kodawari::Quat{v.x, v.y, v.z, 0.0f}), conjugate(q));
    return {p.x, p.y, p.z};
}

// `world` expressed in the rigid frame `frame`.
Transform relative_to(const Transform& frame, const Transform& world) {
    const kodawari::Quat inverse = conjugate(frame.rotation);
    const kodawari::Vec3 offset{world.position.x - frame.position.x, world.position.y - frame.position.y,
                                world.position.z - frame.position.z};
    return Transform{rotate(inverse, offset), multiply(inverse, world.rotation)};
}

// Same rotation up to sign, within `tolerance` per component.
bool same_rotation(const kodawari::Quat& a, const kodawari::Quat& b, float tolerance) {
    const float sign = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w < 0.0f ? -1.0f : 1.0f;
    return std::fabs(a.x - sign * b.x) <= tolerance && std::fabs(a.y - sign * b.y) <= tolerance &&
           std::fabs(a.z - sign * b.z) <= tolerance && std::fabs(a.w - sign * b.w) <= tolerance;
}

// The head swinging sideways and turning: frame `frame` of 1/60 s.
Transform moving_head(int frame) {
    const float t = static_cast<float>(frame) * harness::kDt;
    const float angle = 0.6f * std::sin(2.0f * t);
    return Transform{{0.4f * std::sin(3.0f * t), 1.6f + 0.1f * t, 0.2f * t}, {0.0f, std::sin(0.5f * angle), 0.0f, std::cos(0.5f * angle)}};
}

// A disabled chain is not simulated: while the head (its anchor) moves and turns, its pose relative to the
// head stays exactly what it was, and the stats count it as costing nothing; the enabled chain next to it
// keeps swinging. Enabled again (after a cull under a still head) it carries on swinging without a whip.
void test_disabled_chain_rides_with_its_anchor() {
    const harness::Scene scene = harness::ahoge_scene();
    Engine engine{EngineDef()};
    ChainDef limp;
    limp.stiffness = 0.3f;
    const ViewDependentPhysicalObject culled = engine.createChain(limp, scene.left);
    const ViewDependentPhysicalObject active = engine.createChain(limp, scene.right);
    CHECK(culled.isEnabled() && active.isEnabled() && !culled.isAsleep());
    const kodawari::Vec3 camera{0.0f, 1.7f, 2.5f};
    int frame = 0;
    for (; frame < 30; ++frame) engine.step(harness::kDt, camera, moving_head(frame));
    const float energy_before = culled.kineticEnergy();
    CHECK(energy_before > 1e-3f);  // swinging when culled: the frozen pose is not the rest pose

    // Culled for half a second under a still head, then enabled: it goes on from its pose, no whip.
    culled.setEnabled(false);
    CHECK(!culled.isEnabled() && active.isEnabled());
    for (int end = frame + 30; frame < end; ++frame) engine.step(harness::kDt, camera, moving_head(29));
    CHECK(engine.stats().chains_asleep == 1);
    culled.setEnabled(true);
    float energy_after = 0.0f;
    for (int end = frame + 10; frame < end; ++frame) {
        engine.step(harness::kDt, camera, moving_head(29));
        energy_after = std::fmax(energy_after, culled.kineticEnergy());
    }
    CHECK(engine.stats().chains_asleep == 0);
    CHECK(energy_after < 2.0f * energy_before + 0.05f);

    // Culled while the head swings, turns and travels: the pose relative to the head does not change.
    const float energy_at_cull = culled.kineticEnergy();
    culled.setEnabled(false);
    std::vector<Transform> frozen, world;
    culled.readWorld(frozen);
    const Transform head_at_cull = moving_head(29);
    for (Transform& joint : frozen) joint = relative_to(head_at_cull, joint);
    float worst = 0.0f;
    int head_frame = 30;
    for (int end = frame + 60; frame < end; ++frame, ++head_frame) {
        const Transform head = moving_head(head_frame);
        engine.step(harness::kDt, camera, head);
        culled.readWorld(world);
        CHECK(world.size() == frozen.size());
        for (std::size_t j = 0; j < world.size(); ++j) {
            const Transform now = relative_to(head, world[j]);
            worst = std::fmax(worst, distance(now.position, frozen[j].position));
            CHECK(same_rotation(now.rotation, frozen[j].rotation, 1e-5f));
        }
        const kodawari::EngineStats stats = engine.stats();
        CHECK(stats.chains_asleep == 1 && stats.chain_count == 2);  // the culled chain; the other swings
        CHECK(!active.isAsleep() && !culled.isEnabled());
    }
    CHECK(worst < 2e-6f);
    const Transform travelled = relative_to(head_at_cull, moving_head(head_frame - 1));
    CHECK(distance(travelled.position, {0.0f, 0.0f, 0.0f}) > 0.2f);  // the anchor really moved
    std::printf("     culled while the head travelled %.2f m: pose relative to the head kept within %.1e m\n",
                double(distance(travelled.position, {0.0f, 0.0f, 0.0f})), double(worst));

    // Enabled again after that: it carries on from its frozen state, carried to where the head is now, without
    // a whip (before the fix the first step pulled it back across the distance travelled: 38-58 J from 1.6 J).
    culled.setEnabled(true);
    engine.step(harness::kDt, camera, moving_head(head_frame));
    culled.readWorld(world);
    float jump = 0.0f;
    for (std::size_t j = 0; j < world.size(); ++j)
        jump = std::fmax(jump, distance(relative_to(moving_head(head_frame), world[j]).position, frozen[j].position));
    std::printf("     re-enabled after that: first step moves a joint %.3f m relative to the head, energy %.2f J "
                "(%.2f J when culled)\n",
                double(jump), double(culled.kineticEnergy()), double(energy_at_cull));
    CHECK(culled.kineticEnergy() < 1.5f * energy_at_cull + 0.05f);
}

// A damped chain under a still head settles and falls asleep (stats count it); moving the head wakes it;
// with sleep_speed 0 the same chain never sleeps. lod round-trips through the def.
void test_settled_chain_sleeps() {
    const harness::Scene scene = harness::ahoge_scene();
    EngineDef def;
    CHECK(def.sleep_speed == 5e-6f && def.lod == 0u);
    EngineDef never = def;
    never.sleep_speed = 0.0f;
    Engine sleeper{def}, awake{never};
    ChainDef damped = ahoge_def(scene);
    damped.damping = 5.0f;
    const ViewDependentPhysicalObject a = sleeper.createChain(damped, scene.left);
    const ViewDependentPhysicalObject b = awake.createChain(damped, scene.left);
    const kodawari::Vec3 camera{0.0f, 1.7f, 2.5f};
    int fell_asleep = -1;
    for (int frame = 0; frame < 300; ++frame) {  // 5 s
        sleeper.step(harness::kDt, camera, scene.head);
        awake.step(harness::kDt, camera, scene.head);
        if (fell_asleep < 0 && a.isAsleep()) fell_asleep = frame;
        CHECK(!b.isAsleep());
    }
    CHECK(fell_asleep > 0 && a.isAsleep());
    CHECK(sleeper.stats().chains_asleep == 1 && awake.stats().chains_asleep == 0);
    const uint64_t hash = sleeper.stateHash();
    Transform moved = scene.head;
    moved.position.x += 0.05f;
    sleeper.step(harness::kDt, camera, moved);
    CHECK(!a.isAsleep() && sleeper.stats().chains_asleep == 0 && sleeper.stateHash() != hash);
    std::printf("     damping 5: asleep after %.2f s; sleep_speed 0: awake after 5 s\n",
                double(static_cast<float>(fell_asleep + 1) * harness::kDt));

    EngineDef far = sleeper.def();
    far.lod = 3;
    sleeper.setDef(far);
    CHECK(sleeper.def().lod == 3u);
    sleeper.step(harness::kDt, camera, moved);  // 240 Hz / 8 = 30 Hz: at most one substep per 1/60 s
    CHECK(sleeper.stats().substeps_last_step <= 1u);
    far.lod = 4;
    CHECK_THROWS(sleeper.setDef(far), KDW_STATUS_INVALID_ARGUMENT);
    far.lod = 0;
    far.sleep_speed = -1.0f;
    CHECK_THROWS(sleeper.setDef(far), KDW_STATUS_INVALID_ARGUMENT);
}

// kodawari::stepEngines: four engines stepped in one call end in exactly the state four single steps give;
// a repeated, null or empty engine, or a missing view reference, fails the whole call and moves nothing.
void test_step_engines_equals_single_steps() {
    const harness::Scene scene = harness::ahoge_scene();
    constexpr std::size_t kCount = 4;
    std::vector<Engine> batched, single;
    for (std::size_t i = 0; i < kCount; ++i) {
        for (std::vector<Engine>* group : {&batched, &single}) {
            group->emplace_back(EngineDef());
            ChainDef def = ahoge_def(scene);
            def.stiffness = 0.3f + 0.15f * static_cast<float>(i);
            const ViewDependentPhysicalObject chain = group->back().createChain(def, scene.base);
            chain.addViewShape(scene.from_left, scene.left, 1.0f);
        }
    }
    std::vector<Engine*> handles;
    for (Engine& engine : batched) handles.push_back(&engine);
    std::array<Transform, kCount> heads{};
    for (int frame = 0; frame < 90; ++frame) {
        for (std::size_t i = 0; i < kCount; ++i) {
            heads[i] = scene.head;
            heads[i].position.x = static_cast<float>(i) + 0.1f * std::sin(0.2f * static_cast<float>(frame));
        }
        const kodawari::Vec3 camera = harness::orbit_camera(frame);
        kodawari::stepEngines(handles, harness::kDt, camera, heads);
        for (std::size_t i = 0; i < kCount; ++i) single[i].step(harness::kDt, camera, heads[i]);
    }
    std::array<uint64_t, kCount> hashes{};
    for (std::size_t i = 0; i < kCount; ++i) {
        hashes[i] = batched[i].stateHash();
        CHECK(hashes[i] == single[i].stateHash());
        CHECK(batched[i].stats().substeps_total == single[i].stats().substeps_total);
        if (i > 0) CHECK(hashes[i] != hashes[i - 1]);  // four different scenes
    }

    const kodawari::Vec3 camera = harness::orbit_camera(90);
    std::array<Engine*, kCount> repeated{handles[0], handles[1], handles[2], handles[0]};
    CHECK_THROWS(kodawari::stepEngines(repeated, harness::kDt, camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    std::array<Engine*, kCount> with_null{handles[0], nullptr, handles[2], handles[3]};
    CHECK_THROWS(kodawari::stepEngines(with_null, harness::kDt, camera, heads), KDW_STATUS_NULL_POINTER);
    Engine empty;
    std::array<Engine*, kCount> with_empty{handles[0], handles[1], &empty, handles[3]};
    CHECK_THROWS(kodawari::stepEngines(with_empty, harness::kDt, camera, heads), KDW_STATUS_NULL_POINTER);
    CHECK_THROWS(kodawari::stepEngines(handles, harness::kDt, camera, kodawari::Span<const Transform>(heads.data(), 3)),
                 KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(kodawari::stepEngines(handles, -1.0f, camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    std::array<Transform, kCount> bad_heads = heads;
    bad_heads[3].rotation = kodawari::Quat{0.0f, 0.0f, 0.0f, 0.0f};
    CHECK_THROWS(kodawari::stepEngines(handles, harness::kDt, camera, bad_heads), KDW_STATUS_INVALID_ARGUMENT);
    for (std::size_t i = 0; i < kCount; ++i) CHECK(batched[i].stateHash() == hashes[i]);
    kodawari::stepEngines(nullptr, 0, harness::kDt, camera, nullptr);  // nothing to step
    kodawari::stepEngines(handles.data(), 2, harness::kDt, camera, heads.data());  // a prefix
    CHECK(batched[0].stateHash() != hashes[0] && batched[2].stateHash() == hashes[2]);
}

// Collider::setSize: a limp chain draped over a ball rests on its surface; grown to 1.5 times the radius,
// the ball pushes the chain out to the new surface; invalid sizes throw and change nothing.
void test_collider_set_size() {
    Engine engine{EngineDef()};
    std::vector<Transform> level;
    for (int j = 0; j < 8; ++j) level.push_back(Transform{{0.05f * static_cast<float>(j), 0.0f, 0.0f}, kIdentity});
    ChainDef def;
    def.stiffness = 0.02f;
    def.damping = 3.0f;
    const ViewDependentPhysicalObject chain = engine.createChain(def, level);
    chain.setJointRadii(std::vector<float>(8, 0.0f));
    const kodawari::Vec3 centre{0.2f, 0.82f, 0.0f};
    const Collider ball = engine.createCollider(ColliderDef::sphere(0.1f, Transform{centre, kIdentity}));
    const Transform anchor{{0.0f, 1.0f, 0.0f}, kIdentity};
    const kodawari::Vec3 camera{0.0f, 1.0f, 3.0f};
    std::vector<Transform> world;
    const auto settle = [&](float radius) {
        float closest = 0.0f;
        for (int frame = 0; frame < 120; ++frame) {
            engine.step(harness::kDt, camera, anchor);
            chain.readWorld(world);
            closest = 1e30f;
            for (const Transform& joint : world) closest = std::fmin(closest, distance(joint.position, centre));
            if (frame >= 10 && closest < radius - 1e-4f) return -closest;  // inside after the push-out
        }
        return closest;
    };
    const float small = settle(0.1f);
    CHECK(small >= 0.1f - 1e-4f && small < 0.1f + 3.5e-3f);

    const uint64_t before = engine.stateHash();
    CHECK_THROWS(ball.setSize(-0.1f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(ball.setSize(std::numeric_limits<float>::quiet_NaN(), 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_THROWS(ball.setSize(0.1f, 2e6f), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.stateHash() == before);

    ball.setSize(0.15f, 0.0f);
    CHECK(engine.stateHash() != before);
    const float large = settle(0.15f);
    CHECK(large >= 0.15f - 1e-4f && large < 0.15f + 5e-3f);
    std::printf("     ball radius 0.10 -> 0.15: closest joint %.4f -> %.4f m from its centre\n", double(small),
                double(large));

    ball.destroy();
    CHECK_THROWS(ball.setSize(0.1f, 0.0f), KDW_STATUS_INVALID_ID);
    const Collider hood = engine.createCollider([&] {
        ColliderDef inside = ColliderDef::sphere(0.5f, anchor);
        inside.shape = KDW_COLLIDER_INSIDE_SPHERE;
        return inside;
    }());
    CHECK_THROWS(hood.setSize(0.0f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);  // inside shapes need a radius
    hood.setSize(0.6f, 0.0f);
}

// Engine::setSolver / solver() round trip; four equal chains without colliders make one lane group (stats
// lane_chains 4) on the lane solvers and none on the scalar one; both lane solvers give the same bits; an
// unknown value throws and changes nothing.
void test_solver_selection() {
    const harness::Scene scene = harness::ahoge_scene();
    const kodawari::Solver solvers[3] = {kodawari::Solver::Lanes, kodawari::Solver::LanesPortable,
                                         kodawari::Solver::Scalar};
    std::vector<Engine> engines;
    for (const kodawari::Solver solver : solvers) {
        engines.emplace_back(EngineDef());
        Engine& engine = engines.back();
        CHECK(engine.solver() == kodawari::Solver::Lanes);  // the default
        engine.setSolver(solver);
        CHECK(engine.solver() == solver);
        for (int c = 0; c < 4; ++c) {
            ChainDef def = ahoge_def(scene);
            def.stiffness = 0.3f + 0.2f * static_cast<float>(c);
            engine.createChain(def, scene.base);
        }
    }
    CHECK(engines[0].stateHash() != engines[1].stateHash() && engines[0].stateHash() != engines[2].stateHash());

    const uint64_t before = engines[0].stateHash();
    CHECK_THROWS(engines[0].setSolver(static_cast<kodawari::Solver>(3)), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engines[0].stateHash() == before && engines[0].solver() == kodawari::Solver::Lanes);

    Transform head = scene.head;  // sways gently, so the chains keep moving (a still chain would fall asleep)
    for (int frame = 0; frame < 60; ++frame) {
        head.position.x = 0.02f * std::sin(0.05f * static_cast<float>(frame));
        for (Engine& engine : engines) engine.step(harness::kDt, harness::orbit_camera(frame), head);
    }
    CHECK(engines[0].stats().lane_chains == 4 && engines[1].stats().lane_chains == 4);
    CHECK(engines[2].stats().lane_chains == 0 && engines[2].stats().chain_count == 4);
    std::vector<Transform> lanes, portable, scalar;
    engines[0].readWorld(lanes);
    engines[1].readWorld(portable);
    engines[2].readWorld(scalar);
    CHECK(harness::same_bits(lanes, portable));
    CHECK(scalar.size() == lanes.size());
}

// Runs a test; an unexpected exception fails it.
#define RUN(test)                                                                          \
    harness::run(#test, [] {                                                               \
        try {                                                                              \
            test();                                                                        \
        } catch (const std::exception& error) {                                            \
            harness::fail(__FILE__, __LINE__, (std::string("unexpected exception: ") + error.what()).c_str()); \
        }                                                                                  \
    })

}  // namespace

int main() {
    RUN(test_defaults_and_versions);
    RUN(test_abi_mismatch_refuses_to_create);
    RUN(test_life_cycle);
    RUN(test_moves_destroy_exactly_once);
    RUN(test_invalid_calls_throw_and_leave_state_unchanged);
    RUN(test_orbit_scene_matches_plain_c);
    RUN(test_removed_and_destroyed_handles);
    RUN(test_shape_from_stroke);
    RUN(test_colliders_and_joint_radii);
    RUN(test_teleports_and_scale);
    RUN(test_disabled_chain_rides_with_its_anchor);
    RUN(test_settled_chain_sleeps);
    RUN(test_step_engines_equals_single_steps);
    RUN(test_collider_set_size);
    RUN(test_solver_selection);
    run_no_exception_tests();
    std::printf("%d passed, %d failed\n", harness::counters().passed, harness::counters().failed);
    return harness::counters().failed == 0 ? 0 : 1;
}
