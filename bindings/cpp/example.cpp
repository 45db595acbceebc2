// kodawari C++ quick start: an ahoge that curls toward the side the camera sees it from.
#include <cmath>
#include <cstdio>
#include <vector>
#include "kodawari.hpp"

int main() try {
    kodawari::Engine engine{kodawari::EngineDef()};  // checks the ABI; destroyed at scope exit
    std::vector<kodawari::Transform> base, left, right;  // head frame, root first
    for (float t = 0; t < 6; ++t) {
        base.push_back({{0, 0.12f + 0.03f * t, 0}, {0, 0, 0, 1}});
        left.push_back({{-0.01f * t * t, 0.12f + 0.025f * t, 0}, {0, 0, 0, 1}});
        right.push_back({{0.01f * t * t, 0.12f + 0.025f * t, 0}, {0, 0, 0, 1}});
    }
    kodawari::ChainDef def;  // starts from the library defaults
    def.stiffness = 0.9f;
    kodawari::ViewDependentPhysicalObject ahoge = engine.createChain(def, base);
    ahoge.addViewShape({-1, 0, 0}, left, 1.0f);  // seen from the left, it curls left
    ahoge.addViewShape({1, 0, 0}, right, 1.0f);  // seen from the right, it curls right

    const kodawari::Transform head{{0, 1.6f, 0}, {0, 0, 0, 1}};
    std::vector<kodawari::Transform> joints;  // reused every frame: no allocation
    for (int frame = 0; frame <= 240; ++frame) {
        const float angle = 6.2831853f * static_cast<float>(frame) / 240;
        engine.step(1.0f / 60, {2.5f * std::sin(angle), 1.7f, 2.5f * std::cos(angle)}, head);
        engine.readWorld(joints);
        if (frame % 60 == 0) std::printf("frame %3d: tip x %+.3f\n", frame, double(joints.back().position.x));
    }
    return 0;
} catch (const kodawari::Error& error) {  // a KDW_STATUS_* and the library's message
    std::fprintf(stderr, "kodawari: %s\n", error.what());
    return 1;
}
