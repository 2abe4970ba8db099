// `coloc rsu-listen` and `coloc rsu-publish`: the vehicle's and a roadside unit's ends of the V2I link,
// over Fast DDS as ROS 2 puts it on the wire.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/rsu_client/link_emulator.hpp"
#include "commands.hpp"
#include "number_checks.hpp"
#include "dds_options.hpp"
#include "teardown_watchdog.hpp"

namespace coloc::tools {

namespace {

std::vector<rsu_client::RsuFix> fixesFromFile(const std::string& path, const std::string& rsu) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the fix file");
  std::vector<rsu_client::RsuFix> fixes;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t, x, y;
    char c1, c2;
    if (!(s >> t >> c1 >> x >> c2 >> y) || c1 != ',' || c2 != ',')
      throw Error(path + ":" + std::to_string(number) + ": expected 't_offset_s,x,y'");
    fixes.push_back({fromSeconds(t), rsu, x, y, std::nullopt, std::nullopt, std::nullopt});
  }
  return fixes;
}

}  // namespace

void addRsuListenCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("rsu-listen", "Receive roadside fixes over DDS and print each with its verdict");
  static DdsOptions dds;
  static std::string registry_path = "config/rsu.yaml";
  static int count = 0;
  static double timeout = 0.0, idle = 0.0;
  static std::vector<double> dimensions;
  static std::int64_t station_id = -1;
  static bool accept_unaddressed = false;
  cmd->add_option("--registry", registry_path, "RSU registry (YAML)")->capture_default_str();
  cmd->add_option("--station-id", station_id, "this vehicle's station id: only fixes addressed to it pass (default: none)")
      ->check(CLI::Range(static_cast<std::int64_t>(0), static_cast<std::int64_t>(4294967295LL)));
  cmd->add_flag("--accept-unaddressed", accept_unaddressed, "take fixes that name no vehicle (a setup with one connected vehicle)");
  cmd->add_option("--count", count, "exit after this many fixes (0 = run until --timeout or Ctrl-C)")->check(wholeNumber(0, 1000000000));
  cmd->add_option("--timeout", timeout, "exit after this many seconds (0 = no limit)")->check(finiteNumber(0.0));
  cmd->add_option("--idle-exit", idle, "exit once this many seconds pass without a fix, after the first (0 = never)")->check(finiteNumber(0.0));
  cmd->add_option("--dimensions", dimensions,
                  "publish this vehicle's dimensions for the RSUs, twice a second as CAMs repeat: station_id length width")
      ->expected(3);
  cmd->add_option("--name", dds.name, "DDS participant name (and security file prefix)");
  addDdsOptions(cmd, dds);
  cmd->callback([] {
    if (!dimensions.empty() &&
        !(dimensions[0] >= 0.0 && dimensions[0] <= 4294967295.0 && dimensions[0] == std::floor(dimensions[0]) && std::isfinite(dimensions[1]) &&
          dimensions[1] > 0.0 && std::isfinite(dimensions[2]) && dimensions[2] > 0.0))
      throw Error("rsu-listen: --dimensions takes a station id (a whole number below 2^32) and a length and width > 0 in metres");
    rsu_client::FixCheckConfig checks;
    if (station_id >= 0) checks.station_id = static_cast<std::uint32_t>(station_id);
    checks.accept_unaddressed = accept_unaddressed;
    rsu_client::FixChecker checker(rsu_client::RsuRegistry::load(registry_path), checks);
    std::vector<std::string> ids;
    for (const auto& r : checker.registry().rsus()) ids.push_back(r.id);
    const rsu_client::DdsConfig config = ddsConfig(dds, "vehicle");
    printSecurity(config);
    std::mutex mutex;
    std::atomic<int> received{0};
    std::atomic<std::int64_t> last_fix{0};  // steady-clock ns of the newest fix
    TeardownWatchdog watchdog("rsu-listen");
    watchdog.arm(1);  // a participant that fails to come up is deleted at once
    rsu_client::FixSubscriber subscriber(config, ids, [&](const rsu_client::RsuFix& fix, Stamp now) {
      std::lock_guard<std::mutex> lock(mutex);
      const rsu_client::FixVerdict v = checker.check(fix, now);
      if (v.accepted())
        std::printf("fix %s %s x=%.3f y=%.3f accepted (variance %.5f, delay %.1f ms)\n", fix.rsu_id.c_str(), formatSeconds(fix.stamp).c_str(),
                    fix.x, fix.y, v.measurement.covariance(0, 0), 1e3 * toSeconds(now - fix.stamp));
      else
        std::printf("%s\n", v.detail.c_str());
      std::fflush(stdout);
      ++received;
      last_fix = std::chrono::steady_clock::now().time_since_epoch().count();
    }, [&](const std::string& line) {
      std::lock_guard<std::mutex> lock(mutex);
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    });
    std::unique_ptr<rsu_client::DimensionsPublisher> dims;
    if (!dimensions.empty()) dims = std::make_unique<rsu_client::DimensionsPublisher>(config);
    watchdog.disarm();
    const TeardownWatchdog::ArmOnExit arm_on_exit(watchdog);
    std::printf("listening on %zu RSUs (%s and %s), domain %d, %s\n", ids.size(), ids.empty() ? "" : rsu_client::addressedFixTopic(ids.front()).c_str(),
                ids.empty() ? "" : rsu_client::fixTopic(ids.front()).c_str(),
                config.domain, config.loopback_only ? "loopback only" : "every interface");
    std::fflush(stdout);
    const auto start = std::chrono::steady_clock::now();
    const auto idle_for = [&] {
      return std::chrono::steady_clock::now() - std::chrono::steady_clock::time_point(std::chrono::steady_clock::duration(last_fix.load()));
    };
    auto next_cam = std::chrono::steady_clock::now();
    while ((count == 0 || received.load() < count) &&
           (timeout <= 0.0 || std::chrono::steady_clock::now() - start < std::chrono::duration<double>(timeout)) &&
           (idle <= 0.0 || received.load() == 0 || idle_for() < std::chrono::duration<double>(idle))) {
      if (dims && std::chrono::steady_clock::now() >= next_cam) {
        dims->publish({rsu_client::systemNow(), static_cast<std::uint32_t>(dimensions[0]), dimensions[1], dimensions[2], 0.0, 0.0});
        next_cam += std::chrono::milliseconds(500);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [id, c] : checker.counters()) {
      std::printf("summary %s: received %llu passed the checks %llu", id.c_str(), (unsigned long long)c.received, (unsigned long long)c.passed_checks);
      for (const auto& [reason, count] : rsu_client::refusals(c)) std::printf(" %s %llu", reason, (unsigned long long)count);
      std::printf("\n");
    }
    const rsu_client::SampleCounters refused = subscriber.sampleCounters();
    std::printf("summary samples refused before decoding: wrong_encapsulation %llu undecodable %llu\n",
                (unsigned long long)refused.wrong_encapsulation, (unsigned long long)refused.undecodable);
  });
}

void addRsuPublishCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("rsu-publish", "Publish roadside fixes over DDS as an RSU would");
  static DdsOptions dds;
  static std::string registry_path = "config/rsu.yaml", rsu, from;
  static int generate = 0, wait_subscribers = 1;
  static double rate = 10.0, wait_timeout = 10.0, speed = 10.0;
  static rsu_client::LinkConfig link;
  static bool dimensions = false, unaddressed = false;
  static std::int64_t station_id = -1;
  cmd->add_option("--registry", registry_path, "RSU registry (YAML)")->capture_default_str();
  cmd->add_option("--rsu", rsu, "the RSU id to publish as")->required();
  cmd->add_option("--station-id", station_id, "the vehicle the fixes are addressed to (its CAM's station id); required unless --unaddressed")
      ->check(CLI::Range(static_cast<std::int64_t>(0), static_cast<std::int64_t>(4294967295LL)));
  cmd->add_flag("--unaddressed", unaddressed, "publish on the unaddressed topic /rsu/<id>/fix (a setup with one connected vehicle)");
  cmd->add_option("--from", from, "fixes from a CSV file: t_offset_s,x,y per line");
  cmd->add_option("--generate", generate, "generate this many fixes of a vehicle driving past the RSU")->check(wholeNumber(0, 1000000));
  cmd->add_option("--speed", speed, "speed of the generated vehicle, m/s")->check(finiteNumber(0.0, 100.0))->capture_default_str();
  cmd->add_option("--rate", rate, "fixes per second")->check(finiteNumber(0.0, 1000.0, true))->capture_default_str();
  cmd->add_option("--wait-subscribers", wait_subscribers, "wait for this many listeners before sending")->check(wholeNumber(0, 1000))->capture_default_str();
  cmd->add_option("--wait-timeout", wait_timeout, "seconds to wait for them")->check(finiteNumber(0.0, 3600.0))->capture_default_str();
  cmd->add_flag("--dimensions", dimensions, "print the vehicle dimensions received on /vehicle/dimensions (the CAM content)");
  cmd->add_option("--delay", link.delay, "emulated link delay, s")->check(finiteNumber(0.0, 10.0))->capture_default_str();
  cmd->add_option("--jitter", link.jitter, "emulated delay jitter (standard deviation), s")->check(finiteNumber(0.0, 10.0))->capture_default_str();
  cmd->add_option("--loss", link.loss, "emulated independent loss probability")->check(finiteNumber(0.0, 1.0))->capture_default_str();
  cmd->add_flag("--burst", link.burst, "bursty (Gilbert-Elliott) loss instead of independent");
  cmd->add_option("--seed", link.seed, "seed of the link emulation")->capture_default_str();
  cmd->add_option("--name", dds.name, "DDS participant name (and security file prefix); default: the RSU id");
  addDdsOptions(cmd, dds);
  cmd->callback([] {
    if (unaddressed == (station_id >= 0))
      throw Error("rsu-publish: give the vehicle's --station-id (addressed fixes, the protocol) or --unaddressed, one of the two");
    const rsu_client::RsuRegistry registry = rsu_client::RsuRegistry::load(registry_path);
    const rsu_client::RsuInfo* info = registry.find(rsu);
    if (!info) throw Error(registry_path + ": no RSU '" + rsu + "'");
    std::vector<rsu_client::RsuFix> fixes;
    if (!from.empty()) fixes = fixesFromFile(from, rsu);
    for (int i = 0; i < generate; ++i) {  // a straight pass 3 m from the RSU, centred on it
      const double t = i / rate, along = -0.5 * speed * generate / rate + speed * t;
      fixes.push_back({fromSeconds(t), rsu, info->position.x() + along, info->position.y() + 3.0, std::nullopt, std::nullopt, std::nullopt});
    }
    if (fixes.empty()) throw Error("rsu-publish: nothing to send (give --from or --generate)");
    const rsu_client::DdsConfig config = ddsConfig(dds, rsu);
    printSecurity(config);
    TeardownWatchdog watchdog("rsu-publish");
    watchdog.arm(1);  // a participant that fails to come up is deleted at once
    rsu_client::FixPublisher publisher(config, rsu, !unaddressed);
    std::mutex print;
    std::atomic<bool> have_dimensions{false};
    std::unique_ptr<rsu_client::DimensionsSubscriber> dims;
    if (dimensions)
      dims = std::make_unique<rsu_client::DimensionsSubscriber>(config, [&](const rsu_client::VehicleDimensions& d) {
        if (have_dimensions.exchange(true)) return;  // CAMs repeat: print the first
        std::lock_guard<std::mutex> lock(print);
        std::printf("dimensions station %u length %.3f width %.3f reference (%.3f, %.3f)\n", d.station_id, d.length, d.width,
                    d.reference_x, d.reference_y);
        std::fflush(stdout);
      }, [&](const std::string& line) {
        std::lock_guard<std::mutex> lock(print);
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
      });
    watchdog.disarm();
    const TeardownWatchdog::ArmOnExit arm_on_exit(watchdog);
    if (wait_subscribers > 0 &&
        !publisher.waitForSubscribers(wait_subscribers, std::chrono::milliseconds(static_cast<long>(wait_timeout * 1000))))
      throw Error("rsu-publish: no listener matched within " + std::to_string(wait_timeout) + " s");
    rsu_client::LinkEmulator emulator(link);
    const Stamp start = rsu_client::systemNow();
    int sent = 0, dropped = 0;
    for (const rsu_client::RsuFix& planned : fixes) {
      // Fixes are stamped at capture on the vehicle's clock; the emulated link decides when (and if) each arrives.
      rsu_client::RsuFix fix = planned;
      fix.stamp = start + planned.stamp;
      if (!unaddressed) fix.station_id = static_cast<std::uint32_t>(station_id);
      std::this_thread::sleep_until(std::chrono::system_clock::time_point(std::chrono::nanoseconds(fix.stamp)));
      const std::optional<Stamp> delivery = emulator.transmit(fix.stamp);
      if (!delivery) {
        ++dropped;
        continue;
      }
      std::this_thread::sleep_until(std::chrono::system_clock::time_point(std::chrono::nanoseconds(*delivery)));
      publisher.publish(fix, registry.variance(*info));
      ++sent;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let the last samples leave
    if (dimensions)  // the vehicle's CAMs come twice a second: a short wait is enough to have one
      for (int i = 0; i < 200 && !have_dimensions.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::lock_guard<std::mutex> lock(print);
    std::printf("published %d fixes as %s%s, %d dropped by the emulated link\n", sent, rsu.c_str(),
                unaddressed ? " (unaddressed)" : (" to station " + std::to_string(station_id)).c_str(), dropped);
  });
}

}  // namespace coloc::tools
