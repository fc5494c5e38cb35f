#pragma once
// tools/ibl-bake/report/report_table.hpp — the rows of the printed report, number formatting, the alarm
// thresholds and the definitions of the report's metric names.
//
// The printed report has two forms: the compact table (the default, every line under 100
// columns: product, the method in short words, time, the headline error figure with its metric
// name, and under an alarming figure one line saying what it means) and the wide table
// (--verbose: every column and every sub-row). report.json is the full record either way.

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace ibl_bake {

/// Thresholds above which a figure is alarming: the compact report prints a line under it saying
/// what it means, and report.json lists it under checks.alarms (docs/ibl-bake.md, "Reading the
/// report").
inline constexpr double alarm_relative = 0.05;     ///< relative errors (rel RMSE, mean or max |rel|): 5%
inline constexpr double alarm_absolute = 0.01;     ///< absolute errors of [0, 1] tables (DFG A, B)
inline constexpr double alarm_quantisation = 0.01; ///< storage's max relative error: 1% (or any value clamped)

/// One line of the printed table: product, method, cost knob, time (ms; < 0: none), error.
struct table_row {
    std::string product, method, cost;
    double ms = 0.0;
    std::string error;
    bool detail = false;   ///< a sub-row (a level, a second model or lookup): printed with --verbose only
    bool summary = false;  ///< a compact-table row only (the wide table prints the detail rows it sums up)
    std::string brief{};   ///< the method in short words for the compact table (empty: method)
    std::string headline{}; ///< the headline error figure with its metric name (empty: error)
    std::string meaning{}; ///< set when a figure is alarming: one line saying what it means

    /// Sets the compact columns.
    table_row& compact(std::string b, std::string h) {
        brief = std::move(b);
        headline = std::move(h);
        return *this;
    }
    /// Sets `meaning` when value > threshold (an alarming figure).
    table_row& alarm(double value, double threshold, std::string what) {
        if (value > threshold) meaning = std::move(what);
        return *this;
    }
};

/// printf-style formatting of one or two numbers into a std::string.
std::string fmt(const char* f, double a);
std::string fmt2(const char* f, double a, double b);

/// The wide table with aligned columns (--verbose): every row but the summaries, an alarming
/// row's meaning under it.
void print_table(std::FILE* out, const std::vector<table_row>& rows);

/// Columns of the compact report: every line it prints is shorter than this.
inline constexpr std::size_t compact_width = 100;

/// The compact table (the default): rows without `detail`, product, brief method, time and the
/// headline figure, long figures wrapped, an alarming row's meaning on a line under it.
void print_compact_table(std::FILE* out, const std::vector<table_row>& rows);

/// Prints text wrapped at spaces into lines shorter than compact_width, continuation lines
/// indented by `indent` spaces (a word longer than a line is printed whole).
void print_wrapped(std::FILE* out, const std::string& text, std::size_t indent);

/// The metric names report.json may use (its keys), each with a one-sentence definition.
const std::vector<std::pair<std::string, std::string>>& metric_definitions();

} // namespace ibl_bake
