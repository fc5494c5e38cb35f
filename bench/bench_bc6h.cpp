// bake/bc6h: BC6H_UFLOAT encoding of a cubemap chain (6 faces x every level, each face level one
// bc6h_encode_image call) at the three quality levels, and decoding it back, on
//   env 0: the default sky with its 1-degree sun (3e4), baked to 256^2 (k = 2) with its full mip
//          chain: smooth gradients, a horizon step and the sun (the content of a sky probe);
//   env 1: the same sky textured by value noise (x 0.3 .. 1.7 over a few texels) with 24 small
//          bright spots of 50 .. 5000: the texture and point lights of a captured probe.
// Arguments: env, quality (0 fast, 1 normal, 2 exhaustive), face size of level 0 (256: 32.8k
// blocks, fast and normal; 32: 522 blocks, all three levels on the same content). Counters: rmsle (RMS of ln(1 + x) differences
// of the decoded chain against the input, every channel of every texel), blocks (per chain) and
// the rate of blocks per second. Timing uses thread_executor{2} (the 2-core target machine).
#include <benchmark/benchmark.h>

#include <ibl/bake/bc6h.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace {

/// One face level as the encoder reads it: n x n texels of RGB.
struct face_image {
    int n = 0;
    std::vector<float> rgb;
};

/// Value noise in [0, 1] on a lattice of spacing 1 / freq in 3D (trilinear between hashed nodes).
float value_noise(const ibl::vec3<float>& d, float freq) {
    auto hash = [](int x, int y, int z) {
        std::uint32_t h =
            std::uint32_t(x) * 0x8da6b343u ^ std::uint32_t(y) * 0xd8163841u ^ std::uint32_t(z) * 0xcb1ab31fu;
        h ^= h >> 13;
        h *= 0x5bd1e995u;
        h ^= h >> 15;
        return float(h & 0xFFFFu) / 65535.f;
    };
    const float px = d.x * freq, py = d.y * freq, pz = d.z * freq;
    const int x0 = int(std::floor(px)), y0 = int(std::floor(py)), z0 = int(std::floor(pz));
    const float fx = px - float(x0), fy = py - float(y0), fz = pz - float(z0);
    float v = 0.f;
    for (int k = 0; k < 8; ++k) {
        const int dx = k & 1, dy = (k >> 1) & 1, dz = k >> 2;
        v += hash(x0 + dx, y0 + dy, z0 + dz) * (dx ? fx : 1.f - fx) * (dy ? fy : 1.f - fy) * (dz ? fz : 1.f - fz);
    }
    return v;
}

ibl::cubemap<float> bake(int env, int n) {
    const ibl::sky_environment<float> sky = ibl::make_default_sky<float>();
    if (env == 0) return ibl::bake_cubemap<float>(sky, n, 2, ibl::thread_executor{2});
    std::array<std::pair<ibl::vec3<float>, float>, 24> spots{};
    for (int i = 0; i < 24; ++i) { // directions on a golden-angle spiral, radiance 50 .. 5000
        const float z = 1.f - (2.f * float(i) + 1.f) / 24.f, r = std::sqrt(1.f - z * z), phi = 2.39996f * float(i);
        spots[std::size_t(i)] = {ibl::vec3<float>(r * std::cos(phi), z, r * std::sin(phi)),
                                 50.f * std::pow(100.f, float(i % 7) / 6.f)};
    }
    const auto textured = ibl::make_lambda_environment<float>([sky, spots](const ibl::vec3<float>& d) {
        ibl::vec3<float> l = sky.radiance(d) * (0.3f + 1.4f * value_noise(d, 40.f));
        for (const auto& s : spots)
            if (glm::dot(d, s.first) > 0.99995f) l += ibl::vec3<float>(s.second);
        return l;
    });
    return ibl::bake_cubemap<float>(textured, n, 2, ibl::thread_executor{2});
}

