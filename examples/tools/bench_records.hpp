// bench_records.hpp — the benchmark rows of Google Benchmark JSON output (--benchmark_format=json
// or --benchmark_out=file.json) as flat records: the run name split into its family and its
// arguments, the times per iteration in milliseconds, and every numeric field (user counters
// included) by name.
#pragma once

#include "json_value.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace bench_plot {

using ibl_examples::json_value;
using ibl_examples::json_error;
using ibl_examples::parse_json;


struct bench_error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct bench_arg {
    std::string name;  // "spp" for ".../spp:64/...", "arg0", "arg1", ... for unnamed arguments
    double value = 0.0;
    std::size_t token = 0; // index of the name token it came from (0 = the function name)
};

struct bench_record {
    std::string file;
    std::string name;                      // run_name (the benchmark name without aggregate suffix)
    std::vector<std::string> tokens;       // name split at '/'
    std::vector<bench_arg> args;
    double real_ms = 0.0, cpu_ms = 0.0;    // per iteration
    std::map<std::string, double> numbers; // every numeric member (counters, iterations, ...)

    [[nodiscard]] const bench_arg* arg(std::string_view n) const {
        for (const auto& a : args)
            if (a.name == n) return &a;
        return nullptr;
    }
    [[nodiscard]] std::optional<double> number(const std::string& n) const {
        const auto it = numbers.find(n);
        if (it == numbers.end()) return std::nullopt;
        return it->second;
    }
};

namespace detail {

inline std::vector<std::string> split(std::string_view s, char sep) {
    std::vector<std::string> out;
    std::size_t b = 0;
    for (;;) {
        const std::size_t e = s.find(sep, b);
        out.emplace_back(s.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b));
        if (e == std::string_view::npos) return out;
        b = e + 1;
    }
}

inline std::optional<double> parse_double(std::string_view s) {
    if (s.empty()) return std::nullopt;
    double v = 0.0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
    return v;
}

/// Name tokens that are run options rather than arguments ("real_time", "threads:2", ...).
inline bool is_option_token(std::string_view key) {
    return key == "real_time" || key == "manual_time" || key == "process_time" || key == "threads" ||
           key == "min_time" || key == "min_warmup_time" || key == "iterations" || key == "repeats";
}

inline double ms_per_unit(const std::string& unit, const std::string& where) {
    if (unit == "ns") return 1e-6;
    if (unit == "us") return 1e-3;
    if (unit == "ms") return 1.0;
    if (unit == "s") return 1e3;
    throw bench_error(where + ": unknown time_unit \"" + unit + "\"");
}

} // namespace detail

/// Splits a run name into tokens and arguments.
inline void split_name(bench_record& r) {
    r.tokens = detail::split(r.name, '/');
    int unnamed = 0;
    for (std::size_t k = 1; k < r.tokens.size(); ++k) {
        const std::string& t = r.tokens[k];
        const std::size_t colon = t.find(':');
        if (colon == std::string::npos) {
            if (const auto v = detail::parse_double(t)) r.args.push_back({"arg" + std::to_string(unnamed++), *v, k});
            continue;
        }
        const std::string key = t.substr(0, colon);
        if (detail::is_option_token(key)) continue;
        if (const auto v = detail::parse_double(std::string_view(t).substr(colon + 1))) r.args.push_back({key, *v, k});
    }
}

struct load_stats {
    int skipped_errors = 0;     // rows with error_occurred
    int skipped_aggregates = 0; // mean/median/stddev rows of --benchmark_repetitions
};

/// The iteration rows of one Google Benchmark JSON document (aggregates and failed runs are
/// skipped and counted). Throws bench_error on a document that is not benchmark output.
inline std::vector<bench_record> load_benchmarks(const json_value& doc, const std::string& file, load_stats& stats) {
    if (!doc.is_object()) throw bench_error(file + ": not a Google Benchmark JSON document (top level is not an object)");
    const json_value* list = doc.find("benchmarks");
    if (!list || !list->is_array())
        throw bench_error(file + ": not a Google Benchmark JSON document (no \"benchmarks\" array)");
    std::vector<bench_record> out;
    std::size_t index = 0;
    for (const json_value& b : list->values) {
        const std::string where = file + ": benchmarks[" + std::to_string(index++) + "]";
        if (!b.is_object()) throw bench_error(where + " is not an object");
        if (const json_value* e = b.find("error_occurred"); e && e->is_bool() && e->boolean) {
            ++stats.skipped_errors;
            continue;
        }
        if (const json_value* t = b.find("run_type"); t && t->is_string() && t->string == "aggregate") {
            ++stats.skipped_aggregates;
            continue;
        }
        bench_record r;
        r.file = file;
        const json_value* name = b.find("run_name");
        if (!name || !name->is_string()) name = b.find("name");
        if (!name || !name->is_string()) throw bench_error(where + " has no \"name\"");
        r.name = name->string;
        const std::string at = file + ": " + r.name;
        const json_value* unit = b.find("time_unit");
        const double scale = detail::ms_per_unit(unit && unit->is_string() ? unit->string : std::string("ns"), at);
        const json_value* real = b.find("real_time");
        const json_value* cpu = b.find("cpu_time");
        if (!real || !real->is_number() || !cpu || !cpu->is_number()) throw bench_error(at + ": no numeric real_time / cpu_time");
        r.real_ms = real->number * scale;
        r.cpu_ms = cpu->number * scale;
        for (std::size_t i = 0; i < b.keys.size(); ++i)
            if (b.values[i].is_number()) r.numbers[b.keys[i]] = b.values[i].number;
        split_name(r);
        out.push_back(std::move(r));
    }
    return out;
}

} // namespace bench_plot
