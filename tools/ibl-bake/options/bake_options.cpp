// tools/ibl-bake/options/bake_options.cpp — command line parsing of ibl-bake (see bake_options.hpp).

#include "options/bake_options.hpp"

#include <ibl/bake/prefilter.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <map>
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

quality_settings check_settings_for(quality_settings q, const std::string& checks) {
    if (checks != "fast") return q;
    q.ref_grid = std::max(3, q.ref_grid - 3);
    q.ld_ref_samples = std::max(256u, q.ld_ref_samples / 4);
    q.sky_ref_samples = std::max(256u, q.sky_ref_samples / 4);
    q.split_sum_samples = std::max(1u << 10, q.split_sum_samples / 8);
    return q;
}

int auto_levels(int size) { return ibl::prefilter_auto_levels(size); }

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

namespace {

/// One value from a fixed list, or a usage_error naming the choices.
std::string choice(const std::string& option, const std::string& v, std::initializer_list<const char*> allowed) {
    std::string list;
    for (const char* a : allowed) {
        if (v == a) return v;
        list += (list.empty() ? "" : ", ") + std::string(a);
    }
    throw usage_error(option + ": expected one of " + list + ", got '" + v + "'");
}

/// A comma-separated list of values from a fixed list (each once).
std::vector<std::string> choices(const std::string& option, const std::string& v, std::initializer_list<const char*> allowed) {
    std::vector<std::string> out;
    std::size_t b = 0;
    while (b <= v.size()) {
        const std::size_t e = std::min(v.find(',', b), v.size());
        const std::string item = choice(option, v.substr(b, e - b), allowed);
        if (std::find(out.begin(), out.end(), item) != out.end()) throw usage_error(option + ": '" + item + "' given twice");
        out.push_back(item);
        b = e + 1;
    }
    return out;
}

std::string path_value(const std::string& option, const std::string& v) {
    if (v.empty()) throw usage_error(option + ": empty path");
    return v;
}

/// The conventions of an engine (docs/ibl-bake.md, "Presets").
/// default = the textbook products (what every renderer that implements Karis's split sum reads:
/// n.l chain read by textureLod at lod(r), uniform (n.v, r) DFG table, nothing taken out of the
/// environment); accurate = the more accurate conventions (G1 chain, remapped DFG table, the
/// fitted lobe LUT, a compact sun taken out as a disk light, the log-geometric chain lookup).
void apply_preset(bake_options& o, const std::string& p) {
    o.preset = p;
    const bool accurate = p == "accurate";
    const bool engine = p == "filament" || p == "gltf";
    o.policy = p == "filament" ? "filament" : "linear";
    o.specular_lookup = accurate ? "accurate" : "textbook";
    o.dfg_layout = accurate ? "remapped" : "uniform";
    o.dfg_channels = p == "filament" ? "filament" : "ab";
    o.mirror = p == "filament";
    o.extract_sun = accurate ? "auto" : "off";
    o.irradiance_size = engine ? 0 : 32;
    o.ld_weight = accurate ? "g1" : "nl";
    o.runtime = accurate ? "lobe" : "split-sum";
}

using handler = std::function<void(bake_options&, const std::string&)>;
struct option_spec {
    bool takes_value;
    handler apply;
};

const std::map<std::string, option_spec>& option_table() {
    static const std::map<std::string, option_spec> t = {
        {"--help", {false, [](bake_options& o, const std::string&) { o.help = true; }}},
        {"-h", {false, [](bake_options& o, const std::string&) { o.help = true; }}},
        {"--version", {false, [](bake_options& o, const std::string&) { o.version = true; }}},
        {"--quiet", {false, [](bake_options& o, const std::string&) { o.quiet = true; }}},
        {"--preset", {true, [](bake_options& o, const std::string& v) { apply_preset(o, choice("--preset", v, {"default", "accurate", "filament", "gltf"})); }}},
        {"--policy", {true, [](bake_options& o, const std::string& v) { o.policy = choice("--policy", v, {"linear", "filament"}); }}},
        {"--mirror", {false, [](bake_options& o, const std::string&) { o.mirror = true; }}},
        {"--sheen", {false, [](bake_options& o, const std::string&) { o.sheen = true; }}},
        {"--compare-full", {false, [](bake_options& o, const std::string&) { o.compare_full = true; }}},
        {"--strict", {false, [](bake_options& o, const std::string&) { o.strict = true; }}},
        {"--checks", {true, [](bake_options& o, const std::string& v) { o.checks = choice("--checks", v, {"fast", "full", "none"}); }}},
        {"--verbose", {false, [](bake_options& o, const std::string&) { o.verbose = true; }}},
        {"--scene", {true, [](bake_options& o, const std::string& v) { o.scene = path_value("--scene", v); }}},
        {"--input", {true, [](bake_options& o, const std::string& v) { o.input = path_value("--input", v); }}},
        {"--out", {true, [](bake_options& o, const std::string& v) { o.out = path_value("--out", v); }}},
        {"--sh-bands", {true, [](bake_options& o, const std::string& v) { o.sh_bands = int(parse_integer("--sh-bands", v, 2, 5)); }}},
        {"--sh-window", {true, [](bake_options& o, const std::string& v) {
             if (v != "auto" && v != "none") {
                 double w = 0.0;
                 const auto r = std::from_chars(v.data(), v.data() + v.size(), w);
                 if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size() || !(w > 0.0) || !std::isfinite(w))
                     throw usage_error("--sh-window: expected auto, none or a width > 0, got '" + v + "'");
             }
             o.sh_window = v;
         }}},
        {"--irradiance-size", {true, [](bake_options& o, const std::string& v) {
             o.irradiance_size = int(parse_integer("--irradiance-size", v, 0, 256));
         }}},
        {"--extract-sun", {true, [](bake_options& o, const std::string& v) {
             o.extract_sun = choice("--extract-sun", v, {"auto", "on", "off"});
         }}},
        {"--dfg-layout", {true, [](bake_options& o, const std::string& v) {
             o.dfg_layout = choice("--dfg-layout", v, {"remapped", "uniform"});
         }}},
        {"--specular-lookup", {true, [](bake_options& o, const std::string& v) {
             o.specular_lookup = choice("--specular-lookup", v, {"textbook", "accurate"});
         }}},
        {"--ld-weight", {true, [](bake_options& o, const std::string& v) { o.ld_weight = choice("--ld-weight", v, {"g1", "nl"}); }}},
        {"--runtime", {true, [](bake_options& o, const std::string& v) { o.runtime = choice("--runtime", v, {"lobe", "taps2", "split-sum"}); }}},
        {"--lookup", {true, [](bake_options& o, const std::string& v) { o.lookup = path_value("--lookup", v); }}},
        {"--part", {true, [](bake_options& o, const std::string& v) {
             if (v.empty()) throw usage_error("--part: empty name");
             o.part = v;
         }}},
        {"--input-layout", {true, [](bake_options& o, const std::string& v) {
             o.input_layout = choice("--input-layout", v, {"auto", "latlong", "hcross", "vcross", "hstrip", "vstrip", "faces", "ktx2"});
         }}},
        {"--layout", {true, [](bake_options& o, const std::string& v) {
             o.layouts = choices("--layout", v, {"faces", "latlong", "cross", "octahedral"});
         }}},
        {"--size", {true, [](bake_options& o, const std::string& v) { o.size = int(parse_integer("--size", v, 1, 4096)); }}},
        {"--lut-size", {true, [](bake_options& o, const std::string& v) { o.lut_size = int(parse_integer("--lut-size", v, 1, 1024)); }}},
        {"--levels", {true, [](bake_options& o, const std::string& v) { o.levels = int(parse_integer("--levels", v, 0, 13)); }}},
        {"--threads", {true, [](bake_options& o, const std::string& v) { o.threads = unsigned(parse_integer("--threads", v, 0, 256)); }}},
        {"--max-input-pixels", {true, [](bake_options& o, const std::string& v) {
             o.max_input_pixels = std::uint64_t(parse_integer("--max-input-pixels", v, 1, 1ll << 32));
         }}},
        {"--quality", {true, [](bake_options& o, const std::string& v) {
             const std::string q = choice("--quality", v, {"low", "default", "high"});
             o.q = q == "low" ? quality::low : q == "high" ? quality::high : quality::standard;
         }}},
        {"--ktx2-format", {true, [](bake_options& o, const std::string& v) {
             const std::string f = choice("--ktx2-format", v, {"f16", "f32", "rgba16f", "rgba32f", "b10g11r11", "e5b9g9r9"});
             o.ktx2_format = f == "f16" ? "rgba16f" : f == "f32" ? "rgba32f" : f;
             o.ktx2_f32 = o.ktx2_format == "rgba32f";
         }}},
    };
    return t;
}

