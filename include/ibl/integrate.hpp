#pragma once
// ibl/integrate.hpp — umbrella of the integrators.
#include "integrate/dfg.hpp"
#include "integrate/dfg_export.hpp"
#include "integrate/dfg_fit.hpp"
#include "integrate/dfg_lut.hpp"
#include "integrate/dfg_multiscatter.hpp"
#include "integrate/env_importance.hpp"
#include "integrate/gauss_legendre.hpp"
#include "integrate/radiance_reference.hpp"
