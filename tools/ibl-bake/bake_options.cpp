// tools/ibl-bake/bake_options.cpp — command line parsing of ibl-bake (see bake_options.hpp).

#include "bake_options.hpp"

#include <charconv>
#include <string_view>

namespace ibl_bake {

quality_settings settings_for(quality q) {
    switch (q) {
    case quality::low:
        return {"low", 2, 64, false, ibl::dfg_quadrature_nodes{6, 6, 12, 6}, 2048, 1024, 16, 4, 1u << 13, 2};
    case quality::high:
        return {"high", 8, 2048, true, ibl::dfg_quadrature_nodes{16, 16, 32, 16}, 1u << 15, 8192, 48, 8, 1u << 18, 4};
    case quality::standard:
    default:
        return {"default", 4, 512, true, ibl::dfg_quadrature_nodes{12, 12, 24, 12}, 1u << 13, 4096, 32, 6, 1u << 16, 4};
    }
}

int auto_levels(int size) {
    int log2n = 0;
    while ((size >> (log2n + 1)) > 0) ++log2n;
    const int full = log2n + 1;
    int l = log2n - 1;
    if (l < 1) l = 1;
    if (l > 6) l = 6;
    return l < full ? l : full;
}

namespace {

long long parse_integer(const std::string& option, const std::string& text, long long lo, long long hi) {
    long long v = 0;
    const char* b = text.data();
    const char* e = b + text.size();
    const auto r = std::from_chars(b, e, v);
    if (text.empty() || r.ec == std::errc::invalid_argument || r.ptr != e)
        throw usage_error(option + ": expected an integer, got '" + text + "'");
    if (r.ec == std::errc::result_out_of_range || v < lo || v > hi)
        throw usage_error(option + ": " + text + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                          "]");
    return v;
}

} // namespace

bake_options parse_options(const std::vector<std::string>& args) {
    bake_options o;
    bool have_out = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        std::string name = args[i], value;
        bool inline_value = false;
        if (name.rfind("--", 0) == 0) {
            const auto eq = name.find('=');
            if (eq != std::string::npos) {
                value = name.substr(eq + 1);
                name = name.substr(0, eq);
                inline_value = true;
            }
        } else {
            throw usage_error("unexpected argument '" + name + "' (options start with --)");
        }
        auto flag = [&] {
            if (inline_value) throw usage_error(name + " takes no value");
        };
        auto take = [&]() -> std::string {
            if (inline_value) return value;
            if (i + 1 >= args.size()) throw usage_error(name + ": missing value");
            return args[++i];
        };
        if (name == "--help" || name == "-h") {
            flag();
            o.help = true;
        } else if (name == "--version") {
            flag();
            o.version = true;
        } else if (name == "--quiet") {
            flag();
            o.quiet = true;
        } else if (name == "--scene") {
            o.scene = take();
            if (o.scene.empty()) throw usage_error("--scene: empty path");
        } else if (name == "--compare-full") {
            flag();
            o.compare_full = true;
        } else if (name == "--input") {
            o.input = take();
            if (o.input.empty()) throw usage_error("--input: empty path");
        } else if (name == "--out") {
            o.out = take();
            if (o.out.empty()) throw usage_error("--out: empty path");
            have_out = true;
        } else if (name == "--size") {
            o.size = int(parse_integer(name, take(), 1, 4096));
        } else if (name == "--lut-size") {
            o.lut_size = int(parse_integer(name, take(), 1, 1024));
        } else if (name == "--levels") {
            o.levels = int(parse_integer(name, take(), 0, 13));
        } else if (name == "--threads") {
            o.threads = unsigned(parse_integer(name, take(), 0, 256));
        } else if (name == "--quality") {
            const std::string q = take();
            if (q == "low") o.q = quality::low;
            else if (q == "default") o.q = quality::standard;
            else if (q == "high") o.q = quality::high;
            else throw usage_error("--quality: expected low, default or high, got '" + q + "'");
        } else if (name == "--ktx2-format") {
            const std::string f = take();
            if (f == "f16") o.ktx2_f32 = false;
            else if (f == "f32") o.ktx2_f32 = true;
            else throw usage_error("--ktx2-format: expected f16 or f32, got '" + f + "'");
        } else {
            throw usage_error("unknown option '" + name + "'");
        }
    }
    if (o.help || o.version) return o;
    if (!have_out) throw usage_error("--out DIR is required");
    if (o.compare_full && o.scene.empty()) throw usage_error("--compare-full needs --scene");
    if (o.levels > 0) {
        int full = 1;
        while ((o.size >> full) > 0) ++full;
        if (o.levels > full)
            throw usage_error("--levels: " + std::to_string(o.levels) + " exceeds the " + std::to_string(full) +
                              " levels of a " + std::to_string(o.size) + " face");
    }
    return o;
}

std::string usage_text() {
    return "usage: ibl-bake --out DIR [options]\n"
           "Bakes image-based-lighting products (prefiltered specular cubemap, SH irradiance, DFG LUT),\n"
           "a preview and an error/time report from a lat-long HDR image or the built-in sky.\n\n"
           "  --input PATH       lat-long (2:1) Radiance .hdr or OpenEXR (default: built-in sky + sun)\n"
           "  --out DIR          output directory (created; existing files of the same names replaced)\n"
           "  --size N           face size of the prefiltered base level, 1..4096 (default 256)\n"
           "  --lut-size N       DFG LUT size, 1..1024 (default 128)\n"
           "  --levels N         prefiltered mip levels, 0 = automatic (default)\n"
           "  --threads N        worker threads, 0 = all cores (default)\n"
           "  --quality Q        low | default | high\n"
           "  --ktx2-format F    f16 (default) | f32\n"
           "  --quiet            no progress on stderr\n"
           "  --scene PATH       bake only what the scene needs (docs/scene-format.md)\n"
           "  --compare-full     with --scene: also time the full bake and measure the error\n"
           "  --help, --version\n";
}

} // namespace ibl_bake
