#pragma once
// ibl/sampling.hpp — umbrella of the sampling layer: low-discrepancy sequences and the warps
// (sample / pdf / invert triplets) of the disk, the hemisphere, the GGX and Charlie distributions,
// and the lobe concept of the prefilter (GGX, Charlie).

#include "sampling/charlie.hpp"
#include "sampling/ggx.hpp"
#include "sampling/hemisphere.hpp"
#include "sampling/lobe.hpp"
#include "sampling/sequence.hpp"
