#include <gtest/gtest.h>

#include <set>
#include <string>

#include "coloc/fusion/ekf_params.hpp"

namespace coloc::fusion {
namespace {

TEST(EkfParams, EveryKeyIsUniqueAndDocumented) {
  std::set<std::string> keys;
  for (const EkfParam& p : ekfParams()) {
    EXPECT_TRUE(keys.insert(p.key).second) << "duplicate key " << p.key;
    EXPECT_GT(std::string(p.meaning).size(), 10u) << p.key;
  }
  // One row per EkfConfig field (42); a field added without a table row would be unreachable from YAML.
  EXPECT_EQ(keys.size(), 42u);
}

TEST(EkfParams, FormatsDefaultsAsTheirYamlText) {
  const EkfConfig defaults;
  for (const EkfParam& p : ekfParams()) {
    const std::string key = p.key;
    if (key == "predict_frequency") { EXPECT_EQ(formatValue(p, defaults), "50.0"); }
    if (key == "history_steps") { EXPECT_EQ(formatValue(p, defaults), "50"); }
    if (key == "pose_gate_alpha") { EXPECT_EQ(formatValue(p, defaults), "1e-10"); }
    if (key == "auto_initialize") { EXPECT_EQ(formatValue(p, defaults), "true"); }
  }
}

}  // namespace
}  // namespace coloc::fusion
