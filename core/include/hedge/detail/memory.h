// Memory helpers of the mesh's arrays. Not part of hedge's interface: mesh.h needs them in
// its member types and inline functions, nothing outside the core should use them.
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace hedge::detail {

//! Memory for an array of `bytes`, aligned to `alignment`, uninitialised; throws
//! std::bad_alloc. Arrays of 2 MiB or more are asked for on transparent huge pages where
//! Linux offers them (a hint; small pages otherwise): the mesh's arrays are read in random
//! order, where small pages mean a TLB miss at nearly every step, and each 4 KiB page's
//! first touch is a fault, which costs far more than writing the page in a virtual machine.
//! Give it back with free_array().
void* allocate_array(std::size_t bytes, std::size_t alignment);
void free_array(void* p) noexcept;

//! Asks for huge pages, as allocate_array() does, under the whole 2 MiB pages that lie inside
//! [p, p + bytes): for a big array another allocator made, before its first touch.
void advise_huge_pages(const void* p, std::size_t bytes) noexcept;

//! v.reserve(n) for an empty std::vector, its memory on huge pages where whole ones fit: the
//! readers' and extract()'s big arrays, whose type the soup's interface fixes.
template <class Vector>
void reserve_on_huge_pages(Vector& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data(), v.capacity() * sizeof(*v.data()));
}

//! v.resize(n, value) for an empty std::vector, on huge pages as above.
template <class Vector>
void resize_on_huge_pages(Vector& v, std::size_t n, const typename Vector::value_type& value = {}) {
  reserve_on_huge_pages(v, n);
  v.resize(n, value);
}

//! std::allocator, except that an element made without a value (resize(n), emplace_back())
//! is left unset. The mesh's connectivity arrays use it so that a builder that writes every
//! field itself (Mesh::resize_unset) does not pay for a fill first: on a big mesh that fill
//! is one thread taking every page fault of tens of megabytes, which the builder's own
//! writes, spread over its threads, take anyway. Its memory comes from allocate_array().
template <class T>
struct UnsetAllocator : std::allocator<T> {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
  using value_type = T;
  UnsetAllocator() = default;
  template <class U>
  UnsetAllocator(const UnsetAllocator<U>&) noexcept {}
  template <class U>
  struct rebind {
    using other = UnsetAllocator<U>;
  };
  T* allocate(std::size_t n) {
    if (n > std::numeric_limits<std::size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_array(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t) noexcept { free_array(p); }
  template <class U>
  void construct(U*) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    std::construct_at(p, std::forward<Args>(args)...);
  }
};

//! Starts loading the cache line at p (a hint; changes nothing, a no-op where unsupported).
inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

//! each(i, new_to_old[i]) for i in [begin, end), the element at(new_to_old[i]) fetched some
//! places ahead. What a compaction keeps lies scattered through the old array, too sparsely
//! for the hardware to see a stream, so each element would otherwise wait on memory.
template <class Index, class At, class Each>
void gather_ahead(const Index* new_to_old, std::size_t begin, std::size_t end, At at, Each each) {
  constexpr std::size_t kAhead = 16;
  for (std::size_t i = begin; i < end; ++i) {
    if (i + kAhead < end) prefetch(at(new_to_old[i + kAhead]));
    each(i, new_to_old[i]);
  }
}

}  // namespace hedge::detail