/// The chain of env at face size n: face levels in (level, face) order, computed once.
const std::vector<face_image>& chain(int env, int n) {
    static std::map<std::pair<int, int>, std::vector<face_image>> cache;
    auto it = cache.find({env, n});
    if (it != cache.end()) return it->second;
    const ibl::cubemap<float> cube = bake(env, n);
    std::vector<face_image> faces;
    for (int l = 0; l < cube.levels(); ++l)
        for (int f = 0; f < 6; ++f) {
            face_image img;
            img.n = cube.size(l);
            img.rgb.resize(std::size_t(img.n) * std::size_t(img.n) * 3);
            for (int y = 0; y < img.n; ++y)
                for (int x = 0; x < img.n; ++x) {
                    const ibl::vec3<float>& v = cube.texel(f, x, y, l);
                    float* dst = img.rgb.data() + (std::size_t(y) * std::size_t(img.n) + std::size_t(x)) * 3;
                    dst[0] = v.x, dst[1] = v.y, dst[2] = v.z;
                }
            faces.push_back(std::move(img));
        }
    return cache.emplace(std::make_pair(env, n), std::move(faces)).first->second;
}

std::size_t chain_blocks(const std::vector<face_image>& faces) {
    std::size_t blocks = 0;
    for (const face_image& f : faces) blocks += std::size_t((f.n + 3) / 4) * std::size_t((f.n + 3) / 4);
    return blocks;
}

/// RMSLE of the decoded chain against its input.
double chain_rmsle(const std::vector<face_image>& faces, const std::vector<std::vector<unsigned char>>& coded) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < faces.size(); ++i) {
        const std::vector<float> dec = ibl::bc6h_decode_image(coded[i].data(), faces[i].n, faces[i].n);
        const double r = ibl::bc6h_rmsle(faces[i].rgb.data(), dec.data(), dec.size());
        sum += r * r * double(dec.size());
        count += dec.size();
    }
    return std::sqrt(sum / double(count));
}

/// args: env, quality, face size.
void BM_bc6h_encode_chain(benchmark::State& state) {
    const int env = int(state.range(0)), n = int(state.range(2));
    const auto quality = static_cast<ibl::bc6h_quality>(state.range(1));
    const std::vector<face_image>& faces = chain(env, n);
    std::vector<std::vector<unsigned char>> coded(faces.size());
    for (auto _ : state) {
        for (std::size_t i = 0; i < faces.size(); ++i)
            coded[i] =
                ibl::bc6h_encode_image(faces[i].rgb.data(), faces[i].n, faces[i].n, quality, ibl::thread_executor{2});
        benchmark::DoNotOptimize(coded.back().data());
    }
    const std::size_t blocks = chain_blocks(faces);
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(blocks));
    state.counters["blocks"] = double(blocks);
    state.counters["blocks_per_s"] = benchmark::Counter(double(blocks), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["rmsle"] = chain_rmsle(faces, coded);
}

/// args: env, face size. Decoding (one thread) of the chain encoded at normal quality.
void BM_bc6h_decode_chain(benchmark::State& state) {
    const int env = int(state.range(0)), n = int(state.range(1));
    const std::vector<face_image>& faces = chain(env, n);
    std::vector<std::vector<unsigned char>> coded(faces.size());
    for (std::size_t i = 0; i < faces.size(); ++i)
        coded[i] = ibl::bc6h_encode_image(faces[i].rgb.data(), faces[i].n, faces[i].n, ibl::bc6h_quality::normal,
                                          ibl::thread_executor{2});
    std::vector<float> out;
    for (auto _ : state) {
        for (std::size_t i = 0; i < faces.size(); ++i) {
            out = ibl::bc6h_decode_image(coded[i].data(), faces[i].n, faces[i].n);
            benchmark::DoNotOptimize(out.data());
        }
    }
    const std::size_t blocks = chain_blocks(faces);
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(blocks));
    state.counters["blocks_per_s"] = benchmark::Counter(double(blocks), benchmark::Counter::kIsIterationInvariantRate);
}

} // namespace

BENCHMARK(BM_bc6h_encode_chain)
    ->ArgNames({"env", "quality", "n"})
    ->ArgsProduct({{0, 1}, {0, 1}, {256}})
    ->ArgsProduct({{0, 1}, {0, 1, 2}, {32}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_bc6h_decode_chain)
    ->ArgNames({"env", "n"})
    ->Args({0, 256})
    ->Args({1, 256})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
