// libFuzzer target: read_obj() on arbitrary bytes; whatever it accepts must build, validate
// and round-trip through extract().
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.h"
#include "hedge/io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // A view, not a copy: files are read mapped, with nothing after their last byte.
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  hedge::Soup soup;
  try {
    soup = hedge::read_obj(bytes, "fuzz");
  } catch (const hedge::Error&) {
    return 0;
  }
  hedge_fuzz::check_build_round_trip(soup);
  return 0;
}
