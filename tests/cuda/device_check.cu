// Compile-only check (no GPU needed): the library's headers compile as CUDA device code, and a
// __global__ kernel can call the core, sampling, BRDF, environment-geometry and shading functions.
#include <ibl/ibl.hpp>

__global__ void ibl_device_check(float* out, const float* in, int n) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const float x = in[i];
    // core
    float acc = ibl::saturate(x) + ibl::safe_sqrt(x) + ibl::sqr(x) + ibl::pow5(x) + ibl::sin_from_cos(x);
    const ibl::frame<float> f = ibl::make_frame(glm::normalize(ibl::vec3<float>(x, 1.0f, 0.5f)));
    acc += f.to_world(ibl::vec3<float>(0.0f, 0.0f, 1.0f)).y;
    ibl::neumaier_sum<float> s;
    s.add(acc);
    // sampling
    const ibl::vec2<float> u = ibl::hammersley<float>(unsigned(i), unsigned(n));
    const ibl::vec3<float> h = ibl::sample_ggx_ndf(u, 0.25f);
    const ibl::vec3<float> v(ibl::sin_from_cos(x), 0.0f, x);
    const ibl::vec3<float> hv = ibl::sample_ggx_vndf(v, u, 0.25f);
    s.add(h.z + hv.z + ibl::ggx_vndf_pdf(v, hv, 0.25f) + ibl::sample_cosine_hemisphere(u).z);
    s.add(ibl::invert_ggx_ndf(h, 0.25f).x + ibl::radical_inverse<float>(unsigned(i)));
    // brdf
    const float vh = glm::dot(v, h);
    const ibl::vec3<float> l = 2.0f * vh * h - v;
    s.add(ibl::ndf_ggx(h.z, 0.25f) + ibl::g_smith_schlick_ggx(x, l.z, ibl::k_ibl(0.5f)) +
          ibl::v_smith_ggx_correlated(x, l.z, 0.25f));
    s.add(ibl::ggx_height_correlated::sample_weight(x, l.z, h.z, vh, 0.5f) +
          ibl::ggx_schlick_ibl::sample_weight(x, l.z, h.z, vh, 0.5f));
    const ibl::vec3<float> fr = ibl::fresnel_schlick_roughness(x, ibl::vec3<float>(0.04f), 0.3f) +
                                ibl::fresnel_schlick(x, ibl::vec3<float>(0.04f), ibl::vec3<float>(1.0f));
    s.add(fr.x + ibl::lambert(0.8f) + ibl::f0_from_ior(1.5f));
    // env geometry, split-sum limit, shading
    s.add(ibl::cube_texel_solid_angle<float>(i % 8, i % 5, 8) + ibl::cube_lookup(f.n).s);
    const ibl::vec2<float> dfg = ibl::dfg_smooth_limit(x);
    const ibl::vec3<float> spec = ibl::specular_ibl(ibl::vec3<float>(1.0f), ibl::vec3<float>(0.04f), dfg);
    s.add(spec.y);
    out[i] = s.value();
}
