// tools/ibl-bake/tests/test_image_io.cpp — image I/O of the bake tool: round trips, the texel
// policy, malformed inputs (each must throw image_error naming the file and the problem), atomic
// writes, and the shared real data.

#include <doctest/doctest.h>

#include "io/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace ibl_bake;

namespace {

const std::string data_dir = IBL_BAKE_TEST_DATA_DIR;
const std::string regression_dir = IBL_BAKE_REGRESSION_DIR;

// A fresh, empty scratch directory per test case.
struct scratch_dir {
    fs::path path;
    explicit scratch_dir(const std::string& tag) {
        path = fs::temp_directory_path() / ("ibl_bake_io_tests_" + tag + "_" + std::to_string(::getpid()));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~scratch_dir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
    std::size_t entries() const { return std::size_t(std::distance(fs::directory_iterator(path), fs::directory_iterator())); }
};

image_rgb32f test_image(int w, int h, unsigned seed) {
    image_rgb32f img(w, h);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float& x : img.rgb) x = std::exp2(40.0f * u(rng) - 20.0f) * u(rng); // 2^-20 .. 2^20
    return img;
}

// The message of the image_error thrown by f (empty if none or another exception).
template <class F> std::string error_of(F&& f) {
    try {
        f();
    } catch (const image_error& e) {
        return e.what();
    } catch (...) {
        return "<other exception>";
    }
    return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::vector<unsigned char> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

} // namespace

TEST_CASE("image_io: the shared real environments load with the documented texel policy") {
    // tests/data/README.md: the ZIP re-encodes hold the originals' half values bit for bit; their
    // extremes and negative-texel counts were measured with OpenEXR on the originals. Half floats
    // convert to float exactly, so the comparisons are exact.
    struct expected {
        const char* file;
        float max;
        std::size_t negative_texels;
        float most_negative;
    };
    for (const expected& e : {expected{"studio.exr", 118.375f, 3, -3.03984e-06f},
                              expected{"courtyard.exr", 55.5625f, 1188, -0.00318527f}}) {
        CAPTURE(e.file);
        read_report r;
        const image_rgb32f img = read_latlong(data_dir + "/" + e.file, {}, &r);
        CHECK(r.format == "OpenEXR");
        REQUIRE(img.width == 1024);
        REQUIRE(img.height == 512);
        CHECK(*std::max_element(img.rgb.begin(), img.rgb.end()) == e.max);
        CHECK(*std::min_element(img.rgb.begin(), img.rgb.end()) == 0.0f); // negatives clamped
        CHECK(r.negative_texels == e.negative_texels);
        CHECK(r.most_negative == doctest::Approx(e.most_negative).epsilon(1e-5)); // printed to 6 digits
        CHECK(r.nonfinite_values == 0);
    }
}

TEST_CASE("image_io: an EXR whose compression attribute lies gives a clean image_error") {
    // A real ZIP file with its compression attribute patched to DWAB (9): OpenEXR then decodes
    // ZIP data as DWAB, which must end in an image_error naming the file, not a crash.
    std::ifstream in(data_dir + "/studio.exr", std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key("compression\0compression\0", 24);
    auto it = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
    REQUIRE(it != bytes.end());
    const std::size_t value_at = std::size_t(it - bytes.begin()) + key.size() + 4; // after the int32 size
    REQUIRE(value_at < bytes.size());
    bytes[value_at] = 9; // DWAB
    const std::string msg = error_of([&] { (void)read_image_memory(bytes, "patched.exr"); });
    CAPTURE(msg);
    CHECK(contains(msg, "patched.exr: "));
    CHECK(contains(msg, "OpenEXR"));
    bytes[value_at] = 10; // beyond OpenEXR 3.1's compressions
    CHECK(contains(error_of([&] { (void)read_image_memory(bytes, "patched.exr"); }), "unsupported OpenEXR compression (value 10)"));
}

TEST_CASE("image_io: OpenEXR float32 round trip is bit-exact (memory and file)") {
    const image_rgb32f img = test_image(37, 19, 1);
    const auto enc = encode_exr(img);
    read_report r;
    const image_rgb32f back = read_exr_memory(enc, "mem.exr", {}, &r);
    CHECK(r.format == "OpenEXR");
    REQUIRE(back.width == 37);
    REQUIRE(back.height == 19);
    CHECK(std::memcmp(back.rgb.data(), img.rgb.data(), img.rgb.size() * sizeof(float)) == 0);
    CHECK(r.negative_values == 0);
    CHECK(r.nonfinite_values == 0);

    scratch_dir dir("exr");
    const image_rgb32f ll = test_image(64, 32, 2);
    write_exr(dir.file("env.exr"), ll);
    const image_rgb32f ll_back = read_latlong(dir.file("env.exr"));
    CHECK(std::memcmp(ll_back.rgb.data(), ll.rgb.data(), ll.rgb.size() * sizeof(float)) == 0);
    CHECK(dir.entries() == 1); // no temporary left behind
}

TEST_CASE("image_io: texel policy — negatives clamped and counted, NaN/inf rejected or zeroed") {
    image_rgb32f img = test_image(16, 8, 3);
    img.texel(1, 0)[0] = -0.003f; // one texel, two negative values
    img.texel(1, 0)[2] = -1e-6f;
    img.texel(5, 2)[1] = -0.5f;
    img.texel(7, 3)[1] = std::numeric_limits<float>::quiet_NaN();
    img.texel(9, 4)[2] = std::numeric_limits<float>::infinity();
    const auto enc = encode_exr(img);

    const std::string msg = error_of([&] { (void)read_exr_memory(enc, "nan.exr"); });
    CAPTURE(msg);
    CHECK(contains(msg, "nan.exr"));
    CHECK(contains(msg, "2 NaN/infinite values"));
    CHECK(contains(msg, "x = 7, y = 3"));

    read_options o;
    o.nonfinite = nonfinite_policy::replace_with_zero;
    read_report r;
    const image_rgb32f back = read_exr_memory(enc, "nan.exr", o, &r);
    CHECK(r.nonfinite_values == 2);
    CHECK(r.negative_values == 3);
    CHECK(r.negative_texels == 2);
    CHECK(r.most_negative == -0.5f);
    CHECK(back.texel(1, 0)[0] == 0.0f);
    CHECK(back.texel(7, 3)[1] == 0.0f);
    CHECK(back.texel(9, 4)[2] == 0.0f);
    for (float x : back.rgb) CHECK((std::isfinite(x) && x >= 0.0f));
}

TEST_CASE("image_io: Radiance HDR round trip within RGBE precision (RLE and flat scanlines)") {
    // RGBE: shared exponent e with 2^(e-1) <= max < 2^e, 8-bit mantissas; stb truncates on
    // encoding and decodes m 2^(e-8) without centring, so 0 <= x - x' < 2^(e-8) per channel
    // (up to one float rounding of x 2^(8-e), which can carry x' one step above: allow 2^-20 x).
    for (int w : {64, 5}) { // 64: run-length encoded scanlines; 5 (< 8): flat pixels
        const image_rgb32f img = test_image(w, 7, 4);
        const auto enc = encode_hdr(img);
        read_report r;
        const image_rgb32f back = read_hdr_memory(enc, "rt.hdr", {}, &r);
        CHECK(r.format == "Radiance HDR");
        REQUIRE(back.width == w);
        REQUIRE(back.height == 7);
        double worst = 0;
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < w; ++x) {
                const float* a = img.texel(x, y);
                const float* b = back.texel(x, y);
                int e = 0;
                std::frexp(std::max({a[0], a[1], a[2]}), &e);
                for (int c = 0; c < 3; ++c) {
                    const double d = double(a[c]) - double(b[c]);
                    const double unit = std::ldexp(1.0, e - 8);
                    CHECK(d < unit);
                    CHECK(d >= -std::ldexp(double(a[c]), -20));
                    worst = std::max(worst, std::fabs(d) / unit);
                }
            }
        MESSAGE("HDR width " << w << ": worst error / 2^(e-8) = " << worst);
    }
    // The file path version goes through the same reader.
    scratch_dir dir("hdr");
    write_hdr(dir.file("env.hdr"), test_image(32, 16, 5));
    CHECK(read_latlong(dir.file("env.hdr")).width == 32);
}

TEST_CASE("image_io: malformed inputs throw image_error naming the file and the problem") {
    scratch_dir dir("bad");
    const auto write_raw = [&](const std::string& name, const std::vector<unsigned char>& b) {
        std::ofstream(dir.file(name), std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
        return dir.file(name);
    };
    const auto expect = [&](const std::string& path, const std::string& part) {
        const std::string msg = error_of([&] { (void)read_image(path); });
        CAPTURE(msg);
        CHECK(contains(msg, path));
        CHECK(contains(msg, part));
    };

    SUBCASE("nonexistent path and a directory") {
        expect(dir.file("missing.exr"), "no such file");
        expect(dir.path.string(), "is a directory");
    }
    SUBCASE("empty file") { expect(write_raw("empty.hdr", {}), "empty file"); }
    SUBCASE("truncated EXR: the first 100 bytes of a real file and of our own") {
        std::ifstream in(data_dir + "/studio.exr", std::ios::binary);
        std::vector<unsigned char> head(100);
        in.read(reinterpret_cast<char*>(head.data()), 100);
        expect(write_raw("studio_100.exr", head), "OpenEXR");
        const auto enc = encode_exr(test_image(64, 32, 6));
        expect(write_raw("own_100.exr", {enc.begin(), enc.begin() + 100}), "OpenEXR");
        expect(write_raw("own_cut.exr", {enc.begin(), enc.end() - 10}), "truncated OpenEXR");
        expect(write_raw("own_8.exr", {enc.begin(), enc.begin() + 6}), "truncated OpenEXR");
    }
    SUBCASE("truncated HDR: inside the header and inside the pixels (RLE and flat)") {
        const auto enc = encode_hdr(test_image(64, 32, 7));
        expect(write_raw("head.hdr", {enc.begin(), enc.begin() + 30}), "truncated Radiance HDR header");
        expect(write_raw("half.hdr", {enc.begin(), enc.begin() + std::ptrdiff_t(enc.size() / 2)}),
               "truncated Radiance HDR data");
        expect(write_raw("last.hdr", {enc.begin(), enc.end() - 1}), "truncated Radiance HDR data");
        const auto flat = encode_hdr(test_image(4, 4, 8));
        expect(write_raw("flat.hdr", {flat.begin(), flat.end() - 1}), "truncated Radiance HDR data");
    }
    SUBCASE("an RLE scanline of zero-length dumps that runs out (stb alone would loop forever)") {
        std::string s = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 16\n";
        s += std::string("\x02\x02\x00\x10", 4) + std::string(64, '\0');
        expect(write_raw("zero_dumps.hdr", bytes_of(s)), "truncated Radiance HDR data");
    }
    SUBCASE("absurd and unsupported HDR headers") {
        expect(write_raw("huge.hdr", bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 200000\n")),
               "exceed the limit");
        expect(write_raw("zero.hdr", bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 2\n")),
               "invalid dimensions");
        expect(write_raw("flip.hdr", bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 2 +X 2\n")),
               "resolution line");
        expect(write_raw("xyz.hdr", bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 2\n")),
               "32-bit_rle_xyze");
    }
    SUBCASE("random bytes") {
        std::mt19937 rng(42);
        std::vector<unsigned char> junk(4096);
        for (auto& b : junk) b = static_cast<unsigned char>(rng() & 0xff);
        junk[0] = 'J'; // not a PNG/JPEG/... signature by accident
        expect(write_raw("junk.exr", junk), "unrecognised image format");
    }
    SUBCASE("an LDR PNG given as input") {
        const auto png = encode_png(test_image(8, 4, 9));
        expect(write_raw("preview.png", png), "LDR input not supported");
    }
    SUBCASE("a lat-long map that is not 2:1") {
        write_exr(dir.file("square.exr"), test_image(16, 16, 10));
        const std::string msg = error_of([&] { (void)read_latlong(dir.file("square.exr")); });
        CHECK(contains(msg, "not 2:1"));
        CHECK(contains(msg, "square.exr"));
    }
    SUBCASE("regression inputs found by fuzzing") {
        // Every file in tools/ibl-bake/tests/data/fuzz-*: must throw image_error (or decode),
        // never crash, hang or leak (the sanitizer build checks the latter).
        for (const auto& entry : fs::directory_iterator(regression_dir)) {
            if (!entry.path().filename().string().starts_with("fuzz-")) continue;
            const std::string msg = error_of([&] {
                read_options o;
                o.max_pixels = 1u << 22;
                (void)read_image_memory(ibl_bake::read_file(entry.path().string()), entry.path().string(), o);
            });
            CAPTURE(entry.path().string());
            CHECK(msg != "<other exception>");
        }
    }
}

TEST_CASE("image_io: atomic writes leave either the old file or the new one, nothing else") {
    scratch_dir dir("atomic");
    const std::string path = dir.file("out.bin");
    const std::vector<unsigned char> a{1, 2, 3}, b{4, 5, 6, 7};
    write_file_atomic(path, a);
    write_file_atomic(path, b);
    CHECK(read_file(path) == b);
    CHECK(dir.entries() == 1);
    // A destination in a missing directory fails cleanly, naming the file.
    const std::string bad = dir.file("no/such/dir/out.exr");
    const std::string msg = error_of([&] { write_exr(bad, test_image(4, 2, 11)); });
    CHECK(contains(msg, bad));
    CHECK(contains(msg, "temporary"));
    CHECK(dir.entries() == 1);
    // An image whose size does not match its dimensions is refused before anything is written.
    image_rgb32f broken(4, 2);
    broken.rgb.pop_back();
    CHECK(contains(error_of([&] { write_png(dir.file("broken.png"), broken); }), "cannot write"));
    CHECK(dir.entries() == 1);
}

TEST_CASE("image_io: PNG preview tonemap and sRGB encoding") {
    png_options clampo{1.0f, tonemap::clamp};
    png_options rh{1.0f, tonemap::reinhard};
    CHECK(tonemap_png(0.0f, rh) == 0);
    CHECK(tonemap_png(-1.0f, rh) == 0);
    CHECK(tonemap_png(std::numeric_limits<float>::quiet_NaN(), rh) == 0);
    CHECK(tonemap_png(std::numeric_limits<float>::infinity(), rh) == 255);
    CHECK(tonemap_png(1.0f, clampo) == 255);
    CHECK(tonemap_png(5.0f, clampo) == 255);
    // Reinhard maps 1 to 0.5; sRGB(0.5) = 1.055 0.5^(1/2.4) - 0.055 = 0.735357, * 255 = 187.52 -> 188.
    CHECK(tonemap_png(1.0f, rh) == 188);
    // The linear segment of the sRGB OETF: 0.002 -> 12.92 * 0.002 * 255 = 6.59 -> 7.
    CHECK(tonemap_png(0.002f, clampo) == 7);
    // Exposure scales before the curve.
    CHECK(tonemap_png(0.5f, png_options{2.0f, tonemap::reinhard}) == 188);
    const auto png = encode_png(test_image(8, 4, 12));
    REQUIRE(png.size() > 8);
    CHECK(std::memcmp(png.data(), "\x89PNG\r\n\x1a\n", 8) == 0);
}
