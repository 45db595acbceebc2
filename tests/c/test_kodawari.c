/*
 * Plain-C tests of the kodawari C ABI (include/kodawari.h), linked dynamically against the cdylib.
 * Built and run by tests/c_harness.rs (`cargo test --test c_harness`), also under valgrind.
 *
 * Conventions: a test is `static int test_x(void)` returning 0 on success (see harness.h). Engines are
 * created through engine_new(), which registers their destruction after the test so that a failing test
 * does not leak. Everything is deterministic: no clocks, no random numbers.
 */

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kodawari.h"
#include "harness.h"
#include "test_sketch.h"

/* ---- ABI layout: every struct is padding-free and has the size the other language bindings assume ---- */

_Static_assert(sizeof(kdw_vec3) == 12, "kdw_vec3 is 12 bytes");
_Static_assert(sizeof(kdw_quat) == 16, "kdw_quat is 16 bytes");
_Static_assert(sizeof(kdw_transform) == 28, "kdw_transform is 28 bytes");
_Static_assert(sizeof(kdw_engine_def) == 56, "kdw_engine_def is 56 bytes");
_Static_assert(sizeof(kdw_chain_def) == 40, "kdw_chain_def is 40 bytes");
_Static_assert(sizeof(kdw_engine_stats) == 72, "kdw_engine_stats is 72 bytes");
_Static_assert(sizeof(kdw_collider_def) == 48, "kdw_collider_def is 48 bytes");
_Static_assert(sizeof(kdw_status) == 4, "kdw_status is int32_t");
_Static_assert(sizeof(kdw_chain_id) == 8, "kdw_chain_id is uint64_t");
_Static_assert(sizeof(kdw_view_shape_id) == 8, "kdw_view_shape_id is uint64_t");
_Static_assert(sizeof(kdw_collider_id) == 8, "kdw_collider_id is uint64_t");

_Static_assert(offsetof(kdw_vec3, x) == 0 && offsetof(kdw_vec3, y) == 4 && offsetof(kdw_vec3, z) == 8,
               "kdw_vec3 fields are packed");
_Static_assert(offsetof(kdw_quat, x) == 0 && offsetof(kdw_quat, y) == 4 && offsetof(kdw_quat, z) == 8 &&
                   offsetof(kdw_quat, w) == 12,
               "kdw_quat is (x, y, z, w), packed");
_Static_assert(offsetof(kdw_transform, position) == 0, "kdw_transform.position first");
_Static_assert(offsetof(kdw_transform, rotation) == 12, "kdw_transform.rotation right after position");

_Static_assert(offsetof(kdw_engine_def, struct_size) == 0, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, gravity) == 4, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, substep_rate) == 16, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, max_substeps) == 20, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, iterations) == 24, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, time_scale) == 28, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, teleport_distance) == 32, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, teleport_angle) == 36, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, teleport_mode) == 40, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, sleep_speed) == 44, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, lod) == 48, "kdw_engine_def layout");
_Static_assert(offsetof(kdw_engine_def, scale) == 52, "kdw_engine_def layout");

_Static_assert(offsetof(kdw_chain_def, struct_size) == 0, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, stiffness) == 4, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, damping) == 8, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, momentum_suppression) == 12, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, mass) == 16, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, radius) == 20, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, gravity_scale) == 24, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, anchor) == 28, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, collision_mask) == 32, "kdw_chain_def layout");
_Static_assert(offsetof(kdw_chain_def, friction) == 36, "kdw_chain_def layout");

_Static_assert(offsetof(kdw_collider_def, struct_size) == 0, "kdw_collider_def layout");
_Static_assert(offsetof(kdw_collider_def, shape) == 4, "kdw_collider_def layout");
_Static_assert(offsetof(kdw_collider_def, radius) == 8, "kdw_collider_def layout");
_Static_assert(offsetof(kdw_collider_def, half_height) == 12, "kdw_collider_def layout");
_Static_assert(offsetof(kdw_collider_def, transform) == 16, "kdw_collider_def layout");
_Static_assert(offsetof(kdw_collider_def, layers) == 44, "kdw_collider_def layout");

_Static_assert(offsetof(kdw_engine_stats, struct_size) == 0, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, chain_count) == 4, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, joint_count) == 8, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, substeps_last_step) == 12, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, chains_asleep) == 16, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, lane_chains) == 20, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, collider_count) == 24, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, reserved) == 28, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, substeps_total) == 32, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, solver_fallbacks) == 40, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, time_dropped) == 48, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, simulated_time) == 56, "kdw_engine_stats layout");
_Static_assert(offsetof(kdw_engine_stats, contact_pairs_tested) == 64, "kdw_engine_stats layout");

/* The constants the bindings mirror. */
_Static_assert(KDW_ABI_VERSION == 3, "solver selection and kdw_engine_stats.lane_chains are ABI version 3");
_Static_assert(KDW_COLLIDER_SPHERE == 0 && KDW_COLLIDER_CAPSULE == 1 && KDW_COLLIDER_PLANE == 2 &&
                   KDW_COLLIDER_INSIDE_SPHERE == 3 && KDW_COLLIDER_INSIDE_CAPSULE == 4,
               "collider shapes");
_Static_assert(KDW_TELEPORT_CARRY_SHAPE == 0 && KDW_TELEPORT_RESET == 1, "teleport modes");
_Static_assert(KDW_SOLVER_LANES == 0 && KDW_SOLVER_LANES_PORTABLE == 1 && KDW_SOLVER_SCALAR == 2, "solvers");

/* ---- constants ------------------------------------------------------------------------------------------ */

#define PI_F 3.14159265358979f
#define FRAME_DT (1.0f / 60.0f)
#define ORBIT_FRAMES 240

#define MAX_JOINTS 16
#define MAX_CHAINS 8
#define MAX_TOTAL (MAX_JOINTS * MAX_CHAINS)

/* Root joint vs anchor, relative to the root's distance from the world origin: float rounding of one rigid
 * transform (a few ulps; measured 1.2e-7 m at 1.7 m). */
#define ROOT_TOL_REL 1e-6
/* Segment lengths, relative. */
#define LENGTH_TOL 1e-4
/* Unit length of returned quaternions. */
#define UNIT_TOL 1e-5

#define SENTINEL_U32 0xDEADBEEFu
#define SENTINEL_U64 0xDEADBEEFCAFEF00Dull
#define SENTINEL_BYTE 0xA5

/* ---- small vector and quaternion helpers ------------------------------------------------------------------ */

static kdw_vec3 v3(float x, float y, float z)
{
    kdw_vec3 v = {x, y, z};
    return v;
}

