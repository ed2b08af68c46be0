// Named, typed per-element arrays ("properties"), pmp-style. A PropertyContainer holds
// the arrays of one element kind and keeps them all the same length; garbage collection
// and builders move whole arrays at once through the type-erased PropertyArray.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/error.h"
#include "hedge/handles.h"
#include "hedge/provenance.h"
#include "hedge/vec.h"

namespace hedge {

//! Element scalar types of host attribute channels.
enum class ScalarType : std::uint8_t { f32, f64, i8, u8, i16, u16, i32, u32, i64, u64 };
std::size_t scalar_size(ScalarType type);
const char* scalar_name(ScalarType type);

//! The C++ type of a channel scalar, for f.template operator()<C>().
template <class F>
decltype(auto) with_scalar(ScalarType scalar, F&& f) {
  switch (scalar) {
    case ScalarType::f32:
      return f.template operator()<float>();
    case ScalarType::f64:
      return f.template operator()<double>();
    case ScalarType::i8:
      return f.template operator()<std::int8_t>();
    case ScalarType::u8:
      return f.template operator()<std::uint8_t>();
    case ScalarType::i16:
      return f.template operator()<std::int16_t>();
    case ScalarType::u16:
      return f.template operator()<std::uint16_t>();
    case ScalarType::i32:
      return f.template operator()<std::int32_t>();
    case ScalarType::u32:
      return f.template operator()<std::uint32_t>();
    case ScalarType::i64:
      return f.template operator()<std::int64_t>();
    case ScalarType::u64:
      return f.template operator()<std::uint64_t>();
  }
  throw Error("unknown channel scalar type");
}

//! Type-erased array of one property: what containers need to keep arrays in step.
class PropertyArray {
 public:
  explicit PropertyArray(std::string name) : name_(std::move(name)) {}
  virtual ~PropertyArray() = default;
  const std::string& name() const { return name_; }
  //! build()'s provenance (hedge/provenance.h): bookkeeping about where an element came
  //! from, which a new element made from several old ones does not inherit.
  bool is_internal() const { return name_.starts_with(provenance::kPrefix); }

  virtual std::size_t size() const = 0;
  virtual void resize(std::size_t n) = 0;
  virtual void reserve(std::size_t n) = 0;
  virtual void push_back() = 0;
  virtual void shrink_to_fit() = 0;
  virtual void swap_elements(std::size_t a, std::size_t b) = 0;
  virtual void copy_element(std::size_t from, std::size_t to) = 0;
  //! element[to] = sum w_i element[from_i] for numbers; the value of the largest weight otherwise.
  virtual void interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights) = 0;
  //! element[i] = the default value (zeros for channels).
  virtual void reset(std::size_t i) = 0;
  //! Gather: new[i] = old[new_to_old[i]]; the size becomes new_to_old.size().
  virtual void permute(std::span<const Index> new_to_old) = 0;
  virtual std::unique_ptr<PropertyArray> clone() const = 0;
  virtual const std::type_info& type() const = 0;
  //! Heap bytes held (capacity, not size).
  virtual std::size_t heap_bytes() const = 0;

 private:
  std::string name_;
};

namespace detail {
template <class T>
struct is_vec : std::false_type {};
template <class T, int N>
struct is_vec<Vec<T, N>> : std::true_type {};
// A partial specialisation, so that non-vector types never form T{}[0].
template <class T>
struct is_interpolable : std::is_floating_point<T> {};
template <class T, int N>
struct is_interpolable<Vec<T, N>> : std::is_floating_point<T> {};
template <class T>
inline constexpr bool is_interpolable_v = is_interpolable<T>::value;

template <class W>
std::size_t largest_weight(std::span<const W> weights) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < weights.size(); ++i)
    if (weights[i] > weights[best]) best = i;
  return best;
}
}  // namespace detail

//! A property of values of type T, with a default for new elements.
template <class T>
class TypedArray final : public PropertyArray {
 public:
  TypedArray(std::string name, T default_value) : PropertyArray(std::move(name)), default_(std::move(default_value)) {}

  std::vector<T>& vector() { return data_; }
  const std::vector<T>& vector() const { return data_; }
  const T& default_value() const { return default_; }

