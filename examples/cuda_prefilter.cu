// examples/cuda_prefilter.cu — the prefilter on a CUDA GPU from the library's own headers: the
// host builds the fast filter's taps (ibl::make_ld_table_for + ibl::detail::make_taps, what
// ibl::prefilter builds) and packs the source (ibl::detail::pack_cube); the device runs the C++
// kernel's per-texel arithmetic with the IBL_FUNC functions (cube_texel_direction, make_frame,
// detail::lane_cube_coord), one thread per output texel, one launch per level. The result is
// compared with ibl::prefilter on the host (with the same options: the tap sets alone, without the
// default's peak split, coarse tail and levels by spherical harmonics) and the device time is printed.
//
//   nvcc -std=c++20 --expt-relaxed-constexpr -I include -I /usr/include examples/cuda_prefilter.cu -o cuda_prefilter
//   ./cuda_prefilter [face size, default 256]
//
// The tests compile it (ctest cuda_example_compile, where nvcc is installed); it runs where a GPU is.
#include <ibl/bake/prefilter.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>

#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

struct device_level {
    int n, stride, face_stride, offset;
};

/// Level l of the output: texel (x, y) of face blockIdx.z, as ibl::detail::convolve_lanes computes it.
__global__ void convolve_level(const float4* src, const float4* taps, const device_level* tap_level, int count,
                               float factor, int n, float4* out) {
    const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
    const int face = int(blockIdx.z);
    if (x >= n || y >= n) return;
    const ibl::frame<float> fr = ibl::make_frame(ibl::cube_texel_direction<float>(face, x, y, n));
    float4 total = make_float4(0.f, 0.f, 0.f, 0.f);
    for (int b = 0; b < count; b += int(ibl::detail::tap_block)) {
        float4 block = make_float4(0.f, 0.f, 0.f, 0.f);
        const int e = min(b + int(ibl::detail::tap_block), count);
        for (int i = b; i < e; ++i) {
            const float4 tap = taps[i];
            const device_level lv = tap_level[i];
            const float dx = fr.t.x * tap.x + fr.b.x * tap.y + fr.n.x * tap.z;
            const float dy = fr.t.y * tap.x + fr.b.y * tap.y + fr.n.y * tap.z;
            const float dz = fr.t.z * tap.x + fr.b.z * tap.y + fr.n.z * tap.z;
            int f;
            float s, t;
            ibl::detail::lane_cube_coord(dx, dy, dz, f, s, t);
            const float fx = s * float(lv.n) + 0.5f, fy = t * float(lv.n) + 0.5f;
            const int x0 = min(int(fx), lv.n), y0 = min(int(fy), lv.n);
            const float wx = fx - float(x0), wy = fy - float(y0);
            const int idx = lv.offset + f * lv.face_stride + y0 * lv.stride + x0;
            const float4 p0 = src[idx], p1 = src[idx + 1], q0 = src[idx + lv.stride], q1 = src[idx + lv.stride + 1];
            const float tr = p0.x + wx * (p1.x - p0.x), tg = p0.y + wx * (p1.y - p0.y), tb = p0.z + wx * (p1.z - p0.z);
            const float br = q0.x + wx * (q1.x - q0.x), bg = q0.y + wx * (q1.y - q0.y), bb = q0.z + wx * (q1.z - q0.z);
            block.x += tap.w * (tr + wy * (br - tr));
            block.y += tap.w * (tg + wy * (bg - tg));
            block.z += tap.w * (tb + wy * (bb - tb));
        }
        total.x += block.x, total.y += block.y, total.z += block.z;
    }
    out[(face * n + y) * n + x] = make_float4(total.x * factor, total.y * factor, total.z * factor, 1.f);
}

bool check(cudaError_t e, const char* what) {
    if (e == cudaSuccess) return true;
    std::fprintf(stderr, "cuda_prefilter: %s: %s\n", what, cudaGetErrorString(e));
    return false;
}

} // namespace

