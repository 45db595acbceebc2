// Must NOT compile (with -Werror): every fallible call of bindings/cpp/kodawari.hpp is [[nodiscard]].
// tests/cpp_bindings.rs compiles it in both modes and expects one "nodiscard" diagnostic per marked line.
#include "kodawari.hpp"

void discard_everything(kodawari::Engine& engine, kodawari::ViewDependentPhysicalObject chain,
                        kodawari::ViewShape shape, kodawari::Collider collider) {
    engine.chainCount();                     // DISCARD
    engine.colliderCount();                  // DISCARD
    collider.isValid();                      // DISCARD
    engine.stateHash();                      // DISCARD
    engine.solver();                         // DISCARD
    chain.jointCount();                      // DISCARD
    chain.isValid();                         // DISCARD
    chain.isEnabled();                       // DISCARD
    chain.isAsleep();                        // DISCARD
    kodawari::Engine::create();              // DISCARD
#ifdef KODAWARI_NO_EXCEPTIONS
    engine.step(0.0f, {}, {});               // DISCARD
    engine.reset();                          // DISCARD
    chain.destroy();                         // DISCARD
    shape.remove();                          // DISCARD
    engine.teleport();                       // DISCARD
    engine.setSolver(kodawari::Solver::Scalar);  // DISCARD
    engine.setColliderTransforms(nullptr, 0);  // DISCARD
    chain.teleport();                        // DISCARD
    collider.destroy();                      // DISCARD
    collider.setSize(0.1f, 0.0f);            // DISCARD
    chain.setEnabled(false);                 // DISCARD
    kodawari::stepEngines(nullptr, 0, 0.0f, {}, nullptr);  // DISCARD
#else
    (void)shape;
#endif
}
