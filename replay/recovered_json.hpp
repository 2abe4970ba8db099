#pragma once
// The files of a log read up to their cut (a recording never closed), as summary.json lists them
// (coloc fuse, coloc smooth).
#include <nlohmann/json.hpp>
#include <vector>

#include "coloc/io/bag_reader.hpp"

namespace coloc::replay {

inline nlohmann::ordered_json recoveredJson(const std::vector<io::RecoveredFile>& recovered) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const io::RecoveredFile& r : recovered)
    list.push_back({{"file", r.file}, {"file_bytes", r.file_bytes}, {"read_bytes", r.read_bytes}, {"messages", r.messages}, {"stopped", r.reason}});
  return list;
}

}  // namespace coloc::replay
