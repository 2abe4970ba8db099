#pragma once
// NDT's outcome for a scan, shared between pose sources that ask the very same question: the same scan
// object, the same target object, the same prediction and twist to the bit, the same configuration.
// Replays of one drive that differ only in what they do with the RSUs' fixes (the experiment's network
// grid and covariance variants, a smoothed and a filtered run) are identical up to the first fix they
// treat differently; until then each scan is matched once instead of once per replay, and every replay
// still gets the bytes it would have computed itself.
//
// Thread-safe: a question being answered for one source is waited for by the others. Memory: an outcome
// per question (a few hundred bytes); the scans and targets asked about stay alive while the memo does.
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "coloc/ndt/ndt_pose_source.hpp"

namespace coloc::ndt {

struct AlignmentMemoStats {
  std::uint64_t asked = 0;     ///< questions put to the memo
  std::uint64_t computed = 0;  ///< of them, answered by computing (the rest were shared)
};

class AlignmentMemo {
 public:
  struct Question {
    std::shared_ptr<const PointCloud> scan;  ///< the scan as shared by the caller (identity, not content)
    Stamp stamp = 0;
    std::shared_ptr<const NdtTarget> target;
    Pose predicted;
    double vx = 0.0, wz = 0.0;
  };
  /// The outcome for `question` under `config` (configFingerprint of the asker's configuration):
  /// `compute()`'s, the first time it is asked; the same outcome, copied, every later time. An
  /// exception from `compute()` reaches every caller waiting for it and is not kept.
  ScanOutcome answer(const std::string& config, const Question& question, const std::function<ScanOutcome()>& compute);
  AlignmentMemoStats stats() const;

 private:
  struct Key {
    std::string config;
    const PointCloud* scan;
    const NdtTarget* target;
    Stamp stamp;
    std::uint64_t bits[9];
    bool operator==(const Key& o) const;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  struct Entry;
  mutable std::mutex mutex_;
  std::unordered_map<Key, std::shared_ptr<Entry>, KeyHash> entries_;
  AlignmentMemoStats stats_;
};

/// Every setting of `config` as bytes: equal exactly when two pose sources compute the same.
std::string configFingerprint(const NdtPoseSourceConfig& config);

}  // namespace coloc::ndt
