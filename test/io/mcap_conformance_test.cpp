// The MCAP conformance suite (data/mcap_conformance/): every file, in every layout variant, must give
// exactly the messages, attachments and metadata records its JSON description lists, in file order.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "io_test_support.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct Expected {
  std::vector<BagMessage> messages;
  std::vector<BagAttachment> attachments;
  std::vector<BagMetadataRecord> metadata;
};

// A record's fields as a map; numbers are strings and bytes are lists of strings in the suite's JSON.
std::map<std::string, json> fieldsOf(const json& record) {
  std::map<std::string, json> fields;
  for (const json& f : record.at("fields")) fields[f.at(0).get<std::string>()] = f.at(1);
  return fields;
}

std::uint64_t number(const json& j) { return std::stoull(j.get<std::string>()); }

std::vector<std::uint8_t> bytes(const json& j) {
  std::vector<std::uint8_t> out;
  for (const json& b : j) out.push_back(static_cast<std::uint8_t>(std::stoul(b.get<std::string>())));
  return out;
}

// What the data section holds (the records before Data End), as a reader streaming it must give it.
Expected expectedOf(const fs::path& json_path) {
  std::ifstream in(json_path);
  const json description = json::parse(in);
  Expected e;
  std::map<std::uint64_t, std::string> topic_of_channel;
  for (const json& record : description.at("records")) {
    const std::string type = record.at("type");
    if (type == "DataEnd") break;
    auto f = fieldsOf(record);
    if (type == "Channel") topic_of_channel.emplace(number(f["id"]), f["topic"].get<std::string>());
    if (type == "Message") {
      BagMessage m;
      m.topic = topic_of_channel.at(number(f["channel_id"]));
      m.log_time = static_cast<Stamp>(number(f["log_time"]));
      m.publish_time = static_cast<Stamp>(number(f["publish_time"]));
      m.data = bytes(f["data"]);
      e.messages.push_back(m);
    }
    if (type == "Attachment")
      e.attachments.push_back({static_cast<Stamp>(number(f["log_time"])), static_cast<Stamp>(number(f["create_time"])), f["name"].get<std::string>(),
                               f["media_type"].get<std::string>(), bytes(f["data"])});
    if (type == "Metadata") e.metadata.push_back({f["name"].get<std::string>(), f["metadata"].get<std::map<std::string, std::string>>()});
  }
  return e;
}

TEST(McapConformance, EveryFileOfTheSuiteGivesExactlyTheRecordsItsDescriptionLists) {
  const fs::path suite = COLOC_DATA_DIR "/mcap_conformance";
  ASSERT_TRUE(fs::is_directory(suite)) << suite << " is missing (see data/README.md)";
  std::size_t files = 0, messages = 0, attachments = 0, metadata = 0;
  for (const auto& family : fs::directory_iterator(suite)) {
    if (!family.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(family.path())) {
      if (entry.path().extension() != ".mcap") continue;
      ++files;
      const std::string name = entry.path().filename().string();
      const Expected expected = expectedOf(fs::path(entry.path()).replace_extension(".json"));
      try {
        BagReader reader = BagReader::open(entry.path().string());
        reader.keepAttachments(true);
        std::uint64_t counted = 0;
        for (const TopicInfo& t : reader.topics()) counted += t.message_count;
        EXPECT_EQ(counted, expected.messages.size()) << name << ": message counts of the topics";
        std::vector<BagMessage> read;
        BagMessage m;
        while (reader.next(m)) read.push_back(m);
        ASSERT_EQ(read.size(), expected.messages.size()) << name;
        for (std::size_t i = 0; i < read.size(); ++i) {
          EXPECT_EQ(read[i].topic, expected.messages[i].topic) << name << " message " << i;
          EXPECT_EQ(read[i].log_time, expected.messages[i].log_time) << name << " message " << i;
          EXPECT_EQ(read[i].publish_time, expected.messages[i].publish_time) << name << " message " << i;
          EXPECT_EQ(read[i].data, expected.messages[i].data) << name << " message " << i;
        }
        ASSERT_EQ(reader.attachments().size(), expected.attachments.size()) << name;
        for (std::size_t i = 0; i < expected.attachments.size(); ++i) {
          const BagAttachment &a = reader.attachments()[i], &x = expected.attachments[i];
          EXPECT_TRUE(a.name == x.name && a.media_type == x.media_type && a.log_time == x.log_time && a.create_time == x.create_time &&
                      a.data == x.data)
              << name << " attachment " << i;
        }
        ASSERT_EQ(reader.metadataRecords().size(), expected.metadata.size()) << name;
        for (std::size_t i = 0; i < expected.metadata.size(); ++i) {
          EXPECT_EQ(reader.metadataRecords()[i].name, expected.metadata[i].name) << name;
          EXPECT_EQ(reader.metadataRecords()[i].entries, expected.metadata[i].entries) << name;
        }
        messages += read.size();
        attachments += reader.attachments().size();
        metadata += reader.metadataRecords().size();
      } catch (const Error& e) {
        ADD_FAILURE() << name << " refused: " << e.what();
      }
    }
  }
  EXPECT_EQ(files, 416u) << "the suite's files in " << suite;
  std::printf("conformance: %zu files, %zu messages, %zu attachments, %zu metadata records read as described\n", files, messages, attachments,
              metadata);
}

}  // namespace
}  // namespace coloc::io
