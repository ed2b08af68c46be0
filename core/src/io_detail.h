// Pieces shared by the file readers and writers (core/src/io_*.cpp only): error messages
// that name the place, a text scanner that counts lines, exact number parsing and printing.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "hedge/error.h"
#include "hedge/soup.h"
#include "parallel.h"
#include "text.h"

namespace hedge::io_detail {

[[noreturn]] void fail_line(const std::string& name, std::size_t line, const std::string& what);
[[noreturn]] void fail_byte(const std::string& name, std::size_t offset, const std::string& what);

//! A token for an error message: 'abc' (shortened when long), or "end of line"/"end of file".
std::string quote(std::string_view token, bool at_end_of_file = false);

//! Runs soup.check() and puts the file name in front of its message: readers leave
//! topology alone, but a bad index or a NaN should still be reported against the file.
void check_soup(const Soup& soup, const std::string& name);

using detail::plural;

//! Parses the whole token as a T (integer or floating point). Accepts a leading '+', which
//! std::from_chars does not. Floating-point values too small or too large for T become
//! 0 or infinity, as strtod would give.
template <class T>
bool parse_number(std::string_view token, T& out);

// Out of line: the rare path of values beyond the range of float or double.
bool parse_out_of_range(std::string_view token, float& out);
bool parse_out_of_range(std::string_view token, double& out);

template <class T>
inline bool parse_number(std::string_view token, T& out) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '-' || *first == '+')) return false;
  }
  if (first == last) return false;
  if constexpr (std::is_floating_point_v<T>) {
    auto [ptr, ec] = std::from_chars(first, last, out, std::chars_format::general);
    if (ec == std::errc::result_out_of_range && ptr == last)
      return parse_out_of_range({first, std::size_t(last - first)}, out);
    return ec == std::errc() && ptr == last;
  } else {
    auto [ptr, ec] = std::from_chars(first, last, out);
    return ec == std::errc() && ptr == last;
  }
}

