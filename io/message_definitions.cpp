// ros2msg schema text for the types coloc knows, so that MCAP files it writes are self-describing
// (Foxglove and other MCAP readers decode messages from the schema alone).
#include <map>
#include <set>
#include <string>
#include <vector>

#include "coloc/io/ros_messages.hpp"

namespace coloc::io {
namespace {

struct MsgSpec {
  const char* fields;                 // the .msg body, field lines only
  std::vector<const char*> depends;   // types named in the fields, "pkg/Name" in field order
};

// Field lists as in ROS 2's common_interfaces; comments dropped.
const std::map<std::string, MsgSpec>& specs() {
  static const std::map<std::string, MsgSpec> table{
      {"builtin_interfaces/Time", {"int32 sec\nuint32 nanosec\n", {}}},
      {"std_msgs/Header", {"builtin_interfaces/Time stamp\nstring frame_id\n", {"builtin_interfaces/Time"}}},
      {"geometry_msgs/Point", {"float64 x\nfloat64 y\nfloat64 z\n", {}}},
      {"geometry_msgs/Vector3", {"float64 x\nfloat64 y\nfloat64 z\n", {}}},
      {"geometry_msgs/Quaternion", {"float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n", {}}},
      {"geometry_msgs/Pose",
       {"Point position\nQuaternion orientation\n", {"geometry_msgs/Point", "geometry_msgs/Quaternion"}}},
      {"geometry_msgs/PoseWithCovariance", {"Pose pose\nfloat64[36] covariance\n", {"geometry_msgs/Pose"}}},
      {"geometry_msgs/PoseWithCovarianceStamped",
       {"std_msgs/Header header\nPoseWithCovariance pose\n",
        {"std_msgs/Header", "geometry_msgs/PoseWithCovariance"}}},
      {"geometry_msgs/PoseStamped",
       {"std_msgs/Header header\nPose pose\n", {"std_msgs/Header", "geometry_msgs/Pose"}}},
      {"geometry_msgs/Twist", {"Vector3 linear\nVector3 angular\n", {"geometry_msgs/Vector3"}}},
      {"geometry_msgs/TwistWithCovariance", {"Twist twist\nfloat64[36] covariance\n", {"geometry_msgs/Twist"}}},
      {"geometry_msgs/TwistWithCovarianceStamped",
       {"std_msgs/Header header\nTwistWithCovariance twist\n",
        {"std_msgs/Header", "geometry_msgs/TwistWithCovariance"}}},
      {"geometry_msgs/TwistStamped",
       {"std_msgs/Header header\nTwist twist\n", {"std_msgs/Header", "geometry_msgs/Twist"}}},
      {"nav_msgs/Odometry",
       {"std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
        "geometry_msgs/TwistWithCovariance twist\n",
        {"std_msgs/Header", "geometry_msgs/PoseWithCovariance", "geometry_msgs/TwistWithCovariance"}}},
      {"sensor_msgs/Imu",
       {"std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
        "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
        "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
        {"std_msgs/Header", "geometry_msgs/Quaternion", "geometry_msgs/Vector3"}}},
      {"sensor_msgs/PointField",
       {"uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\n"
        "uint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n",
        {}}},
      {"sensor_msgs/PointCloud2",
       {"std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
        "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
        {"std_msgs/Header", "sensor_msgs/PointField"}}},
      {"geometry_msgs/Transform",
       {"Vector3 translation\nQuaternion rotation\n", {"geometry_msgs/Vector3", "geometry_msgs/Quaternion"}}},
      {"geometry_msgs/TransformStamped",
       {"std_msgs/Header header\nstring child_frame_id\nTransform transform\n", {"std_msgs/Header", "geometry_msgs/Transform"}}},
      {"tf2_msgs/TFMessage", {"geometry_msgs/TransformStamped[] transforms\n", {"geometry_msgs/TransformStamped"}}},
      {"coloc_msgs/Cam",
       {"std_msgs/Header header\nuint32 station_id\nfloat64 x\nfloat64 y\nfloat64 heading\nfloat64 speed\nfloat64 yaw_rate\n"
        "float64 length\nfloat64 width\n",
        {"std_msgs/Header"}}},
  };
  return table;
}

/// Dependencies depth first in field order, each once.
void collectDependencies(const std::string& name, std::vector<std::string>& order, std::set<std::string>& seen) {
  for (const char* dependency : specs().at(name).depends) {
    if (!seen.insert(dependency).second) continue;
    order.push_back(dependency);
    collectDependencies(dependency, order, seen);
  }
}

/// "geometry_msgs/msg/Pose" -> "geometry_msgs/Pose", the form the ros2msg separators use.
std::string withoutMsgNamespace(std::string_view ros_type) {
  const auto slash = ros_type.find("/msg/");
  if (slash == std::string_view::npos) return std::string(ros_type);
  return std::string(ros_type.substr(0, slash)) + "/" + std::string(ros_type.substr(slash + 5));
}

}  // namespace

std::string rosMessageDefinition(std::string_view ros_type) {
  const std::string name = withoutMsgNamespace(ros_type);
  const auto found = specs().find(name);
  if (found == specs().end()) return {};
  std::string text = found->second.fields;
  std::vector<std::string> order;
  std::set<std::string> seen{name};
  collectDependencies(name, order, seen);
  for (const auto& dependency : order) {
    text += "\n" + std::string(80, '=') + "\nMSG: " + dependency + "\n" + specs().at(dependency).fields;
  }
  return text;
}

}  // namespace coloc::io
