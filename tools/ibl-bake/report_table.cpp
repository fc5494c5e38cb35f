// tools/ibl-bake/report_table.cpp — see report_table.hpp.

#include "report_table.hpp"

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

void print_table(std::FILE* out, const std::vector<table_row>& rows) {
    std::size_t w[4] = {7, 6, 9, 5};
    for (const auto& r : rows) {
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
    for (const auto& r : rows) line(r.product, r.method, r.cost, r.ms >= 0 ? fmt("%.1f", r.ms) : "", r.error);
}

} // namespace ibl_bake
