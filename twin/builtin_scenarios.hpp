#pragma once
#include <string>
// The scenarios of config/scenarios/, compiled in so that `coloc experiment` runs on built-in defaults
// from any folder.
namespace coloc::twin {

/// The YAML text of the built-in scenario `name` (file name without .yaml), or nullptr.
const char* builtinScenario(const char* name);
inline const char* builtinScenario(const std::string& name) { return builtinScenario(name.c_str()); }

/// The built-in scenarios' names, comma-separated, for messages.
const char* builtinScenarioNames();

}  // namespace coloc::twin
