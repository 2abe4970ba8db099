#pragma once
// Checks for the numeric options of the commands. CLI11's Range lets a NaN through (every comparison
// with it is false) and says nothing of infinities; these refuse both, naming what the option takes.
#include <CLI/CLI.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace coloc::tools {

/// A finite number in [lo, hi] (hi infinite: no upper bound); `open_lo`: above lo, not at it.
inline CLI::Validator finiteNumber(double lo, double hi = std::numeric_limits<double>::infinity(), bool open_lo = false) {
  std::ostringstream what;
  what << "must be a finite number " << (open_lo ? "> " : ">= ") << lo;
  if (std::isfinite(hi)) what << " and <= " << hi;
  const std::string description = what.str();
  std::ostringstream range;  // for --help: "in [0, 10]", ">= 0", "in (0, 1000]"
  if (std::isfinite(hi)) range << "in " << (open_lo ? "(" : "[") << lo << ", " << hi << "]";
  else range << (open_lo ? "> " : ">= ") << lo;
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0.0;
        std::size_t used = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          return description + " (got '" + text + "')";
        }
        if (used != text.size() || !std::isfinite(value) || (open_lo ? !(value > lo) : !(value >= lo)) || value > hi)
          return description + " (got '" + text + "')";
        return std::string();
      },
      range.str());
}

/// A whole number in [lo, hi].
inline CLI::Validator wholeNumber(long long lo, long long hi = std::numeric_limits<long long>::max()) {
  const std::string description =
      "must be a whole number >= " + std::to_string(lo) + (hi < std::numeric_limits<long long>::max() ? " and <= " + std::to_string(hi) : "");
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long value = 0;
        std::size_t used = 0;
        try {
          value = std::stoll(text, &used);
        } catch (const std::exception&) {
          return description + " (got '" + text + "')";
        }
        if (used != text.size() || value < lo || value > hi) return description + " (got '" + text + "')";
        return std::string();
      },
      hi < std::numeric_limits<long long>::max() ? "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" : ">= " + std::to_string(lo));
}

}  // namespace coloc::tools
