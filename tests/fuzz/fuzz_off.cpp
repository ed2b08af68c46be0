// libFuzzer target: read_off() on arbitrary bytes; read whole and in runs of a few bytes on two
// threads it must give the same soup or the same error, and whatever it accepts must build,
// validate and round-trip through extract().
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.h"
#include "hedge/io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // A view, not a copy: files are read mapped, with nothing after their last byte.
  hedge_fuzz::check_reader(std::string_view(reinterpret_cast<const char*>(data), size),
                           [](std::string_view bytes) { return hedge::read_off(bytes, "fuzz"); });
  return 0;
}
