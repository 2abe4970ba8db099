#include "bag_metadata.hpp"

#include <yaml-cpp/yaml.h>

#include "coloc/core/error.hpp"

namespace coloc::io::detail {
namespace {

/// Reads typed values out of the document, naming the file and the key path in every error.
class MetadataParser {
 public:
  explicit MetadataParser(std::string path) : path_(std::move(path)) {}

  template <class T>
  T required(const YAML::Node& parent, const char* key, const std::string& context, const char* kind) const {
    const YAML::Node node = parent[key];
    if (!node) fail("missing key '" + context + key + "'");
    return scalar<T>(node, context + key, kind);
  }

  template <class T>
  T optional(const YAML::Node& parent, const char* key, const std::string& context, const char* kind,
             T fallback) const {
    const YAML::Node node = parent[key];
    if (!node || node.IsNull()) return fallback;
    return scalar<T>(node, context + key, kind);
  }

  template <class T>
  T scalar(const YAML::Node& node, const std::string& key, const char* kind) const {
    T value{};
    if (!node.IsScalar() || !YAML::convert<T>::decode(node, value)) fail("key '" + key + "' must be " + kind);
    return value;
  }

  /// {nanoseconds: N} or {nanoseconds_since_epoch: N}.
  std::int64_t nanoseconds(const YAML::Node& parent, const char* key, const char* inner, const std::string& context) const {
    const YAML::Node node = parent[key];
    if (!node || node.IsNull()) return 0;
    if (!node.IsMap()) fail("key '" + context + key + "' must be a mapping with '" + inner + "'");
    return required<std::int64_t>(node, inner, context + key + ".", "an integer");
  }

  /// By value: YAML::Node is a handle, and the callers pass temporaries from operator[].
  YAML::Node sequence(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence()) fail("key '" + key + "' must be a list");
    return node;
  }

  [[noreturn]] void fail(const std::string& reason) const { throw Error(path_ + ": " + reason); }

 private:
  std::string path_;
};

std::string qosText(const YAML::Node& node, const MetadataParser& parser, const std::string& key) {
  if (!node || node.IsNull()) return {};
  if (node.IsScalar()) return node.Scalar();                // versions 4..8: YAML text in a string
  if (node.IsSequence()) return node.size() == 0 ? std::string() : YAML::Dump(node);  // version 9: a list
  parser.fail("key '" + key + "' must be a string or a list");
}

TopicInfo parseTopic(const YAML::Node& entry, std::size_t index, const MetadataParser& parser) {
  const std::string context = "topics_with_message_count[" + std::to_string(index) + "].";
  if (!entry.IsMap() || !entry["topic_metadata"].IsMap()) {
    parser.fail("key '" + context + "topic_metadata' must be a mapping");
  }
  const YAML::Node metadata = entry["topic_metadata"];
  const std::string inner = context + "topic_metadata.";
  TopicInfo topic;
  topic.name = parser.required<std::string>(metadata, "name", inner, "a string");
  topic.type = parser.required<std::string>(metadata, "type", inner, "a string");
  topic.serialization_format = parser.optional<std::string>(metadata, "serialization_format", inner, "a string", "cdr");
  topic.offered_qos_profiles = qosText(metadata["offered_qos_profiles"], parser, inner + "offered_qos_profiles");
  topic.message_count = parser.optional<std::uint64_t>(entry, "message_count", context, "an integer", 0);
  return topic;
}

BagFileMetadata parseFile(const YAML::Node& entry, std::size_t index, const MetadataParser& parser) {
  const std::string context = "files[" + std::to_string(index) + "].";
  if (!entry.IsMap()) parser.fail("key 'files[" + std::to_string(index) + "]' must be a mapping");
  BagFileMetadata file;
  file.path = parser.required<std::string>(entry, "path", context, "a string");
  file.starting_time = parser.nanoseconds(entry, "starting_time", "nanoseconds_since_epoch", context);
  file.duration = parser.nanoseconds(entry, "duration", "nanoseconds", context);
  file.message_count = parser.optional<std::uint64_t>(entry, "message_count", context, "an integer", 0);
  return file;
}

YAML::Node loadDocument(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error(path + ": cannot open the metadata file");
  } catch (const YAML::Exception& e) {
    throw Error(path + ": not valid YAML: " + e.what());
  }
}

