#pragma once
// ibl/sampling/sequence.hpp — the base-2 radical inverse (van der Corput sequence), the
// Hammersley point set, and their Owen-scrambled / XOR-scrambled variants.
//
//   radical_inverse(i) = sum_k b_k 2^-(k+1)   for i = sum_k b_k 2^k   (bits of i mirrored about
//                        the binary point) — J. G. van der Corput 1935; J. M. Hammersley 1960.
//   hammersley(i, n)   = (i / n, radical_inverse(i)), i in [0, n): for n = 2^m the set is a
//                        (0, m, 2)-net in base 2 (H. Niederreiter, "Random Number Generation and
//                        Quasi-Monte Carlo Methods", SIAM 1992, ch. 4): every dyadic box of area
//                        2^-m holds exactly one point.
//
// Every result lies in [0, 1) and is exactly representable: k / 2^32 for double; for float the
// 32-bit fraction is truncated to its top 24 bits (k / 2^24), so it never rounds up to 1.
// Integer arithmetic only (no intrinsics): the same code runs in CUDA device code.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstdint>

#include "../core/constants.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// Bit reversal of a 32-bit word by five branch-free swaps of halves, quarters, ... single bits
/// (the classic divide-and-conquer permutation; H. S. Warren, "Hacker's Delight", 2nd ed., 7-1).
IBL_FUNC constexpr std::uint32_t reverse_bits(std::uint32_t x) noexcept {
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00FF00FFu) << 8) | ((x & 0xFF00FF00u) >> 8);
    x = ((x & 0x0F0F0F0Fu) << 4) | ((x & 0xF0F0F0F0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xCCCCCCCCu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xAAAAAAAAu) >> 1);
    return x;
}

namespace detail {
/// A 32-bit binary fraction bits / 2^32 as T, exactly, in [0, 1). float keeps the top 24 bits
/// (truncation: round-to-nearest would map 0xFFFFFF80.. to 1.0f).
template <class T> IBL_FUNC constexpr T fraction_from_bits(std::uint32_t bits) noexcept {
    return T(bits) * T(0x1p-32);
}
template <> IBL_FUNC constexpr float fraction_from_bits<float>(std::uint32_t bits) noexcept {
    return float(bits >> 8) * 0x1p-24f;
}
} // namespace detail

/// Base-2 radical inverse of i. Domain: any i. Range: [0, 1), exactly k / 2^32 (double) or the
/// same truncated to k / 2^24 (float). radical_inverse(1) = 0.5, (2) = 0.25, (3) = 0.75.
template <class T = float> IBL_FUNC constexpr T radical_inverse(std::uint32_t i) noexcept {
    return detail::fraction_from_bits<T>(reverse_bits(i));
}

/// Radical inverse with random-digit scrambling: the digits are XOR-ed with those of
/// `scramble` (A. Kollig, A. Keller, "Efficient Multidimensional Sampling", EG 2002). The
/// scrambled set of the first 2^m indices is still a (0, m, 1)-net (a permutation of the
/// k / 2^m grid). Range [0, 1) as radical_inverse.
template <class T = float>
IBL_FUNC constexpr T radical_inverse_xor(std::uint32_t i, std::uint32_t scramble) noexcept {
    return detail::fraction_from_bits<T>(reverse_bits(i) ^ scramble);
}

/// Laine-Karras style hash used as a nested-uniform (Owen) permutation of the base-2 digits of
/// the index: output bit k depends only on input bits 0..k (additions carry upward, products
/// with even constants only shift bits upward). Constants of B. Burley, "Practical Hash-based
/// Owen Scrambling", JCGT 9(4), 2020, listing 3.
IBL_FUNC constexpr std::uint32_t owen_hash_permutation(std::uint32_t x, std::uint32_t seed) noexcept {
    x += seed;
    x ^= x * 0x6C50B47Cu;
    x ^= x * 0xB82F1E52u;
    x ^= x * 0xC7AFE638u;
    x ^= x * 0x8D22F6E6u;
    return x;
}

/// Owen-scrambled base-2 radical inverse (Burley 2020): the digit permutation of the radical
/// inverse's j-th digit depends on digits 1..j-1 and on the seed. For the first 2^m indices the
/// output is again one point in each interval [k/2^m, (k+1)/2^m). Range [0, 1).
template <class T = float>
IBL_FUNC constexpr T radical_inverse_owen(std::uint32_t i, std::uint32_t seed) noexcept {
    return detail::fraction_from_bits<T>(reverse_bits(owen_hash_permutation(i, seed)));
}

namespace detail {
/// i / n as T for i < n, kept strictly below 1 (in float, (n - 1) / n rounds to 1 once n > 2^24).
template <class T> IBL_FUNC constexpr T index_fraction(std::uint32_t i, std::uint32_t n) noexcept {
    const T x = T(double(i) / double(n));
    return x < T(1) ? x : one_minus_epsilon_v<T>;
}
} // namespace detail

/// Point i of the n-point Hammersley set: (i / n, radical_inverse(i)). Domain: 0 <= i < n.
/// Range: [0, 1)^2. For n = 2^m: a (0, m, 2)-net in base 2 (exact in double; in float for
/// n <= 2^24, beyond which i / n is not representable).
template <class T = float> IBL_FUNC constexpr vec2<T> hammersley(std::uint32_t i, std::uint32_t n) noexcept {
    return vec2<T>(detail::index_fraction<T>(i, n), radical_inverse<T>(i));
}

/// Owen-scrambled Hammersley point (second coordinate scrambled with radical_inverse_owen; the
/// first, i / n, is left as is). Nested scrambling of one coordinate keeps the (0, m, 2)-net
/// property for n = 2^m. Range [0, 1)^2.
template <class T = float>
IBL_FUNC constexpr vec2<T> hammersley_owen(std::uint32_t i, std::uint32_t n, std::uint32_t seed) noexcept {
    return vec2<T>(detail::index_fraction<T>(i, n), radical_inverse_owen<T>(i, seed));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
