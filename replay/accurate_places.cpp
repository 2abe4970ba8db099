#include "coloc/replay/accurate_places.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/core/number_text.hpp"

namespace coloc::replay {

AccuratePlaces AccuratePlaces::fromErrors(const std::vector<ErrorSample>& errors, double cell, double below, std::size_t min_samples) {
  if (!(std::isfinite(cell) && cell > 0.0)) throw Error("accurate places: cell must be a finite number of metres > 0, not " + exactNumberText(cell));
  if (!(std::isfinite(below) && below > 0.0)) throw Error("accurate places: below must be a finite number of metres > 0, not " + exactNumberText(below));
  AccuratePlaces p;
  p.cell_ = cell;
  p.below_ = below;
  std::map<Key, std::pair<double, std::size_t>> sums;  // error sum, poses
  for (const ErrorSample& e : errors) {
    // A place beyond what a long long indexes at this cell size says nothing of the road.
    if (!e.truth.allFinite() || !std::isfinite(e.error) || e.truth.cwiseAbs().maxCoeff() / cell > 1e15) continue;
    auto& s = sums[p.keyOf(e.truth)];
    s.first += e.error;
    ++s.second;
  }
  for (const auto& [key, s] : sums)
    if (s.second >= std::max<std::size_t>(1, min_samples)) p.judged_[key] = s.first / static_cast<double>(s.second) < below;
  return p;
}

std::map<std::string, AccuratePlaces> AccuratePlaces::fromInputErrorCsv(const std::string& path, double cell, double below, std::size_t min_samples) {
  fromErrors({}, cell, below, min_samples);  // the settings checked before the file, which may hold no pose
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot be read (an input_error.csv of a reference drive)");
  const auto split = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream text(line);
    for (std::string f; std::getline(text, f, ',');) fields.push_back(f);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    return fields;
  };
  std::string line;
  if (!std::getline(in, line)) throw Error(path + ": empty, not an input_error.csv");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::vector<std::string> header = split(line);
  const auto column = [&](const char* name) {
    const auto at = std::find(header.begin(), header.end(), name);
    if (at == header.end()) throw Error(path + ": no column " + name + " (an input_error.csv that coloc fuse writes has source, truth_x, truth_y, error_m)");
    return static_cast<std::size_t>(at - header.begin());
  };
  const std::size_t source = column("source"), x = column("truth_x"), y = column("truth_y"), error = column("error_m");
  std::map<std::string, std::vector<ErrorSample>> samples;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> fields = split(line);
    if (fields.size() != header.size())
      throw Error(path + ":" + std::to_string(number) + ": " + std::to_string(fields.size()) + " fields, the header has " + std::to_string(header.size()));
    const auto number_in = [&](std::size_t c) {
      const std::string& f = fields[c];
      char* end = nullptr;
      const double v = std::strtod(f.c_str(), &end);
      // coloc fuse writes each of these as a finite number (an error as a distance): anything else is not its file.
      if (f.empty() || end != f.c_str() + f.size() || !std::isfinite(v))
        throw Error(path + ":" + std::to_string(number) + ": " + header[c] + ": '" + f + "' is not a finite number");
      if (c == error && v < 0.0) throw Error(path + ":" + std::to_string(number) + ": error_m: " + f + " is negative; an error is a distance");
      return v;
    };
    ErrorSample e{};
    e.truth = Eigen::Vector2d(number_in(x), number_in(y));
    e.error = number_in(error);
    samples[fields[source]].push_back(e);
  }
  std::map<std::string, AccuratePlaces> out;
  for (const auto& [name, errors] : samples) out[name] = fromErrors(errors, cell, below, min_samples);
  return out;
}

AccuratePlaces::Key AccuratePlaces::keyOf(const Eigen::Vector2d& xy) const {
  return {static_cast<long long>(std::floor(xy.x() / cell_)), static_cast<long long>(std::floor(xy.y() / cell_))};
}

bool AccuratePlaces::contains(const Eigen::Vector2d& xy) const {
  if (!xy.allFinite() || xy.cwiseAbs().maxCoeff() / cell_ > 1e15) return false;
  const auto found = judged_.find(keyOf(xy));
  return found != judged_.end() && found->second;
}

std::size_t AccuratePlaces::accurate() const {
  std::size_t n = 0;
  for (const auto& [key, accurate] : judged_) n += accurate ? 1 : 0;
  return n;
}

}  // namespace coloc::replay
