#pragma once
// ibl/reference.hpp — the reference layer: converged references and error metrics that tests,
// benchmarks and ibl-bake's checks measure the products and the runtime lookups against (slow by
// design, double precision).
#include "reference/analytic_room.hpp"
#include "reference/disk_light.hpp"
#include "reference/env_importance.hpp"
#include "reference/ld_irradiance.hpp"
#include "reference/lookup_error.hpp"
#include "reference/metrics.hpp"
#include "reference/occluded_specular.hpp"
#include "reference/radiance.hpp"
