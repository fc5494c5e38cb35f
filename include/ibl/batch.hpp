#pragma once
// ibl/batch.hpp — umbrella of the structure-of-arrays kernels.
#include "batch/dfg_kernel.hpp"
