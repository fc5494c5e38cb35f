#pragma once
// ibl/core.hpp — the core layer: configuration, constants, safe math, frames, summation, colour.
#include "core/color.hpp"
#include "core/config.hpp"
#include "core/constants.hpp"
#include "core/frame.hpp"
#include "core/gauss_legendre.hpp"
#include "core/limits.hpp"
#include "core/math.hpp"
#include "core/sum.hpp"
#include "core/vec.hpp"
