// tools/ibl-bake/report/report_table.cpp — see report_table.hpp.

#include "report/report_table.hpp"

#include <algorithm>

namespace ibl_bake {

std::string fmt(const char* f, double a) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a);
    return buf;
}

std::string fmt2(const char* f, double a, double b) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a, b);
    return buf;
}

namespace {

/// text split at spaces into pieces of at most `width` characters (a longer word stays whole).
std::vector<std::string> wrap(const std::string& text, std::size_t width) {
    std::vector<std::string> out;
    std::string line;
    std::size_t b = 0;
    while (b < text.size()) {
        std::size_t e = text.find(' ', b);
        if (e == std::string::npos) e = text.size();
        const std::string word = text.substr(b, e - b);
        if (!line.empty() && line.size() + 1 + word.size() > width) {
            out.push_back(line);
            line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
        b = e + 1;
    }
    if (!line.empty() || out.empty()) out.push_back(line);
    return out;
}

std::string time_text(double ms) { return ms >= 0 ? fmt("%.1f", ms) : ""; }

constexpr const char* meaning_mark = "  ! ";

} // namespace

void print_wrapped(std::FILE* out, const std::string& text, std::size_t indent) {
    const std::vector<std::string> first = wrap(text, compact_width - 1);
    std::fprintf(out, "%s\n", first[0].c_str());
    if (first.size() == 1) return;
    const std::string rest = text.substr(std::min(text.size(), first[0].size() + 1));
    for (const auto& l : wrap(rest, compact_width - 1 - indent)) std::fprintf(out, "%*s%s\n", int(indent), "", l.c_str());
}

void print_table(std::FILE* out, const std::vector<table_row>& rows) {
    std::size_t w[4] = {7, 6, 9, 5};
    for (const auto& r : rows) {
        if (r.summary) continue;
        w[0] = std::max(w[0], r.product.size());
        w[1] = std::max(w[1], r.method.size());
        w[2] = std::max(w[2], r.cost.size());
        w[3] = std::max(w[3], r.error.size());
    }
    auto line = [&](const std::string& a, const std::string& b, const std::string& c, const std::string& d,
                    const std::string& e) {
        std::fprintf(out, "%-*s  %-*s  %-*s  %9s  %s\n", int(w[0]), a.c_str(), int(w[1]), b.c_str(), int(w[2]),
                     c.c_str(), d.c_str(), e.c_str());
    };
    line("product", "method", "cost knob", "time (ms)", "error");
    std::fprintf(out, "%s\n", std::string(w[0] + w[1] + w[2] + w[3] + 19, '-').c_str());
    for (const auto& r : rows) {
        if (r.summary) continue;
        line(r.product, r.method, r.cost, time_text(r.ms), r.error);
        if (!r.meaning.empty()) std::fprintf(out, "%s%s\n", meaning_mark, r.meaning.c_str());
    }
}

void print_compact_table(std::FILE* out, const std::vector<table_row>& rows) {
    constexpr std::size_t max_product = 22, max_brief = 24, time_w = 8;
    std::size_t w0 = 7, w1 = 6;
    for (const auto& r : rows) {
        if (r.detail) continue;
        w0 = std::max(w0, std::min(max_product, r.product.size()));
        w1 = std::max(w1, std::min(max_brief, (r.brief.empty() ? r.method : r.brief).size()));
    }
    const std::size_t col = w0 + 2 + w1 + 2 + time_w + 2;
    const std::size_t avail = compact_width - 1 - col;
    auto cut = [](const std::string& s, std::size_t n) { return s.size() <= n ? s : s.substr(0, n - 1) + "~"; };
    auto line = [&](const std::string& a, const std::string& b, const std::string& t, const std::string& e) {
        const std::vector<std::string> parts = wrap(e, avail);
        std::fprintf(out, "%-*s  %-*s  %*s  %s\n", int(w0), cut(a, w0).c_str(), int(w1), cut(b, w1).c_str(), int(time_w), t.c_str(),
                     parts[0].c_str());
        for (std::size_t k = 1; k < parts.size(); ++k) std::fprintf(out, "%*s%s\n", int(col), "", parts[k].c_str());
    };
    line("product", "method", "ms", "error (metric)");
    std::fprintf(out, "%s\n", std::string(compact_width - 1, '-').c_str());
    for (const auto& r : rows) {
        if (r.detail) continue;
        line(r.product, r.brief.empty() ? r.method : r.brief, time_text(r.ms), r.headline.empty() ? r.error : r.headline);
        if (!r.meaning.empty()) {
            const std::string mark = meaning_mark;
            const std::vector<std::string> parts = wrap(r.meaning, compact_width - 1 - mark.size());
            for (const auto& p : parts) std::fprintf(out, "%s%s\n", mark.c_str(), p.c_str());
        }
    }
}

const std::vector<std::pair<std::string, std::string>>& metric_definitions() {
    static const std::vector<std::pair<std::string, std::string>> d = {
        {"rel_rmse", "relative RMSE: the root mean square over the compared RGB elements of (product - reference) / "
                     "max(|reference|, floor), the floor 1e-3 x the mean radiance (relative_error_floor)"},
        {"nrmse", "normalised RMSE: sqrt(sum (product - reference)^2 / sum reference^2) over the compared RGB elements "
                  "(dominated by the bright regions)"},
        {"max_overshoot", "the largest ratio product / reference over the compared RGB elements whose reference is above the "
                          "floor (1 = no overshoot; 2 = some element is twice its reference)"},
        {"max_rel", "the largest relative error |product - reference| / max(|reference|, floor) over the compared values "
                    "(RGB elements; for irradiance the RGB sum of E at each check normal)"},
        {"mean_rel", "the mean over the check normals of |E_product - E_reference| / E_reference, E the RGB sum of the "
                     "irradiance"},
        {"mean_rel_unwindowed", "mean_rel of the SH irradiance before the window (the raw projection)"},
        {"max_rel_unwindowed", "max_rel of the SH irradiance before the window (the raw projection)"},
        {"max_abs", "the largest absolute difference |product - reference| over the compared values (DFG: A and B, both in "
                    "[0, 1])"},
        {"max_abs_a", "the largest |A_lookup - A_exact| of the DFG table's bilinear lookup over the check points"},
        {"max_abs_b", "the largest |B_lookup - B_exact| of the DFG table's bilinear lookup over the check points"},
        {"rms", "the root mean square of |lookup - exact| over A and B at the DFG lookup check's points"},
        {"max_rel_error", "storage: the largest |decoded - float| / max(|float|, floor) over the level's stored values, floor "
                          "1e-3 x the level's mean |value|"},
        {"rms_rel_error", "storage: the root mean square of |decoded - float| / max(|float|, floor) over the level's stored values"},
        {"total_rel_rmse", "relative RMSE of the luminance of the chain's lookup at roughness r against the exact LD at r over "
                           "the check directions (floor 1e-3 x the mean)"},
        {"interpolation_rel_rmse", "relative RMSE of the lookup's blend of exact levels against the exact LD at r: the part "
                                   "of the error due to the levels' spacing"},
        {"levels_rel_rmse", "relative RMSE of the lookup against the same blend of exact levels: the part of the error due to "
                            "the baked levels themselves"},
        {"total_max_rel", "the largest relative error of the lookup's luminance against the exact LD at r over the check "
                          "directions"},
        {"rel", "Y_model / Y_reference - 1: the signed relative error of the shaded luminance in one view"},
        {"mean_abs_rel", "the mean over the views of |Y_model / Y_reference - 1|, Y the shaded luminance"},
        {"mean_abs_rel_std_error", "the standard error of mean_abs_rel from the MIS reference's own noise: sqrt(sum over "
                                   "the views of ((1 + rel) se_rel)^2) / views"},
        {"split_sum_mean_abs_rel", "mean_abs_rel of the plain split sum (LD(R, r) (F0 A + F90 B)) at the same views, the "
                                   "figure the runtime model is compared with ('excess' = model - split sum, 'noise' = 2 "
                                   "sqrt(se_model^2 + se_split^2); 'worse' when excess > noise)"},
        {"max_abs_rel", "the largest over the views of |Y_model / Y_reference - 1|, Y the shaded luminance"},
        {"reference_rel_std_error", "the Monte Carlo reference's own relative standard error (its noise): an error below "
                                    "about twice it is not resolved"},
        {"ab_vs_dfg_max_abs", "the largest |A - A_dfg|, |B - B_dfg| of the table's (A, B) against the DFG table read at the "
                              "table's texels"},
        {"l1", "L1 distances integral |p - q| between the normalised specular lobe p and the chain kernel(s) q standing for "
               "it: 0 = identical, 2 = disjoint"},
        {"mean_l1", "the mean over the fitted texels of the L1 distance of each texel's fit to the specular lobe (2 = disjoint)"},
        {"max_l1", "the largest over the fitted texels of the L1 distance of each texel's fit to the specular lobe"},
        {"rel_rms", "the root mean square over the shading points of the relative error of the ambient luminance against the "
                    "converged products"},
        {"nrmse_planned", "nrmse of a level of the scene plan's chain against the reference LD at the check texels"},
        {"nrmse_full", "nrmse of the same level of the full bake's chain against the reference LD at the check texels"},
        {"nrmse_vs_converged_planned", "nrmse of a level of the scene plan's chain against the converged chain"},
        {"nrmse_vs_converged_full", "nrmse of the same level of the full bake's chain against the converged chain"},
        {"expected_nrmse_vs_converged", "the plan's cost model's predicted nrmse of the level against the converged chain"},
        {"expected_nrmse", "the plan's cost model's predicted nrmse of a level against the converged chain"},
        {"expected_max_abs", "the plan's cost model's predicted largest absolute error of the DFG table"},
        {"lut_max_abs_vs_sheen_albedo", "the largest |E_table - E_exact| of the sheen albedo table against ibl::sheen_albedo"},
    };
    return d;
}

} // namespace ibl_bake
