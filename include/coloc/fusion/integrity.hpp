#pragma once
// Whether the filter's estimate can be believed. Beside every estimate the filter reports a state:
// initialising (no estimate yet), localized, degraded (its sources disagree with it, or it has gone
// without a pose for a while) or lost (an independent anchor, such as a roadside fix, keeps telling
// the same different story), with the reason. While degraded or lost the reported position covariance
// grows by the disagreement, so that a filter metres off never reports centimetres.
#include <cstdint>
#include <string>

#include "coloc/core/time.hpp"

namespace coloc::fusion {

enum class LocalizationState : std::uint8_t { kInitialising, kLocalized, kDegraded, kLost };
const char* toString(LocalizationState state);

struct IntegrityStatus {
  LocalizationState state = LocalizationState::kInitialising;
  std::string reason;              ///< why the state is what it is; empty when localized
  Stamp since = 0;                 ///< the filter's time when the state was entered
  std::uint64_t degradations = 0;  ///< times the state became degraded
  std::uint64_t losses = 0;        ///< times it became lost
  /// A search of the map doubted the position (Localizer::doubt) and no anchor has confirmed it since.
  bool doubted = false;
};

}  // namespace coloc::fusion
