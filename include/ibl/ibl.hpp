#pragma once
// ibl/ibl.hpp — the umbrella header: every layer of the library. Include the layer headers
// (ibl/core.hpp, ibl/brdf.hpp, ibl/sampling.hpp, ibl/env.hpp, ibl/integrate.hpp, ...) or single
// files to pay only for what you use.
#include "batch.hpp"
#include "brdf.hpp"
#include "core.hpp"
#include "core/executor.hpp"
#include "env.hpp"
#include "integrate.hpp"
#include "lookup.hpp"
#include "plan.hpp"
#include "runtime.hpp"
#include "sampling.hpp"
#include "shade.hpp"
#include "sh.hpp"
