// tests/simd/sh_lanes_avx512.cpp — the spherical-harmonic levels' reconstruction in sixteen lanes
// (bake/prefilter_sh.hpp: sh_f16, one AVX-512 register, which builds for an AVX-512 target take)
// against the same kernel in two chunks of eight lanes (sh_f8), compiled together in this
// translation unit with -mavx512f -mfma: every texel of every row of levels of 1 to 32 bands on
// faces of 1 to 70 texels (a row's tail past a multiple of 16 included), with random coefficients,
// must have the same bits. A plain program, not the doctest suite: it runs only where the CPU has
// AVX-512 (exit 77, skipped, elsewhere), and nothing compiled with these flags is linked into the
// other tests.
#include <ibl/bake/prefilter_sh.hpp>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#if !defined(IBL_DETAIL_SH_F16)
#error "this file is compiled with -mavx512f: prefilter_sh.hpp should take its sixteen-lane path"
#endif

int main() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx512f")) {
        std::printf("skipped: the CPU has no AVX-512F\n");
        return 77;
    }
#endif
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    long texels = 0, differ = 0;
    for (const int bands : {1, 2, 5, 11, 17, 24, 32}) {
        ibl::detail::sh_level lv;
        lv.bands = bands;
        lv.rec = ibl::detail::sh_recurrence(bands);
        lv.coef.resize(ibl::detail::sh_pair_count(bands) * 6);
        for (float& c : lv.coef) c = u(rng);
        for (const int n : {1, 7, 16, 33, 70}) {
            std::vector<float> norm(static_cast<std::size_t>(6 * n * n));
            for (float& v : norm) v = 0.5f + 0.5f * (u(rng) + 1.f);
            std::vector<ibl::vec3<float>> a(static_cast<std::size_t>(n)), b(static_cast<std::size_t>(n));
            for (int face = 0; face < 6; ++face)
                for (int y = 0; y < n; ++y) {
                    const float* nr = norm.data() + ibl::cube_texel_index(face, 0, y, n);
                    for (int x = 0; x < n; x += 16) {
                        ibl::detail::sh_level_lanes<ibl::detail::sh_f16, 16>(lv, face, x, y, n, a.data(), nr);
                        ibl::detail::sh_level_lanes<ibl::detail::sh_f8, 8>(lv, face, x, y, n, b.data(), nr);
                    }
                    for (int x = 0; x < n; ++x, ++texels)
                        differ += std::memcmp(&a[std::size_t(x)], &b[std::size_t(x)], sizeof(ibl::vec3<float>)) != 0 ? 1 : 0;
                }
        }
    }
    std::printf("%ld texels, %ld with other bits in sixteen lanes than in two chunks of eight\n", texels, differ);
    return differ == 0 && texels > 0 ? 0 : 1;
}
