// tools/ibl-bake/io/block_codec.cpp — BC6H through the library's codec, ASTC HDR through astcenc
// (policy and quality levels: block_codec.hpp).

#include "io/block_codec.hpp"

#include <astcenc.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>

#include <ibl/bake/bc6h.hpp>
#include <ibl/core/executor.hpp>

#include "io/image_io.hpp"

namespace ibl_bake {

int ktx2_block_dim(ktx2_format f) noexcept {
    switch (f) {
    case ktx2_format::bc6h:
    case ktx2_format::astc4x4: return 4;
    case ktx2_format::astc6x6: return 6;
    default: return 1;
    }
}

bool ktx2_block_compressed(ktx2_format f) noexcept { return ktx2_block_dim(f) > 1; }

std::size_t block_image_bytes(ktx2_format f, int s) noexcept {
    const std::size_t b = std::size_t(ktx2_block_dim(f));
    const std::size_t n = (std::size_t(s) + b - 1) / b;
    return n * n * 16;
}

namespace {

ibl::bc6h_quality bc6h_quality_of(block_quality q) {
    switch (q) {
    case block_quality::fast: return ibl::bc6h_quality::fast;
    case block_quality::exhaustive: return ibl::bc6h_quality::exhaustive;
    default: return ibl::bc6h_quality::normal;
    }
}

float astc_preset(block_quality q) {
    switch (q) {
    case block_quality::fast: return ASTCENC_PRE_FAST;
    case block_quality::exhaustive: return ASTCENC_PRE_EXHAUSTIVE;
    default: return ASTCENC_PRE_MEDIUM;
    }
}

/// The input policy of block_codec.hpp on one value.
float clamp_half_range(float x) noexcept {
    if (!(x > 0.0f)) return 0.0f; // NaN, negatives, zero
    return std::min(x, 65504.0f);
}

/// An astcenc context: allocated once per (block size, effort, threads, decoder or encoder) and
/// reused (allocation builds the encoder's tables); one image at a time (its mutex).
struct astc_context {
    astcenc_context* ctx = nullptr;
    unsigned threads = 1;
    std::mutex busy;
    ~astc_context() {
        if (ctx) astcenc_context_free(ctx);
    }
};

astc_context& astc_context_for(int dim, block_quality q, unsigned threads, bool decode_only) {
    static std::mutex m;
    static std::map<std::tuple<int, int, unsigned, bool>, std::unique_ptr<astc_context>> cache;
    const std::lock_guard<std::mutex> lock(m);
    auto& slot = cache[{dim, int(q), threads, decode_only}];
    if (!slot) {
        astcenc_config cfg{};
        astcenc_error e = astcenc_config_init(ASTCENC_PRF_HDR_RGB_LDR_A, unsigned(dim), unsigned(dim), 1, astc_preset(q),
                                              decode_only ? ASTCENC_FLG_DECOMPRESS_ONLY : 0u, &cfg);
        if (e != ASTCENC_SUCCESS) throw image_error("<astc>", std::string("astcenc configuration failed: ") + astcenc_get_error_string(e));
        auto c = std::make_unique<astc_context>();
        c->threads = threads;
        e = astcenc_context_alloc(&cfg, threads, &c->ctx);
        if (e != ASTCENC_SUCCESS) throw image_error("<astc>", std::string("astcenc context failed: ") + astcenc_get_error_string(e));
        slot = std::move(c);
    }
    return *slot;
}

constexpr astcenc_swizzle rgb1{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_1};

std::vector<unsigned char> astc_encode(int dim, const float* rgb, int s, block_quality q, unsigned threads) {
    std::vector<float> rgba(std::size_t(s) * std::size_t(s) * 4);
    for (std::size_t t = 0; t < std::size_t(s) * std::size_t(s); ++t) {
        for (std::size_t c = 0; c < 3; ++c) rgba[4 * t + c] = clamp_half_range(rgb[3 * t + c]);
        rgba[4 * t + 3] = 1.0f;
    }
    const std::size_t blocks = (std::size_t(s) + std::size_t(dim) - 1) / std::size_t(dim);
    // Small images on one thread: a thread start costs more than their blocks.
    const unsigned use = blocks * blocks < 64 ? 1u : threads;
    astc_context& ac = astc_context_for(dim, q, use, false);
    std::vector<unsigned char> out(blocks * blocks * 16);
    void* slice = rgba.data();
    astcenc_image img{unsigned(s), unsigned(s), 1, ASTCENC_TYPE_F32, &slice};
    const std::lock_guard<std::mutex> lock(ac.busy);
    std::vector<astcenc_error> err(use, ASTCENC_SUCCESS);
    const auto work = [&](unsigned i) { err[i] = astcenc_compress_image(ac.ctx, &img, &rgb1, out.data(), out.size(), i); };
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < use; ++i) pool.emplace_back(work, i);
    work(0);
    for (auto& t : pool) t.join();
    astcenc_compress_reset(ac.ctx);
    for (astcenc_error e : err)
        if (e != ASTCENC_SUCCESS) throw image_error("<astc>", std::string("astcenc compression failed: ") + astcenc_get_error_string(e));
    return out;
}

std::vector<float> astc_decode(int dim, const unsigned char* blocks, std::size_t bytes, int s) {
    astc_context& ac = astc_context_for(dim, block_quality::normal, 1, true);
    std::vector<std::uint16_t> rgba(std::size_t(s) * std::size_t(s) * 4);
    void* slice = rgba.data();
    astcenc_image img{unsigned(s), unsigned(s), 1, ASTCENC_TYPE_F16, &slice};
    {
        const std::lock_guard<std::mutex> lock(ac.busy);
        const astcenc_error e = astcenc_decompress_image(ac.ctx, blocks, bytes, &img, &rgb1, 0);
        astcenc_decompress_reset(ac.ctx);
        if (e != ASTCENC_SUCCESS) throw image_error("<astc>", std::string("astcenc decompression failed: ") + astcenc_get_error_string(e));
    }
    std::vector<float> out(std::size_t(s) * std::size_t(s) * 3);
    for (std::size_t t = 0; t < std::size_t(s) * std::size_t(s); ++t)
        for (std::size_t c = 0; c < 3; ++c) out[3 * t + c] = half_to_float(rgba[4 * t + c]);
    return out;
}

} // namespace