static kdw_vec3 v_add(kdw_vec3 a, kdw_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static kdw_vec3 v_sub(kdw_vec3 a, kdw_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static kdw_vec3 v_scale(kdw_vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static kdw_vec3 v_cross(kdw_vec3 a, kdw_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static double v_length(kdw_vec3 a) { return sqrt((double)a.x * a.x + (double)a.y * a.y + (double)a.z * a.z); }
static double v_dist(kdw_vec3 a, kdw_vec3 b) { return v_length(v_sub(a, b)); }
static kdw_vec3 v_normalize(kdw_vec3 a) { return v_scale(a, (float)(1.0 / v_length(a))); }
static int v_is_finite(kdw_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

static kdw_quat q4(float x, float y, float z, float w)
{
    kdw_quat q = {x, y, z, w};
    return q;
}

static kdw_quat q_identity(void) { return q4(0.0f, 0.0f, 0.0f, 1.0f); }

/* Rotation by `angle` radians about the axis (x, y, z) (need not be unit). */
static kdw_quat q_axis_angle(float x, float y, float z, float angle)
{
    float n = sqrtf(x * x + y * y + z * z);
    float s = sinf(0.5f * angle) / n;
    return q4(x * s, y * s, z * s, cosf(0.5f * angle));
}

static kdw_quat q_mul(kdw_quat a, kdw_quat b)
{
    return q4(a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
              a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}

static kdw_quat q_conjugate(kdw_quat q) { return q4(-q.x, -q.y, -q.z, q.w); }
static kdw_quat q_scale(kdw_quat q, float s) { return q4(q.x * s, q.y * s, q.z * s, q.w * s); }
static double q_norm(kdw_quat q)
{
    return sqrt((double)q.x * q.x + (double)q.y * q.y + (double)q.z * q.z + (double)q.w * q.w);
}
static kdw_quat q_normalize(kdw_quat q) { return q_scale(q, (float)(1.0 / q_norm(q))); }
static int q_is_finite(kdw_quat q) { return isfinite(q.x) && isfinite(q.y) && isfinite(q.z) && isfinite(q.w); }

static kdw_vec3 q_rotate(kdw_quat q, kdw_vec3 v)
{
    kdw_vec3 u = v3(q.x, q.y, q.z);
    kdw_vec3 t = v_scale(v_cross(u, v), 2.0f);
    return v_add(v_add(v, v_scale(t, q.w)), v_cross(u, t));
}

/* Largest component difference of two rotations, sign-agnostic (q and -q are the same rotation). */
static double q_distance(kdw_quat a, kdw_quat b)
{
    double plus = fmax(fmax(fabs((double)a.x - b.x), fabs((double)a.y - b.y)),
                       fmax(fabs((double)a.z - b.z), fabs((double)a.w - b.w)));
    double minus = fmax(fmax(fabs((double)a.x + b.x), fabs((double)a.y + b.y)),
                        fmax(fabs((double)a.z + b.z), fabs((double)a.w + b.w)));
    return fmin(plus, minus);
}

static kdw_transform xf(kdw_vec3 position, kdw_quat rotation)
{
    kdw_transform t = {position, rotation};
    return t;
}

static int bytes_are(const void *data, size_t size, unsigned char value)
{
    const unsigned char *p = (const unsigned char *)data;
    for (size_t i = 0; i < size; ++i) {
        if (p[i] != value) {
            return 0;
        }
    }
    return 1;
}

/* ---- chain shapes ------------------------------------------------------------------------------------- */

typedef struct chain_spec {
    uint32_t n;
    kdw_transform joints[MAX_JOINTS];
} chain_spec;

/* The shapes every test uses (filled by init_shapes() before the first test). */
static chain_spec g_ahoge;       /* 8 joints straight up from (0, 0.1, 0), 0.05 apart, identity rotations */
static chain_spec g_ahoge_left;  /* the same chain bent toward -x */
static chain_spec g_ahoge_right; /* the same chain bent toward +x */
static chain_spec g_side_lock;   /* 5 joints hanging down from (0.08, 0, 0.02), 0.04 apart */
static chain_spec g_tail;        /* 6 joints going down and back from (0, 0.05, -0.1), 0.06 apart */

static void make_straight(chain_spec *s, uint32_t n, kdw_vec3 root, kdw_vec3 direction, float spacing)
{
    s->n = n;
    for (uint32_t j = 0; j < n; ++j) {
        s->joints[j] = xf(v_add(root, v_scale(direction, spacing * (float)j)), q_identity());
    }
}

/* The ahoge, each segment turned `bend` radians further about +z than its parent: bend > 0 leans the
 * chain toward -x, bend < 0 toward +x. Joint j is rotated like segment j (the tip like its parent). */
static void make_ahoge_bent(chain_spec *s, float bend)
{
    s->n = 8;
    kdw_vec3 p = v3(0.0f, 0.1f, 0.0f);
    for (uint32_t j = 0; j < s->n; ++j) {
        uint32_t segment = j + 1 < s->n ? j : j - 1;
        float angle = bend * (float)(segment + 1);
        s->joints[j] = xf(p, q_axis_angle(0.0f, 0.0f, 1.0f, angle));
        p = v_add(p, v_scale(v3(-sinf(angle), cosf(angle), 0.0f), 0.05f));
    }
}

static void init_shapes(void)
{
    make_straight(&g_ahoge, 8, v3(0.0f, 0.1f, 0.0f), v3(0.0f, 1.0f, 0.0f), 0.05f);
    make_ahoge_bent(&g_ahoge_left, 0.15f);
    make_ahoge_bent(&g_ahoge_right, -0.15f);
    make_straight(&g_side_lock, 5, v3(0.08f, 0.0f, 0.02f), v3(0.0f, -1.0f, 0.0f), 0.04f);
    make_straight(&g_tail, 6, v3(0.0f, 0.05f, -0.1f), v3(0.0f, -0.6f, -0.8f), 0.06f);
}

/* ---- scene ------------------------------------------------------------------------------------------------ */

static kdw_transform head_at_rest(void) { return xf(v3(0.0f, 1.6f, 0.0f), q_identity()); }

/* Camera orbiting the head: (3 cos a, 0.3, 3 sin a), a = 2 pi frame / 240. */
static kdw_vec3 orbit_camera(int frame)
{
    float a = 2.0f * PI_F * (float)frame / (float)ORBIT_FRAMES;
    return v3(3.0f * cosf(a), 0.3f, 3.0f * sinf(a));
}

static void destroy_engine_cleanup(void *engine) { (void)kdw_engine_destroy((kdw_engine *)engine); }

/* Creates an engine that is destroyed after the current test (unless engine_free() is called first). */
static kdw_engine *engine_new(const kdw_engine_def *def)
{
    kdw_engine *engine = NULL;
    kdw_status status = kdw_engine_create(def, &engine);
    if (status != KDW_STATUS_OK || engine == NULL) {
        printf("    kdw_engine_create failed: %s (%s)\n", kdw_status_str(status), harness_last_error());
        return NULL;
    }
    harness_defer(destroy_engine_cleanup, engine);
    return engine;
}

static kdw_engine *engine_new_default(void)
{
    kdw_engine_def def = kdw_engine_def_default();
    return engine_new(&def);
}

static kdw_status engine_free(kdw_engine *engine)
{
    harness_cancel(engine);
    return kdw_engine_destroy(engine);
}

/* Three view-reference chains (ahoge, side lock, tail) and, optionally, two view shapes on the ahoge. */
typedef struct scene {
    kdw_engine *engine;
    kdw_chain_id chains[3];
    kdw_view_shape_id left, right;
} scene;

static const chain_spec *const g_scene_specs[3] = {&g_ahoge, &g_side_lock, &g_tail};

static int scene_build(scene *s, int with_view_shapes)
{
    memset(s, 0, sizeof *s);
    s->engine = engine_new_default();
    ENSURE(s->engine != NULL);
    kdw_chain_def def = kdw_chain_def_default();
    for (int i = 0; i < 3; ++i) {
        ENSURE_OK(kdw_chain_create(s->engine, &def, g_scene_specs[i]->joints, g_scene_specs[i]->n, &s->chains[i]));
        ENSURE(s->chains[i] != 0);
    }
    if (with_view_shapes) {
        kdw_vec3 left = v3(-1.0f, 0.0f, 0.0f);
        kdw_vec3 right = v3(1.0f, 0.0f, 0.0f);
        ENSURE_OK(kdw_chain_add_view_shape(s->engine, s->chains[0], &left, g_ahoge_left.joints, g_ahoge_left.n,
                                           1.0f, &s->left));
        ENSURE_OK(kdw_chain_add_view_shape(s->engine, s->chains[0], &right, g_ahoge_right.joints,
                                           g_ahoge_right.n, 2.0f, &s->right));
        ENSURE(s->left != 0 && s->right != 0 && s->left != s->right);
    }
    return 0;
}

static int step_orbit(kdw_engine *engine, int frame, const kdw_transform *head)
{
    kdw_vec3 camera = orbit_camera(frame);
    ENSURE_OK(kdw_engine_step(engine, FRAME_DT, &camera, head));
    return 0;
}

static int step_frames(kdw_engine *engine, int first, int count)
{
    kdw_transform head = head_at_rest();
    for (int frame = first; frame < first + count; ++frame) {
        ENSURE(step_orbit(engine, frame, &head) == 0);
    }
    return 0;
}

static uint64_t hash_of(const kdw_engine *engine)
{
    uint64_t hash = 0;
    if (kdw_engine_state_hash(engine, &hash) != KDW_STATUS_OK) {
        printf("    kdw_engine_state_hash failed: %s\n", harness_last_error());
        return 0;
    }
    return hash;
}

/* ---- pose checks ------------------------------------------------------------------------------------------ */

/* Where the last check_pose failure happened (for the report). */
static int g_pose_chain = -1;
static int g_pose_joint = -1;

/*
 * Reads everything back through the batched calls and checks, for chain i (creation order) with base
 * shape specs[i] and world anchor anchors[i] (rotation need not be unit):
 * finite; root joint at anchor * base joint 0; segment lengths of the base within LENGTH_TOL relative;
 * world and local rotations unit within UNIT_TOL; skinning-ready rotations (each joint's bone axis,
 * taken from the base shape, points at the next joint); local rotations compose to the world ones
 * (anchor * local_0 * local_1 ...); and kdw_chain_read_world equal to the batched read.
 */
static int check_pose(const kdw_engine *engine, const chain_spec *const specs[], const kdw_transform anchors[],
                      uint32_t chain_count)
{
    g_pose_chain = -1;
    g_pose_joint = -1;
    uint32_t count = SENTINEL_U32;
    ENSURE_OK(kdw_engine_chain_count(engine, &count));
    ENSURE(count == chain_count && count <= MAX_CHAINS);
    uint32_t expected_joints = 0;
    for (uint32_t i = 0; i < chain_count; ++i) {
        expected_joints += specs[i]->n;
    }
    uint32_t joints = SENTINEL_U32;
    ENSURE_OK(kdw_engine_joint_count(engine, &joints));
    ENSURE(joints == expected_joints && joints <= MAX_TOTAL);

    kdw_transform world[MAX_TOTAL];
    kdw_quat local[MAX_TOTAL];
    kdw_chain_id ids[MAX_CHAINS];
    uint32_t written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_read_world(engine, world, joints, &written));
    ENSURE(written == joints);
    written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_read_local_rotations(engine, local, joints, &written));
    ENSURE(written == joints);
    written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_chain_ids(engine, ids, MAX_CHAINS, &written));
    ENSURE(written == chain_count);

    uint32_t offset = 0;
    for (uint32_t i = 0; i < chain_count; ++i) {
        g_pose_chain = (int)i;
        g_pose_joint = -1;
        const chain_spec *s = specs[i];
        const kdw_transform *w = world + offset;
        const kdw_quat *l = local + offset;
        kdw_quat anchor_rotation = q_normalize(anchors[i].rotation);

        uint32_t n = SENTINEL_U32;
        ENSURE_OK(kdw_chain_joint_count(engine, ids[i], &n));
        ENSURE(n == s->n);
        kdw_transform own[MAX_JOINTS];
        written = SENTINEL_U32;
        ENSURE_OK(kdw_chain_read_world(engine, ids[i], own, MAX_JOINTS, &written));
        ENSURE(written == n);
        ENSURE(memcmp(own, w, n * sizeof *w) == 0);

        for (uint32_t j = 0; j < n; ++j) {
            g_pose_joint = (int)j;
            ENSURE(v_is_finite(w[j].position) && q_is_finite(w[j].rotation) && q_is_finite(l[j]));
            ENSURE_SMALL(q_norm(w[j].rotation) - 1.0, UNIT_TOL);
            ENSURE_SMALL(q_norm(l[j]) - 1.0, UNIT_TOL);
        }

        g_pose_joint = 0;
        kdw_vec3 expected_root = v_add(anchors[i].position, q_rotate(anchor_rotation, s->joints[0].position));
        ENSURE_SMALL(v_dist(w[0].position, expected_root), ROOT_TOL_REL * (1.0 + v_length(expected_root)));

        for (uint32_t j = 0; j + 1 < n; ++j) {
            g_pose_joint = (int)j;
            kdw_vec3 base_segment = v_sub(s->joints[j + 1].position, s->joints[j].position);
            double rest = v_length(base_segment);
            kdw_vec3 segment = v_sub(w[j + 1].position, w[j].position);
            ENSURE_SMALL(v_length(segment) / rest - 1.0, LENGTH_TOL);
            /* Skinning-ready: the bone axis (base segment in the base joint's frame) points at the next joint,
             * up to the direction error float positions allow (a few ulps of |position| over the length). */
            kdw_vec3 axis = v_normalize(q_rotate(q_conjugate(q_normalize(s->joints[j].rotation)), base_segment));
            double position_ulp = 1.2e-7 * (1.0 + v_length(w[j].position));
            ENSURE_SMALL(v_dist(q_rotate(w[j].rotation, axis), v_normalize(segment)), 1e-5 + 4.0 * position_ulp / rest);
        }

        kdw_quat parent = anchor_rotation;
        for (uint32_t j = 0; j < n; ++j) {
            g_pose_joint = (int)j;
            ENSURE_SMALL(q_distance(q_mul(parent, l[j]), w[j].rotation), 1e-5);
            parent = w[j].rotation;
        }
        offset += n;
    }
    g_pose_chain = -1;
    g_pose_joint = -1;
    return 0;
}

#define ENSURE_POSE(engine, specs, anchors, count, frame)                                                   \
    do {                                                                                                   \
        if (check_pose((engine), (specs), (anchors), (count)) != 0) {                                      \
            printf("    (pose check at frame %d, chain %d, joint %d)\n", (int)(frame), g_pose_chain,       \
                   g_pose_joint);                                                                          \
            return 1;                                                                                      \
        }                                                                                                  \
    } while (0)

/* ---- rejected calls ----------------------------------------------------------------------------------- */

static char g_primed_message[256];

/* Makes the thread's last error message a known one, so that the next failure can be seen to replace it. */
static int prime_error_message(void)
{
    kdw_engine_def def = kdw_engine_def_default();
    def.struct_size = 0xC0FFEEu;
    kdw_engine *engine = NULL;
    kdw_status status = kdw_engine_create(&def, &engine);
    if (engine != NULL) {
        (void)kdw_engine_destroy(engine);
    }
    ENSURE(status == KDW_STATUS_STRUCT_SIZE_MISMATCH && engine == NULL);
    uint32_t length = 0;
    ENSURE_OK(kdw_last_error_message(g_primed_message, (uint32_t)sizeof g_primed_message, &length));
    ENSURE(length > 0 && strlen(g_primed_message) == length);
    return 0;
}

/* The last error message is non-empty, consistent with its length, and not the primed one. */
static int error_message_is_fresh(void)
{
    char message[512];
    uint32_t length = SENTINEL_U32;
    ENSURE_OK(kdw_last_error_message(message, (uint32_t)sizeof message, &length));
    ENSURE(length > 0 && length == strlen(message));
    if (strcmp(message, g_primed_message) == 0) {
        printf("    the failing call did not set its own error message (still \"%s\")\n", message);
        return 1;
    }
    return 0;
}

/*
 * `call` must fail with `expected`, set a fresh non-empty error message, and leave `engine` bit-identical
 * (kdw_engine_state_hash unchanged). `engine` is the engine the call targets, or a witness engine when the
 * call targets none (NULL engine, kdw_engine_create).
 */
#define ENSURE_REJECTED(engine, call, expected)                                                             \
    do {                                                                                                   \
        uint64_t rejected_before_ = 0, rejected_after_ = 0;                                                \
        ENSURE_OK(kdw_engine_state_hash((engine), &rejected_before_));                                     \
        ENSURE(prime_error_message() == 0);                                                                \
        ENSURE_STATUS(call, expected);                                                                     \
        if (error_message_is_fresh() != 0) {                                                               \
            printf("%s:%d: after %s\n", __FILE__, __LINE__, #call);                                        \
            return 1;                                                                                      \
        }                                                                                                  \
        ENSURE_OK(kdw_engine_state_hash((engine), &rejected_after_));                                      \
        if (rejected_before_ != rejected_after_) {                                                         \
            printf("%s:%d: rejected call changed the engine state: %s\n", __FILE__, __LINE__, #call);       \
            return 1;                                                                                      \
        }                                                                                                  \
    } while (0)

/* ================================================================================================== */
/* Tests                                                                                              */
/* ================================================================================================== */

/* Must run first: no call has failed on this thread yet. */
static int test_last_error_initially_empty(void)
{
    uint32_t length = SENTINEL_U32;
    ENSURE_OK(kdw_last_error_message(NULL, 0, &length));
    ENSURE(length == 0);
    char buffer[8];
    memset(buffer, 'x', sizeof buffer);
    length = SENTINEL_U32;
    ENSURE_OK(kdw_last_error_message(buffer, (uint32_t)sizeof buffer, &length));
    ENSURE(length == 0 && buffer[0] == '\0');
    return 0;
}

static int test_layout(void)
{
    kdw_engine_def engine_def = kdw_engine_def_default();
    kdw_chain_def chain_def = kdw_chain_def_default();
    ENSURE(engine_def.struct_size == sizeof(kdw_engine_def));
    ENSURE(chain_def.struct_size == sizeof(kdw_chain_def));

    kdw_engine *engine = engine_new(&engine_def);
    ENSURE(engine != NULL);
    kdw_engine_stats stats;
    memset(&stats, SENTINEL_BYTE, sizeof stats);
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.struct_size == sizeof(kdw_engine_stats));
    ENSURE(stats.collider_count == 0 && stats.contact_pairs_tested == 0);
    ENSURE(stats.chain_count == 0 && stats.joint_count == 0 && stats.substeps_total == 0);
    ENSURE(stats.simulated_time == 0.0 && stats.time_dropped == 0.0);
    ENSURE(stats.lane_chains == 0 && stats.reserved == 0);
    ENSURE_OK(engine_free(engine));
    return 0;
}

static int test_version(void)
{
    ENSURE(kdw_abi_version() == KDW_ABI_VERSION);
    const char *version = kdw_version_string();
    ENSURE(version != NULL && version[0] != '\0');
    ENSURE(strchr(version, '.') != NULL);

    const kdw_status known[] = {KDW_STATUS_OK,
                                KDW_STATUS_NULL_POINTER,
                                KDW_STATUS_INVALID_ID,
                                KDW_STATUS_INVALID_ARGUMENT,
                                KDW_STATUS_BUFFER_TOO_SMALL,
                                KDW_STATUS_CAPACITY_EXCEEDED,
                                KDW_STATUS_STRUCT_SIZE_MISMATCH,
                                KDW_STATUS_ABI_MISMATCH,
                                KDW_STATUS_PANIC};
    const size_t count = sizeof known / sizeof known[0];
    const char *unknown = kdw_status_str(12345);
    ENSURE(unknown != NULL && unknown[0] != '\0');
    for (size_t i = 0; i < count; ++i) {
        const char *text = kdw_status_str(known[i]);
        ENSURE(text != NULL && text[0] != '\0');
        ENSURE(strcmp(text, unknown) != 0);
        for (size_t j = 0; j < i; ++j) {
            ENSURE(strcmp(text, kdw_status_str(known[j])) != 0);
        }
    }
    const kdw_status unknowns[] = {1, -8, -99, -101, 12345, INT32_MIN, INT32_MAX};
    for (size_t i = 0; i < sizeof unknowns / sizeof unknowns[0]; ++i) {
        const char *text = kdw_status_str(unknowns[i]);
        ENSURE(text != NULL && strcmp(text, unknown) == 0);
    }
    return 0;
}

static int test_defaults_and_settings(void)
{
    kdw_engine_def def = kdw_engine_def_default();
    ENSURE(def.gravity.x == 0.0f && def.gravity.y == -9.81f && def.gravity.z == 0.0f);
    ENSURE(def.substep_rate == 240.0f && def.max_substeps == 16 && def.iterations == 2);
    ENSURE(def.time_scale == 1.0f && def.teleport_distance == 1.0f);
    ENSURE_SMALL(def.teleport_angle - 0.5f * PI_F, 1e-6);
    ENSURE(def.teleport_mode == KDW_TELEPORT_CARRY_SHAPE && def.scale == 1.0f);

    kdw_chain_def chain = kdw_chain_def_default();
    ENSURE(chain.stiffness == 0.5f && chain.damping == 1.0f && chain.momentum_suppression == 1.0f);
    ENSURE(chain.mass == 1.0f && chain.radius == 0.02f && chain.gravity_scale == 1.0f);
    ENSURE(chain.anchor == KDW_ANCHOR_VIEW_REFERENCE);
    ENSURE(chain.collision_mask == 0xFFFFFFFFu && chain.friction == 0.3f);

    kdw_collider_def collider = kdw_collider_def_default();
    ENSURE(collider.struct_size == sizeof(kdw_collider_def));
    ENSURE(collider.shape == KDW_COLLIDER_SPHERE && collider.radius == 0.1f && collider.half_height == 0.0f);
    ENSURE(collider.layers == 1u);
    ENSURE(v_length(collider.transform.position) == 0.0 && q_distance(collider.transform.rotation, q_identity()) == 0.0);

    kdw_engine *engine = engine_new(&def);
    ENSURE(engine != NULL);
    kdw_engine_def got;
    memset(&got, SENTINEL_BYTE, sizeof got);
    ENSURE_OK(kdw_engine_get_def(engine, &got));
    ENSURE(memcmp(&got, &def, sizeof def) == 0);

    kdw_engine_def changed = def;
    changed.iterations = 4;
    changed.substep_rate = 120.0f;
    changed.gravity = v3(0.0f, -1.62f, 0.0f);
    changed.teleport_mode = KDW_TELEPORT_RESET;
    changed.scale = 0.5f;
    ENSURE_OK(kdw_engine_set_def(engine, &changed));
    ENSURE_OK(kdw_engine_get_def(engine, &got));
    ENSURE(memcmp(&got, &changed, sizeof got) == 0);

    kdw_vec3 gravity = v3(1.0f, -3.0f, 0.5f);
    ENSURE_OK(kdw_engine_set_gravity(engine, &gravity));
    ENSURE_OK(kdw_engine_get_def(engine, &got));
    ENSURE(got.gravity.x == 1.0f && got.gravity.y == -3.0f && got.gravity.z == 0.5f);
    ENSURE(got.iterations == 4 && got.substep_rate == 120.0f);

    kdw_chain_id id = 0;
    ENSURE_OK(kdw_chain_create(engine, &chain, g_tail.joints, g_tail.n, &id));
    kdw_chain_def chain_got;
    memset(&chain_got, SENTINEL_BYTE, sizeof chain_got);
    ENSURE_OK(kdw_chain_get_def(engine, id, &chain_got));
    ENSURE(memcmp(&chain_got, &chain, sizeof chain) == 0);
    kdw_chain_def stiffer = chain;
    stiffer.stiffness = 0.9f;
    stiffer.damping = 3.0f;
    stiffer.gravity_scale = -0.5f;
    stiffer.anchor = KDW_ANCHOR_OWN;
    stiffer.collision_mask = 0x5u;
    stiffer.friction = 2.5f;
    ENSURE_OK(kdw_chain_set_def(engine, id, &stiffer));
    ENSURE_OK(kdw_chain_get_def(engine, id, &chain_got));
    ENSURE(memcmp(&chain_got, &stiffer, sizeof chain_got) == 0);
    return 0;
}

/* The full life cycle through the C ABI with three chains and two view shapes. */
static int test_life_cycle(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    kdw_engine *engine = s.engine;
    ENSURE(s.chains[0] != s.chains[1] && s.chains[1] != s.chains[2] && s.chains[0] != s.chains[2]);
    ENSURE(s.left != s.chains[0] && s.left != s.chains[1] && s.left != s.chains[2]);

    uint32_t count = SENTINEL_U32;
    ENSURE_OK(kdw_chain_view_shape_count(engine, s.chains[0], &count));
    ENSURE(count == 2);
    ENSURE_OK(kdw_chain_view_shape_count(engine, s.chains[1], &count));
    ENSURE(count == 0);
    ENSURE_OK(kdw_engine_chain_count(engine, &count));
    ENSURE(count == 3);
    ENSURE_OK(kdw_engine_joint_count(engine, &count));
    ENSURE(count == 8 + 5 + 6);
    for (int i = 0; i < 3; ++i) {
        uint32_t valid = SENTINEL_U32;
        ENSURE_OK(kdw_chain_is_valid(engine, s.chains[i], &valid));
        ENSURE(valid == 1);
    }

    const kdw_transform head = head_at_rest();
    const kdw_transform anchors[3] = {head, head, head};
    for (int frame = 0; frame < ORBIT_FRAMES; ++frame) {
        ENSURE(step_orbit(engine, frame, &head) == 0);
        ENSURE_POSE(engine, g_scene_specs, anchors, 3, frame);

        if (frame == 0 || frame == ORBIT_FRAMES / 2) {
            /* Camera on +x (frame 0) or -x (frame 120): the rest shape is (mostly) the matching view shape. */
            kdw_transform rest[MAX_JOINTS];
            uint32_t written = SENTINEL_U32;
            ENSURE_OK(kdw_chain_read_rest_shape(engine, s.chains[0], rest, MAX_JOINTS, &written));
            ENSURE(written == g_ahoge.n);
            ENSURE_SMALL(v_dist(rest[0].position, g_ahoge.joints[0].position), 1e-6);
            for (uint32_t j = 0; j + 1 < written; ++j) {
                ENSURE_SMALL(v_dist(rest[j + 1].position, rest[j].position) / 0.05 - 1.0, 1e-5);
            }
            float tip_x = rest[written - 1].position.x;
            if (frame == 0) {
                ENSURE(tip_x > 0.1f); /* the +x shape's tip is at x = +0.189 */
            } else {
                ENSURE(tip_x < -0.1f); /* the -x shape's tip is at x = -0.189 */
            }
        }
    }

    kdw_engine_stats stats;
    memset(&stats, SENTINEL_BYTE, sizeof stats);
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.struct_size == sizeof stats);
    ENSURE(stats.chain_count == 3);
    ENSURE(stats.joint_count == 19);
    ENSURE(stats.substeps_last_step == 4);
    ENSURE(stats.substeps_total == (uint64_t)ORBIT_FRAMES * 4u);
    ENSURE(stats.chains_asleep <= stats.chain_count);
    ENSURE(stats.collider_count == 0 && stats.contact_pairs_tested == 0); /* no colliders, no contact cost */
    ENSURE(stats.solver_fallbacks == 0);
    ENSURE(stats.lane_chains == 0); /* three different joint counts: no lane group, all on the scalar solver */
    ENSURE(stats.time_dropped == 0.0);
    ENSURE_SMALL(stats.simulated_time - ORBIT_FRAMES * (double)FRAME_DT, 1e-9);

    kdw_chain_id ids[MAX_CHAINS];
    uint32_t written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_chain_ids(engine, ids, MAX_CHAINS, &written));
    ENSURE(written == 3);
    ENSURE(ids[0] == s.chains[0] && ids[1] == s.chains[1] && ids[2] == s.chains[2]);
    ENSURE_OK(kdw_engine_get_chain_ids(engine, ids, 3, &written));
    ENSURE(written == 3);

    for (int i = 0; i < 3; ++i) {
        float energy = -1.0f;
        ENSURE_OK(kdw_chain_kinetic_energy(engine, s.chains[i], &energy));
        ENSURE(isfinite(energy) && energy >= 0.0f);
        kdw_chain_def def;
        ENSURE_OK(kdw_chain_get_def(engine, s.chains[i], &def));
        kdw_chain_def expected = kdw_chain_def_default();
        ENSURE(memcmp(&def, &expected, sizeof def) == 0);
    }

    /* Remove one view shape: the chain keeps the other; the removed id goes stale. */
    uint32_t shape_valid = 0;
    ENSURE_OK(kdw_view_shape_is_valid(engine, s.right, &shape_valid));
    ENSURE(shape_valid == 1);
    /* The last blend's weights: base + two view shapes, non-negative, summing to 1. */
    float weights[3] = {-1.0f, -1.0f, -1.0f};
    uint32_t weight_count = 0;
    ENSURE_REJECTED(engine, kdw_chain_read_weights(engine, s.chains[0], weights, 2, &weight_count),
                    KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(weights[0] == -1.0f && weight_count == 0);
    ENSURE_OK(kdw_chain_read_weights(engine, s.chains[0], weights, 3, &weight_count));
    ENSURE(weight_count == 3 && weights[0] >= 0.0f && weights[1] >= 0.0f && weights[2] >= 0.0f);
    ENSURE_SMALL(weights[0] + weights[1] + weights[2] - 1.0f, 1e-6f);
    uint64_t before = hash_of(engine);
    ENSURE_OK(kdw_view_shape_remove(engine, s.right));
    ENSURE_OK(kdw_view_shape_is_valid(engine, s.right, &shape_valid));
    ENSURE(shape_valid == 0);
    ENSURE_OK(kdw_view_shape_is_valid(engine, s.chains[0], &shape_valid)); /* a chain id is no view shape id */
    ENSURE(shape_valid == 0);
    ENSURE(hash_of(engine) != before);
    ENSURE_OK(kdw_chain_view_shape_count(engine, s.chains[0], &count));
    ENSURE(count == 1);
    ENSURE_REJECTED(engine, kdw_view_shape_remove(engine, s.right), KDW_STATUS_INVALID_ID);
    ENSURE_REJECTED(engine, kdw_view_shape_set_influence(engine, s.right, 1.0f), KDW_STATUS_INVALID_ID);
    ENSURE_OK(kdw_view_shape_set_influence(engine, s.left, 3.0f));

    /* Destroy the first chain: the others keep their order and their pose. */
    kdw_transform world_before[MAX_TOTAL];
    ENSURE_OK(kdw_engine_read_world(engine, world_before, MAX_TOTAL, &written));
    ENSURE(written == 19);
    ENSURE_OK(kdw_chain_destroy(engine, s.chains[0]));
    ENSURE_OK(kdw_engine_chain_count(engine, &count));
    ENSURE(count == 2);
    ENSURE_OK(kdw_engine_joint_count(engine, &count));
    ENSURE(count == 11);
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.chain_count == 2 && stats.joint_count == 11);
    uint32_t valid = SENTINEL_U32;
    ENSURE_OK(kdw_chain_is_valid(engine, s.chains[0], &valid));
    ENSURE(valid == 0);
    ENSURE_REJECTED(engine, kdw_view_shape_remove(engine, s.left), KDW_STATUS_INVALID_ID);
    ENSURE_OK(kdw_engine_get_chain_ids(engine, ids, MAX_CHAINS, &written));
    ENSURE(written == 2 && ids[0] == s.chains[1] && ids[1] == s.chains[2]);
    kdw_transform world_after[MAX_TOTAL];
    ENSURE_OK(kdw_engine_read_world(engine, world_after, MAX_TOTAL, &written));
    ENSURE(written == 11);
    ENSURE(memcmp(world_after, world_before + 8, 11 * sizeof(kdw_transform)) == 0);

    /* A new chain (reusing the freed slot) comes last in the batched order; the old id stays stale. */
    kdw_chain_def def = kdw_chain_def_default();
    kdw_chain_id again = 0;
    ENSURE_OK(kdw_chain_create(engine, &def, g_ahoge.joints, g_ahoge.n, &again));
    ENSURE(again != 0 && again != s.chains[0]);
    ENSURE_OK(kdw_chain_is_valid(engine, s.chains[0], &valid));
    ENSURE(valid == 0);
    ENSURE_OK(kdw_engine_get_chain_ids(engine, ids, MAX_CHAINS, &written));
    ENSURE(written == 3 && ids[0] == s.chains[1] && ids[1] == s.chains[2] && ids[2] == again);
    const chain_spec *const reordered[3] = {&g_side_lock, &g_tail, &g_ahoge};
    for (int frame = 0; frame < 30; ++frame) {
        ENSURE(step_orbit(engine, frame, &head) == 0);
        ENSURE_POSE(engine, reordered, anchors, 3, frame);
    }

    /* Resets are accepted and change the state (chains are re-placed at the next step). */
    before = hash_of(engine);
    ENSURE_OK(kdw_engine_reset(engine));
    ENSURE(hash_of(engine) != before);
    ENSURE(step_frames(engine, 0, 1) == 0);
    ENSURE_OK(kdw_chain_reset(engine, again));
    ENSURE(step_frames(engine, 1, 1) == 0);
    ENSURE_POSE(engine, reordered, anchors, 3, 1);

    ENSURE_OK(kdw_chain_destroy(engine, s.chains[1]));
    ENSURE_OK(kdw_chain_destroy(engine, s.chains[2]));
    ENSURE_OK(kdw_chain_destroy(engine, again));
    ENSURE_OK(kdw_engine_chain_count(engine, &count));
    ENSURE(count == 0);
    ENSURE_OK(engine_free(engine));
    return 0;
}

/* The simulated chain follows the view: a stiff ahoge leans to the side the camera sees it from. (With the
 * default stiffness 0.5 this 0.35 m standing chain buckles under gravity, so this test stiffens it.) */
static int test_view_dependence(void)
{
    kdw_engine *engine = engine_new_default();
    ENSURE(engine != NULL);
    kdw_chain_def def = kdw_chain_def_default();
    def.stiffness = 0.9f;
    kdw_chain_id id = 0;
    kdw_view_shape_id left = 0, right = 0;
    const kdw_vec3 from_left = v3(-1.0f, 0.0f, 0.0f), from_right = v3(1.0f, 0.0f, 0.0f);
    ENSURE_OK(kdw_chain_create(engine, &def, g_ahoge.joints, g_ahoge.n, &id));
    ENSURE_OK(kdw_chain_add_view_shape(engine, id, &from_left, g_ahoge_left.joints, 8, 1.0f, &left));
    ENSURE_OK(kdw_chain_add_view_shape(engine, id, &from_right, g_ahoge_right.joints, 8, 2.0f, &right));
    const kdw_transform head = head_at_rest();
    for (int frame = 0; frame < ORBIT_FRAMES; ++frame) {
        ENSURE(step_orbit(engine, frame, &head) == 0);
        kdw_transform world[MAX_JOINTS];
        uint32_t written = 0;
        ENSURE_OK(kdw_chain_read_world(engine, id, world, MAX_JOINTS, &written));
        ENSURE(written == 8);
        kdw_vec3 tip = v_sub(world[7].position, head.position);
        ENSURE(tip.y > 0.3f); /* stands up: the root is at 0.1, the straight tip at 0.45 */
        ENSURE_SMALL(tip.z, 1e-4); /* every shape lies in the xy plane */
        if (frame == 0 || frame == ORBIT_FRAMES - 1) {
            ENSURE(tip.x > 0.1f); /* seen from +x */
        }
        if (frame == ORBIT_FRAMES / 2) {
            ENSURE(tip.x < -0.1f); /* seen from -x */
        }
    }
    return 0;
}

/* Chains anchored to their own bones, moved with kdw_engine_set_anchors. */
/* kdw_engine_step_and_read is set_anchors + step + read_local_rotations in one call: same results bit for
 * bit, and a rejected frame leaves the engine untouched. */
static int test_step_and_read(void)
{
    kdw_engine *single = engine_new_default();
    kdw_engine *separate = engine_new_default();
    ENSURE(single != NULL && separate != NULL);
    kdw_chain_def own = kdw_chain_def_default();
    own.anchor = KDW_ANCHOR_OWN;
    kdw_chain_def follow = kdw_chain_def_default();
    kdw_chain_id ids[2];
    for (int e = 0; e < 2; ++e) {
        kdw_engine *engine = e == 0 ? single : separate;
        ENSURE_OK(kdw_chain_create(engine, &own, g_side_lock.joints, g_side_lock.n, &ids[0]));
        ENSURE_OK(kdw_chain_create(engine, &follow, g_ahoge.joints, g_ahoge.n, &ids[1]));
    }
    const uint32_t joints = g_side_lock.n + g_ahoge.n;
    kdw_quat a[MAX_TOTAL], b[MAX_TOTAL];
    const kdw_transform head = head_at_rest();
    for (int frame = 0; frame < 90; ++frame) {
        float t = (float)frame / 60.0f;
        kdw_transform anchors[2] = {xf(v3(0.2f * sinf(6.0f * t), 1.0f, 0.0f), q_identity()), head};
        kdw_vec3 camera = v3(3.0f * cosf(t), 1.7f, 3.0f * sinf(t));
        uint32_t written = 0;
        ENSURE_OK(kdw_engine_step_and_read(single, 1.0f / 60.0f, &camera, &head, anchors, 2, a, MAX_TOTAL, &written));
        ENSURE(written == joints);
        ENSURE_OK(kdw_engine_set_anchors(separate, anchors, 2));
        ENSURE_OK(kdw_engine_step(separate, 1.0f / 60.0f, &camera, &head));
        ENSURE_OK(kdw_engine_read_local_rotations(separate, b, MAX_TOTAL, &written));
        ENSURE(memcmp(a, b, joints * sizeof a[0]) == 0);
    }
    ENSURE(hash_of(single) == hash_of(separate));

    /* Rejected frames: nothing changes, not even the anchors. */
    kdw_transform anchors[2] = {xf(v3(9.0f, 9.0f, 9.0f), q_identity()), head};
    kdw_vec3 camera = v3(0.0f, 1.7f, 3.0f);
    uint32_t written = 12345;
    ENSURE_REJECTED(single, kdw_engine_step_and_read(single, NAN, &camera, &head, anchors, 2, a, MAX_TOTAL, &written),
                    KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_REJECTED(single, kdw_engine_step_and_read(single, 0.1f, &camera, &head, anchors, 1, a, MAX_TOTAL, &written),
                    KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_REJECTED(single, kdw_engine_step_and_read(single, 0.1f, &camera, &head, anchors, 2, a, joints - 1, &written),
                    KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE_REJECTED(single, kdw_engine_step_and_read(single, 0.1f, &camera, &head, anchors, 2, NULL, MAX_TOTAL, &written),
                    KDW_STATUS_NULL_POINTER);
    ENSURE(written == 12345);
    ENSURE(hash_of(single) == hash_of(separate));

    ENSURE_OK(engine_free(single));
    ENSURE_OK(engine_free(separate));
    return 0;
}

static int test_own_anchors(void)
{
    kdw_engine *engine = engine_new_default();
    ENSURE(engine != NULL);
    kdw_chain_def own = kdw_chain_def_default();
    own.anchor = KDW_ANCHOR_OWN;
    kdw_chain_def follow = kdw_chain_def_default();
    kdw_chain_id a = 0, b = 0, c = 0;
    ENSURE_OK(kdw_chain_create(engine, &own, g_side_lock.joints, g_side_lock.n, &a));
    ENSURE_OK(kdw_chain_create(engine, &follow, g_ahoge.joints, g_ahoge.n, &b));
    ENSURE_OK(kdw_chain_create(engine, &own, g_tail.joints, g_tail.n, &c));
    const chain_spec *const specs[3] = {&g_side_lock, &g_ahoge, &g_tail};

    const kdw_transform head = head_at_rest();
    kdw_transform anchors[4];
    for (int i = 0; i < 4; ++i) {
        anchors[i] = xf(v3(0.3f, 1.0f, 0.0f), q_identity());
    }
    /* count must equal the chain count (3) */
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 2), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 4), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 0), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, NULL, 3), KDW_STATUS_NULL_POINTER);
    /* every entry is validated, also those of view-reference chains */
    anchors[1].position.y = NAN;
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 3), KDW_STATUS_INVALID_ARGUMENT);
    anchors[1].position.y = 1.0f;
    anchors[2].rotation = q4(0.0f, 0.0f, 0.0f, 0.0f);
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 3), KDW_STATUS_INVALID_ARGUMENT);
    anchors[2].rotation = q4(0.0f, INFINITY, 0.0f, 1.0f);
    ENSURE_REJECTED(engine, kdw_engine_set_anchors(engine, anchors, 3), KDW_STATUS_INVALID_ARGUMENT);

    const int frames = 120;
    for (int frame = 0; frame < frames; ++frame) {
        float b_angle = 2.0f * PI_F * (float)frame / (float)frames;
        /* A hand moving on a circle and swinging; a hip bobbing and turning. Rotations deliberately not unit. */
        kdw_transform hand = xf(v3(0.3f * cosf(b_angle), 1.0f + 0.1f * sinf(2.0f * b_angle), 0.3f * sinf(b_angle)),
                                q_scale(q_axis_angle(0.0f, 0.0f, 1.0f, 0.6f * sinf(b_angle)), 2.0f));
        kdw_transform unused = xf(v3(5.0f, 5.0f, 5.0f), q_axis_angle(1.0f, 0.0f, 0.0f, 1.0f));
        kdw_transform hip = xf(v3(0.0f, 0.9f + 0.05f * sinf(3.0f * b_angle), -0.05f),
                               q_scale(q_axis_angle(0.0f, 1.0f, 0.0f, 0.5f * sinf(b_angle)), 0.5f));
        kdw_transform set[3] = {hand, unused, hip};
        ENSURE_OK(kdw_engine_set_anchors(engine, set, 3));
        ENSURE(step_orbit(engine, frame, &head) == 0);
        /* The view-reference chain ignores its entry and follows the head. */
        kdw_transform expected[3] = {hand, head, hip};
        ENSURE_POSE(engine, specs, expected, 3, frame);
    }

    /* An engine without chains takes zero anchors. */
    kdw_engine *empty = engine_new_default();
    ENSURE(empty != NULL);
    ENSURE_OK(kdw_engine_set_anchors(empty, NULL, 0));
    ENSURE_REJECTED(empty, kdw_engine_set_anchors(empty, anchors, 1), KDW_STATUS_INVALID_ARGUMENT);
    return 0;
}

