#pragma once
// Whether bytes from outside (a message's strings, a frame name) are text: names that reach logs and
// reports must be well-formed UTF-8.
#include <cstddef>

namespace coloc {

/// True if `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past U+10FFFF).
bool isValidUtf8(const char* text, std::size_t size);

}  // namespace coloc
