#include "coloc/core/yaml_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "coloc/core/config_error.hpp"

namespace coloc {

namespace {

std::string shortNumber(double v) {
  std::string s = std::to_string(v);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

}  // namespace

std::string YamlReader::readFile(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the " + what);
  // A folder opens as a stream on Linux and reads as nothing: say what it is, not that it is empty.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a folder, not the " + what);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

YAML::Node YamlReader::parse(const std::string& text) const {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(source_ + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

void YamlReader::fail(const YAML::Node& node, const std::string& key, const std::string& why) const {
  throwConfigError(source_, node.Mark().line, key, why);
}

double YamlReader::number(const YAML::Node& node, const std::string& key) const {
  double v = 0.0;
  try {
    if (!node.IsScalar()) fail(node, key, "expected a number");
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(node, key, "expected a number");
  }
  if (std::isnan(v)) fail(node, key, "must not be NaN");
  return v;
}

double YamlReader::finite(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!std::isfinite(v)) fail(node, key, "must be finite");
  return v;
}

double YamlReader::positive(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!(v > 0.0) || !std::isfinite(v)) fail(node, key, "must be a finite number > 0");
  return v;
}

double YamlReader::inRange(const YAML::Node& node, const std::string& key, double lo, double hi) const {
  const double v = number(node, key);
  if (!(v >= lo && v <= hi)) fail(node, key, "must be in [" + shortNumber(lo) + ", " + shortNumber(hi) + "]");
  return v;
}

long long YamlReader::integer(const YAML::Node& node, const std::string& key, long long lo, long long hi) const {
  long long v = 0;
  try {
    if (!node.IsScalar()) fail(node, key, "expected an integer");
    v = node.as<long long>();
  } catch (const YAML::Exception&) {
    fail(node, key, "expected an integer");
  }
  if (v < lo || v > hi) fail(node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

bool YamlReader::flag(const YAML::Node& node, const std::string& key) const {
  try {
    if (node.IsScalar()) return node.as<bool>();
  } catch (const YAML::Exception&) {
  }
  fail(node, key, "expected true or false");
}

std::string YamlReader::text(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) fail(node, key, "expected a string");
  return node.as<std::string>();
}

std::string YamlReader::choice(const YAML::Node& node, const std::string& key, std::initializer_list<const char*> options) const {
  const std::string v = text(node, key);
  std::string list;
  for (const char* o : options) {
    if (v == o) return v;
    list += std::string(list.empty() ? "" : ", ") + o;
  }
  fail(node, key, "expected one of " + list + ", got '" + v + "'");
}

std::vector<double> YamlReader::numbers(const YAML::Node& node, const std::string& key, std::size_t count, const std::string& shape) const {
  if (!node.IsSequence() || node.size() != count) fail(node, key, "expected " + shape);
  std::vector<double> v;
  v.reserve(count);
  for (std::size_t i = 0; i < count; ++i) v.push_back(number(node[i], key));
  return v;
}

std::vector<double> YamlReader::numberList(const YAML::Node& node, const std::string& key, double lo, double hi) const {
  if (!node.IsSequence() || node.size() == 0) fail(node, key, "expected a non-empty list of numbers");
  std::vector<double> v;
  for (const auto& e : node) v.push_back(inRange(e, key, lo, hi));
  return v;
}

std::vector<std::string> YamlReader::textList(const YAML::Node& node, const std::string& key) const {
  if (!node.IsSequence() || node.size() == 0) fail(node, key, "expected a non-empty list");
  std::vector<std::string> v;
  for (const auto& e : node) v.push_back(text(e, key));
  return v;
}

void YamlReader::requireMap(const YAML::Node& node, const std::string& key) const {
  if (!node.IsMap()) fail(node, key, "expected a mapping of keys to values");
}

std::string YamlReader::key(const YAML::Node& key_node) const {
  if (!key_node.IsScalar()) fail(key_node, "(a key)", "a key must be plain text, not a list or a mapping");
  return key_node.Scalar();
}

void YamlReader::allowKeys(const YAML::Node& node, const std::string& where, std::initializer_list<const char*> allowed) const {
  requireMap(node, where);
  std::string list;
  for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
  for (const auto& entry : node) {
    const std::string k = key(entry.first);
    bool ok = false;
    for (const char* a : allowed) ok = ok || k == a;
    if (!ok) fail(entry.first, (where.empty() || where == "(top level)" ? "" : where + ".") + k, "unknown key (" + list + ")");
  }
}

YAML::Node YamlReader::require(const YAML::Node& node, const char* key, const std::string& where) const {
  if (!node.IsMap() || !node[key]) fail(node, where, std::string("needs ") + key);
  return node[key];
}

}  // namespace coloc
