// core/: safe math edges, the Duff orthonormal basis, compensated and pairwise sums, executors.
#include <doctest/doctest.h>

#include <ibl/core.hpp>
#include <ibl/core/executor.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <atomic>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>
#if defined(__unix__)
#include <csignal>
#include <sys/wait.h>
#include <unistd.h>
#endif

TEST_CASE_TEMPLATE("safe math: clamps, NaN handling and exact corners", T, float, double) {
    const T nan = std::numeric_limits<T>::quiet_NaN();
    SUBCASE("saturate") {
        CHECK(ibl::saturate(T(-1)) == T(0));
        CHECK(ibl::saturate(T(2)) == T(1));
        CHECK(ibl::saturate(T(0.25)) == T(0.25));
        CHECK(ibl::saturate(nan) == T(0)); // documented: NaN -> 0
    }
    SUBCASE("safe_sqrt of a rounded negative is 0, NaN is 0") {
        CHECK(ibl::safe_sqrt(T(-1e-30)) == T(0));
        CHECK(ibl::safe_sqrt(nan) == T(0));
        CHECK(ibl::safe_sqrt(T(4)) == T(2));
    }
    SUBCASE("safe_asin/acos at and beyond +-1") {
        CHECK(ibl::safe_acos(T(1) + ibl::epsilon_v<T>) == T(0));
        CHECK(ibl::safe_asin(T(-2)) == doctest::Approx(-ibl::half_pi_v<T>));
    }
    SUBCASE("sin_from_cos keeps relative accuracy near cos = 1") {
        // cos = 1 - eps: sin = sqrt(eps (2 - eps)); the factored form has relative error ~ eps.
        const T c = T(1) - ibl::epsilon_v<T>;
        const double exact = std::sqrt(double(ibl::epsilon_v<T>) * (2.0 - double(ibl::epsilon_v<T>)));
        CHECK(double(ibl::sin_from_cos(c)) == doctest::Approx(exact).epsilon(4 * double(ibl::epsilon_v<T>)));
        CHECK(ibl::sin_from_cos(T(1)) == T(0));
        CHECK(ibl::sin_from_cos(T(-1)) == T(0));
    }
    SUBCASE("sqr_minus_one is exact at 0 and 1") {
        CHECK(ibl::sqr_minus_one(T(0)) == T(-1));
        CHECK(ibl::sqr_minus_one(T(1)) == T(0));
    }
    SUBCASE("pow5 and constants") {
        CHECK(ibl::pow5(T(0.5)) == T(0.03125));
        CHECK(ibl::one_minus_epsilon_v<T> < T(1));
        CHECK(ibl::one_minus_epsilon_v<T> + ibl::epsilon_v<T> / T(2) == T(1));
        CHECK(ibl::pi_v<T> * ibl::inv_pi_v<T> == doctest::Approx(T(1)));
    }
}

TEST_CASE_TEMPLATE("make_frame is orthonormal and right-handed everywhere, including n = -z", T, float, double) {
    // Orthonormality error of Duff et al.'s construction is a few ulps: bound 8 eps.
    const T tol = T(8) * ibl::epsilon_v<T>;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g;
    std::vector<ibl::vec3<T>> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, -0.0}};
    normals.push_back(glm::normalize(ibl::vec3<T>(T(1e-7), T(-1e-7), T(-1))));
    for (int i = 0; i < 2000; ++i)
        normals.push_back(glm::normalize(ibl::vec3<T>(T(g(rng)), T(g(rng)), T(g(rng)))));
    for (const auto& n0 : normals) {
        const ibl::vec3<T> n = n0.z == T(0) && n0.x == T(0) && n0.y == T(0) ? ibl::vec3<T>(0, 0, 1) : n0;
        const auto f = ibl::make_frame(n);
        CHECK(std::fabs(glm::dot(f.t, f.t) - T(1)) <= tol);
        CHECK(std::fabs(glm::dot(f.b, f.b) - T(1)) <= tol);
        CHECK(std::fabs(glm::dot(f.t, f.b)) <= tol);
        CHECK(std::fabs(glm::dot(f.t, n)) <= tol);
        CHECK(std::fabs(glm::dot(f.b, n)) <= tol);
        CHECK(glm::dot(glm::cross(f.t, f.b), n) == doctest::Approx(T(1)).epsilon(double(tol)));
        const ibl::vec3<T> w(T(0.3), T(-0.5), T(0.8));
        const auto back = f.to_world(f.to_local(w));
        CHECK(glm::length(back - w) <= tol * T(4));
    }
}

