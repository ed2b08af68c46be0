// Property containers and host attribute channels.
#include "hedge/properties.h"

#include <algorithm>
#include <cstring>

namespace hedge {

std::size_t scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::i8:
    case ScalarType::u8:
      return 1;
    case ScalarType::i16:
    case ScalarType::u16:
      return 2;
    case ScalarType::f32:
    case ScalarType::i32:
    case ScalarType::u32:
      return 4;
    case ScalarType::f64:
    case ScalarType::i64:
    case ScalarType::u64:
      return 8;
  }
  return 0;
}

const char* scalar_name(ScalarType type) {
  switch (type) {
    case ScalarType::f32:
      return "float32";
    case ScalarType::f64:
      return "float64";
    case ScalarType::i8:
      return "int8";
    case ScalarType::u8:
      return "uint8";
    case ScalarType::i16:
      return "int16";
    case ScalarType::u16:
      return "uint16";
    case ScalarType::i32:
      return "int32";
    case ScalarType::u32:
      return "uint32";
    case ScalarType::i64:
      return "int64";
    case ScalarType::u64:
      return "uint64";
  }
  return "unknown";
}

void ChannelArray::swap_elements(std::size_t a, std::size_t b) {
  if (a == b) return;
  std::swap_ranges(element(a), element(a) + stride_, element(b));
}

void ChannelArray::interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights) {
  detail::blend_element(*this, from, weights, element(to));
}

void ChannelArray::permute(std::span<const Index> new_to_old) {
  std::vector<std::byte> out(new_to_old.size() * stride_);
  detail::gather_ahead(
      new_to_old.data(), 0, new_to_old.size(), [&](Index j) { return element(j); },
      [&](std::size_t i, Index j) { std::memcpy(out.data() + i * stride_, element(j), stride_); });
  data_.swap(out);
}

PropertyContainer::PropertyContainer(const PropertyContainer& other) : size_(other.size_) {
  for (const auto& a : other.arrays_) arrays_.push_back(a->clone());
}

PropertyContainer& PropertyContainer::operator=(const PropertyContainer& other) {
  if (this != &other) {
    PropertyContainer copy(other);
    *this = std::move(copy);
  }
  return *this;
}

std::vector<std::string> PropertyContainer::names() const {
  std::vector<std::string> out;
  for (const auto& a : arrays_) out.push_back(a->name());
  return out;
}

PropertyArray* PropertyContainer::find(const std::string& name) const {
  for (const auto& a : arrays_)
    if (a->name() == name) return a.get();
  return nullptr;
}

ChannelArray* PropertyContainer::add_channel(const std::string& name, ScalarType scalar, int components) {
  if (exists(name)) throw Error("property '" + name + "' exists already");
  auto array = std::make_unique<ChannelArray>(name, scalar, components);
  array->resize(size_);
  auto* raw = array.get();
  arrays_.push_back(std::move(array));
  return raw;
}

ChannelArray* PropertyContainer::get_channel(const std::string& name) const {
  PropertyArray* array = find(name);
  return array && array->type() == typeid(ChannelArray) ? static_cast<ChannelArray*>(array) : nullptr;
}

void PropertyContainer::remove(const std::string& name) {
  std::erase_if(arrays_, [&](const auto& a) { return a->name() == name; });
}

void PropertyContainer::resize(std::size_t n) {
  for (auto& a : arrays_) a->resize(n);
  size_ = n;
}
void PropertyContainer::reserve(std::size_t n) {
  for (auto& a : arrays_) a->reserve(n);
}
void PropertyContainer::push_back() {
  for (auto& a : arrays_) a->push_back();
  ++size_;
}
void PropertyContainer::shrink_to_fit() {
  for (auto& a : arrays_) a->shrink_to_fit();
}
void PropertyContainer::swap_elements(std::size_t a, std::size_t b) {
  for (auto& p : arrays_) p->swap_elements(a, b);
}
void PropertyContainer::copy_element(std::size_t from, std::size_t to) {
  for (auto& p : arrays_) p->copy_element(from, to);
}
void PropertyContainer::interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights) {
  for (auto& p : arrays_) {
    if (p->is_internal())
      p->reset(to);
    else
      p->interpolate(to, from, weights);
  }
}
void PropertyContainer::permute(std::span<const Index> new_to_old) {
  for (auto& p : arrays_) p->permute(new_to_old);
  size_ = new_to_old.size();
}
std::size_t PropertyContainer::heap_bytes() const {
  std::size_t bytes = arrays_.capacity() * sizeof(arrays_[0]);
  for (const auto& a : arrays_) bytes += a->heap_bytes() + sizeof(*a);
  return bytes;
}

}  // namespace hedge