int main(int argc, char** argv) {
    const int size = argc > 1 ? std::max(4, std::atoi(argv[1])) : 256;
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        std::printf("cuda_prefilter: no CUDA device; nothing to run\n");
        return 0;
    }
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), size, 2, ibl::thread_executor{});
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    // The kernel below is the tap set alone, on every level: the C++ chain it is compared with is
    // filtered the same way (the default chain adds the peak split, the coarse tail and the rough
    // levels by spherical harmonics, which include/ibl/glsl/ibl_prefilter.glsl runs on a GPU).
    o.sh_rough.enabled = false;
    o.peaks.enabled = false;
    o.coarse_tail = false;
    const ibl::specular_chain chain = ibl::prefilter(src, o, ibl::thread_executor{});
    const ibl::detail::packed_cube packed = ibl::detail::pack_cube(src);
    float4* d_src = nullptr;
    if (!check(cudaMalloc(&d_src, packed.data.size() * sizeof(float)), "cudaMalloc") ||
        !check(cudaMemcpy(d_src, packed.data.data(), packed.data.size() * sizeof(float), cudaMemcpyHostToDevice), "upload"))
        return 1;
    cudaEvent_t t0, t1;
    cudaEventCreate(&t0);
    cudaEventCreate(&t1);
    double worst = 0.0, device_ms = 0.0;
    const std::vector<ibl::prefilter_level> plan = ibl::prefilter_plan(o, size);
    for (std::size_t l = 0; l < plan.size(); ++l) {
        const ibl::prefilter_level& lp = plan[l];
        if (lp.level == 0) continue; // the mirror level is a copy of the source
        ibl::sphere_sample_table<float> table =
            ibl::make_ld_table_for<float>(src, lp.roughness, lp.samples, o.method, o.lod_bias, o.weight);
        table.trilinear = lp.trilinear;
        const ibl::detail::tap_table taps = ibl::detail::make_taps(table, int(packed.levels.size()));
        const int count = int(taps.w.size()), n = chain.size(int(l));
        std::vector<float4> h_taps(static_cast<std::size_t>(count));
        std::vector<device_level> h_levels(static_cast<std::size_t>(count));
        for (int i = 0; i < count; ++i) {
            h_taps[std::size_t(i)] = make_float4(taps.x[std::size_t(i)], taps.y[std::size_t(i)], taps.z[std::size_t(i)], taps.w[std::size_t(i)]);
            const ibl::detail::packed_cube::level& lv = packed.levels[std::size_t(taps.level[std::size_t(i)])];
            h_levels[std::size_t(i)] = {lv.n, lv.stride, lv.face_stride, lv.offset};
        }
        float4 *d_taps = nullptr, *d_out = nullptr;
        device_level* d_levels = nullptr;
        const std::size_t texels = std::size_t(6) * std::size_t(n) * std::size_t(n);
        if (!check(cudaMalloc(&d_taps, h_taps.size() * sizeof(float4)), "cudaMalloc") ||
            !check(cudaMalloc(&d_levels, h_levels.size() * sizeof(device_level)), "cudaMalloc") ||
            !check(cudaMalloc(&d_out, texels * sizeof(float4)), "cudaMalloc"))
            return 1;
        cudaMemcpy(d_taps, h_taps.data(), h_taps.size() * sizeof(float4), cudaMemcpyHostToDevice);
        cudaMemcpy(d_levels, h_levels.data(), h_levels.size() * sizeof(device_level), cudaMemcpyHostToDevice);
        const dim3 block(16, 16, 1), grid(unsigned((n + 15) / 16), unsigned((n + 15) / 16), 6);
        cudaEventRecord(t0);
        convolve_level<<<grid, block>>>(d_src, d_taps, d_levels, count, taps.factor, n, d_out);
        cudaEventRecord(t1);
        if (!check(cudaEventSynchronize(t1), "kernel")) return 1;
        float ms = 0.f;
        cudaEventElapsedTime(&ms, t0, t1);
        device_ms += double(ms);
        std::vector<float4> out(texels);
        cudaMemcpy(out.data(), d_out, texels * sizeof(float4), cudaMemcpyDeviceToHost);
        double level_worst = 0.0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const ibl::vec3<float> want = chain.texel(f, x, y, int(l));
                    const float4 got = out[ibl::cube_texel_index(f, x, y, n)];
                    const float g[3] = {got.x, got.y, got.z};
                    for (int c = 0; c < 3; ++c)
                        level_worst = std::max(level_worst, std::fabs(double(g[c]) - double(want[c])) / std::max(1e-30, std::fabs(double(want[c]))));
                }
        std::printf("level %zu: %d^2 x 6, %d taps, %.3f ms on the device, worst relative difference from ibl::prefilter %.3g\n", l,
                    n, count, double(ms), level_worst);
        worst = std::max(worst, level_worst);
        cudaFree(d_taps);
        cudaFree(d_levels);
        cudaFree(d_out);
    }
    cudaFree(d_src);
    std::printf("the chain's convolved levels: %.3f ms on the device; worst relative difference %.3g (half-float rounding: 4.9e-4)\n",
                device_ms, worst);
    return worst <= 0x1p-11 ? 0 : 1;
}
