#pragma once
// ibl/sh.hpp — spherical harmonics: real basis (B <= 5 bands), projection from cube faces,
// lat-long images and functions, Lambert convolution and reconstruction, the irradiance quadratic
// form, shader constants, windowing, rotation and probe interpolation.
// Depends only on core/ and env/cube_geometry.hpp.
#include "sh/basis.hpp"
#include "sh/convolve.hpp"
#include "sh/probe.hpp"
#include "sh/project.hpp"
#include "sh/rotate.hpp"
#include "sh/window.hpp"
