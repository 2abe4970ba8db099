#pragma once
// Line and scatter plots as self-contained SVG files, which open in any browser or image viewer. Small
// on purpose: axes with round tick values, a legend, shaded bands (coverage ranges), equal aspect for
// maps of trajectories.
#include <string>
#include <vector>

namespace coloc::replay {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  std::string color;    ///< any SVG colour; empty = next of the default palette
  bool points = false;  ///< markers instead of a line
};

struct PlotBand {
  double from, to;  ///< along x
  std::string label;
  std::string color = "#2a9d8f";
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  std::vector<PlotBand> bands;
  bool equal_aspect = false;  ///< one metre is as long on both axes
  bool y_from_zero = false;
  int width = 900, height = 520;
};

std::string renderSvg(const Plot& plot);
/// Throws coloc::Error naming the file if it cannot be written.
void writeSvg(const std::string& path, const Plot& plot);

}  // namespace coloc::replay