  std::size_t size() const override { return data_.size(); }
  void resize(std::size_t n) override { data_.resize(n, default_); }
  void reserve(std::size_t n) override { data_.reserve(n); }
  void push_back() override { data_.push_back(default_); }
  void shrink_to_fit() override { data_.shrink_to_fit(); }
  void swap_elements(std::size_t a, std::size_t b) override {
    T tmp = data_[a];
    data_[a] = data_[b];
    data_[b] = tmp;
  }
  void copy_element(std::size_t from, std::size_t to) override { data_[to] = T(data_[from]); }
  void interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights) override {
    if (from.empty()) return;
    if constexpr (detail::is_interpolable_v<T>) {
      T sum{};
      for (std::size_t i = 0; i < from.size(); ++i) sum += data_[from[i]] * weights[i];
      data_[to] = sum;
    } else {
      data_[to] = T(data_[from[detail::largest_weight(weights)]]);
    }
  }
  void reset(std::size_t i) override { data_[i] = default_; }
  void permute(std::span<const Index> new_to_old) override {
    std::vector<T> out;
    out.reserve(new_to_old.size());
    if constexpr (std::is_same_v<T, bool>) {  // no address to fetch
      for (Index i : new_to_old) out.push_back(data_[i]);
    } else {
      detail::gather_ahead(
          new_to_old.data(), 0, new_to_old.size(), [&](Index j) { return &data_[j]; },
          [&](std::size_t, Index j) { out.push_back(data_[j]); });
    }
    data_.swap(out);
  }
  std::unique_ptr<PropertyArray> clone() const override { return std::make_unique<TypedArray>(*this); }
  const std::type_info& type() const override { return typeid(T); }
  std::size_t heap_bytes() const override {
    if constexpr (std::is_same_v<T, bool>)
      return data_.capacity() / 8;
    else
      return data_.capacity() * sizeof(T);
  }

 private:
  std::vector<T> data_;
  T default_;
};

//! A host attribute channel: `components` scalars of one ScalarType per element, kept as
//! raw bytes so that a round trip is bit for bit.
class ChannelArray final : public PropertyArray {
 public:
  ChannelArray(std::string name, ScalarType scalar, int components)
      : PropertyArray(std::move(name)),
        scalar_(scalar),
        components_(components),
        stride_(scalar_size(scalar) * static_cast<std::size_t>(components)) {}

  ScalarType scalar() const { return scalar_; }
  int components() const { return components_; }
  std::size_t stride() const { return stride_; }
  std::vector<std::byte>& bytes() { return data_; }
  const std::vector<std::byte>& bytes() const { return data_; }
  std::byte* element(std::size_t i) { return data_.data() + i * stride_; }
  const std::byte* element(std::size_t i) const { return data_.data() + i * stride_; }
  //! Whether elements a and b hold the same bytes. The common sizes compare as words: a call
  //! to memcmp for each corner compared was a sixth of decimating a mesh with a UV map.
  bool same(std::size_t a, std::size_t b) const {
    const std::byte *x = element(a), *y = element(b);
    auto word = [](const std::byte* p, std::size_t at) {
      std::uint64_t w;
      std::memcpy(&w, p + at, sizeof w);
      return w;
    };
    auto half = [](const std::byte* p, std::size_t at) {
      std::uint32_t w;
      std::memcpy(&w, p + at, sizeof w);
      return w;
    };
    switch (stride_) {
      case 4:
        return half(x, 0) == half(y, 0);
      case 8:
        return word(x, 0) == word(y, 0);
      case 12:
        return word(x, 0) == word(y, 0) && half(x, 8) == half(y, 8);
      case 16:
        return word(x, 0) == word(y, 0) && word(x, 8) == word(y, 8);
      default:
        return std::memcmp(x, y, stride_) == 0;
    }
  }

  std::size_t size() const override { return stride_ ? data_.size() / stride_ : 0; }
  void resize(std::size_t n) override { data_.resize(n * stride_); }
  void reserve(std::size_t n) override { data_.reserve(n * stride_); }
  void push_back() override { data_.resize(data_.size() + stride_); }
  void shrink_to_fit() override { data_.shrink_to_fit(); }
  void swap_elements(std::size_t a, std::size_t b) override;
  void copy_element(std::size_t from, std::size_t to) override {
    if (from != to) std::memcpy(element(to), element(from), stride_);
  }
  void interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights) override;
  void reset(std::size_t i) override { std::memset(element(i), 0, stride_); }
  void permute(std::span<const Index> new_to_old) override;
  std::unique_ptr<PropertyArray> clone() const override { return std::make_unique<ChannelArray>(*this); }
  const std::type_info& type() const override { return typeid(ChannelArray); }
  std::size_t heap_bytes() const override { return data_.capacity(); }

 private:
  ScalarType scalar_;
  int components_;
  std::size_t stride_;
  std::vector<std::byte> data_;
};

