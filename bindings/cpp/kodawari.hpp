// kodawari C++ binding: header-only C++17 RAII over the C API in kodawari.h.
//
//   kodawari::Engine                      owns a kdw_engine* (move-only, destroyed by its destructor)
//   kodawari::ViewDependentPhysicalObject a chain: non-owning handle (engine pointer + kdw_chain_id)
//   kodawari::ViewShape                   a view shape of a chain: non-owning handle
//   kodawari::Collider                    a collision shape of the engine: non-owning handle
//   kodawari::EngineDef / ChainDef / ColliderDef  the C def structs, initialised to the library defaults
//   kodawari::StrokeCamera, shapeFromStroke()  the sketch tool: a screen-space stroke -> a chain shape
//   kodawari::stepEngines()               steps many engines in one call (kdw_engines_step)
//   kodawari::Solver, simdPath()          Engine::setSolver's choices; the lane solver's instruction set
//
// Errors: by default every failing call throws kodawari::Error (status + the library's message). Define
// KODAWARI_NO_EXCEPTIONS before including this header to get no throws at all: the same methods then
// return kodawari::Result<T> (or kodawari::Status for calls without a value), expected-style and
// [[nodiscard]]. `kodawari::Ret<T>` names what a method returns in the current mode (T or Result<T>).
// With exceptions, getters are [[nodiscard]]; a created chain, view shape or collider handle may be ignored
// (the engine owns the object).
// Both modes can be mixed in one program: each lives in its own inline namespace.
//
// Handles hold the raw kdw_engine*, so they stay usable when the owning Engine object is moved, and must
// not be used after the engine is destroyed. Ids are validated by the library on every call: a stale id
// fails with KDW_STATUS_INVALID_ID, never undefined behaviour.

#ifndef KODAWARI_HPP
#define KODAWARI_HPP

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "kodawari.h"

// Built with exceptions disabled (-fno-exceptions, /EHs-c-): no-exception mode whether asked for or not.
#if !defined(KODAWARI_NO_EXCEPTIONS) && !defined(__cpp_exceptions) && !defined(__EXCEPTIONS) && !defined(_CPPUNWIND)
#define KODAWARI_NO_EXCEPTIONS
#endif

#ifdef KODAWARI_NO_EXCEPTIONS
#define KODAWARI_DETAIL_MODE no_exceptions
#else
#define KODAWARI_DETAIL_MODE exceptions
#endif

