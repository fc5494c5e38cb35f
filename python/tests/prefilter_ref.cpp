// python/tests/prefilter_ref.cpp — the C++ side of test_prefilter_vs_cpp.py: the prefiltered chain of
// a cube as a program using the library computes it (cubemap, generate_mips, prefilter), written
// independently of the binding, so that ibl.prefilter can be compared with it texel by texel.
//
//   ibl_python_prefilter_ref IN N OUT LEVELS SAMPLES METHOD WEIGHT THREADS [--time]
//
// IN: 6 N N 3 float32 values, native byte order, [face][y][x][rgb] with faces +X, -X, +Y, -Y, +Z,
// -Z and (x, y) the texel of env/cube_geometry.hpp (the Python module's documented layout).
// LEVELS: prefilter_options::levels (-1 automatic, 0 full chain); SAMPLES: options.samples (0 = the
// default schedule); METHOD fis | fast | importance; WEIGHT n_dot_l | g1; THREADS for the executor.
// OUT: every level in order, each 6 n n 3 float32 in the same layout. Exit 0, or 2 with a message.
// --time: also print "seconds <t>", the wall time of cubemap + generate_mips + prefilter (what a
// program using the library spends; python/bench.py compares ibl.prefilter with it).
#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/cubemap.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace {

int fail(const std::string& msg) {
    std::fprintf(stderr, "ibl_python_prefilter_ref: %s\n", msg.c_str());
    return 2;
}

} // namespace

int main(int argc, char** argv) {
    const bool timed = argc == 10 && std::string(argv[9]) == "--time";
    if (argc != 9 && !timed) return fail("usage: IN N OUT LEVELS SAMPLES METHOD WEIGHT THREADS [--time]");
    try {
        const int n = std::atoi(argv[2]);
        if (n < 1 || n > 4096) return fail("bad N");
        ibl::prefilter_options opt;
        opt.levels = std::atoi(argv[4]);
        opt.samples = std::uint32_t(std::atol(argv[5]));
        const std::string method = argv[6], weight = argv[7];
        if (method == "fis") opt.method = ibl::prefilter_method::filtered_importance;
        else if (method == "fast") opt.method = ibl::prefilter_method::fast;
        else if (method == "importance") opt.method = ibl::prefilter_method::importance;
        else return fail("bad METHOD " + method);
        if (weight == "n_dot_l") opt.weight = ibl::ld_weight::n_dot_l;
        else if (weight == "g1") opt.weight = ibl::ld_weight::g1;
        else return fail("bad WEIGHT " + weight);
        const unsigned threads = unsigned(std::atoi(argv[8]));

        const std::size_t count = std::size_t(6) * std::size_t(n) * std::size_t(n) * 3;
        std::vector<float> in(count);
        std::FILE* f = std::fopen(argv[1], "rb");
        if (!f) return fail(std::string("cannot open ") + argv[1]);
        const std::size_t got = std::fread(in.data(), sizeof(float), count, f);
        std::fclose(f);
        if (got != count) return fail("IN holds fewer than 6 N N 3 floats");

        const auto t0 = std::chrono::steady_clock::now();
        ibl::cubemap<float> cube(n);
        cube.fill(0, [&](int face, int x, int y) {
            const float* t = in.data() + ((std::size_t(face) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x)) * 3;
            return ibl::vec3<float>(t[0], t[1], t[2]);
        });
        cube.generate_mips(ibl::thread_executor{threads});
        const ibl::specular_chain chain = ibl::prefilter(cube, opt, ibl::thread_executor{threads});
        if (timed)
            std::printf("seconds %.6f\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());

        std::FILE* o = std::fopen(argv[3], "wb");
        if (!o) return fail(std::string("cannot write ") + argv[3]);
        for (int l = 0; l < chain.levels(); ++l) {
            const int s = chain.size(l);
            for (int face = 0; face < 6; ++face)
                for (int y = 0; y < s; ++y)
                    for (int x = 0; x < s; ++x) {
                        const ibl::vec3<float> v = chain.texel(face, x, y, l);
                        const float rgb[3] = {v.x, v.y, v.z};
                        std::fwrite(rgb, sizeof(float), 3, o);
                    }
        }
        return std::fclose(o) == 0 ? 0 : fail("write failed");
    } catch (const std::exception& e) {
        return fail(e.what());
    }
}
