// libFuzzer target: build() on a soup drawn from the input (positions with the odd NaN or
// infinity, polygons of any size, indices mostly in range, channels of all three domains).
// hedge::Error is an answer; a crash, another exception or a broken mesh is a bug. When
// build() accepts the soup, extract() must give it back bit for bit, bar skipped faces, with
// and without the input to guard its weld (ExtractOptions::input).
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "fuzz_common.h"

namespace {

float coordinate(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 15)) {
    case 0: return std::numeric_limits<float>::quiet_NaN();
    case 1: return std::numeric_limits<float>::infinity();
    case 2: return -0.0f;
    case 3: return in.ConsumeFloatingPoint<float>();  // any value, huge or denormal
    default: return static_cast<float>(in.ConsumeIntegralInRange<int>(-4, 4));  // coincident points
  }
}

hedge::Soup draw_soup(FuzzedDataProvider& in) {
  hedge::Soup soup;
  std::size_t nv = in.ConsumeIntegralInRange<std::size_t>(0, 24);
  for (std::size_t i = 0; i < nv; ++i) {
    float x = coordinate(in), y = coordinate(in), z = coordinate(in);
    soup.positions.push_back({x, y, z});
  }
  std::size_t nf = in.ConsumeIntegralInRange<std::size_t>(0, 32);
  for (std::size_t f = 0; f < nf && in.remaining_bytes() > 0; ++f) {
    std::uint32_t size = in.ConsumeIntegralInRange<std::uint32_t>(in.ConsumeProbability<float>() < 0.05f ? 0 : 3, 6);
    soup.face_sizes.push_back(size);
    for (std::uint32_t c = 0; c < size; ++c) {
      std::uint32_t idx;
      if (nv == 0 || in.ConsumeProbability<float>() < 0.02f)
        idx = in.ConsumeIntegral<std::uint32_t>();  // out of range (usually)
      else
        idx = in.ConsumeIntegralInRange<std::uint32_t>(0, static_cast<std::uint32_t>(nv - 1));
      soup.corners.push_back(idx);
    }
  }
  static const char* names[] = {"normal", "color", "uv", "quality", "selected", "material", "custom"};
  static const hedge::ScalarType types[] = {hedge::ScalarType::f32, hedge::ScalarType::f64, hedge::ScalarType::i8,
                                            hedge::ScalarType::u8,  hedge::ScalarType::i16, hedge::ScalarType::u16,
                                            hedge::ScalarType::i32, hedge::ScalarType::u32, hedge::ScalarType::i64,
                                            hedge::ScalarType::u64};
  std::size_t nc = in.ConsumeIntegralInRange<std::size_t>(0, 4);
  for (std::size_t i = 0; i < nc; ++i) {
    auto domain = static_cast<hedge::Domain>(in.ConsumeIntegralInRange<int>(0, 2));
    std::string name = names[in.ConsumeIntegralInRange<int>(0, 6)];
    if (soup.find(name, domain)) name += std::to_string(i);
    auto scalar = types[in.ConsumeIntegralInRange<int>(0, 9)];
    int components = in.ConsumeIntegralInRange<int>(1, 4);
    hedge::Channel ch = hedge::Channel::make(name, domain, scalar, components, soup.domain_size(domain));
    // Wrong lengths now and then: build() must reject them with an Error.
    if (in.ConsumeProbability<float>() < 0.03f) ch.data.resize(ch.data.size() + ch.stride());
    std::string bytes = in.ConsumeBytesAsString(ch.data.size());
    for (std::size_t b = 0; b < bytes.size(); ++b) ch.data[b] = static_cast<std::byte>(bytes[b]);
    soup.channels.push_back(std::move(ch));
  }
  return soup;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  hedge::Soup soup = draw_soup(in);
  hedge_fuzz::check_build_round_trip(soup, /*with_input=*/true);
  return 0;
}
