#pragma once
// ibl/core/memory.hpp — storage for buffers that their producer overwrites whole.
//
// detail::default_init_allocator<T>: std::allocator<T> whose value-less construct default-
// initialises (for float and the GLM vectors: leaves the memory as it is) instead of value-
// initialising (zero). A std::vector with it, resized, neither writes nor touches its new
// elements; the first writer does. The library's bulk outputs (a prefiltered chain, its packed
// source) are written in full by the executor's workers, so their pages are first touched by the
// threads that fill them rather than zeroed by one thread before the work (figures:
// docs/ARCHITECTURE.md, "The fast filter"). Every other construction (a value given, a copy) is
// std::allocator's.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace ibl::detail {

template <class T> struct default_init_allocator : std::allocator<T> {
    using std::allocator<T>::allocator;
    template <class U> struct rebind {
        using other = default_init_allocator<U>;
    };
    default_init_allocator() noexcept = default;
    template <class U> default_init_allocator(const default_init_allocator<U>& o) noexcept : std::allocator<T>(o) {}

    /// Default-initialises (no value given).
    template <class U> void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) { ::new (static_cast<void*>(p)) U; }
    /// Any other construction: as std::allocator.
    template <class U, class... Args> void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

template <class T, class U> bool operator==(const default_init_allocator<T>&, const default_init_allocator<U>&) noexcept { return true; }

/// Tag of the constructors that leave their storage to be overwritten (cubemap).
struct for_overwrite_t {
    explicit for_overwrite_t() = default;
};
inline constexpr for_overwrite_t for_overwrite{};

} // namespace ibl::detail

#endif // IBL_DETAIL_CXX20
