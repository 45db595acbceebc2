// The KODAWARI_NO_EXCEPTIONS mode of bindings/cpp/kodawari.hpp, built with -fno-exceptions and linked into
// the same program as test_kodawari.cpp (the two modes live in different inline namespaces, so mixing
// them is safe). Every fallible method returns kodawari::Result<T> / kodawari::Status instead of throwing.

#ifndef KODAWARI_NO_EXCEPTIONS
#error "build this file with -DKODAWARI_NO_EXCEPTIONS -fno-exceptions"
#endif

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "kodawari.hpp"

void run_no_exception_tests();

namespace {

using kodawari::ChainDef;
using kodawari::Engine;
using kodawari::EngineDef;
using kodawari::Result;
using kodawari::Status;
using kodawari::ViewDependentPhysicalObject;
using kodawari::ViewShape;

// The same method names as with exceptions, returning results.
static_assert(std::is_same_v<decltype(Engine::create()), Result<Engine>>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().chainCount()), Result<uint32_t>>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().step(0.0f, {}, {})), Status>);
static_assert(std::is_same_v<decltype(std::declval<ViewShape&>().remove()), Status>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().createCollider(kodawari::ColliderDef())),
                             Result<kodawari::Collider>>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().setColliderTransforms(nullptr, 0)), Status>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().teleport()), Status>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().setSolver(kodawari::Solver::Scalar)), Status>);
static_assert(std::is_same_v<decltype(std::declval<Engine&>().solver()), Result<kodawari::Solver>>);
static_assert(std::is_same_v<kodawari::Ret<void>, Status>);
static_assert(!std::is_constructible_v<Engine, const EngineDef&>, "no throwing constructor without exceptions");

// `expression` must fail with `expected` status and a non-empty message.
#define CHECK_FAILS(expression, expected)                 \
    do {                                                  \
        const auto outcome = (expression);                \
        CHECK(!outcome.ok() && !outcome);                 \
        CHECK(outcome.status() == (expected));            \
        CHECK(!outcome.message().empty());                \
    } while (0)

