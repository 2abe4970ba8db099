#pragma once
// The one shape of a configuration error, whichever file it comes from: "FILE:LINE: KEY: WHY".
#include <string>

#include "coloc/core/error.hpp"

namespace coloc {

/// `line` is 0-based as YAML parsers report it; a negative line (unknown) is left out.
[[noreturn]] inline void throwConfigError(const std::string& source, int line, const std::string& key, const std::string& why) {
  std::string where = source;
  if (line >= 0) where += ":" + std::to_string(line + 1);
  throw Error(where + ": " + key + ": " + why);
}

}  // namespace coloc
