#pragma once
// ibl/ibl.hpp — the umbrella header: every layer of the library. Include the layer headers
// (ibl/core.hpp, ibl/brdf.hpp, ibl/sampling.hpp, ...) or single files to pay only for what you use.
#include "brdf.hpp"
#include "core.hpp"
#include "core/executor.hpp"
#include "env/cube_geometry.hpp"
#include "sampling.hpp"
