#pragma once
// tests/support/same_bits.hpp — bitwise equality of two cubemap chains, shared by the tests of the
// time-sliced prefilter and of the rough levels by spherical harmonics.

#include <ibl/env/cubemap.hpp>

#include <cstring>

namespace ibl_test {

/// Bitwise equality of every texel of every level, borders included (prefilter_update builds
/// them a face at a time, prefilter all at once), and both chains ready for lookups.
inline bool same_cube_bits(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) {
    if (a.levels() != b.levels() || !a.borders_valid() || !b.borders_valid()) return false;
    for (int l = 0; l < a.levels(); ++l) {
        if (a.size(l) != b.size(l)) return false;
        for (int f = 0; f < 6; ++f)
            for (int y = -1; y <= a.size(l); ++y)
                for (int x = -1; x <= a.size(l); ++x) {
                    const ibl::vec3<float> p = a.texel(f, x, y, l), q = b.texel(f, x, y, l);
                    if (std::memcmp(&p, &q, sizeof p) != 0) return false;
                }
    }
    return true;
}

} // namespace ibl_test
