#pragma once
// ibl/runtime/chain.hpp — a prefiltered specular chain that records its conventions.
//
// prefilter() returns a specular_chain: the cubemap of the levels plus the LD weight its levels
// were filtered with and the roughness <-> lod mapping of its levels. It is a cubemap<float>, so
// every function that takes a cubemap takes it; the lookups that read a chain (runtime/lookup.hpp,
// runtime/specular_models.hpp) take the chain as a template parameter and, given a specular_chain,
//   * read the mapping from the chain (the lookup description's mapping is the chain's: a chain
//     cannot be read at the lods of another mapping), and
//   * refuse a lobe table fitted to another weight (std::invalid_argument naming both): the lobe
//     LUT and the fitted taps are fitted to the kernel of one weight.
// A plain cubemap<float> (a chain loaded from a file) carries no conventions: the caller's
// description is used as given (the files record theirs: ibl-bake's ibl.ld_weight, ibl.policy).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <utility>

#include "../env/cubemap.hpp"
#include "ld_weight.hpp"
#include "roughness_mip.hpp"

namespace ibl {

struct specular_chain : cubemap<float> {
    ld_weight weight = ld_weight::n_dot_l;                 ///< the LD weight of every level >= 1
    roughness_mapping mapping = roughness_mapping::linear; ///< roughness <-> lod of the levels

    specular_chain(cubemap<float> levels, ld_weight w, roughness_mapping m)
        : cubemap<float>(std::move(levels)), weight(w), mapping(m) {}
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
