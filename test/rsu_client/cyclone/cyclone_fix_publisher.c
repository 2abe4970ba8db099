/* A ROS 2 node's view of an RSU, written against Eclipse Cyclone DDS (rmw_cyclonedds's middleware)
 * with its defaults: the domain from ROS_DOMAIN_ID, discovery and interfaces as CYCLONEDDS_URI says
 * (none set: Cyclone's defaults), ROS 2 sensor-data QoS (best effort, keep last 5). With a STATION_ID,
 * fixes addressed to that vehicle as the protocol says (nav_msgs/msg/Odometry on rt/rsu/<id>/addressed_fix,
 * the station id in decimal as child_frame_id); without, unaddressed ones (PoseWithCovarianceStamped on
 * rt/rsu/<id>/fix). Publishes COUNT fixes at 10 Hz once a reader matched, stamped now, in frame "map".
 *
 * usage: cyclone_fix_publisher RSU_ID COUNT X Y VARIANCE [WAIT_S [STATION_ID]] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "Ros2Pose.h"
#include "dds/dds.h"

int main(int argc, char** argv) {
  if (argc < 6) {
    fprintf(stderr, "usage: %s RSU_ID COUNT X Y VARIANCE [WAIT_S [STATION_ID]]\n", argv[0]);
    return 2;
  }
  const int count = atoi(argv[2]);
  const double x = atof(argv[3]), y = atof(argv[4]), variance = atof(argv[5]);
  const double wait_s = argc > 6 ? atof(argv[6]) : 15.0;
  const char* station = argc > 7 ? argv[7] : NULL;
  const char* domain_text = getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain = domain_text && *domain_text ? (dds_domainid_t)atoi(domain_text) : 0;

  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cyclone: no participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  char topic_name[256];
  snprintf(topic_name, sizeof topic_name, station ? "rt/rsu/%s/addressed_fix" : "rt/rsu/%s/fix", argv[1]);
  const dds_entity_t topic = dds_create_topic(
      participant, station ? &nav_msgs_msg_dds__Odometry__desc : &geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, topic_name, NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
  const dds_entity_t writer = dds_create_writer(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (topic < 0 || writer < 0) {
    fprintf(stderr, "cyclone: no topic or writer\n");
    return 1;
  }
  dds_publication_matched_status_t matched;
  memset(&matched, 0, sizeof matched);
  for (int waited = 0; waited < (int)(wait_s * 10) && matched.current_count == 0; ++waited) {
    dds_sleepfor(DDS_MSECS(100));
    dds_get_publication_matched_status(writer, &matched);
  }
  if (matched.current_count == 0) {
    printf("cyclone: no reader matched in %.0f s\n", wait_s);
    dds_delete(participant);
    return 1;
  }
  printf("cyclone: matched %u reader(s)\n", (unsigned)matched.current_count);
  dds_sleepfor(DDS_MSECS(300));  /* the reader's side of discovery completes too */
  for (int i = 0; i < count; ++i) {
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    geometry_msgs_msg_dds__PoseWithCovariance_ pose;
    memset(&pose, 0, sizeof pose);
    pose.pose.position.x = x + 0.1 * i;
    pose.pose.position.y = y;
    pose.pose.orientation.w = 1.0;
    pose.covariance[0] = pose.covariance[7] = variance;
    pose.covariance[14] = pose.covariance[21] = pose.covariance[28] = pose.covariance[35] = INFINITY;
    dds_return_t rc;
    if (station) {
      nav_msgs_msg_dds__Odometry_ msg;
      memset(&msg, 0, sizeof msg);
      msg.header.stamp.sec = (int32_t)now.tv_sec;
      msg.header.stamp.nanosec = (uint32_t)now.tv_nsec;
      msg.header.frame_id = "map";
      msg.child_frame_id = (char*)station;
      msg.pose = pose;
      for (int k = 0; k < 6; ++k) msg.twist.covariance[7 * k] = -1.0;  /* the twist is not part of a fix */
      rc = dds_write(writer, &msg);
    } else {
      geometry_msgs_msg_dds__PoseWithCovarianceStamped_ msg;
      memset(&msg, 0, sizeof msg);
      msg.header.stamp.sec = (int32_t)now.tv_sec;
      msg.header.stamp.nanosec = (uint32_t)now.tv_nsec;
      msg.header.frame_id = "map";
      msg.pose = pose;
      rc = dds_write(writer, &msg);
    }
    if (rc != DDS_RETCODE_OK) fprintf(stderr, "cyclone: write failed: %s\n", dds_strretcode(-rc));
    dds_sleepfor(DDS_MSECS(100));
  }
  printf("cyclone: published %d fixes on %s\n", count, topic_name);
  dds_sleepfor(DDS_MSECS(300));
  dds_delete(participant);
  return 0;
}
