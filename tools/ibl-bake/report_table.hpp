#pragma once
// tools/ibl-bake/report_table.hpp — the rows of the printed report and number formatting.

#include <cstdio>
#include <string>
#include <vector>

namespace ibl_bake {

/// One line of the printed table: product, method, cost knob, time (ms; < 0: none), error.
struct table_row {
    std::string product, method, cost;
    double ms = 0.0;
    std::string error;
};

/// printf-style formatting of one or two numbers into a std::string.
std::string fmt(const char* f, double a);
std::string fmt2(const char* f, double a, double b);

/// The table with aligned columns.
void print_table(std::FILE* out, const std::vector<table_row>& rows);

} // namespace ibl_bake
