#pragma once
// ibl/env/detail/resample.hpp — exact box overlap of two regular grids on [0, 1], used by the
// mip generators of cubemap and latlong (host only).
//
// A fine grid of n cells and a coarse grid of m cells on [0, 1] cut [0, 1] into the pieces
// between the union of their boundaries i/n and j/m. Every piece lies in exactly one fine cell
// and one coarse cell. Boundaries are compared as integers (i m versus j n), so the partition is
// exact for any n, m (power of two or not); positions are given as doubles (exact when n m is a
// power of two, else correctly rounded).

#include "../../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ibl::detail {

struct grid_piece {
    int fine;      ///< index of the fine cell holding the piece
    int coarse;    ///< index of the coarse cell holding the piece
    double lo, hi; ///< piece extent in [0, 1]
};

/// Pieces of [0, 1] cut by the boundaries of an n-cell and an m-cell grid, in increasing order.
/// Pieces of one coarse cell are contiguous.
inline std::vector<grid_piece> grid_overlap(int n, int m) {
    const long long nn = n, mm = m, den = nn * mm;
    std::vector<long long> cuts;
    cuts.reserve(std::size_t(n + m + 2));
    for (long long i = 0; i <= nn; ++i) cuts.push_back(i * mm);
    for (long long j = 0; j <= mm; ++j) cuts.push_back(j * nn);
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    std::vector<grid_piece> pieces;
    pieces.reserve(cuts.size() - 1);
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        const long long p = cuts[k], q = cuts[k + 1];
        pieces.push_back({int(p / mm), int(p / nn), double(p) / double(den), double(q) / double(den)});
    }
    return pieces;
}

/// [first, last) ranges of the pieces of each coarse cell (pieces are sorted by coarse index).
inline std::vector<std::pair<int, int>> coarse_ranges(const std::vector<grid_piece>& pieces, int m) {
    std::vector<std::pair<int, int>> r(std::size_t(m), {0, 0});
    for (std::size_t k = 0; k < pieces.size(); ++k) {
        auto& e = r[std::size_t(pieces[k].coarse)];
        if (e.first == e.second) e.first = int(k);
        e.second = int(k) + 1;
    }
    return r;
}

/// Number of levels of a full chain halving (floor) a size down to 1: floor(log2(size)) + 1.
inline int full_chain_levels(int size) {
    int levels = 1;
    while ((size >> levels) > 0) ++levels;
    return levels;
}

} // namespace ibl::detail

#endif // IBL_DETAIL_CXX20
