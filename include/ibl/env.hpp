#pragma once
// ibl/env.hpp — the environment layer: the environment concept, cube geometry, cubemap<T>,
// latlong<T>, analytic environments (constant, sky + sun, lambda adapter) and conversions.
#include "env/analytic.hpp"
#include "env/convert.hpp"
#include "env/cube_geometry.hpp"
#include "env/cubemap.hpp"
#include "env/environment.hpp"
#include "env/latlong.hpp"
#include "env/sun_extract.hpp"
