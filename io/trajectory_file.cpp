// TUM trajectory files. Stamps are printed from the int64 nanoseconds and parsed back digit by digit,
// because a double cannot hold an epoch time to the nanosecond (1.7e9 s needs 19 significant digits).
#include "coloc/io/trajectory_file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>

#include "coloc/core/error.hpp"

namespace coloc::io {
namespace {

/// Seconds as written by formatSeconds ("-12.345678901", up to nine decimals) to nanoseconds, exactly;
/// exponent notation goes through a double. nullopt if the text is not a number.
std::optional<Stamp> parseSeconds(const std::string& text) {
  if (text.find_first_of("eE") != std::string::npos) {
    char* end = nullptr;
    errno = 0;
    const double seconds = std::strtod(text.c_str(), &end);
    if (errno != 0 || *end != '\0' || !std::isfinite(seconds) || std::abs(seconds) > 9.2e9) return std::nullopt;
    return fromSeconds(seconds);
  }
  std::size_t i = 0;
  bool negative = false;
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    negative = text[0] == '-';
    i = 1;
  }
  std::int64_t whole = 0, fraction = 0;
  int whole_digits = 0, fraction_digits = 0;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++whole_digits) {
    if (whole > (INT64_MAX / kNanosPerSecond - 9) / 10) return std::nullopt;  // beyond int64 nanoseconds
    whole = whole * 10 + (text[i] - '0');
  }
  if (i < text.size() && text[i] == '.') {
    for (++i; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++fraction_digits) {
      // Digits past the ninth are below a nanosecond: the tenth rounds, the rest are dropped.
      if (fraction_digits < 9) fraction = fraction * 10 + (text[i] - '0');
      if (fraction_digits == 9 && text[i] >= '5') fraction += 1;
    }
  }
  if (i != text.size() || whole_digits + fraction_digits == 0) return std::nullopt;
  for (int d = std::min(fraction_digits, 9); d < 9; ++d) fraction *= 10;
  const Stamp magnitude = whole * kNanosPerSecond + fraction;
  return negative ? -magnitude : magnitude;
}

std::optional<double> parseDouble(const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || errno == ERANGE || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

[[noreturn]] void failLine(const std::string& source, std::size_t line, const std::string& reason) {
  throw Error(source + ":" + std::to_string(line) + ": " + reason);
}

TrajectoryPoint parseLine(const std::string& text, const std::string& source, std::size_t line) {
  std::istringstream fields(text);
  std::vector<std::string> tokens;
  for (std::string token; fields >> token;) tokens.push_back(token);
  if (tokens.size() != 8) {
    failLine(source, line, "expected 8 values \"t x y z qx qy qz qw\", found " + std::to_string(tokens.size()));
  }
  const auto stamp = parseSeconds(tokens[0]);
  if (!stamp) failLine(source, line, "time stamp '" + tokens[0] + "' is not a number of seconds");
  double v[7];
  static const char* const kNames[7] = {"x", "y", "z", "qx", "qy", "qz", "qw"};
  for (int k = 0; k < 7; ++k) {
    const auto value = parseDouble(tokens[k + 1]);
    if (!value) failLine(source, line, std::string(kNames[k]) + " '" + tokens[k + 1] + "' is not a finite number");
    v[k] = *value;
  }
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    failLine(source, line, "quaternion (qx qy qz qw) has norm " + std::to_string(norm) + ", not 1");
  }
  TrajectoryPoint point;
  point.stamp = *stamp;
  point.pose.position = {v[0], v[1], v[2]};
  point.pose.orientation = q.normalized();
  return point;
}

}  // namespace

void writeTumTrajectory(std::ostream& out, const std::vector<TrajectoryPoint>& points, const std::string& comment) {
  std::istringstream comment_lines(comment);
  for (std::string line; std::getline(comment_lines, line);) out << "# " << line << '\n';
  char buffer[256];
  for (const auto& point : points) {
    const auto& p = point.pose.position;
    const auto& q = point.pose.orientation;
    std::snprintf(buffer, sizeof buffer, " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.x(), p.y(), p.z(), q.x(), q.y(),
                  q.z(), q.w());
    out << formatSeconds(point.stamp) << buffer;
  }
}

struct TumWriter::Impl {
  std::ofstream out;
};

TumWriter::TumWriter(const std::string& path, const std::string& comment, std::size_t flush_every)
    : impl_(std::make_unique<Impl>()), path_(path), flush_every_(std::max<std::size_t>(1, flush_every)) {
  impl_->out.open(path, std::ios::binary | std::ios::trunc);
  if (!impl_->out) throw Error(path + ": cannot create the trajectory file");
  writeTumTrajectory(impl_->out, {}, comment);
  impl_->out.flush();
}

TumWriter::~TumWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor cannot report it; close() called before does.
  }
}

void TumWriter::append(const TrajectoryPoint& point) {
  if (!impl_->out.is_open()) throw Error(path_ + ": the trajectory file is closed");
  writeTumTrajectory(impl_->out, {point});
  if (++points_ % flush_every_ == 0) impl_->out.flush();
  if (!impl_->out) throw Error(path_ + ": writing the trajectory file failed");
}

void TumWriter::close() {
  if (!impl_->out.is_open()) return;
  impl_->out.close();
  if (!impl_->out) throw Error(path_ + ": writing the trajectory file failed");
}

void writeTumTrajectory(const std::string& path, const std::vector<TrajectoryPoint>& points,
                        const std::string& comment) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path + ": cannot create the trajectory file");
  writeTumTrajectory(out, points, comment);
  out.close();
  if (!out) throw Error(path + ": writing the trajectory file failed");
}

std::vector<TrajectoryPoint> readTumTrajectory(std::istream& in, const std::string& source) {
  std::vector<TrajectoryPoint> points;
  std::size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // files written on Windows
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    points.push_back(parseLine(line, source, number));
  }
  if (in.bad()) throw Error(source + ": reading failed after line " + std::to_string(number));
  return points;
}

std::vector<TrajectoryPoint> readTumTrajectory(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the trajectory file");
  return readTumTrajectory(in, path);
}

}  // namespace coloc::io
