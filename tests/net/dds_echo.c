/* An independent subscriber to mixpilot's telemetry (SPEC §9): plain C on Cyclone DDS, built
 * from the same IDL but not linked with any of mixpilot's code, as a ROS 2 tool would be.
 * Listens for SECONDS on rt/mixpilot/{pose,lambda,predicted_path,reference_path} in DOMAIN and
 * prints, per topic, the type name, the sample count and the last values.
 * Usage: dds_echo DOMAIN SECONDS */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>

#include "ros2_msgs.h"

static dds_entity_t reader(dds_entity_t pp, const dds_topic_descriptor_t* d, const char* name) {
  dds_entity_t t = dds_create_topic(pp, d, name, NULL, NULL);
  return t < 0 ? t : dds_create_reader(pp, t, NULL, NULL);
}

static void type_of(dds_entity_t rd, const char* topic) {
  char name[128] = "";
  dds_get_type_name(dds_get_topic(rd), name, sizeof name);
  printf("%s type %s\n", topic, name);
}

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: dds_echo DOMAIN SECONDS\n");
    return 2;
  }
  dds_entity_t pp = dds_create_participant((dds_domainid_t)atoi(argv[1]), NULL, NULL);
  if (pp < 0) {
    fprintf(stderr, "dds_echo: %s\n", dds_strretcode(pp));
    return 1;
  }
  dds_entity_t pose = reader(pp, &geometry_msgs_msg_dds__PoseStamped__desc, "rt/mixpilot/pose");
  dds_entity_t lambda = reader(pp, &std_msgs_msg_dds__Float64__desc, "rt/mixpilot/lambda");
  dds_entity_t pred = reader(pp, &nav_msgs_msg_dds__Path__desc, "rt/mixpilot/predicted_path");
  dds_entity_t ref = reader(pp, &nav_msgs_msg_dds__Path__desc, "rt/mixpilot/reference_path");
  if (pose < 0 || lambda < 0 || pred < 0 || ref < 0) {
    fprintf(stderr, "dds_echo: cannot subscribe\n");
    return 1;
  }
  long n_pose = 0, n_lambda = 0, n_pred = 0, n_ref = 0;
  double x = 0, y = 0, z = 0, qw = 0, qx = 0, qy = 0, qz = 0, l = -1;
  unsigned pred_len = 0, ref_len = 0;
  double pred_z = 0, ref_z = 0;
  const dds_time_t end = dds_time() + DDS_SECS(atoi(argv[2]));
  while (dds_time() < end) {
    void* s[8] = {NULL};
    dds_sample_info_t info[8];
    int n = dds_take(pose, s, info, 8, 8);
    for (int i = 0; i < n; ++i)
      if (info[i].valid_data) {
        const geometry_msgs_msg_dds__PoseStamped_* m = s[i];
        x = m->pose.position.x, y = m->pose.position.y, z = m->pose.position.z;
        qw = m->pose.orientation.w, qx = m->pose.orientation.x;
        qy = m->pose.orientation.y, qz = m->pose.orientation.z;
        ++n_pose;
      }
    if (n > 0) dds_return_loan(pose, s, n);
    n = dds_take(lambda, s, info, 8, 8);
    for (int i = 0; i < n; ++i)
      if (info[i].valid_data) l = ((const std_msgs_msg_dds__Float64_*)s[i])->data, ++n_lambda;
    if (n > 0) dds_return_loan(lambda, s, n);
    n = dds_take(pred, s, info, 8, 8);
    for (int i = 0; i < n; ++i)
      if (info[i].valid_data) {
        const nav_msgs_msg_dds__Path_* m = s[i];
        pred_len = m->poses._length;
        if (pred_len) pred_z = m->poses._buffer[pred_len - 1].pose.position.z;
        ++n_pred;
      }
    if (n > 0) dds_return_loan(pred, s, n);
    n = dds_take(ref, s, info, 8, 8);
    for (int i = 0; i < n; ++i)
      if (info[i].valid_data) {
        const nav_msgs_msg_dds__Path_* m = s[i];
        ref_len = m->poses._length;
        if (ref_len) ref_z = m->poses._buffer[ref_len - 1].pose.position.z;
        ++n_ref;
      }
    if (n > 0) dds_return_loan(ref, s, n);
    dds_sleepfor(DDS_MSECS(5));
  }
  type_of(pose, "pose");
  type_of(lambda, "lambda");
  type_of(pred, "predicted_path");
  type_of(ref, "reference_path");
  printf("pose %ld samples, last position %.4f %.4f %.4f, quaternion %.4f %.4f %.4f %.4f\n",
         n_pose, x, y, z, qw, qx, qy, qz);
  printf("lambda %ld samples, last %.4f\n", n_lambda, l);
  printf("predicted_path %ld samples, last %u poses ending at z %.4f\n", n_pred, pred_len, pred_z);
  printf("reference_path %ld samples, last %u poses ending at z %.4f\n", n_ref, ref_len, ref_z);
  dds_delete(pp);
  return 0;
}
