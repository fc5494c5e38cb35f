// tools/ibl-bake/fuzz/make_seeds.cpp — writes small valid inputs for the fuzz seed corpus:
// OpenEXR (every compression; tiled with mipmaps; multi-part with a part named "rgb"; Y, Y/RY/BY,
// RGBA, an offset data window), Radiance HDR (run-length and flat scanlines), PNG, KTX2 cubemaps.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfTiledOutputFile.h>
#include <ImfTiledRgbaFile.h>
#include <half.h>

#include "io/image_io.hpp"
#include "io/ktx2.hpp"

#include <utility>

namespace {

constexpr int W = 16, H = 8;

float value(int i) { return std::ldexp(float(i % 7 + 1), i % 11 - 5); }

void write_rgb(const std::string& path, Imf::Compression c, Imf::PixelType t, bool alpha, Imath::Box2i data) {
    Imf::Header hdr(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(W - 1, H - 1)), data);
    hdr.compression() = c;
    std::vector<std::string> names = {"R", "G", "B"};
    if (alpha) names.push_back("A");
    const int w = data.max.x - data.min.x + 1, h = data.max.y - data.min.y + 1;
    std::vector<float> f(std::size_t(w * h) * names.size());
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = value(int(i));
    std::vector<half> hv(f.begin(), f.end());
    Imf::FrameBuffer fb;
    for (std::size_t k = 0; k < names.size(); ++k) {
        hdr.channels().insert(names[k], Imf::Channel(t));
        void* p = t == Imf::HALF ? static_cast<void*>(hv.data() + k * std::size_t(w * h)) : f.data() + k * std::size_t(w * h);
        fb.insert(names[k], Imf::Slice::Make(t, p, data));
    }
    Imf::OutputFile file(path.c_str(), hdr, 0);
    file.setFrameBuffer(fb);
    file.writePixels(h);
}

ibl_bake::image_rgb32f test_image(int w, int h) {
    ibl_bake::image_rgb32f img(w, h);
    for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = value(int(i));
    return img;
}

std::vector<Imf::Rgba> rgba_pixels() {
    std::vector<Imf::Rgba> px(W * H);
    for (int i = 0; i < W * H; ++i) px[std::size_t(i)] = Imf::Rgba(value(i), value(i + 3), value(i + 5), 1.0f);
    return px;
}

/// Scanline RGB(A) in every compression, FLOAT with alpha, an offset data window.
void write_rgb_seeds(const std::string& dir, const Imath::Box2i& full) {
    const char* cnames[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};
    for (int c = 0; c < 10; ++c)
        write_rgb(dir + "/seed_" + cnames[c] + ".exr", Imf::Compression(c), Imf::HALF, false, full);
    write_rgb(dir + "/seed_float_rgba_pxr24.exr", Imf::PXR24_COMPRESSION, Imf::FLOAT, true, full);
    write_rgb(dir + "/seed_window.exr", Imf::ZIP_COMPRESSION, Imf::HALF, false,
              Imath::Box2i(Imath::V2i(-2, 3), Imath::V2i(W + 1, H + 2)));
}

/// Grey (Y), luminance/chroma (Y, RY, BY) and tiled with mipmaps.
void write_y_seeds(const std::string& dir, const Imath::Box2i& full) {
    {
        Imf::Header hdr(W, H);
        hdr.channels().insert("Y", Imf::Channel(Imf::FLOAT));
        std::vector<float> y(W * H);
        for (int i = 0; i < W * H; ++i) y[std::size_t(i)] = value(i);
        Imf::FrameBuffer fb;
        fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, y.data(), full));
        Imf::OutputFile file((dir + "/seed_y.exr").c_str(), hdr, 0);
        file.setFrameBuffer(fb);
        file.writePixels(H);
    }
    std::vector<Imf::Rgba> px = rgba_pixels();
    {
        Imf::Header hdr(W, H);
        hdr.compression() = Imf::PIZ_COMPRESSION;
        Imf::RgbaOutputFile file((dir + "/seed_yc.exr").c_str(), hdr, Imf::WRITE_YC, 0);
        file.setFrameBuffer(px.data(), 1, W);
        file.writePixels(H);
    }
    Imf::Header hdr(W, H);
    Imf::TiledRgbaOutputFile file((dir + "/seed_tiled_mip.exr").c_str(), hdr, Imf::WRITE_RGB, 8, 4, Imf::MIPMAP_LEVELS,
                                  Imf::ROUND_DOWN, 0);
    file.setFrameBuffer(px.data(), 1, W);
    for (int l = 0; l < file.numLevels(); ++l) file.writeTiles(0, file.numXTiles(l) - 1, 0, file.numYTiles(l) - 1, l);
}

