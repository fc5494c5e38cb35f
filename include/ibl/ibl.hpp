#pragma once
// ibl/ibl.hpp — the umbrella header: every layer of the library. Include the layer headers
// (ibl/core.hpp, ibl/sampling.hpp, ibl/brdf.hpp, ...) or single files to pay only for what you use.
#include "brdf/ggx.hpp"
#include "core.hpp"
#include "env/cube_geometry.hpp"
