// tools/ibl-bake/fuzz/make_seeds.cpp — writes small valid inputs for the fuzz seed corpus:
// OpenEXR (ZIP, float32), Radiance HDR (run-length and flat scanlines), KTX2 cubemaps.
#include <cmath>
#include <cstdio>
#include <string>

#include "image_io.hpp"
#include "ktx2.hpp"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_seeds <directory>\n");
        return 2;
    }
    const std::string dir = argv[1];
    const auto image = [](int w, int h) {
        ibl_bake::image_rgb32f img(w, h);
        for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = std::ldexp(float(i % 7 + 1), int(i % 11) - 5);
        return img;
    };
    ibl_bake::write_exr(dir + "/seed_8x4.exr", image(8, 4));
    ibl_bake::write_exr(dir + "/seed_1x1.exr", image(1, 1));
    ibl_bake::write_hdr(dir + "/seed_rle_16x8.hdr", image(16, 8));
    ibl_bake::write_hdr(dir + "/seed_flat_4x2.hdr", image(4, 2));
    ibl_bake::write_png(dir + "/seed_ldr.png", image(4, 2));
    ibl_bake::write_ktx2_cubemap(dir + "/seed_cube.ktx2", ibl_bake::cubemap_rgb32f::zeros(2, 2),
                                 ibl_bake::ktx2_format::rgba16f);
    return 0;
}
