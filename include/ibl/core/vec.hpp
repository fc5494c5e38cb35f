#pragma once
// ibl/core/vec.hpp — GLM vector aliases used at the scalar API. Only the GLM headers that the
// library needs are included (vector types and geometric functions), not <glm/glm.hpp>.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace ibl {
template <class T> using vec2 = glm::vec<2, T, glm::defaultp>;
template <class T> using vec3 = glm::vec<3, T, glm::defaultp>;
template <class T> using vec4 = glm::vec<4, T, glm::defaultp>;
} // namespace ibl

#endif // IBL_DETAIL_CXX20
