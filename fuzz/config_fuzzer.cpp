// The YAML a user hands coloc: the first byte picks the pipeline config (config/coloc.yaml) or the RSU
// registry (config/rsu.yaml); the rest is the file's text.
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    if (data[0] % 2 == 0) {
      coloc::pipeline::parseConfig(text, "fuzz.yaml");
    } else {
      const coloc::rsu_client::RsuRegistry registry = coloc::rsu_client::RsuRegistry::parse(text, "fuzz.yaml");
      // The registry coloc writes must read back (the twin and commissioning write registries).
      coloc::rsu_client::RsuRegistry::parse(registry.toYaml(), "again.yaml");
    }
  } catch (const coloc::Error&) {
  }
  return 0;
}