/// Two parts: "z" (one FLOAT channel) and "rgb" (HALF R, G, B, DWAB).
void write_multipart_seed(const std::string& dir, const Imath::Box2i& full) {
    Imf::Header h0(W, H), h1(W, H);
    h0.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    h0.setName("z");
    h0.setType(Imf::SCANLINEIMAGE);
    for (const char* c : {"R", "G", "B"}) h1.channels().insert(c, Imf::Channel(Imf::HALF));
    h1.setName("rgb");
    h1.setType(Imf::SCANLINEIMAGE);
    h1.compression() = Imf::DWAB_COMPRESSION;
    const Imf::Header hs[2] = {h0, h1};
    Imf::MultiPartOutputFile file((dir + "/seed_multipart.exr").c_str(), hs, 2, false, 0);
    std::vector<float> z(W * H, 1.0f);
    Imf::FrameBuffer f0;
    f0.insert("Z", Imf::Slice::Make(Imf::FLOAT, z.data(), full));
    Imf::OutputPart p0(file, 0);
    p0.setFrameBuffer(f0);
    p0.writePixels(H);
    std::vector<Imf::Rgba> px = rgba_pixels();
    Imf::FrameBuffer f1;
    f1.insert("R", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(&px[0].r), sizeof(Imf::Rgba), sizeof(Imf::Rgba) * W));
    f1.insert("G", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(&px[0].g), sizeof(Imf::Rgba), sizeof(Imf::Rgba) * W));
    f1.insert("B", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(&px[0].b), sizeof(Imf::Rgba), sizeof(Imf::Rgba) * W));
    Imf::OutputPart p1(file, 1);
    p1.setFrameBuffer(f1);
    p1.writePixels(H);
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_seeds <directory>\n");
        return 2;
    }
    const std::string dir = argv[1];
    ibl_bake::write_exr(dir + "/seed_8x4.exr", test_image(8, 4));
    ibl_bake::write_exr(dir + "/seed_1x1.exr", test_image(1, 1));
    const Imath::Box2i full(Imath::V2i(0, 0), Imath::V2i(W - 1, H - 1));
    write_rgb_seeds(dir, full);
    write_y_seeds(dir, full);
    write_multipart_seed(dir, full);
    ibl_bake::write_hdr(dir + "/seed_rle_16x8.hdr", test_image(16, 8));
    ibl_bake::write_hdr(dir + "/seed_flat_4x2.hdr", test_image(4, 2));
    ibl_bake::write_png(dir + "/seed_ldr.png", test_image(4, 2));
    ibl_bake::write_ktx2_cubemap(dir + "/seed_cube.ktx2", ibl_bake::cubemap_rgb32f::zeros(2, 2),
                                 ibl_bake::ktx2_format::rgba16f);
    // the block formats and Zstandard supercompression (a 8^2 cube of varied values, 4 levels)
    ibl_bake::cubemap_rgb32f cube = ibl_bake::cubemap_rgb32f::zeros(8, 4);
    for (auto& level : cube.levels)
        for (auto& face : level)
            for (std::size_t i = 0; i < face.size(); ++i) face[i] = float(0.01 * double(i % 37) * double(1 + i % 5));
    const std::pair<const char*, ibl_bake::ktx2_format> blocks[] = {
        {"bc6h", ibl_bake::ktx2_format::bc6h}, {"astc4x4", ibl_bake::ktx2_format::astc4x4}, {"astc6x6", ibl_bake::ktx2_format::astc6x6}};
    for (const auto& [name, format] : blocks) {
        ibl_bake::write_ktx2_cubemap(dir + "/seed_" + name + ".ktx2", cube, format, "seed", {}, {ibl_bake::block_quality::fast, 0, 1});
        ibl_bake::write_ktx2_cubemap(dir + "/seed_" + name + "_zstd.ktx2", cube, format, "seed", {}, {ibl_bake::block_quality::fast, 3, 1});
    }
    ibl_bake::write_ktx2_cubemap(dir + "/seed_rgba16f_zstd.ktx2", cube, ibl_bake::ktx2_format::rgba16f, "seed", {},
                                 {ibl_bake::block_quality::fast, 3, 1});
    return 0;
}
