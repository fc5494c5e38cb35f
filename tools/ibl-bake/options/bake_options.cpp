// tools/ibl-bake/options/bake_options.cpp — command line parsing of ibl-bake (see bake_options.hpp).

#include "options/bake_options.hpp"

#include <ibl/bake/prefilter.hpp>

#include <algorithm>
#include <array>
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
        return {"low", 2, 64, false, ibl::dfg_quadrature_nodes{6, 6, 12, 6}, 1024, 16, 4, 1u << 13, 2};
    case quality::high:
        return {"high", 8, 2048, true, ibl::dfg_quadrature_nodes{16, 16, 32, 16}, 8192, 48, 8, 1u << 18, 4};
    case quality::standard:
    default:
        return {"default", 4, 512, true, ibl::dfg_quadrature_nodes{12, 12, 24, 12}, 4096, 32, 6, 1u << 16, 4};
    }
}

quality_settings check_settings_for(quality_settings q, check_mode checks) {
    if (checks != check_mode::fast) return q;
    q.ref_grid = std::max(3, q.ref_grid - 3);
    q.sky_ref_samples = std::max(256u, q.sky_ref_samples / 4);
    q.split_sum_samples = std::max(1u << 10, q.split_sum_samples / 8);
    return q;
}

int auto_levels(int size) { return ibl::prefilter_auto_levels(size); }

const char* to_string(quality q) noexcept { return settings_for(q).name; }

// The names of each enum's values, in the order of its declaration.
const char* to_string(bake_preset p) noexcept { return std::array{"default", "accurate", "filament", "gltf"}[std::size_t(p)]; }
const char* to_string(check_mode c) noexcept { return std::array{"fast", "full", "none"}[std::size_t(c)]; }
const char* to_string(sun_extraction s) noexcept { return std::array{"off", "auto", "on"}[std::size_t(s)]; }
const char* to_string(dfg_channel_order c) noexcept { return std::array{"ab", "filament"}[std::size_t(c)]; }
const char* to_string(runtime_choice r) noexcept { return std::array{"split-sum", "lobe", "taps2"}[std::size_t(r)]; }
const char* to_string(level_layout l) noexcept { return std::array{"faces", "latlong", "cross", "octahedral"}[std::size_t(l)]; }
const char* to_string(input_form f) noexcept {
    return std::array{"auto", "latlong", "hcross", "vcross", "hstrip", "vstrip", "faces", "ktx2"}[std::size_t(f)];
}
const char* to_string(prefilter_choice p) noexcept { return std::array{"fis", "fast"}[std::size_t(p)]; }
const char* to_string(ktx2_storage f) noexcept {
    return std::array{"rgba16f", "rgba32f", "b10g11r11", "e5b9g9r9", "bc6h", "astc4x4", "astc6x6"}[std::size_t(f)];
}
const char* to_string(block_quality q) noexcept { return std::array{"fast", "normal", "exhaustive"}[std::size_t(q)]; }

std::string to_string(const sh_window_choice& w) {
    return w.k == sh_window_choice::kind::hanning ? w.text : w.k == sh_window_choice::kind::none ? "none" : "auto";
}

const char* to_string(ibl::ld_weight w) noexcept { return w == ibl::ld_weight::g1 ? "g1" : "nl"; }

const char* to_string(ibl::roughness_mip_policy p) noexcept {
    return p.mapping == ibl::roughness_mapping::filament ? "filament" : "linear";
}

