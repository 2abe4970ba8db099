#include "coloc/twin/experiment_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <cstdlib>
#include <tuple>
#include <vector>

#include "coloc/core/error.hpp"
#include "coloc/fusion/verdict.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/replay/svg_plot.hpp"

namespace coloc::twin {

using replay::Plot;
using replay::PlotBand;
using replay::PlotSeries;
using replay::writeSvg;

namespace {

struct Spread {
  double mean = 0.0, sd = 0.0, min = 0.0, max = 0.0;
  std::size_t n = 0;
  /// The mean's standard error (the values independent: each from a drive of its own); NaN from fewer than two.
  double standardError() const { return n > 1 ? sd / std::sqrt(static_cast<double>(n)) : std::numeric_limits<double>::quiet_NaN(); }
};

Spread spread(const std::vector<double>& v) {
  Spread s;
  s.n = v.size();
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= v.size();
  for (double x : v) s.sd += (x - s.mean) * (x - s.mean);
  s.sd = v.size() > 1 ? std::sqrt(s.sd / (v.size() - 1)) : 0.0;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

std::string fmt(const char* f, double a) {
  char b[64];
  std::snprintf(b, sizeof b, f, a);
  return b;
}
std::string cm(const Spread& s) {  // "9.9 ± 0.4 cm"
  char b[64];
  if (s.n > 1) std::snprintf(b, sizeof b, "%.1f ± %.1f cm", 100 * s.mean, 100 * s.sd);
  else std::snprintf(b, sizeof b, "%.1f cm", 100 * s.mean);
  return b;
}
double improvement(double baseline, double fused) { return baseline > 0.0 ? 100.0 * (1.0 - fused / baseline) : 0.0; }

// Where NDT alone errs by less than this, the fused error is a fraction of a few centimetres and a
// percentage of it measures noise: Table I gives the ratio of fused to NDT there, and the improvement
// only where NDT falls short (the paper's locations: 8-13 cm).
constexpr double kNdtFallsShort = 0.05;  // m
// network.csv's scope for those sites pooled.
constexpr const char* kNdtFallsShortScope = "ndt_falls_short";
// "93 % (91-95)" where NDT falls short, "0.48x NDT" where it does not.
std::string gainCell(double ndt, double fused, const Spread* range = nullptr) {
  if (ndt < kNdtFallsShort) return fmt("%.2fx NDT", ndt > 0.0 ? fused / ndt : 0.0);
  std::string cell = fmt("%.0f %%", improvement(ndt, fused));
  if (range && range->n > 1) cell += fmt(" (%.0f", range->min) + fmt("-%.0f)", range->max);
  return cell;
}

double rangeOf(const std::string& lidar) {
  const rsu_client::LidarModel* m = rsu_client::findLidarModel(lidar);
  return m ? m->range : 0.0;
}

const ExperimentRun* find(const std::vector<ExperimentRun>& runs, const std::string& site, int trial, const std::string& lidar,
                          double delay, double loss, const std::string& variant) {
  for (const ExperimentRun& r : runs)
    if (r.site == site && r.trial == trial && r.lidar == lidar && r.delay == delay && r.loss == loss && r.variant == variant) return &r;
  return nullptr;
}

// Minimum error in each bin of road (the paper's per-2-m figure), over the samples within `range` of the RSU.
std::map<long, double> binMinima(const ExperimentRun& run, double bin, double range = std::numeric_limits<double>::infinity()) {
  std::map<long, double> m;
  for (std::size_t i = 0; i < run.error.size(); ++i) {
    if (run.to_rsu[i] > range) continue;
    const long k = static_cast<long>(std::floor(run.along[i] / bin));
    auto it = m.find(k);
    if (it == m.end()) m[k] = run.error[i];
    else it->second = std::min(it->second, run.error[i]);
  }
  return m;
}

const char* colorOf(const std::string& lidar, bool light) {
  if (lidar.empty()) return light ? "#9ecae1" : "#1f77b4";
  if (lidar == "VLP-16") return light ? "#fdd0a2" : "#ff7f0e";
  return light ? "#a1d99b" : "#2ca02c";
}

// Where along the drive the vehicle is within `range` of the RSU (from a run's samples).
std::pair<double, double> coverageAlong(const ExperimentRun& run, double range) {
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < run.error.size(); ++i)
    if (run.to_rsu[i] <= range) lo = std::min(lo, run.along[i]), hi = std::max(hi, run.along[i]);
  return {lo, hi};
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw Error(path + ": cannot write");
}

}  // namespace

double errorOutsideCoverage(const ExperimentRun& run, double range) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < run.error.size(); ++i)
    if (run.to_rsu[i] > range) sum += run.error[i], ++n;
  return n ? sum / n : 0.0;
}

ErrorInCoverage errorInCoverage(const ExperimentRun& run, double range, double bin_length) {
  ErrorInCoverage e;
  for (std::size_t i = 0; i < run.error.size(); ++i)
    if (run.to_rsu[i] <= range) e.plain += run.error[i], ++e.samples;
  if (e.samples == 0) return e;
  e.plain /= e.samples;
  const std::map<long, double> minima = binMinima(run, bin_length, range);
  for (const auto& [k, v] : minima) e.paper += v;
  e.paper /= minima.size();
  return e;
}

