#pragma once
// tools/ibl-bake/query/probe_lookup.hpp — `ibl-bake --lookup DIR` on a probe-set folder (the
// output of --probes: probes.json + probes.ktx2, stages/probe_bake.hpp). Queries on stdin, one
// answer line each, the line rules of query/lookup.hpp (# comments, "error: line L: ..." lines,
// exit status 1 when a query was not answered, 9 significant digits):
//   local PX PY PZ DX DY DZ R        -> r g b   blended, parallax-corrected specular LD at the point
//                                     P for the reflection direction D (normalised), roughness R
//   local_irradiance PX PY PZ NX NY NZ -> r g b  blended SH irradiance E (not E/pi) at P, normal N
// Per probe i: the influence weight w_i = ibl::influence_weight(influence, fade, P), the
// contributions c_i = ibl::blend_probe_weights(w, priority) (higher priority first). A probe set
// has no distant environment, so the fallback share is not used: the c_i are divided by their sum
// when it is > 0; when every w_i is 0 (P outside every influence volume) the nearest probe (the
// distance from P to its position; the first on ties) answers alone, without parallax correction.
// local: each contributing probe's chain (the decoded layer of probes.ktx2) read by
// ibl::specular_lookup with the textbook desc and the chain's mapping at
// ibl::parallax_correct(proxy, position, P, D).direction and ibl::corrected_roughness(R, that
// lookup) (its distances and the proxy's slopes at the hit). local_irradiance: max(0, sh_evaluate(sh_irradiance_i, N)) per probe.
// The words of a single bake (specular, irradiance, ...) get an error line on a probe set.

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include <ibl/env/cubemap.hpp>
#include <ibl/runtime/local_probe.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/sh/basis.hpp>

namespace ibl_bake {

struct loaded_probe {
    int layer = 0;
    ibl::vec3<double> position{0.0};
    bool proxy_sphere = false, influence_sphere = false;
    ibl::probe_box<double> proxy_box, influence_box;
    ibl::probe_sphere<double> proxy_ball, influence_ball;
    double fade = 1.0;
    int priority = 0;
    ibl::sh_coeffs<double, 3> irradiance{};
    ibl::cubemap<float> chain{1};
};

struct probe_set_folder {
    std::vector<loaded_probe> probes;
    ibl::specular_lookup_desc specular = ibl::specular_lookup_desc::textbook();
};

/// True when DIR holds probes.json (a --probes output) and either no report.json or a probe-set report
/// (its "format" is probe_report_format, stages/probe_bake.hpp).
bool is_probe_set_folder(const std::string& dir);

/// Loads DIR's probes.json and probes.ktx2. Throws image_error / std::runtime_error naming the file.
probe_set_folder load_probe_set(const std::string& dir);

/// The normalised contributions of the probes at p (see the header); sums to 1.
std::vector<double> probe_contributions(const probe_set_folder& s, const ibl::vec3<double>& p);

/// The answers of `local` and `local_irradiance`.
ibl::vec3<double> local_specular(const probe_set_folder& s, const ibl::vec3<double>& p, const ibl::vec3<double>& d, double roughness);
ibl::vec3<double> local_irradiance(const probe_set_folder& s, const ibl::vec3<double>& p, const ibl::vec3<double>& n);

/// Answers the queries of `in` on `out`. Returns the exit status (0 or 1).
int run_probe_lookup(const probe_set_folder& s, std::istream& in, std::ostream& out);

} // namespace ibl_bake
