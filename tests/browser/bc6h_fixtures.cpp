// tests/browser/bc6h_fixtures.cpp — the blocks of run_browser_test.py --mode bc6h and what the
// library's BC6H decoder (ibl/bake/bc6h.hpp, bc6h_decode_block_half) makes of each texel, printed as
// JSON: {"blocks_per_row", "blocks": base64 of the 16-byte blocks, "halves": base64 of 16 x 3
// little-endian u16 per block (texel y*4+x, R G B bit patterns), "groups": [{"name", "first",
// "count"}]}. The browser decodes the same blocks with its own BC6H decoder
// (EXT_texture_compression_bptc) and the driver compares every texel's bits.
//
// The blocks (all deterministic):
//   random    for each of the 18 mode codes (the 2-bit codes 00, 01 and the 5-bit codes 00010 ..
//             11111, the four reserved ones included) 512 blocks whose other bits are random: half
//             of them uniform, half with each byte drawn from {0x00, 0xFF, uniform} so that
//             endpoint fields at their extremes (0, 2^b - 1: the unquantizer's special cases) and
//             delta wrap-arounds occur often; plus the code with all other bits 0 and with all 1.
//   encoded   bc6h_encode_image of HDR content: the default sky (a 1-degree sun ~1e4 times the sky)
//             baked to a 32^2 cube with its mips down to 1x1 (every face of every level one image),
//             scaled by 1 (fast, normal, exhaustive), 4 (the sun above 65504: clamped) and 1e-5
//             (the sky among half subnormals; fast and normal); and a 64 x 64 image of independent
//             log-uniform values in [1e-7, 6e4] per channel (normal).

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <ibl/bake/bc6h.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>

namespace {

struct group {
    std::string name;
    std::size_t first = 0, count = 0;
};

struct fixtures {
    std::vector<unsigned char> blocks;
    std::vector<group> groups;

    void begin(const std::string& name) { groups.push_back({name, blocks.size() / 16, 0}); }
    void add(const unsigned char* b, std::size_t n_blocks) {
        blocks.insert(blocks.end(), b, b + 16 * n_blocks);
        groups.back().count += n_blocks;
    }
};

std::string base64(const unsigned char* p, std::size_t n) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    s.reserve((n + 2) / 3 * 4);
    for (std::size_t i = 0; i < n; i += 3) {
        const unsigned v = unsigned(p[i]) << 16 | (i + 1 < n ? unsigned(p[i + 1]) << 8 : 0u) | (i + 2 < n ? unsigned(p[i + 2]) : 0u);
        s += t[v >> 18 & 63];
        s += t[v >> 12 & 63];
        s += i + 1 < n ? t[v >> 6 & 63] : '=';
        s += i + 2 < n ? t[v & 63] : '=';
    }
    return s;
}

/// Sets the low bits of a block to a mode code: 2 bits for the codes 0 and 1, else 5 bits.
void set_code(unsigned char b[16], unsigned code, int bits) {
    const unsigned mask = (1u << bits) - 1u;
    b[0] = static_cast<unsigned char>((b[0] & ~mask) | (code & mask));
}

void random_blocks(fixtures& fx) {
    std::mt19937_64 rng(0x6263366866697874ull); // fixed: the same blocks every run
    std::uniform_int_distribution<int> byte(0, 255), pick(0, 2);
    struct code {
        unsigned value;
        int bits;
        const char* name;
    };
    const code codes[] = {{0x00, 2, "mode 1 (00)"},       {0x01, 2, "mode 2 (01)"},        {0x02, 5, "mode 3 (00010)"},
                          {0x06, 5, "mode 4 (00110)"},    {0x0a, 5, "mode 5 (01010)"},     {0x0e, 5, "mode 6 (01110)"},
                          {0x12, 5, "mode 7 (10010)"},    {0x16, 5, "mode 8 (10110)"},     {0x1a, 5, "mode 9 (11010)"},
                          {0x1e, 5, "mode 10 (11110)"},   {0x03, 5, "mode 11 (00011)"},    {0x07, 5, "mode 12 (00111)"},
                          {0x0b, 5, "mode 13 (01011)"},   {0x0f, 5, "mode 14 (01111)"},    {0x13, 5, "reserved (10011)"},
                          {0x17, 5, "reserved (10111)"},  {0x1b, 5, "reserved (11011)"},   {0x1f, 5, "reserved (11111)"}};
    for (const code& c : codes) {
        fx.begin(std::string("random, ") + c.name);
        unsigned char b[16];
        for (int fill : {0x00, 0xff}) {
            std::memset(b, fill, 16);
            set_code(b, c.value, c.bits);
            fx.add(b, 1);
        }
        for (int k = 0; k < 512; ++k) {
            for (auto& v : b) {
                const int how = k < 256 ? 2 : pick(rng);
                v = static_cast<unsigned char>(how == 0 ? 0x00 : how == 1 ? 0xff : byte(rng));
            }
            set_code(b, c.value, c.bits);
            fx.add(b, 1);
        }
    }
}