void test_no_exceptions_scene() {
    const harness::Scene scene = harness::ahoge_scene();
    Result<Engine> created = Engine::create(EngineDef());
    CHECK(created.ok() && created.status() == KDW_STATUS_OK && created.message().empty());
    Engine engine = std::move(created).value();
    CHECK(engine);

    ChainDef def;
    def.stiffness = scene.stiffness;
    const Result<ViewDependentPhysicalObject> ahoge = engine.createChain(def, scene.base);
    CHECK(ahoge.ok() && ahoge.value().isValid());
    CHECK(ahoge.value().addViewShape(scene.from_left, scene.left, 1.0f).ok());
    const Result<ViewShape> right = ahoge.value().addViewShape(scene.from_right, scene.right, 1.0f);
    CHECK(right.ok());

    std::vector<kodawari::Transform> joints;
    for (int frame = 0; frame < harness::kFrames; ++frame) {
        CHECK(engine.step(harness::kDt, harness::orbit_camera(frame), scene.head).ok());
        CHECK(engine.readWorld(joints).ok());
    }
    const harness::OrbitRun reference = harness::c_reference_orbit();
    CHECK(reference.ok && engine.stateHash().value() == reference.hash);
    CHECK(harness::same_bits(joints, std::vector<kodawari::Transform>(reference.frames.end() - harness::kJoints,
                                                                      reference.frames.end())));

    // Failures come back as results, and leave the engine as it was.
    const uint64_t before = engine.stateHash().value();
    ChainDef too_stiff = ahoge.value().def().value();
    too_stiff.stiffness = 2.0f;
    CHECK_FAILS(ahoge.value().setDef(too_stiff), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_FAILS(engine.step(std::numeric_limits<float>::quiet_NaN(), harness::orbit_camera(0), scene.head),
                KDW_STATUS_INVALID_ARGUMENT);
    CHECK_FAILS(engine.createChain(def, scene.base, 1), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.stateHash().value() == before);

    harness::counters().fake_abi_version = KDW_ABI_VERSION + 1;  // see kdw_abi_version in test_kodawari.cpp
    const Result<Engine> mismatched = Engine::create();
    harness::counters().fake_abi_version = 0;
    CHECK(!mismatched.ok() && mismatched.status() == kodawari::kStatusAbiMismatch && !mismatched.message().empty());

    EngineDef no_iterations;
    no_iterations.iterations = 0;
    CHECK_FAILS(Engine::create(no_iterations), KDW_STATUS_INVALID_ARGUMENT);

    // Stale handles.
    CHECK(right.value().remove().ok());
    CHECK_FAILS(right.value().setInfluence(2.0f), KDW_STATUS_INVALID_ID);
    CHECK(ahoge.value().destroy().ok());
    CHECK(!ahoge.value().isValid());
    CHECK_FAILS(ahoge.value().jointCount(), KDW_STATUS_INVALID_ID);
    CHECK_FAILS(ahoge.value().readWorld(joints), KDW_STATUS_INVALID_ID);
    CHECK(engine.chainCount().value() == 0 && engine.chainCount().valueOr(9) == 0);
    CHECK(Engine().jointCount().valueOr(9) == 9);

    // Colliders, joint radii and teleports report failures the same way.
    const Result<kodawari::Collider> ball = engine.createCollider(kodawari::ColliderDef());
    CHECK(ball.ok() && ball.value().isValid() && engine.colliderCount().value() == 1);
    const uint64_t with_ball = engine.stateHash().value();
    CHECK_FAILS(engine.createCollider(kodawari::ColliderDef::sphere(-1.0f, scene.head)), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_FAILS(engine.setColliderTransforms(nullptr, 0), KDW_STATUS_INVALID_ARGUMENT);  // one pose per collider
    CHECK_FAILS(engine.chain(ball.value().id()).teleport(), KDW_STATUS_INVALID_ID);
    CHECK(engine.stateHash().value() == with_ball);
    CHECK(engine.setColliderTransforms(&scene.head, 1).ok());
    CHECK(engine.teleport().ok());
    CHECK(ball.value().destroy().ok());
    CHECK_FAILS(ball.value().setLayers(2u), KDW_STATUS_INVALID_ID);
    CHECK(engine.colliderCount().valueOr(9) == 0);

    // Solver selection.
    CHECK(engine.solver().value() == kodawari::Solver::Lanes);
    CHECK(engine.setSolver(kodawari::Solver::Scalar).ok() && engine.solver().value() == kodawari::Solver::Scalar);
    CHECK_FAILS(engine.setSolver(static_cast<kodawari::Solver>(7)), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(engine.solver().value() == kodawari::Solver::Scalar);
    CHECK_FAILS(Engine().solver(), KDW_STATUS_NULL_POINTER);
}

// Culling, sleeping state, collider resizing and batch stepping return results too.
void test_no_exceptions_culling_and_batches() {
    const harness::Scene scene = harness::ahoge_scene();
    Engine first = Engine::create().value();
    Engine second = Engine::create().value();
    const Result<ViewDependentPhysicalObject> chain = first.createChain(ChainDef(), scene.base);
    CHECK(chain.ok() && second.createChain(ChainDef(), scene.base).ok());
    static_assert(std::is_same_v<decltype(chain.value().isEnabled()), Result<bool>>);
    static_assert(std::is_same_v<decltype(kodawari::stepEngines(nullptr, 0, 0.0f, {}, nullptr)), Status>);
    CHECK(chain.value().isEnabled().value() && !chain.value().isAsleep().value());
    CHECK(chain.value().setEnabled(false).ok() && !chain.value().isEnabled().value());

    std::vector<Engine*> both{&first, &second};
    const std::vector<kodawari::Transform> heads(2, scene.head);
    CHECK(kodawari::stepEngines(both, harness::kDt, harness::orbit_camera(0), heads).ok());
    CHECK(first.stats().value().chains_asleep == 1 && second.stats().value().chains_asleep == 0);
    const uint64_t before = first.stateHash().value();
    both[1] = &first;
    CHECK_FAILS(kodawari::stepEngines(both, harness::kDt, harness::orbit_camera(1), heads), KDW_STATUS_INVALID_ARGUMENT);
    CHECK_FAILS(kodawari::stepEngines(both, harness::kDt, harness::orbit_camera(1), kodawari::Span<const kodawari::Transform>()),
                KDW_STATUS_INVALID_ARGUMENT);
    CHECK(first.stateHash().value() == before);

    const Result<kodawari::Collider> ball = first.createCollider(kodawari::ColliderDef());
    CHECK(ball.ok() && ball.value().setSize(0.2f, 0.0f).ok());
    CHECK_FAILS(ball.value().setSize(-1.0f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    CHECK(chain.value().destroy().ok());
    CHECK_FAILS(chain.value().setEnabled(true), KDW_STATUS_INVALID_ID);
    CHECK_FAILS(chain.value().isAsleep(), KDW_STATUS_INVALID_ID);
}

}  // namespace

void run_no_exception_tests() {
    harness::run("test_no_exceptions_scene (-fno-exceptions)", test_no_exceptions_scene);
    harness::run("test_no_exceptions_culling_and_batches (-fno-exceptions)", test_no_exceptions_culling_and_batches);
}
