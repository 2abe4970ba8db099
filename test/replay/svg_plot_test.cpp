#include <gtest/gtest.h>

#include <cmath>

#include "coloc/replay/svg_plot.hpp"

namespace coloc::replay {
namespace {

TEST(SvgPlot, RendersSeriesLegendAndBandsAsValidSvg) {
  Plot plot;
  plot.title = "error <m>";
  plot.series.push_back({"fused", {0, 1, 2}, {0.1, 0.05, 0.02}, "", false});
  plot.series.push_back({"ndt", {0, 1, 2}, {0.2, 0.15, 0.12}, "", true});
  plot.bands.push_back({0.5, 1.5, "VLP-16 coverage"});
  const std::string svg = renderSvg(plot);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("error &lt;m&gt;"), std::string::npos);  // text is escaped
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_NE(svg.find("<circle"), std::string::npos);
  EXPECT_NE(svg.find("VLP-16 coverage"), std::string::npos);
}

TEST(SvgPlot, EmptyAndNonFiniteDataDoNotBreakTheAxes) {
  Plot plot;
  plot.series.push_back({"gap", {0, 1, 2}, {1.0, std::nan(""), 2.0}, "", false});
  plot.series.push_back({"empty", {}, {}, "", false});
  const std::string svg = renderSvg(plot);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

}  // namespace
}  // namespace coloc::replay
