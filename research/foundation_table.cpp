// research/foundation_table.cpp — the library's first report: the directional albedo E(n.v, r) of the two
// shipped GGX models (Fresnel = 1), estimated the way the literature's DFG shaders do it
// (Hammersley + GGX NDF importance sampling, 1024 samples) next to a converged estimate
// (2^20 samples, double), with the error and the time of each.
//
//   E(mu, r) = integral over the hemisphere of f(v, l) n.l d(omega_l),  f = D V (F = 1)
//   estimator: (1/N) sum_i M::sample_weight(n.v, n.l_i, n.h_i, v.h_i, r),  h_i ~ D(h) n.h
//
// A baseline kept for comparison: the bake tool (tools/ibl-bake, run by scripts/main.sh) bakes and
// reports the DFG table by exact quadrature (bake/dfg_lut.hpp's make_dfg_lut_exact) instead.
// Produces: no docs table. Run with
//   cmake --preset release && cmake --build --preset release --target foundation_table
//   ./build/release/research/foundation_table
#include <ibl/ibl.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace {

template <class Model, class T> T albedo_mc(T n_dot_v, T roughness, std::uint32_t n) {
    const ibl::vec3<T> v(ibl::sin_from_cos(n_dot_v), T(0), n_dot_v);
    const T alpha = Model::alpha(roughness);
    ibl::neumaier_sum<T> sum;
    for (std::uint32_t i = 0; i < n; ++i) {
        const ibl::vec3<T> h = ibl::sample_ggx_ndf(ibl::hammersley<T>(i, n), alpha);
        const T v_dot_h = glm::dot(v, h);
        const ibl::vec3<T> l = T(2) * v_dot_h * h - v;
        sum.add(Model::sample_weight(n_dot_v, l.z, h.z, v_dot_h, roughness));
    }
    return sum.value() / T(n);
}

template <class Model> void table() {
    std::printf("\nmodel %s: directional albedo E(n.v, r), F = 1\n", Model::name);
    std::printf("%6s %6s | %10s %10s | %10s %9s\n", "r", "n.v", "E (1024)", "E (2^20)", "|error|", "time/us");
    double worst = 0, total_us = 0;
    for (double r : {0.1, 0.3, 0.5, 0.7, 1.0}) {
        for (double mu : {0.05, 0.25, 0.5, 1.0}) {
            const auto t0 = std::chrono::steady_clock::now();
            const float e1024 = albedo_mc<Model>(float(mu), float(r), 1024);
            const auto t1 = std::chrono::steady_clock::now();
            const double eref = albedo_mc<Model>(mu, r, 1u << 20);
            const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
            const double err = std::fabs(double(e1024) - eref);
            worst = err > worst ? err : worst;
            total_us += us;
            std::printf("%6.2f %6.2f | %10.6f %10.6f | %10.2e %9.1f\n", r, mu, double(e1024), eref, err, us);
        }
    }
    std::printf("largest error of the 1024-sample estimate: %.3e (total %.0f us for 20 texels)\n", worst, total_us);
}

} // namespace

int main() {
    std::printf("ibl %d.%d.%d foundation report\n", ibl::version_major, ibl::version_minor, ibl::version_patch);
    table<ibl::ggx_schlick_ibl>();
    table<ibl::ggx_height_correlated>();
    return 0;
}
