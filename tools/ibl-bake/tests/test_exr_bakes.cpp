// tools/ibl-bake/tests/test_exr_bakes.cpp — end-to-end: a lat-long stored with every kind of EXR
// encoding bakes to the products of the original. tests/data/courtyard.exr (1024 x 512 half RGB,
// ZIP) is written again with the OpenEXR API as DWAA, DWAB, B44, B44A, PXR24 (float channels),
// tiled (ZIP, mipmapped) and as the second part of a multi-part file (the first part has no RGB);
// each is baked at --size 16 and compared with the bake of the original:
//   * lossless encodings (tiled, multi-part, PXR24 of half values widened to float, which rounds
//     only below float's 24-bit mantissa cut to 16 bits, i.e. not at all for half data) give
//     bit-identical products;
//   * lossy codecs (DWA: quantised DCT; B44: 4x4 blocks of half values relative to the block's
//     largest) differ by their own loss, averaged by the bake: the SH within 2% of L00 and each
//     specular level within 3% relative RMS (about 6x the measured B44 figures below, the
//     codecs' loss being per texel up to a few percent in dark blocks). Measured at --size 16:
//     DWAA and DWAB SH 4.8e-5 of L00, levels 7.8e-5; B44 and B44A SH 2.4e-3, levels 5.2e-3.

#include <doctest/doctest.h>

#include "io/image_io.hpp"
#include "tool_test_support.hpp"
#include "io/json_value.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

namespace fs = std::filesystem;
using namespace ibl_bake;
using ibl_bake_test::scratch;
using ibl_bake_test::shell;
using ibl_bake_test::level_rel_rms;
using ibl_bake_test::sh_radiance;
using ibl_bake_test::slurp;

namespace {

const std::string tool = IBL_BAKE_TOOL;
const std::string data_dir = IBL_BAKE_TEST_DATA_DIR;

int bake(const std::string& in, const std::string& out) {
    const std::string cmd = tool + " --quiet --quality low --lut-size 16 --size 16 --input '" + in + "' --out '" + out + "' >/dev/null 2>&1";
    return shell(cmd);
}

/// The original's half RGB planes.
struct planes {
    int w = 0, h = 0;
    std::vector<half> c[3];
};
planes read_original() {
    Imf::InputFile in((data_dir + "/courtyard.exr").c_str(), 0);
    const Imath::Box2i dw = in.header().dataWindow();
    planes p;
    p.w = dw.max.x - dw.min.x + 1, p.h = dw.max.y - dw.min.y + 1;
    Imf::FrameBuffer fb;
    for (int k = 0; k < 3; ++k) {
        p.c[k].resize(std::size_t(p.w) * std::size_t(p.h));
        fb.insert(k == 0 ? "R" : k == 1 ? "G" : "B", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(p.c[k].data()), sizeof(half),
                                                              sizeof(half) * std::size_t(p.w)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return p;
}

/// A frame buffer over p, as half or widened to float (kept alive in `wide`).
Imf::FrameBuffer frame(const planes& p, bool as_float, std::vector<float> (&wide)[3]) {
    Imf::FrameBuffer fb;
    for (int k = 0; k < 3; ++k) {
        const char* n = k == 0 ? "R" : k == 1 ? "G" : "B";
        if (as_float) {
            wide[k].assign(p.c[k].begin(), p.c[k].end());
            fb.insert(n, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(wide[k].data()), sizeof(float), sizeof(float) * std::size_t(p.w)));
        } else {
            fb.insert(n, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(const_cast<half*>(p.c[k].data())), sizeof(half),
                                    sizeof(half) * std::size_t(p.w)));
        }
    }
    return fb;
}

Imf::Header rgb_header(const planes& p, Imf::Compression c, bool as_float) {
    Imf::Header h(p.w, p.h);
    h.compression() = c;
    for (const char* n : {"R", "G", "B"}) h.channels().insert(n, Imf::Channel(as_float ? Imf::FLOAT : Imf::HALF));
    return h;
}

void write_scanline(const planes& p, const std::string& path, Imf::Compression c, bool as_float) {
    std::vector<float> wide[3];
    Imf::OutputFile out(path.c_str(), rgb_header(p, c, as_float), 0);
    out.setFrameBuffer(frame(p, as_float, wide));
    out.writePixels(p.h);
}

void write_tiled(const planes& p, const std::string& path) {
    std::vector<float> wide[3];
    Imf::Header h = rgb_header(p, Imf::ZIP_COMPRESSION, false);
    h.setTileDescription(Imf::TileDescription(64, 64, Imf::ONE_LEVEL));
    Imf::TiledOutputFile out(path.c_str(), h, 0);
    out.setFrameBuffer(frame(p, false, wide));
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
}

void write_multipart(const planes& p, const std::string& path) {
    Imf::Header aux(p.w, p.h);
    aux.setName("aux");
    aux.setType(Imf::SCANLINEIMAGE);
    aux.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    Imf::Header beauty = rgb_header(p, Imf::PIZ_COMPRESSION, false);
    beauty.setName("beauty");
    beauty.setType(Imf::SCANLINEIMAGE);
    const Imf::Header headers[2] = {aux, beauty};
    Imf::MultiPartOutputFile out(path.c_str(), headers, 2, false, 0);
    std::vector<float> z(std::size_t(p.w) * std::size_t(p.h), 1.0f), wide[3];
    Imf::OutputPart a(out, 0), b(out, 1);
    Imf::FrameBuffer fz;
    fz.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(z.data()), sizeof(float), sizeof(float) * std::size_t(p.w)));
    a.setFrameBuffer(fz);
    a.writePixels(p.h);
    b.setFrameBuffer(frame(p, false, wide));
    b.writePixels(p.h);
}

} // namespace

