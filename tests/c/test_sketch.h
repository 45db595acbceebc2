/*
 * C tests of the sketch tool (kdw_shape_from_stroke, kdw_stroke_camera_*), defined in test_sketch.c and run
 * by main() in test_kodawari.c. Each returns 0 on success (see harness.h).
 */

#ifndef KDW_TEST_SKETCH_H
#define KDW_TEST_SKETCH_H

int test_sketch_layout_and_defaults(void);
int test_sketch_follows_fitting_strokes(void);
int test_sketch_round_trip(void);
int test_sketch_duplicate_points(void);
int test_sketch_camera_down_the_chain(void);
int test_sketch_errors(void);
int test_sketch_result_feeds_a_view_shape(void);

#endif /* KDW_TEST_SKETCH_H */
