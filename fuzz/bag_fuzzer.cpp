// Recordings of any shape, through BagReader as `coloc fuse` opens them: open (MCAP: magic, footer,
// summary; sqlite3: schema, topics, metadata row), then stream every message (MCAP chunks
// decompressed) and collect the attachments and metadata records. Built twice: the file name
// (COLOC_FUZZ_BAG_FILE) decides which storage reader the bytes meet.
#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = coloc::fuzz::inputFile(data, size, COLOC_FUZZ_BAG_FILE);
  try {
    coloc::io::BagReader reader = coloc::io::BagReader::open(path);
    reader.keepAttachments(true);
    coloc::io::BagMessage message;
    while (reader.next(message)) {
    }
  } catch (const coloc::Error&) {
    // refused with a reason: what a reader must do with a bad file
  }
  return 0;
}
