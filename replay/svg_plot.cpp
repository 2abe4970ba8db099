#include "coloc/replay/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "coloc/core/error.hpp"

namespace coloc::replay {

namespace {

const char* const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// Round tick spacing (1, 2 or 5 times a power of ten) giving about `count` ticks over the span.
double tickStep(double span, int count) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / magnitude;
  return magnitude * (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0);
}

std::string number(double v) {
  std::ostringstream out;
  out << (std::abs(v) < 1e-12 ? 0.0 : v);
  return out.str();
}

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void pad() {
    if (!std::isfinite(lo)) lo = 0.0, hi = 1.0;
    if (hi - lo < 1e-9) lo -= 0.5, hi += 0.5;
    const double margin = 0.04 * (hi - lo);
    lo -= margin;
    hi += margin;
  }
};

}  // namespace

std::string renderSvg(const Plot& plot) {
  const double left = 78, right = 20, top = 40, bottom = 58;
  const double legend_height = 18.0 * static_cast<double>(plot.series.size() + plot.bands.size());
  const double w = plot.width - left - right, h = plot.height - top - bottom;
  Range xr, yr;
  for (const auto& s : plot.series) {
    for (double v : s.x) xr.add(v);
    for (double v : s.y) yr.add(v);
  }
  for (const auto& b : plot.bands) xr.add(b.from), xr.add(b.to);
  if (plot.y_from_zero) yr.add(0.0);
  xr.pad();
  yr.pad();
  if (plot.y_from_zero && yr.lo < 0.0) yr.lo = 0.0;
  yr.hi += (yr.hi - yr.lo) * legend_height / std::max(h - legend_height, 1.0);  // room for the legend
  if (plot.equal_aspect) {
    const double scale = std::max((xr.hi - xr.lo) / w, (yr.hi - yr.lo) / h);
    const double cx = 0.5 * (xr.lo + xr.hi), cy = 0.5 * (yr.lo + yr.hi);
    xr.lo = cx - 0.5 * scale * w, xr.hi = cx + 0.5 * scale * w;
    yr.lo = cy - 0.5 * scale * h, yr.hi = cy + 0.5 * scale * h;
  }
  auto X = [&](double v) { return left + (v - xr.lo) / (xr.hi - xr.lo) * w; };
  auto Y = [&](double v) { return top + h - (v - yr.lo) / (yr.hi - yr.lo) * h; };

  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << plot.width << "\" height=\"" << plot.height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<text x=\"" << plot.width / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape(plot.title) << "</text>\n";
  for (std::size_t i = 0; i < plot.bands.size(); ++i) {
    const PlotBand& b = plot.bands[i];
    svg << "<rect x=\"" << X(b.from) << "\" y=\"" << top << "\" width=\"" << X(b.to) - X(b.from) << "\" height=\"" << h
        << "\" fill=\"" << b.color << "\" fill-opacity=\"0.12\"/>\n";
  }
  // Grid and tick labels.
  const double xs = tickStep(xr.hi - xr.lo, 8), ys = tickStep(yr.hi - yr.lo, 6);
  for (double v = std::ceil(xr.lo / xs) * xs; v <= xr.hi; v += xs)
    svg << "<line x1=\"" << X(v) << "\" y1=\"" << top << "\" x2=\"" << X(v) << "\" y2=\"" << top + h
        << "\" stroke=\"#ddd\"/><text x=\"" << X(v) << "\" y=\"" << top + h + 16 << "\" text-anchor=\"middle\">" << number(v)
        << "</text>\n";
  for (double v = std::ceil(yr.lo / ys) * ys; v <= yr.hi; v += ys)
    svg << "<line x1=\"" << left << "\" y1=\"" << Y(v) << "\" x2=\"" << left + w << "\" y2=\"" << Y(v)
        << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << Y(v) + 4 << "\" text-anchor=\"end\">" << number(v)
        << "</text>\n";
  svg << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h
      << "\" fill=\"none\" stroke=\"#333\"/>\n";
  svg << "<text x=\"" << left + w / 2 << "\" y=\"" << plot.height - 14 << "\" text-anchor=\"middle\">" << escape(plot.x_label)
      << "</text>\n";
  svg << "<text transform=\"translate(18," << top + h / 2 << ") rotate(-90)\" text-anchor=\"middle\">" << escape(plot.y_label)
      << "</text>\n";
  // Data, clipped to the plot area.
  svg << "<clipPath id=\"area\"><rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h
      << "\"/></clipPath>\n<g clip-path=\"url(#area)\">\n";
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    const std::string color = s.color.empty() ? kPalette[i % 8] : s.color;
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.points) {
      for (std::size_t k = 0; k < n; ++k)
        if (std::isfinite(s.x[k]) && std::isfinite(s.y[k]))
          svg << "<circle cx=\"" << X(s.x[k]) << "\" cy=\"" << Y(s.y[k]) << "\" r=\"2.2\" fill=\"" << color << "\"/>\n";
      continue;
    }
    svg << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"1.5\" points=\"";
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) {  // a gap: end this line, start another
        svg << "\"/>\n<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"1.5\" points=\"";
        continue;
      }
      svg << X(s.x[k]) << "," << Y(s.y[k]) << " ";
    }
    svg << "\"/>\n";
  }
  svg << "</g>\n";
  // Legend, top left inside the plot.
  double ly = top + 14;
  for (std::size_t i = 0; i < plot.series.size(); ++i, ly += 18) {
    const std::string color = plot.series[i].color.empty() ? kPalette[i % 8] : plot.series[i].color;
    svg << "<rect x=\"" << left + 10 << "\" y=\"" << ly - 9 << "\" width=\"18\" height=\"" << (plot.series[i].points ? 6 : 3)
        << "\" fill=\"" << color << "\"/><text x=\"" << left + 34 << "\" y=\"" << ly - 3 << "\">" << escape(plot.series[i].label)
        << "</text>\n";
  }
  for (const PlotBand& b : plot.bands) {
    svg << "<rect x=\"" << left + 10 << "\" y=\"" << ly - 12 << "\" width=\"18\" height=\"10\" fill=\"" << b.color
        << "\" fill-opacity=\"0.25\"/><text x=\"" << left + 34 << "\" y=\"" << ly - 3 << "\">" << escape(b.label) << "</text>\n";
    ly += 18;
  }
  svg << "</svg>\n";
  return svg.str();
}

void writeSvg(const std::string& path, const Plot& plot) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write the plot");
  out << renderSvg(plot);
  if (!out) throw Error(path + ": write failed");
}

}  // namespace coloc::replay
