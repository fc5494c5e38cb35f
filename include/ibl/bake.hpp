#pragma once
// ibl/bake.hpp — the bake layer: the producers of the products a renderer reads (prefiltered chain,
// irradiance, DFG / sheen / lobe / occlusion tables) and the scene-driven bake plan. It includes the
// runtime layer (the structs and conventions it produces), never a reference (tests/header_deps.cmake).
#include "bake/bc6h.hpp" // BC6H_UFLOAT block compression of the HDR products (decoder and encoder)
#include "bake/dfg.hpp"
#include "bake/dfg_export.hpp"
#include "bake/dfg_lut.hpp"
#include "bake/dfg_multiscatter.hpp"
#include "bake/irradiance.hpp"
#include "bake/lobe_fit.hpp"
#include "bake/lobe_moments.hpp"
#include "bake/plan.hpp"
#include "bake/prefilter.hpp"
#include "bake/prefilter_fast.hpp"
#include "bake/prefilter_peaks.hpp" // the fast filter's peak split
#include "bake/prefilter_update.hpp"
#include "bake/sheen.hpp"
#include "bake/specular_occlusion_lut.hpp"
#include "bake/sphere_convolve.hpp"
