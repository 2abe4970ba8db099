#pragma once
// Numbers written into configuration files: as short as they can be and still read back to the bit,
// so that defaults print as they are written and any configuration written out is the same one.
#include <string>

namespace coloc {

/// The shortest "%g" text, with at least `min_precision` significant digits when that is shorter,
/// that strtod reads back as exactly `v` (finite values).
std::string exactNumberText(double v, int min_precision = 6);

}  // namespace coloc
