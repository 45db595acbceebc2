/*
 * Plain-C tests of the sketch tool: kdw_shape_from_stroke and the kdw_stroke_camera helpers.
 *
 * A second translation unit of the C harness: test_kodawari.c's main() runs these through RUN_TEST. The
 * harness's deferred cleanups live in that other unit, so tests here release what they create themselves.
 * Cameras are built from yaw and pitch (they look along rotation * (0, 0, -1)); strokes are made by
 * projecting known shapes with kdw_stroke_camera_project.
 */

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "kodawari.h"

/* harness.h is written for one translation unit: its pass/fail counters are used only by RUN_TEST there. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-variable"
#include "harness.h"
#pragma GCC diagnostic pop

#include "test_sketch.h"

_Static_assert(sizeof(kdw_vec2) == 8, "kdw_vec2 is 8 bytes");
_Static_assert(offsetof(kdw_vec2, x) == 0 && offsetof(kdw_vec2, y) == 4, "kdw_vec2 is (x, y), packed");
_Static_assert(sizeof(kdw_stroke_camera) == 56, "kdw_stroke_camera is 56 bytes");
_Static_assert(offsetof(kdw_stroke_camera, struct_size) == 0, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, position) == 4, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, rotation) == 16, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, projection) == 32, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, forward_axis) == 36, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, vertical_fov) == 40, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, orthographic_half_height) == 44, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, viewport_width) == 48, "kdw_stroke_camera layout");
_Static_assert(offsetof(kdw_stroke_camera, viewport_height) == 52, "kdw_stroke_camera layout");

#define SK_JOINTS 8
#define SK_SEGMENT 0.04f
#define SK_MAX_STROKE 64
/* Projected joints must lie this close to the stroke (pixels). */
#define SK_ON_STROKE_PX 0.5
/* Segment lengths, relative. */
#define SK_LENGTH_TOL 1e-5

/* ---- small vector and quaternion helpers ----------------------------------------------------------------- */