namespace kodawari {
inline namespace KODAWARI_DETAIL_MODE {

using Vec3 = kdw_vec3;
using Quat = kdw_quat;
using Transform = kdw_transform;
using ChainId = kdw_chain_id;
using ViewShapeId = kdw_view_shape_id;
using ColliderId = kdw_collider_id;
using EngineStats = kdw_engine_stats;
using Vec2 = kdw_vec2;

/// The loaded library's ABI version differs from the header's.
inline constexpr kdw_status kStatusAbiMismatch = KDW_STATUS_ABI_MISMATCH;

/// The library's ABI version (compare with KDW_ABI_VERSION).
inline uint32_t abiVersion() noexcept { return kdw_abi_version(); }

/// The library's version string, e.g. "0.1.0".
inline const char* versionString() noexcept { return kdw_version_string(); }

/// The instruction set the lane solver's kernel runs with on this CPU: "avx512", "avx2", "sse2" (the portable
/// x86-64 kernel), "neon" or "scalar". Static, never null.
inline const char* simdPath() noexcept { return kdw_simd_path(); }

/// Whether the library was built with `portable-determinism`: the same bits on x86-64 and aarch64 (replays,
/// lockstep). Check it on every peer that must agree.
inline bool portableDeterminism() noexcept { return kdw_portable_determinism() != 0; }

/// Which solver steps an engine's chains (KDW_SOLVER_*). They agree up to float
/// rounding; a chain's bits never depend on its lane, its group or the kernel copy.
enum class Solver : uint32_t {
    /// Chains of equal joint count side by side in SIMD lanes (the default; contacts lane by lane). The last 1
    /// or 2 chains of a joint count after its groups of 16 or 8 (too few for a group) take the scalar solver.
    Lanes = KDW_SOLVER_LANES,
    /// Lanes with the portable kernel copy whatever the CPU has: the same bits, slower (determinism checks).
    LanesPortable = KDW_SOLVER_LANES_PORTABLE,
    /// One chain at a time: the reference implementation.
    Scalar = KDW_SOLVER_SCALAR,
};

/// A static description of a status.
inline const char* statusString(kdw_status status) noexcept {
    return kdw_status_str(status);
}

/// This thread's message about its last failed C call (empty if none).
inline std::string lastErrorMessage() {
    uint32_t length = 0;
    if (kdw_last_error_message(nullptr, 0, &length) != KDW_STATUS_OK || length == 0) return {};
    std::string message(length + 1, '\0');
    if (kdw_last_error_message(&message[0], length + 1, &length) != KDW_STATUS_OK) return {};
    message.resize(length);
    return message;
}

/// A failed call: the status and the library's detail message. `what()` is "<status>: <message>".
class Error : public std::runtime_error {
public:
    /// Wraps a failing status and its detail message.
    Error(kdw_status status, const std::string& message)
        : std::runtime_error(std::string(statusString(status)) + (message.empty() ? "" : ": " + message)),
          status_(status), message_(message) {}
    /// The KDW_STATUS_* value.
    kdw_status status() const noexcept { return status_; }
    /// The library's detail message (kdw_last_error_message at the time of the failure).
    const std::string& message() const noexcept { return message_; }

private:
    kdw_status status_;
    std::string message_;
};

/// Outcome of a call without a value: OK, or a failing status with its message.
class [[nodiscard]] Status {
public:
    /// Success.
    Status() noexcept = default;
    /// A status with its detail message.
    Status(kdw_status status, std::string message) noexcept : status_(status), message_(std::move(message)) {}
    /// True on success.
    bool ok() const noexcept { return status_ == KDW_STATUS_OK; }
    /// True on success.
    explicit operator bool() const noexcept { return ok(); }
    /// The KDW_STATUS_* value (KDW_STATUS_OK on success).
    kdw_status status() const noexcept { return status_; }
    /// The library's detail message (empty on success).
    const std::string& message() const noexcept { return message_; }

private:
    kdw_status status_ = KDW_STATUS_OK;
    std::string message_;
};

/// Outcome of a call with a value: the value, or a failing status with its message (like std::expected).
template <class T>
class [[nodiscard]] Result {
public:
    /// Success with a value.
    Result(T value) : value_(std::move(value)) {}
    /// Failure (`error` must not be OK).
    Result(Status error) : status_(std::move(error)) {}
    /// True on success.
    bool ok() const noexcept { return status_.ok(); }
    /// True on success.
    explicit operator bool() const noexcept { return ok(); }
    /// The value; calling it on a failure throws Error (aborts under KODAWARI_NO_EXCEPTIONS).
    T& value() & {
        ensure();
        return value_;
    }
    /// The value; calling it on a failure throws Error (aborts under KODAWARI_NO_EXCEPTIONS).
    const T& value() const& {
        ensure();
        return value_;
    }
    /// The value, moved out; calling it on a failure throws Error (aborts under KODAWARI_NO_EXCEPTIONS).
    T&& value() && {
        ensure();
        return std::move(value_);
    }
    /// The value on success, else `fallback`.
    T valueOr(T fallback) const& { return ok() ? value_ : fallback; }
    /// The KDW_STATUS_* value (KDW_STATUS_OK on success).
    kdw_status status() const noexcept { return status_.status(); }
    /// The library's detail message (empty on success).
    const std::string& message() const noexcept { return status_.message(); }

private:
    void ensure() const {
        if (ok()) return;
#ifdef KODAWARI_NO_EXCEPTIONS
        std::abort();
#else
        throw Error(status_.status(), status_.message());
#endif
    }
    T value_{};
    Status status_;
};

namespace detail {
#ifdef KODAWARI_NO_EXCEPTIONS
template <class T>
struct ReturnType { using type = Result<T>; };
template <>
struct ReturnType<void> { using type = Status; };
#else
template <class T>
struct ReturnType { using type = T; };
#endif
}  // namespace detail

/// What a fallible method returns: `T` (exceptions) or `Result<T>` / `Status` (KODAWARI_NO_EXCEPTIONS).
template <class T>
using Ret = typename detail::ReturnType<T>::type;

namespace detail {
/// The one place a status becomes an error: throws Error, or returns a Status under KODAWARI_NO_EXCEPTIONS.
inline Ret<void> check(kdw_status status, const char* message = nullptr) {
    if (status == KDW_STATUS_OK) return Ret<void>();
#ifdef KODAWARI_NO_EXCEPTIONS
    return Status(status, message ? std::string(message) : lastErrorMessage());
#else
    throw Error(status, message ? std::string(message) : lastErrorMessage());
#endif
}

/// `value` if `status` is OK, else the error of check().
template <class T>
Ret<T> result(kdw_status status, T value) {
#ifdef KODAWARI_NO_EXCEPTIONS
    if (status != KDW_STATUS_OK) return check(status);
#else
    check(status);
#endif
    return value;
}
}  // namespace detail

// Returns early from the enclosing method with the failure of `expr` (a check() result).
#ifdef KODAWARI_NO_EXCEPTIONS
#define KODAWARI_DETAIL_TRY(expr)                        \
    do {                                                 \
        ::kodawari::Status kdw_try_status = (expr);      \
        if (!kdw_try_status.ok()) return kdw_try_status; \
    } while (0)
#else
#define KODAWARI_DETAIL_TRY(expr) expr
#endif

/// A contiguous, non-owning view of `T` (a C++17 stand-in for std::span): from a pointer + count, a C
/// array, or any container with data() and size() (std::vector, std::array).
template <class T>
class Span {
public:
    /// Empty.
    constexpr Span() noexcept = default;
    /// `size` elements starting at `data`.
    constexpr Span(T* data, uint32_t size) noexcept : data_(data), size_(size) {}
    /// A whole C array.
    template <std::size_t N>
    constexpr Span(T (&array)[N]) noexcept : data_(array), size_(static_cast<uint32_t>(N)) {}
    /// A whole container (std::vector, std::array, ...).
    template <class Container,
              class = std::enable_if_t<!std::is_same_v<std::decay_t<Container>, Span> &&
                                       std::is_convertible_v<decltype(std::declval<Container&>().data()), T*>>>
    constexpr Span(Container&& container) noexcept
        : data_(container.data()), size_(static_cast<uint32_t>(container.size())) {}
    /// First element.
    constexpr T* data() const noexcept { return data_; }
    /// Number of elements.
    constexpr uint32_t size() const noexcept { return size_; }
    /// True if there are no elements.
    constexpr bool empty() const noexcept { return size_ == 0; }
    /// Start of the range.
    constexpr T* begin() const noexcept { return data_; }
    /// End of the range.
    constexpr T* end() const noexcept { return data_ + size_; }
    /// Element `i` (unchecked).
    constexpr T& operator[](uint32_t i) const noexcept { return data_[i]; }

private:
    T* data_ = nullptr;
    uint32_t size_ = 0;
};

/// Engine settings, initialised to kdw_engine_def_default(). The fields are the C struct's: gravity,
/// substep_rate, max_substeps, iterations, time_scale, teleport_distance, teleport_angle, teleport_mode,
/// sleep_speed (character units/s below which a still chain falls asleep; 0 never sleeps), lod (0-3: each
/// level halves the step rate, not below 30 Hz, and the iterations, not below 1) and scale.
struct EngineDef : kdw_engine_def {
    /// The library defaults.
    EngineDef() noexcept : kdw_engine_def(kdw_engine_def_default()) {}
};

/// Chain parameters, initialised to kdw_chain_def_default().
struct ChainDef : kdw_chain_def {
    /// The library defaults.
    ChainDef() noexcept : kdw_chain_def(kdw_chain_def_default()) {}
};

/// A collider, initialised to kdw_collider_def_default() (a 0.1 m sphere at the origin on layer 1). Shapes:
/// KDW_COLLIDER_SPHERE, _CAPSULE (along local Y), _PLANE (solid below local Y), _INSIDE_SPHERE, _INSIDE_CAPSULE.
/// Sizes and the pose are world units.
struct ColliderDef : kdw_collider_def {
    /// The library defaults.
    ColliderDef() noexcept : kdw_collider_def(kdw_collider_def_default()) {}
    /// A sphere of `radius` at `pose`.
    static ColliderDef sphere(float radius, const Transform& pose) noexcept {
        ColliderDef def;
        def.shape = KDW_COLLIDER_SPHERE;
        def.radius = radius;
        def.transform = pose;
        return def;
    }
    /// A capsule: `radius` around the segment from -halfHeight to +halfHeight on the pose's local Y axis.
    static ColliderDef capsule(float radius, float halfHeight, const Transform& pose) noexcept {
        ColliderDef def = sphere(radius, pose);
        def.shape = KDW_COLLIDER_CAPSULE;
        def.half_height = halfHeight;
        return def;
    }
};

/// The camera a stroke was drawn in, initialised to kdw_stroke_camera_default() (perspective, 60° vertical
/// field of view, 1920 x 1080 pixels, looking along its local -Z; set forwardAxis to
/// KDW_CAMERA_FORWARD_POSITIVE_Z for Unity's position and rotation). Pixels: origin top-left, y down.
struct StrokeCamera : kdw_stroke_camera {
    /// The library defaults.
    StrokeCamera() noexcept : kdw_stroke_camera(kdw_stroke_camera_default()) {}
    /// Pixel position of a world point; fails for a point on or behind a perspective camera's eye plane.
    [[nodiscard]] Ret<Vec2> project(const Vec3& point) const {
        Vec2 pixel{};
        const kdw_status status = kdw_stroke_camera_project(this, &point, &pixel);
        return detail::result(status, pixel);
    }
};

/// A chain shape drawn as a stroke (shapeFromStroke): pass it to ViewDependentPhysicalObject::addViewShape.
struct StrokeShape {
    /// The new joints in the anchor frame, as many as the chain has.
    std::vector<Transform> joints;
    /// Unit direction from the view reference joint to the camera, in the joint's frame.
    Vec3 viewDirection{};
};

/// The sketch tool (kdw_shape_from_stroke): a shape for a chain whose projection through `camera` follows
/// `strokePixels` (root to tip, >= 2 distinct points, moved to start at the projected root), keeping the
/// root and every segment length; depth comes from the current shape where the stroke cannot tell it.
/// `currentWorldJoints` (>= 2), `anchorWorld` (the frame of the result) and `viewReferenceWorld` are world
/// transforms.
[[nodiscard]] inline Ret<StrokeShape> shapeFromStroke(const StrokeCamera& camera,
                                                      Span<const Transform> currentWorldJoints,
                                                      const Transform& anchorWorld,
                                                      const Transform& viewReferenceWorld,
                                                      Span<const Vec2> strokePixels) {
    StrokeShape shape;
    shape.joints.resize(currentWorldJoints.size());
    const kdw_status status = kdw_shape_from_stroke(
        &camera, currentWorldJoints.data(), currentWorldJoints.size(), &anchorWorld, &viewReferenceWorld,
        strokePixels.data(), strokePixels.size(), shape.joints.data(), currentWorldJoints.size(), &shape.viewDirection);
    return detail::result(status, std::move(shape));
}

/// A view shape of a chain: non-owning handle (engine pointer + id), cheap to copy.
class ViewShape {
public:
    /// The null handle.
    ViewShape() noexcept = default;
    /// Wraps an id of `engine`.
    ViewShape(kdw_engine* engine, ViewShapeId id) noexcept : engine_(engine), id_(id) {}

    /// The engine this view shape belongs to.
    kdw_engine* engine() const noexcept { return engine_; }
    /// The C id.
    ViewShapeId id() const noexcept { return id_; }

    /// True if the id names a live view shape of its engine (false for null, removed or foreign ids).
    [[nodiscard]] bool isValid() const noexcept {
        uint32_t valid = 0;
        return engine_ != nullptr && id_ != 0 && kdw_view_shape_is_valid(engine_, id_, &valid) == KDW_STATUS_OK &&
               valid != 0;
    }

    /// Sets the influence (> 0): large narrows, small widens the cone of directions it acts in.
    Ret<void> setInfluence(float influence) const {
        return detail::check(kdw_view_shape_set_influence(engine_, id_, influence));
    }
    /// Sets the view direction (view reference frame, non-zero).
    Ret<void> setDirection(const Vec3& direction) const {
        return detail::check(kdw_view_shape_set_direction(engine_, id_, &direction));
    }
    /// Replaces the joints (as many as the chain has, anchor frame).
    Ret<void> setJoints(const Transform* joints, uint32_t count) const {
        return detail::check(kdw_view_shape_set_joints(engine_, id_, joints, count));
    }
    /// Replaces the joints (as many as the chain has, anchor frame).
    Ret<void> setJoints(Span<const Transform> joints) const { return setJoints(joints.data(), joints.size()); }
    /// Removes the view shape from its chain; this handle (and its copies) become invalid.
    Ret<void> remove() const { return detail::check(kdw_view_shape_remove(engine_, id_)); }

    /// Same engine and id.
    friend bool operator==(const ViewShape& a, const ViewShape& b) noexcept {
        return a.engine_ == b.engine_ && a.id_ == b.id_;
    }
    /// Different engine or id.
    friend bool operator!=(const ViewShape& a, const ViewShape& b) noexcept { return !(a == b); }

private:
    kdw_engine* engine_ = nullptr;
    ViewShapeId id_ = 0;
};

/// A collider of an engine: non-owning handle (engine pointer + id), cheap to copy. Its pose is set for all
/// colliders at once by Engine::setColliderTransforms (creation order, see Engine::colliderIds).
class Collider {
public:
    /// The null handle.
    Collider() noexcept = default;
    /// Wraps an id of `engine`.
    Collider(kdw_engine* engine, ColliderId id) noexcept : engine_(engine), id_(id) {}

    /// The engine this collider belongs to.
    kdw_engine* engine() const noexcept { return engine_; }
    /// The C id.
    ColliderId id() const noexcept { return id_; }

    /// True if the id names a live collider of its engine (false for null, destroyed or foreign ids).
    [[nodiscard]] bool isValid() const noexcept {
        uint32_t valid = 0;
        return engine_ != nullptr && id_ != 0 && kdw_collider_is_valid(engine_, id_, &valid) == KDW_STATUS_OK &&
               valid != 0;
    }
    /// Moves the collider to other layers: it affects chains whose collision mask shares a bit.
    Ret<void> setLayers(uint32_t layers) const { return detail::check(kdw_collider_set_layers(engine_, id_, layers)); }
    /// Resizes the collider, keeping its shape kind: `radius` and `halfHeight` in world units, validated as in
    /// ColliderDef (e.g. when the bone it follows is scaled).
    Ret<void> setSize(float radius, float halfHeight) const {
        return detail::check(kdw_collider_set_size(engine_, id_, radius, halfHeight));
    }
    /// Destroys the collider; this handle (and its copies) become invalid. Later colliders keep their order.
    Ret<void> destroy() const { return detail::check(kdw_collider_destroy(engine_, id_)); }

    /// Same engine and id.
    friend bool operator==(const Collider& a, const Collider& b) noexcept {
        return a.engine_ == b.engine_ && a.id_ == b.id_;
    }
    /// Different engine or id.
    friend bool operator!=(const Collider& a, const Collider& b) noexcept { return !(a == b); }

private:
    kdw_engine* engine_ = nullptr;
    ColliderId id_ = 0;
};

/// A chain (hair strand, ear, tail): non-owning handle (engine pointer + id), cheap to copy. Methods are
/// const because the handle is a value like an id; they act on the chain inside the engine.
class ViewDependentPhysicalObject {
public:
    /// The null handle.
    ViewDependentPhysicalObject() noexcept = default;
    /// Wraps an id of `engine`.
    ViewDependentPhysicalObject(kdw_engine* engine, ChainId id) noexcept : engine_(engine), id_(id) {}

    /// The engine this chain belongs to.
    kdw_engine* engine() const noexcept { return engine_; }
    /// The C id.
    ChainId id() const noexcept { return id_; }

    /// True if the id names a live chain of its engine (false for null, destroyed or foreign ids).
    [[nodiscard]] bool isValid() const noexcept {
        uint32_t valid = 0;
        return engine_ != nullptr && id_ != 0 && kdw_chain_is_valid(engine_, id_, &valid) == KDW_STATUS_OK &&
               valid != 0;
    }
    /// Destroys the chain and its view shapes; this handle (and its copies) become invalid.
    Ret<void> destroy() const { return detail::check(kdw_chain_destroy(engine_, id_)); }

    /// The chain's parameters.
    [[nodiscard]] Ret<ChainDef> def() const {
        ChainDef def;
        const kdw_status status = kdw_chain_get_def(engine_, id_, &def);
        return detail::result(status, def);
    }
    /// Replaces the parameters (validated as a whole; nothing changes on error).
    Ret<void> setDef(const ChainDef& def) const { return detail::check(kdw_chain_set_def(engine_, id_, &def)); }
    /// Replaces the base shape (same joint count, anchor frame), blended in without injecting momentum.
    Ret<void> setBaseShape(const Transform* joints, uint32_t count) const {
        return detail::check(kdw_chain_set_base_shape(engine_, id_, joints, count));
    }
    /// Replaces the base shape (same joint count, anchor frame), blended in without injecting momentum.
    Ret<void> setBaseShape(Span<const Transform> joints) const { return setBaseShape(joints.data(), joints.size()); }
    /// Puts the chain back to its rest shape, at rest, at the next step.
    Ret<void> reset() const { return detail::check(kdw_chain_reset(engine_, id_)); }
    /// Treats the anchor's motion in the next step as a teleport (the engine's teleport_mode), however small.
    Ret<void> teleport() const { return detail::check(kdw_chain_teleport(engine_, id_)); }
    /// Per-joint collision radii (character units, x the engine's scale): one per joint, each in [0, 1e6].
    Ret<void> setJointRadii(const float* radii, uint32_t count) const {
        return detail::check(kdw_chain_set_joint_radii(engine_, id_, radii, count));
    }
    /// Per-joint collision radii (one per joint); an empty span goes back to the def's radius for every joint.
    Ret<void> setJointRadii(Span<const float> radii) const { return setJointRadii(radii.data(), radii.size()); }
    /// Enables or disables (culls) the chain. A disabled chain is not simulated and costs nothing: it rides
    /// rigidly with its anchor in its last pose; enabled again it carries on from there without a whip.
    Ret<void> setEnabled(bool enabled) const {
        return detail::check(kdw_chain_set_enabled(engine_, id_, enabled ? 1u : 0u));
    }
    /// True if the chain is enabled (the default).
    [[nodiscard]] Ret<bool> isEnabled() const {
        uint32_t enabled = 0;
        const kdw_status status = kdw_chain_is_enabled(engine_, id_, &enabled);
        return detail::result(status, enabled != 0);
    }
    /// True if the chain slept through the last step (its anchor, rest shape and nearby colliders were still
    /// and its motion had died out; see EngineDef::sleep_speed).
    [[nodiscard]] Ret<bool> isAsleep() const {
        uint32_t asleep = 0;
        const kdw_status status = kdw_chain_is_asleep(engine_, id_, &asleep);
        return detail::result(status, asleep != 0);
    }

    /// Number of joints.
    [[nodiscard]] Ret<uint32_t> jointCount() const {
        uint32_t count = 0;
        const kdw_status status = kdw_chain_joint_count(engine_, id_, &count);
        return detail::result(status, count);
    }
    /// World transforms of the joints into `out` (capacity >= joint count); returns how many were written.
    [[nodiscard]] Ret<uint32_t> readWorld(Transform* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_chain_read_world(engine_, id_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// World transforms of the joints; `out` is resized to the joint count (no allocation if it fits).
    Ret<void> readWorld(std::vector<Transform>& out) const {
        return readInto(out, [this](Transform* data, uint32_t capacity, uint32_t* written) {
            return kdw_chain_read_world(engine_, id_, data, capacity, written);
        });
    }
    /// The current rest shape (blend of the shapes for the last view direction, anchor frame) into `out`;
    /// returns how many joints were written.
    [[nodiscard]] Ret<uint32_t> readRestShape(Transform* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_chain_read_rest_shape(engine_, id_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// The current rest shape (anchor frame); `out` is resized to the joint count.
    Ret<void> readRestShape(std::vector<Transform>& out) const {
        return readInto(out, [this](Transform* data, uint32_t capacity, uint32_t* written) {
            return kdw_chain_read_rest_shape(engine_, id_, data, capacity, written);
        });
    }
    /// Kinetic energy of the dynamic joints, J.
    [[nodiscard]] Ret<float> kineticEnergy() const {
        float energy = 0.0f;
        const kdw_status status = kdw_chain_kinetic_energy(engine_, id_, &energy);
        return detail::result(status, energy);
    }

    /// Adds a view shape: seen from `direction` (view reference frame, non-zero) the rest shape becomes
    /// `joints` (as many as the chain has); `influence > 0` sets the width of its cone.
    Ret<ViewShape> addViewShape(const Vec3& direction, const Transform* joints, uint32_t count,
                                float influence) const {
        ViewShapeId id = 0;
        const kdw_status status = kdw_chain_add_view_shape(engine_, id_, &direction, joints, count, influence, &id);
        return detail::result(status, ViewShape(engine_, id));
    }
    /// Adds a view shape (see the pointer overload).
    Ret<ViewShape> addViewShape(const Vec3& direction, Span<const Transform> joints, float influence) const {
        return addViewShape(direction, joints.data(), joints.size(), influence);
    }
    /// Adds a sketched shape (shapeFromStroke) as a view shape seen from its camera's direction.
    Ret<ViewShape> addViewShape(const StrokeShape& shape, float influence) const {
        return addViewShape(shape.viewDirection, shape.joints.data(), static_cast<uint32_t>(shape.joints.size()),
                            influence);
    }
    /// Number of view shapes.
    [[nodiscard]] Ret<uint32_t> viewShapeCount() const {
        uint32_t count = 0;
        const kdw_status status = kdw_chain_view_shape_count(engine_, id_, &count);
        return detail::result(status, count);
    }

    /// Same engine and id.
    friend bool operator==(const ViewDependentPhysicalObject& a, const ViewDependentPhysicalObject& b) noexcept {
        return a.engine_ == b.engine_ && a.id_ == b.id_;
    }
    /// Different engine or id.
    friend bool operator!=(const ViewDependentPhysicalObject& a, const ViewDependentPhysicalObject& b) noexcept {
        return !(a == b);
    }

private:
    template <class Read>
    Ret<void> readInto(std::vector<Transform>& out, Read read) const {
        uint32_t count = 0;
        KODAWARI_DETAIL_TRY(detail::check(kdw_chain_joint_count(engine_, id_, &count)));
        out.resize(count);
        uint32_t written = 0;
        return detail::check(read(out.data(), count, &written));
    }

    kdw_engine* engine_ = nullptr;
    ChainId id_ = 0;
};

/// One per character: owns its chains, view shapes and colliders. Move-only; the destructor destroys the engine.
class Engine {
public:
    /// An empty engine (falsy); assign one from create().
    Engine() noexcept = default;
    /// Takes ownership of an engine made by kdw_engine_create (nullptr gives an empty engine).
    explicit Engine(kdw_engine* owned) noexcept : handle_(owned) {}
#ifndef KODAWARI_NO_EXCEPTIONS
    /// Creates an engine; throws Error on an ABI mismatch or invalid settings.
    explicit Engine(const EngineDef& def) : Engine(create(def)) {}
#endif
    /// Creates an engine after checking kdw_abi_version() == KDW_ABI_VERSION.
    [[nodiscard]] static Ret<Engine> create(const EngineDef& def = EngineDef()) {
        if (kdw_abi_version() != KDW_ABI_VERSION) {
            KODAWARI_DETAIL_TRY(detail::check(kStatusAbiMismatch,
                                              "the loaded kodawari library has another ABI version than kodawari.h"));
        }
        kdw_engine* raw = nullptr;
        const kdw_status status = kdw_engine_create(&def, &raw);
        return detail::result(status, Engine(raw));
    }

    /// Destroys the engine (if any) and everything it owns.
    ~Engine() {
        if (handle_ != nullptr) kdw_engine_destroy(handle_);
    }
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;
    /// Takes over `other`'s engine; `other` becomes empty.
    Engine(Engine&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    /// Destroys the current engine (if any) and takes over `other`'s; `other` becomes empty.
    Engine& operator=(Engine&& other) noexcept {
        Engine old(std::move(other));
        std::swap(handle_, old.handle_);
        return *this;
    }

    /// True if this object owns an engine.
    explicit operator bool() const noexcept { return handle_ != nullptr; }
    /// The C handle (nullptr if empty); still owned by this object.
    kdw_engine* handle() const noexcept { return handle_; }
    /// Gives up ownership: returns the C handle, which the caller must kdw_engine_destroy.
    [[nodiscard]] kdw_engine* release() noexcept { return std::exchange(handle_, nullptr); }

    /// The current settings.
    [[nodiscard]] Ret<EngineDef> def() const {
        EngineDef def;
        const kdw_status status = kdw_engine_get_def(handle_, &def);
        return detail::result(status, def);
    }
    /// Replaces all settings (validated as a whole; nothing changes on error).
    Ret<void> setDef(const EngineDef& def) { return detail::check(kdw_engine_set_def(handle_, &def)); }
    /// World gravity, m/s².
    [[nodiscard]] Ret<Vec3> gravity() const {
        EngineDef def;
        const kdw_status status = kdw_engine_get_def(handle_, &def);
        return detail::result(status, def.gravity);
    }
    /// Sets world gravity, m/s².
    Ret<void> setGravity(const Vec3& gravity) { return detail::check(kdw_engine_set_gravity(handle_, &gravity)); }
    /// Selects the solver for the engine's chains (Solver::Lanes by default); part of stateHash().
    /// A value outside Solver fails with KDW_STATUS_INVALID_ARGUMENT and changes nothing.
    Ret<void> setSolver(Solver solver) {
        return detail::check(kdw_engine_set_solver(handle_, static_cast<uint32_t>(solver)));
    }
    /// The engine's solver.
    [[nodiscard]] Ret<Solver> solver() const {
        uint32_t solver = 0;
        const kdw_status status = kdw_engine_get_solver(handle_, &solver);
        return detail::result(status, static_cast<Solver>(solver));
    }

    /// Advances every chain by `dt` s (finite, >= 0), seen from `camera` (world), with the view reference
    /// joint K at `viewReference` (world).
    Ret<void> step(float dt, const Vec3& camera, const Transform& viewReference) {
        return detail::check(kdw_engine_step(handle_, dt, &camera, &viewReference));
    }
    /// Sets every chain's anchor for the next step (`count` == chain count, creation order, world space).
    Ret<void> setAnchors(const Transform* anchors, uint32_t count) {
        return detail::check(kdw_engine_set_anchors(handle_, anchors, count));
    }
    /// Sets every chain's anchor for the next step (one per chain, creation order, world space).
    Ret<void> setAnchors(Span<const Transform> anchors) { return setAnchors(anchors.data(), anchors.size()); }

    /// Number of chains.
    [[nodiscard]] Ret<uint32_t> chainCount() const {
        uint32_t count = 0;
        const kdw_status status = kdw_engine_chain_count(handle_, &count);
        return detail::result(status, count);
    }
    /// Total number of joints of all chains (the size readWorld needs).
    [[nodiscard]] Ret<uint32_t> jointCount() const {
        uint32_t count = 0;
        const kdw_status status = kdw_engine_joint_count(handle_, &count);
        return detail::result(status, count);
    }
    /// Chain ids in creation order into `out` (capacity >= chain count); returns how many were written.
    [[nodiscard]] Ret<uint32_t> chainIds(ChainId* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_engine_get_chain_ids(handle_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// Chain ids in creation order; `out` is resized to the chain count (no allocation if it fits).
    Ret<void> chainIds(std::vector<ChainId>& out) const {
        return readInto(out, kdw_engine_chain_count, kdw_engine_get_chain_ids);
    }
    /// A handle for a chain id of this engine (not checked here; see isValid()).
    ViewDependentPhysicalObject chain(ChainId id) noexcept { return {handle_, id}; }

    /// World transforms of every joint (chains in creation order, root to tip) into `out`; returns how
    /// many were written (capacity >= jointCount()).
    [[nodiscard]] Ret<uint32_t> readWorld(Transform* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_engine_read_world(handle_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// World transforms of every joint; `out` is resized to jointCount() (no allocation if it fits).
    Ret<void> readWorld(std::vector<Transform>& out) const {
        return readInto(out, kdw_engine_joint_count, kdw_engine_read_world);
    }
    /// Each joint's rotation relative to its parent (Unity's localRotation), in readWorld order, into
    /// `out`; returns how many were written.
    [[nodiscard]] Ret<uint32_t> readLocalRotations(Quat* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_engine_read_local_rotations(handle_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// Local rotations in readWorld order; `out` is resized to jointCount() (no allocation if it fits).
    Ret<void> readLocalRotations(std::vector<Quat>& out) const {
        return readInto(out, kdw_engine_joint_count, kdw_engine_read_local_rotations);
    }

    /// A whole frame in one native call: anchors (one per chain), step, local rotations out (`capacity` >=
    /// jointCount()). Nothing changes unless every input is valid. Returns how many rotations were written.
    Ret<uint32_t> stepAndReadLocalRotations(float dt, const Vec3& camera, const Transform& viewReference,
                                            const Transform* anchors, uint32_t anchorCount, Quat* out,
                                            uint32_t capacity) {
        uint32_t written = 0;
        const kdw_status status = kdw_engine_step_and_read(handle_, dt, &camera, &viewReference, anchors, anchorCount,
                                                           out, capacity, &written);
        return detail::result(status, written);
    }

    /// Counters: chains, joints, substeps, time dropped, chains asleep, chains the lane solver stepped
    /// (lane_chains) in the last step.
    [[nodiscard]] Ret<EngineStats> stats() const {
        EngineStats stats{};
        const kdw_status status = kdw_engine_get_stats(handle_, &stats);
        return detail::result(status, stats);
    }
    /// Puts every chain back to its rest shape, at rest, at the next step.
    Ret<void> reset() { return detail::check(kdw_engine_reset(handle_)); }
    /// Every chain treats its anchor's motion in the next step as a teleport (teleport_mode), however small:
    /// call it when the character is placed somewhere new.
    Ret<void> teleport() { return detail::check(kdw_engine_teleport(handle_)); }
    /// A hash of everything that determines future results (determinism and "unchanged" checks).
    [[nodiscard]] Ret<uint64_t> stateHash() const {
        uint64_t hash = 0;
        const kdw_status status = kdw_engine_state_hash(handle_, &hash);
        return detail::result(status, hash);
    }

    /// Creates a chain from its base shape (>= 2 joints, anchor frame, root first).
    Ret<ViewDependentPhysicalObject> createChain(const ChainDef& def, const Transform* joints, uint32_t count) {
        ChainId id = 0;
        const kdw_status status = kdw_chain_create(handle_, &def, joints, count, &id);
        return detail::result(status, ViewDependentPhysicalObject(handle_, id));
    }
    /// Creates a chain from its base shape (>= 2 joints, anchor frame, root first).
    Ret<ViewDependentPhysicalObject> createChain(const ChainDef& def, Span<const Transform> joints) {
        return createChain(def, joints.data(), joints.size());
    }

    /// Creates a collider; chains whose collision mask shares a bit with its layers are kept out of it (or in).
    Ret<Collider> createCollider(const ColliderDef& def) {
        ColliderId id = 0;
        const kdw_status status = kdw_collider_create(handle_, &def, &id);
        return detail::result(status, Collider(handle_, id));
    }
    /// Destroys a collider (as Collider::destroy).
    Ret<void> destroyCollider(const Collider& collider) {
        return detail::check(kdw_collider_destroy(handle_, collider.id()));
    }
    /// A handle for a collider id of this engine (not checked here; see isValid()).
    Collider collider(ColliderId id) noexcept { return {handle_, id}; }
    /// Number of colliders.
    [[nodiscard]] Ret<uint32_t> colliderCount() const {
        uint32_t count = 0;
        const kdw_status status = kdw_engine_collider_count(handle_, &count);
        return detail::result(status, count);
    }
    /// Collider ids in creation order (the order of setColliderTransforms) into `out`; returns how many.
    [[nodiscard]] Ret<uint32_t> colliderIds(ColliderId* out, uint32_t capacity) const {
        uint32_t written = 0;
        const kdw_status status = kdw_engine_get_collider_ids(handle_, out, capacity, &written);
        return detail::result(status, written);
    }
    /// Collider ids in creation order; `out` is resized to the collider count (no allocation if it fits).
    Ret<void> colliderIds(std::vector<ColliderId>& out) const {
        return readInto(out, kdw_engine_collider_count, kdw_engine_get_collider_ids);
    }
    /// Every collider's world pose for the next step, in ONE call: `count` == colliderCount(), creation order.
    /// The step sweeps each collider from its last pose to this one.
    Ret<void> setColliderTransforms(const Transform* poses, uint32_t count) {
        return detail::check(kdw_engine_set_collider_transforms(handle_, poses, count));
    }
    /// Every collider's world pose for the next step (one per collider, creation order).
    Ret<void> setColliderTransforms(Span<const Transform> poses) {
        return setColliderTransforms(poses.data(), poses.size());
    }

private:
    template <class T, class Count, class Read>
    Ret<void> readInto(std::vector<T>& out, Count count_of, Read read) const {
        uint32_t count = 0;
        KODAWARI_DETAIL_TRY(detail::check(count_of(handle_, &count)));
        out.resize(count);
        uint32_t written = 0;
        return detail::check(read(handle_, out.data(), count, &written));
    }

    kdw_engine* handle_ = nullptr;
};

/// Steps several distinct engines by `dt` with one camera, `engines[i]` with its view reference
/// `viewReferences[i]` (as Engine::step each), in one call: in parallel when the library is built with its
/// `parallel` feature. `count` handles and references; every handle and input is checked before any engine
/// moves (a null or empty engine, or one given twice, fails the whole call and changes nothing). Allocates
/// nothing for up to 64 engines.
inline Ret<void> stepEngines(Engine* const* engines, uint32_t count, float dt, const Vec3& camera,
                             const Transform* viewReferences) {
    // kdw_engine* handles on the stack for small batches, else on the heap (the call is per frame).
    constexpr uint32_t kStackHandles = 64;
    if (engines == nullptr) return detail::check(kdw_engines_step(nullptr, count, dt, &camera, viewReferences));
    kdw_engine* stack[kStackHandles];
    std::vector<kdw_engine*> heap;
    kdw_engine** handles = stack;
    if (count > kStackHandles) {
        heap.resize(count);
        handles = heap.data();
    }
    for (uint32_t i = 0; i < count; ++i) handles[i] = engines[i] != nullptr ? engines[i]->handle() : nullptr;
    return detail::check(kdw_engines_step(handles, count, dt, &camera, viewReferences));
}

/// Steps several distinct engines in one call (see the pointer overload): `engines` and `viewReferences`
/// must have the same size, else KDW_STATUS_INVALID_ARGUMENT and nothing moves.
inline Ret<void> stepEngines(Span<Engine* const> engines, float dt, const Vec3& camera,
                             Span<const Transform> viewReferences) {
    if (engines.size() != viewReferences.size()) {
        return detail::check(KDW_STATUS_INVALID_ARGUMENT, "stepEngines: one view reference per engine");
    }
    return stepEngines(engines.data(), engines.size(), dt, camera, viewReferences.data());
}

}  // inline namespace KODAWARI_DETAIL_MODE
}  // namespace kodawari

#undef KODAWARI_DETAIL_TRY
#undef KODAWARI_DETAIL_MODE

#endif  // KODAWARI_HPP
