// bench_plot — Google Benchmark JSON -> log-log PNG plot of an error counter against time.
//
//   bench_plot -o plot.png --y max_abs_err [options] run1.json [run2.json ...]
//
// Each benchmark row (iteration runs; aggregates and failed runs are skipped) becomes one point:
// x = time per iteration in ms (real_time by default), y = the chosen counter. Points are grouped
// into curves, one per method:
//   --curve 'LABEL=REGEX[=YSPEC[=dashed]]'  rows whose run name matches REGEX (ECMAScript, searched
//                                            anywhere in the name; a row joins every curve whose REGEX
//                                            matches, so one row can give a point on an error curve and
//                                            one on a standard-error curve); YSPEC overrides --y.
//   without --curve: one curve per family = the run name without its knob argument
//                    (e.g. BM_prefilter_fis/env:0/spp:64/real_time -> BM_prefilter_fis/env:0/real_time).
// The knob (--knob NAME, default: the last argument of the name) orders the points along a curve
// and is what --annotate prints. See usage() for the rest.
//
// Exit status: 0 = plot written; 1 = bad input (unreadable file, malformed JSON, not benchmark
// output, missing counter, nothing to plot); 2 = bad command line. The PNG is written to a
// temporary file and renamed, so a failed run never leaves a partial plot behind.
#include "bench_records.hpp"
#include "json_value.hpp"
#include "raster.hpp"

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <optional>
// libstdc++ 12's <regex> trips g++'s -Wmaybe-uninitialized (a false positive inside std::function,
// seen at -O1 under the sanitizers); the warning is silenced for the header's code only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <functional>
#include <regex>
#pragma GCC diagnostic pop
#else
#include <regex>
#endif
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bp = bench_plot;

