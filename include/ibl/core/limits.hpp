#pragma once
// ibl/core/limits.hpp — the documented upper bounds on sizes and counts that the library's public
// entry points accept, and the host-only argument checks that enforce them.
//
// Every public function that takes a size, a count or a level checks it before any allocation
// or loop: a bad value (below the domain: a size < 1, a level outside the chain, zero nodes)
// throws std::invalid_argument, a value above a bound throws std::length_error. The message
// names the function, the argument and its value ("ibl::cubemap: face size = 2147483647 exceeds
// limits::max_face_size = 65536", "ibl::cubemap: face size must be >= 1, got 0"). Sizes are multiplied in std::size_t with an overflow check
// (detail::checked_mul), never in int.
//
// The bounds and why (docs/ARCHITECTURE.md, section "Limits"):
//   max_face_size      65536      cube face size, lat-long width and height: keeps n + 2, 2 n + 1
//                                 and n k (k <= max_subsamples) inside int, and the texel
//                                 coordinates scaled by n exact in float's 24-bit mantissa.
//   max_texels         2^30       texels stored by one cubemap / latlong (borders and mips
//                                 included): 12 GiB of vec3<float>, 24 GiB of vec3<double>. A
//                                 full chain of face size 8192 (5.4e8 texels) fits; the memory
//                                 bound, not max_face_size, limits a cube in practice.
//   max_samples        2^24       samples / directions per texel or per estimate (Monte Carlo
//                                 DFG, prefilter and irradiance tables, LD and irradiance
//                                 references, radiance_reference): float Hammersley points are
//                                 distinct only up to 2^24 (i / n and the radical inverse keep 24
//                                 bits), and a 2^24 table is 320 MiB (prefilter, 5 floats each).
//   max_work           2^34       total integrand evaluations of one bake call (bake_cubemap's
//                                 6 n^2 k^2 sub-samples, prefilter's and irradiance_cubemap's
//                                 texels x taps, a DFG table's texels x nodes or samples): about
//                                 minutes on one core (the time per tap: docs/ARCHITECTURE.md,
//                                 "Limits"), seconds with a thread executor; no single argument
//                                 buys hours of work.
//   max_subsamples     64         bake_cubemap's k (k^2 = 4096 sub-samples per texel, far past
//                                 the O(1 / (n k)^2) accuracy any product needs).
//   max_quadrature_nodes 256      each count of dfg_quadrature_nodes (2 x 256^2 weight
//                                 evaluations per texel; the converged tables use 12 - 32).
//   max_gauss_legendre_nodes 4096 make_gauss_legendre: O(n^2) construction, and the Newton
//                                 roots stay accurate to ~1 ulp only up to a few thousand nodes.
//   max_dfg_lut_size   4096       texels per side of a DFG table (64 MiB of float at 4 channels;
//                                 the interpolation error is first order, 0.6 / N: 1.5e-4 there).
//   max_sh_degree      1024       project_function's degree (about 1.05e6 directions).
//   max_cap_nodes      2048       the sun-cap rule of reference_ld_sky / reference_irradiance_sky
//                                 (4 n^2 = 1.7e7 directions).
//   max_distribution_size 4096    face size of the level a cube_env_distribution is built from
//                                 (19 doubles per texel: 2.3 GiB at 4096; pick a coarser level).
//   max_batches        65536      radiance_reference batches (one result record each).
//   max_plan_levels    17         plan_settings::levels: the full chain of max_face_size, so
//                                 every shift n << v, base >> v stays defined.
// Device-callable functions (IBL_FUNC) never throw: they clamp a count to its bound or report
// failure in their result (documented where they do, e.g. sh_auto_window).

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace ibl {

namespace limits {
inline constexpr int max_face_size = 65536;
inline constexpr std::size_t max_texels = std::size_t(1) << 30;
inline constexpr std::uint32_t max_samples = 1u << 24;
inline constexpr std::uint64_t max_work = std::uint64_t(1) << 34;
inline constexpr int max_subsamples = 64;
inline constexpr std::uint32_t max_quadrature_nodes = 256;
inline constexpr std::size_t max_gauss_legendre_nodes = 4096;
inline constexpr std::uint32_t max_dfg_lut_size = 4096;
inline constexpr int max_sh_degree = 1024;
inline constexpr int max_cap_nodes = 2048;
inline constexpr int max_distribution_size = 4096;
inline constexpr std::uint32_t max_batches = 65536;
inline constexpr int max_plan_levels = 17;
} // namespace limits

namespace detail {

/// "ibl::<fn>: <arg> = <value>" — the common head of every argument message.
template <class V> std::string arg_message(const char* fn, const char* arg, V value) {
    return std::string("ibl::") + fn + ": " + arg + " = " + std::to_string(value);
}

/// Throws std::invalid_argument unless lo <= value (a bad value), std::length_error unless
/// value <= hi (too large); `bound` names the limit in the message.
template <class V, class L, class H>
void check_arg(const char* fn, const char* arg, V value, L lo, H hi, const char* bound) {
    if (value < V(lo))
        throw std::invalid_argument(std::string("ibl::") + fn + ": " + arg + " must be >= " + std::to_string(lo) +
                                    ", got " + std::to_string(value));
    if (value > V(hi))
        throw std::length_error(arg_message(fn, arg, value) + " exceeds " + bound + " = " + std::to_string(hi));
}

/// Throws std::length_error with the function, the quantity and its value when value > hi.
template <class V, class H> void check_total(const char* fn, const char* what, V value, H hi, const char* bound) {
    if (value > V(hi))
        throw std::length_error(arg_message(fn, what, value) + " exceeds " + bound + " = " + std::to_string(hi));
}

/// a * b in std::size_t; std::length_error naming fn and what if the product does not fit.
inline std::size_t checked_mul(std::size_t a, std::size_t b, const char* fn, const char* what) {
    if (a != 0 && b > std::numeric_limits<std::size_t>::max() / a)
        throw std::length_error(std::string("ibl::") + fn + ": " + what + " = " + std::to_string(a) + " * " +
                                std::to_string(b) + " overflows std::size_t");
    return a * b;
}

/// Work counter of one call: adds a * b (saturating at 2^64 - 1).
inline std::uint64_t work_add(std::uint64_t acc, std::uint64_t a, std::uint64_t b) noexcept {
    constexpr std::uint64_t top = std::numeric_limits<std::uint64_t>::max();
    if (a != 0 && b > top / a) return top;
    const std::uint64_t p = a * b;
    return p > top - acc ? top : acc + p;
}

} // namespace detail
} // namespace ibl

#endif // IBL_DETAIL_CXX20
