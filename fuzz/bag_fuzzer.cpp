// Recordings of any shape, through BagReader as `coloc fuse` opens them: open (MCAP: magic, footer,
// summary; sqlite3: schema, topics, metadata row), then stream every message (MCAP chunks
// decompressed) and collect the attachments and metadata records; then again with recovery on, as
// `--recover` opens a recording that was never closed (the counts it promised must be what it reads).
// Built twice: the file name (COLOC_FUZZ_BAG_FILE) decides which storage reader the bytes meet.
#include <cstdlib>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = coloc::fuzz::inputFile(data, size, COLOC_FUZZ_BAG_FILE);
  for (const bool recover : {false, true}) {
    try {
      coloc::io::BagReader reader = coloc::io::BagReader::open(path, coloc::io::BagReadOptions{recover});
      reader.keepAttachments(true);
      coloc::io::BagMessage message;
      std::uint64_t read = 0;
      while (reader.next(message)) ++read;
      // A recovered file is read exactly as far as its opening scan counted.
      if (!reader.recovered().empty() && read != reader.messageCount()) std::abort();
    } catch (const coloc::Error&) {
      // refused with a reason: what a reader must do with a bad file
    }
  }
  return 0;
}