//! Appends the shortest text that reads back as exactly `value`.
template <class T>
inline void append_number(std::string& out, T value) {
  char buffer[64];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

//! A file's contents as pieces, in order: what writers format on several threads is kept
//! as it comes rather than copied into one string (write_mesh() writes the pieces as they
//! are; the write_*() functions join them).
struct Pieces {
  std::vector<std::string> parts;
  std::string joined() &&;
};

//! Thrown by a reader reading a run of a file when the run is not what the parallel reading
//! assumed (PLY text: one element a line; STL text: runs end after a facet): the file is then
//! read in one pass.
struct Irregular {};

//! The bytes of text a reader reads as one run (tests make runs of a few bytes).
inline std::size_t run_bytes() { return testing::parallel_grain() ? testing::parallel_grain() : std::size_t(1) << 20; }

//! read(r) for every run r in [0, n), each thread taking the next run left: runs of faces
//! take longer than runs of vertices.
template <class Read>
void read_runs(std::size_t n, Read&& read) {
  std::atomic<std::size_t> next{0};
  parallel_for(
      std::min<std::size_t>(n, resolve_thread_count(0)), 0,
      [&](std::size_t, std::size_t) {
        for (std::size_t r; (r = next.fetch_add(1)) < n;) read(r);
      },
      1);
}

//! Cuts `text` into runs of about `bytes` each, every run but the last ending with a line
//! break at which `may_cut(text, i)` (i: the break's index) allows a cut.
template <class MayCut>
std::vector<std::string_view> cut_into_runs(std::string_view text, std::size_t bytes, MayCut may_cut) {
  std::vector<std::string_view> runs;
  for (std::size_t begin = 0; begin < text.size();) {
    std::size_t end = std::min(begin + bytes, text.size());
    for (;;) {
      end = text.find('\n', end);
      if (end == std::string_view::npos) {
        end = text.size();
        break;
      }
      if (may_cut(text, end++)) break;
    }
    runs.push_back(text.substr(begin, end - begin));
    begin = end;
  }
  return runs;
}

//! A text body cut at line breaks into runs of about run_bytes(), for readers that read one
//! element a line, and the elements before each run.
struct LineRuns {
  std::vector<std::string_view> text;
  std::vector<std::uint64_t> first;  //!< elements before run r; the last entry holds them all
};

//! `body` as LineRuns, `count_elements(run)` telling the elements in each run (on all threads).
template <class CountElements>
LineRuns cut_into_line_runs(std::string_view body, CountElements count_elements) {
  LineRuns runs;
  runs.text = cut_into_runs(body, run_bytes(), [](std::string_view, std::size_t) { return true; });
  runs.first.assign(runs.text.size() + 1, 0);
  read_runs(runs.text.size(), [&](std::size_t r) { runs.first[r + 1] = count_elements(runs.text[r]); });
  for (std::size_t r = 0; r < runs.text.size(); ++r) runs.first[r + 1] += runs.first[r];
  return runs;
}

//! read_runs for the readers that hand the file to one pass when a run is not what they
//! assumed or fails: false when any run threw Irregular or Error (the runs left are skipped).
template <class Read>
bool read_runs_or_give_way(std::size_t n, Read&& read) {
  std::atomic<bool> ok{true};
  read_runs(n, [&](std::size_t r) {
    if (!ok.load(std::memory_order_relaxed)) return;
    try {
      read(r);
    } catch (const Irregular&) {
      ok = false;
    } catch (const Error&) {
      ok = false;
    }
  });
  return ok;
}

Pieces format_off(const Soup& soup);
Pieces format_obj(const Soup& soup);
Pieces format_ply(const Soup& soup, bool binary);
Pieces format_stl(const Soup& soup, bool binary);

//! Appends the text (or bytes) of elements [0, n), element i written by write(text, i), to
//! `out`, or, for many elements, moves `out` into `pieces` and adds runs of elements
//! written on several threads, each into a string of its own: the same bytes in order as one
//! pass. Formatting numbers is most of a writer's time.
template <class Write>
void append_elements(Pieces& pieces, std::string& out, std::size_t n, Write&& write) {
  const std::size_t per_run = testing::parallel_grain() ? testing::parallel_grain() : std::size_t(1) << 16;
  const std::size_t runs = (n + per_run - 1) / per_run;
  if (runs <= 1) {
    for (std::size_t i = 0; i < n; ++i) write(out, i);
    return;
  }
  // Room for 128 bytes an element, so that a run's string is seldom copied as it grows
  // (pages never touched cost nothing).
  std::vector<std::string> text(runs);
  parallel_for(
      runs, 0,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t r = begin; r < end; ++r) {
          text[r].reserve((n * (r + 1) / runs - n * r / runs) * 128);
          for (std::size_t i = n * r / runs; i < n * (r + 1) / runs; ++i) write(text[r], i);
        }
      },
      1);
  pieces.parts.push_back(std::move(out));
  out.clear();
  for (std::string& t : text) pieces.parts.push_back(std::move(t));
}

//! Little- or big-endian loads and stores of numbers, whatever the host's order.
template <class T>
inline T load(const unsigned char* p, bool big_endian) {
  using U = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                               std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                  std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  U bits;
  std::memcpy(&bits, p, sizeof bits);
  if (big_endian != (std::endian::native == std::endian::big)) {
    if constexpr (sizeof(U) == 2) bits = static_cast<U>(__builtin_bswap16(bits));
    if constexpr (sizeof(U) == 4) bits = __builtin_bswap32(bits);
    if constexpr (sizeof(U) == 8) bits = __builtin_bswap64(bits);
  }
  return std::bit_cast<T>(bits);
}

template <class T>
inline void append_le(std::string& out, T value) {
  auto bits = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if constexpr (std::endian::native == std::endian::big)
    for (std::size_t i = sizeof(T); i-- > 0;) out.push_back(bits[i]);
  else
    out.append(bits.data(), sizeof(T));
}

//! Whitespace-separated tokens over a text, counting lines for error messages.
//! Optionally a comment character (a token starting with it runs to the end of the line)
//! and backslash line continuation (OBJ).
class TextScanner {
 public:
  //! `first_line`: the number of the text's first line, when it is a run of a file's lines.
  TextScanner(std::string_view text, const std::string& name, char comment = 0, bool continuation = false,
              std::size_t first_line = 1)
      : begin_(text.data()),
        p_(text.data()),
        end_(text.data() + text.size()),
        line_(first_line),
        name_(name),
        comment_(comment),
        continuation_(continuation) {}

  //! The next token on the current line; empty at the end of the line or file.
  [[gnu::always_inline]] std::string_view line_token() {
    skip_space_in_line();
    const char* start = p_;
    if (continuation_) {
      while (p_ < end_ && !is_space(*p_) && !(*p_ == '\\' && is_continuation(p_))) ++p_;
    } else {
      while (p_ < end_ && !is_space(*p_)) ++p_;
    }
    return {start, static_cast<std::size_t>(p_ - start)};
  }

