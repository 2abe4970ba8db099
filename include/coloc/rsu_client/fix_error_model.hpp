#pragma once
// The error of a commissioned RSU's fixes as the vehicle is told it (the registry's
// calibrated_variance and calibrated_error_by_range), measured from fixes against a reference vehicle.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::rsu_client {

/// From the fixes (map frame) of an RSU at `rsu_position` and their residuals (fix minus where the
/// reference vehicle was), in the same order: per band of `band` metres of range, the residuals along
/// and across each fix's line of sight at the band's mean range. With `headings` (the reference
/// vehicle's, rad, one per fix), also their mean forward and to the left of the vehicle, which the
/// vehicle then takes off, and the spread about it; without, the root mean square. Tails included
/// either way: what the filter is given must cover what it gets. A band with fewer than `fewest`
/// usable fixes (finite, off the RSU's own position, with a finite heading where headings are given)
/// gives no row: the rows about it bridge it. Empty when no band has enough, or when the sizes differ.
std::vector<RsuInfo::ErrorAtRange> fixErrorByRange(const Eigen::Vector2d& rsu_position, const std::vector<Eigen::Vector2d>& fixes,
                                                   const std::vector<Eigen::Vector2d>& residuals, double band, std::size_t fewest,
                                                   const std::vector<double>& headings = {});

}  // namespace coloc::rsu_client
