#pragma once
// ibl/sampling.hpp — umbrella of the sampling layer: low-discrepancy sequences and the warps
// (sample / pdf / invert triplets) of the disk, the hemisphere and the GGX distributions.

#include "sampling/ggx.hpp"
#include "sampling/hemisphere.hpp"
#include "sampling/sequence.hpp"
