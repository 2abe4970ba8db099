#include "coloc/live/log_player.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/rsu_client/dds_node.hpp"

namespace coloc::live {

namespace {

using SteadyClock = std::chrono::steady_clock;

// The QoS a topic was recorded with, as far as readers care: rosbag2 stores the offered profiles as
// YAML (reliability 1 = reliable, 2 = best effort; durability 1 = transient local). Unknown: reliable,
// which readers of either kind match.
rsu_client::TopicQos recordedQos(const io::TopicInfo& topic) {
  rsu_client::TopicQos q;
  q.reliable = topic.offered_qos_profiles.find("reliability: 2") == std::string::npos;
  q.transient_local = topic.offered_qos_profiles.find("durability: 1") != std::string::npos;
  q.depth = 10;
  return q;
}

}  // namespace

PlayReport playLog(const std::string& log_path, const PlayOptions& options) {
  if (!(options.rate > 0.0) || !std::isfinite(options.rate)) throw Error("play: the rate must be a finite number > 0");
  if (!(options.clock_frequency >= 1.0 && options.clock_frequency <= 1e4))
    throw Error("play: the clock frequency must be a number of Hz in [1, 10000]");
  if (!(std::isfinite(options.delay) && options.delay >= 0.0)) throw Error("play: the delay before the first message must be a finite number of seconds >= 0");
  io::BagReader probe = io::BagReader::open(log_path, io::BagReadOptions{options.recover});
  for (const auto& [from, to] : options.remap) {
    const auto& all = probe.topics();
    if (std::none_of(all.begin(), all.end(), [&](const io::TopicInfo& t) { return t.name == from; })) throw Error(log_path + ": has no topic " + from + " to remap");
    if (to.empty() || to[0] != '/') throw Error("play: remap of " + from + ": the new name '" + to + "' must start with /");
  }
  for (const std::string& wanted : options.topics) {
    const auto& all = probe.topics();
    if (std::none_of(all.begin(), all.end(), [&](const io::TopicInfo& t) { return t.name == wanted; }))
      throw Error(log_path + ": has no topic " + wanted);
  }
  rsu_client::DdsNode node(options.dds);
  std::map<std::string, rsu_client::DdsNode::Writer> writers;
  for (const io::TopicInfo& t : probe.topics()) {
    if (!options.topics.empty() && std::find(options.topics.begin(), options.topics.end(), t.name) == options.topics.end()) continue;
    if (t.type.empty() || t.serialization_format != "cdr") continue;  // nothing a DDS reader could take
    const auto renamed = options.remap.find(t.name);
    writers.emplace(t.name, node.advertise(renamed == options.remap.end() ? t.name : renamed->second, t.type, recordedQos(t)));
  }
  rsu_client::DdsNode::Writer clock;
  if (options.publish_clock) {
    rsu_client::TopicQos q;
    q.depth = 1;
    clock = node.advertise(io::kClockTopic, io::kClockType, q);
  }
  if (options.delay > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(options.delay));

  PlayReport report;
  report.recovered = probe.recovered();
  const auto wall_start = SteadyClock::now();
  const Duration clock_period = static_cast<Duration>(1e9 / options.clock_frequency);  // checked: 1 Hz or more
  const std::uint64_t total = std::max<std::uint64_t>(probe.messageCount(), 1);
  for (bool first_pass = true; first_pass || (options.loop && (options.passes <= 0 || report.loops < static_cast<std::uint64_t>(options.passes)));
       first_pass = false) {
    io::BagReader bag = io::BagReader::open(log_path, io::BagReadOptions{options.recover});
    io::BagMessage message;
    bool started = false;
    Stamp log_start = 0, last_clock = 0, last_log = 0;
    SteadyClock::time_point pass_start;
    std::uint64_t index = 0;
    auto due = [&](Stamp log_time) {
      return pass_start + std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(log_time - log_start) / options.rate));
    };
    auto sendClock = [&](Stamp t) {
      if (options.publish_clock && clock.write(io::encodeClock(t))) last_clock = t;
    };
    while (bag.next(message)) {
      if (options.stop_requested && options.stop_requested()) {
        report.stopped = true;
        return report;
      }
      if (!started) {
        started = true;
        log_start = message.log_time;
        pass_start = SteadyClock::now();
        sendClock(log_start);
      }
      // /clock keeps ticking between messages, as a player's clock does.
      while (options.publish_clock && message.log_time - last_clock > clock_period) {
        const Stamp tick = last_clock + clock_period;
        std::this_thread::sleep_until(due(tick));
        sendClock(tick);
      }
      std::this_thread::sleep_until(due(message.log_time));
      last_log = std::max(last_log, message.log_time);
      const auto writer = writers.find(message.topic);
      ++index;
      if (options.progress && index % 64 == 0) options.progress(std::min(1.0, static_cast<double>(index) / total));
      if (writer == writers.end()) continue;
      report.max_lag_ms = std::max(report.max_lag_ms, std::chrono::duration<double, std::milli>(SteadyClock::now() - due(message.log_time)).count());
      if (message.log_time > last_clock) sendClock(message.log_time);  // a node on /clock sees the message arrive at its log time
      if (writer->second.write(message.data)) ++report.published[message.topic];
      else ++report.failed;
    }
    if (started) report.log_seconds = toSeconds(last_log - log_start);
    ++report.loops;
    if (options.stop_requested && options.stop_requested()) break;
  }
  // Reliable readers get everything before the writers go: deleting a writer drops what is unacknowledged.
  for (auto& [topic, writer] : writers) writer.waitForAcknowledgments(5.0);
  report.wall_seconds = std::chrono::duration<double>(SteadyClock::now() - wall_start).count();
  if (options.progress) options.progress(1.0);
  return report;
}

}  // namespace coloc::live
