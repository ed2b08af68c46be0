// libFuzzer target: read_obj() on arbitrary bytes; whatever it accepts must build, validate
// and round-trip through extract(). The reader cuts a file into runs of lines read on
// several threads: read in runs of a few bytes on two threads, the same bytes must give
// the same soup, or the same error, as read whole.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_common.h"
#include "hedge/io.h"
#include "hedge/threads.h"
#include "parallel.h"

namespace {

//! The soup, or the error's message.
struct Read {
  hedge::Soup soup;
  std::string error;
  bool failed = false;
};

Read read(std::string_view bytes) {
  Read r;
  try {
    r.soup = hedge::read_obj(bytes, "fuzz");
  } catch (const hedge::Error& e) {
    r.failed = true;
    r.error = e.what();
  }
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // A view, not a copy: files are read mapped, with nothing after their last byte.
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const Read whole = read(bytes);
  hedge::set_thread_count(2);
  hedge::testing::set_parallel_grain(1 + size % 7);
  const Read in_runs = read(bytes);
  hedge::set_thread_count(0);
  hedge::testing::set_parallel_grain(0);
  if (whole.failed != in_runs.failed || whole.error != in_runs.error || !(whole.soup == in_runs.soup))
    hedge_fuzz::fail("read in runs of " + std::to_string(1 + size % 7) + " bytes differs from the whole file: '" +
                     (whole.failed ? whole.error : "a soup") + "' against '" +
                     (in_runs.failed ? in_runs.error : "a soup") + "'");
  if (!whole.failed) hedge_fuzz::check_build_round_trip(whole.soup);
  return 0;
}