TEST_CASE("exr bakes: every encoding of the lat-long bakes to the original's products") {
    scratch s("ibl_bake_exr_bakes");
    const planes p = read_original();
    REQUIRE(bake(data_dir + "/courtyard.exr", s / "ref") == 0);
    struct variant {
        const char* name;
        bool lossless;
    };
    write_scanline(p, s / "DWAA.exr", Imf::DWAA_COMPRESSION, false);
    write_scanline(p, s / "DWAB.exr", Imf::DWAB_COMPRESSION, false);
    write_scanline(p, s / "B44.exr", Imf::B44_COMPRESSION, false);
    write_scanline(p, s / "B44A.exr", Imf::B44A_COMPRESSION, false);
    write_scanline(p, s / "PXR24.exr", Imf::PXR24_COMPRESSION, true);
    write_tiled(p, s / "tiled.exr");
    write_multipart(p, s / "multipart.exr");
    const std::vector<double> ref = sh_radiance(s / "ref");
    for (const variant v : {variant{"DWAA", false}, variant{"DWAB", false}, variant{"B44", false}, variant{"B44A", false},
                            variant{"PXR24", true}, variant{"tiled", true}, variant{"multipart", true}}) {
        INFO(v.name);
        const std::string out = s / (std::string("out_") + v.name);
        REQUIRE(bake(s / (std::string(v.name) + ".exr"), out) == 0);
        const std::vector<double> sh = sh_radiance(out);
        double sh_diff = 0.0, level_diff = 0.0;
        for (std::size_t i = 0; i < sh.size(); ++i) sh_diff = std::max(sh_diff, std::fabs(sh[i] - ref[i]) / ref[i % 3]);
        for (int l = 0; l < 3; ++l) level_diff = std::max(level_diff, level_rel_rms(out, s / "ref", l));
        MESSAGE(std::string(v.name) << ": SH max |diff| / L00 " << sh_diff << ", worst specular level rel RMS " << level_diff);
        if (v.lossless) {
            CHECK(slurp(out + "/sh.json") == slurp(s / "ref/sh.json"));
            CHECK(slurp(out + "/specular.ktx2") == slurp(s / "ref/specular.ktx2"));
        } else {
            CHECK(sh_diff < 2e-2);
            CHECK(level_diff < 3e-2);
        }
    }
}