static int test_engine_without_chains(void)
{
    kdw_engine *engine = engine_new_default();
    ENSURE(engine != NULL);
    uint32_t written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_read_world(engine, NULL, 0, &written));
    ENSURE(written == 0);
    written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_read_local_rotations(engine, NULL, 0, &written));
    ENSURE(written == 0);
    written = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_chain_ids(engine, NULL, 0, &written));
    ENSURE(written == 0);
    ENSURE(step_frames(engine, 0, 3) == 0);
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.chain_count == 0 && stats.joint_count == 0 && stats.substeps_total == 12);
    ENSURE_OK(kdw_engine_reset(engine));
    return 0;
}

/* Fixed substeps: the cap drops time and counts it; time_scale 0 pauses. */
static int test_substep_clock(void)
{
    kdw_engine *engine = engine_new_default();
    ENSURE(engine != NULL);
    kdw_chain_def def = kdw_chain_def_default();
    kdw_chain_id id = 0;
    ENSURE_OK(kdw_chain_create(engine, &def, g_tail.joints, g_tail.n, &id));
    kdw_transform head = head_at_rest();
    kdw_vec3 camera = v3(0.0f, 1.6f, 3.0f);

    ENSURE_OK(kdw_engine_step(engine, 1.0f, &camera, &head));
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.substeps_last_step == 16 && stats.substeps_total == 16);
    ENSURE_SMALL(stats.time_dropped - (1.0 - 16.0 / 240.0), 1e-9);
    ENSURE_SMALL(stats.simulated_time - 1.0, 1e-9);

    ENSURE_OK(kdw_engine_step(engine, FRAME_DT, &camera, &head));
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.substeps_last_step == 4 && stats.substeps_total == 20);

    kdw_engine_def paused = kdw_engine_def_default();
    paused.time_scale = 0.0f;
    ENSURE_OK(kdw_engine_set_def(engine, &paused));
    kdw_transform before[MAX_JOINTS], after[MAX_JOINTS];
    uint32_t written = 0;
    ENSURE_OK(kdw_chain_read_world(engine, id, before, MAX_JOINTS, &written));
    ENSURE_OK(kdw_engine_step(engine, FRAME_DT, &camera, &head));
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.substeps_last_step == 0 && stats.substeps_total == 20);
    ENSURE_OK(kdw_chain_read_world(engine, id, after, MAX_JOINTS, &written));
    ENSURE(memcmp(before, after, written * sizeof before[0]) == 0);

    kdw_engine_def slow = kdw_engine_def_default();
    slow.substep_rate = 60.0f;
    ENSURE_OK(kdw_engine_set_def(engine, &slow));
    ENSURE_OK(kdw_engine_step(engine, FRAME_DT, &camera, &head));
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.substeps_last_step == 1 && stats.substeps_total == 21);
    return 0;
}

/* Same calls, same results: state hash and read-back bit-identical across two engines. */
static int determinism_case(int with_view_shapes)
{
    scene a, b;
    ENSURE(scene_build(&a, with_view_shapes) == 0);
    ENSURE(scene_build(&b, with_view_shapes) == 0);
    ENSURE(step_frames(a.engine, 0, 120) == 0);
    ENSURE(step_frames(b.engine, 0, 120) == 0);

    kdw_transform world_a[MAX_TOTAL], world_b[MAX_TOTAL];
    kdw_quat local_a[MAX_TOTAL], local_b[MAX_TOTAL];
    uint32_t na = 0, nb = 0;
    ENSURE_OK(kdw_engine_read_world(a.engine, world_a, MAX_TOTAL, &na));
    ENSURE_OK(kdw_engine_read_world(b.engine, world_b, MAX_TOTAL, &nb));
    ENSURE(na == 19 && nb == 19);
    ENSURE(memcmp(world_a, world_b, na * sizeof world_a[0]) == 0);
    ENSURE_OK(kdw_engine_read_local_rotations(a.engine, local_a, MAX_TOTAL, &na));
    ENSURE_OK(kdw_engine_read_local_rotations(b.engine, local_b, MAX_TOTAL, &nb));
    ENSURE(memcmp(local_a, local_b, na * sizeof local_a[0]) == 0);

    /* Ids differ between the engines (they carry the engine's salt); the hash must not depend on them. */
    ENSURE(a.chains[0] != b.chains[0]);
    ENSURE(hash_of(a.engine) == hash_of(b.engine));

    /* One more step on one engine only: the hashes part; the same step on the other joins them again. */
    ENSURE(step_frames(a.engine, 120, 1) == 0);
    ENSURE(hash_of(a.engine) != hash_of(b.engine));
    ENSURE_OK(kdw_engine_read_world(a.engine, world_a, MAX_TOTAL, &na));
    ENSURE(memcmp(world_a, world_b, na * sizeof world_a[0]) != 0);
    ENSURE(step_frames(b.engine, 120, 1) == 0);
    ENSURE(hash_of(a.engine) == hash_of(b.engine));
    ENSURE_OK(kdw_engine_read_world(b.engine, world_b, MAX_TOTAL, &nb));
    ENSURE(memcmp(world_a, world_b, na * sizeof world_a[0]) == 0);
    return 0;
}

static int test_determinism_without_view_shapes(void) { return determinism_case(0); }
static int test_determinism_with_view_shapes(void) { return determinism_case(1); }

/* ---- solver selection ------------------------------------------------------------------------------------- */

#define SOLVER_CHAINS 4
#define SOLVER_JOINTS 8
#define SOLVER_TOTAL (SOLVER_CHAINS * SOLVER_JOINTS)
#define SOLVER_FRAMES 120
/* Scalar vs lane solver after SOLVER_FRAMES frames, m: they implement the same operations grouped
 * differently, so they differ by float rounding only (measured 3.0e-8 m on these 0.28 m chains). */
#define SOLVER_AGREEMENT_TOL 1e-6

/* Four chains of 8 joints hanging from the head side by side (different stiffness) on a fresh engine, no
 * colliders: one lane group of 4 on the lane solvers. Hanging, so that their motion is not chaotic and the
 * solvers' rounding differences stay rounding-sized. */
static kdw_vec3 solver_root(int chain) { return v3(-0.06f + 0.04f * (float)chain, 0.0f, 0.08f); }

static int solver_scene(kdw_engine **out, uint32_t solver)
{
    kdw_engine *engine = engine_new_default();
    ENSURE(engine != NULL);
    uint32_t got = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_solver(engine, &got));
    ENSURE(got == KDW_SOLVER_LANES); /* the default */
    ENSURE_OK(kdw_engine_set_solver(engine, solver));
    got = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_solver(engine, &got));
    ENSURE(got == solver);
    for (int c = 0; c < SOLVER_CHAINS; ++c) {
        chain_spec spec;
        make_straight(&spec, SOLVER_JOINTS, solver_root(c), v3(0.0f, -1.0f, 0.0f), 0.04f);
        kdw_chain_def def = kdw_chain_def_default();
        def.stiffness = 0.3f + 0.2f * (float)c;
        kdw_chain_id id = 0;
        ENSURE_OK(kdw_chain_create(engine, &def, spec.joints, spec.n, &id));
    }
    *out = engine;
    return 0;
}

/* kdw_engine_set_solver / kdw_engine_get_solver round trips, kdw_engine_stats.lane_chains counts the chains the
 * lane solver stepped (all four on both lane solvers, none on the scalar one), the two lane solvers give the
 * same bits (the kernel copy does not change a chain's result), the scalar solver agrees up to rounding, and the
 * solver is part of the state hash. kdw_simd_path names the kernel; kdw_portable_determinism says the build has
 * no `portable-determinism`. */