/// Checks that need every option: required ones, combinations, --levels against --size.
void check_combination(const bake_options& o, bool have_out) {
    if (!o.lookup.empty()) {
        if (have_out || !o.input.empty() || !o.scene.empty())
            throw usage_error("--lookup DIR answers queries about an existing bake: no --out, --input or --scene");
        return;
    }
    if (!have_out) throw usage_error("--out DIR is required");
    if (o.compare_full && o.scene.empty()) throw usage_error("--compare-full needs --scene");
    if (o.strict && o.scene.empty()) throw usage_error("--strict needs --scene");
    if (o.levels > 0) {
        int full = 1;
        while ((o.size >> full) > 0) ++full;
        if (o.levels > full)
            throw usage_error("--levels: " + std::to_string(o.levels) + " exceeds the " + std::to_string(full) +
                              " levels of a " + std::to_string(o.size) + " face");
    }
}

} // namespace

bake_options parse_options(const std::vector<std::string>& args) {
    bake_options o;
    bool have_out = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        std::string name = args[i], value;
        bool inline_value = false;
        if (name.rfind("--", 0) != 0 && name != "-h")
            throw usage_error("unexpected argument '" + name + "' (options start with --)");
        if (const auto eq = name.find('='); eq != std::string::npos) {
            value = name.substr(eq + 1);
            name = name.substr(0, eq);
            inline_value = true;
        }
        const auto it = option_table().find(name);
        if (it == option_table().end()) throw usage_error("unknown option '" + name + "'");
        if (!it->second.takes_value && inline_value) throw usage_error(name + " takes no value");
        if (it->second.takes_value && !inline_value) {
            if (i + 1 >= args.size()) throw usage_error(name + ": missing value");
            value = args[++i];
        }
        it->second.apply(o, value);
        have_out = have_out || name == "--out";
    }
    if (o.help || o.version) return o;
    check_combination(o, have_out);
    return o;
}

