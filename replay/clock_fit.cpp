#include "coloc/replay/clock_fit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace coloc::replay {

Stamp ClockFit::toStampClock(Stamp log_time) const {
  return stamp_origin + static_cast<Duration>(std::llround(rate * static_cast<double>(log_time - log_origin)));
}

ClockFit fitClock(const std::vector<ClockSample>& samples) {
  if (samples.empty()) throw std::invalid_argument("fitClock needs at least one sample");
  // Coordinates relative to the first sample keep full nanosecond precision in doubles.
  const Stamp log0 = samples.front().log_time, stamp0 = samples.front().stamp;
  struct P { double x, y; };
  std::vector<P> points;
  points.reserve(samples.size());
  double mean_x = 0.0;
  for (const ClockSample& s : samples) {
    points.push_back({static_cast<double>(s.log_time - log0), static_cast<double>(s.stamp - stamp0)});
    mean_x += points.back().x;
  }
  mean_x /= static_cast<double>(points.size());
  std::sort(points.begin(), points.end(), [](const P& a, const P& b) { return a.x != b.x ? a.x < b.x : a.y > b.y; });
  // Upper hull, left to right (monotone chain).
  std::vector<P> hull;
  for (const P& p : points) {
    if (!hull.empty() && hull.back().x == p.x) continue;  // the highest y of each x came first
    while (hull.size() >= 2) {
      const P& a = hull[hull.size() - 2];
      const P& b = hull.back();
      const double cross = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
      if (cross >= 0.0) hull.pop_back();  // b lies on or below the chord a-p
      else break;
    }
    hull.push_back(p);
  }
  double rate = 1.0;
  P through = hull.front();
  for (std::size_t i = 0; i + 1 < hull.size(); ++i) {
    if (hull[i].x <= mean_x && mean_x <= hull[i + 1].x) {
      rate = (hull[i + 1].y - hull[i].y) / (hull[i + 1].x - hull[i].x);
      through = hull[i];
      break;
    }
  }
  ClockFit fit;
  fit.log_origin = log0;
  if (hull.size() >= 2 && rate >= 0.5 && rate <= 2.0) {
    fit.rate = rate;
    fit.stamp_origin = stamp0 + static_cast<Duration>(std::llround(through.y - rate * through.x));
  } else {
    double highest = -INFINITY;  // offset making the smallest delay zero
    for (const P& p : points) highest = std::max(highest, p.y - p.x);
    fit.rate = 1.0;
    fit.stamp_origin = stamp0 + static_cast<Duration>(std::llround(highest));
  }
  return fit;
}

}  // namespace coloc::replay