  //! The next token, on this line or a later one; empty at the end of the file.
  std::string_view token() {
    skip_space();
    return line_token();
  }

  //! Skips spaces, comments and line ends; the line count follows.
  void skip_space() {
    for (;;) {
      skip_space_in_line();
      if (p_ < end_ && *p_ == '\n') {
        ++p_;
        ++line_;
        continue;
      }
      return;
    }
  }

  //! True when nothing but spaces or a comment is left on the current line.
  [[gnu::always_inline]] bool at_line_end() {
    skip_space_in_line();
    return p_ == end_ || *p_ == '\n';
  }

  //! Moves to the start of the next line (or the end of the file).
  void next_line() {
    const void* nl = std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_));
    if (nl) {
      p_ = static_cast<const char*>(nl) + 1;
      ++line_;
    } else {
      p_ = end_;
    }
  }

  //! The rest of the current line without its line end; the scanner moves past it.
  std::string_view rest_of_line() {
    const char* start = p_;
    const void* nl = std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_));
    const char* stop = nl ? static_cast<const char*>(nl) : end_;
    p_ = stop;
    while (stop > start && (stop[-1] == '\r')) --stop;
    return {start, static_cast<std::size_t>(stop - start)};
  }

  bool at_end() const { return p_ == end_; }
  std::size_t line() const { return line_; }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }
  std::size_t offset() const { return static_cast<std::size_t>(p_ - begin_); }
  const std::string& name() const { return name_; }

  //! The line to name in a message: at the end of a file that ends with a line break,
  //! the last line rather than the empty one after it.
  std::size_t error_line() const {
    return p_ == end_ && p_ > begin_ && p_[-1] == '\n' && line_ > 1 ? line_ - 1 : line_;
  }
  [[noreturn]] void fail(const std::string& what) const { fail_line(name_, error_line(), what); }
  //! "expected <what>, found <token>" at the current line.
  [[noreturn]] void fail_expected(const std::string& what, std::string_view found) const {
    fail(what.empty() ? "unexpected " + quote(found, p_ == end_)
                      : "expected " + what + ", found " + quote(found, p_ == end_));
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

  bool is_continuation(const char* p) const {
    ++p;
    if (p < end_ && *p == '\r') ++p;
    return p == end_ || *p == '\n';
  }

  [[gnu::always_inline]] void skip_space_in_line() {
    for (;;) {
      while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r' || *p_ == '\v' || *p_ == '\f')) ++p_;
      if (p_ == end_) return;
      if (comment_ && *p_ == comment_) {
        const void* nl = std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_));
        p_ = nl ? static_cast<const char*>(nl) : end_;
        return;
      }
      if (continuation_ && *p_ == '\\' && is_continuation(p_)) {
        ++p_;
        if (p_ < end_ && *p_ == '\r') ++p_;
        if (p_ < end_) {
          ++p_;
          ++line_;
        }
        continue;
      }
      return;
    }
  }

  const char* begin_;
  const char* p_;
  const char* end_;
  std::size_t line_;
  const std::string& name_;
  char comment_;
  bool continuation_;
};

//! Colours in files are 0..255 integers or 0..1 reals; channels hold u8.
inline std::uint8_t color_from_real(double v) {
  if (!(v > 0.0)) return 0;  // also NaN
  if (v >= 1.0) return 255;
  return static_cast<std::uint8_t>(v * 255.0 + 0.5);
}
inline std::uint8_t color_from_integer(double v) {
  if (!(v > 0.0)) return 0;
  if (v >= 255.0) return 255;
  return static_cast<std::uint8_t>(v + 0.5);
}

//! Reads a "color" channel (u8 x4 or f32 x4, any domain) as RGBA bytes; nullptr when absent
//! or of another layout.
struct ColorView {
  const Channel* channel = nullptr;
  explicit operator bool() const { return channel != nullptr; }
  std::array<std::uint8_t, 4> operator[](std::size_t i) const;
};
ColorView find_color(const Soup& soup, Domain domain);

//! The channel `name` of `domain` when it has exactly this layout, else nullptr.
const Channel* find_channel(const Soup& soup, const std::string& name, Domain domain, ScalarType scalar,
                            int components);

}  // namespace hedge::io_detail
