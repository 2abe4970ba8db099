#include "bag_compression.hpp"

#include <zstd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "chunk_compression.hpp"
#include "coloc/core/error.hpp"

namespace coloc::io::detail {
namespace {

using DCtx = std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)>;
using CCtx = std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)>;

// Opens both files or throws; on any later failure the caller's guard removes the output.
struct FilePair {
  std::ifstream in;
  std::ofstream out;
  FilePair(const std::string& from, const std::string& to) : in(from, std::ios::binary) {
    if (!in) throw Error(from + ": cannot open for reading");
    std::error_code ec;
    if (std::filesystem::exists(to, ec)) throw Error(to + ": already exists; refusing to overwrite it");
    out.open(to, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(to + ": cannot create the file");
  }
};

// Removes a half-written output unless released.
struct RemoveUnlessDone {
  std::string path;
  bool done = false;
  ~RemoveUnlessDone() {
    if (done) return;
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

}  // namespace

void decompressZstdFile(const std::string& from, const std::string& to) {
  FilePair files(from, to);
  RemoveUnlessDone guard{to};
  DCtx context(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  if (!context) throw Error(from + ": cannot create a zstd decoder");
  std::vector<char> input(ZSTD_DStreamInSize()), output(ZSTD_DStreamOutSize());
  std::size_t last_hint = 1;  // 0 once a frame is complete
  std::uint64_t consumed = 0;
  while (files.in) {
    files.in.read(input.data(), static_cast<std::streamsize>(input.size()));
    const std::size_t got = static_cast<std::size_t>(files.in.gcount());
    if (got == 0) break;
    ZSTD_inBuffer in{input.data(), got, 0};
    while (in.pos < in.size) {
      ZSTD_outBuffer out{output.data(), output.size(), 0};
      last_hint = ZSTD_decompressStream(context.get(), &out, &in);
      if (ZSTD_isError(last_hint))
        throw Error(from + ": not a valid zstd file near byte " + std::to_string(consumed + in.pos) + " (" + ZSTD_getErrorName(last_hint) + ")");
      files.out.write(output.data(), static_cast<std::streamsize>(out.pos));
      if (!files.out) throw Error(to + ": write failed (disk full?)");
    }
    consumed += got;
  }
  if (consumed == 0) throw Error(from + ": empty, not a zstd file");
  if (last_hint != 0) throw Error(from + ": the zstd data is truncated (" + std::to_string(consumed) + " bytes)");
  files.out.close();
  if (!files.out) throw Error(to + ": closing the file failed");
  guard.done = true;
}

void compressZstdFile(const std::string& from, const std::string& to) {
  FilePair files(from, to);
  RemoveUnlessDone guard{to};
  CCtx context(ZSTD_createCCtx(), &ZSTD_freeCCtx);
  if (!context) throw Error(to + ": cannot create a zstd encoder");
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, 1);
  std::vector<char> input(ZSTD_CStreamInSize()), output(ZSTD_CStreamOutSize());
  for (;;) {
    files.in.read(input.data(), static_cast<std::streamsize>(input.size()));
    const std::size_t got = static_cast<std::size_t>(files.in.gcount());
    const bool last = got < input.size();
    ZSTD_inBuffer in{input.data(), got, 0};
    for (;;) {
      ZSTD_outBuffer out{output.data(), output.size(), 0};
      const std::size_t left = ZSTD_compressStream2(context.get(), &out, &in, last ? ZSTD_e_end : ZSTD_e_continue);
      if (ZSTD_isError(left)) throw Error(to + ": zstd compression failed: " + ZSTD_getErrorName(left));
      files.out.write(output.data(), static_cast<std::streamsize>(out.pos));
      if (!files.out) throw Error(to + ": write failed (disk full?)");
      if (last ? left == 0 : in.pos == in.size) break;
    }
    if (last) break;
  }
  files.out.close();
  if (!files.out) throw Error(to + ": closing the file failed");
  guard.done = true;
}

std::vector<std::uint8_t> decompressZstdMessage(const std::uint8_t* data, std::size_t size, const std::string& where) {
  const unsigned long long declared = ZSTD_getFrameContentSize(data, size);
  if (declared == ZSTD_CONTENTSIZE_ERROR) throw Error(where + ": not a zstd frame (the bag says MESSAGE compression)");
  if (declared == ZSTD_CONTENTSIZE_UNKNOWN) throw Error(where + ": the zstd frame does not declare its size");
  if (declared > kMaxDecompressedMessage)
    throw Error(where + ": the zstd frame declares " + std::to_string(declared) + " bytes, more than the " +
                std::to_string(kMaxDecompressedMessage) + " a message may have");
  // Memory grows with what is produced, not with what the frame declares.
  return decompressChunk("zstd", data, size, declared, where);
}

std::vector<std::uint8_t> compressZstdMessage(const std::uint8_t* data, std::size_t size) {
  return compressChunk(McapCompression::kZstd, data, size);
}

}  // namespace coloc::io::detail