namespace {

// ---- command line ---------------------------------------------------------------------------

struct usage_error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A y value: one counter, or a reduction over several ("max(rel_1,rel_2)", "mean(...)", "rms(...)").
struct y_spec {
    std::string text;
    std::string reduce; // "" (single counter), "max", "min", "mean", "rms"
    std::vector<std::string> counters;
};

y_spec parse_y_spec(const std::string& s) {
    y_spec y;
    y.text = s;
    const std::size_t open = s.find('(');
    if (open == std::string::npos) {
        if (s.empty()) throw usage_error("empty counter name");
        y.counters = {s};
        return y;
    }
    if (s.back() != ')') throw usage_error("bad counter expression '" + s + "' (expected FUNC(a,b,...))");
    y.reduce = s.substr(0, open);
    if (y.reduce != "max" && y.reduce != "min" && y.reduce != "mean" && y.reduce != "rms")
        throw usage_error("unknown reduction '" + y.reduce + "' in '" + s + "' (max, min, mean, rms)");
    for (std::string c : bp::detail::split(s.substr(open + 1, s.size() - open - 2), ',')) {
        c.erase(0, c.find_first_not_of(' '));
        c.erase(c.find_last_not_of(' ') + 1);
        if (c.empty()) throw usage_error("empty counter name in '" + s + "'");
        y.counters.push_back(c);
    }
    return y;
}

struct curve_spec {
    std::string label;
    std::string pattern;
    std::regex re;
    std::optional<y_spec> y;
    bool dashed = false;
};

enum class legend_pos { automatic, top_left, top_right, bottom_left, bottom_right, right };
enum class annotate_mode { none, ends, all };

struct options {
    std::string output;
    std::vector<std::string> inputs;
    y_spec y;
    bool have_y = false;
    std::string x = "real_time"; // real_time | cpu_time | knob | <counter>
    std::string knob;            // "" = last argument of each name
    std::vector<curve_spec> curves;
    std::optional<std::regex> filter;
    std::string title, xlabel, ylabel;
    int width = 960, height = 600;
    legend_pos legend = legend_pos::automatic;
    annotate_mode annotate = annotate_mode::none;
    bool quiet = false;
};

void usage(std::ostream& os) {
    os << "usage: bench_plot -o OUT.png --y SPEC [options] FILE.json [FILE.json ...]\n"
          "\n"
          "Plots Google Benchmark JSON output (--benchmark_format=json or --benchmark_out=FILE.json)\n"
          "as a log-log chart of an error counter (y) against time per iteration (x), one curve per method.\n"
          "\n"
          "  -o, --output FILE        PNG to write (required)\n"
          "  --y SPEC                 y: a counter name, or max(a,b,..) / min(..) / mean(..) / rms(..)\n"
          "                           of several counters (required)\n"
          "  --x WHAT                 x: real_time (default) or cpu_time per iteration, in ms;\n"
          "                           knob (the knob argument's value); or a counter name\n"
          "  --knob NAME              the argument varying along a curve (default: last argument)\n"
          "  --curve 'LABEL=REGEX[=YSPEC[=dashed]]'\n"
          "                           a curve of the rows whose run name matches REGEX (repeatable; a row\n"
          "                           joins every matching curve; REGEX must not contain '='); YSPEC\n"
          "                           overrides --y for this curve; dashed draws it dashed.\n"
          "                           Without --curve: one curve per family (name minus the knob)\n"
          "  --filter REGEX           without --curve: keep only rows whose name matches\n"
          "  --title TEXT, --xlabel TEXT, --ylabel TEXT\n"
          "  --size WxH               image size in pixels (default 960x600, at least 320x240)\n"
          "  --legend WHERE           auto (default), tl, tr, bl, br (inside), right (outside)\n"
          "  --annotate WHICH         print knob values next to points: none (default), ends, all\n"
          "  -q, --quiet              no table of the plotted points on stdout\n"
          "  -h, --help\n"
          "\n"
          "Exit status: 0 written, 1 bad input (malformed JSON, missing counter, nothing to plot), 2 usage.\n";
}

int parse_int(const std::string& s, const std::string& what) {
    const auto v = bp::detail::parse_double(s);
    if (!v || *v != std::floor(*v) || *v < 1 || *v > 20000) throw usage_error("bad " + what + " '" + s + "'");
    return int(*v);
}

std::regex make_regex(const std::string& pattern) {
    try {
        return std::regex(pattern, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
        throw usage_error("bad regular expression '" + pattern + "': " + e.what());
    }
}

options parse_args(int argc, char** argv) {
    options o;
    auto value = [&](int& i) -> std::string {
        if (i + 1 >= argc) throw usage_error(std::string("option ") + argv[i] + " needs a value");
        return argv[++i];
    };
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            usage(std::cout);
            std::exit(0);
        } else if (a == "-o" || a == "--output") {
            o.output = value(i);
        } else if (a == "--y") {
            o.y = parse_y_spec(value(i));
            o.have_y = true;
        } else if (a == "--x") {
            o.x = value(i);
        } else if (a == "--knob") {
            o.knob = value(i);
        } else if (a == "--curve") {
            const std::string v = value(i);
            const auto f = bp::detail::split(v, '=');
            if (f.size() < 2 || f.size() > 4 || f[0].empty() || f[1].empty())
                throw usage_error("bad --curve '" + v + "' (expected LABEL=REGEX[=YSPEC[=dashed]])");
            curve_spec c{f[0], f[1], make_regex(f[1]), std::nullopt, false};
            if (f.size() >= 3 && !f[2].empty()) c.y = parse_y_spec(f[2]);
            if (f.size() == 4) {
                if (f[3] != "dashed" && f[3] != "solid") throw usage_error("bad line style '" + f[3] + "' (dashed or solid)");
                c.dashed = f[3] == "dashed";
            }
            o.curves.push_back(std::move(c));
        } else if (a == "--filter") {
            o.filter = make_regex(value(i));
        } else if (a == "--title") {
            o.title = value(i);
        } else if (a == "--xlabel") {
            o.xlabel = value(i);
        } else if (a == "--ylabel") {
            o.ylabel = value(i);
        } else if (a == "--size") {
            const std::string v = value(i);
            const std::size_t x = v.find('x');
            if (x == std::string::npos) throw usage_error("bad --size '" + v + "' (expected WxH)");
            o.width = parse_int(v.substr(0, x), "width");
            o.height = parse_int(v.substr(x + 1), "height");
            if (o.width < 320 || o.height < 240) throw usage_error("--size: at least 320x240");
        } else if (a == "--legend") {
            const std::string v = value(i);
            if (v == "auto") o.legend = legend_pos::automatic;
            else if (v == "tl") o.legend = legend_pos::top_left;
            else if (v == "tr") o.legend = legend_pos::top_right;
            else if (v == "bl") o.legend = legend_pos::bottom_left;
            else if (v == "br") o.legend = legend_pos::bottom_right;
            else if (v == "right") o.legend = legend_pos::right;
            else throw usage_error("bad --legend '" + v + "'");
        } else if (a == "--annotate") {
            const std::string v = value(i);
            if (v == "none") o.annotate = annotate_mode::none;
            else if (v == "ends") o.annotate = annotate_mode::ends;
            else if (v == "all") o.annotate = annotate_mode::all;
            else throw usage_error("bad --annotate '" + v + "'");
        } else if (a == "-q" || a == "--quiet") {
            o.quiet = true;
        } else if (a.size() > 1 && a[0] == '-') {
            throw usage_error("unknown option '" + a + "'");
        } else {
            o.inputs.push_back(a);
        }
    }
    if (o.output.empty()) throw usage_error("no output file (-o FILE.png)");
    if (!o.have_y) throw usage_error("no y counter (--y NAME)");
    if (o.inputs.empty()) throw usage_error("no input JSON file");
    if (!o.curves.empty() && o.filter) throw usage_error("--filter applies only without --curve");
    return o;
}