TEST_CASE_TEMPLATE("neumaier_sum and pairwise_sum beat naive accumulation", T, float, double) {
    // 1 followed by n copies of eps/4: naive float/double summation never moves from 1, the exact
    // sum is 1 + n eps/4. Neumaier is exact here (each lost term is caught in c).
    const std::size_t n = 1u << 16;
    const T small = ibl::epsilon_v<T> / T(4);
    ibl::neumaier_sum<T> s;
    T naive = T(1);
    s.add(T(1));
    std::vector<T> xs(n + 1, small);
    xs[0] = T(1);
    for (std::size_t i = 0; i < n; ++i) {
        s.add(small);
        naive += small;
    }
    const double exact = 1.0 + double(n) * double(small);
    CHECK(naive == T(1));
    CHECK(double(s.value()) == doctest::Approx(exact).epsilon(double(ibl::epsilon_v<T>)));
    // Pairwise: error O(eps log2 n) relative to sum|x|; here the small terms pair up first.
    CHECK(double(ibl::pairwise_sum(xs.data(), xs.size())) ==
          doctest::Approx(exact).epsilon(2 * double(ibl::epsilon_v<T>)));
    SUBCASE("merge of partial accumulators equals one accumulator (up to its own bound)") {
        ibl::neumaier_sum<T> a, b;
        a.add(T(1));
        for (std::size_t i = 0; i < n / 2; ++i) a.add(small);
        for (std::size_t i = n / 2; i < n; ++i) b.add(small);
        a.merge(b);
        CHECK(double(a.value()) == doctest::Approx(exact).epsilon(double(ibl::epsilon_v<T>)));
    }
    SUBCASE("cancellation: 1e8, 1, -1e8 sums to 1") {
        ibl::neumaier_sum<T> c;
        c.add(T(1e8));
        c.add(T(1));
        c.add(T(-1e8));
        CHECK(c.value() == T(1));
    }
}

TEST_CASE("executors cover [0, count) exactly once and reductions are partition-independent") {
    for (std::size_t count : {0u, 1u, 2u, 7u, 1000u}) {
        for (unsigned threads : {1u, 2u, 3u, 8u}) {
            std::vector<int> hits(count, 0);
            ibl::thread_executor{threads}(count, [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) ++hits[i];
            });
            for (int h : hits) CHECK(h == 1);
        }
    }
    // A float reduction whose naive result depends on the order: block results must be identical
    // for every executor.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1e4f, 1e4f);
    std::vector<float> x(10000);
    for (auto& v : x) v = u(rng);
    auto block = [&](std::size_t b) {
        float s = 0;
        for (std::size_t i = b * 100; i < (b + 1) * 100; ++i) s += x[i];
        return s;
    };
    auto add = [](float a, float b) { return a + b; };
    const float ref = ibl::parallel_reduce_blocks(ibl::serial_executor{}, 100, 0.0f, block, add);
    for (unsigned threads : {1u, 2u, 3u, 7u})
        CHECK(ibl::parallel_reduce_blocks(ibl::thread_executor{threads}, 100, 0.0f, block, add) == ref);
}

TEST_CASE("thread_executor: its persistent workers take every item once, nested and concurrent calls included") {
    // Many calls in a row reuse the pool's workers (each call covers its range exactly once).
    for (int call = 0; call < 200; ++call) {
        const std::size_t count = std::size_t(1 + call % 37);
        std::vector<int> hits(count, 0);
        ibl::thread_executor{2}(count, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) ++hits[i];
        });
        for (int h : hits) REQUIRE(h == 1);
    }
    // A call from inside a chunk (the pool is busy): it runs on threads of its own.
    std::vector<std::atomic<int>> nested(64 * 16);
    ibl::thread_executor{3}(64, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            ibl::thread_executor{3}(16, [&](std::size_t nb, std::size_t ne) {
                for (std::size_t j = nb; j < ne; ++j) nested[i * 16 + j].fetch_add(1);
            });
    });
    for (const std::atomic<int>& h : nested) CHECK(h.load() == 1);
    // Calls from two threads at once: one gets the pool, the other its own threads.
    std::vector<int> a(5000, 0), c(5000, 0);
    auto fill = [](std::vector<int>& v) {
        for (int rep = 0; rep < 20; ++rep)
            ibl::thread_executor{2}(v.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) ++v[i];
            });
    };
    std::thread other([&] { fill(a); });
    fill(c);
    other.join();
    for (std::size_t i = 0; i < a.size(); ++i) REQUIRE((a[i] == 20 && c[i] == 20));
    // An exception in a chunk, whichever thread runs it, reaches the caller once the workers are
    // done, and the pool serves the next call.
    for (int rep = 0; rep < 20; ++rep)
        CHECK_THROWS_AS(ibl::thread_executor{2}(100, [&](std::size_t b, std::size_t e) {
                            if (b <= std::size_t(rep) && std::size_t(rep) < e) throw std::runtime_error("item rep");
                        }),
                        std::runtime_error);
    // The same from inside a chunk (the nested call's own threads).
    ibl::thread_executor{2}(2, [&](std::size_t, std::size_t) {
        CHECK_THROWS_AS(ibl::thread_executor{2}(10, [&](std::size_t b, std::size_t) {
                            if (b > 0) throw std::runtime_error("second range");
                        }),
                        std::runtime_error);
    });
    std::vector<int> after(100, 0);
    ibl::thread_executor{2}(100, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) ++after[i];
    });
    for (int h : after) CHECK(h == 1);
}

#if defined(__unix__)
TEST_CASE("thread_executor: a child of fork() gets workers of its own") {
    std::vector<int> hits(64, 0);
    ibl::thread_executor{2}(hits.size(), [&](std::size_t b, std::size_t e) { // the parent's pool exists
        for (std::size_t i = b; i < e; ++i) ++hits[i];
    });
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) { // the child: a call must finish (alarm: a hang ends the child with SIGALRM)
        alarm(20);
        std::vector<int> h(64, 0);
        ibl::thread_executor{2}(h.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) ++h[i];
        });
        int ok = 1;
        for (int v : h) ok &= v == 1 ? 1 : 0;
        _exit(ok ? 0 : 1);
    }
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
}
#endif
