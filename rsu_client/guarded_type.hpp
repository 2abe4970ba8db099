#pragma once
// A generated Fast DDS type whose decoding can neither throw nor accept what it cannot read. Any
// participant on the domain may send a sample; Fast DDS 2.9's generated code throws from deserialize
// on an encapsulation it does not know (XCDR2, 0x0006-0x000b), and the exception leaves the data
// reader's listener and ends the process. Here a sample is decoded only if its encapsulation is plain
// CDR (what ROS 2 sends: 0x0000 big-, 0x0001 little-endian); otherwise, or if decoding throws or fails,
// it is counted by reason and refused (Fast DDS then drops it), and the reader goes on.
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {

/// The counters a guarded type fills, thread-safe: decoding runs on DDS threads.
struct AtomicSampleCounters {
  std::atomic<std::uint64_t> wrong_encapsulation{0}, undecodable{0};
  SampleCounters snapshot() const { return {wrong_encapsulation.load(), undecodable.load()}; }
};

template <typename Generated>
class GuardedType : public Generated {
 public:
  /// `topic` names the samples in `on_refused` messages; both outlive the type.
  GuardedType(std::string topic, AtomicSampleCounters* counters, const std::function<void(const std::string&)>* on_refused)
      : topic_(std::move(topic)), counters_(counters), on_refused_(on_refused) {}

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    if (payload == nullptr || payload->data == nullptr || payload->length < 4) return refuse(counters_->undecodable, "shorter than its encapsulation header");
    const unsigned encapsulation = (static_cast<unsigned>(payload->data[0]) << 8) | payload->data[1];
    if (encapsulation > 0x0001) {
      char why[96];
      std::snprintf(why, sizeof why, "encapsulation 0x%04x, not plain CDR (0x0000 or 0x0001)", encapsulation);
      return refuse(counters_->wrong_encapsulation, why);
    }
    try {
      if (Generated::deserialize(payload, data)) return true;
      return refuse(counters_->undecodable, "does not decode as its type");
    } catch (const std::exception& e) {
      return refuse(counters_->undecodable, std::string("does not decode as its type: ") + e.what());
    } catch (...) {
      return refuse(counters_->undecodable, "does not decode as its type");
    }
  }

 private:
  bool refuse(std::atomic<std::uint64_t>& counter, const std::string& why) {
    ++counter;
    if (on_refused_ && *on_refused_) (*on_refused_)("sample on " + topic_ + " refused: " + why);
    return false;
  }

  std::string topic_;
  AtomicSampleCounters* counters_;
  const std::function<void(const std::string&)>* on_refused_;
};

}  // namespace coloc::rsu_client
