/* kodawari C quick start: one engine, one chain with two view shapes, a camera orbiting the head. */
#include <math.h>
#include <stdio.h>
#include "kodawari.h"

#define JOINTS 6

static int check(kdw_status status, const char *what) {
    if (status == KDW_STATUS_OK) return 0;
    char message[256];
    kdw_last_error_message(message, sizeof message, NULL);
    fprintf(stderr, "%s failed: %s (%s)\n", what, kdw_status_str(status), message);
    return 1;
}

int main(void) {
    if (kdw_abi_version() != KDW_ABI_VERSION) return 1;

    kdw_engine_def engine_def = kdw_engine_def_default();
    kdw_engine *engine = NULL;
    if (check(kdw_engine_create(&engine_def, &engine), "create engine")) return 1;

    /* An ahoge standing up from the top of the head, in the head's frame (the view reference K). */
    kdw_transform base[JOINTS], left[JOINTS], right[JOINTS];
    for (int i = 0; i < JOINTS; ++i) {
        float t = (float)i;
        kdw_quat identity = {0.0f, 0.0f, 0.0f, 1.0f};
        base[i] = (kdw_transform){{0.0f, 0.12f + 0.03f * t, 0.0f}, identity};
        left[i] = (kdw_transform){{-0.01f * t * t, 0.12f + 0.025f * t, 0.0f}, identity};
        right[i] = (kdw_transform){{0.01f * t * t, 0.12f + 0.025f * t, 0.0f}, identity};
    }
    kdw_chain_def chain_def = kdw_chain_def_default();
    chain_def.stiffness = 0.9f;
    kdw_chain_id ahoge = 0;
    if (check(kdw_chain_create(engine, &chain_def, base, JOINTS, &ahoge), "create chain")) return 1;

    /* Seen from the head's left (-x) it curls left; from the right it curls right. */
    kdw_vec3 from_left = {-1.0f, 0.0f, 0.0f}, from_right = {1.0f, 0.0f, 0.0f};
    kdw_view_shape_id shape_left = 0, shape_right = 0;
    if (check(kdw_chain_add_view_shape(engine, ahoge, &from_left, left, JOINTS, 1.0f, &shape_left), "add left")) return 1;
    if (check(kdw_chain_add_view_shape(engine, ahoge, &from_right, right, JOINTS, 1.0f, &shape_right), "add right"))
        return 1;

    kdw_transform head = {{0.0f, 1.6f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}};
    kdw_transform joints[JOINTS];
    uint32_t written = 0;
    for (int frame = 0; frame <= 240; ++frame) {
        float angle = 6.2831853f * (float)frame / 240.0f;
        kdw_vec3 camera = {2.5f * sinf(angle), 1.7f, 2.5f * cosf(angle)};
        if (check(kdw_engine_step(engine, 1.0f / 60.0f, &camera, &head), "step")) return 1;
        if (check(kdw_engine_read_world(engine, joints, JOINTS, &written), "read")) return 1;
        if (frame % 60 == 0)
            printf("frame %3d: camera at %5.1f deg, ahoge tip at (%+.3f, %.3f, %+.3f)\n", frame,
                   (double)(angle * 57.29578f), (double)joints[JOINTS - 1].position.x,
                   (double)joints[JOINTS - 1].position.y, (double)joints[JOINTS - 1].position.z);
    }
    return check(kdw_engine_destroy(engine), "destroy engine");
}