static kdw_vec3 sk_v3(float x, float y, float z)
{
    kdw_vec3 v = {x, y, z};
    return v;
}
static kdw_vec3 sk_add(kdw_vec3 a, kdw_vec3 b) { return sk_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static kdw_vec3 sk_sub(kdw_vec3 a, kdw_vec3 b) { return sk_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static kdw_vec3 sk_scale(kdw_vec3 a, float s) { return sk_v3(a.x * s, a.y * s, a.z * s); }
static double sk_dist(kdw_vec3 a, kdw_vec3 b)
{
    kdw_vec3 d = sk_sub(a, b);
    return sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
}
static kdw_vec3 sk_normalize(kdw_vec3 a)
{
    double n = sqrt((double)a.x * a.x + (double)a.y * a.y + (double)a.z * a.z);
    return sk_scale(a, (float)(1.0 / n));
}

static kdw_quat sk_q(float x, float y, float z, float w)
{
    kdw_quat q = {x, y, z, w};
    return q;
}
static kdw_quat sk_mul(kdw_quat a, kdw_quat b)
{
    return sk_q(a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}
static kdw_quat sk_axis_angle(kdw_vec3 axis, float angle)
{
    kdw_vec3 n = sk_normalize(axis);
    float s = sinf(0.5f * angle);
    return sk_q(n.x * s, n.y * s, n.z * s, cosf(0.5f * angle));
}
static kdw_vec3 sk_rotate(kdw_quat q, kdw_vec3 v)
{
    kdw_vec3 u = sk_v3(q.x, q.y, q.z);
    kdw_vec3 uv = sk_v3(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x);
    kdw_vec3 t = sk_scale(uv, 2.0f);
    kdw_vec3 ut = sk_v3(u.y * t.z - u.z * t.y, u.z * t.x - u.x * t.z, u.x * t.y - u.y * t.x);
    return sk_add(sk_add(v, sk_scale(t, q.w)), ut);
}
static kdw_transform sk_xf(kdw_vec3 p, kdw_quat q)
{
    kdw_transform t = {p, q};
    return t;
}
static int sk_finite3(kdw_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* ---- scene ------------------------------------------------------------------------------------------------ */

static const kdw_vec3 SK_HEAD = {0.0f, 1.6f, 0.0f};

/* 8 joints from the top of the head, SK_SEGMENT apart, first along `first`, each next one turned by `bend`
 * radians about `axis`. Rotations carry a twist that changes along the chain. */
static void sk_curled(kdw_transform out[SK_JOINTS], kdw_vec3 first, kdw_vec3 axis, float bend)
{
    kdw_quat turn = sk_axis_angle(axis, bend);
    kdw_vec3 dir = sk_normalize(first);
    kdw_vec3 p = sk_add(SK_HEAD, sk_v3(0.0f, 0.12f, 0.0f));
    for (int j = 0; j < SK_JOINTS; ++j) {
        out[j] = sk_xf(p, sk_axis_angle(sk_v3(0.0f, 1.0f, 0.0f), 0.3f * (float)j));
        p = sk_add(p, sk_scale(dir, SK_SEGMENT));
        if (j + 2 < SK_JOINTS) {
            dir = sk_normalize(sk_rotate(turn, dir));
        }
    }
}

static void sk_straight(kdw_transform out[SK_JOINTS])
{
    sk_curled(out, sk_v3(0.0f, 1.0f, 0.0f), sk_v3(0.0f, 0.0f, 1.0f), 0.0f);
}

static void sk_target(kdw_transform out[SK_JOINTS])
{
    sk_curled(out, sk_v3(0.2f, 1.0f, 0.3f), sk_v3(1.0f, 0.0f, -0.6f), 0.35f);
}

/* A camera `distance` from `centre`, turned `yaw` about +y then `pitch` about its x; it looks along its -z
 * at `centre`. */
static kdw_stroke_camera sk_camera(float yaw, float pitch, float distance, uint32_t projection)
{
    kdw_vec3 centre = sk_add(SK_HEAD, sk_v3(0.0f, 0.2f, 0.0f));
    kdw_quat q = sk_mul(sk_axis_angle(sk_v3(0.0f, 1.0f, 0.0f), yaw), sk_axis_angle(sk_v3(1.0f, 0.0f, 0.0f), pitch));
    kdw_stroke_camera camera = kdw_stroke_camera_default();
    camera.position = sk_add(centre, sk_rotate(q, sk_v3(0.0f, 0.0f, distance)));
    camera.rotation = q;
    camera.projection = projection;
    camera.vertical_fov = 0.8f;
    camera.orthographic_half_height = 0.35f;
    camera.viewport_width = 800.0f;
    camera.viewport_height = 600.0f;
    return camera;
}

#define SK_CAMERAS 6
static kdw_stroke_camera sk_camera_at(int i)
{
    static const float yaw[3] = {0.0f, 1.2f, -2.4f};
    static const float pitch[3] = {-0.1f, -0.5f, 0.2f};
    uint32_t projection = i < 3 ? KDW_PROJECTION_PERSPECTIVE : KDW_PROJECTION_ORTHOGRAPHIC;
    return sk_camera(yaw[i % 3], pitch[i % 3], 1.5f, projection);
}

/* Projects joints to pixels; 0 on success. */
static int sk_project(const kdw_stroke_camera *camera, const kdw_transform *joints, int n, kdw_vec2 *out)
{
    for (int j = 0; j < n; ++j) {
        ENSURE_OK(kdw_stroke_camera_project(camera, &joints[j].position, &out[j]));
    }
    return 0;
}

/* `points` with every segment split in `parts`; returns the new count. */
static uint32_t sk_densify(const kdw_vec2 *points, uint32_t count, uint32_t parts, kdw_vec2 *out)
{
    uint32_t written = 0;
    out[written++] = points[0];
    for (uint32_t i = 0; i + 1 < count; ++i) {
        for (uint32_t k = 1; k <= parts; ++k) {
            float t = (float)k / (float)parts;
            kdw_vec2 p = {points[i].x + (points[i + 1].x - points[i].x) * t,
                          points[i].y + (points[i + 1].y - points[i].y) * t};
            out[written++] = p;
        }
    }
    return written;
}

static double sk_distance_to_polyline(kdw_vec2 p, const kdw_vec2 *line, uint32_t count)
{
    double best = INFINITY;
    for (uint32_t i = 0; i + 1 < count; ++i) {
        double ax = line[i].x, ay = line[i].y;
        double bx = line[i + 1].x - ax, by = line[i + 1].y - ay;
        double len2 = bx * bx + by * by;
        double t = len2 > 0.0 ? ((p.x - ax) * bx + (p.y - ay) * by) / len2 : 0.0;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        double dx = p.x - (ax + bx * t), dy = p.y - (ay + by * t);
        double d = sqrt(dx * dx + dy * dy);
        best = d < best ? d : best;
    }
    return best;
}

/* Every segment of `result` has the length of `current`'s, relative; everything finite. */
static int sk_check_lengths(const kdw_transform *current, const kdw_transform *result, int n)
{
    for (int j = 0; j < n; ++j) {
        ENSURE(sk_finite3(result[j].position));
        ENSURE(isfinite(result[j].rotation.w));
    }
    for (int j = 0; j + 1 < n; ++j) {
        double before = sk_dist(current[j].position, current[j + 1].position);
        double after = sk_dist(result[j].position, result[j + 1].position);
        ENSURE_SMALL((after - before) / before, SK_LENGTH_TOL);
    }
    return 0;
}

static kdw_status sk_sketch(const kdw_stroke_camera *camera, const kdw_transform *current, const kdw_vec2 *stroke,
                            uint32_t count, kdw_transform *out, kdw_vec3 *out_direction)
{
    kdw_transform identity = sk_xf(sk_v3(0.0f, 0.0f, 0.0f), sk_q(0.0f, 0.0f, 0.0f, 1.0f));
    kdw_transform head = sk_xf(SK_HEAD, sk_q(0.0f, 0.0f, 0.0f, 1.0f));
    return kdw_shape_from_stroke(camera, current, SK_JOINTS, &identity, &head, stroke, count, out, SK_JOINTS,
                                 out_direction);
}

/* ---- tests ------------------------------------------------------------------------------------------------ */

int test_sketch_layout_and_defaults(void)
{
    kdw_stroke_camera camera = kdw_stroke_camera_default();
    ENSURE(camera.struct_size == sizeof(kdw_stroke_camera));
    ENSURE(camera.projection == KDW_PROJECTION_PERSPECTIVE);
    ENSURE(camera.forward_axis == KDW_CAMERA_FORWARD_NEGATIVE_Z);
    ENSURE(camera.rotation.w == 1.0f && camera.rotation.x == 0.0f);
    ENSURE_SMALL(camera.vertical_fov - 1.04719755f, 1e-6);
    ENSURE(camera.viewport_width == 1920.0f && camera.viewport_height == 1080.0f);

    /* The default camera looks along -z; the centre of the screen is straight ahead, y grows downwards. */
    kdw_vec3 ahead = sk_v3(0.0f, 0.0f, -2.0f);
    kdw_vec3 above = sk_v3(0.0f, 0.5f, -2.0f);
    kdw_vec3 right = sk_v3(0.5f, 0.0f, -2.0f);
    kdw_vec2 pixel;
    ENSURE_OK(kdw_stroke_camera_project(&camera, &ahead, &pixel));
    ENSURE_SMALL(pixel.x - 960.0f, 1e-3);
    ENSURE_SMALL(pixel.y - 540.0f, 1e-3);
    ENSURE_OK(kdw_stroke_camera_project(&camera, &above, &pixel));
    ENSURE(pixel.y < 540.0f);
    ENSURE_OK(kdw_stroke_camera_project(&camera, &right, &pixel));
    ENSURE(pixel.x > 960.0f);
    /* Unity's convention: the same rotation looks along +z. */
    camera.forward_axis = KDW_CAMERA_FORWARD_POSITIVE_Z;
    kdw_vec3 behind = sk_v3(0.0f, 0.0f, 2.0f);
    ENSURE_OK(kdw_stroke_camera_project(&camera, &behind, &pixel));
    ENSURE_SMALL(pixel.x - 960.0f, 1e-3);
    return 0;
}

int test_sketch_follows_fitting_strokes(void)
{
    kdw_transform current[SK_JOINTS], target[SK_JOINTS], result[SK_JOINTS];
    sk_straight(current);
    sk_target(target);
    for (int i = 0; i < SK_CAMERAS; ++i) {
        kdw_stroke_camera camera = sk_camera_at(i);
        kdw_vec2 projected[SK_JOINTS], stroke[SK_MAX_STROKE];
        ENSURE(sk_project(&camera, target, SK_JOINTS, projected) == 0);
        uint32_t count = sk_densify(projected, SK_JOINTS, 4, stroke);
        kdw_vec3 direction;
        ENSURE_OK(sk_sketch(&camera, current, stroke, count, result, &direction));
        ENSURE(sk_check_lengths(current, result, SK_JOINTS) == 0);
        ENSURE(memcmp(&result[0].position, &current[0].position, sizeof(kdw_vec3)) == 0); /* root exact */
        for (int j = 0; j < SK_JOINTS; ++j) {
            kdw_vec2 pixel;
            ENSURE_OK(kdw_stroke_camera_project(&camera, &result[j].position, &pixel));
            double off = sk_distance_to_polyline(pixel, stroke, count);
            if (!(off <= SK_ON_STROKE_PX)) {
                printf("    camera %d, joint %d: %.3f px from the stroke\n", i, j, off);
            }
            ENSURE(off <= SK_ON_STROKE_PX);
        }
        /* The view direction is the one from the head to the camera. */
        kdw_vec3 expected = sk_normalize(sk_sub(camera.position, SK_HEAD));
        ENSURE_SMALL(sk_dist(direction, expected), 1e-6);
    }
    return 0;
}

int test_sketch_round_trip(void)
{
    kdw_transform target[SK_JOINTS], result[SK_JOINTS];
    sk_target(target);
    for (int i = 0; i < SK_CAMERAS; ++i) {
        kdw_stroke_camera camera = sk_camera_at(i);
        kdw_vec2 projected[SK_JOINTS], again[SK_JOINTS];
        ENSURE(sk_project(&camera, target, SK_JOINTS, projected) == 0);
        kdw_vec3 direction;
        ENSURE_OK(sk_sketch(&camera, target, projected, SK_JOINTS, result, &direction));
        ENSURE(sk_project(&camera, result, SK_JOINTS, again) == 0);
        for (int j = 0; j < SK_JOINTS; ++j) {
            ENSURE_SMALL(again[j].x - projected[j].x, 0.01);
            ENSURE_SMALL(again[j].y - projected[j].y, 0.01);
            ENSURE_SMALL(sk_dist(result[j].position, target[j].position), 2e-4);
        }
    }
    return 0;
}

int test_sketch_duplicate_points(void)
{
    kdw_transform current[SK_JOINTS], target[SK_JOINTS], once[SK_JOINTS], twice[SK_JOINTS];
    sk_straight(current);
    sk_target(target);
    kdw_stroke_camera camera = sk_camera_at(4);
    kdw_vec2 projected[SK_JOINTS], doubled[2 * SK_JOINTS];
    ENSURE(sk_project(&camera, target, SK_JOINTS, projected) == 0);
    for (int j = 0; j < SK_JOINTS; ++j) {
        doubled[2 * j] = projected[j];
        doubled[2 * j + 1] = projected[j];
    }
    kdw_vec3 d1, d2;
    ENSURE_OK(sk_sketch(&camera, current, projected, SK_JOINTS, once, &d1));
    ENSURE_OK(sk_sketch(&camera, current, doubled, 2 * SK_JOINTS, twice, &d2));
    for (int j = 0; j < SK_JOINTS; ++j) {
        ENSURE_SMALL(sk_dist(once[j].position, twice[j].position), 1e-6);
    }
    return 0;
}

int test_sketch_camera_down_the_chain(void)
{
    kdw_transform current[SK_JOINTS], result[SK_JOINTS];
    sk_straight(current);
    for (uint32_t projection = 0; projection < 2; ++projection) {
        /* Straight above the chain (pitch -90°), looking down along it. */
        kdw_stroke_camera camera = sk_camera(0.0f, -1.5707963f, 1.5f, projection);
        camera.position = sk_add(current[0].position, sk_v3(0.0f, 1.5f, 0.0f));
        kdw_vec2 root;
        ENSURE_OK(kdw_stroke_camera_project(&camera, &current[0].position, &root));
        kdw_vec2 stroke[3] = {root, {root.x + 60.0f, root.y + 10.0f}, {root.x + 90.0f, root.y + 60.0f}};
        kdw_vec3 direction;
        ENSURE_OK(sk_sketch(&camera, current, stroke, 3, result, &direction));
        ENSURE(sk_check_lengths(current, result, SK_JOINTS) == 0);
        ENSURE(sk_finite3(direction));
        /* A stroke far longer than the chain: still finite, lengths kept. */
        stroke[2].x = root.x + 5000.0f;
        ENSURE_OK(sk_sketch(&camera, current, stroke, 3, result, &direction));
        ENSURE(sk_check_lengths(current, result, SK_JOINTS) == 0);
    }
    return 0;
}

int test_sketch_errors(void)
{
    kdw_transform current[SK_JOINTS], out[SK_JOINTS];
    sk_straight(current);
    kdw_stroke_camera camera = sk_camera_at(0);
    kdw_transform identity = sk_xf(sk_v3(0.0f, 0.0f, 0.0f), sk_q(0.0f, 0.0f, 0.0f, 1.0f));
    kdw_vec2 root;
    ENSURE_OK(kdw_stroke_camera_project(&camera, &current[0].position, &root));
    kdw_vec2 stroke[2] = {root, {root.x + 40.0f, root.y - 80.0f}};
    kdw_vec3 direction = sk_v3(7.0f, 7.0f, 7.0f);
    memset(out, 0xA5, sizeof out);

    /* One point, or two equal ones: rejected with a clear message, nothing written. */
    ENSURE_STATUS(sk_sketch(&camera, current, stroke, 1, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(strstr(harness_last_error(), "at least 2 distinct points") != NULL);
    kdw_vec2 same[2] = {root, root};
    ENSURE_STATUS(sk_sketch(&camera, current, same, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(sk_sketch(&camera, current, NULL, 0, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(direction.x == 7.0f);

    /* NULL and too-small buffers. */
    kdw_transform head = sk_xf(SK_HEAD, sk_q(0.0f, 0.0f, 0.0f, 1.0f));
    ENSURE_STATUS(kdw_shape_from_stroke(NULL, current, SK_JOINTS, &identity, &head, stroke, 2, out, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, NULL, SK_JOINTS, &identity, &head, stroke, 2, out, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, current, SK_JOINTS, NULL, &head, stroke, 2, out, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, current, SK_JOINTS, &identity, NULL, stroke, 2, out, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, current, SK_JOINTS, &identity, &head, NULL, 2, out, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, current, SK_JOINTS, &identity, &head, stroke, 2, NULL, SK_JOINTS,
                                        &direction),
                  KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(
        kdw_shape_from_stroke(&camera, current, SK_JOINTS, &identity, &head, stroke, 2, out, SK_JOINTS, NULL),
        KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_shape_from_stroke(&camera, current, SK_JOINTS, &identity, &head, stroke, 2, out,
                                        SK_JOINTS - 1, &direction),
                  KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(direction.x == 7.0f);
    unsigned char *bytes = (unsigned char *)out;
    for (size_t i = 0; i < sizeof out; ++i) {
        ENSURE(bytes[i] == 0xA5);
    }

    /* Invalid cameras and values. */
    kdw_stroke_camera bad = camera;
    bad.struct_size = 12;
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    bad = camera;
    bad.projection = 7;
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    bad = camera;
    bad.forward_axis = 2;
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    bad = camera;
    bad.vertical_fov = 0.0f;
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    bad = camera;
    bad.viewport_height = NAN;
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    bad = camera;
    bad.rotation = sk_q(0.0f, 0.0f, 0.0f, 0.0f);
    ENSURE_STATUS(sk_sketch(&bad, current, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    kdw_vec2 nan_stroke[2] = {root, {NAN, 3.0f}};
    ENSURE_STATUS(sk_sketch(&camera, current, nan_stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    kdw_transform broken[SK_JOINTS];
    memcpy(broken, current, sizeof broken);
    broken[3].position.y = INFINITY;
    ENSURE_STATUS(sk_sketch(&camera, broken, stroke, 2, out, &direction), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(bytes[0] == 0xA5 && direction.x == 7.0f);

    /* A point behind a perspective camera has no pixel. */
    kdw_vec3 behind = sk_add(camera.position, sk_rotate(camera.rotation, sk_v3(0.0f, 0.0f, 1.0f)));
    kdw_vec2 pixel = {-1.0f, -1.0f};
    ENSURE_STATUS(kdw_stroke_camera_project(&camera, &behind, &pixel), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(pixel.x == -1.0f);
    ENSURE_STATUS(kdw_stroke_camera_project(&camera, &behind, NULL), KDW_STATUS_NULL_POINTER);
    return 0;
}

/* Body of test_sketch_result_feeds_a_view_shape, with the engine made by the caller. */
static int sk_feed_engine(kdw_engine *engine)
{
    kdw_transform base[SK_JOINTS], current_world[SK_JOINTS], target_world[SK_JOINTS], sketched[SK_JOINTS];
    kdw_transform head = sk_xf(SK_HEAD, sk_q(0.0f, 0.0f, 0.0f, 1.0f));
    sk_straight(current_world);
    sk_target(target_world);
    for (int j = 0; j < SK_JOINTS; ++j) {
        base[j] = current_world[j];
        base[j].position = sk_sub(current_world[j].position, SK_HEAD); /* anchor = head, unrotated */
    }
    kdw_chain_def def = kdw_chain_def_default();
    kdw_chain_id chain = 0;
    ENSURE_OK(kdw_chain_create(engine, &def, base, SK_JOINTS, &chain));

    kdw_stroke_camera camera = sk_camera_at(1);
    kdw_vec2 stroke[SK_JOINTS];
    ENSURE(sk_project(&camera, target_world, SK_JOINTS, stroke) == 0);
    kdw_vec3 direction;
    ENSURE_OK(kdw_shape_from_stroke(&camera, current_world, SK_JOINTS, &head, &head, stroke, SK_JOINTS, sketched,
                                    SK_JOINTS, &direction));
    kdw_view_shape_id shape = 0;
    ENSURE_OK(kdw_chain_add_view_shape(engine, chain, &direction, sketched, SK_JOINTS, 1.0f, &shape));

    /* Seen from that camera the view shape has weight 1: the rest shape is the sketch. */
    ENSURE_OK(kdw_engine_step(engine, 1.0f / 60.0f, &camera.position, &head));
    kdw_transform rest[SK_JOINTS];
    uint32_t written = 0;
    ENSURE_OK(kdw_chain_read_rest_shape(engine, chain, rest, SK_JOINTS, &written));
    ENSURE(written == SK_JOINTS);
    for (int j = 0; j < SK_JOINTS; ++j) {
        ENSURE_SMALL(sk_dist(rest[j].position, sketched[j].position), 1e-5);
    }
    return 0;
}

int test_sketch_result_feeds_a_view_shape(void)
{
    kdw_engine_def def = kdw_engine_def_default();
    kdw_engine *engine = NULL;
    ENSURE_OK(kdw_engine_create(&def, &engine));
    int result = sk_feed_engine(engine);
    ENSURE_OK(kdw_engine_destroy(engine));
    return result;
}
