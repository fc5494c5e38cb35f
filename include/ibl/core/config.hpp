#pragma once
// ibl/core/config.hpp — the one function macro and the user-overridable hooks.
//
// IBL_FUNC       qualifies every public value-returning function: [[nodiscard]] inline, and
//                __host__ __device__ when the translation unit is compiled by nvcc, so the same
//                headers serve CPU code and CUDA device code.
// IBL_FUNC_VOID  the same without [[nodiscard]], for functions returning void.
// IBL_RESTRICT   the compilers' restrict qualifier, for the pointer arguments of batch kernels.
// IBL_ASSERT(c)  precondition checks on the host (default: assert from <cassert>). Define it before
//                including any ibl header to route checks into an engine's own assert. Device code
//                never asserts: under nvcc device compilation it expands to nothing.
//
// Hooks are documented in one place: docs/ARCHITECTURE.md, section "Configuration".

#if defined(__CUDACC__)
#define IBL_HOST_DEVICE __host__ __device__
#else
#define IBL_HOST_DEVICE
#endif

#define IBL_FUNC [[nodiscard]] IBL_HOST_DEVICE inline
#define IBL_FUNC_VOID IBL_HOST_DEVICE inline

#ifndef IBL_RESTRICT
#if defined(_MSC_VER)
#define IBL_RESTRICT __restrict
#else
#define IBL_RESTRICT __restrict__
#endif
#endif

#ifndef IBL_ASSERT
#if defined(__CUDA_ARCH__)
#define IBL_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define IBL_ASSERT(cond) assert(cond)
#endif
#endif

namespace ibl {
/// Version of the headers, kept in step with project(VERSION) in CMakeLists.txt.
inline constexpr int version_major = 0;
inline constexpr int version_minor = 1;
inline constexpr int version_patch = 0;
} // namespace ibl
