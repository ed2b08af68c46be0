// Small pieces of text for messages, shared by the readers, build() and the operations.
#pragma once

#include <cstdint>
#include <string>

namespace hedge::detail {

//! "1 face", "2 faces"; irregular words give their plural: plural(n, "vertex", "vertices").
inline std::string plural(std::uint64_t n, const char* word, const char* words = nullptr) {
  if (n == 1) return "1 " + std::string(word);
  return std::to_string(n) + " " + (words ? std::string(words) : std::string(word) + "s");
}

}  // namespace hedge::detail
