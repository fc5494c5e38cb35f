#pragma once
// ibl/ibl.hpp — the umbrella header: every shipping layer of the library, from the bottom up
// (core < brdf, sampling, env < sh, batch < runtime < bake < reference; docs/ARCHITECTURE.md).
// Include a layer header (ibl/core.hpp, ..., ibl/runtime.hpp, ibl/bake.hpp, ibl/reference.hpp) or
// single files to pay only for what you use.
#include "core.hpp"
#include "core/executor.hpp"
#include "brdf.hpp"
#include "sampling.hpp"
#include "env.hpp"
#include "sh.hpp"
#include "batch.hpp"
#include "runtime.hpp"
#include "bake.hpp"
#include "reference.hpp"