namespace detail {
template <class T, class W>
void blend_reals(const ChannelArray& src, std::span<const Index> from, std::span<const W> weights, std::byte* to) {
  for (int k = 0; k < src.components(); ++k) {
    double sum = 0;
    for (std::size_t i = 0; i < from.size(); ++i) {
      T value;
      std::memcpy(&value, src.element(from[i]) + k * sizeof(T), sizeof(T));
      sum += static_cast<double>(value) * static_cast<double>(weights[i]);
    }
    const T out = static_cast<T>(sum);
    std::memcpy(to + k * sizeof(T), &out, sizeof(T));
  }
}

//! The one rule by which a channel element is made from others: real components are weighted
//! sums (taken in double); integer channels (ids, flags, 8-bit colours) take the heaviest
//! source's value. Component k of every source is read before component k of `to` is written,
//! so `to` may be one of the sources. `to` is an element of a channel laid out like `src`.
template <class W>
void blend_element(const ChannelArray& src, std::span<const Index> from, std::span<const W> weights, std::byte* to) {
  if (from.empty()) return;
  switch (src.scalar()) {
    case ScalarType::f32:
      return blend_reals<float>(src, from, weights, to);
    case ScalarType::f64:
      return blend_reals<double>(src, from, weights, to);
    default:
      std::memmove(to, src.element(from[largest_weight(weights)]), src.stride());
  }
}
}  // namespace detail

//! A typed view of one property of element kind H (Vertex, Halfedge, Edge or Face).
//! Valid while the property exists; cheap to copy.
template <class H, class T>
class Property {
 public:
  Property() = default;
  explicit Property(TypedArray<T>* array) : array_(array) {}
  explicit operator bool() const { return array_ != nullptr; }

  decltype(auto) operator[](H h) { return array_->vector()[h.idx()]; }
  decltype(auto) operator[](H h) const { return std::as_const(array_->vector())[h.idx()]; }
  std::vector<T>& vector() { return array_->vector(); }
  const std::vector<T>& vector() const { return array_->vector(); }
  const std::string& name() const { return array_->name(); }

 private:
  TypedArray<T>* array_ = nullptr;
};

template <class T>
using VertexProperty = Property<Vertex, T>;
template <class T>
using HalfedgeProperty = Property<Halfedge, T>;
template <class T>
using EdgeProperty = Property<Edge, T>;
template <class T>
using FaceProperty = Property<Face, T>;

//! The properties of one element kind, all of length size().
class PropertyContainer {
 public:
  PropertyContainer() = default;
  PropertyContainer(const PropertyContainer& other);
  PropertyContainer& operator=(const PropertyContainer& other);
  PropertyContainer(PropertyContainer&&) noexcept = default;
  PropertyContainer& operator=(PropertyContainer&&) noexcept = default;

  std::size_t size() const { return size_; }
  std::size_t count() const { return arrays_.size(); }
  std::vector<std::string> names() const;
  PropertyArray* find(const std::string& name) const;
  PropertyArray& at(std::size_t i) const { return *arrays_[i]; }
  bool exists(const std::string& name) const { return find(name) != nullptr; }

  template <class T>
  TypedArray<T>* add(const std::string& name, T default_value = T()) {
    if (exists(name)) throw Error("property '" + name + "' exists already");
    auto array = std::make_unique<TypedArray<T>>(name, std::move(default_value));
    array->resize(size_);
    auto* raw = array.get();
    arrays_.push_back(std::move(array));
    return raw;
  }
  template <class T>
  TypedArray<T>* get(const std::string& name) const {
    PropertyArray* array = find(name);
    return array && array->type() == typeid(T) ? static_cast<TypedArray<T>*>(array) : nullptr;
  }
  ChannelArray* add_channel(const std::string& name, ScalarType scalar, int components);
  ChannelArray* get_channel(const std::string& name) const;
  void remove(const std::string& name);
  void clear() {
    arrays_.clear();
    size_ = 0;
  }

  void resize(std::size_t n);
  void reserve(std::size_t n);
  void push_back();
  void shrink_to_fit();
  void swap_elements(std::size_t a, std::size_t b);
  void copy_element(std::size_t from, std::size_t to);
  //! Interpolates every array, except internal ones, which take their default.
  void interpolate(std::size_t to, std::span<const Index> from, std::span<const float> weights);
  void permute(std::span<const Index> new_to_old);
  std::size_t heap_bytes() const;

 private:
  std::vector<std::unique_ptr<PropertyArray>> arrays_;
  std::size_t size_ = 0;
};

}  // namespace hedge
