#pragma once
// NDT's outcome for a scan, shared between pose sources that ask the very same question: the same scan
// object, the same target object, the same prediction and twist to the bit, the same configuration.
// Replays of one drive that differ only in what they do with the RSUs' fixes (the experiment's network
// grid and covariance variants, a smoothed and a filtered run) are identical up to the first fix they
// treat differently; until then each scan is matched once instead of once per replay, and every replay
// still gets the bytes it would have computed itself.
//
// The scan preprocessed (cropped, deskewed, thinned) is shared the same way, by scan object, settings
// and deskew twist: replays whose filters agree on the twist to the deskew's resolution (ndt_pose_source
// rounds it) preprocess a scan once, however their predictions differ.
//
// Thread-safe: a question being answered for one source is waited for by the others. Memory: an outcome
// per question (a few hundred bytes) and a preprocessed scan per twist asked (at most
// PreprocessConfig::max_points points); the scans and targets asked about stay alive while the memo does.
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
  std::uint64_t preprocessings_asked = 0;     ///< scans asked for preprocessed (by the computed questions)
  std::uint64_t preprocessings_computed = 0;  ///< of them, preprocessed here (the rest were shared)
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
  /// `compute()`'s preprocessed scan for `scan` under `config` (preprocessFingerprint) and the twist
  /// `vx`, `wz`, the first time it is asked; the same cloud, shared, every later time.
  std::shared_ptr<const PointCloud> preprocessed(const std::string& config, const std::shared_ptr<const PointCloud>& scan, double vx, double wz,
                                                 const std::function<PointCloud()>& compute);
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
  template <typename T>
  struct Slot;
  template <typename T>
  using Table = std::unordered_map<Key, std::shared_ptr<Slot<T>>, KeyHash>;
  template <typename T>
  T share(Table<T>& table, const Key& key, const Question& question, std::uint64_t& asked, std::uint64_t& computed, const std::function<T()>& compute);
  mutable std::mutex mutex_;
  Table<ScanOutcome> entries_;
  Table<std::shared_ptr<const PointCloud>> preprocessed_;
  AlignmentMemoStats stats_;
};

/// Every setting of `config` as bytes: equal exactly when two pose sources compute the same.
std::string configFingerprint(const NdtPoseSourceConfig& config);
/// The preprocessing's settings as bytes: equal exactly when two sources preprocess a scan alike.
std::string preprocessFingerprint(const PreprocessConfig& config);

}  // namespace coloc::ndt
