// Seed corpora for the fuzz targets, from the real data in data/ and coloc's own writers: small valid
// inputs of every kind a reader takes, so that fuzzing starts from what real files look like.
//
// usage: make_seeds SOURCE_DIR OUT_DIR   (writes OUT_DIR/<target>/...)
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "OdometryPubSubTypes.h"
#include "PoseWithCovarianceStampedPubSubTypes.h"
#include "VehicleDimensionsPubSubTypes.h"
#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/mcap_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/io/v2x_messages.hpp"

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

namespace {

fs::path out_root;

void seed(const std::string& target, const std::string& name, const Bytes& bytes, int selector = -1) {
  fs::create_directories(out_root / target);
  std::ofstream out(out_root / target / name, std::ios::binary);
  if (selector >= 0) out.put(static_cast<char>(selector));
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

Bytes readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

// The first `count` messages of the real recording, as MCAP files written every way coloc writes them.
void mcapSeeds(const fs::path& recording, const fs::path& scratch) {
  int k = 0;
  for (const auto compression : {coloc::io::McapCompression::kNone, coloc::io::McapCompression::kZstd, coloc::io::McapCompression::kLz4}) {
    for (const bool full : {true, false}) {
      coloc::io::McapWriterOptions options;
      options.compression = compression;
      options.chunk_size = 4096;
      options.write_summary = options.write_message_indexes = options.write_crcs = full;
      const fs::path path = scratch / ("seed" + std::to_string(k) + ".mcap");
      {
        coloc::io::BagReader reader = coloc::io::BagReader::open(recording.string());
        coloc::io::McapWriter writer = coloc::io::McapWriter::create(path.string(), options);
        for (const auto& topic : reader.topics()) writer.addTopic(topic);
        coloc::io::BagMessage message;
        for (int i = 0; i < 12 && reader.next(message); ++i) writer.write(message);
        if (k == 1) {
          writer.writeAttachment({1, 2, "note.txt", "text/plain", text("calibrated")});
          writer.writeMetadata({"recording", {{"vehicle", "ego"}}});
        }
        writer.close();
      }
      const Bytes written = readFile(path);
      seed("mcap_fuzzer", "written_" + std::to_string(k) + ".mcap", written);
      // Cut inside a chunk, as a recorder that died leaves a file: the way into recovery.
      seed("mcap_fuzzer", "cut_" + std::to_string(k++) + ".mcap", Bytes(written.begin(), written.begin() + written.size() * 2 / 3));
    }
  }
}

// The same messages in a rosbag2 sqlite3 bag: its database and its metadata.yaml.
void sqliteSeeds(const fs::path& recording, const fs::path& scratch) {
  const fs::path bag = scratch / "bag";
  {
    coloc::io::BagReader reader = coloc::io::BagReader::open(recording.string());
    coloc::io::BagWriter writer = coloc::io::BagWriter::create(bag.string());
    for (const auto& topic : reader.topics()) writer.addTopic(topic);
    coloc::io::BagMessage message;
    for (int i = 0; i < 12 && reader.next(message); ++i) writer.write(message);
    writer.close();
  }
  seed("sqlite_bag_fuzzer", "written.db3", readFile(bag / "bag_0.db3"));
  const Bytes metadata = readFile(bag / "metadata.yaml");
  seed("bag_metadata_fuzzer", "written_v5.yaml", metadata);
  // Newer layouts: version 9 keys and a compressed bag's fields.
  std::string v9(metadata.begin(), metadata.end());
  v9.replace(v9.find("version: 5"), 10, "version: 9");
  v9 += "  custom_data: ~\n  ros_distro: jazzy\n";
  seed("bag_metadata_fuzzer", "written_v9.yaml", text(v9));
}

// Every decodable message of the recording (a few per type) and coloc's own encodings of the rest.
void cdrSeeds(const fs::path& recording) {
  coloc::io::BagReader reader = coloc::io::BagReader::open(recording.string());
  std::map<std::string, coloc::io::MessageKind> kinds;
  for (const auto& topic : reader.topics())
    if (const auto kind = coloc::io::messageKindOf(topic.type)) kinds[topic.name] = *kind;
  std::map<std::string, int> taken;
  coloc::io::BagMessage message;
  while (reader.next(message)) {
    const auto kind = kinds.find(message.topic);
    if (kind == kinds.end() || taken[message.topic]++ >= 3) continue;
    seed("cdr_fuzzer", "recorded_" + std::to_string(static_cast<int>(kind->second)) + "_" + std::to_string(taken[message.topic]), message.data,
         static_cast<int>(kind->second));
  }
  using coloc::io::MessageKind;
  coloc::io::StampedPose pose;
  pose.header = {1'700'000'000'000'000'000LL, "map"};
  pose.measurement.covariance.diagonal() << 0.01, 0.01, 1e9, 1e9, 1e9, 0.1;
  seed("cdr_fuzzer", "pose_cov", coloc::io::encodePoseWithCovarianceStamped(pose), static_cast<int>(MessageKind::kPoseWithCovarianceStamped));
  // The live node's service requests and replies and its diagnostics, as coloc encodes them.
  seed("node_interfaces_fuzzer", "set_bool_request", coloc::io::encodeSetBoolRequest(true), 0);
  seed("node_interfaces_fuzzer", "set_bool_response", coloc::io::encodeSetBoolResponse({true, "activated"}), 1);
  seed("node_interfaces_fuzzer", "align_request", coloc::io::encodePoseAlignRequest(pose), 2);
  coloc::io::PoseAlignResponse aligned;
  aligned.success = aligned.reliable = true;
  aligned.pose = pose;
  seed("node_interfaces_fuzzer", "align_response", coloc::io::encodePoseAlignResponse(aligned), 3);
  coloc::io::DiagnosticArray diagnostics;
  diagnostics.header.stamp = pose.header.stamp;
  diagnostics.status.push_back({coloc::io::DiagnosticStatus::kWarn, "localization: ekf_localizer", "[WARN]process is not activated", "coloc",
                                {{"is_activated", "False"}}});
  seed("node_interfaces_fuzzer", "diagnostics", coloc::io::encodeDiagnosticArray(diagnostics), 4);
  coloc::io::Cam cam;
  cam.header = {1'700'000'001'000'000'000LL, "map"};
  cam.station_id = 1002;
  cam.reference = {12.0, -1.75};
  cam.speed = 8.0;
  cam.length = 4.7;
  cam.width = 1.9;
  seed("node_interfaces_fuzzer", "cam", coloc::io::encodeCam(cam), 5);
  seed("cdr_fuzzer", "pose", coloc::io::encodePoseStamped(pose), static_cast<int>(MessageKind::kPoseStamped));
  coloc::io::StampedTwist twist;
  twist.header = pose.header;
  seed("cdr_fuzzer", "twist_cov", coloc::io::encodeTwistWithCovarianceStamped(twist), static_cast<int>(MessageKind::kTwistWithCovarianceStamped));
  seed("cdr_fuzzer", "twist", coloc::io::encodeTwistStamped(twist), static_cast<int>(MessageKind::kTwistStamped));
  coloc::io::Imu imu;
  imu.header = pose.header;
  seed("cdr_fuzzer", "imu", coloc::io::encodeImu(imu), static_cast<int>(MessageKind::kImu));
  coloc::io::Odometry odom;
  odom.header = pose.header;
  odom.child_frame_id = "base_link";
  seed("cdr_fuzzer", "odometry", coloc::io::encodeOdometry(odom), static_cast<int>(MessageKind::kOdometry));
  coloc::io::PointCloud2 cloud;
  cloud.header = {pose.header.stamp, "velodyne"};
  cloud.height = 1;
  cloud.width = 3;
  cloud.point_step = 16;
  cloud.row_step = 48;
  for (const char* field : {"x", "y", "z", "time"})
    cloud.fields.push_back({field, static_cast<std::uint32_t>(4 * cloud.fields.size()), coloc::io::PointField::kFloat32, 1});
  cloud.data.assign(48, 0);
  for (int i = 0; i < 12; ++i) {
    const float v = 0.5f * static_cast<float>(i);
    std::memcpy(cloud.data.data() + 4 * i, &v, 4);
  }
  seed("cdr_fuzzer", "cloud", coloc::io::encodePointCloud2(cloud), static_cast<int>(MessageKind::kPointCloud2));
  coloc::io::TFMessage tf;
  tf.transforms.push_back({{pose.header.stamp, "base_link"}, "velodyne", {0.9, 0.0, 1.8}, Eigen::Quaterniond(0.9998, 0.0, 0.0, 0.02)});
  tf.transforms.push_back({{pose.header.stamp, "base_footprint"}, "base_link", {0.0, 0.0, 0.1}, Eigen::Quaterniond::Identity()});
  seed("cdr_fuzzer", "tf_static", coloc::io::encodeTFMessage(tf), static_cast<int>(MessageKind::kTFMessage));
}

// Small PCDs of each data kind; binary_compressed is written with LZF literal runs only, which every
// LZF decoder must take.
void pcdSeeds() {
  const std::string header = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\n";
  seed("pcd_fuzzer", "ascii.pcd", text(header + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\nnan 0 0\n"));
  std::vector<float> xyz = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  Bytes binary = text(header + "DATA binary\n");
  const auto* p = reinterpret_cast<const std::uint8_t*>(xyz.data());
  binary.insert(binary.end(), p, p + 48);
  seed("pcd_fuzzer", "binary.pcd", binary);
  // binary_compressed stores the fields one after the other (all x, all y, all z).
  std::vector<float> soa = {1, 4, 7, 10, 2, 5, 8, 11, 3, 6, 9, 12};
  const auto* q = reinterpret_cast<const std::uint8_t*>(soa.data());
  Bytes lzf;
  for (std::size_t i = 0; i < 48; i += 32) {
    const std::size_t run = std::min<std::size_t>(32, 48 - i);
    lzf.push_back(static_cast<std::uint8_t>(run - 1));
    lzf.insert(lzf.end(), q + i, q + i + run);
  }
  Bytes compressed = text(header + "DATA binary_compressed\n");
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(lzf.size()), 48};
  const auto* s = reinterpret_cast<const std::uint8_t*>(sizes);
  compressed.insert(compressed.end(), s, s + 8);
  compressed.insert(compressed.end(), lzf.begin(), lzf.end());
  seed("pcd_fuzzer", "binary_compressed.pcd", compressed);
}

void configSeeds(const fs::path& source) {
  seed("config_fuzzer", "coloc.yaml", readFile(source / "config" / "coloc.yaml"), 0);
  seed("config_fuzzer", "rsu.yaml", readFile(source / "config" / "rsu.yaml"), 1);
}

template <typename Generated>
Bytes serialized(typename Generated::type& message) {
  Generated type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&message)());
  if (!type.serialize(&message, &payload)) throw coloc::Error("make_seeds: serialization failed");
  return Bytes(payload.data, payload.data + payload.length);
}

void ddsSeeds() {
  geometry_msgs::msg::PoseWithCovarianceStamped fix;
  fix.header().stamp().sec(1'700'000'000);
  fix.header().frame_id("map");
  fix.pose().pose().position().x(95.0);
  fix.pose().pose().position().y(-3.0);
  fix.pose().pose().orientation().w(1.0);
  std::array<double, 36> covariance{};
  covariance[0] = covariance[7] = 0.01486;
  covariance[14] = covariance[21] = covariance[28] = covariance[35] = 1e300;
  fix.pose().covariance(covariance);
  seed("dds_payload_fuzzer", "fix", serialized<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>(fix), 0);
  nav_msgs::msg::Odometry addressed;
  addressed.header(fix.header());
  addressed.child_frame_id("7");
  addressed.pose(fix.pose());
  seed("dds_payload_fuzzer", "addressed_fix", serialized<nav_msgs::msg::OdometryPubSubType>(addressed), 1);
  coloc_msgs::msg::VehicleDimensions dimensions;
  dimensions.station_id(7);
  dimensions.length(4.8);
  dimensions.width(1.9);
  seed("dds_payload_fuzzer", "dimensions", serialized<coloc_msgs::msg::VehicleDimensionsPubSubType>(dimensions), 2);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SOURCE_DIR OUT_DIR\n", argv[0]);
    return 2;
  }
  const fs::path source = argv[1];
  out_root = argv[2];
  try {
    const fs::path scratch = out_root / "scratch";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    const fs::path recording = source / "data" / "rosbag2" / "nav2_turtlebot.mcap";
    mcapSeeds(recording, scratch);
    // The MCAP conformance suite: every layout variant the format allows, each a small file.
    for (const auto& family : fs::directory_iterator(source / "data" / "mcap_conformance"))
      if (family.is_directory())
        for (const auto& file : fs::directory_iterator(family.path()))
          if (file.path().extension() == ".mcap") seed("mcap_fuzzer", "conformance_" + file.path().filename().string(), readFile(file.path()));
    sqliteSeeds(recording, scratch);
    cdrSeeds(recording);
    pcdSeeds();
    configSeeds(source);
    ddsSeeds();
    fs::remove_all(scratch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  for (const auto& dir : fs::directory_iterator(out_root))
    std::printf("seeds %s: %zu files\n", dir.path().filename().c_str(),
                static_cast<std::size_t>(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator())));
  return 0;
}
