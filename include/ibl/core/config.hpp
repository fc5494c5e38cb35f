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
// IBL_VERSION_MAJOR / _MINOR / _PATCH, IBL_VERSION (major * 10000 + minor * 100 + patch) and
//                IBL_VERSION_STRING ("major.minor.patch"): the version of the headers. These three
//                numbers are the only place the version is written: CMakeLists.txt reads them
//                for project(VERSION), so the installed package (iblConfigVersion.cmake) agrees.
//
// Language: C++20. An older language mode (__cplusplus, or _MSVC_LANG on MSVC, below 202002L)
// stops with one #error: every public header includes this file before anything else and
// compiles its body only under IBL_DETAIL_CXX20.
//
// Hooks are documented in one place: docs/ARCHITECTURE.md, section "Configuration".

#define IBL_VERSION_MAJOR 0
#define IBL_VERSION_MINOR 1
#define IBL_VERSION_PATCH 0
#define IBL_VERSION (IBL_VERSION_MAJOR * 10000 + IBL_VERSION_MINOR * 100 + IBL_VERSION_PATCH)
#define IBL_DETAIL_STRINGIFY_(x) #x
#define IBL_DETAIL_STRINGIFY(x) IBL_DETAIL_STRINGIFY_(x)
#define IBL_VERSION_STRING                                                                         \
    IBL_DETAIL_STRINGIFY(IBL_VERSION_MAJOR) "." IBL_DETAIL_STRINGIFY(IBL_VERSION_MINOR) "."      \
        IBL_DETAIL_STRINGIFY(IBL_VERSION_PATCH)

#if defined(_MSVC_LANG) // MSVC keeps __cplusplus at 199711L unless /Zc:__cplusplus is given
#define IBL_DETAIL_CPLUSPLUS _MSVC_LANG
#else
#define IBL_DETAIL_CPLUSPLUS __cplusplus
#endif
#if IBL_DETAIL_CPLUSPLUS >= 202002L
#define IBL_DETAIL_CXX20 1
#else
#define IBL_DETAIL_CXX20 0
#error "ibl requires C++20 or later: compile with -std=c++20 (g++, clang++) or /std:c++20 (MSVC)"
#endif

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

#if IBL_DETAIL_CXX20
namespace ibl {
/// Version of the headers (the IBL_VERSION_* macros as constants).
inline constexpr int version_major = IBL_VERSION_MAJOR;
inline constexpr int version_minor = IBL_VERSION_MINOR;
inline constexpr int version_patch = IBL_VERSION_PATCH;
} // namespace ibl
#endif