std::string writeExperimentReport(const ExperimentResults& results, const std::string& out_dir, const std::string& command_line) {
  const ExperimentConfig& c = results.config;
  const double bin = c.bin_length;
  std::ostringstream md;
  // The tables a run may write. An earlier run's into the same folder go first: a quick run after a full
  // one leaves no calibration or sweep table of the full run's beside its own.
  static const char* const kTables[] = {"table1.csv", "smoother.csv", "calibration.csv", "network.csv", "sweeps.csv",
                                        "fix_error_by_distance.csv", "attribution.csv", "ndt_vs_fused.csv"};
  for (const char* t : kTables) std::filesystem::remove(out_dir + "/" + t);
  std::filesystem::remove(out_dir + "/network.svg");  // the network table's figure

  // runs.csv: every replay's error within each LiDAR's coverage.
  {
    std::ostringstream csv;
    csv << "site,trial,configuration,lidar,delay_s,loss,variant,coverage_lidar,range_m,error_paper_m,error_mean_m,samples,fixes_applied,"
           "fixes_gated,fixes_lost,replay_s\n";
    for (const ExperimentRun& r : results.runs)
      for (const std::string& lidar : c.lidars) {
        const ErrorInCoverage e = errorInCoverage(r, rangeOf(lidar), bin);
        csv << r.site << "," << r.trial << ",\"" << r.label() << "\"," << r.lidar << "," << r.delay << "," << r.loss << ",\"" << r.variant
            << "\"," << lidar << "," << rangeOf(lidar) << "," << e.paper << "," << e.plain << "," << e.samples << "," << r.fixes_applied << ","
            << r.fixes_gated << "," << r.fixes_lost << "," << r.replay_seconds << "\n";
      }
    writeFile(out_dir + "/runs.csv", csv.str());
  }

  // Table I, with the main covariance and the reference one beside it.
  const std::string reference = std::string("covariance ") + toString(referenceCovariance(c.rsu_covariance));
  std::ostringstream table1, table1_csv;
  table1 << "| site | roadside LiDAR | coverage | NDT only | NDT + RSU | improvement (ratio where NDT < " << fmt("%.0f", 100 * kNdtFallsShort)
         << " cm) | NDT + RSU, smoother | NDT + RSU, " << reference
         << " | improvement | NDT only (all samples) | NDT + RSU (all samples) | improvement (all samples) |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  table1_csv << "site,lidar,range_m,trials,ndt_paper_m,ndt_paper_sd,fused_paper_m,fused_paper_sd,improvement_paper_pct,improvement_min_pct,"
                "improvement_max_pct,ndt_mean_m,fused_mean_m,improvement_mean_pct,reference_covariance,fused_reference_paper_m,"
                "improvement_reference_pct,smoothed_paper_m,smoothed_mean_m,fused_over_ndt_paper\n";
  for (const SiteInfo& site : results.sites)
    for (const std::string& lidar : c.lidars) {
      const double range = rangeOf(lidar);
      std::vector<double> ndt_p, fused_p, ndt_m, fused_m, gain, ref_p, smooth_p, smooth_m;
      for (int t = 0; t < c.trials; ++t) {
        const ExperimentRun* ndt = find(results.runs, site.name, t, "", 0, 0, "");
        const ExperimentRun* fused = find(results.runs, site.name, t, lidar, 0, 0, "");
        if (!ndt || !fused) continue;
        const ErrorInCoverage a = errorInCoverage(*ndt, range, bin), b = errorInCoverage(*fused, range, bin);
        if (a.samples == 0) continue;  // the drive never within this LiDAR's coverage of any RSU
        ndt_p.push_back(a.paper), fused_p.push_back(b.paper), ndt_m.push_back(a.plain), fused_m.push_back(b.plain);
        gain.push_back(improvement(a.paper, b.paper));
        if (const ExperimentRun* ref = find(results.runs, site.name, t, lidar, 0, 0, reference))
          ref_p.push_back(errorInCoverage(*ref, range, bin).paper);
        if (const ExperimentRun* sm = find(results.runs, site.name, t, lidar, 0, 0, kSmootherVariant)) {
          const ErrorInCoverage e = errorInCoverage(*sm, range, bin);
          smooth_p.push_back(e.paper), smooth_m.push_back(e.plain);
        }
      }
      if (ndt_p.empty()) {
        table1 << "| " << site.name << " | " << lidar << " | " << fmt("%.0f m", range) << " | never in coverage | - | - | - | - | - | - | - | - |\n";
        table1_csv << site.name << "," << lidar << "," << range << ",0,,,,,,,,,,,,,,,,\n";
        continue;
      }
      const Spread np = spread(ndt_p), fp = spread(fused_p), nm = spread(ndt_m), fm = spread(fused_m), g = spread(gain), rp = spread(ref_p),
                   sp = spread(smooth_p), sm = spread(smooth_m);
      table1 << "| " << site.name << " | " << lidar << " | " << fmt("%.0f m", range) << " | " << cm(np) << " | " << cm(fp) << " | "
             << gainCell(np.mean, fp.mean, &g) << " | " << (sp.n ? cm(sp) : "-") << " | " << (rp.n ? cm(rp) : "-") << " | "
             << (rp.n ? gainCell(np.mean, rp.mean) : "-") << " | " << cm(nm) << " | " << cm(fm) << " | " << gainCell(nm.mean, fm.mean) << " |\n";
      table1_csv << site.name << "," << lidar << "," << range << "," << np.n << "," << np.mean << "," << np.sd << "," << fp.mean << "," << fp.sd
                 << "," << improvement(np.mean, fp.mean) << "," << g.min << "," << g.max << "," << nm.mean << "," << fm.mean << ","
                 << improvement(nm.mean, fm.mean) << "," << toString(referenceCovariance(c.rsu_covariance)) << "," << rp.mean << ","
                 << improvement(np.mean, rp.mean) << "," << (sp.n ? sp.mean : std::nan("")) << "," << (sm.n ? sm.mean : std::nan("")) << ","
                 << (np.mean > 0.0 ? fp.mean / np.mean : std::nan("")) << "\n";
    }
  writeFile(out_dir + "/table1.csv", table1_csv.str());

  // The smoother against the filter, on the same replays: plain means within and outside coverage.
  std::ostringstream smoother_md;
  {
    std::ostringstream csv;
    csv << "site,lidar,range_m,trials,ndt_filter_in_m,ndt_smoother_in_m,fused_filter_in_m,fused_smoother_in_m,ratio_in,fused_filter_out_m,"
           "fused_smoother_out_m,ratio_out\n";
    smoother_md << "| site | roadside LiDAR | NDT only: filter | NDT only: smoother | NDT + RSU: filter | NDT + RSU: smoother | smoother / filter "
                   "in coverage | NDT + RSU outside coverage: filter | smoother | smoother / filter outside |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SiteInfo& site : results.sites)
      for (const std::string& lidar : c.lidars) {
        const double range = rangeOf(lidar);
        std::vector<double> nf, ns, ff, fs, ffo, fso;
        for (int t = 0; t < c.trials; ++t) {
          const ExperimentRun* ndt = find(results.runs, site.name, t, "", 0, 0, "");
          const ExperimentRun* ndt_s = find(results.runs, site.name, t, "", 0, 0, kSmootherVariant);
          const ExperimentRun* fused = find(results.runs, site.name, t, lidar, 0, 0, "");
          const ExperimentRun* fused_s = find(results.runs, site.name, t, lidar, 0, 0, kSmootherVariant);
          if (!ndt || !ndt_s || !fused || !fused_s) continue;
          nf.push_back(errorInCoverage(*ndt, range, bin).plain);
          ns.push_back(errorInCoverage(*ndt_s, range, bin).plain);
          ff.push_back(errorInCoverage(*fused, range, bin).plain);
          fs.push_back(errorInCoverage(*fused_s, range, bin).plain);
          ffo.push_back(errorOutsideCoverage(*fused, range));
          fso.push_back(errorOutsideCoverage(*fused_s, range));
        }
        if (nf.empty()) continue;
        const Spread a = spread(nf), b = spread(ns), f1 = spread(ff), f2 = spread(fs), o1 = spread(ffo), o2 = spread(fso);
        smoother_md << "| " << site.name << " | " << lidar << " | " << cm(a) << " | " << cm(b) << " | " << cm(f1) << " | " << cm(f2) << " | "
                    << fmt("%.2fx", f2.mean / f1.mean) << " | " << cm(o1) << " | " << cm(o2) << " | " << fmt("%.2fx", o2.mean / o1.mean) << " |\n";
        csv << site.name << "," << lidar << "," << range << "," << a.n << "," << a.mean << "," << b.mean << "," << f1.mean << "," << f2.mean << ","
            << f2.mean / f1.mean << "," << o1.mean << "," << o2.mean << "," << o2.mean / o1.mean << "\n";
      }
    if (!smoother_md.str().empty()) writeFile(out_dir + "/smoother.csv", csv.str());
  }

  // A LiDAR model's row names its RSU where the site has several of that model.
  const auto withRsu = [&](const std::string& site, const std::string& lidar, const std::string& rsu) {
    std::set<std::string> ids;
    for (const CalibrationResult& c : results.calibrations)
      if (c.site == site && c.lidar == lidar) ids.insert(c.rsu);
    for (const Commissioning& c : results.commissioning)
      if (c.site == site && c.lidar == lidar) ids.insert(c.rsu);
    return ids.size() > 1 ? lidar + " (" + rsu + ")" : lidar;
  };

  // The calibration table: what one drive found, and what it is worth on the next one.
  std::ostringstream calibration_md;
  if (!results.calibrations.empty()) {
    std::ostringstream csv;
    csv << "site,lidar,rsu,injected_dx_m,injected_dy_m,injected_dyaw_deg,injected_clock_ms,dx_m,dy_m,dyaw_deg,clock_ms,sd_dx_m,sd_dy_m,sd_dyaw_deg,"
           "sd_clock_ms,observable,clock_observable,next_as_surveyed_m,next_calibrated_m,next_perfect_m\n";
    calibration_md << "| site | roadside LiDAR | injected (dx, dy, dyaw, clock) | found (± sd) | next drive, registry as surveyed | "
                      "calibrated | perfect RSU | calibrated / perfect |\n|---|---|---|---|---|---|---|---|\n";
    const double deg = 180.0 / M_PI;
    for (const CalibrationResult& cr : results.calibrations) {
      const double range = rangeOf(cr.lidar);
      auto next = [&](const char* variant) {
        const ExperimentRun* r = nullptr;
        for (const ExperimentRun& run : results.runs)
          if (run.site == cr.site && run.lidar == cr.lidar && run.variant == variant) r = &run;
        return r ? errorInCoverage(*r, range, bin).plain : std::nan("");
      };
      const double as_surveyed = next(kNextMiscalibrated), calibrated = next(kNextCalibrated), perfect = next(kNextPerfect);
      const smoother::RsuCalibration& f = cr.found;
      char injected[128], found[192];
      std::snprintf(injected, sizeof injected, "%.3f m, %.3f m, %.2f deg, %.1f ms", cr.dx, cr.dy, cr.dyaw * deg, cr.clock_offset * 1e3);
      if (f.observable && f.clock_observable)
        std::snprintf(found, sizeof found, "%.3f ± %.3f m, %.3f ± %.3f m, %.3f ± %.3f deg, %.1f ± %.1f ms", f.dx, f.sd_dx, f.dy, f.sd_dy, f.dyaw * deg,
                      f.sd_dyaw * deg, f.clock_offset * 1e3, f.sd_clock_offset * 1e3);
      else if (f.observable)
        std::snprintf(found, sizeof found, "%.3f ± %.3f m, %.3f ± %.3f m, %.3f ± %.3f deg, clock not separable (one speed): held at 0", f.dx, f.sd_dx,
                      f.dy, f.sd_dy, f.dyaw * deg, f.sd_dyaw * deg);
      else
        std::snprintf(found, sizeof found, "not determined (%s)", f.note.c_str());
      calibration_md << "| " << cr.site << " | " << withRsu(cr.site, cr.lidar, cr.rsu) << " | " << injected << " | " << found << " | " << fmt("%.2f cm", 100 * as_surveyed)
                     << " | " << (std::isnan(calibrated) ? std::string("-") : fmt("%.2f cm", 100 * calibrated)) << " | "
                     << fmt("%.2f cm", 100 * perfect) << " | " << (std::isnan(calibrated) ? std::string("-") : fmt("%.2fx", calibrated / perfect))
                     << " |\n";
      csv << cr.site << "," << cr.lidar << "," << cr.rsu << "," << cr.dx << "," << cr.dy << "," << cr.dyaw * deg << "," << cr.clock_offset * 1e3 << "," << f.dx << ","
          << f.dy << "," << f.dyaw * deg << "," << f.clock_offset * 1e3 << "," << f.sd_dx << "," << f.sd_dy << "," << f.sd_dyaw * deg << ","
          << f.sd_clock_offset * 1e3 << "," << (f.observable ? 1 : 0) << "," << (f.clock_observable ? 1 : 0) << "," << as_surveyed << "," << calibrated << "," << perfect << "\n";
    }
    writeFile(out_dir + "/calibration.csv", csv.str());
  }

  // The error sources: fix error against distance, real beside ideal, on each site's noise calibration
  // drive (the same frames imaged twice).
  std::ostringstream sources_md;
  if (!results.ideal_comparison.empty()) {
    constexpr double kBin = 5.0;
    constexpr int kBins = 6;
    std::ostringstream csv;
    csv << "site_lidar,distance_from_m,distance_to_m,frames,fixes_real,fixes_ideal,mean_error_real_m,mean_error_ideal_m,p95_error_real_m\n";
    sources_md << "| site, roadside LiDAR |";
    for (int b = 0; b < kBins; ++b) sources_md << fmt(" %.0f-", b * kBin) << fmt("%.0f m |", (b + 1) * kBin);
    sources_md << " all |\n|---|";
    for (int b = 0; b <= kBins; ++b) sources_md << "---|";
    sources_md << "\n";
    for (const auto& [key, frames] : results.ideal_comparison) {
      sources_md << "| " << key << " |";
      for (int b = 0; b <= kBins; ++b) {
        std::vector<double> real, ideal;
        std::size_t n = 0;
        for (const RsuFrameRecord& f : frames) {
          const bool in_bin = b == kBins || (f.distance >= b * kBin && (f.distance < (b + 1) * kBin || b == kBins - 1));
          if (!in_bin) continue;
          ++n;
          if (f.found) real.push_back(f.error);
          if (f.ideal_error >= 0.0) ideal.push_back(f.ideal_error);
        }
        const double mr = real.empty() ? std::nan("") : spread(real).mean, mi = ideal.empty() ? std::nan("") : spread(ideal).mean;
        double p95 = std::nan("");
        if (!real.empty()) {
          std::sort(real.begin(), real.end());
          p95 = real[static_cast<std::size_t>(0.95 * static_cast<double>(real.size() - 1))];
        }
        // A bin with frames but no fix on one side says so ("-") rather than "nan".
        const auto cm = [&](double v) { return std::isnan(v) ? std::string("-") : fmt("%.1f", 100 * v); };
        sources_md << " " << (n == 0 ? std::string("-") : cm(mr) + " / " + cm(mi) + " cm") << " |";
        csv << key << "," << (b < kBins ? b * kBin : 0.0) << "," << (b < kBins ? (b + 1) * kBin : 1e3) << "," << n << "," << real.size() << ","
            << ideal.size() << "," << mr << "," << mi << "," << p95 << "\n";
      }
      sources_md << "\n";
    }
    writeFile(out_dir + "/fix_error_by_distance.csv", csv.str());
  }

  // Commissioning: each RSU's survey and clock error as drawn, and as the reference vehicle found it.
  if (!results.commissioning.empty()) {
    const double deg = 180.0 / M_PI;
    sources_md << "\nEach RSU's survey and clock error as drawn from the error sources, and as commissioning against the reference "
                  "vehicle on the noise calibration drive found it (`rsu_client/commissioning`: fixes matched by stamp to the "
                  "reference trajectory); the evaluated drives use the calibration when it is determined. The last two columns hold "
                  "the fixes as sent, calibrated, against the covariance of their own fit (`roadside/fix_covariance`): the mean "
                  "normalized squared error (2 if honest) and the fixes beyond three standard deviations (1.1 % if honest):\n\n"
               << "| site | roadside LiDAR | drawn (dx, dy, dyaw, clock) | found (± sd) | fixes used / left out | residual sd | fixes' NES | beyond 3 sd |\n"
                  "|---|---|---|---|---|---|---|---|\n";
    for (const Commissioning& cr : results.commissioning) {
      const rsu_client::CommissioningResult& f = cr.found;
      char drawn[128], found[224];
      std::snprintf(drawn, sizeof drawn, "%.3f m, %.3f m, %.3f deg, %.2f ms", cr.dx, cr.dy, cr.dyaw * deg, cr.clock_offset * 1e3);
      const std::string clock =
          f.clock_observable ? fmt("%.2f", f.calibration.clock_offset * 1e3) + fmt(" ± %.2f ms", f.sd[3] * 1e3) : std::string("clock held at 0");
      if (f.sd[0] < 0.0)  // nothing estimated (too few fixes)
        std::snprintf(found, sizeof found, "none (%s)", f.note.c_str());
      else
        std::snprintf(found, sizeof found, "%.3f ± %.3f m, %.3f ± %.3f m, %.3f ± %.3f deg, %s%s", f.calibration.dx, f.sd[0], f.calibration.dy, f.sd[1],
                      f.calibration.dyaw * deg, f.sd[2] * deg, clock.c_str(), f.determined ? "" : (" (not used: " + f.note + ")").c_str());
      sources_md << "| " << cr.site << " | " << withRsu(cr.site, cr.lidar, cr.rsu) << " | " << drawn << " | " << found << " | " << f.inliers << " / " << f.outliers << " | "
                 << fmt("%.1f cm", 100 * f.residual_sd) << " | " << (cr.fixes ? fmt("%.2f", cr.mean_nes) : std::string("-")) << " | "
                 << (cr.fixes ? std::to_string(cr.beyond_3sd) + " of " + std::to_string(cr.fixes) + fmt(" (%.1f %%)", 100.0 * cr.beyond_3sd / cr.fixes)
                              : std::string("-"))
                 << " |\n";
    }
  }

  // Other road users: what the roadside perception sent and refused on the evaluated trials.
  std::ostringstream attribution_md;
  if (!results.rsu_frames.empty()) {
    std::ostringstream csv;
    csv << "site_lidar,frames,frames_with_neighbours,fixes_sent,gross_fixes,gross_fixes_with_neighbours,gross_per_100_frames_with_neighbours";
    for (int r = 1; r < roadside::kRefusalCount; ++r) csv << ",refused_" << r;
    csv << "\n";
    attribution_md << "| site, roadside LiDAR | frames in coverage | with neighbours | fixes sent | refused (reasons) | gross fixes sent "
                      "(> 0.3 m) | per 100 frames with neighbours |\n|---|---|---|---|---|---|---|\n";
    for (const auto& [key, frames] : results.rsu_frames) {
      std::size_t with = 0, sent = 0, gross = 0, gross_with = 0;
      std::array<std::size_t, roadside::kRefusalCount> refused{};
      for (const RsuFrameRecord& f : frames) {
        with += f.neighbours ? 1 : 0;
        if (!f.found) {
          ++refused[static_cast<int>(f.refusal)];
          continue;
        }
        ++sent;
        if (f.error > 0.3) ++gross, gross_with += f.neighbours ? 1 : 0;
      }
      std::string reasons;
      for (int r = 1; r < roadside::kRefusalCount; ++r)
        if (refused[r]) reasons += (reasons.empty() ? "" : "; ") + std::to_string(refused[r]) + " " + roadside::toString(static_cast<roadside::Refusal>(r));
      const double per100 = with ? 100.0 * static_cast<double>(gross_with) / static_cast<double>(with) : 0.0;
      attribution_md << "| " << key << " | " << frames.size() << " | " << with << " | " << sent << " | " << (reasons.empty() ? "none" : reasons) << " | "
                     << gross << " | " << (with ? fmt("%.1f", per100) : std::string("-")) << " |\n";
      csv << key << "," << frames.size() << "," << with << "," << sent << "," << gross << "," << gross_with << "," << per100;
      for (int r = 1; r < roadside::kRefusalCount; ++r) csv << "," << refused[r];
      csv << "\n";
    }
    writeFile(out_dir + "/attribution.csv", csv.str());
  }

  // The filter beside NDT's own poses at their stamps: never worse than its best input? By speed (the
  // main drives and the speed sweep's) and configuration, the sites pooled; per site in the CSV.
  std::ostringstream ndt_md;
  {
    struct Pool {
      double n = 0, ndt = 0, fused = 0, settled = 0, acc_n = 0, acc_ndt = 0, acc_fused = 0, acc_settled = 0;
      double place_n = 0, place_ndt = 0, place_fused = 0, place_settled = 0;
      // Each replay's settled / NDT there: whether a pooled ratio near 1 is a replay's luck or the rule.
      std::vector<double> acc_ratios, place_ratios;
      void add(const replay::InputComparison& k) {
        n += k.samples, ndt += k.input_mean * k.samples, fused += k.fused_mean * k.samples, settled += k.settled_mean * k.samples;
        acc_n += k.accurate_samples, acc_ndt += k.accurate_input_mean * k.accurate_samples;
        acc_fused += k.accurate_fused_mean * k.accurate_samples, acc_settled += k.accurate_settled_mean * k.accurate_samples;
        place_n += k.place_samples, place_ndt += k.place_input_mean * k.place_samples;
        place_fused += k.place_fused_mean * k.place_samples, place_settled += k.place_settled_mean * k.place_samples;
        if (k.accurate_samples > 0 && k.accurate_input_mean > 0.0) acc_ratios.push_back(k.accurate_settled_mean / k.accurate_input_mean);
        if (k.place_samples > 0 && k.place_input_mean > 0.0) place_ratios.push_back(k.place_settled_mean / k.place_input_mean);
      }
    };
    const auto ratioStandardError = [](const std::vector<double>& ratios) { return spread(ratios).standardError(); };
    const auto csvNumber = [](double x) { return std::isnan(x) ? std::string() : fmt("%.6g", x); };
    const auto ratioCell = [&](double ratio, const std::vector<double>& ratios) {
      const double se = ratioStandardError(ratios);
      return fmt("%.2f", ratio) + (std::isnan(se) ? std::string() : fmt(" ± %.3f", se));
    };
    std::map<std::tuple<double, std::string, std::string>, Pool> by;  // (speed, configuration, site or "")
    double stretch = 0.0, below = 0.0;
    for (const ExperimentRun& r : results.runs) {
      if (r.ndt.samples == 0 || r.delay != 0.0 || r.loss != 0.0) continue;
      double speed = 0.0;
      if (r.variant.empty()) {
        for (const SiteInfo& s : results.sites)
          if (s.name == r.site) speed = s.cruise_speed;
      } else if (r.variant.rfind("speed ", 0) == 0) {
        speed = std::atof(r.variant.c_str() + 6);
      } else {
        continue;
      }
      const std::string configuration = r.lidar.empty() ? "NDT only" : "NDT + " + r.lidar;
      by[{speed, configuration, ""}].add(r.ndt);
      by[{speed, configuration, r.site}].add(r.ndt);
      stretch = r.ndt.stretch_length, below = r.ndt.accurate_below;
    }
    if (!by.empty()) {
      std::ostringstream csv;
      csv << "speed_mps,configuration,site,scans,ndt_mean_m,output_mean_m,settled_mean_m,accurate_scans,accurate_ndt_mean_m,accurate_output_mean_m,"
             "accurate_settled_mean_m,place_scans,place_ndt_mean_m,place_output_mean_m,place_settled_mean_m,"
             "accurate_replays,accurate_ratio_se,place_replays,place_ratio_se\n";
      ndt_md << "NDT's own pose per scan beside the filter at the same stamps, the sites and trials pooled: its output as given out "
                "then (interpolated between ticks; it cannot know that scan's pose yet, which comes a sweep and a match later), and "
                "its estimate for the stamp once that scan's pose is in (settled: the same information NDT's pose has, and what came "
                "before). \"Where NDT is accurate\": the "
             << fmt("%.0f m", stretch) << " stretches of road where NDT's mean error is below " << fmt("%.0f cm", 100 * below)
             << " (chosen by stretch, not by scan, which would favour NDT by its luck on those scans). Chosen by this drive's own "
                "NDT error, a stretch is still chosen for its luck on it, most at speed, where it holds few scans; \"where NDT was "
                "accurate\" chooses the places (cells of "
             << fmt("%.0f m", stretch) << ") by the same criterion on the site's noise calibration drive, another drive over the same road. "
                "Each ratio's ± is the standard error of the mean of its replays' own ratios (each replay a drive of its own; "
                "`*_ratio_se` in the CSV, beside the replays counted): a ratio within it of 1 is not told from 1 by these drives.\n\n"
             << "| speed | configuration | NDT per scan | output | settled | scans where NDT is accurate | NDT there | output there | settled there | settled / NDT there "
                "| scans where NDT was accurate | NDT there | settled there | settled / NDT there |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      for (const auto& [key, p] : by) {
        const auto& [speed, configuration, site] = key;
        csv << speed << "," << configuration << "," << (site.empty() ? "all" : site) << "," << p.n << "," << p.ndt / p.n << "," << p.fused / p.n << ","
            << p.settled / p.n << "," << p.acc_n << "," << (p.acc_n ? p.acc_ndt / p.acc_n : 0.0) << "," << (p.acc_n ? p.acc_fused / p.acc_n : 0.0) << ","
            << (p.acc_n ? p.acc_settled / p.acc_n : 0.0) << "," << p.place_n << "," << (p.place_n ? p.place_ndt / p.place_n : 0.0) << ","
            << (p.place_n ? p.place_fused / p.place_n : 0.0) << "," << (p.place_n ? p.place_settled / p.place_n : 0.0) << ","
            << p.acc_ratios.size() << "," << csvNumber(ratioStandardError(p.acc_ratios)) << "," << p.place_ratios.size() << ","
            << csvNumber(ratioStandardError(p.place_ratios)) << "\n";
        if (!site.empty()) continue;
        ndt_md << "| " << fmt("%.0f m/s", speed) << " | " << configuration << " | " << fmt("%.2f cm", 100 * p.ndt / p.n) << " | "
               << fmt("%.2f cm", 100 * p.fused / p.n) << " | " << fmt("%.2f cm", 100 * p.settled / p.n) << " | "
               << fmt("%.0f %%", 100 * p.acc_n / p.n) << " | ";
        if (p.acc_n > 0)
          ndt_md << fmt("%.2f cm", 100 * p.acc_ndt / p.acc_n) << " | " << fmt("%.2f cm", 100 * p.acc_fused / p.acc_n) << " | "
                 << fmt("%.2f cm", 100 * p.acc_settled / p.acc_n) << " | " << ratioCell(p.acc_settled / p.acc_ndt, p.acc_ratios) << " | ";
        else
          ndt_md << "- | - | - | - | ";
        ndt_md << fmt("%.0f %%", 100 * p.place_n / p.n) << " | ";
        if (p.place_n > 0)
          ndt_md << fmt("%.2f cm", 100 * p.place_ndt / p.place_n) << " | " << fmt("%.2f cm", 100 * p.place_settled / p.place_n) << " | "
                 << ratioCell(p.place_settled / p.place_ndt, p.place_ratios) << " |\n";
        else
          ndt_md << "- | - | - |\n";
      }
      writeFile(out_dir + "/ndt_vs_fused.csv", csv.str());
    }
    // NDT's normalized innovation squared per site and configuration, the main drives' ideal network.
    std::map<std::pair<std::string, std::string>, std::pair<double, std::uint64_t>> nis;
    std::map<std::pair<std::string, std::string>, std::array<std::pair<double, std::uint64_t>, 3>> nis_parts, nis_shares;
    std::set<std::string> present;
    for (const ExperimentRun& r : results.runs) {
      if (!r.variant.empty() || r.delay != 0.0 || r.loss != 0.0 || r.ndt_nis_dof == 0) continue;
      const std::string configuration = r.lidar.empty() ? "NDT only" : "NDT + " + r.lidar;
      auto& n = nis[{r.site, configuration}];
      n.first += r.ndt_nis_sum;
      n.second += r.ndt_nis_dof;
      auto& parts = nis_parts[{r.site, configuration}];
      for (std::size_t k = 0; k < parts.size(); ++k) parts[k].first += r.ndt_nis_component_sum[k], parts[k].second += r.ndt_nis_component_samples[k];
      auto& shares = nis_shares[{r.site, configuration}];
      for (std::size_t k = 0; k < shares.size(); ++k) shares[k].first += r.ndt_nis_prediction_share_sum[k], shares[k].second += r.ndt_nis_component_samples[k];
      present.insert(configuration);
    }
    std::vector<std::string> configurations;  // NDT only first, then each LiDAR as configured
    if (present.count("NDT only")) configurations.push_back("NDT only");
    for (const std::string& lidar : c.lidars)
      if (present.count("NDT + " + lidar)) configurations.push_back("NDT + " + lidar);
    if (!nis.empty()) {
      // One row per site, one cell per configuration ("-" where the site has none).
      const auto by_site = [&](const std::function<std::string(const std::string&, const std::string&)>& cell) {
        ndt_md << "| site |";
        for (const std::string& configuration : configurations) ndt_md << " " << configuration << " |";
        ndt_md << "\n|---|";
        for (std::size_t k = 0; k < configurations.size(); ++k) ndt_md << "---|";
        ndt_md << "\n";
        for (const SiteInfo& site : results.sites) {
          ndt_md << "| " << site.name << " |";
          for (const std::string& configuration : configurations) ndt_md << " " << cell(site.name, configuration) << " |";
          ndt_md << "\n";
        }
      };
      ndt_md << "\n**NDT's normalized innovation squared** per degree of freedom in the filter (d^2 = e' (H P H' + R)^-1 e at its "
                "first use; 1 when the filter's and NDT's covariances are honest), the main drives on the ideal network, each with "
                "the band it lies in 95 % of the time when they are:\n\n";
      by_site([&](const std::string& site, const std::string& configuration) {
        const auto found = nis.find({site, configuration});
        if (found == nis.end()) return std::string("-");
        const auto band = fusion::nisBand(found->second.second);
        return fmt("%.2f", found->second.first / static_cast<double>(found->second.second)) + fmt(" (%.2f-", band.first) + fmt("%.2f)", band.second);
      });
      // A cell per site and configuration of the three components' means, "along / across / yaw".
      const auto by_component = [&](const auto& sums, double scale, const char* format) {
        by_site([&](const std::string& site, const std::string& configuration) {
          const auto found = sums.find({site, configuration});
          if (found == sums.end()) return std::string("-");
          std::string cell;
          for (const auto& [sum, n] : found->second)
            cell += (cell.empty() ? "" : " / ") + (n ? fmt(format, scale * sum / static_cast<double>(n)) : std::string("-"));
          return cell;
        });
      };
      // The whole figure can hide one direction trusted too little behind another trusted too much.
      ndt_md << "\nThe same per component (each e_i^2 / S_ii alone, 1 when honest): along the vehicle / across it / yaw:\n\n";
      by_component(nis_parts, 1.0, "%.3g");
      // Where S is mostly the filter's own prediction, NDT's covariance hardly enters its figure: the
      // figure then measures the prediction (the odometry's stated covariance, the process noise).
      ndt_md << "\nThe share of each component's S that is the filter's prediction, (H P H')_ii / S_ii, not NDT's covariance: along / "
                "across / yaw:\n\n";
      by_component(nis_shares, 100.0, "%.0f %%");
    }
  }

  // Tables II and III: the network grid, per LiDAR, over sites and trials.
  std::ostringstream network_md, network_csv;
  network_csv << "site,lidar,delay_s,loss,error_paper_m,error_mean_m,change_pct,change_mean_pct,fixes_lost\n";
  Plot network_plot;
  network_plot.title = "Fused error within coverage under network delay and loss (mean over sites and trials)";
  network_plot.x_label = "packet loss [%]";
  network_plot.y_label = "error within coverage [cm] (minimum per " + fmt("%.0f", bin) + " m, mean)";
  network_plot.y_from_zero = true;
  if (c.network) {
    int table = 2;
    std::ostringstream by_site;  // the worst cell against the ideal network, per site
    const double worst_delay = c.delays.back(), worst_loss = c.losses.back();
    by_site << "\n**At " << fmt("%.0f ms", 1e3 * worst_delay) << " and " << fmt("%.0f %% loss", 100 * worst_loss)
            << ", all sites, each site, and the sites where NDT alone errs by " << fmt("%.0f cm", 100 * kNdtFallsShort)
            << " or more within the LiDAR's coverage, pooled (change against the ideal network, ± the standard error of the drives' own "
               "changes; the paper: +9.5 % with the VLP-16, +19.2 % with the VLP-32C, on its metric)**\n\n"
            << "| site | roadside LiDAR | paper's metric | change (± se) | plain mean | change (± se) |\n|---|---|---|---|---|---|\n";
    for (const std::string& lidar : c.lidars) {
      const double range = rangeOf(lidar);
      struct Cell {
        double paper = 0.0, plain = 0.0;
        std::uint64_t lost = 0;
      };
      // A scope: the sites a figure pools (all of them where none is named).
      using Scope = std::vector<std::string>;
      const auto inScope = [](const Scope& scope, const std::string& site) { return scope.empty() || std::count(scope.begin(), scope.end(), site) > 0; };
      // Mean over the scope's sites and the grid's trials: every cell on the same drives.
      auto cell = [&](double delay, double loss, const Scope& scope) {
        Cell out;
        int n = 0;
        for (const SiteInfo& site : results.sites)
          for (int t = 0; t < std::min(c.trials, c.network_trials); ++t)
            if (const ExperimentRun* r = find(results.runs, site.name, t, lidar, delay, loss, ""); r && inScope(scope, site.name)) {
              const ErrorInCoverage e = errorInCoverage(*r, range, bin);
              out.paper += e.paper, out.plain += e.plain, out.lost += r->fixes_lost, ++n;
            }
        if (n) out.paper /= n, out.plain /= n;
        return out;
      };
      auto change = [](double value, double reference) { return reference > 0.0 ? 100.0 * (value / reference - 1.0) : 0.0; };
      // How far a change can be trusted: the standard error of the drives' own changes (each drive of the
      // scope against its own ideal network: the same drive), "" with fewer than two drives.
      auto standardError = [&](double delay, double loss, const Scope& scope, bool paper) -> std::string {
        std::vector<double> changes;
        for (const SiteInfo& site : results.sites)
          for (int t = 0; t < std::min(c.trials, c.network_trials) && inScope(scope, site.name); ++t) {
            const ExperimentRun* a = find(results.runs, site.name, t, lidar, 0.0, 0.0, "");
            const ExperimentRun* b = find(results.runs, site.name, t, lidar, delay, loss, "");
            if (!a || !b) continue;
            const ErrorInCoverage ea = errorInCoverage(*a, range, bin), eb = errorInCoverage(*b, range, bin);
            changes.push_back(paper ? change(eb.paper, ea.paper) : change(eb.plain, ea.plain));
          }
        const double se = spread(changes).standardError();
        return std::isnan(se) ? std::string() : fmt(" (± %.1f)", se);
      };
      // The sites where NDT falls short within this LiDAR's coverage (Table I's NDT only, the paper's
      // metric, over the trials), pooled: the paper's locations, where its figures were measured.
      Scope short_sites;
      for (const SiteInfo& site : results.sites) {
        std::vector<double> ndt;
        for (int t = 0; t < c.trials; ++t)
          if (const ExperimentRun* r = find(results.runs, site.name, t, "", 0.0, 0.0, ""))
            if (const ErrorInCoverage e = errorInCoverage(*r, range, bin); e.samples > 0) ndt.push_back(e.paper);
        if (!ndt.empty() && spread(ndt).mean >= kNdtFallsShort) short_sites.push_back(site.name);
      }
      struct Named {
        std::string csv, row;
        Scope sites;
      };
      std::vector<Named> scopes = {{"all", "all sites", {}}};
      for (const SiteInfo& site : results.sites) scopes.push_back({site.name, site.name, {site.name}});
      // Pooled where it is more than one site and not every one (that is "all").
      if (short_sites.size() > 1 && short_sites.size() < results.sites.size()) {
        std::string names;
        for (const std::string& s : short_sites) names += (names.empty() ? "" : ", ") + s;
        scopes.push_back({kNdtFallsShortScope, "where NDT falls short (" + names + ")", short_sites});
      }
      for (const Named& scope : scopes) {
        const Cell ideal = cell(0, 0, scope.sites);
        for (double delay : c.delays)
          for (double loss : c.losses) {
            const Cell e = cell(delay, loss, scope.sites);
            network_csv << scope.csv << "," << lidar << "," << delay << "," << loss << "," << e.paper << "," << e.plain << ","
                        << change(e.paper, ideal.paper) << "," << change(e.plain, ideal.plain) << "," << e.lost << "\n";
          }
        const Cell worst = cell(worst_delay, worst_loss, scope.sites);
        by_site << "| " << scope.row << " | " << lidar << fmt(" | %.2f cm", 100 * worst.paper) << fmt(" | %+.1f %%", change(worst.paper, ideal.paper))
                << standardError(worst_delay, worst_loss, scope.sites, true) << fmt(" | %.2f cm", 100 * worst.plain)
                << fmt(" | %+.1f %%", change(worst.plain, ideal.plain)) << standardError(worst_delay, worst_loss, scope.sites, false) << " |\n";
      }
      const Cell ideal = cell(0, 0, {});
      network_md << "\n**Table " << (table == 2 ? "II" : table == 3 ? "III" : std::to_string(table).c_str()) << ": NDT + " << lidar
                 << " within " << fmt("%.0f m", range) << ", by delay and loss: paper's metric / plain mean (change against the ideal network)**\n\n| delay |";
      ++table;
      for (double loss : c.losses) network_md << fmt(" %.0f %% loss |", 100 * loss);
      network_md << "\n|---|";
      for (std::size_t i = 0; i < c.losses.size(); ++i) network_md << "---|";
      network_md << "\n";
      for (double delay : c.delays) {
        network_md << fmt("| %.0f ms |", 1e3 * delay);
        PlotSeries series;
        series.label = lidar + fmt(", %.0f ms", 1e3 * delay);
        for (double loss : c.losses) {
          const Cell e = cell(delay, loss, {});
          network_md << fmt(" %.2f", 100 * e.paper) << fmt(" / %.2f cm", 100 * e.plain)
                     << (delay == 0.0 && loss == 0.0 ? std::string() : fmt(" (%+.1f", change(e.paper, ideal.paper)) + fmt(" / %+.1f %%)", change(e.plain, ideal.plain)))
                     << " |";
          series.x.push_back(100 * loss);
          series.y.push_back(100 * e.paper);
        }
        network_md << "\n";
        network_plot.series.push_back(series);
      }
    }
    network_md << by_site.str();
    writeFile(out_dir + "/network.csv", network_csv.str());
    writeSvg(out_dir + "/network.svg", network_plot);
  }

  // Figures 4 and 5 per site: error along the road (trial 0) and its spread over the trials.
  std::ostringstream along_csv;
  along_csv << "site,trial,configuration,bin_start_m,min_error_m\n";
  std::vector<std::string> configs = {""};
  for (const std::string& l : c.lidars) configs.push_back(l);
  for (const SiteInfo& site : results.sites) {
    Plot fig4, fig5;
    fig4.title = site.name + ": localization error along the road (minimum per " + fmt("%.0f", bin) + " m), trial 0";
    fig5.title = site.name + ": error along the road over " + std::to_string(c.trials) + " trials (line: mean, dots: each trial)";
    for (Plot* p : {&fig4, &fig5}) {
      p->x_label = "distance along the road [m]";
      p->y_label = "error [m]";
      p->y_from_zero = true;
    }
    for (const std::string& lidar : configs) {
      std::map<long, std::vector<double>> per_bin;
      PlotSeries dots;
      dots.label = (lidar.empty() ? std::string("NDT only") : "NDT + " + lidar) + ", each trial";
      dots.points = true;
      dots.color = colorOf(lidar, true);
      for (int t = 0; t < c.trials; ++t) {
        const ExperimentRun* r = find(results.runs, site.name, t, lidar, 0, 0, "");
        if (!r) continue;
        const std::map<long, double> minima = binMinima(*r, bin);
        PlotSeries line;
        line.label = r->label();
        line.color = colorOf(lidar, false);
        for (const auto& [k, v] : minima) {
          along_csv << site.name << "," << t << ",\"" << r->label() << "\"," << k * bin << "," << v << "\n";
          per_bin[k].push_back(v);
          if (t == 0) line.x.push_back((k + 0.5) * bin), line.y.push_back(v);
          dots.x.push_back((k + 0.5) * bin), dots.y.push_back(v);
        }
        if (t == 0) fig4.series.push_back(line);
      }
      if (per_bin.empty()) continue;
      PlotSeries mean;
      mean.label = (lidar.empty() ? std::string("NDT only") : "NDT + " + lidar) + ", mean";
      mean.color = colorOf(lidar, false);
      for (const auto& [k, v] : per_bin) mean.x.push_back((k + 0.5) * bin), mean.y.push_back(spread(v).mean);
      if (c.trials > 1) fig5.series.push_back(dots);
      fig5.series.push_back(mean);
    }
    if (const ExperimentRun* ndt = find(results.runs, site.name, 0, "", 0, 0, ""))
      for (const std::string& lidar : c.lidars) {
        const auto [lo, hi] = coverageAlong(*ndt, rangeOf(lidar));
        if (lo < hi) {
          PlotBand band{lo, hi, lidar + fmt(" coverage (%.0f m)", rangeOf(lidar)), colorOf(lidar, false)};
          fig4.bands.push_back(band);
          fig5.bands.push_back(band);
        }
      }
    writeSvg(out_dir + "/fig4_error_along_road_" + site.name + ".svg", fig4);
    writeSvg(out_dir + "/fig5_trials_" + site.name + ".svg", fig5);
  }
  writeFile(out_dir + "/error_along_road.csv", along_csv.str());

  // Sweeps: each variant against the paper's setting, on the same trials.
  std::ostringstream sweeps_md;
  if (c.sweeps) {
    std::ostringstream sweeps_csv;
    sweeps_csv << "variant,lidar,trials,ndt_paper_m,fused_paper_m,improvement_pct,fused_mean_m\n";
    sweeps_md << "| variant | roadside LiDAR | NDT only | NDT + RSU | improvement | NDT + RSU (all samples) |\n|---|---|---|---|---|---|\n";
    std::vector<std::string> variants = {""};
    for (const ExperimentRun& r : results.runs)
      if (!r.variant.empty() && r.variant != kSmootherVariant && std::find(variants.begin(), variants.end(), r.variant) == variants.end())
        variants.push_back(r.variant);
    for (const std::string& variant : variants)
      for (const std::string& lidar : c.lidars) {
        const double range = rangeOf(lidar);
        std::vector<double> ndt_v, fused_v, fused_plain;
        for (const SiteInfo& site : results.sites)
          for (int t = 0; t < std::min(c.sweep_trials, c.trials); ++t) {
            const ExperimentRun* fused = find(results.runs, site.name, t, lidar, 0, 0, variant);
            // The variants that change only the filter share the drive, hence the NDT-only run, of the main experiment.
            const ExperimentRun* ndt = find(results.runs, site.name, t, "", 0, 0, variant);
            if (!ndt) ndt = variant.rfind("speed", 0) == 0 ? nullptr : find(results.runs, site.name, t, "", 0, 0, "");
            if (!fused || !ndt) continue;
            ndt_v.push_back(errorInCoverage(*ndt, range, bin).paper);
            fused_v.push_back(errorInCoverage(*fused, range, bin).paper);
            fused_plain.push_back(errorInCoverage(*fused, range, bin).plain);
          }
        if (fused_v.empty()) continue;
        const Spread n = spread(ndt_v), f = spread(fused_v), fp = spread(fused_plain);
        const std::string name =
            variant.empty() ? std::string("main experiment (covariance ") + toString(c.rsu_covariance) + ", RSU at 2 m, 10 m/s)" : variant;
        sweeps_md << "| " << name << " | " << lidar << " | " << cm(n) << " | " << cm(f) << " | " << gainCell(n.mean, f.mean) << " | " << cm(fp)
                  << " |\n";
        sweeps_csv << "\"" << name << "\"," << lidar << "," << f.n << "," << n.mean << "," << f.mean << "," << improvement(n.mean, f.mean) << ","
                   << fp.mean << "\n";
      }
    writeFile(out_dir + "/sweeps.csv", sweeps_csv.str());
  }

  // README.md
  const ExperimentTiming& tm = results.timing;
  md << "# coloc experiment: cooperative localization on the digital twin\n\n"
     << "`" << command_line << "`\n\n"
     << c.trials << " trial(s) per site; RSU fix covariance " << toString(c.rsu_covariance) << "; sites: ";
  for (std::size_t i = 0; i < results.sites.size(); ++i) md << (i ? ", " : "") << results.sites[i].name;
  md << ". Errors are planar, against ground truth, where the vehicle is within the roadside LiDAR's coverage. "
     << "\"NDT only\" is the same drive and scans without the RSU's fixes. The paper's metric is the minimum error in each "
     << fmt("%.0f", bin) << " m of road, averaged over the road in coverage; \"all samples\" is the plain mean of the fused pose at 50 Hz. "
     << "Spread: standard deviation over trials; the improvement's range is over trials; where NDT alone errs by less than "
     << fmt("%.0f", 100 * kNdtFallsShort) << " cm the improvement columns give the ratio of fused to NDT instead (a percentage of a few centimetres measures noise). "
     << "\"NDT + RSU\" fuses the fixes with their covariance " << toString(c.rsu_covariance) << ", the column beside it with "
     << toString(referenceCovariance(c.rsu_covariance))
     << " (published: the paper's per-LiDAR figures 0.01486 / 0.00681 as variances, as Autoware takes them; estimated: the "
        "variance of the fixes' error on the site's first drive, a calibration pass).\n\n";
  if (c.oracle_fix_limit > 0.0)
    md << "**An analysis bound, not a result**: every fix more than " << fmt("%.3f", c.oracle_fix_limit)
       << " m from the vehicle's true position was withheld (`oracle_fix_limit`), which no RSU can do; what a perception that never "
          "sent one of the fixes' tails would give.\n\n";
  md << "## Table I: error within coverage\n\n"
     << table1.str() << "\n";
  if (!results.notes.empty()) {
    md << "Notes:\n\n";
    for (const std::string& note : results.notes) md << "- " << note << "\n";
    md << "\n";
  }
  if (!smoother_md.str().empty())
    md << "## The smoother against the filter\n\nThe same replays smoothed by the Ceres smoother (`coloc smooth`: every measurement for "
          "every pose, each source's noise measured on the drive); plain means of all samples, within and outside the LiDAR's coverage.\n\n"
       << smoother_md.str() << "\n";
  if (!calibration_md.str().empty())
    md << "## RSU self-calibration\n\nEvery RSU of the site miscalibrated (its surveyed pose and clock); one drive past it calibrates it "
          "(`coloc smooth --calibrate-rsus`, anchored by NDT), and the filter replays a second drive with the registry as surveyed, with the "
          "calibration found, and with the fixes the same RSUs would have sent on that drive perfectly surveyed and synchronised (the twin "
          "records both). Errors: plain mean within coverage.\n\n"
       << calibration_md.str() << "\n";
  if (!sources_md.str().empty())
    md << "## Error sources: fix error against distance\n\nEach site's noise calibration drive, every RSU frame imaged twice: with "
          "the site's error sources (RSU survey and clock, a real car's shape, range-dependent noise and dropouts) and in the ideal "
          "twin. Mean fix error, real / ideal, per 5 m of distance from the RSU (the last bin takes everything beyond).\n\n"
       << sources_md.str() << "\n";
  if (!attribution_md.str().empty())
    md << "## Other road users: what the roadside perception sent\n\nEvery RSU frame within coverage on the evaluated trials; "
          "\"with neighbours\": another vehicle the RSU's background does not have within 10 m of the ego vehicle "
       << (c.rsu_background_learned ? "(traffic: each RSU learns its background from frames of the street with its traffic and parked cars before the drive)"
                                    : "(traffic, and a car parked since the survey: each RSU's background is the empty street as surveyed)")
       << ".\n\n"
       << attribution_md.str() << "\n";
  if (!ndt_md.str().empty()) md << "## The filter against its best input: NDT's own poses\n\n" << ndt_md.str() << "\n";
  if (c.network)
    md << "## Tables II and III: network delay and packet loss\n\nMean over the sites and the first " << std::min(c.trials, c.network_trials)
       << " trial(s) of each; every cell replays the same drives.\n" << network_md.str() << "\n![network](network.svg)\n\n";
  md << "## Figures\n\n";
  for (const SiteInfo& site : results.sites)
    md << "![" << site.name << "](fig4_error_along_road_" << site.name << ".svg)\n![" << site.name << " trials](fig5_trials_" << site.name
       << ".svg)\n\n";
  if (c.sweeps) md << "## Sweeps beyond the paper (" << std::min(c.sweep_trials, c.trials) << " trial(s) per site, the sites pooled)\n\n" << sweeps_md.str() << "\n";
  if (!results.estimated_variance.empty()) {
    md << "Measured on each site's noise calibration drive, which is not evaluated: the fixes' variance (a commissioned RSU's: "
          "the mean square of its residuals against the reference vehicle; otherwise robust, from the median absolute error per axis): ";
    bool first = true;
    for (const auto& [key, v] : results.estimated_variance) {
      md << (first ? "" : ", ") << key << fmt(" %.2e m^2", v) << fmt(" (sigma %.1f cm)", 100 * std::sqrt(v));
      first = false;
    }
    md << ".";
    if (c.twist_covariance_estimated) {
      md << " The odometry's, which the filter then uses: ";
      first = true;
      for (const auto& [site, v] : results.estimated_twist_variance) {
        md << (first ? "" : ", ") << site << fmt(" speed %.3f m/s", std::sqrt(v[0])) << fmt(", yaw rate %.4f rad/s", std::sqrt(v[1]));
        first = false;
      }
      md << " (the messages say 0.2 m/s and 0.1 rad/s).";
    }
    if (!results.estimated_ndt_variance.empty()) {
      md << " NDT's covariance, from its own poses on the same drive (the mean square error, x/y and yaw): ";
      first = true;
      for (const auto& [site, v] : results.estimated_ndt_variance) {
        md << (first ? "" : ", ") << site << fmt(" %.1f cm", 100 * std::sqrt(v[0])) << fmt(" and %.2f deg", std::sqrt(v[1]) * 180.0 / M_PI);
        first = false;
      }
      md << " (Autoware's fixed matrix says 15 cm and 1.4 deg). The filter takes it ";
      switch (c.ndt_covariance) {
        case NdtCovarianceSource::kMultiNdtScore:
          if (!results.ndt_quality_cells.empty()) {
            md << "where no place says otherwise; NDT's x/y covariance from its score (raised where the score is flat along a direction; yaw "
                  "Autoware's) is floored at NDT's mean square error on that drive where the pose is, per 10 m cell with 5 poses or more (";
            bool first_site = true;
            for (const auto& [site, cells] : results.ndt_quality_cells) {
              md << (first_site ? "" : ", ") << site << " " << cells << " cells";
              first_site = false;
            }
            md << "; `ndt_quality.yaml` of each noise calibration drive, `ndt.quality_map`).";
          } else {
            md << "as the floor of NDT's covariance from its score (x/y raised where the score is flat along a direction; yaw Autoware's).";
          }
          break;
        case NdtCovarianceSource::kEstimatedPosition: md << "for NDT's x/y covariance (yaw Autoware's)."; break;
        case NdtCovarianceSource::kEstimated: md << "for NDT's x/y and yaw covariance."; break;
        case NdtCovarianceSource::kPublished: md << "nowhere (Autoware's fixed matrix is used)."; break;
      }
    }
    md << "\n\n";
  }
  md << "## Run time\n\n"
     << fmt("%.0f s in all", tm.total) << fmt(": survey maps %.1f s, ", tm.survey) << fmt("simulating %.0f s of driving ", tm.driven_seconds) << fmt("%.1f s ", tm.simulation)
     << fmt("(ray casting %.1f s: ", tm.ray_casting) << fmt("%.0f M rays at ", tm.rays * 1e-6)
     << fmt("%.1f M rays/s, ", tm.rays / std::max(tm.ray_casting, 1e-9) * 1e-6) << tm.reused_sweeps
     << " sweeps and frames reused from an earlier drive of the site; " << fmt("the LiDARs' noise and dropouts %.1f s, ", tm.lidar)
     << fmt("roadside perception %.2f s), ", tm.perception) << tm.replays << fmt(" replays through NDT + EKF %.0f s of CPU time ", tm.replay)
     << "(" << c.jobs << " side by side)";
  if (tm.matches_asked > 0)
    md << "; of the " << tm.matches_asked << " scans they gave NDT, " << tm.matches_computed
       << " were matched (the rest shared by replays identical up to then) and " << tm.preprocessings_computed
       << " preprocessed (shared by replays that agree on the deskew's twist)";
  md << ".\n\n"
     << "## Files\n\n- ";
  const char* separator = "";
  for (const char* t : kTables)
    if (std::filesystem::exists(out_dir + "/" + t)) md << separator << "`" << t << "`", separator = ", ";
  md << ": the tables; `runs.csv`: every replay's error within each coverage range\n"
     << "- `error_along_road.csv`: minimum error per bin along the road, per site, trial and configuration (figures 4 and 5)\n"
     << "- `recordings/SITE/trial_N/`: each drive's map and fuse configuration, the RSU fixes, every RSU frame's outcome "
        "(`rsu_frames.csv`) and, for trial 0, what each perception step buys (`rsu_perception.svg`)"
     << (c.recordings ? "; the drive as a rosbag2 log (`log/`, `coloc fuse` replays it)\n"
                      : "; the drives were replayed from memory (`--recordings` keeps each as a rosbag2 log that `coloc fuse` replays)\n");
  writeFile(out_dir + "/README.md", md.str());
  return table1.str();
}

}  // namespace coloc::twin