ibl::ld_weight ld_weight_from(const std::string& name) noexcept {
    return name == to_string(ibl::ld_weight::g1) ? ibl::ld_weight::g1 : ibl::ld_weight::n_dot_l;
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

namespace {

std::string name_of(const std::string& name) { return name; }
std::string name_of(const char* name) { return name; }
template <class E> std::string name_of(const E& value) { return name_of(to_string(value)); }
std::string name_of(const ibl::dfg_lut_layout& layout) { return layout.name(); }
std::string name_of(const ibl::specular_lookup_desc& lookup) { return lookup.name(); }

/// The value among `allowed` whose name is v, or a usage_error naming the choices.
template <class E> E choice(const std::string& option, const std::string& v, std::initializer_list<E> allowed) {
    std::string list;
    for (const E& a : allowed) {
        if (v == name_of(a)) return a;
        list += (list.empty() ? "" : ", ") + name_of(a);
    }
    throw usage_error(option + ": expected one of " + list + ", got '" + v + "'");
}

/// A comma-separated list of values from a fixed list (each once).
template <class E> std::vector<E> choices(const std::string& option, const std::string& v, std::initializer_list<E> allowed) {
    std::vector<E> out;
    std::size_t b = 0;
    while (b <= v.size()) {
        const std::size_t e = std::min(v.find(',', b), v.size());
        const E item = choice(option, v.substr(b, e - b), allowed);
        if (std::find(out.begin(), out.end(), item) != out.end())
            throw usage_error(option + ": '" + name_of(item) + "' given twice");
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
/// fitted lobe LUT, a compact sun taken out as a disk light, the log-geometric chain lookup on
/// levels spaced as lod = (V - 1) r (2 - r): denser at low roughness, the best spacing of the
/// same levels and storage measured, docs/lookup.md).
void apply_preset(bake_options& o, bake_preset p) {
    o.preset = p;
    const bool accurate = p == bake_preset::accurate;
    const bool filament = p == bake_preset::filament;
    const bool engine = filament || p == bake_preset::gltf;
    o.policy = filament || accurate ? ibl::roughness_mip_policy::filament() : ibl::roughness_mip_policy::linear();
    o.specular_lookup = accurate ? ibl::specular_lookup_desc::accurate() : ibl::specular_lookup_desc::textbook();
    o.dfg_layout = accurate ? ibl::dfg_lut_layout::remapped() : ibl::dfg_lut_layout::uniform();
    o.dfg_channels = filament ? dfg_channel_order::filament : dfg_channel_order::ab;
    o.mirror = filament;
    o.extract_sun = accurate ? sun_extraction::automatic : sun_extraction::off;
    o.irradiance_size = engine ? 0 : 32;
    o.ld_weight = accurate ? ibl::ld_weight::g1 : ibl::ld_weight::n_dot_l;
    o.runtime = accurate ? runtime_choice::lobe : runtime_choice::split_sum;
}

/// --sh-window: auto, none or a Hanning width > 0.
sh_window_choice sh_window_from(const std::string& option, const std::string& v) {
    sh_window_choice w;
    if (v == "auto") return w;
    if (v == "none") {
        w.k = sh_window_choice::kind::none;
        return w;
    }
    const auto r = std::from_chars(v.data(), v.data() + v.size(), w.width);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size() || !(w.width > 0.0) || !std::isfinite(w.width))
        throw usage_error(option + ": expected auto, none or a width > 0, got '" + v + "'");
    w.k = sh_window_choice::kind::hanning;
    w.text = v;
    return w;
}

using handler = std::function<void(bake_options&, const std::string&)>;
struct option_spec {
    bool takes_value;
    handler apply;
};

using option_map = std::map<std::string, option_spec>;

/// The switches (no value).
option_map switch_options() {
    const auto on = [](bool bake_options::*field) {
        return option_spec{false, [field](bake_options& o, const std::string&) { o.*field = true; }};
    };
    return {{"--help", on(&bake_options::help)},         {"-h", on(&bake_options::help)},
            {"--version", on(&bake_options::version)},   {"--quiet", on(&bake_options::quiet)},
            {"--mirror", on(&bake_options::mirror)},     {"--sheen", on(&bake_options::sheen)},
            {"--compare-full", on(&bake_options::compare_full)}, {"--strict", on(&bake_options::strict)},
            {"--verbose", on(&bake_options::verbose)}};
}

/// The conventions of the products: what --preset sets, each also on its own.
option_map convention_options() {
    return {
        {"--preset", {true, [](bake_options& o, const std::string& v) {
             apply_preset(o, choice("--preset", v, {bake_preset::standard, bake_preset::accurate, bake_preset::filament, bake_preset::gltf}));
         }}},
        {"--policy", {true, [](bake_options& o, const std::string& v) {
             o.policy = choice("--policy", v, {ibl::roughness_mip_policy::linear(), ibl::roughness_mip_policy::filament()});
         }}},
        {"--irradiance-size", {true, [](bake_options& o, const std::string& v) {
             o.irradiance_size = int(parse_integer("--irradiance-size", v, 0, 256));
         }}},
        {"--extract-sun", {true, [](bake_options& o, const std::string& v) {
             o.extract_sun = choice("--extract-sun", v, {sun_extraction::automatic, sun_extraction::on, sun_extraction::off});
         }}},
        {"--dfg-layout", {true, [](bake_options& o, const std::string& v) {
             o.dfg_layout = choice("--dfg-layout", v, {ibl::dfg_lut_layout::remapped(), ibl::dfg_lut_layout::uniform()});
         }}},
        {"--specular-lookup", {true, [](bake_options& o, const std::string& v) {
             o.specular_lookup = choice("--specular-lookup", v, {ibl::specular_lookup_desc::textbook(), ibl::specular_lookup_desc::accurate()});
         }}},
        {"--prefilter", {true, [](bake_options& o, const std::string& v) { o.prefilter = choice("--prefilter", v, {prefilter_choice::fis, prefilter_choice::fast}); }}},
        {"--fast-peaks", {true, [](bake_options& o, const std::string& v) {
             o.fast_peaks = std::uint32_t(parse_integer("--fast-peaks", v, 0, 1 << 20));
         }}},
        {"--fast-sh-bands", {true, [](bake_options& o, const std::string& v) {
             o.fast_sh_bands = int(parse_integer("--fast-sh-bands", v, 0, ibl::detail::sh_rough_band_limit));
         }}},
        {"--fast-mid-tail", {true, [](bake_options& o, const std::string& v) { o.fast_mid_tail = parse_integer("--fast-mid-tail", v, 0, 1) != 0; }}},
        {"--ld-weight", {true, [](bake_options& o, const std::string& v) { o.ld_weight = choice("--ld-weight", v, {ibl::ld_weight::g1, ibl::ld_weight::n_dot_l}); }}},
        {"--runtime", {true, [](bake_options& o, const std::string& v) { o.runtime = choice("--runtime", v, {runtime_choice::lobe, runtime_choice::taps2, runtime_choice::split_sum}); }}},
    };
}

/// What is read and written: paths, the input's form, the files' layouts and format.
option_map file_options() {
    return {
        {"--scene", {true, [](bake_options& o, const std::string& v) { o.scene = path_value("--scene", v); }}},
        {"--probes", {true, [](bake_options& o, const std::string& v) { o.probes = path_value("--probes", v); }}},
        {"--input", {true, [](bake_options& o, const std::string& v) { o.input = path_value("--input", v); }}},
        {"--out", {true, [](bake_options& o, const std::string& v) { o.out = path_value("--out", v); }}},
        {"--lookup", {true, [](bake_options& o, const std::string& v) { o.lookup = path_value("--lookup", v); }}},
        {"--part", {true, [](bake_options& o, const std::string& v) {
             if (v.empty()) throw usage_error("--part: empty name");
             o.part = v;
         }}},
        {"--input-layout", {true, [](bake_options& o, const std::string& v) {
             o.input_layout = choice("--input-layout", v, {input_form::automatic, input_form::latlong, input_form::hcross, input_form::vcross,
                                                            input_form::hstrip, input_form::vstrip, input_form::faces, input_form::ktx2});
         }}},
        {"--layout", {true, [](bake_options& o, const std::string& v) {
             o.layouts = choices("--layout", v, {level_layout::faces, level_layout::latlong, level_layout::cross, level_layout::octahedral});
         }}},
        {"--max-input-pixels", {true, [](bake_options& o, const std::string& v) {
             o.max_input_pixels = std::uint64_t(parse_integer("--max-input-pixels", v, 1, 1ll << 32));
         }}},
        {"--ktx2-format", {true, [](bake_options& o, const std::string& v) {
             const std::string f = choice("--ktx2-format", v,
                                          std::initializer_list<std::string>{"f16", "f32", "rgba16f", "rgba32f", "b10g11r11",
                                                                             "e5b9g9r9", "bc6h", "astc4x4", "astc6x6"});
             o.ktx2_format = choice("--ktx2-format", f == "f16" ? "rgba16f" : f == "f32" ? "rgba32f" : f,
                                    {ktx2_storage::rgba16f, ktx2_storage::rgba32f, ktx2_storage::b10g11r11, ktx2_storage::e5b9g9r9,
                                     ktx2_storage::bc6h, ktx2_storage::astc4x4, ktx2_storage::astc6x6});
         }}},
        {"--ktx2-quality", {true, [](bake_options& o, const std::string& v) {
             o.ktx2_quality = choice("--ktx2-quality", v, {block_quality::fast, block_quality::normal, block_quality::exhaustive});
         }}},
        {"--ktx2-zstd", {true, [](bake_options& o, const std::string& v) { o.ktx2_zstd = int(parse_integer("--ktx2-zstd", v, 0, 22)); }}},
    };
}

/// The sizes, the cost and the checks.
option_map size_options() {
    return {
        {"--size", {true, [](bake_options& o, const std::string& v) { o.size = int(parse_integer("--size", v, 1, 4096)); }}},
        {"--lut-size", {true, [](bake_options& o, const std::string& v) { o.lut_size = int(parse_integer("--lut-size", v, 1, 1024)); }}},
        {"--levels", {true, [](bake_options& o, const std::string& v) { o.levels = int(parse_integer("--levels", v, 0, 13)); }}},
        {"--threads", {true, [](bake_options& o, const std::string& v) { o.threads = unsigned(parse_integer("--threads", v, 0, 256)); }}},
        {"--sh-bands", {true, [](bake_options& o, const std::string& v) { o.sh_bands = int(parse_integer("--sh-bands", v, 2, 5)); }}},
        {"--sh-window", {true, [](bake_options& o, const std::string& v) { o.sh_window = sh_window_from("--sh-window", v); }}},
        {"--quality", {true, [](bake_options& o, const std::string& v) { o.q = choice("--quality", v, {quality::low, quality::standard, quality::high}); }}},
        {"--checks", {true, [](bake_options& o, const std::string& v) { o.checks = choice("--checks", v, {check_mode::fast, check_mode::full, check_mode::none}); }}},
    };
}

const option_map& option_table() {
    static const option_map t = [] {
        option_map m = switch_options();
        for (option_map part : {convention_options(), file_options(), size_options()}) m.merge(part);
        return m;
    }();
    return t;
}

/// The options a probe-set bake (--probes) uses besides --probes and --out: each capture is read
/// like --input (--input-layout, --max-input-pixels, --part), baked into the full bake's chain
/// (--size, --levels, --quality, --threads, --policy, --ld-weight, --prefilter, --fast-peaks,
/// --fast-sh-bands, --fast-mid-tail, --mirror) and SH3,
/// and stored in one KTX2 array (--ktx2-format, --ktx2-quality, --ktx2-zstd); --quiet.
bool applies_to_probes(const std::string& name) {
    static const char* const used[] = {"--probes", "--out", "--input-layout", "--max-input-pixels", "--part", "--size",
                                       "--levels", "--quality", "--threads", "--policy", "--ld-weight", "--prefilter",
                                       "--fast-peaks", "--fast-sh-bands", "--fast-mid-tail", "--mirror", "--ktx2-format", "--ktx2-quality", "--ktx2-zstd", "--quiet",
                                       "--help", "-h", "--version"};
    for (const char* u : used)
        if (name == u) return true;
    return false;
}

/// Checks that need every option: required ones, combinations, --levels against --size.
void check_combination(const bake_options& o, bool have_out, const std::vector<std::string>& given) {
    if (!o.lookup.empty()) {
        if (have_out || !o.input.empty() || !o.scene.empty() || !o.probes.empty())
            throw usage_error("--lookup DIR answers queries about an existing bake: no --out, --input, --scene or --probes");
        return;
    }
    if (!have_out) throw usage_error("--out DIR is required");
    if (!o.probes.empty() && (!o.input.empty() || !o.scene.empty()))
        throw usage_error("--probes takes each probe's input from its file: no --input or --scene");
    if (!o.probes.empty())
        for (const std::string& name : given)
            if (!applies_to_probes(name))
                throw usage_error(name + " does not apply to --probes (a probe set bakes each capture's specular chain and "
                                         "SH3 only; it takes --size, --levels, --quality, --threads, --policy, --ld-weight, "
                                         "--prefilter, --fast-peaks, --fast-sh-bands, --fast-mid-tail, --mirror, --input-layout, --max-input-pixels, --part, --ktx2-format, "
                                         "--ktx2-quality, --ktx2-zstd, --quiet)");
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
    std::vector<std::string> given; // the options named, in order (a probe-set bake refuses the others)
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
        given.push_back(name);
    }
    if (o.help || o.version) return o;
    check_combination(o, have_out, given);
    return o;
}

std::string usage_text() {
    return "usage: ibl-bake --out DIR [options]\n"
           "       ibl-bake --probes probes.json --out DIR [options]\n"
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
           "  --ktx2-format F    rgba16f (default of every preset; f16) | rgba32f (f32) | b10g11r11 | e5b9g9r9 |\n"
           "                     bc6h | astc4x4 | astc6x6 (block-compressed HDR, 8 / 8 / 3.56 bits per texel)\n"
           "  --ktx2-quality Q   fast | normal (default) | exhaustive: the block formats' encoder effort\n"
           "  --ktx2-zstd N      Zstandard supercompression of the KTX2 files, level 1..22 (default 0: none)\n"
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
           "  --prefilter M      fis (default: filtered importance sampling) | fast (the fast filter)\n"
           "  --fast-peaks N     the fast filter's peak split: at most N source texels (default 1024;\n"
           "                     0 = off) taken out of the tap set and added back exactly\n"
           "  --fast-sh-bands N  the fast filter's rough levels by spherical-harmonic convolution: a level\n"
           "                     whose kernel needs at most N bands (default 24, at most 32; 0 = off)\n"
           "  --fast-mid-tail B  the fast filter's intermediate coarse tail (default 1; 0 = off): a level at\n"
           "                     r <= 0.3 reads its kernel's tail from a half-size level between it and the\n"
           "                     next, where that face resolves the kernel (a 256^2 chain's level 1)\n"
           "  --ld-weight W      nl (default: Karis D n.l) | g1 (D G1, the true lobe at n.v = 1)\n"
           "  --runtime M        split-sum (default: LD(R, r) DFG) | lobe (lobe LUT) | taps2 (two fitted taps)\n"
           "  --lookup DIR       answer queries on stdin from the bake in DIR: specular X Y Z R, dfg NV R,\n"
           "                     irradiance X Y Z, shade NX NY NZ VX VY VZ R M BR BG BB, sheen X Y Z R,\n"
           "                     dfg_sheen NV R (--sheen bakes), lobe NV R, taps NV R; on a probe set:\n"
           "                     local PX PY PZ DX DY DZ R, local_irradiance PX PY PZ NX NY NZ\n"
           "  --scene PATH       bake only what the scene needs (docs/scene-format.md)\n"
           "  --probes PATH      bake the local reflection probes of PATH (JSON) into DIR: probes.ktx2 (a\n"
           "                     cubemap array of the chains), probes.json (volumes, SH3, conventions)\n"
           "  --compare-full     with --scene: also time the full bake and measure the error\n"
           "  --strict           with --scene: a missed error target is an error (exit 1, DIR untouched)\n"
           "  --help, --version\n";
}

} // namespace ibl_bake
