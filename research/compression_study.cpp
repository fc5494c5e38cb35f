// research/compression_study.cpp — the tables of docs/ibl-bake.md, "Compressed HDR outputs": the
// prefiltered chain (256^2 source, 6 levels, the default filtered importance sampling, 2 threads)
// of the built-in sky + sun and of tests/data/{courtyard,studio}.exr, encoded to each block format
// at each encoder effort (BC6H: the library's ibl/bake/bc6h.hpp; ASTC HDR: astcenc through the bake
// tool's io/block_codec.hpp), decoded as a GPU decodes it and compared with the float chain:
// RMSLE per level (RMS over texels and channels of ln(1 + x') - ln(1 + x)), encode time of the
// whole chain on 2 threads, and the default BC6H encoder's RMSLE over the exhaustive search's.
//
//   compression_study             every environment, every format and effort (BC6H exhaustive
//                                 takes minutes)
//   compression_study quick       without BC6H exhaustive and ASTC exhaustive
// Regenerate the docs' table: build/dev/research/compression_study > /tmp/compression.md

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <span>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>

#include "io/block_codec.hpp"
#include "io/cube_layout.hpp"
#include "io/image_io.hpp"
#include "io/ktx2.hpp"

namespace {

struct codec {
    const char* name;
    ibl_bake::ktx2_format format;
    ibl_bake::block_quality quality;
    bool slow;
};

double rmsle(const std::vector<float>& a, const std::vector<float>& b) {
    double sq = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double d = std::log1p(double(std::max(b[i], 0.0f))) - std::log1p(double(std::max(a[i], 0.0f)));
        sq += d * d;
    }
    return a.empty() ? 0.0 : std::sqrt(sq / double(a.size()));
}

void study(const std::string& name, const ibl::cubemap<float>& src, bool quick) {
    ibl::prefilter_options opt;
    const ibl::specular_chain chain = ibl::prefilter(src, opt, ibl::thread_executor{2});
    const ibl_bake::cubemap_rgb32f rgb = ibl_bake::cubemap_to_rgb32f(chain);
    const codec codecs[] = {
        {"BC6H fast", ibl_bake::ktx2_format::bc6h, ibl_bake::block_quality::fast, false},
        {"BC6H normal", ibl_bake::ktx2_format::bc6h, ibl_bake::block_quality::normal, false},
        {"BC6H exhaustive", ibl_bake::ktx2_format::bc6h, ibl_bake::block_quality::exhaustive, true},
        {"ASTC 4x4 fast", ibl_bake::ktx2_format::astc4x4, ibl_bake::block_quality::fast, false},
        {"ASTC 4x4 medium", ibl_bake::ktx2_format::astc4x4, ibl_bake::block_quality::normal, false},
        {"ASTC 6x6 medium", ibl_bake::ktx2_format::astc6x6, ibl_bake::block_quality::normal, false},
    };
    std::printf("\n%s (%d^2, %d levels)\n\n| format, effort | encode ms (2 threads) | bits/texel |", name.c_str(), chain.size(0), chain.levels());
    for (int l = 0; l < chain.levels(); ++l) std::printf(" RMSLE l%d |", l);
    std::printf("\n|---|---|---|");
    for (int l = 0; l < chain.levels(); ++l) std::printf("---|");
    std::printf("\n");
    std::vector<double> normal_err, exhaustive_err;
    for (const codec& c : codecs) {
        if (quick && c.slow) continue;
        std::size_t bytes = 0, texels = 0;
        std::vector<double> err;
        double ms = 0.0;
        for (int l = 0; l < chain.levels(); ++l) {
            const int s = chain.size(l);
            std::vector<float> a, b;
            const float* faces[6];
            for (int f = 0; f < 6; ++f) faces[f] = rgb.levels[std::size_t(l)][std::size_t(f)].data();
            const auto t0 = std::chrono::steady_clock::now();
            const std::vector<unsigned char> blocks = ibl_bake::encode_block_level(c.format, faces, s, c.quality, 2);
            ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            const std::size_t fb = ibl_bake::block_image_bytes(c.format, s);
            for (int f = 0; f < 6; ++f) {
                const std::vector<float>& face = rgb.levels[std::size_t(l)][std::size_t(f)];
                const std::vector<float> d = ibl_bake::decode_block_image(c.format, blocks.data() + std::size_t(f) * fb, fb, s);
                a.insert(a.end(), face.begin(), face.end());
                b.insert(b.end(), d.begin(), d.end());
                texels += std::size_t(s) * std::size_t(s);
            }
            bytes += blocks.size();
            err.push_back(rmsle(a, b));
        }
        std::printf("| %s | %.0f | %.2f |", c.name, ms, 8.0 * double(bytes) / double(texels));
        for (double e : err) std::printf(" %.4f |", e);
        std::printf("\n");
        if (c.format == ibl_bake::ktx2_format::bc6h && c.quality == ibl_bake::block_quality::normal) normal_err = err;
        if (c.format == ibl_bake::ktx2_format::bc6h && c.quality == ibl_bake::block_quality::exhaustive) exhaustive_err = err;
    }
    if (!exhaustive_err.empty()) {
        std::printf("\nBC6H normal / exhaustive RMSLE per level:");
        for (std::size_t l = 0; l < normal_err.size(); ++l)
            std::printf(" %.3f", exhaustive_err[l] > 0 ? normal_err[l] / exhaustive_err[l] : 1.0);
        std::printf("\n");
    }
    std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "quick") == 0;
    try {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        study("built-in sky + sun", ibl::bake_cubemap<float>(sky, 256, 4, ibl::thread_executor{2}), quick);
        for (const char* file : {"courtyard.exr", "studio.exr"}) {
            const std::string path = std::string(IBL_RESEARCH_DATA_DIR) + "/" + file;
            try {
                const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(path, {});
                ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
                map.update_borders();
                study(file, ibl::bake_cubemap<float>(map, 256, 2, ibl::thread_executor{2}), quick);
            } catch (const ibl_bake::image_error& ex) {
                std::printf("%s skipped: %s\n", file, ex.what());
            }
        }
    } catch (const std::exception& ex) {
        std::fprintf(stderr, "compression_study: %s\n", ex.what());
        return 1;
    }
    return 0;
}