std::vector<unsigned char> encode_block_image(ktx2_format format, const float* rgb, int s, block_quality quality, unsigned threads) {
    if (s < 1) throw image_error("<blocks>", "image size must be >= 1");
    if (format == ktx2_format::bc6h)
        return ibl::bc6h_encode_image(rgb, s, s, bc6h_quality_of(quality), ibl::thread_executor{threads});
    if (!ktx2_block_compressed(format)) throw image_error("<blocks>", "not a block-compressed format");
    return astc_encode(ktx2_block_dim(format), rgb, s, quality, threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : threads);
}

std::vector<unsigned char> encode_block_level(ktx2_format format, const float* const faces[6], int s, block_quality quality,
                                              unsigned threads) {
    const int b = ktx2_block_dim(format);
    if (format == ktx2_format::bc6h && s >= b && s % b == 0) {
        const std::size_t face = std::size_t(s) * std::size_t(s) * 3;
        std::vector<float> stacked(6 * face);
        for (std::size_t f = 0; f < 6; ++f) std::copy(faces[f], faces[f] + face, stacked.begin() + std::ptrdiff_t(f * face));
        return ibl::bc6h_encode_image(stacked.data(), s, 6 * s, bc6h_quality_of(quality), ibl::thread_executor{threads});
    }
    std::vector<unsigned char> out;
    out.reserve(6 * block_image_bytes(format, s));
    for (int f = 0; f < 6; ++f) {
        const std::vector<unsigned char> blocks = encode_block_image(format, faces[f], s, quality, threads);
        out.insert(out.end(), blocks.begin(), blocks.end());
    }
    return out;
}

std::vector<float> decode_block_image(ktx2_format format, const unsigned char* blocks, std::size_t bytes, int s) {
    if (s < 1 || bytes != block_image_bytes(format, s))
        throw image_error("<blocks>", "compressed image of " + std::to_string(bytes) + " bytes for a " + std::to_string(s) + "^2 image");
    if (format == ktx2_format::bc6h) return ibl::bc6h_decode_image(blocks, s, s);
    if (!ktx2_block_compressed(format)) throw image_error("<blocks>", "not a block-compressed format");
    return astc_decode(ktx2_block_dim(format), blocks, bytes, s);
}

} // namespace ibl_bake