static int test_solver_selection(void)
{
    const char *path = kdw_simd_path();
    ENSURE(path != NULL);
    ENSURE(strcmp(path, "avx512") == 0 || strcmp(path, "avx2") == 0 || strcmp(path, "sse2") == 0 ||
           strcmp(path, "neon") == 0 || strcmp(path, "scalar") == 0);
    ENSURE(kdw_simd_path() == path); /* static */
    ENSURE(kdw_portable_determinism() == 0); /* the harness links the default build (tests/common/native.rs) */

    const uint32_t solvers[3] = {KDW_SOLVER_LANES, KDW_SOLVER_LANES_PORTABLE, KDW_SOLVER_SCALAR};
    const uint32_t expected_lane_chains[3] = {SOLVER_CHAINS, SOLVER_CHAINS, 0};
    kdw_engine *engines[3];
    uint64_t hashes[3];
    for (int i = 0; i < 3; ++i) {
        ENSURE(solver_scene(&engines[i], solvers[i]) == 0);
        hashes[i] = hash_of(engines[i]);
    }
    /* Before any step the engines differ only in their solver: so do their hashes. */
    ENSURE(hashes[0] != hashes[1] && hashes[0] != hashes[2] && hashes[1] != hashes[2]);
    ENSURE_OK(kdw_engine_set_solver(engines[1], KDW_SOLVER_LANES));
    ENSURE(hash_of(engines[1]) == hashes[0]);
    ENSURE_OK(kdw_engine_set_solver(engines[1], KDW_SOLVER_LANES_PORTABLE));
    ENSURE(hash_of(engines[1]) == hashes[1]);

    /* An unknown solver is rejected and changes nothing. */
    ENSURE_REJECTED(engines[2], kdw_engine_set_solver(engines[2], 3), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(strstr(harness_last_error(), "solver") != NULL);
    ENSURE_REJECTED(engines[2], kdw_engine_set_solver(engines[2], UINT32_MAX), KDW_STATUS_INVALID_ARGUMENT);
    uint32_t got = SENTINEL_U32;
    ENSURE_OK(kdw_engine_get_solver(engines[2], &got));
    ENSURE(got == KDW_SOLVER_SCALAR);

    /* The head sways gently sideways (2 cm at 0.5 Hz), so the chains swing and never fall asleep. */
    kdw_transform head = head_at_rest();
    for (int frame = 0; frame < SOLVER_FRAMES; ++frame) {
        head.position.x = 0.02f * sinf(0.05f * (float)frame);
        for (int i = 0; i < 3; ++i) {
            ENSURE(step_orbit(engines[i], frame, &head) == 0);
            kdw_engine_stats stats;
            ENSURE_OK(kdw_engine_get_stats(engines[i], &stats));
            ENSURE(stats.chain_count == SOLVER_CHAINS && stats.chains_asleep == 0);
            ENSURE(stats.lane_chains == expected_lane_chains[i]);
        }
    }

    kdw_transform world[3][SOLVER_TOTAL];
    kdw_quat local[3][SOLVER_TOTAL];
    for (int i = 0; i < 3; ++i) {
        uint32_t written = 0;
        ENSURE_OK(kdw_engine_read_world(engines[i], world[i], SOLVER_TOTAL, &written));
        ENSURE(written == SOLVER_TOTAL);
        ENSURE_OK(kdw_engine_read_local_rotations(engines[i], local[i], SOLVER_TOTAL, &written));
        ENSURE(written == SOLVER_TOTAL);
    }
    /* Lanes and portable lanes: bit for bit. */
    ENSURE(memcmp(world[0], world[1], sizeof world[0]) == 0);
    ENSURE(memcmp(local[0], local[1], sizeof local[0]) == 0);
    /* Lanes and scalar: float rounding; and the chains did bend away from their rest shape under the head. */
    double largest = 0.0, moved = 0.0;
    for (int j = 0; j < SOLVER_TOTAL; ++j) {
        ENSURE(v_is_finite(world[0][j].position) && v_is_finite(world[2][j].position));
        double d = v_dist(world[0][j].position, world[2][j].position);
        largest = d > largest ? d : largest;
    }
    for (int c = 0; c < SOLVER_CHAINS; ++c) {
        const kdw_transform tip = world[0][c * SOLVER_JOINTS + SOLVER_JOINTS - 1];
        const kdw_vec3 hanging = v3(0.0f, -0.04f * (float)(SOLVER_JOINTS - 1), 0.0f);
        const kdw_vec3 rest_tip = v_add(head.position, v_add(solver_root(c), hanging));
        double d = v_dist(tip.position, rest_tip);
        moved = d > moved ? d : moved;
    }
    printf("     simd path %s; lanes vs scalar after %d frames: largest joint difference %.3g m (tips swung up to "
           "%.3g m off rest)\n",
           path, SOLVER_FRAMES, largest, moved);
    ENSURE(moved > 1e-3);
    ENSURE(largest <= SOLVER_AGREEMENT_TOL);
    return 0;
}

/* Edge cases of the anchor and camera: a camera sitting on the view reference (no view direction), a teleport
 * (far jump and half turn in one step), and a new base shape whose segment lengths the chain takes on. */
static int test_teleport_camera_on_head_and_new_base(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    kdw_engine *e = s.engine;
    ENSURE(step_frames(e, 0, 30) == 0);

    kdw_transform head = head_at_rest();
    kdw_transform anchors[3] = {head, head, head};
    for (int frame = 0; frame < 10; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &head.position, &head));
        ENSURE_POSE(e, g_scene_specs, anchors, 3, frame);
    }

    /* 5.7 m away (the teleport distance is 1 m; close enough to the origin for 1e-4 relative float lengths) */
    kdw_transform far = xf(v3(4.0f, 1.6f, -3.0f), q_axis_angle(0.0f, 1.0f, 0.0f, 3.0f));
    kdw_vec3 camera = v_add(far.position, v3(0.0f, 0.3f, 3.0f));
    for (int i = 0; i < 3; ++i) {
        anchors[i] = far;
    }
    for (int frame = 0; frame < 30; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &far));
        ENSURE_POSE(e, g_scene_specs, anchors, 3, frame);
    }
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(e, &stats));
    ENSURE(stats.substeps_total == 70u * 4u);

    /* the side lock gets 0.05 m segments instead of 0.04 */
    chain_spec longer;
    make_straight(&longer, 5, v3(0.08f, 0.0f, 0.02f), v3(0.0f, -1.0f, 0.0f), 0.05f);
    ENSURE_OK(kdw_chain_set_base_shape(e, s.chains[1], longer.joints, longer.n));
    const chain_spec *const specs[3] = {&g_ahoge, &longer, &g_tail};
    for (int frame = 0; frame < 30; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &far));
        ENSURE_POSE(e, specs, anchors, 3, frame);
    }
    kdw_transform rest[MAX_JOINTS];
    uint32_t written = 0;
    ENSURE_OK(kdw_chain_read_rest_shape(e, s.chains[1], rest, MAX_JOINTS, &written));
    ENSURE(written == 5);
    for (uint32_t j = 0; j < written; ++j) {
        ENSURE_SMALL(v_dist(rest[j].position, longer.joints[j].position), 1e-6);
    }
    return 0;
}

/* dt == 0 changes nothing, whatever camera and view reference come with it. */
static int test_dt_zero_changes_nothing(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    kdw_transform elsewhere = xf(v3(1.0f, 2.0f, 3.0f), q_axis_angle(0.0f, 1.0f, 0.0f, 1.0f));
    kdw_vec3 camera = v3(-4.0f, 0.0f, 2.0f);

    /* on a fresh engine (nothing placed yet) */
    uint64_t before = hash_of(s.engine);
    ENSURE_OK(kdw_engine_step(s.engine, 0.0f, &camera, &elsewhere));
    ENSURE(hash_of(s.engine) == before);

    ENSURE(step_frames(s.engine, 0, 30) == 0);
    before = hash_of(s.engine);
    kdw_transform world_before[MAX_TOTAL], world_after[MAX_TOTAL];
    uint32_t written = 0;
    ENSURE_OK(kdw_engine_read_world(s.engine, world_before, MAX_TOTAL, &written));
    kdw_engine_stats stats_before, stats_after;
    ENSURE_OK(kdw_engine_get_stats(s.engine, &stats_before));

    ENSURE_OK(kdw_engine_step(s.engine, 0.0f, &camera, &elsewhere));
    ENSURE(hash_of(s.engine) == before);
    ENSURE_OK(kdw_engine_step(s.engine, -0.0f, &camera, &elsewhere));
    ENSURE(hash_of(s.engine) == before);
    ENSURE_OK(kdw_engine_read_world(s.engine, world_after, MAX_TOTAL, &written));
    ENSURE(memcmp(world_before, world_after, written * sizeof world_before[0]) == 0);
    ENSURE_OK(kdw_engine_get_stats(s.engine, &stats_after));
    ENSURE(stats_after.substeps_total == stats_before.substeps_total);
    ENSURE(stats_after.simulated_time == stats_before.simulated_time);
    return 0;
}

/* The swaying, turning head of test_non_unit_view_reference at `frame`, its rotation scaled by `scale`. */
static kdw_transform swaying_head(int frame, float scale)
{
    float t = (float)frame / 120.0f;
    kdw_quat q = q_mul(q_axis_angle(0.0f, 1.0f, 0.0f, 0.8f * sinf(2.0f * PI_F * t)),
                       q_axis_angle(1.0f, 0.0f, 0.0f, 0.2f));
    return xf(v3(0.1f * t, 1.6f, 0.0f), q_scale(q, scale));
}

/* The largest difference between the world poses of the same joint in two engines: position (m) or rotation
 * (rad), and whether every byte is the same. */
static int world_difference(const kdw_engine *a, const kdw_engine *b, double *largest, int *same_bits)
{
    kdw_transform wa[MAX_TOTAL], wb[MAX_TOTAL];
    uint32_t na = 0, nb = 0;
    ENSURE_OK(kdw_engine_read_world(a, wa, MAX_TOTAL, &na));
    ENSURE_OK(kdw_engine_read_world(b, wb, MAX_TOTAL, &nb));
    ENSURE(na == nb && na == 19);
    *largest = 0.0;
    for (uint32_t j = 0; j < na; ++j) {
        double d = v_dist(wa[j].position, wb[j].position);
        double r = q_distance(wa[j].rotation, wb[j].rotation);
        *largest = d > *largest ? d : *largest;
        *largest = r > *largest ? r : *largest;
    }
    *same_bits = memcmp(wa, wb, na * sizeof wa[0]) == 0;
    return 0;
}

/* A view reference quaternion need not be unit: the engine uses q / |q|. Scaled by a power of two, q / |q| is
 * the same float32 value as for q (the scale is exact and cancels exactly), so the two engines must give the
 * same bits at every frame. Scaled by 3, q / |q| differs from q's by a rounding (1e-7), and the poses must stay
 * within 1e-4 at every frame: the swaying chains carry a rounding difference up to a few 1e-5 (a rounding
 * can flip one of the solver's stopping decisions, whose results differ by up to its tolerances, and the
 * motion then grows that), while a missing or approximate normalisation is off by more than 1e-3. */
static int test_non_unit_view_reference(void)
{
    const float scales[3] = {4.0f, 0.25f, 3.0f};
    const chain_spec *const specs[3] = {&g_ahoge, &g_side_lock, &g_tail};
    for (int k = 0; k < 3; ++k) {
        int exact = scales[k] != 3.0f;
        scene unit, scaled;
        ENSURE(scene_build(&unit, 1) == 0);
        ENSURE(scene_build(&scaled, 1) == 0);
        for (int frame = 0; frame < 120; ++frame) {
            kdw_transform head = swaying_head(frame, 1.0f);
            kdw_transform head_scaled = swaying_head(frame, scales[k]);
            kdw_vec3 camera = orbit_camera(frame);
            ENSURE_OK(kdw_engine_step(unit.engine, FRAME_DT, &camera, &head));
            ENSURE_OK(kdw_engine_step(scaled.engine, FRAME_DT, &camera, &head_scaled));
            const kdw_transform anchors[3] = {head, head, head};
            ENSURE_POSE(scaled.engine, specs, anchors, 3, frame);
            double largest = 0.0;
            int same_bits = 0;
            ENSURE(world_difference(unit.engine, scaled.engine, &largest, &same_bits) == 0);
            if (exact) {
                ENSURE(same_bits);
            } else {
                ENSURE_SMALL(largest, 1e-4);
            }
        }
    }
    return 0;
}

/* ---- colliders, per-joint radii, teleports, scale ------------------------------------------------------ */

static kdw_collider_def collider_at(uint32_t shape, float radius, float half_height, kdw_vec3 position)
{
    kdw_collider_def def = kdw_collider_def_default();
    def.shape = shape;
    def.radius = radius;
    def.half_height = half_height;
    def.transform = xf(position, q_identity());
    return def;
}

/* Collider ids in creation order must be exactly `expected`. */
static int check_collider_ids(const kdw_engine *engine, const kdw_collider_id *expected, uint32_t count)
{
    kdw_collider_id listed[8];
    uint32_t written = SENTINEL_U32, total = SENTINEL_U32;
    ENSURE_OK(kdw_engine_collider_count(engine, &total));
    ENSURE(total == count);
    ENSURE_OK(kdw_engine_get_collider_ids(engine, listed, 8, &written));
    ENSURE(written == count);
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t valid = SENTINEL_U32;
        ENSURE(listed[i] == expected[i]);
        ENSURE_OK(kdw_collider_is_valid(engine, listed[i], &valid));
        ENSURE(valid == 1);
    }
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(engine, &stats));
    ENSURE(stats.collider_count == count);
    return 0;
}

/* Create, list, destroy: ids are unique, of their own kind, stale after destruction (also once the slot is
 * reused); the batched order is creation order with destroyed colliders left out. */
static int test_collider_life_cycle(void)
{
    scene s, other;
    ENSURE(scene_build(&s, 0) == 0);
    ENSURE(scene_build(&other, 0) == 0);
    kdw_engine *e = s.engine;
    const kdw_status ID = KDW_STATUS_INVALID_ID;
    const kdw_collider_def sphere = collider_at(KDW_COLLIDER_SPHERE, 0.1f, 0.0f, v3(1.0f, 1.0f, 0.0f));
    const kdw_collider_def capsule = collider_at(KDW_COLLIDER_CAPSULE, 0.05f, 0.2f, v3(-1.0f, 1.0f, 0.0f));
    const kdw_collider_def plane = collider_at(KDW_COLLIDER_PLANE, 0.0f, 0.0f, v3(0.0f, -5.0f, 0.0f));
    ENSURE(check_collider_ids(e, NULL, 0) == 0);

    kdw_collider_id ids[3] = {0, 0, 0};
    ENSURE_OK(kdw_collider_create(e, &sphere, &ids[0]));
    ENSURE_OK(kdw_collider_create(e, &capsule, &ids[1]));
    ENSURE_OK(kdw_collider_create(e, &plane, &ids[2]));
    for (int i = 0; i < 3; ++i) {
        ENSURE(ids[i] != 0 && ids[i] != ids[(i + 1) % 3]);
        for (int c = 0; c < 3; ++c) {
            ENSURE(ids[i] != s.chains[c]);
        }
    }
    ENSURE(check_collider_ids(e, ids, 3) == 0);
    ENSURE(step_frames(e, 0, 5) == 0);

    uint64_t before = hash_of(e);
    ENSURE_OK(kdw_collider_set_layers(e, ids[1], 0x6u));
    ENSURE(hash_of(e) != before);

    /* Destroying the middle one: the others keep their relative order. */
    ENSURE_OK(kdw_collider_destroy(e, ids[1]));
    const kdw_collider_id survivors[2] = {ids[0], ids[2]};
    ENSURE(check_collider_ids(e, survivors, 2) == 0);
    uint32_t valid = SENTINEL_U32;
    ENSURE_OK(kdw_collider_is_valid(e, ids[1], &valid));
    ENSURE(valid == 0);
    ENSURE_REJECTED(e, kdw_collider_destroy(e, ids[1]), ID);
    ENSURE_REJECTED(e, kdw_collider_set_layers(e, ids[1], 1u), ID);
    ENSURE_REJECTED(e, kdw_collider_destroy(e, 0), ID);

    /* Ids of one kind are never ids of another. */
    ENSURE_OK(kdw_collider_is_valid(e, s.chains[0], &valid));
    ENSURE(valid == 0);
    ENSURE_OK(kdw_chain_is_valid(e, ids[0], &valid));
    ENSURE(valid == 0);
    ENSURE_REJECTED(e, kdw_collider_destroy(e, s.chains[0]), ID);
    ENSURE_REJECTED(e, kdw_collider_set_layers(e, s.chains[1], 1u), ID);
    ENSURE_REJECTED(e, kdw_chain_destroy(e, ids[0]), ID);
    ENSURE_REJECTED(e, kdw_chain_teleport(e, ids[0]), ID);
    const float radii[8] = {0};
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, ids[2], radii, 8), ID);

    /* A foreign id is rejected here and fine on its own engine. */
    kdw_collider_id foreign = 0;
    ENSURE_OK(kdw_collider_create(other.engine, &sphere, &foreign));
    ENSURE_OK(kdw_collider_is_valid(e, foreign, &valid));
    ENSURE(valid == 0);
    ENSURE_REJECTED(e, kdw_collider_destroy(e, foreign), ID);
    ENSURE_REJECTED(e, kdw_collider_set_layers(e, foreign, 2u), ID);
    ENSURE_OK(kdw_collider_is_valid(other.engine, foreign, &valid));
    ENSURE(valid == 1);

    /* A new collider comes last (reusing the freed slot); the old id stays stale. */
    kdw_collider_id again = 0;
    ENSURE_OK(kdw_collider_create(e, &capsule, &again));
    ENSURE(again != 0 && again != ids[1]);
    const kdw_collider_id reordered[3] = {ids[0], ids[2], again};
    ENSURE(check_collider_ids(e, reordered, 3) == 0);
    ENSURE_REJECTED(e, kdw_collider_destroy(e, ids[1]), ID);

    /* Too small a buffer: nothing written. */
    kdw_collider_id listed[3];
    memset(listed, SENTINEL_BYTE, sizeof listed);
    uint32_t written = SENTINEL_U32;
    ENSURE_REJECTED(e, kdw_engine_get_collider_ids(e, listed, 2, &written), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE_REJECTED(e, kdw_engine_get_collider_ids(e, NULL, 0, &written), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE_REJECTED(e, kdw_engine_get_collider_ids(e, NULL, 3, &written), KDW_STATUS_NULL_POINTER);
    ENSURE(written == SENTINEL_U32 && bytes_are(listed, sizeof listed, SENTINEL_BYTE));

    /* Every collider call rejects a NULL engine. */
    const kdw_status NP = KDW_STATUS_NULL_POINTER;
    kdw_collider_id id_out = SENTINEL_U64;
    uint32_t u = SENTINEL_U32;
    const kdw_transform poses[3] = {sphere.transform, plane.transform, capsule.transform};
    ENSURE_REJECTED(e, kdw_collider_create(NULL, &sphere, &id_out), NP);
    ENSURE_REJECTED(e, kdw_collider_create(e, NULL, &id_out), NP);
    ENSURE_REJECTED(e, kdw_collider_create(e, &sphere, NULL), NP);
    ENSURE_REJECTED(e, kdw_collider_destroy(NULL, ids[0]), NP);
    ENSURE_REJECTED(e, kdw_collider_is_valid(NULL, ids[0], &u), NP);
    ENSURE_REJECTED(e, kdw_collider_is_valid(e, ids[0], NULL), NP);
    ENSURE_REJECTED(e, kdw_collider_set_layers(NULL, ids[0], 1u), NP);
    ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(NULL, poses, 3), NP);
    ENSURE_REJECTED(e, kdw_engine_collider_count(NULL, &u), NP);
    ENSURE_REJECTED(e, kdw_engine_collider_count(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_get_collider_ids(NULL, listed, 3, &u), NP);
    ENSURE_REJECTED(e, kdw_engine_teleport(NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_teleport(NULL, s.chains[0]), NP);
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(NULL, s.chains[0], radii, 8), NP);
    ENSURE(id_out == SENTINEL_U64 && u == SENTINEL_U32);

    /* Without colliders, zero poses (NULL allowed) is the right count. */
    for (int i = 0; i < 3; ++i) {
        ENSURE_OK(kdw_collider_destroy(e, reordered[i]));
    }
    ENSURE(check_collider_ids(e, NULL, 0) == 0);
    ENSURE_OK(kdw_engine_set_collider_transforms(e, NULL, 0));
    ENSURE(step_frames(e, 5, 1) == 0);
    return 0;
}

/* Every way a collider def can be wrong is rejected before anything changes. */
static int test_error_collider_def(void)
{
    scene s;
    ENSURE(scene_build(&s, 0) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_collider_def good = collider_at(KDW_COLLIDER_CAPSULE, 0.05f, 0.1f, v3(0.5f, 1.0f, 0.0f));
    kdw_collider_id out = SENTINEL_U64;

    const uint32_t bad_sizes[] = {0, (uint32_t)sizeof(kdw_collider_def) - 4, (uint32_t)sizeof(kdw_collider_def) + 4};
    for (size_t i = 0; i < sizeof bad_sizes / sizeof bad_sizes[0]; ++i) {
        kdw_collider_def def = good;
        def.struct_size = bad_sizes[i];
        ENSURE_REJECTED(e, kdw_collider_create(e, &def, &out), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    }

    kdw_collider_def bad[24];
    int n = 0;
    for (int i = 0; i < 24; ++i) {
        bad[i] = good;
    }
    bad[n++].radius = NAN;
    bad[n++].radius = INFINITY;
    bad[n++].radius = -0.01f;
    bad[n++].radius = 2e6f;
    bad[n++].half_height = NAN;
    bad[n++].half_height = -INFINITY;
    bad[n++].half_height = -0.01f;
    bad[n].radius = 0.0f; /* a capsule of no size */
    bad[n++].half_height = 0.0f;
    bad[n++] = collider_at(KDW_COLLIDER_INSIDE_SPHERE, 0.0f, 0.0f, v3(0.0f, 1.0f, 0.0f));
    bad[n++] = collider_at(KDW_COLLIDER_INSIDE_CAPSULE, 0.0f, 0.1f, v3(0.0f, 1.0f, 0.0f));
    bad[n++] = collider_at(KDW_COLLIDER_SPHERE, -1.0f, 0.0f, v3(0.0f, 1.0f, 0.0f));
    bad[n++].shape = 5;
    bad[n++].shape = 0xFFFFFFFFu;
    bad[n++].transform.position.x = NAN;
    bad[n++].transform.position.z = -INFINITY;
    bad[n++].transform.position.y = 2e9f;
    bad[n++].transform.rotation.w = NAN;
    bad[n++].transform.rotation.y = INFINITY;
    bad[n++].transform.rotation = q4(0.0f, 0.0f, 0.0f, 0.0f);
    for (int i = 0; i < n; ++i) {
        ENSURE_REJECTED(e, kdw_collider_create(e, &bad[i], &out), KDW_STATUS_INVALID_ARGUMENT);
    }
    ENSURE(out == SENTINEL_U64);
    ENSURE(check_collider_ids(e, NULL, 0) == 0);

    /* the edges of the ranges are accepted: a point-like sphere, a segment capsule, a non-unit rotation */
    kdw_collider_def edge = collider_at(KDW_COLLIDER_SPHERE, 0.0f, 0.0f, v3(0.5f, 1.0f, 0.0f));
    ENSURE_OK(kdw_collider_create(e, &edge, &out));
    edge = collider_at(KDW_COLLIDER_CAPSULE, 0.0f, 0.1f, v3(0.5f, 1.0f, 0.0f));
    edge.transform.rotation = q4(0.0f, 0.0f, 2.0f, 2.0f);
    ENSURE_OK(kdw_collider_create(e, &edge, &out));
    ENSURE_OK(kdw_collider_create(e, &good, &out));
    return 0;
}

/* The batched collider poses and the per-joint radii validate everything before changing anything. */
static int test_error_collider_transforms_and_joint_radii(void)
{
    scene s;
    ENSURE(scene_build(&s, 0) == 0);
    kdw_engine *e = s.engine;
    const kdw_collider_def sphere = collider_at(KDW_COLLIDER_SPHERE, 0.1f, 0.0f, v3(1.0f, 1.0f, 0.0f));
    kdw_collider_id ids[2];
    ENSURE_OK(kdw_collider_create(e, &sphere, &ids[0]));
    ENSURE_OK(kdw_collider_create(e, &sphere, &ids[1]));
    ENSURE(step_frames(e, 0, 10) == 0);
    const kdw_status IA = KDW_STATUS_INVALID_ARGUMENT;

    kdw_transform poses[3] = {xf(v3(1.0f, 1.1f, 0.0f), q_identity()), xf(v3(-1.0f, 1.1f, 0.0f), q_identity()),
                              xf(v3(0.0f, 3.0f, 0.0f), q_identity())};
    /* one pose per collider: not fewer, not more */
    ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, poses, 1), IA);
    ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, poses, 3), IA);
    ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, NULL, 0), IA);
    ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, NULL, 2), KDW_STATUS_NULL_POINTER);
    /* every pose is checked, the last one too */
    const kdw_transform good[2] = {poses[0], poses[1]};
    for (int slot = 0; slot < 2; ++slot) {
        kdw_transform broken[2] = {good[0], good[1]};
        broken[slot].position.x = NAN;
        ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, broken, 2), IA);
        broken[slot] = good[slot];
        broken[slot].position.y = INFINITY;
        ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, broken, 2), IA);
        broken[slot] = good[slot];
        broken[slot].position.z = -2e9f;
        ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, broken, 2), IA);
        broken[slot] = good[slot];
        broken[slot].rotation.x = -INFINITY;
        ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, broken, 2), IA);
        broken[slot] = good[slot];
        broken[slot].rotation = q4(0.0f, 0.0f, 0.0f, 0.0f);
        ENSURE_REJECTED(e, kdw_engine_set_collider_transforms(e, broken, 2), IA);
    }
    /* the valid call is part of the state (it decides the next step) */
    uint64_t before = hash_of(e);
    ENSURE_OK(kdw_engine_set_collider_transforms(e, good, 2));
    ENSURE(hash_of(e) != before);

    /* per-joint radii: one per joint (the ahoge has 8), each finite in [0, 1e6] */
    const kdw_chain_id chain = s.chains[0];
    float radii[9] = {0.01f, 0.01f, 0.01f, 0.01f, 0.01f, 0.01f, 0.01f, 0.01f, 0.01f};
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, radii, 7), IA);
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, radii, 9), IA);
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, radii, 1), IA);
    ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, NULL, 8), KDW_STATUS_NULL_POINTER);
    const float bad_values[] = {NAN, INFINITY, -INFINITY, -0.01f, 2e6f};
    for (size_t i = 0; i < sizeof bad_values / sizeof bad_values[0]; ++i) {
        radii[7] = bad_values[i];
        ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, radii, 8), IA);
        radii[7] = 0.01f;
        radii[0] = bad_values[i];
        ENSURE_REJECTED(e, kdw_chain_set_joint_radii(e, chain, radii, 8), IA);
        radii[0] = 0.01f;
    }
    before = hash_of(e);
    ENSURE_OK(kdw_chain_set_joint_radii(e, chain, radii, 8));
    ENSURE(hash_of(e) != before);
    ENSURE_OK(kdw_chain_set_joint_radii(e, chain, NULL, 0)); /* back to the def's radius */
    return 0;
}

