#pragma once
// rosbag2's compression, zstd in both of its modes: FILE compresses each storage file whole
// ("bag_0.db3.zstd"), MESSAGE compresses each message's bytes in the database. Both read and written
// here; decompression is bounded so that a corrupt or hostile size cannot exhaust memory.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace coloc::io::detail {

/// The largest message MESSAGE mode decompresses (bytes); a larger one is refused as corrupt.
inline constexpr std::uint64_t kMaxDecompressedMessage = std::uint64_t{1} << 30;

/// Streams `from` (a zstd file, one or more frames) into a new file `to`. Throws coloc::Error naming
/// `from` and the reason (truncated, not zstd, ...); removes `to` then.
void decompressZstdFile(const std::string& from, const std::string& to);
/// Streams `from` into a new zstd file `to` (level 1, rosbag2's default for FILE mode).
void compressZstdFile(const std::string& from, const std::string& to);

/// One message's zstd frame to its bytes. Throws coloc::Error starting with `where`.
std::vector<std::uint8_t> decompressZstdMessage(const std::uint8_t* data, std::size_t size, const std::string& where);
std::vector<std::uint8_t> compressZstdMessage(const std::uint8_t* data, std::size_t size);

}  // namespace coloc::io::detail