void encode_cube(fixtures& fx, const ibl::cubemap<float>& cube, float scale, ibl::bc6h_quality q, const char* name) {
    fx.begin(name);
    for (int l = 0; l < cube.levels(); ++l) {
        const int n = cube.size(l);
        std::vector<float> rgb(std::size_t(n) * std::size_t(n) * 3);
        for (int f = 0; f < 6; ++f) {
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const ibl::vec3<float> v = cube.texel(f, x, y, l);
                    float* t = &rgb[(std::size_t(y) * std::size_t(n) + std::size_t(x)) * 3];
                    t[0] = v.x * scale, t[1] = v.y * scale, t[2] = v.z * scale;
                }
            const std::vector<unsigned char> b = ibl::bc6h_encode_image(rgb.data(), n, n, q);
            fx.add(b.data(), b.size() / 16);
        }
    }
}

void encoded_blocks(fixtures& fx) {
    const ibl::cubemap<float> sky = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 32, 2, ibl::serial_executor{}, 0);
    using q = ibl::bc6h_quality;
    encode_cube(fx, sky, 1.0f, q::fast, "encoded sky x1, fast");
    encode_cube(fx, sky, 1.0f, q::normal, "encoded sky x1, normal");
    encode_cube(fx, sky, 1.0f, q::exhaustive, "encoded sky x1, exhaustive");
    encode_cube(fx, sky, 4.0f, q::fast, "encoded sky x4 (sun clamped), fast");
    encode_cube(fx, sky, 4.0f, q::normal, "encoded sky x4 (sun clamped), normal");
    encode_cube(fx, sky, 1e-5f, q::fast, "encoded sky x1e-5 (subnormal halves), fast");
    encode_cube(fx, sky, 1e-5f, q::normal, "encoded sky x1e-5 (subnormal halves), normal");
    std::mt19937_64 rng(0x6c6f67756e69ull);
    std::uniform_real_distribution<double> e(std::log(1e-7), std::log(6e4));
    constexpr int n = 64;
    std::vector<float> rgb(std::size_t(n) * n * 3);
    for (auto& v : rgb) v = float(std::exp(e(rng)));
    fx.begin("encoded log-uniform noise 1e-7 .. 6e4, normal");
    const std::vector<unsigned char> b = ibl::bc6h_encode_image(rgb.data(), n, n, q::normal);
    fx.add(b.data(), b.size() / 16);
}

} // namespace

int main() {
    fixtures fx;
    random_blocks(fx);
    encoded_blocks(fx);
    const std::size_t count = fx.blocks.size() / 16;
    std::vector<unsigned char> halves(count * 16 * 3 * 2);
    for (std::size_t i = 0; i < count; ++i) {
        std::uint16_t h[16][3];
        ibl::bc6h_decode_block_half(&fx.blocks[16 * i], h);
        for (int t = 0; t < 16; ++t)
            for (int c = 0; c < 3; ++c) {
                unsigned char* o = &halves[((i * 16 + std::size_t(t)) * 3 + std::size_t(c)) * 2];
                o[0] = static_cast<unsigned char>(h[t][c] & 0xff);
                o[1] = static_cast<unsigned char>(h[t][c] >> 8);
            }
    }
    std::printf("{\"blocks_per_row\": 128, \"count\": %zu, \"groups\": [", count);
    for (std::size_t g = 0; g < fx.groups.size(); ++g)
        std::printf("%s{\"name\": \"%s\", \"first\": %zu, \"count\": %zu}", g ? ", " : "", fx.groups[g].name.c_str(), fx.groups[g].first,
                    fx.groups[g].count);
    std::printf("],\n\"blocks\": \"%s\",\n", base64(fx.blocks.data(), fx.blocks.size()).c_str());
    std::printf("\"halves\": \"%s\"}\n", base64(halves.data(), halves.size()).c_str());
    return 0;
}