#define DRAPE_JOINTS 8
#define BALL_RADIUS 0.1f

/* A limp 8-joint chain held level at (0, 1, 0) along +x, 5 cm apart, falling onto a ball below its middle. */
static int drape_scene(kdw_engine **out, uint32_t collision_mask, kdw_chain_id *chain, kdw_collider_id *ball,
                       kdw_vec3 ball_centre)
{
    kdw_engine *e = engine_new_default();
    ENSURE(e != NULL);
    chain_spec level;
    make_straight(&level, DRAPE_JOINTS, v3(0.0f, 0.0f, 0.0f), v3(1.0f, 0.0f, 0.0f), 0.05f);
    kdw_chain_def def = kdw_chain_def_default();
    def.stiffness = 0.02f;
    def.damping = 3.0f;
    def.collision_mask = collision_mask;
    ENSURE_OK(kdw_chain_create(e, &def, level.joints, level.n, chain));
    const float zero_radii[DRAPE_JOINTS] = {0};
    ENSURE_OK(kdw_chain_set_joint_radii(e, *chain, zero_radii, DRAPE_JOINTS));
    kdw_collider_def sphere = collider_at(KDW_COLLIDER_SPHERE, BALL_RADIUS, 0.0f, ball_centre);
    sphere.layers = 0x2u;
    ENSURE_OK(kdw_collider_create(e, &sphere, ball));
    *out = e;
    return 0;
}

/* Smallest distance of the chain's joints to `centre` (read through kdw_chain_read_world). */
static int closest_joint(const kdw_engine *e, kdw_chain_id chain, kdw_vec3 centre, double *closest)
{
    kdw_transform world[DRAPE_JOINTS];
    uint32_t written = 0;
    ENSURE_OK(kdw_chain_read_world(e, chain, world, DRAPE_JOINTS, &written));
    ENSURE(written == DRAPE_JOINTS);
    *closest = 1e30;
    for (uint32_t j = 0; j < written; ++j) {
        ENSURE(v_is_finite(world[j].position));
        *closest = fmin(*closest, v_dist(world[j].position, centre));
    }
    return 0;
}

/* A chain falling onto a sphere collider stays outside it in every frame (joint radius 0: the joints
 * themselves), rests on it, is pushed by it when it moves, and keeps its joint radius off it once the def's
 * radius applies again. The same chain with a collision mask that misses the ball falls through it. */
static int test_chain_stays_outside_sphere_collider(void)
{
    const kdw_transform anchor = xf(v3(0.0f, 1.0f, 0.0f), q_identity());
    const kdw_vec3 camera = v3(0.0f, 1.0f, 3.0f);
    kdw_vec3 centre = v3(0.2f, 0.82f, 0.0f);
    kdw_engine *e = NULL, *through = NULL;
    kdw_chain_id chain = 0, ghost = 0;
    kdw_collider_id ball = 0, ghost_ball = 0;
    ENSURE(drape_scene(&e, 0x3u, &chain, &ball, centre) == 0);
    ENSURE(drape_scene(&through, 0x1u, &ghost, &ghost_ball, centre) == 0);

    double resting = 1e30, ghost_closest = 1e30;
    for (int frame = 0; frame < 180; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &anchor));
        ENSURE_OK(kdw_engine_step(through, FRAME_DT, &camera, &anchor));
        double closest = 0.0, other = 0.0;
        ENSURE(closest_joint(e, chain, centre, &closest) == 0);
        ENSURE(closest_joint(through, ghost, centre, &other) == 0);
        if (!(closest >= BALL_RADIUS - 1e-4)) {
            printf("    frame %d: a joint is %.6f m from the ball's centre (radius %.3f)\n", frame, closest,
                   (double)BALL_RADIUS);
            return 1;
        }
        resting = closest;
        ghost_closest = fmin(ghost_closest, other);
    }
    /* It lies on the ball rather than stopping above it. Segments collide too, so a segment can rest tangent to
     * the ball with its joints sqrt(0.1^2 + 0.025^2) - 0.1 = 3.1 mm out. */
    ENSURE(resting < BALL_RADIUS + 3.5e-3);
    ENSURE(ghost_closest < BALL_RADIUS - 0.05); /* without the ball's layer it falls right through */
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(e, &stats));
    ENSURE(stats.collider_count == 1 && stats.contact_pairs_tested > 0);

    /* The ball rises 6 cm over one second, one batched pose per frame: the chain is pushed along. */
    for (int frame = 0; frame < 60; ++frame) {
        centre.y += 0.001f;
        const kdw_transform pose = xf(centre, q_identity());
        ENSURE_OK(kdw_engine_set_collider_transforms(e, &pose, 1));
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &anchor));
        double closest = 0.0;
        ENSURE(closest_joint(e, chain, centre, &closest) == 0);
        ENSURE(closest >= BALL_RADIUS - 1e-4);
    }

    /* Back to the def's radius (0.02 m): the joints settle that much farther out. */
    ENSURE_OK(kdw_chain_set_joint_radii(e, chain, NULL, 0));
    double closest = 0.0;
    for (int frame = 0; frame < 60; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &anchor));
    }
    ENSURE(closest_joint(e, chain, centre, &closest) == 0);
    if (!(closest >= BALL_RADIUS + 0.02 - 1e-3 && closest < BALL_RADIUS + 0.02 + 5e-3)) {
        printf("    with the def's radius the closest joint is %.6f m from the ball's centre\n", closest);
        return 1;
    }
    return 0;
}

/* Engines for the teleport tests: a side lock and a tail on the head, automatic teleports off (FLT_MAX), so
 * that only the explicit calls teleport. */
static kdw_engine *teleport_engine(uint32_t mode, kdw_chain_id chains[2])
{
    kdw_engine_def def = kdw_engine_def_default();
    def.teleport_distance = FLT_MAX;
    def.teleport_mode = mode;
    kdw_engine *e = engine_new(&def);
    if (e == NULL) return NULL;
    kdw_chain_def chain = kdw_chain_def_default();
    if (kdw_chain_create(e, &chain, g_side_lock.joints, g_side_lock.n, &chains[0]) != KDW_STATUS_OK ||
        kdw_chain_create(e, &chain, g_tail.joints, g_tail.n, &chains[1]) != KDW_STATUS_OK) {
        printf("    chain create failed: %s\n", harness_last_error());
        return NULL;
    }
    return e;
}

/* The head swings for 20 frames, then holds still (the chains keep swinging), offset by `jump` from frame 30. */
static kdw_transform swinging_head(int frame, kdw_vec3 jump)
{
    int swing = frame < 20 ? frame : 19;
    kdw_transform head = xf(v3(0.15f * sinf(0.3f * (float)swing), 1.6f, 0.0f), q_identity());
    if (frame >= 30) head.position = v_add(head.position, jump);
    return head;
}

static int step_swinging(kdw_engine *e, int frame, kdw_vec3 jump)
{
    kdw_transform head = swinging_head(frame, jump);
    kdw_vec3 camera = v_add(v3(0.0f, 1.7f, 3.0f), frame >= 30 ? jump : v3(0.0f, 0.0f, 0.0f));
    ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &head));
    return 0;
}

static int chain_energy(const kdw_engine *e, kdw_chain_id chain, double *energy)
{
    float value = -1.0f;
    ENSURE_OK(kdw_chain_kinetic_energy(e, chain, &value));
    ENSURE(isfinite(value) && value >= 0.0f);
    *energy = value;
    return 0;
}

/* kdw_engine_teleport (carry mode) takes the chains through a 100 m jump as if nothing happened: relative to
 * the head their poses and energies equal those of an engine whose head did not jump. The same jump without
 * the call whips them; kdw_chain_teleport spares only its own chain. */
static int test_engine_teleport_carries_chains(void)
{
    kdw_chain_id a[2], still[2], whipped[2], one[2];
    kdw_engine *jumper = teleport_engine(KDW_TELEPORT_CARRY_SHAPE, a);
    kdw_engine *reference = teleport_engine(KDW_TELEPORT_CARRY_SHAPE, still);
    kdw_engine *no_call = teleport_engine(KDW_TELEPORT_CARRY_SHAPE, whipped);
    kdw_engine *chain_call = teleport_engine(KDW_TELEPORT_CARRY_SHAPE, one);
    ENSURE(jumper != NULL && reference != NULL && no_call != NULL && chain_call != NULL);
    const kdw_vec3 jump = v3(100.0f, 0.0f, 0.0f), none = v3(0.0f, 0.0f, 0.0f);

    for (int frame = 0; frame < 60; ++frame) {
        if (frame == 30) {
            uint64_t before = hash_of(jumper);
            ENSURE_OK(kdw_engine_teleport(jumper));
            ENSURE(hash_of(jumper) != before); /* the request is state until the next step */
            ENSURE_OK(kdw_chain_teleport(chain_call, one[0]));
        }
        ENSURE(step_swinging(jumper, frame, jump) == 0);
        ENSURE(step_swinging(reference, frame, none) == 0);
        ENSURE(step_swinging(no_call, frame, jump) == 0);
        ENSURE(step_swinging(chain_call, frame, jump) == 0);
        if (frame < 30) continue;

        const kdw_vec3 head_a = swinging_head(frame, jump).position, head_b = swinging_head(frame, none).position;
        kdw_transform wa[MAX_TOTAL], wb[MAX_TOTAL], wc[MAX_TOTAL];
        uint32_t na = 0, nb = 0, nc = 0;
        ENSURE_OK(kdw_engine_read_world(jumper, wa, MAX_TOTAL, &na));
        ENSURE_OK(kdw_engine_read_world(reference, wb, MAX_TOTAL, &nb));
        ENSURE_OK(kdw_engine_read_world(chain_call, wc, MAX_TOTAL, &nc));
        ENSURE(na == nb && nb == nc && na == g_side_lock.n + g_tail.n);
        for (uint32_t j = 0; j < na; ++j) {
            ENSURE_SMALL(v_dist(v_sub(wa[j].position, head_a), v_sub(wb[j].position, head_b)), 1e-4);
            ENSURE_SMALL(q_distance(wa[j].rotation, wb[j].rotation), 1e-4);
        }
        for (uint32_t j = 0; j < g_side_lock.n; ++j) { /* the chain told to teleport */
            ENSURE_SMALL(v_dist(v_sub(wc[j].position, head_a), v_sub(wb[j].position, head_b)), 1e-4);
        }
        for (int c = 0; c < 2; ++c) {
            double ka = 0.0, kb = 0.0, kw = 0.0, k1 = 0.0;
            ENSURE(chain_energy(jumper, a[c], &ka) == 0);
            ENSURE(chain_energy(reference, still[c], &kb) == 0);
            ENSURE(chain_energy(no_call, whipped[c], &kw) == 0);
            ENSURE(chain_energy(chain_call, one[c], &k1) == 0);
            ENSURE_SMALL(ka - kb, 1e-3 * kb + 1e-7); /* carried: no energy added, none lost */
            if (frame == 30) {
                ENSURE(kb > 1e-5);             /* the chains were still swinging: the comparison means something */
                ENSURE(kw > 1000.0 * kb);       /* dragged 100 m in one frame */
                if (c == 0) ENSURE_SMALL(k1 - kb, 1e-3 * kb + 1e-7);
                else ENSURE(k1 > 1000.0 * kb); /* the other chain was not told to teleport */
            }
        }
    }
    return 0;
}

/* KDW_TELEPORT_RESET: a teleported chain is put back to its rest shape under its new anchor, at rest, i.e.
 * exactly what kdw_chain_reset / kdw_engine_reset do at the same step (same state hash, same read-back). */
static int test_teleport_mode_reset(void)
{
    kdw_chain_id a[2], r[2], carried[2];
    kdw_engine *teleported = teleport_engine(KDW_TELEPORT_RESET, a);
    kdw_engine *reset = teleport_engine(KDW_TELEPORT_RESET, r);
    kdw_engine *carry = teleport_engine(KDW_TELEPORT_CARRY_SHAPE, carried);
    ENSURE(teleported != NULL && reset != NULL && carry != NULL);
    const kdw_vec3 jump = v3(3.0f, 0.5f, -2.0f);
    for (int frame = 0; frame < 50; ++frame) {
        if (frame == 30) { /* one chain */
            ENSURE_OK(kdw_chain_teleport(teleported, a[0]));
            ENSURE_OK(kdw_chain_reset(reset, r[0]));
            ENSURE_OK(kdw_chain_teleport(carry, carried[0]));
        }
        if (frame == 40) { /* every chain, no jump this time: a teleport however small */
            ENSURE_OK(kdw_engine_teleport(teleported));
            ENSURE_OK(kdw_engine_reset(reset));
        }
        ENSURE(step_swinging(teleported, frame, jump) == 0);
        ENSURE(step_swinging(reset, frame, jump) == 0);
        ENSURE(step_swinging(carry, frame, jump) == 0);
        ENSURE(hash_of(teleported) == hash_of(reset));
        kdw_transform wa[MAX_TOTAL], wr[MAX_TOTAL];
        uint32_t na = 0, nr = 0;
        ENSURE_OK(kdw_engine_read_world(teleported, wa, MAX_TOTAL, &na));
        ENSURE_OK(kdw_engine_read_world(reset, wr, MAX_TOTAL, &nr));
        ENSURE(na == nr && memcmp(wa, wr, na * sizeof wa[0]) == 0);
        if (frame == 30) {
            double reset_energy = 0.0, carried_energy = 0.0;
            ENSURE(chain_energy(teleported, a[0], &reset_energy) == 0);
            ENSURE(chain_energy(carry, carried[0], &carried_energy) == 0);
            ENSURE(carried_energy > 10.0 * reset_energy); /* the reset one starts again from rest */
        }
    }
    return 0;
}

/* The engine's scale: validated ([1e-6, 1e6], finite), and a character 100 times larger with scale 100 moves
 * exactly like the original, 100 times larger, collisions included (radii scale, collider sizes do not). */
