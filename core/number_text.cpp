#include "coloc/core/number_text.hpp"

#include <cstdio>
#include <cstdlib>

namespace coloc {

std::string exactNumberText(double v, int min_precision) {
  char buffer[40];
  for (int precision = min_precision; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof buffer, "%.*g", precision, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  return buffer;
}

}  // namespace coloc
