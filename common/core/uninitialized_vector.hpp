// UninitializedVector<T>: a std::vector whose resize() and size constructor leave trivially
// constructible elements uninitialised (default-initialisation instead of value-initialisation).
//
// For large buffers that are filled right after, in parallel: a std::vector<float>(n) first
// zeroes all n elements on one thread, which on a 2-core machine is a serial pass over memory
// (and where the pages are fresh, all their first-touch faults on that thread). assign(),
// push_back() and insert() initialise as usual.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace levelset {

template <class T, class Base = std::allocator<T>>
struct DefaultInitAllocator : Base {
  using Base::Base;
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U, typename std::allocator_traits<Base>::template rebind_alloc<U>>;
  };
  // Value-less construction default-initialises (no zeroing for trivial types).
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    std::allocator_traits<Base>::construct(static_cast<Base&>(*this), p, std::forward<Args>(args)...);
  }
};

template <class T>
using UninitializedVector = std::vector<T, DefaultInitAllocator<T>>;

// Raw storage for n objects of a trivially destructible T that the caller constructs in place
// (in parallel, say), from the same allocator: freed without destructor calls.
template <class T>
class UninitializedArray {
  static_assert(std::is_trivially_destructible_v<T>);

 public:
  explicit UninitializedArray(std::size_t n) : n_(n), p_(DefaultInitAllocator<T>().allocate(n > 0 ? n : 1)) {}
  UninitializedArray(const UninitializedArray&) = delete;
  UninitializedArray& operator=(const UninitializedArray&) = delete;
  ~UninitializedArray() { DefaultInitAllocator<T>().deallocate(p_, n_ > 0 ? n_ : 1); }
  T* data() const { return p_; }
  std::size_t size() const { return n_; }

 private:
  std::size_t n_;
  T* p_;
};

}  // namespace levelset