static int test_engine_scale(void)
{
    scene s; /* target of set_def, witness for create */
    ENSURE(scene_build(&s, 0) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *const marker = (kdw_engine *)(void *)&s;
    kdw_engine *out = marker;
    const float bad_scales[] = {0.0f, -1.0f, 1e-7f, 1e7f, NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof bad_scales / sizeof bad_scales[0]; ++i) {
        kdw_engine_def def = kdw_engine_def_default();
        def.scale = bad_scales[i];
        ENSURE_REJECTED(s.engine, kdw_engine_create(&def, &out), KDW_STATUS_INVALID_ARGUMENT);
        ENSURE_REJECTED(s.engine, kdw_engine_set_def(s.engine, &def), KDW_STATUS_INVALID_ARGUMENT);
    }
    const uint32_t bad_modes[] = {2u, 7u, 0xFFFFFFFFu};
    for (size_t i = 0; i < sizeof bad_modes / sizeof bad_modes[0]; ++i) {
        kdw_engine_def def = kdw_engine_def_default();
        def.teleport_mode = bad_modes[i];
        ENSURE_REJECTED(s.engine, kdw_engine_create(&def, &out), KDW_STATUS_INVALID_ARGUMENT);
        ENSURE_REJECTED(s.engine, kdw_engine_set_def(s.engine, &def), KDW_STATUS_INVALID_ARGUMENT);
    }
    ENSURE(out == marker);
    const float edge_scales[] = {1e-6f, 1e6f};
    for (size_t i = 0; i < 2; ++i) {
        kdw_engine_def def = kdw_engine_def_default();
        def.scale = edge_scales[i];
        kdw_engine *edge = engine_new(&def);
        ENSURE(edge != NULL);
        ENSURE_OK(engine_free(edge));
    }

    /* Same scene at 1x and 100x. */
    kdw_engine *engines[2];
    kdw_chain_id chains[2];
    const float sizes[2] = {1.0f, 100.0f};
    for (int k = 0; k < 2; ++k) {
        kdw_engine_def def = kdw_engine_def_default();
        def.scale = sizes[k];
        engines[k] = engine_new(&def);
        ENSURE(engines[k] != NULL);
        chain_spec lock = g_side_lock;
        for (uint32_t j = 0; j < lock.n; ++j) {
            lock.joints[j].position = v_scale(lock.joints[j].position, sizes[k]);
        }
        kdw_chain_def chain = kdw_chain_def_default();
        ENSURE_OK(kdw_chain_create(engines[k], &chain, lock.joints, lock.n, &chains[k]));
        /* a ball in the lock's way, world units */
        kdw_collider_def ball = collider_at(KDW_COLLIDER_SPHERE, 0.03f * sizes[k], 0.0f,
                                           v_scale(v3(0.1f, 1.5f, 0.06f), sizes[k]));
        kdw_collider_id id = 0;
        ENSURE_OK(kdw_collider_create(engines[k], &ball, &id));
    }
    for (int frame = 0; frame < 90; ++frame) {
        kdw_transform world[2][MAX_JOINTS];
        for (int k = 0; k < 2; ++k) {
            kdw_transform head = swinging_head(frame, v3(0.0f, 0.0f, 0.0f));
            head.position = v_scale(head.position, sizes[k]);
            kdw_vec3 camera = v_scale(v3(0.0f, 1.7f, 3.0f), sizes[k]);
            ENSURE_OK(kdw_engine_step(engines[k], FRAME_DT, &camera, &head));
            uint32_t written = 0;
            ENSURE_OK(kdw_chain_read_world(engines[k], chains[k], world[k], MAX_JOINTS, &written));
            ENSURE(written == g_side_lock.n);
        }
        for (uint32_t j = 0; j < g_side_lock.n; ++j) {
            ENSURE_SMALL(v_dist(v_scale(world[1][j].position, 0.01f), world[0][j].position), 1e-4);
            ENSURE_SMALL(q_distance(world[1][j].rotation, world[0][j].rotation), 1e-4);
        }
    }
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(engines[1], &stats));
    ENSURE(stats.contact_pairs_tested > 0);
    return 0;
}

/* ---- culling, sleeping, batch stepping, collider resizing ---------------------------------------------------- */

/* The head swinging sideways, turning about y and drifting forward: its pose at `frame`. */
static kdw_transform moving_head(int frame)
{
    const float t = (float)frame * FRAME_DT;
    const float angle = 0.6f * sinf(2.0f * t);
    return xf(v3(0.4f * sinf(3.0f * t), 1.6f + 0.1f * t, 0.2f * t), q_axis_angle(0.0f, 1.0f, 0.0f, angle));
}

/* `point` in the rigid frame `frame`. */
static kdw_vec3 position_in(kdw_transform frame, kdw_vec3 point)
{
    return q_rotate(q_conjugate(frame.rotation), v_sub(point, frame.position));
}

/* kdw_chain_set_enabled / kdw_chain_is_enabled: a disabled chain rides rigidly with its (moving, turning) anchor,
 * is counted in chains_asleep while the others swing, and is simulated again once enabled. Values other than
 * 0 and 1, NULL outputs and bad ids are rejected without changing the state. */
static int test_chain_enabled(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    const kdw_vec3 camera = v3(0.0f, 1.7f, 2.5f);
    int frame = 0;
    for (; frame < 30; ++frame) {
        const kdw_transform head = moving_head(frame);
        ENSURE_OK(kdw_engine_step(s.engine, FRAME_DT, &camera, &head));
    }
    uint32_t enabled = 7;
    ENSURE_OK(kdw_chain_is_enabled(s.engine, s.chains[1], &enabled));
    ENSURE(enabled == 1);

    ENSURE_OK(kdw_chain_set_enabled(s.engine, s.chains[1], 0));
    ENSURE_OK(kdw_chain_is_enabled(s.engine, s.chains[1], &enabled));
    ENSURE(enabled == 0);
    ENSURE_OK(kdw_chain_is_enabled(s.engine, s.chains[0], &enabled));
    ENSURE(enabled == 1);
    const uint32_t n = g_side_lock.n;
    kdw_transform world[MAX_JOINTS];
    kdw_vec3 frozen[MAX_JOINTS];
    uint32_t written = 0;
    ENSURE_OK(kdw_chain_read_world(s.engine, s.chains[1], world, MAX_JOINTS, &written));
    ENSURE(written == n);
    const kdw_transform at_cull = moving_head(frame - 1);
    for (uint32_t j = 0; j < n; ++j) frozen[j] = position_in(at_cull, world[j].position);
    double worst = 0.0;
    for (int end = frame + 60; frame < end; ++frame) {
        const kdw_transform head = moving_head(frame);
        ENSURE_OK(kdw_engine_step(s.engine, FRAME_DT, &camera, &head));
        ENSURE_OK(kdw_chain_read_world(s.engine, s.chains[1], world, MAX_JOINTS, &written));
        for (uint32_t j = 0; j < n; ++j) worst = fmax(worst, v_dist(position_in(head, world[j].position), frozen[j]));
        kdw_engine_stats stats;
        ENSURE_OK(kdw_engine_get_stats(s.engine, &stats));
        ENSURE(stats.chains_asleep == 1 && stats.chain_count == 3);
    }
    ENSURE(worst < 2e-6);
    ENSURE(v_dist(moving_head(frame - 1).position, at_cull.position) > 0.2); /* the anchor really moved */

    /* Rejected calls change nothing. */
    const uint64_t hash = hash_of(s.engine);
    ENSURE_STATUS(kdw_chain_set_enabled(s.engine, s.chains[1], 2), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_chain_set_enabled(s.engine, 0, 1), KDW_STATUS_INVALID_ID);
    ENSURE_STATUS(kdw_chain_set_enabled(s.engine, s.left, 1), KDW_STATUS_INVALID_ID); /* a view shape id */
    ENSURE_STATUS(kdw_chain_set_enabled(NULL, s.chains[1], 1), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_chain_is_enabled(s.engine, s.chains[1], NULL), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_chain_is_asleep(s.engine, s.chains[1], NULL), KDW_STATUS_NULL_POINTER);
    uint32_t untouched = 7;
    ENSURE_STATUS(kdw_chain_is_asleep(s.engine, 0, &untouched), KDW_STATUS_INVALID_ID);
    ENSURE(untouched == 7);
    ENSURE(hash_of(s.engine) == hash);

    /* Enabled again: simulated (not counted) from the next step on. */
    ENSURE_OK(kdw_chain_set_enabled(s.engine, s.chains[1], 1));
    ENSURE_OK(kdw_chain_set_enabled(s.engine, s.chains[1], 1)); /* idempotent */
    const kdw_transform head = moving_head(frame - 1);
    ENSURE_OK(kdw_engine_step(s.engine, FRAME_DT, &camera, &head));
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(s.engine, &stats));
    ENSURE(stats.chains_asleep == 0);
    ENSURE_OK(kdw_chain_is_enabled(s.engine, s.chains[1], &enabled));
    ENSURE(enabled == 1);
    return 0;
}

/* kdw_chain_is_asleep and sleep_speed: a damped chain (5/s) under a still head settles and sleeps within 5 s,
 * counted in the stats; a moving head wakes it; with sleep_speed 0 the same chain never sleeps. lod 3 runs one
 * substep per 1/60 s frame. */
static int test_chain_sleeps(void)
{
    kdw_engine_def def = kdw_engine_def_default();
    ENSURE(def.sleep_speed == 5e-6f && def.lod == 0);
    kdw_engine *sleeper = engine_new(&def);
    def.sleep_speed = 0.0f;
    kdw_engine *awake = engine_new(&def);
    ENSURE(sleeper != NULL && awake != NULL);
    kdw_chain_def chain_def = kdw_chain_def_default();
    chain_def.stiffness = 0.9f;
    chain_def.damping = 5.0f;
    kdw_chain_id a = 0, b = 0;
    ENSURE_OK(kdw_chain_create(sleeper, &chain_def, g_ahoge_left.joints, g_ahoge_left.n, &a));
    ENSURE_OK(kdw_chain_create(awake, &chain_def, g_ahoge_left.joints, g_ahoge_left.n, &b));
    const kdw_transform head = head_at_rest();
    const kdw_vec3 camera = v3(0.0f, 1.7f, 2.5f);
    int fell_asleep = -1;
    uint32_t asleep = 0;
    for (int frame = 0; frame < 300; ++frame) {
        ENSURE_OK(kdw_engine_step(sleeper, FRAME_DT, &camera, &head));
        ENSURE_OK(kdw_engine_step(awake, FRAME_DT, &camera, &head));
        ENSURE_OK(kdw_chain_is_asleep(sleeper, a, &asleep));
        if (asleep && fell_asleep < 0) fell_asleep = frame;
        ENSURE_OK(kdw_chain_is_asleep(awake, b, &asleep));
        ENSURE(asleep == 0);
    }
    ENSURE(fell_asleep > 0);
    ENSURE_OK(kdw_chain_is_asleep(sleeper, a, &asleep));
    ENSURE(asleep == 1);
    kdw_engine_stats stats;
    ENSURE_OK(kdw_engine_get_stats(sleeper, &stats));
    ENSURE(stats.chains_asleep == 1);
    ENSURE_OK(kdw_engine_get_stats(awake, &stats));
    ENSURE(stats.chains_asleep == 0);
    printf("    damping 5/s: asleep after %.2f s\n", (double)((float)(fell_asleep + 1) * FRAME_DT));

    const kdw_transform moved = xf(v3(0.05f, 1.6f, 0.0f), q_identity());
    ENSURE_OK(kdw_engine_step(sleeper, FRAME_DT, &camera, &moved));
    ENSURE_OK(kdw_chain_is_asleep(sleeper, a, &asleep));
    ENSURE(asleep == 0);

    kdw_engine_def far = kdw_engine_def_default();
    far.lod = 3;
    ENSURE_OK(kdw_engine_set_def(sleeper, &far));
    ENSURE_OK(kdw_engine_get_def(sleeper, &def));
    ENSURE(def.lod == 3 && def.sleep_speed == 5e-6f);
    for (int frame = 0; frame < 6; ++frame) {
        ENSURE_OK(kdw_engine_step(sleeper, FRAME_DT, &camera, &moved));
        ENSURE_OK(kdw_engine_get_stats(sleeper, &stats));
        ENSURE(stats.substeps_last_step <= 1);
    }
    return 0;
}

/* kdw_engines_step: four engines stepped in one call per frame end in exactly the states (hashes) of four
 * engines stepped one by one; NULL, repeated handles and bad inputs fail the whole call and change no hash. */
static int test_engines_step(void)
{
    enum { COUNT = 4 };
    kdw_engine *batched[COUNT], *single[COUNT];
    for (int i = 0; i < COUNT; ++i) {
        kdw_engine **group[2] = {&batched[i], &single[i]};
        for (int g = 0; g < 2; ++g) {
            kdw_engine *e = engine_new_default();
            ENSURE(e != NULL);
            kdw_chain_def def = kdw_chain_def_default();
            def.stiffness = 0.3f + 0.15f * (float)i;
            kdw_chain_id chain = 0;
            kdw_view_shape_id shape = 0;
            kdw_vec3 left = v3(-1.0f, 0.0f, 0.0f);
            ENSURE_OK(kdw_chain_create(e, &def, g_ahoge.joints, g_ahoge.n, &chain));
            ENSURE_OK(kdw_chain_add_view_shape(e, chain, &left, g_ahoge_left.joints, g_ahoge_left.n, 1.0f, &shape));
            *group[g] = e;
        }
    }
    kdw_transform heads[COUNT];
    for (int frame = 0; frame < 90; ++frame) {
        for (int i = 0; i < COUNT; ++i)
            heads[i] = xf(v3((float)i + 0.1f * sinf(0.2f * (float)frame), 1.6f, 0.0f), q_identity());
        const kdw_vec3 camera = orbit_camera(frame);
        ENSURE_OK(kdw_engines_step(batched, COUNT, FRAME_DT, &camera, heads));
        for (int i = 0; i < COUNT; ++i) ENSURE_OK(kdw_engine_step(single[i], FRAME_DT, &camera, &heads[i]));
    }
    uint64_t hashes[COUNT];
    for (int i = 0; i < COUNT; ++i) {
        hashes[i] = hash_of(batched[i]);
        ENSURE(hashes[i] != 0 && hashes[i] == hash_of(single[i]));
        if (i > 0) ENSURE(hashes[i] != hashes[i - 1]);
    }

    const kdw_vec3 camera = orbit_camera(90);
    kdw_engine *repeated[COUNT] = {batched[0], batched[1], batched[2], batched[1]};
    ENSURE_STATUS(kdw_engines_step(repeated, COUNT, FRAME_DT, &camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    kdw_engine *with_null[COUNT] = {batched[0], batched[1], NULL, batched[3]};
    ENSURE_STATUS(kdw_engines_step(with_null, COUNT, FRAME_DT, &camera, heads), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_engines_step(NULL, COUNT, FRAME_DT, &camera, heads), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, FRAME_DT, NULL, heads), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, FRAME_DT, &camera, NULL), KDW_STATUS_NULL_POINTER);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, NAN, &camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, -1.0f, &camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    kdw_transform bad_heads[COUNT];
    memcpy(bad_heads, heads, sizeof heads);
    bad_heads[COUNT - 1].rotation = q4(0.0f, 0.0f, 0.0f, 0.0f);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, FRAME_DT, &camera, bad_heads), KDW_STATUS_INVALID_ARGUMENT);
    const kdw_vec3 far_camera = v3(2e9f, 0.0f, 0.0f);
    ENSURE_STATUS(kdw_engines_step(batched, COUNT, FRAME_DT, &far_camera, heads), KDW_STATUS_INVALID_ARGUMENT);
    for (int i = 0; i < COUNT; ++i) ENSURE(hash_of(batched[i]) == hashes[i]);

    ENSURE_OK(kdw_engines_step(NULL, 0, FRAME_DT, &camera, NULL)); /* nothing to step */
    ENSURE_OK(kdw_engines_step(batched, 2, FRAME_DT, &camera, heads)); /* a prefix */
    ENSURE(hash_of(batched[1]) != hashes[1] && hash_of(batched[2]) == hashes[2]);
    ENSURE_OK(kdw_engines_step(batched, COUNT, 0.0f, &camera, heads)); /* dt 0 changes nothing */
    ENSURE(hash_of(batched[2]) == hashes[2]);
    return 0;
}

/* kdw_collider_set_size: a limp chain resting on a 0.1 m ball is pushed out to the surface of the same ball grown
 * to 0.15 m; invalid sizes and ids are rejected without changing the state. */
