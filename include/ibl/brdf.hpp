#pragma once
// ibl/brdf.hpp — the BRDF layer: GGX, Blinn-Phong and Charlie (sheen) distributions, Smith masking (Schlick-GGX with
// k policies, height-correlated), Fresnel (Schlick, roughness-aware, F0 from IOR / metallic),
// Lambert, and the BRDF-model concept with the shipped GGX models.
#include "brdf/blinn_phong.hpp"
#include "brdf/charlie.hpp"
#include "brdf/fresnel.hpp"
#include "brdf/ggx.hpp"
#include "brdf/lambert.hpp"
#include "brdf/masking.hpp"
#include "brdf/model.hpp"
