#pragma once
// The one reader of YAML values for every configuration file (the coloc config, the RSU registry,
// scenarios, experiments): each value is read with its key for the error message, so that every file
// reports mistakes the same way, "FILE:LINE: KEY: WHY".
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

namespace coloc {

class YamlReader {
 public:
  /// `source` names the file (or the text's origin) in every error.
  explicit YamlReader(std::string source) : source_(std::move(source)) {}
  const std::string& source() const { return source_; }

  /// A configuration file's whole text; throws coloc::Error "PATH: cannot open the WHAT" if it cannot.
  static std::string readFile(const std::string& path, const std::string& what);

  /// Parses a document; a syntax error names the file and line.
  YAML::Node parse(const std::string& text) const;

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& why) const;

  /// Any number but NaN; .inf is allowed (covariances use it for "not measured").
  double number(const YAML::Node& node, const std::string& key) const;
  double finite(const YAML::Node& node, const std::string& key) const;
  /// Finite and > 0.
  double positive(const YAML::Node& node, const std::string& key) const;
  /// Finite, within [lo, hi].
  double inRange(const YAML::Node& node, const std::string& key, double lo, double hi) const;
  double probability(const YAML::Node& node, const std::string& key) const { return inRange(node, key, 0.0, 1.0); }
  long long integer(const YAML::Node& node, const std::string& key, long long lo, long long hi) const;
  bool flag(const YAML::Node& node, const std::string& key) const;
  std::string text(const YAML::Node& node, const std::string& key) const;
  /// One of `options`, else an error listing them.
  std::string choice(const YAML::Node& node, const std::string& key, std::initializer_list<const char*> options) const;
  /// A list of exactly `count` numbers (NaN refused, .inf allowed); `shape` describes it, e.g. "[x, y]".
  std::vector<double> numbers(const YAML::Node& node, const std::string& key, std::size_t count, const std::string& shape) const;

  /// A non-empty list of numbers, each within [lo, hi].
  std::vector<double> numberList(const YAML::Node& node, const std::string& key, double lo, double hi) const;
  /// A non-empty list of strings.
  std::vector<std::string> textList(const YAML::Node& node, const std::string& key) const;

  void requireMap(const YAML::Node& node, const std::string& key) const;
  /// A mapping's key as text; a key that is a list or a mapping (YAML allows them) fails, with its line.
  std::string key(const YAML::Node& key_node) const;
  /// Fails on the first key of the mapping `node` that is not in `allowed`, listing the allowed ones.
  void allowKeys(const YAML::Node& node, const std::string& where, std::initializer_list<const char*> allowed) const;
  /// The child `key` of `node`, which must be there.
  YAML::Node require(const YAML::Node& node, const char* key, const std::string& where) const;

 private:
  std::string source_;
};

}  // namespace coloc