// ---- data ---------------------------------------------------------------------------------------

struct point {
    double x = 0.0, y = 0.0;
    std::optional<double> knob;
    std::string name;
};

struct curve {
    std::string label;
    bool dashed = false;
    std::vector<point> points;
};

std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw bp::bench_error(path + ": cannot open");
    std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (f.bad()) throw bp::bench_error(path + ": read error");
    return s;
}

std::string counter_list(const bp::bench_record& r) {
    std::string s;
    for (const auto& [k, v] : r.numbers) {
        (void)v;
        if (k == "family_index" || k == "per_family_instance_index" || k == "repetitions" || k == "repetition_index" ||
            k == "threads" || k == "real_time" || k == "cpu_time")
            continue;
        s += (s.empty() ? "" : ", ") + k;
    }
    return s.empty() ? "none" : s;
}

double counter(const bp::bench_record& r, const std::string& c) {
    const auto v = r.number(c);
    if (!v) throw bp::bench_error(r.file + ": " + r.name + ": no counter '" + c + "' (it has: " + counter_list(r) + ")");
    return *v;
}

double eval_y(const bp::bench_record& r, const y_spec& y) {
    if (y.reduce.empty()) return counter(r, y.counters[0]);
    double acc = y.reduce == "max" ? -std::numeric_limits<double>::infinity()
                                   : y.reduce == "min" ? std::numeric_limits<double>::infinity() : 0.0;
    for (const auto& c : y.counters) {
        const double v = counter(r, c);
        if (y.reduce == "max") acc = std::max(acc, v);
        else if (y.reduce == "min") acc = std::min(acc, v);
        else if (y.reduce == "mean") acc += v;
        else acc += v * v;
    }
    const double n = double(y.counters.size());
    if (y.reduce == "mean") acc /= n;
    if (y.reduce == "rms") acc = std::sqrt(acc / n);
    return acc;
}

const bp::bench_arg* knob_of(const bp::bench_record& r, const std::string& knob) {
    if (knob.empty()) return r.args.empty() ? nullptr : &r.args.back();
    return r.arg(knob);
}

double eval_x(const bp::bench_record& r, const options& o) {
    if (o.x == "real_time") return r.real_ms;
    if (o.x == "cpu_time") return r.cpu_ms;
    if (o.x == "knob") {
        const bp::bench_arg* k = knob_of(r, o.knob);
        if (!k) throw bp::bench_error(r.file + ": " + r.name + ": no knob argument" + (o.knob.empty() ? "" : " '" + o.knob + "'") + " for --x knob");
        return k->value;
    }
    return counter(r, o.x);
}

/// The family key of a row: its name without the knob token.
std::string family_key(const bp::bench_record& r, const std::string& knob) {
    const bp::bench_arg* k = knob_of(r, knob);
    std::string key;
    for (std::size_t t = 0; t < r.tokens.size(); ++t) {
        if (k && t == k->token) continue;
        key += (key.empty() ? "" : "/") + r.tokens[t];
    }
    return key;
}

struct dataset {
    std::vector<curve> curves;
    int dropped = 0; // non-positive or non-finite values (a log axis cannot show them)
};

dataset build_curves(const std::vector<bp::bench_record>& rows, const options& o) {
    dataset d;
    std::vector<int> matched(o.curves.size(), 0);
    if (!o.curves.empty())
        for (const auto& c : o.curves) d.curves.push_back({c.label, c.dashed, {}});
    // Adds row r to curve ci with y from spec y (or counts it as dropped).
    auto add = [&](const bp::bench_record& r, std::size_t ci, const y_spec& y) {
        point p;
        p.x = eval_x(r, o);
        p.y = eval_y(r, y);
        p.name = r.name;
        if (const bp::bench_arg* k = knob_of(r, o.knob)) p.knob = k->value;
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && p.x > 0.0 && p.y > 0.0)) {
            std::cerr << "bench_plot: warning: " << r.file << ": " << r.name << ": (x, y) = (" << p.x << ", " << p.y
                      << ") cannot be shown on log axes; dropped\n";
            ++d.dropped;
            return;
        }
        d.curves[ci].points.push_back(std::move(p));
    };
    for (const auto& r : rows) {
        if (!o.curves.empty()) {
            for (std::size_t ci = 0; ci < o.curves.size(); ++ci) {
                if (!std::regex_search(r.name, o.curves[ci].re)) continue;
                ++matched[ci];
                add(r, ci, o.curves[ci].y ? *o.curves[ci].y : o.y);
            }
            continue;
        }
        if (o.filter && !std::regex_search(r.name, *o.filter)) continue;
        const std::string key = family_key(r, o.knob);
        std::size_t ci = 0;
        while (ci < d.curves.size() && d.curves[ci].label != key) ++ci;
        if (ci == d.curves.size()) d.curves.push_back({key, false, {}});
        add(r, ci, o.y);
    }
    for (std::size_t c = 0; c < o.curves.size(); ++c)
        if (matched[c] == 0)
            throw bp::bench_error("curve '" + o.curves[c].label + "': no benchmark name matches '" + o.curves[c].pattern + "'");
    for (auto& c : d.curves) {
        const bool by_knob = std::all_of(c.points.begin(), c.points.end(), [](const point& p) { return p.knob.has_value(); });
        std::stable_sort(c.points.begin(), c.points.end(), [&](const point& a, const point& b) {
            return by_knob ? (*a.knob < *b.knob || (*a.knob == *b.knob && a.x < b.x)) : a.x < b.x;
        });
    }
    std::size_t n = 0;
    for (const auto& c : d.curves) n += c.points.size();
    if (n == 0) throw bp::bench_error("nothing to plot: no benchmark row with positive, finite x and y");
    return d;
}

