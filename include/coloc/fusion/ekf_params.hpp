#pragma once
// A table describing every EkfConfig field: its config key, unit and meaning. The defaults stay in
// EkfConfig's initialisers (the one place); this table lets the YAML loader, `coloc config` and the
// reference table in docs/configuration.md all speak of the same keys without repeating them.
#include <string>
#include <variant>
#include <vector>

#include "coloc/fusion/ekf_config.hpp"

namespace coloc::fusion {

struct EkfParam {
  const char* key;
  const char* unit;
  const char* meaning;
  std::variant<double EkfConfig::*, int EkfConfig::*, bool EkfConfig::*> field;
};

/// Every key of the `fusion:` section, in documentation order.
const std::vector<EkfParam>& ekfParams();

/// The field's value in `config`, formatted as YAML would show it.
std::string formatValue(const EkfParam& param, const EkfConfig& config);

}  // namespace coloc::fusion
