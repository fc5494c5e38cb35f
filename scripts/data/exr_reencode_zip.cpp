// One-off data conversion: re-encode an OpenEXR file's RGB(A) half channels with ZIP compression,
// preserving every pixel value bit for bit (DWAB decode -> half values -> lossless ZIP).
#include <ImfRgbaFile.h>
#include <ImfArray.h>
#include <ImfHeader.h>
#include <ImfCompression.h>
#include <cstdio>
int main(int argc, char** argv) {
    Imf::RgbaInputFile in(argv[1]);
    const Imath::Box2i dw = in.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::printf("%s: %dx%d compression=%d channels=%d\n", argv[1], w, h, int(in.header().compression()), int(in.channels()));
    Imf::Array2D<Imf::Rgba> px(h, w);
    in.setFrameBuffer(&px[0][0] - dw.min.x - dw.min.y * w, 1, w);
    in.readPixels(dw.min.y, dw.max.y);
    Imf::Header hdr(w, h);
    hdr.compression() = Imf::ZIP_COMPRESSION;
    Imf::RgbaOutputFile out(argv[2], hdr, Imf::WRITE_RGB);
    out.setFrameBuffer(&px[0][0], 1, w);
    out.writePixels(h);
    // verify
    Imf::RgbaInputFile chk(argv[2]);
    Imf::Array2D<Imf::Rgba> px2(h, w);
    chk.setFrameBuffer(&px2[0][0], 1, w);
    chk.readPixels(0, h - 1);
    long diff = 0, neg = 0; float mx = 0, mn = 0;
    for (int y = 0; y < h; ++y) for (int x = 0; x < w; ++x) {
        const Imf::Rgba a = px[y][x], b = px2[y][x];
        diff += a.r.bits() != b.r.bits() || a.g.bits() != b.g.bits() || a.b.bits() != b.b.bits();
        for (float v : {float(a.r), float(a.g), float(a.b)}) { if (v > mx) mx = v; if (v < mn) mn = v; }
        neg += float(a.r) < 0 || float(a.g) < 0 || float(a.b) < 0;
    }
    std::printf("  differing texels after re-encode: %ld; range [%g, %g]; texels with a negative channel: %ld\n", diff, mn, mx, neg);
    return diff != 0;
}