void emitNanoseconds(YAML::Emitter& out, const char* key, const char* inner, std::int64_t value) {
  out << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << inner << YAML::Value << value
      << YAML::EndMap;
}

}  // namespace

BagMetadata readBagMetadata(const std::string& path) {
  const MetadataParser parser(path);
  const YAML::Node document = loadDocument(path);
  const YAML::Node root = document.IsMap() ? document["rosbag2_bagfile_information"] : YAML::Node();
  if (!root || !root.IsMap()) parser.fail("no 'rosbag2_bagfile_information' mapping: not a rosbag2 metadata file");
  try {
    BagMetadata m;
    m.version = parser.required<int>(root, "version", "", "an integer");
    if (m.version < 1 || m.version > kNewestMetadataVersion) {
      parser.fail("metadata version " + std::to_string(m.version) + " is not supported (1 to " +
                  std::to_string(kNewestMetadataVersion) + ")");
    }
    m.storage_identifier = parser.required<std::string>(root, "storage_identifier", "", "a string");
    if (!root["relative_file_paths"]) parser.fail("missing key 'relative_file_paths'");
    for (const auto& entry : parser.sequence(root["relative_file_paths"], "relative_file_paths")) {
      m.relative_file_paths.push_back(parser.scalar<std::string>(entry, "relative_file_paths[]", "a list of strings"));
    }
    m.starting_time = parser.nanoseconds(root, "starting_time", "nanoseconds_since_epoch", "");
    m.duration = parser.nanoseconds(root, "duration", "nanoseconds", "");
    m.message_count = parser.optional<std::uint64_t>(root, "message_count", "", "an integer", 0);
    m.compression_format = parser.optional<std::string>(root, "compression_format", "", "a string", "");
    m.compression_mode = parser.optional<std::string>(root, "compression_mode", "", "a string", "");
    if (const YAML::Node topics = root["topics_with_message_count"]; topics && !topics.IsNull()) {
      std::size_t index = 0;
      for (const auto& entry : parser.sequence(topics, "topics_with_message_count")) {
        m.topics.push_back(parseTopic(entry, index++, parser));
      }
    }
    if (const YAML::Node files = root["files"]; files && !files.IsNull()) {
      std::size_t index = 0;
      for (const auto& entry : parser.sequence(files, "files")) m.files.push_back(parseFile(entry, index++, parser));
    }
    return m;
  } catch (const YAML::Exception& e) {
    parser.fail(std::string("malformed metadata: ") + e.what());
  }
}

std::string bagMetadataYaml(const BagMetadata& m, bool with_root) {
  YAML::Emitter out;
  if (with_root) out << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value;
  out << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << 5;
  out << YAML::Key << "storage_identifier" << YAML::Value << m.storage_identifier;
  emitNanoseconds(out, "duration", "nanoseconds", m.duration);
  emitNanoseconds(out, "starting_time", "nanoseconds_since_epoch", m.starting_time);
  out << YAML::Key << "message_count" << YAML::Value << m.message_count;
  out << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
  for (const auto& topic : m.topics) {
    out << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << topic.name;
    out << YAML::Key << "type" << YAML::Value << topic.type;
    out << YAML::Key << "serialization_format" << YAML::Value << topic.serialization_format;
    out << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::DoubleQuoted << topic.offered_qos_profiles;
    out << YAML::EndMap;
    out << YAML::Key << "message_count" << YAML::Value << topic.message_count << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "compression_format" << YAML::Value << YAML::DoubleQuoted << m.compression_format;
  out << YAML::Key << "compression_mode" << YAML::Value << YAML::DoubleQuoted << m.compression_mode;
  out << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq;
  for (const auto& file : m.relative_file_paths) out << file;
  out << YAML::EndSeq;
  out << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
  for (const auto& file : m.files) {
    out << YAML::BeginMap << YAML::Key << "path" << YAML::Value << file.path;
    emitNanoseconds(out, "starting_time", "nanoseconds_since_epoch", file.starting_time);
    emitNanoseconds(out, "duration", "nanoseconds", file.duration);
    out << YAML::Key << "message_count" << YAML::Value << file.message_count << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  if (with_root) out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace coloc::io::detail
