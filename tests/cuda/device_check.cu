// Compile-only check (no GPU needed): the library's headers compile as CUDA device code, and a
// __global__ kernel can call the core, sampling and BRDF functions.
#include <ibl/ibl.hpp>

__global__ void ibl_device_check(float* out, const float* in, int n) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const float x = in[i];
    float acc = ibl::saturate(x) + ibl::safe_sqrt(x) + ibl::sqr(x) + ibl::pow5(x) + ibl::sin_from_cos(x);
    const ibl::frame<float> f = ibl::make_frame(glm::normalize(ibl::vec3<float>(x, 1.0f, 0.5f)));
    acc += f.to_world(ibl::vec3<float>(0.0f, 0.0f, 1.0f)).y;
    acc += ibl::ndf_ggx(x, 0.25f) + ibl::g1_smith_ggx(x, 0.25f) + ibl::lambda_ggx(x, 0.25f);
    acc += ibl::cube_texel_solid_angle<float>(i % 8, i % 5, 8) + ibl::cube_lookup(f.n).s;
    ibl::neumaier_sum<float> s;
    s.add(acc);
    s.add(1e-8f);
    out[i] = s.value();
}