// ---- axes -----------------------------------------------------------------------------------------

struct tick {
    double value;
    bool labelled;
    bool major; // a decade
};

/// A log10 axis over [lo, hi] (log units) with its ticks and labels.
struct log_axis {
    double lo = 0.0, hi = 1.0;
    std::vector<tick> ticks;
    bool superscript = false; // labels as 10^k (else plain decimals)

    /// Axis over [vmin, vmax] with a margin; extra_lo / extra_hi widen it further by that fraction
    /// of the padded span (room for the legend).
    static log_axis fit(double vmin, double vmax, double extra_lo = 0.0, double extra_hi = 0.0) {
        log_axis a;
        double l0 = std::log10(vmin), l1 = std::log10(vmax);
        const double pad = std::max(0.06 * (l1 - l0), 0.12);
        if (l1 - l0 < 1e-9) {
            l0 -= 0.5;
            l1 += 0.5;
        } else {
            l0 -= pad;
            l1 += pad;
        }
        const double span = l1 - l0;
        l0 -= extra_lo * span;
        l1 += extra_hi * span;
        a.lo = l0;
        a.hi = l1;
        const int k0 = int(std::floor(l0)), k1 = int(std::ceil(l1));
        const int decades = int(std::floor(l1)) - int(std::ceil(l0)) + 1; // decade ticks inside
        const int step = decades > 10 ? (decades + 7) / 8 : 1;             // label every step-th decade
        const bool dense = decades < 2;                                      // also label 2 and 5 (or all)
        const bool very_dense = dense && (l1 - l0) < 0.7;
        for (int k = k0; k <= k1; ++k)
            for (int m = 1; m <= 9; ++m) {
                const double v = m * std::pow(10.0, k);
                const double lv = std::log10(v);
                if (lv < l0 || lv > l1) continue;
                if (decades > 12 && m != 1) continue; // no minor grid on very long axes
                bool lab = false;
                if (m == 1) lab = ((k % step) + step) % step == 0;
                else if (very_dense) lab = true;
                else if (dense) lab = m == 2 || m == 5;
                a.ticks.push_back({v, lab, m == 1});
            }
        bool plain = true;
        for (const auto& t : a.ticks)
            if (t.labelled && (t.value < 1e-3 * 0.999 || t.value > 1e4 * 1.001)) plain = false;
        a.superscript = !plain && decades >= 2;
        return a;
    }

    [[nodiscard]] double frac(double v) const { return (std::log10(v) - lo) / (hi - lo); }
};

struct label_text {
    std::string base, exponent; // exponent empty = plain text
};

