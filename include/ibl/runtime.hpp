#pragma once
// ibl/runtime.hpp — the runtime layer: what a renderer evaluates per pixel from the baked products
// (shading, the chain and table lookups, the runtime specular models, specular occlusion, the
// roughness <-> mip policies, the LD weight, local probes (parallax correction, influence
// blending) and the table structs). Mirrored by glsl/. It includes
// no baker and no reference (tests/header_deps.cmake).
#include "runtime/chain.hpp"
#include "runtime/dfg_fit.hpp"
#include "runtime/dfg_layout.hpp"
#include "runtime/ld_weight.hpp"
#include "runtime/local_probe.hpp"
#include "runtime/lookup.hpp"
#include "runtime/roughness_mip.hpp"
#include "runtime/shade.hpp"
#include "runtime/specular_models.hpp"
#include "runtime/specular_occlusion.hpp"
#include "runtime/tables.hpp"