std::string usage_text() {
    return "usage: ibl-bake --out DIR [options]\n"
           "       ibl-bake --lookup DIR < queries   (answers as the shader does; docs/ibl-bake.md)\n"
           "Bakes image-based-lighting products (prefiltered specular cubemap, SH irradiance, DFG LUT),\n"
           "a preview and an error/time report from a lat-long HDR image or the built-in sky.\n\n"
           "  --input PATH       Radiance .hdr, OpenEXR or KTX2: lat-long (2:1), cross (4:3 or 3:4), or six faces\n"
           "                     (a path with {face}: px nx py ny pz nz); default: the built-in sky + sun\n"
           "  --input-layout L   auto (default: by aspect ratio) | latlong | hcross | vcross | hstrip | vstrip |\n"
           "                     faces | ktx2\n"
           "  --part NAME        the part of a multi-part EXR (default: the first with R, G, B)\n"
           "  --max-input-pixels N  refuse larger inputs before decoding (default 134217728 = 16384 x 8192)\n"
           "  --out DIR          output directory (created; existing files of the same names replaced)\n"
           "  --size N           face size of the prefiltered base level, 1..4096 (default 256)\n"
           "  --lut-size N       DFG LUT size, 1..1024 (default 128)\n"
           "  --levels N         prefiltered mip levels, 0 = automatic (default)\n"
           "  --threads N        worker threads, 0 = all cores (default)\n"
           "  --quality Q        low | default | high\n"
           "  --layout L[,L..]   files per specular level: faces (default) | latlong | cross | octahedral\n"
           "  --ktx2-format F    rgba16f (default; f16) | rgba32f (f32) | b10g11r11 | e5b9g9r9\n"
           "  --quiet            no progress on stderr\n"
           "  --checks C         fast (default: cheaper references, checks <= 1/4 of the run) | full | none\n"
           "                     (none: no reference checks; the products are written unchecked)\n"
           "  --verbose          the wide report table (every column, every level and model)\n"
           "  --sh-bands B       SH bands 2..5 (default 3)\n"
           "  --sh-window W      auto (default) | none | Hanning width W: applied to irradiance and shader SH\n"
           "  --irradiance-size N  irradiance map face (default 32), 0 = none\n"
           "  --extract-sun S    off (default) | auto | on: a compact dominant source becomes lights.json\n"
           "  --preset P         default (textbook products) | accurate | filament | gltf (docs/ibl-bake.md);\n"
           "                     options after it override what it sets\n"
           "  --policy P         linear (default) | filament: roughness <-> lod of the chain\n"
           "  --mirror           mirror the environment (x -> -x)\n"
           "  --sheen            also the Charlie sheen chain and the sheen albedo LUT\n"
           "  --dfg-layout L     uniform (default: texel centres in n.v, r) | remapped (cbrt n.v, sqrt r)\n"
           "  --specular-lookup S  textbook (default: textureLod at lod(r)) | accurate (log-geometric)\n"
           "  --ld-weight W      nl (default: Karis D n.l) | g1 (D G1, the true lobe at n.v = 1)\n"
           "  --runtime M        split-sum (default: LD(R, r) DFG) | lobe (lobe LUT) | taps2 (two fitted taps)\n"
           "  --lookup DIR       answer queries on stdin from the bake in DIR: specular X Y Z R, dfg NV R,\n"
           "                     irradiance X Y Z, shade NX NY NZ VX VY VZ R M BR BG BB, sheen X Y Z R,\n"
           "                     dfg_sheen NV R (--sheen bakes), lobe NV R, taps NV R\n"
           "  --scene PATH       bake only what the scene needs (docs/scene-format.md)\n"
           "  --compare-full     with --scene: also time the full bake and measure the error\n"
           "  --strict           with --scene: a missed error target is an error (exit 1, DIR untouched)\n"
           "  --help, --version\n";
}

} // namespace ibl_bake