label_text tick_label(double v, bool superscript) {
    if (superscript) {
        const int k = int(std::lround(std::log10(v)));
        return {"10", std::to_string(k)};
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return {buf, ""};
}

// ---- drawing ----------------------------------------------------------------------------------------

constexpr bp::rgb white{255, 255, 255};
constexpr bp::rgb ink = bp::hex_rgb(0x222222);
constexpr bp::rgb frame_ink = bp::hex_rgb(0x555555);
constexpr bp::rgb grid_major = bp::hex_rgb(0xD9D9D9);
constexpr bp::rgb grid_minor = bp::hex_rgb(0xF0F0F0);
constexpr bp::rgb palette[] = {bp::hex_rgb(0x1F77B4), bp::hex_rgb(0xD62728), bp::hex_rgb(0x2CA02C), bp::hex_rgb(0xFF7F0E),
                               bp::hex_rgb(0x9467BD), bp::hex_rgb(0x8C564B), bp::hex_rgb(0xE377C2), bp::hex_rgb(0x17BECF),
                               bp::hex_rgb(0x7F7F7F), bp::hex_rgb(0xBCBD22)};
constexpr int palette_size = int(sizeof palette / sizeof palette[0]);
constexpr int marker_kinds = 6;

constexpr double s_title = 3.0, s_text = 2.0, s_exp = 4.0 / 3.0;

double label_width(const label_text& l) {
    return bp::text_width(l.base, s_text) + (l.exponent.empty() ? 0.0 : 1.0 + bp::text_width(l.exponent, s_exp));
}

/// Draws l with its top-left at (x, y) (exponent raised above the base).
void draw_label(bp::canvas& cv, double x, double y, const label_text& l, bp::rgb c) {
    cv.text(x, y, l.base, s_text, c);
    if (!l.exponent.empty()) cv.text(x + bp::text_width(l.base, s_text) + 1.0, y - 5.0, l.exponent, s_exp, c);
}

void draw_marker(bp::canvas& cv, int kind, bp::pt p, double r, bp::rgb c) {
    const double pi = 3.14159265358979323846;
    auto ngon = [&](int n, double rad, double rot) {
        std::vector<bp::pt> v;
        for (int k = 0; k < n; ++k) {
            const double a = rot + 2.0 * pi * k / n;
            v.push_back({p.x + rad * std::cos(a), p.y + rad * std::sin(a)});
        }
        return v;
    };
    switch (kind % marker_kinds) {
    case 0: cv.disc(p, r, c); break;
    case 1: cv.fill_rect({p.x - 0.85 * r, p.y - 0.85 * r, p.x + 0.85 * r, p.y + 0.85 * r}, c); break;
    case 2: cv.convex(ngon(3, 1.25 * r, -pi / 2), c); break; // triangle up
    case 3: cv.convex(ngon(4, 1.2 * r, 0.0), c); break;      // diamond
    case 4: cv.convex(ngon(3, 1.25 * r, pi / 2), c); break;  // triangle down
    default: cv.convex(ngon(5, 1.15 * r, -pi / 2), c); break; // pentagon
    }
}

struct legend_entry {
    std::string label;
    bp::rgb colour;
    int marker;
    bool dashed;
};

constexpr double legend_pad = 10.0, legend_sample = 34.0, legend_row = 26.0;

bp::pt legend_size(const std::vector<legend_entry>& e) {
    double w = 0.0;
    for (const auto& x : e) w = std::max(w, bp::text_width(x.label, s_text));
    return {2 * legend_pad + legend_sample + 8.0 + w, 2 * legend_pad + legend_row * double(e.size()) - (legend_row - bp::font_cap * s_text)};
}

void draw_legend(bp::canvas& cv, const bp::rect& box, const std::vector<legend_entry>& e) {
    cv.fill_rect(box, white);
    cv.stroke_rect(box, 1.0, bp::hex_rgb(0xBBBBBB));
    for (std::size_t i = 0; i < e.size(); ++i) {
        const double top = box.y0 + legend_pad + legend_row * double(i);
        const double mid = top + 0.5 * bp::font_cap * s_text;
        const double x0 = box.x0 + legend_pad;
        if (e[i].dashed)
            cv.polyline({{x0, mid}, {x0 + legend_sample, mid}}, 2.0, e[i].colour, 7.0, 4.0);
        else
            cv.line({x0, mid}, {x0 + legend_sample, mid}, 2.0, e[i].colour);
        draw_marker(cv, e[i].marker, {x0 + 0.5 * legend_sample, mid}, 5.5, white);
        draw_marker(cv, e[i].marker, {x0 + 0.5 * legend_sample, mid}, 4.0, e[i].colour);
        cv.text(x0 + legend_sample + 8.0, top, e[i].label, s_text, ink);
    }
}

std::string format_knob(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

/// Axes and the plot rectangle of one layout attempt.
struct frame {
    log_axis ax, ay;
    bp::rect plot;
    std::vector<std::vector<bp::pt>> px; // curve points in pixels
};

frame make_frame(const dataset& d, const options& o, double extra_bottom, double extra_top, double legend_w) {
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
    for (const auto& c : d.curves)
        for (const auto& p : c.points) {
            xmin = std::min(xmin, p.x);
            xmax = std::max(xmax, p.x);
            ymin = std::min(ymin, p.y);
            ymax = std::max(ymax, p.y);
        }
    frame f;
    f.ax = log_axis::fit(xmin, xmax);
    f.ay = log_axis::fit(ymin, ymax, extra_bottom, extra_top);
    // Layout: title on top, y-axis title and tick labels on the left, x ones at the bottom.
    const double cap = bp::font_cap * s_text;
    double ytick_w = 0.0;
    for (const auto& t : f.ay.ticks)
        if (t.labelled) ytick_w = std::max(ytick_w, label_width(tick_label(t.value, f.ay.superscript)));
    const double top = 16.0 + bp::font_cap * s_title + 18.0 + (f.ay.superscript ? 4.0 : 0.0);
    const double left = 16.0 + bp::font_h * s_text + 14.0 + ytick_w + 10.0;
    const double bottom = 10.0 + cap + (f.ax.superscript ? 5.0 : 0.0) + 16.0 + bp::font_h * s_text + 14.0;
    double right = 24.0;
    if (o.legend == legend_pos::right) right += legend_w + 12.0;
    f.plot = {std::round(left), std::round(top), std::round(o.width - right), std::round(o.height - bottom)};
    if (f.plot.w() < 60.0 || f.plot.h() < 60.0) throw bp::bench_error("image too small for the labels and legend (use a larger --size)");
    f.px.resize(d.curves.size());
    for (std::size_t i = 0; i < d.curves.size(); ++i)
        for (const auto& p : d.curves[i].points)
            f.px[i].push_back({f.plot.x0 + f.ax.frac(p.x) * f.plot.w(), f.plot.y1 - f.ay.frac(p.y) * f.plot.h()});
    return f;
}

enum corner { top_right, top_left, bottom_right, bottom_left };

bp::rect corner_box(const bp::rect& plot, corner c, bp::pt size) {
    const double m = 10.0;
    const double x0 = (c == top_left || c == bottom_left) ? plot.x0 + m : plot.x1 - m - size.x;
    const double y0 = (c == top_left || c == top_right) ? plot.y0 + m : plot.y1 - m - size.y;
    return {std::round(x0), std::round(y0), std::round(x0 + size.x), std::round(y0 + size.y)};
}

/// How much of the curves a legend box would hide: markers weigh 20, line samples (every 4 px) 1.
long legend_hits(const frame& f, const bp::rect& box) {
    const bp::rect grown{box.x0 - 8.0, box.y0 - 8.0, box.x1 + 8.0, box.y1 + 8.0};
    long hits = 0;
    for (const auto& poly : f.px)
        for (std::size_t k = 0; k < poly.size(); ++k) {
            if (grown.contains(poly[k])) hits += 20;
            if (k + 1 == poly.size()) continue;
            const double len = std::hypot(poly[k + 1].x - poly[k].x, poly[k + 1].y - poly[k].y);
            const int n = std::max(1, int(len / 4.0));
            for (int s = 1; s < n; ++s) {
                const double t = double(s) / n;
                hits += grown.contains({poly[k].x + t * (poly[k + 1].x - poly[k].x), poly[k].y + t * (poly[k + 1].y - poly[k].y)});
            }
        }
    return hits;
}

/// Chooses the layout and the legend box: the allowed corner that hides nothing; failing that,
/// the y axis is stretched (up for a top corner, down for a bottom one) in steps until one does;
/// failing that, the corner hiding the least of the unstretched layout.
std::pair<frame, bp::rect> place_legend(const dataset& d, const options& o, bp::pt lsize) {
    if (o.legend == legend_pos::right) {
        frame f = make_frame(d, o, 0.0, 0.0, lsize.x);
        const bp::rect box{f.plot.x1 + 14.0, f.plot.y0, std::round(f.plot.x1 + 14.0 + lsize.x), std::round(f.plot.y0 + lsize.y)};
        return {std::move(f), box};
    }
    std::vector<corner> allowed;
    switch (o.legend) {
    case legend_pos::top_right: allowed = {top_right}; break;
    case legend_pos::top_left: allowed = {top_left}; break;
    case legend_pos::bottom_right: allowed = {bottom_right}; break;
    case legend_pos::bottom_left: allowed = {bottom_left}; break;
    default: allowed = {top_right, top_left, bottom_right, bottom_left}; break;
    }
    frame base = make_frame(d, o, 0.0, 0.0, 0.0);
    corner best = allowed.front();
    long best_hits = std::numeric_limits<long>::max();
    for (const corner c : allowed) {
        const long h = legend_hits(base, corner_box(base.plot, c, lsize));
        if (h == 0) return {base, corner_box(base.plot, c, lsize)};
        if (h < best_hits) {
            best_hits = h;
            best = c;
        }
    }
    for (int step = 1; step <= 12; ++step) {
        const double extra = 0.07 * step;
        for (const bool up : {true, false}) {
            frame f = make_frame(d, o, up ? 0.0 : extra, up ? extra : 0.0, 0.0);
            for (const corner c : allowed) {
                if ((c == top_left || c == top_right) != up) continue;
                if (legend_hits(f, corner_box(f.plot, c, lsize)) == 0) {
                    const bp::rect box = corner_box(f.plot, c, lsize);
                    return {std::move(f), box};
                }
            }
        }
    }
    const bp::rect box = corner_box(base.plot, best, lsize);
    return {std::move(base), box};
}

std::vector<std::uint8_t> render(const dataset& d, const options& o, const std::string& title, const std::string& xlabel,
                                 const std::string& ylabel) {
    std::vector<legend_entry> legend;
    for (std::size_t i = 0; i < d.curves.size(); ++i)
        if (!d.curves[i].points.empty())
            legend.push_back({d.curves[i].label, palette[i % palette_size], int(i % marker_kinds), d.curves[i].dashed});
    const bp::pt lsize = legend_size(legend);
    const auto [f, legend_box] = place_legend(d, o, lsize);
    const log_axis& ax = f.ax;
    const log_axis& ay = f.ay;
    const bp::rect& plot = f.plot;
    const double cap = bp::font_cap * s_text;

    bp::canvas cv(o.width, o.height, 3, white);

    // grid (minor first, then decades), ticks and tick labels
    for (int pass = 0; pass < 2; ++pass) {
        for (const auto& t : ax.ticks) {
            if (t.major != (pass == 1)) continue;
            const double x = std::floor(plot.x0 + ax.frac(t.value) * plot.w());
            cv.fill_rect({x, plot.y0, x + 1.0, plot.y1}, t.major ? grid_major : grid_minor);
        }
        for (const auto& t : ay.ticks) {
            if (t.major != (pass == 1)) continue;
            const double y = std::floor(plot.y1 - ay.frac(t.value) * plot.h());
            cv.fill_rect({plot.x0, y, plot.x1, y + 1.0}, t.major ? grid_major : grid_minor);
        }
    }
    for (const auto& t : ax.ticks) {
        const double x = std::floor(plot.x0 + ax.frac(t.value) * plot.w());
        cv.fill_rect({x, plot.y1, x + 1.0, plot.y1 + (t.major ? 6.0 : 3.0)}, frame_ink);
        if (!t.labelled) continue;
        const label_text l = tick_label(t.value, ax.superscript);
        draw_label(cv, std::round(x + 0.5 - 0.5 * label_width(l)), plot.y1 + 10.0 + (ax.superscript ? 5.0 : 0.0), l, ink);
    }
    for (const auto& t : ay.ticks) {
        const double y = std::floor(plot.y1 - ay.frac(t.value) * plot.h());
        cv.fill_rect({plot.x0 - (t.major ? 6.0 : 3.0), y, plot.x0, y + 1.0}, frame_ink);
        if (!t.labelled) continue;
        const label_text l = tick_label(t.value, ay.superscript);
        draw_label(cv, plot.x0 - 10.0 - label_width(l), std::round(y + 0.5 - 0.5 * cap), l, ink);
    }
    cv.stroke_rect({plot.x0 - 1.0, plot.y0 - 1.0, plot.x1 + 1.0, plot.y1 + 1.0}, 1.0, frame_ink);

    // titles
    {
        double ts = s_title;
        double tw = bp::text_width(title, ts);
        if (tw > o.width - 40.0) { // shrink a long title to fit
            ts = s_text;
            tw = bp::text_width(title, ts);
        }
        cv.text(std::round(0.5 * (o.width - tw)), 16.0, title, ts, ink);
        const double xw = bp::text_width(xlabel, s_text);
        cv.text(std::round(plot.x0 + 0.5 * (plot.w() - xw)), o.height - 14.0 - bp::font_h * s_text, xlabel, s_text, ink);
        const double yw = bp::text_width(ylabel, s_text);
        cv.text(16.0, std::round(plot.y0 + 0.5 * (plot.h() + yw)), ylabel, s_text, ink, true);
    }

    // curves, clipped to the frame: lines, then markers on top
    cv.set_clip({plot.x0, plot.y0, plot.x1, plot.y1});
    for (std::size_t i = 0; i < d.curves.size(); ++i) {
        if (d.curves[i].dashed)
            cv.polyline(f.px[i], 2.0, palette[i % palette_size], 8.0, 5.0);
        else
            cv.polyline(f.px[i], 2.0, palette[i % palette_size]);
    }
    std::vector<bp::rect> taken{legend_box}; // for the annotations: what they must not cover
    for (std::size_t i = 0; i < d.curves.size(); ++i)
        for (const auto& q : f.px[i]) {
            draw_marker(cv, int(i % marker_kinds), q, 6.0, white);
            draw_marker(cv, int(i % marker_kinds), q, 4.5, palette[i % palette_size]);
            taken.push_back({q.x - 6.0, q.y - 6.0, q.x + 6.0, q.y + 6.0});
        }
    if (o.annotate != annotate_mode::none) {
        for (std::size_t i = 0; i < d.curves.size(); ++i) {
            const auto& pts = d.curves[i].points;
            for (std::size_t k = 0; k < pts.size(); ++k) {
                if (!pts[k].knob) continue;
                if (o.annotate == annotate_mode::ends && k != 0 && k + 1 != pts.size()) continue;
                const std::string s = format_knob(*pts[k].knob);
                const double w = bp::text_width(s, s_exp), h = bp::font_cap * s_exp;
                const bp::pt q = f.px[i][k];
                // candidate boxes: upper right, lower right, upper left, lower left, right, left
                const bp::rect cand[] = {
                    {q.x + 6.0, q.y - 6.0 - h, q.x + 6.0 + w, q.y - 6.0}, {q.x + 6.0, q.y + 6.0, q.x + 6.0 + w, q.y + 6.0 + h},
                    {q.x - 6.0 - w, q.y - 6.0 - h, q.x - 6.0, q.y - 6.0}, {q.x - 6.0 - w, q.y + 6.0, q.x - 6.0, q.y + 6.0 + h},
                    {q.x + 9.0, q.y - 0.5 * h, q.x + 9.0 + w, q.y + 0.5 * h},  {q.x - 9.0 - w, q.y - 0.5 * h, q.x - 9.0, q.y + 0.5 * h},
                };
                const bp::rect* pick = nullptr;
                for (const bp::rect& c : cand) {
                    const bool inside = c.x0 >= plot.x0 + 2 && c.x1 <= plot.x1 - 2 && c.y0 >= plot.y0 + 2 && c.y1 <= plot.y1 - 2;
                    const bool free = std::none_of(taken.begin(), taken.end(), [&](const bp::rect& t) { return t.intersects(c); });
                    if (inside && free) {
                        pick = &c;
                        break;
                    }
                }
                if (!pick) continue; // no room: leave this point unlabelled rather than overprint
                taken.push_back(*pick);
                cv.text(std::round(pick->x0), std::round(pick->y0), s, s_exp, palette[i % palette_size]);
            }
        }
    }
    cv.reset_clip();

    if (!legend.empty()) draw_legend(cv, legend_box, legend);
    return cv.resolve();
}

void write_png(const std::string& path, int w, int h, const std::vector<std::uint8_t>& rgb) {
    const std::string tmp = path + ".tmp";
    if (!stbi_write_png(tmp.c_str(), w, h, 3, rgb.data(), w * 3)) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw bp::bench_error(path + ": cannot write PNG");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw bp::bench_error(path + ": cannot rename the temporary PNG into place");
    }
}

int run(const options& o) {
    std::vector<bp::bench_record> rows;
    bp::load_stats stats;
    for (const auto& in : o.inputs) {
        const std::string text = read_file(in);
        bp::json_value doc;
        try {
            doc = bp::parse_json(text);
        } catch (const bp::json_error& e) {
            throw bp::bench_error(in + ":" + e.what() + " (malformed JSON)");
        }
        auto r = bp::load_benchmarks(doc, in, stats);
        if (r.empty()) std::cerr << "bench_plot: warning: " << in << ": no benchmark rows\n";
        rows.insert(rows.end(), std::make_move_iterator(r.begin()), std::make_move_iterator(r.end()));
    }
    if (stats.skipped_errors) std::cerr << "bench_plot: warning: skipped " << stats.skipped_errors << " failed benchmark run(s)\n";
    const dataset d = build_curves(rows, o);

    std::string xlabel = o.xlabel, ylabel = o.ylabel, title = o.title;
    if (xlabel.empty()) {
        if (o.x == "real_time") xlabel = "time per iteration (ms, wall clock)";
        else if (o.x == "cpu_time") xlabel = "CPU time per iteration (ms)";
        else if (o.x == "knob") xlabel = o.knob.empty() ? "argument" : o.knob;
        else xlabel = o.x;
    }
    if (ylabel.empty()) ylabel = o.y.text;
    if (title.empty()) title = ylabel + " against " + xlabel;

    if (!o.quiet) {
        for (const auto& c : d.curves) {
            std::cout << c.label << " (" << c.points.size() << " points)\n";
            for (const auto& p : c.points) {
                char buf[160];
                std::snprintf(buf, sizeof buf, "  x %-12.5g y %-12.5g ", p.x, p.y);
                std::cout << buf << p.name << '\n';
            }
        }
    }
    write_png(o.output, o.width, o.height, render(d, o, title, xlabel, ylabel));
    if (!o.quiet) std::cout << "wrote " << o.output << " (" << o.width << "x" << o.height << ")\n";
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    try {
        return run(parse_args(argc, argv));
    } catch (const usage_error& e) {
        std::cerr << "bench_plot: " << e.what() << "\n(bench_plot --help for usage)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "bench_plot: error: " << e.what() << '\n';
        return 1;
    }
}