static int test_collider_set_size(void)
{
    const kdw_transform anchor = xf(v3(0.0f, 1.0f, 0.0f), q_identity());
    const kdw_vec3 camera = v3(0.0f, 1.0f, 3.0f);
    const kdw_vec3 centre = v3(0.2f, 0.82f, 0.0f);
    kdw_engine *e = NULL;
    kdw_chain_id chain = 0;
    kdw_collider_id ball = 0;
    ENSURE(drape_scene(&e, 0x2u, &chain, &ball, centre) == 0);
    double small = 0.0, large = 0.0;
    for (int frame = 0; frame < 120; ++frame) ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &anchor));
    ENSURE(closest_joint(e, chain, centre, &small) == 0);
    ENSURE(small >= BALL_RADIUS - 1e-4 && small < BALL_RADIUS + 3.5e-3);

    const uint64_t hash = hash_of(e);
    ENSURE_STATUS(kdw_collider_set_size(e, ball, -0.1f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_collider_set_size(e, ball, NAN, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_collider_set_size(e, ball, 0.1f, INFINITY), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_collider_set_size(e, ball, 2e6f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_collider_set_size(e, 0, 0.1f, 0.0f), KDW_STATUS_INVALID_ID);
    ENSURE_STATUS(kdw_collider_set_size(e, chain, 0.1f, 0.0f), KDW_STATUS_INVALID_ID);
    ENSURE_STATUS(kdw_collider_set_size(NULL, ball, 0.1f, 0.0f), KDW_STATUS_NULL_POINTER);
    ENSURE(hash_of(e) == hash);

    ENSURE_OK(kdw_collider_set_size(e, ball, 0.15f, 0.0f));
    ENSURE(hash_of(e) != hash);
    for (int frame = 0; frame < 120; ++frame) {
        ENSURE_OK(kdw_engine_step(e, FRAME_DT, &camera, &anchor));
        ENSURE(closest_joint(e, chain, centre, &large) == 0);
        if (frame >= 10) ENSURE(large >= 0.15 - 1e-4); /* pushed out, then kept out */
    }
    ENSURE(large < 0.15 + 5e-3);
    printf("    ball radius 0.10 -> 0.15 m: closest joint %.4f -> %.4f m from its centre\n", small, large);

    /* Shape-specific rules as at creation: a capsule needs a size, inside shapes a radius. */
    kdw_collider_def capsule_def = collider_at(KDW_COLLIDER_CAPSULE, 0.05f, 0.1f, v3(5.0f, 0.0f, 0.0f));
    kdw_collider_def hood_def = collider_at(KDW_COLLIDER_INSIDE_SPHERE, 0.5f, 0.0f, v3(0.0f, 1.0f, 0.0f));
    hood_def.layers = 0x4u;
    kdw_collider_id capsule = 0, hood = 0;
    ENSURE_OK(kdw_collider_create(e, &capsule_def, &capsule));
    ENSURE_OK(kdw_collider_create(e, &hood_def, &hood));
    const uint64_t before = hash_of(e);
    ENSURE_STATUS(kdw_collider_set_size(e, capsule, 0.0f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE_STATUS(kdw_collider_set_size(e, hood, 0.0f, 0.0f), KDW_STATUS_INVALID_ARGUMENT);
    ENSURE(hash_of(e) == before);
    ENSURE_OK(kdw_collider_set_size(e, capsule, 0.0f, 0.2f)); /* a segment */
    ENSURE_OK(kdw_collider_set_size(e, hood, 0.6f, 0.0f));
    ENSURE_OK(kdw_collider_destroy(e, capsule));
    ENSURE_STATUS(kdw_collider_set_size(e, capsule, 0.05f, 0.1f), KDW_STATUS_INVALID_ID);
    return 0;
}

/* ---- error paths ---------------------------------------------------------------------------------------- */

static int test_error_null_engine(void)
{
    scene s; /* a witness: no call below may touch it */
    ENSURE(scene_build(&s, 1) == 0);
    kdw_engine *w = s.engine;
    const kdw_chain_id chain = s.chains[0];
    const kdw_view_shape_id view = s.left;
    const kdw_chain_def chain_def = kdw_chain_def_default();
    const kdw_engine_def engine_def = kdw_engine_def_default();
    const kdw_transform head = head_at_rest();
    const kdw_vec3 camera = v3(3.0f, 0.3f, 0.0f);
    const kdw_vec3 direction = v3(0.0f, 0.0f, 1.0f);
    const kdw_vec3 gravity = v3(0.0f, -1.0f, 0.0f);
    const kdw_transform anchors[3] = {head, head, head};

    uint32_t u = SENTINEL_U32;
    float f = -1.0f;
    uint64_t h = SENTINEL_U64;
    kdw_chain_id id_out = SENTINEL_U64;
    kdw_view_shape_id view_out = SENTINEL_U64;
    kdw_chain_def chain_def_out;
    kdw_engine_def engine_def_out;
    kdw_engine_stats stats_out;
    kdw_transform transforms[MAX_TOTAL];
    kdw_quat quats[MAX_TOTAL];
    kdw_chain_id ids[MAX_CHAINS];
    memset(&chain_def_out, SENTINEL_BYTE, sizeof chain_def_out);
    memset(&engine_def_out, SENTINEL_BYTE, sizeof engine_def_out);
    memset(&stats_out, SENTINEL_BYTE, sizeof stats_out);
    memset(transforms, SENTINEL_BYTE, sizeof transforms);
    memset(quats, SENTINEL_BYTE, sizeof quats);
    memset(ids, SENTINEL_BYTE, sizeof ids);

    const kdw_status NP = KDW_STATUS_NULL_POINTER;
    ENSURE_REJECTED(w, kdw_chain_create(NULL, &chain_def, g_ahoge.joints, g_ahoge.n, &id_out), NP);
    ENSURE_REJECTED(w, kdw_chain_destroy(NULL, chain), NP);
    ENSURE_REJECTED(w, kdw_chain_is_valid(NULL, chain, &u), NP);
    ENSURE_REJECTED(w, kdw_chain_get_def(NULL, chain, &chain_def_out), NP);
    ENSURE_REJECTED(w, kdw_chain_set_def(NULL, chain, &chain_def), NP);
    ENSURE_REJECTED(w, kdw_chain_set_base_shape(NULL, chain, g_ahoge.joints, g_ahoge.n), NP);
    ENSURE_REJECTED(w, kdw_chain_reset(NULL, chain), NP);
    ENSURE_REJECTED(w, kdw_chain_joint_count(NULL, chain, &u), NP);
    ENSURE_REJECTED(w, kdw_chain_read_world(NULL, chain, transforms, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(w, kdw_chain_read_rest_shape(NULL, chain, transforms, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(w, kdw_chain_kinetic_energy(NULL, chain, &f), NP);
    ENSURE_OK(kdw_engine_destroy(NULL)); /* NULL is a no-op, like free(NULL) */
    ENSURE_REJECTED(w, kdw_engine_get_def(NULL, &engine_def_out), NP);
    ENSURE_REJECTED(w, kdw_engine_set_def(NULL, &engine_def), NP);
    ENSURE_REJECTED(w, kdw_engine_set_gravity(NULL, &gravity), NP);
    ENSURE_REJECTED(w, kdw_engine_set_solver(NULL, KDW_SOLVER_SCALAR), NP);
    ENSURE_REJECTED(w, kdw_engine_get_solver(NULL, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_step(NULL, FRAME_DT, &camera, &head), NP);
    ENSURE_REJECTED(w, kdw_engine_set_anchors(NULL, anchors, 3), NP);
    ENSURE_REJECTED(w, kdw_engine_chain_count(NULL, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_joint_count(NULL, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_get_chain_ids(NULL, ids, MAX_CHAINS, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_read_world(NULL, transforms, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_read_local_rotations(NULL, quats, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(w, kdw_engine_get_stats(NULL, &stats_out), NP);
    ENSURE_REJECTED(w, kdw_engine_reset(NULL), NP);
    ENSURE_REJECTED(w, kdw_engine_state_hash(NULL, &h), NP);
    ENSURE_REJECTED(w, kdw_chain_add_view_shape(NULL, chain, &direction, g_ahoge.joints, g_ahoge.n, 1.0f, &view_out),
                    NP);
    ENSURE_REJECTED(w, kdw_view_shape_set_influence(NULL, view, 2.0f), NP);
    ENSURE_REJECTED(w, kdw_view_shape_set_direction(NULL, view, &direction), NP);
    ENSURE_REJECTED(w, kdw_view_shape_set_joints(NULL, view, g_ahoge.joints, g_ahoge.n), NP);
    ENSURE_REJECTED(w, kdw_view_shape_remove(NULL, view), NP);
    ENSURE_REJECTED(w, kdw_chain_view_shape_count(NULL, chain, &u), NP);

    /* outputs are written only on success */
    ENSURE(u == SENTINEL_U32 && f == -1.0f && h == SENTINEL_U64);
    ENSURE(id_out == SENTINEL_U64 && view_out == SENTINEL_U64);
    ENSURE(bytes_are(&chain_def_out, sizeof chain_def_out, SENTINEL_BYTE));
    ENSURE(bytes_are(&engine_def_out, sizeof engine_def_out, SENTINEL_BYTE));
    ENSURE(bytes_are(&stats_out, sizeof stats_out, SENTINEL_BYTE));
    ENSURE(bytes_are(transforms, sizeof transforms, SENTINEL_BYTE));
    ENSURE(bytes_are(quats, sizeof quats, SENTINEL_BYTE));
    ENSURE(bytes_are(ids, sizeof ids, SENTINEL_BYTE));
    return 0;
}

static int test_error_null_out_pointers(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    kdw_engine *e = s.engine;
    const kdw_chain_id chain = s.chains[0];
    const kdw_chain_def chain_def = kdw_chain_def_default();
    const kdw_engine_def engine_def = kdw_engine_def_default();
    const kdw_vec3 direction = v3(0.0f, 0.0f, 1.0f);
    uint32_t u = SENTINEL_U32;
    kdw_transform transforms[MAX_TOTAL];
    kdw_quat quats[MAX_TOTAL];
    kdw_chain_id ids[MAX_CHAINS];
    memset(transforms, SENTINEL_BYTE, sizeof transforms);
    memset(quats, SENTINEL_BYTE, sizeof quats);
    memset(ids, SENTINEL_BYTE, sizeof ids);
    const kdw_status NP = KDW_STATUS_NULL_POINTER;

    ENSURE_REJECTED(e, kdw_engine_create(&engine_def, NULL), NP); /* and no engine leaks (valgrind) */
    ENSURE_REJECTED(e, kdw_chain_create(e, &chain_def, g_tail.joints, g_tail.n, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_is_valid(e, chain, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_get_def(e, chain, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_joint_count(e, chain, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_read_world(e, chain, NULL, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(e, kdw_chain_read_world(e, chain, transforms, MAX_TOTAL, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_read_rest_shape(e, chain, NULL, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(e, kdw_chain_read_rest_shape(e, chain, transforms, MAX_TOTAL, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_kinetic_energy(e, chain, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_get_def(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_chain_count(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_joint_count(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_get_chain_ids(e, NULL, MAX_CHAINS, &u), NP);
    ENSURE_REJECTED(e, kdw_engine_get_chain_ids(e, ids, MAX_CHAINS, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_read_world(e, NULL, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(e, kdw_engine_read_world(e, transforms, MAX_TOTAL, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_read_local_rotations(e, NULL, MAX_TOTAL, &u), NP);
    ENSURE_REJECTED(e, kdw_engine_read_local_rotations(e, quats, MAX_TOTAL, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_get_stats(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_get_solver(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_state_hash(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &direction, g_ahoge.joints, g_ahoge.n, 1.0f, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_view_shape_count(e, chain, NULL), NP);

    ENSURE(u == SENTINEL_U32);
    ENSURE(bytes_are(transforms, sizeof transforms, SENTINEL_BYTE));
    ENSURE(bytes_are(quats, sizeof quats, SENTINEL_BYTE));
    ENSURE(bytes_are(ids, sizeof ids, SENTINEL_BYTE));
    ENSURE_OK(kdw_engine_chain_count(e, &u));
    ENSURE(u == 3);
    ENSURE_OK(kdw_chain_view_shape_count(e, chain, &u));
    ENSURE(u == 2);
    return 0;
}

static int test_error_null_inputs(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_chain_id chain = s.chains[0];
    const kdw_chain_def chain_def = kdw_chain_def_default();
    const kdw_transform head = head_at_rest();
    const kdw_vec3 camera = v3(3.0f, 0.3f, 0.0f);
    const kdw_vec3 direction = v3(0.0f, 0.0f, 1.0f);
    kdw_engine *engine_out = (kdw_engine *)(void *)&s; /* any non-NULL marker */
    kdw_chain_id id_out = SENTINEL_U64;
    kdw_view_shape_id view_out = SENTINEL_U64;
    const kdw_status NP = KDW_STATUS_NULL_POINTER;

    ENSURE_REJECTED(e, kdw_engine_create(NULL, &engine_out), NP);
    ENSURE(engine_out == (kdw_engine *)(void *)&s);
    ENSURE_REJECTED(e, kdw_engine_set_def(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_set_gravity(e, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_create(e, NULL, g_tail.joints, g_tail.n, &id_out), NP);
    ENSURE_REJECTED(e, kdw_chain_create(e, &chain_def, NULL, g_tail.n, &id_out), NP);
    ENSURE_REJECTED(e, kdw_chain_set_def(e, chain, NULL), NP);
    ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, chain, NULL, g_ahoge.n), NP);
    ENSURE_REJECTED(e, kdw_engine_step(e, FRAME_DT, NULL, &head), NP);
    ENSURE_REJECTED(e, kdw_engine_step(e, FRAME_DT, &camera, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_step(e, FRAME_DT, NULL, NULL), NP);
    ENSURE_REJECTED(e, kdw_engine_set_anchors(e, NULL, 3), NP);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, NULL, g_ahoge.joints, g_ahoge.n, 1.0f, &view_out), NP);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &direction, NULL, g_ahoge.n, 1.0f, &view_out), NP);
    ENSURE_REJECTED(e, kdw_view_shape_set_direction(e, s.left, NULL), NP);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, s.left, NULL, g_ahoge.n), NP);
    ENSURE(id_out == SENTINEL_U64 && view_out == SENTINEL_U64);
    return 0;
}

/* Every chain-id taking call rejects `bad`; kdw_chain_is_valid answers 0 for it. */
static int check_bad_chain_id(kdw_engine *e, kdw_chain_id bad)
{
    const kdw_chain_def chain_def = kdw_chain_def_default();
    const kdw_vec3 direction = v3(0.0f, 0.0f, 1.0f);
    const kdw_status ID = KDW_STATUS_INVALID_ID;
    uint32_t u = SENTINEL_U32;
    float f = -1.0f;
    kdw_view_shape_id view_out = SENTINEL_U64;
    kdw_chain_def def_out;
    kdw_transform transforms[MAX_JOINTS];
    memset(&def_out, SENTINEL_BYTE, sizeof def_out);
    memset(transforms, SENTINEL_BYTE, sizeof transforms);

    ENSURE_OK(kdw_chain_is_valid(e, bad, &u));
    ENSURE(u == 0);
    u = SENTINEL_U32;
    ENSURE_REJECTED(e, kdw_chain_destroy(e, bad), ID);
    ENSURE_REJECTED(e, kdw_chain_get_def(e, bad, &def_out), ID);
    ENSURE_REJECTED(e, kdw_chain_set_def(e, bad, &chain_def), ID);
    ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, bad, g_ahoge.joints, g_ahoge.n), ID);
    ENSURE_REJECTED(e, kdw_chain_reset(e, bad), ID);
    ENSURE_REJECTED(e, kdw_chain_joint_count(e, bad, &u), ID);
    ENSURE_REJECTED(e, kdw_chain_read_world(e, bad, transforms, MAX_JOINTS, &u), ID);
    ENSURE_REJECTED(e, kdw_chain_read_rest_shape(e, bad, transforms, MAX_JOINTS, &u), ID);
    ENSURE_REJECTED(e, kdw_chain_kinetic_energy(e, bad, &f), ID);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, bad, &direction, g_ahoge.joints, g_ahoge.n, 1.0f, &view_out), ID);
    ENSURE_REJECTED(e, kdw_chain_view_shape_count(e, bad, &u), ID);
    ENSURE(u == SENTINEL_U32 && f == -1.0f && view_out == SENTINEL_U64);
    ENSURE(bytes_are(&def_out, sizeof def_out, SENTINEL_BYTE));
    ENSURE(bytes_are(transforms, sizeof transforms, SENTINEL_BYTE));
    return 0;
}

/* Every view-shape-id taking call rejects `bad`. */
static int check_bad_view_shape_id(kdw_engine *e, kdw_view_shape_id bad)
{
    const kdw_vec3 direction = v3(0.0f, 0.0f, 1.0f);
    const kdw_status ID = KDW_STATUS_INVALID_ID;
    ENSURE_REJECTED(e, kdw_view_shape_set_influence(e, bad, 2.0f), ID);
    ENSURE_REJECTED(e, kdw_view_shape_set_direction(e, bad, &direction), ID);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, bad, g_ahoge_left.joints, g_ahoge_left.n), ID);
    ENSURE_REJECTED(e, kdw_view_shape_remove(e, bad), ID);
    return 0;
}

static int test_error_ids(void)
{
    scene a, b;
    ENSURE(scene_build(&a, 1) == 0);
    ENSURE(scene_build(&b, 1) == 0);
    ENSURE(step_frames(a.engine, 0, 5) == 0);
    kdw_engine *e = a.engine;
    const kdw_chain_def def = kdw_chain_def_default();
    const kdw_vec3 direction = v3(0.0f, 0.0f, -1.0f);

    /* stale ids: a destroyed chain (also after its slot is reused) and a removed view shape */
    kdw_chain_id stale = 0, reused = 0;
    kdw_view_shape_id stale_view = 0, orphan_view = 0;
    ENSURE_OK(kdw_chain_create(e, &def, g_ahoge.joints, g_ahoge.n, &stale));
    ENSURE_OK(kdw_chain_add_view_shape(e, stale, &direction, g_ahoge_left.joints, g_ahoge_left.n, 1.0f,
                                       &orphan_view));
    ENSURE_OK(kdw_chain_add_view_shape(e, a.chains[1], &direction, g_side_lock.joints, g_side_lock.n, 1.0f,
                                       &stale_view));
    ENSURE_OK(kdw_view_shape_remove(e, stale_view));
    ENSURE_OK(kdw_chain_destroy(e, stale));

    ENSURE(check_bad_chain_id(e, 0) == 0);                         /* null */
    ENSURE(check_bad_chain_id(e, stale) == 0);                     /* stale */
    ENSURE(check_bad_chain_id(e, b.chains[0]) == 0);               /* foreign */
    ENSURE(check_bad_chain_id(e, a.left) == 0);                    /* a view-shape id */
    ENSURE(check_bad_chain_id(e, 0x123456789ABCDEF0ull) == 0);     /* garbage */
    ENSURE(check_bad_chain_id(e, UINT64_MAX) == 0);                /* garbage */
    ENSURE(check_bad_view_shape_id(e, 0) == 0);                    /* null */
    ENSURE(check_bad_view_shape_id(e, stale_view) == 0);           /* removed */
    ENSURE(check_bad_view_shape_id(e, orphan_view) == 0);          /* its chain was destroyed */
    ENSURE(check_bad_view_shape_id(e, b.left) == 0);               /* foreign */
    ENSURE(check_bad_view_shape_id(e, a.chains[0]) == 0);          /* a chain id */

    ENSURE_OK(kdw_chain_create(e, &def, g_ahoge.joints, g_ahoge.n, &reused));
    ENSURE(reused != stale);
    ENSURE(check_bad_chain_id(e, stale) == 0);             /* still stale with its slot in use again */
    ENSURE(check_bad_view_shape_id(e, orphan_view) == 0);  /* and so are its view shapes */
    kdw_view_shape_id fresh_view = 0;
    ENSURE_OK(kdw_chain_add_view_shape(e, reused, &direction, g_ahoge_left.joints, g_ahoge_left.n, 1.0f, &fresh_view));
    ENSURE(fresh_view != orphan_view && fresh_view != stale_view);
    ENSURE(check_bad_view_shape_id(e, orphan_view) == 0);
    ENSURE(check_bad_view_shape_id(e, stale_view) == 0);

    /* the foreign ids are fine on their own engine, and b was not touched */
    uint32_t valid = SENTINEL_U32;
    ENSURE_OK(kdw_chain_is_valid(b.engine, b.chains[0], &valid));
    ENSURE(valid == 1);
    ENSURE_OK(kdw_view_shape_set_influence(b.engine, b.left, 1.5f));
    return 0;
}

static int test_error_step_inputs(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 10) == 0);
    kdw_engine *e = s.engine;
    const kdw_transform head = head_at_rest();
    const kdw_vec3 camera = orbit_camera(10);
    const kdw_status IA = KDW_STATUS_INVALID_ARGUMENT;
    kdw_engine_stats before, after;
    ENSURE_OK(kdw_engine_get_stats(e, &before));

    ENSURE_REJECTED(e, kdw_engine_step(e, NAN, &camera, &head), IA);
    ENSURE_REJECTED(e, kdw_engine_step(e, INFINITY, &camera, &head), IA);
    ENSURE_REJECTED(e, kdw_engine_step(e, -INFINITY, &camera, &head), IA);
    ENSURE_REJECTED(e, kdw_engine_step(e, -FRAME_DT, &camera, &head), IA);
    ENSURE_REJECTED(e, kdw_engine_step(e, -1e-30f, &camera, &head), IA);

    const kdw_vec3 bad_cameras[] = {v3(NAN, 0.3f, 3.0f), v3(3.0f, INFINITY, 0.0f), v3(3.0f, 0.3f, -INFINITY)};
    for (size_t i = 0; i < sizeof bad_cameras / sizeof bad_cameras[0]; ++i) {
        ENSURE_REJECTED(e, kdw_engine_step(e, FRAME_DT, &bad_cameras[i], &head), IA);
    }

    kdw_transform bad_heads[8];
    for (int i = 0; i < 8; ++i) {
        bad_heads[i] = head;
    }
    bad_heads[0].position.x = NAN;
    bad_heads[1].position.y = INFINITY;
    bad_heads[2].position.z = -INFINITY;
    bad_heads[3].rotation.w = NAN;
    bad_heads[4].rotation.x = INFINITY;
    bad_heads[5].rotation = q4(0.0f, 0.0f, 0.0f, 0.0f);
    bad_heads[6].rotation = q4(NAN, NAN, NAN, NAN);
    bad_heads[7].rotation = q4(0.0f, -0.0f, 0.0f, -0.0f);
    for (int i = 0; i < 8; ++i) {
        ENSURE_REJECTED(e, kdw_engine_step(e, FRAME_DT, &camera, &bad_heads[i]), IA);
    }

    ENSURE_OK(kdw_engine_get_stats(e, &after));
    ENSURE(after.substeps_total == before.substeps_total && after.simulated_time == before.simulated_time);
    /* and the engine still works */
    ENSURE(step_frames(e, 10, 1) == 0);
    return 0;
}

static int test_error_chain_shapes(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_chain_def def = kdw_chain_def_default();
    const kdw_status IA = KDW_STATUS_INVALID_ARGUMENT;
    kdw_chain_id id_out = SENTINEL_U64;

    /* too few joints */
    ENSURE_REJECTED(e, kdw_chain_create(e, &def, g_ahoge.joints, 0, &id_out), IA);
    ENSURE_REJECTED(e, kdw_chain_create(e, &def, NULL, 0, &id_out), IA);
    ENSURE_REJECTED(e, kdw_chain_create(e, &def, g_ahoge.joints, 1, &id_out), IA);

    /* broken shapes, each at create and as a new base shape of a live chain */
    chain_spec bad[7];
    for (int i = 0; i < 7; ++i) {
        bad[i] = g_ahoge;
    }
    bad[0].joints[3].position = bad[0].joints[2].position;  /* zero-length segment */
    bad[1].joints[1].position = bad[1].joints[0].position;  /* zero-length first segment */
    bad[2].joints[3].position.x = NAN;                      /* NaN position */
    bad[3].joints[7].position.y = INFINITY;                 /* Inf position */
    bad[4].joints[2].rotation.z = NAN;                      /* NaN rotation */
    bad[5].joints[5].rotation = q4(0.0f, 0.0f, 0.0f, 0.0f); /* null quaternion */
    bad[6].joints[0].rotation.w = -INFINITY;                /* Inf rotation */
    for (int i = 0; i < 7; ++i) {
        ENSURE_REJECTED(e, kdw_chain_create(e, &def, bad[i].joints, bad[i].n, &id_out), IA);
        ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, s.chains[0], bad[i].joints, bad[i].n), IA);
    }
    /* a new base shape must keep the joint count */
    ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, s.chains[0], g_ahoge.joints, g_ahoge.n - 1), IA);
    ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, s.chains[1], g_ahoge.joints, g_ahoge.n), IA);
    ENSURE_REJECTED(e, kdw_chain_set_base_shape(e, s.chains[0], g_ahoge.joints, 0), IA);

    ENSURE(id_out == SENTINEL_U64);
    uint32_t count = 0;
    ENSURE_OK(kdw_engine_chain_count(e, &count));
    ENSURE(count == 3);
    /* a valid replacement base is accepted */
    ENSURE_OK(kdw_chain_set_base_shape(e, s.chains[0], g_ahoge_right.joints, g_ahoge_right.n));
    return 0;
}

static int test_error_view_shapes(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_chain_id chain = s.chains[0];
    const kdw_status IA = KDW_STATUS_INVALID_ARGUMENT;
    const kdw_vec3 good = v3(0.0f, 0.0f, 1.0f);
    kdw_view_shape_id out = SENTINEL_U64;
    const chain_spec *j = &g_ahoge_left;

    /* wrong joint count */
    chain_spec longer = *j;
    longer.n = j->n + 1;
    longer.joints[j->n] = xf(v_add(j->joints[j->n - 1].position, v3(0.0f, 0.05f, 0.0f)), q_identity());
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, j->joints, j->n - 1, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, longer.joints, longer.n, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, NULL, 0, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, s.chains[1], &good, j->joints, j->n, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, s.left, j->joints, j->n - 1), IA);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, s.left, longer.joints, longer.n), IA);

    /* broken joints */
    chain_spec zero = *j, nan_joint = *j;
    zero.joints[4].position = zero.joints[5].position;
    nan_joint.joints[6].rotation.y = NAN;
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, zero.joints, zero.n, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, nan_joint.joints, nan_joint.n, 1.0f, &out), IA);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, s.left, zero.joints, zero.n), IA);
    ENSURE_REJECTED(e, kdw_view_shape_set_joints(e, s.left, nan_joint.joints, nan_joint.n), IA);

    /* bad directions */
    const kdw_vec3 bad_directions[] = {v3(0.0f, 0.0f, 0.0f), v3(NAN, 0.0f, 1.0f), v3(0.0f, INFINITY, 0.0f),
                                       v3(-INFINITY, 0.0f, 0.0f)};
    for (size_t i = 0; i < sizeof bad_directions / sizeof bad_directions[0]; ++i) {
        ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &bad_directions[i], j->joints, j->n, 1.0f, &out), IA);
        ENSURE_REJECTED(e, kdw_view_shape_set_direction(e, s.left, &bad_directions[i]), IA);
    }

    /* bad influences */
    const float bad_influences[] = {0.0f, -0.0f, -1.0f, NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof bad_influences / sizeof bad_influences[0]; ++i) {
        ENSURE_REJECTED(e, kdw_chain_add_view_shape(e, chain, &good, j->joints, j->n, bad_influences[i], &out), IA);
        ENSURE_REJECTED(e, kdw_view_shape_set_influence(e, s.left, bad_influences[i]), IA);
    }

    ENSURE(out == SENTINEL_U64);
    uint32_t count = 0;
    ENSURE_OK(kdw_chain_view_shape_count(e, chain, &count));
    ENSURE(count == 2);
    /* the valid versions are accepted */
    const kdw_vec3 tiny_but_fine = v3(0.0f, 1e-3f, 0.0f);
    ENSURE_OK(kdw_view_shape_set_direction(e, s.left, &tiny_but_fine));
    ENSURE_OK(kdw_view_shape_set_influence(e, s.left, 0.25f));
    ENSURE_OK(kdw_view_shape_set_joints(e, s.left, g_ahoge_right.joints, g_ahoge_right.n));
    ENSURE_OK(kdw_chain_add_view_shape(e, chain, &good, j->joints, j->n, 1.0f, &out));
    ENSURE(out != SENTINEL_U64 && out != 0);
    return 0;
}

static int test_error_chain_def(void)
{
    scene s;
    ENSURE(scene_build(&s, 0) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_chain_id chain = s.chains[1];
    kdw_chain_id out = SENTINEL_U64;
    const kdw_chain_def good = kdw_chain_def_default();

    const uint32_t bad_sizes[] = {0, (uint32_t)sizeof(kdw_chain_def) - 4, (uint32_t)sizeof(kdw_chain_def) + 4, 1000};
    for (size_t i = 0; i < sizeof bad_sizes / sizeof bad_sizes[0]; ++i) {
        kdw_chain_def def = good;
        def.struct_size = bad_sizes[i];
        ENSURE_REJECTED(e, kdw_chain_create(e, &def, g_tail.joints, g_tail.n, &out), KDW_STATUS_STRUCT_SIZE_MISMATCH);
        ENSURE_REJECTED(e, kdw_chain_set_def(e, chain, &def), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    }

    kdw_chain_def bad[20];
    int n = 0;
    for (int i = 0; i < 20; ++i) {
        bad[i] = good;
    }
    bad[n++].stiffness = 2.0f;
    bad[n++].stiffness = NAN;
    bad[n++].stiffness = -0.1f;
    bad[n++].anchor = 7;
    bad[n++].anchor = 2;
    bad[n++].anchor = 0xFFFFFFFFu;
    bad[n++].damping = -1.0f;
    bad[n++].damping = 1001.0f;
    bad[n++].damping = NAN;
    bad[n++].momentum_suppression = 1.5f;
    bad[n++].momentum_suppression = NAN;
    bad[n++].mass = 0.0f;
    bad[n++].mass = -1.0f;
    bad[n++].mass = INFINITY;
    bad[n++].radius = -0.01f;
    bad[n++].radius = NAN;
    bad[n++].gravity_scale = 101.0f;
    bad[n++].gravity_scale = NAN;
    for (int i = 0; i < n; ++i) {
        ENSURE_REJECTED(e, kdw_chain_create(e, &bad[i], g_tail.joints, g_tail.n, &out), KDW_STATUS_INVALID_ARGUMENT);
        ENSURE_REJECTED(e, kdw_chain_set_def(e, chain, &bad[i]), KDW_STATUS_INVALID_ARGUMENT);
    }
    ENSURE(out == SENTINEL_U64);
    kdw_chain_def got;
    ENSURE_OK(kdw_chain_get_def(e, chain, &got));
    ENSURE(memcmp(&got, &good, sizeof got) == 0);
    return 0;
}

static int test_error_engine_def(void)
{
    scene s; /* the target of set_def, and the witness for create */
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_engine_def good = kdw_engine_def_default();
    kdw_engine *const marker = (kdw_engine *)(void *)&s;
    kdw_engine *out = marker;

    const uint32_t bad_sizes[] = {0, (uint32_t)sizeof(kdw_engine_def) - 4, (uint32_t)sizeof(kdw_engine_def) + 4};
    for (size_t i = 0; i < sizeof bad_sizes / sizeof bad_sizes[0]; ++i) {
        kdw_engine_def def = good;
        def.struct_size = bad_sizes[i];
        ENSURE_REJECTED(e, kdw_engine_create(&def, &out), KDW_STATUS_STRUCT_SIZE_MISMATCH);
        ENSURE_REJECTED(e, kdw_engine_set_def(e, &def), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    }

    kdw_engine_def bad[24];
    int n = 0;
    for (int i = 0; i < 24; ++i) {
        bad[i] = good;
    }
    bad[n++].substep_rate = 0.0f;
    bad[n++].substep_rate = NAN;
    bad[n++].substep_rate = 29.0f;
    bad[n++].substep_rate = 10001.0f;
    bad[n++].substep_rate = INFINITY;
    bad[n++].iterations = 0;
    bad[n++].iterations = 65;
    bad[n++].max_substeps = 0;
    bad[n++].max_substeps = 1001;
    bad[n++].time_scale = -1.0f;
    bad[n++].time_scale = 101.0f;
    bad[n++].time_scale = NAN;
    bad[n++].teleport_distance = 0.0f;
    bad[n++].teleport_distance = -1.0f;
    bad[n++].teleport_distance = NAN;
    bad[n++].teleport_distance = INFINITY;
    bad[n++].teleport_angle = 0.0f;
    bad[n++].teleport_angle = NAN;
    bad[n++].gravity.y = NAN;
    bad[n++].gravity.x = INFINITY;
    for (int i = 0; i < n; ++i) {
        ENSURE_REJECTED(e, kdw_engine_create(&bad[i], &out), KDW_STATUS_INVALID_ARGUMENT);
        ENSURE_REJECTED(e, kdw_engine_set_def(e, &bad[i]), KDW_STATUS_INVALID_ARGUMENT);
    }
    ENSURE(out == marker);

    const kdw_vec3 bad_gravity[] = {v3(NAN, 0.0f, 0.0f), v3(0.0f, -INFINITY, 0.0f)};
    for (size_t i = 0; i < sizeof bad_gravity / sizeof bad_gravity[0]; ++i) {
        ENSURE_REJECTED(e, kdw_engine_set_gravity(e, &bad_gravity[i]), KDW_STATUS_INVALID_ARGUMENT);
    }
    kdw_engine_def got;
    ENSURE_OK(kdw_engine_get_def(e, &got));
    ENSURE(memcmp(&got, &good, sizeof got) == 0);
    return 0;
}

static int test_error_buffers(void)
{
    scene s;
    ENSURE(scene_build(&s, 1) == 0);
    ENSURE(step_frames(s.engine, 0, 5) == 0);
    kdw_engine *e = s.engine;
    const kdw_status BTS = KDW_STATUS_BUFFER_TOO_SMALL;
    kdw_transform transforms[MAX_TOTAL];
    kdw_quat quats[MAX_TOTAL];
    kdw_chain_id ids[MAX_CHAINS];
    memset(transforms, SENTINEL_BYTE, sizeof transforms);
    memset(quats, SENTINEL_BYTE, sizeof quats);
    memset(ids, SENTINEL_BYTE, sizeof ids);
    uint32_t written = SENTINEL_U32;

    ENSURE_REJECTED(e, kdw_engine_read_world(e, transforms, 18, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_read_world(e, transforms, 1, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_read_world(e, NULL, 0, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_read_local_rotations(e, quats, 18, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_read_local_rotations(e, NULL, 0, &written), BTS);
    ENSURE_REJECTED(e, kdw_chain_read_world(e, s.chains[0], transforms, 7, &written), BTS);
    ENSURE_REJECTED(e, kdw_chain_read_world(e, s.chains[0], NULL, 0, &written), BTS);
    ENSURE_REJECTED(e, kdw_chain_read_rest_shape(e, s.chains[0], transforms, 7, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_get_chain_ids(e, ids, 2, &written), BTS);
    ENSURE_REJECTED(e, kdw_engine_get_chain_ids(e, NULL, 0, &written), BTS);
    ENSURE(written == SENTINEL_U32);
    ENSURE(bytes_are(transforms, sizeof transforms, SENTINEL_BYTE));
    ENSURE(bytes_are(quats, sizeof quats, SENTINEL_BYTE));
    ENSURE(bytes_are(ids, sizeof ids, SENTINEL_BYTE));

    /* exactly large enough: written in full, nothing beyond touched */
    ENSURE_OK(kdw_engine_read_world(e, transforms, 19, &written));
    ENSURE(written == 19);
    ENSURE(bytes_are(transforms + 19, sizeof transforms - 19 * sizeof transforms[0], SENTINEL_BYTE));
    ENSURE_OK(kdw_engine_read_local_rotations(e, quats, 19, &written));
    ENSURE(written == 19);
    ENSURE(bytes_are(quats + 19, sizeof quats - 19 * sizeof quats[0], SENTINEL_BYTE));
    ENSURE_OK(kdw_engine_get_chain_ids(e, ids, 3, &written));
    ENSURE(written == 3);
    ENSURE(bytes_are(ids + 3, sizeof ids - 3 * sizeof ids[0], SENTINEL_BYTE));
    memset(transforms, SENTINEL_BYTE, sizeof transforms);
    ENSURE_OK(kdw_chain_read_rest_shape(e, s.chains[0], transforms, 8, &written));
    ENSURE(written == 8);
    ENSURE(bytes_are(transforms + 8, sizeof transforms - 8 * sizeof transforms[0], SENTINEL_BYTE));
    return 0;
}

static int test_last_error_message(void)
{
    scene s;
    ENSURE(scene_build(&s, 0) == 0);
    const kdw_transform head = head_at_rest();
    const kdw_vec3 camera = v3(3.0f, 0.3f, 0.0f);
    ENSURE_STATUS(kdw_engine_step(s.engine, NAN, &camera, &head), KDW_STATUS_INVALID_ARGUMENT);

    uint32_t length = SENTINEL_U32;
    ENSURE_OK(kdw_last_error_message(NULL, 0, &length)); /* length query */
    ENSURE(length > 4 && length < 400);
    ENSURE_OK(kdw_last_error_message(NULL, 0, NULL));
    char full[512];
    uint32_t full_length = SENTINEL_U32;
    ENSURE_OK(kdw_last_error_message(full, (uint32_t)sizeof full, &full_length));
    ENSURE(full_length == length && strlen(full) == length);
    ENSURE(strstr(full, "dt") != NULL); /* it talks about the argument that was wrong */

    /* truncation: capacity 4 -> 3 characters + NUL, full length reported, nothing beyond written */
    char small[8];
    memset(small, 'X', sizeof small);
    uint32_t reported = SENTINEL_U32;
    ENSURE_STATUS(kdw_last_error_message(small, 4, &reported), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(reported == length);
    ENSURE(small[3] == '\0' && memcmp(small, full, 3) == 0);
    ENSURE(small[4] == 'X' && small[5] == 'X' && small[6] == 'X' && small[7] == 'X');

    /* exactly the length is one too small (the NUL); length + 1 fits */
    char exact[512];
    memset(exact, 'X', sizeof exact);
    ENSURE_STATUS(kdw_last_error_message(exact, length, &reported), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(exact[length - 1] == '\0' && memcmp(exact, full, length - 1) == 0 && exact[length] == 'X');
    ENSURE_OK(kdw_last_error_message(exact, length + 1, &reported));
    ENSURE(strcmp(exact, full) == 0 && reported == length);
    ENSURE_STATUS(kdw_last_error_message(exact, 1, NULL), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(exact[0] == '\0');

    /* capacity 0 with a buffer: nothing written; a NULL buffer with capacity > 0 is a NULL pointer */
    memset(small, 'X', sizeof small);
    ENSURE_STATUS(kdw_last_error_message(small, 0, &reported), KDW_STATUS_BUFFER_TOO_SMALL);
    ENSURE(bytes_are(small, sizeof small, 'X'));
    reported = SENTINEL_U32;
    ENSURE_STATUS(kdw_last_error_message(NULL, 16, &reported), KDW_STATUS_NULL_POINTER);
    ENSURE(reported == SENTINEL_U32);

    /* neither that nor successful calls replace the message */
    uint32_t count = 0;
    ENSURE_OK(kdw_engine_chain_count(s.engine, &count));
    ENSURE(step_frames(s.engine, 0, 1) == 0);
    ENSURE_OK(kdw_last_error_message(exact, (uint32_t)sizeof exact, &reported));
    ENSURE(strcmp(exact, full) == 0);

    /* a new failure replaces it */
    ENSURE_STATUS(kdw_chain_destroy(s.engine, 0), KDW_STATUS_INVALID_ID);
    ENSURE_OK(kdw_last_error_message(exact, (uint32_t)sizeof exact, &reported));
    ENSURE(reported > 0 && strcmp(exact, full) != 0);
    return 0;
}

int main(void)
{
    init_shapes();
    printf("kodawari %s (ABI %u) C tests\n", kdw_version_string(), (unsigned)kdw_abi_version());

    RUN_TEST(test_last_error_initially_empty); /* first: no call may have failed before it */
    RUN_TEST(test_layout);
    RUN_TEST(test_version);
    RUN_TEST(test_defaults_and_settings);
    RUN_TEST(test_life_cycle);
    RUN_TEST(test_view_dependence);
    RUN_TEST(test_own_anchors);
    RUN_TEST(test_step_and_read);
    RUN_TEST(test_engine_without_chains);
    RUN_TEST(test_substep_clock);
    RUN_TEST(test_determinism_without_view_shapes);
    RUN_TEST(test_determinism_with_view_shapes);
    RUN_TEST(test_solver_selection);
    RUN_TEST(test_teleport_camera_on_head_and_new_base);
    RUN_TEST(test_dt_zero_changes_nothing);
    RUN_TEST(test_non_unit_view_reference);
    RUN_TEST(test_collider_life_cycle);
    RUN_TEST(test_chain_stays_outside_sphere_collider);
    RUN_TEST(test_engine_teleport_carries_chains);
    RUN_TEST(test_teleport_mode_reset);
    RUN_TEST(test_engine_scale);
    RUN_TEST(test_chain_enabled);
    RUN_TEST(test_chain_sleeps);
    RUN_TEST(test_engines_step);
    RUN_TEST(test_collider_set_size);
    RUN_TEST(test_error_null_engine);
    RUN_TEST(test_error_null_out_pointers);
    RUN_TEST(test_error_null_inputs);
    RUN_TEST(test_error_ids);
    RUN_TEST(test_error_step_inputs);
    RUN_TEST(test_error_chain_shapes);
    RUN_TEST(test_error_view_shapes);
    RUN_TEST(test_error_chain_def);
    RUN_TEST(test_error_engine_def);
    RUN_TEST(test_error_collider_def);
    RUN_TEST(test_error_collider_transforms_and_joint_radii);
    RUN_TEST(test_error_buffers);
    RUN_TEST(test_last_error_message);
    RUN_TEST(test_sketch_layout_and_defaults);
    RUN_TEST(test_sketch_follows_fitting_strokes);
    RUN_TEST(test_sketch_round_trip);
    RUN_TEST(test_sketch_duplicate_points);
    RUN_TEST(test_sketch_camera_down_the_chain);
    RUN_TEST(test_sketch_errors);
    RUN_TEST(test_sketch_result_feeds_a_view_shape);

    return HARNESS_SUMMARY();
}
