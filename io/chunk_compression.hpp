#pragma once
// MCAP chunk compression: "" (none), "zstd", "lz4" (the LZ4 frame format).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "coloc/io/mcap_writer.hpp"

namespace coloc::io::detail {

/// Decompresses a chunk's records to exactly `uncompressed_size` bytes. Memory grows with the bytes
/// actually produced, so a corrupt size field cannot trigger a huge allocation. Errors throw
/// coloc::Error starting with `where` (file and chunk offset).
std::vector<std::uint8_t> decompressChunk(std::string_view compression, const std::uint8_t* data, std::size_t size,
                                          std::uint64_t uncompressed_size, const std::string& where);

std::vector<std::uint8_t> compressChunk(McapCompression compression, const std::uint8_t* data, std::size_t size);

/// "", "zstd" or "lz4".
std::string_view compressionName(McapCompression compression);

}  // namespace coloc::io::detail
