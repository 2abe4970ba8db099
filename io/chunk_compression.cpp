#include "chunk_compression.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <memory>

#include "coloc/core/error.hpp"

namespace coloc::io::detail {
namespace {

/// Output buffer that grows by doubling up to one byte past the declared size; that extra byte is how
/// an overlong stream is detected.
class GrowingOutput {
 public:
  GrowingOutput(std::uint64_t declared, std::size_t input_size, const std::string& where)
      : declared_(declared), where_(where) {
    const std::uint64_t first = std::max<std::uint64_t>(std::uint64_t{1} << 20, std::uint64_t{input_size} * 8);
    bytes_.resize(static_cast<std::size_t>(std::min(limit(), first)));
  }
  std::uint64_t limit() const { return declared_ + 1; }
  bool full() const { return produced_ == bytes_.size(); }
  void grow() {
    const std::uint64_t next = std::min<std::uint64_t>(limit(), std::uint64_t{bytes_.size()} * 2);
    if (next > SIZE_MAX) fail("does not fit in memory");
    bytes_.resize(static_cast<std::size_t>(next));
  }
  std::uint8_t* free() { return bytes_.data() + produced_; }
  std::size_t freeSize() const { return bytes_.size() - produced_; }
  void produced(std::size_t n) {
    produced_ += n;
    if (produced_ > declared_) fail("decompresses to more than the " + std::to_string(declared_) + " bytes its header declares");
  }
  std::vector<std::uint8_t> finish() {
    if (produced_ != declared_) {
      fail("decompresses to " + std::to_string(produced_) + " bytes, its header declares " + std::to_string(declared_));
    }
    bytes_.resize(produced_);
    return std::move(bytes_);
  }
  [[noreturn]] void fail(const std::string& reason) const { throw Error(where_ + ": " + reason); }

 private:
  std::uint64_t declared_;
  const std::string& where_;
  std::vector<std::uint8_t> bytes_;
  std::size_t produced_ = 0;
};

std::vector<std::uint8_t> decompressZstd(const std::uint8_t* data, std::size_t size, GrowingOutput& out) {
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  if (!context) out.fail("cannot create a zstd decoder");
  ZSTD_inBuffer in{data, size, 0};
  for (;;) {
    if (out.full()) out.grow();
    ZSTD_outBuffer buffer{out.free(), out.freeSize(), 0};
    const std::size_t remaining_hint = ZSTD_decompressStream(context.get(), &buffer, &in);
    if (ZSTD_isError(remaining_hint)) out.fail(std::string("zstd: ") + ZSTD_getErrorName(remaining_hint));
    out.produced(buffer.pos);
    if (remaining_hint == 0 && in.pos == in.size) break;  // last frame complete, input used up
    // zstd fills the output whenever it can; room left means it is waiting for input.
    if (buffer.pos < buffer.size && in.pos == in.size) out.fail("zstd data is truncated");
  }
  return out.finish();
}

std::vector<std::uint8_t> decompressLz4(const std::uint8_t* data, std::size_t size, GrowingOutput& out) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) out.fail("cannot create an lz4 decoder");
  std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(raw, &LZ4F_freeDecompressionContext);
  std::size_t consumed = 0;
  for (;;) {
    if (out.full()) out.grow();
    std::size_t out_size = out.freeSize();
    std::size_t in_size = size - consumed;
    const std::size_t hint = LZ4F_decompress(context.get(), out.free(), &out_size, data + consumed, &in_size, nullptr);
    if (LZ4F_isError(hint)) out.fail(std::string("lz4: ") + LZ4F_getErrorName(hint));
    out.produced(out_size);
    consumed += in_size;
    if (hint == 0 && consumed == size) break;  // frame complete, input used up
    if (consumed == size && !out.full()) out.fail("lz4 frame is truncated");
    if (out_size == 0 && in_size == 0 && !out.full()) out.fail("lz4 decoder made no progress");
  }
  return out.finish();
}

}  // namespace

std::vector<std::uint8_t> decompressChunk(std::string_view compression, const std::uint8_t* data, std::size_t size,
                                          std::uint64_t uncompressed_size, const std::string& where) {
  if (compression.empty()) {
    if (size != uncompressed_size) {
      throw Error(where + ": uncompressed records are " + std::to_string(size) + " bytes, the header declares " +
                  std::to_string(uncompressed_size));
    }
    return std::vector<std::uint8_t>(data, data + size);
  }
  GrowingOutput out(uncompressed_size, size, where);
  if (compression == "zstd") return decompressZstd(data, size, out);
  if (compression == "lz4") return decompressLz4(data, size, out);
  throw Error(where + ": unknown compression \"" + std::string(compression) +
              "\" (supported: \"\" for none, \"zstd\", \"lz4\")");
}

std::vector<std::uint8_t> compressChunk(McapCompression compression, const std::uint8_t* data, std::size_t size) {
  switch (compression) {
    case McapCompression::kNone:
      return std::vector<std::uint8_t>(data, data + size);
    case McapCompression::kZstd: {
      std::vector<std::uint8_t> out(ZSTD_compressBound(size));
      const std::size_t n = ZSTD_compress(out.data(), out.size(), data, size, ZSTD_CLEVEL_DEFAULT);
      if (ZSTD_isError(n)) throw Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
      out.resize(n);
      return out;
    }
    case McapCompression::kLz4: {
      LZ4F_preferences_t preferences;
      std::memset(&preferences, 0, sizeof preferences);
      preferences.frameInfo.contentSize = size;  // lets readers check the size before decoding
      std::vector<std::uint8_t> out(LZ4F_compressFrameBound(size, &preferences));
      const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), data, size, &preferences);
      if (LZ4F_isError(n)) throw Error(std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
      out.resize(n);
      return out;
    }
  }
  throw Error("compressChunk: invalid McapCompression");
}

std::string_view compressionName(McapCompression compression) {
  switch (compression) {
    case McapCompression::kNone: return "";
    case McapCompression::kZstd: return "zstd";
    case McapCompression::kLz4: return "lz4";
  }
  return "";
}

}  // namespace coloc::io::detail
