// Size limits of the 32-bit mesh (hedge/limits.h).
#include "hedge/limits.h"

#include "hedge/error.h"

namespace hedge {

std::string with_commas(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

std::string limit_message(std::uint64_t count, std::uint64_t limit, const std::string& what) {
  return with_commas(count) + " " + what + " asked for, but hedge's 32-bit indices hold at most " + with_commas(limit) +
         " " + what;
}

void check_limit(const std::string& context, std::uint64_t count, std::uint64_t limit, const std::string& what) {
  if (count > limit) throw Error(context + ": " + limit_message(count, limit, what));
}

}  // namespace hedge
