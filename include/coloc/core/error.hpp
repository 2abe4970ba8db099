#pragma once
// The one exception type coloc throws. Its message always names the input (file, topic, message
// index, config key) and the reason, so that a user can act on it without a debugger.
#include <stdexcept>
#include <string>

namespace coloc {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace coloc
