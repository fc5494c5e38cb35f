#pragma once
// ibl/batch.hpp — umbrella of the structure-of-arrays kernels (the DFG lanes and the cubemap
// spherical-convolution lanes). batch/ depends only on core/, brdf/, sampling/ and env/, never on
// bake/: the bakers build the tables and call these kernels.
#include "batch/dfg_kernel.hpp"
#include "batch/sphere_kernel.hpp"
