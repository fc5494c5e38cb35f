// tools/ibl-bake/fuzz/fuzz_probes.cpp — libFuzzer harness over the probe-set reader of ibl-bake
// --probes: ibl_bake::parse_probes (JSON syntax, the probes' keys and values).
// Contract under test: any text either gives 1..probe_set_max probes whose numbers are finite,
// boxes ordered (oriented ones: half extents >= 0, axes orthonormal), radii and fades > 0, or throws ibl_bake::probes_error; anything else (a crash, a
// sanitizer report, another exception, a hang, a leak, a probe breaking the rules) is a finding.
//
// Build and run: scripts/fuzz_tool.sh (clang++ -fsanitize=fuzzer,address,undefined).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "io/probes_reader.hpp"

namespace {
bool finite3(const std::array<double, 3>& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }
bool valid(const ibl_bake::probe_volume_desc& v) {
    if (v.sphere) return finite3(v.center) && std::isfinite(v.radius) && v.radius > 0.0;
    if (v.oriented) {
        if (!finite3(v.center) || !finite3(v.half_extents) || v.half_extents[0] < 0.0 || v.half_extents[1] < 0.0 ||
            v.half_extents[2] < 0.0)
            return false;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                const auto& a = v.axes[std::size_t(i)];
                const auto& b = v.axes[std::size_t(j)];
                const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                if (!(std::fabs(d - (i == j ? 1.0 : 0.0)) <= 1e-9)) return false; // orthonormal
            }
        return true;
    }
    return finite3(v.min) && finite3(v.max) && v.min[0] <= v.max[0] && v.min[1] <= v.max[1] && v.min[2] <= v.max[2];
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const auto probes = ibl_bake::parse_probes(text, "fuzz.json", (size > 0 && (data[0] & 1)) ? "base" : "");
        if (probes.empty() || probes.size() > ibl_bake::probe_set_max) std::abort();
        for (const auto& p : probes)
            if (p.input.empty() || !finite3(p.position) || !valid(p.proxy) || !valid(p.influence) || !(p.fade > 0.0) ||
                !std::isfinite(p.fade))
                std::abort();
    } catch (const ibl_bake::probes_error&) {
    }
    return 0;
}
