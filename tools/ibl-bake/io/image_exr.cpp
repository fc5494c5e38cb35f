// tools/ibl-bake/io/image_exr.cpp — OpenEXR of image_io.hpp: the bounds-checked walk of every part's
// header, then decoding and encoding by OpenEXR 3 (libopenexr-dev, with Imath; linked as
// OpenEXR::OpenEXR). Its decoders read from memory through span_istream (an Imf::IStream over the
// caller's bytes), so files and the fuzz harness share one code path; encode_exr writes through
// vector_ostream.

#include "io/image_common.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>
#include <string_view>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfStringAttribute.h>
#include <ImfTiledInputPart.h>
#include <ImfTiledOutputFile.h>
#include <ImfVersion.h>
#include <Iex.h>

namespace ibl_bake {
namespace {

// ---- OpenEXR -----------------------------------------------------------------------------------
//
// Decoding is OpenEXR's (libopenexr-dev). Before OpenEXR sees a byte, scan_exr_headers walks
// every part's header exactly as OpenEXR's Header::readFrom will (the same name-length limits,
// the same number of bytes consumed per attribute), rejects what OpenEXR would misread or what
// would make it allocate more than the limits allow (a preview image of 2^64 bytes, a string
// vector entry of 2 GB, a chunk table larger than the file), and checks the `type` attribute
// against the file's layout. OpenEXR then parses the same bytes to the same values.

constexpr std::uint32_t exr_tiled_flag = 0x200, exr_long_names_flag = 0x400, exr_non_image_flag = 0x800,
                        exr_multipart_flag = 0x1000;

constexpr const char* exr_compression_names[] = {"NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB"};
/// Scanlines per chunk of each compression (OpenEXR's numLinesInBuffer).
constexpr int exr_lines_per_chunk[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};

struct exr_box {
    std::int64_t x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    std::int64_t width() const { return x1 - x0 + 1; }
    std::int64_t height() const { return y1 - y0 + 1; }
};

/// What scan_exr_headers learnt about one part.
struct exr_part_scan {
    std::string name, type;
    bool has_name = false, has_type = false, has_data = false, has_display = false, has_tiles = false,
         has_chunk_count = false, has_channels = false;
    exr_box data, display;
    int compression = -1;
    std::uint32_t tile_x = 0, tile_y = 0;
    int level_mode = 0, rounding_mode = 0;
    std::int64_t chunk_count = 0;
    std::uint64_t bytes_per_pixel = 0; ///< all channels at full resolution (an upper bound)
    bool tiled = false, deep = false;
};

/// Bounds-checked little-endian reads; every failure is a truncated or corrupt header.
struct exr_reader {
    std::span<const unsigned char> b;
    std::size_t p = 0;
    const std::string& file;

    [[noreturn]] void fail(const std::string& what) const { throw image_error(file, "corrupt OpenEXR header (" + what + ")"); }
    [[noreturn]] void truncated(const std::string& what) const {
        throw image_error(file, "truncated OpenEXR file (header ends inside " + what + ")");
    }
    void need(std::size_t n, const std::string& what) const {
        if (b.size() - p < n) truncated(what);
    }
    std::uint8_t u8(const std::string& what) {
        need(1, what);
        return b[p++];
    }
    std::uint32_t u32(const std::string& what) {
        need(4, what);
        const std::uint32_t v = std::uint32_t(b[p]) | (std::uint32_t(b[p + 1]) << 8) | (std::uint32_t(b[p + 2]) << 16) |
                                (std::uint32_t(b[p + 3]) << 24);
        p += 4;
        return v;
    }
    std::int32_t i32(const std::string& what) { return static_cast<std::int32_t>(u32(what)); }
    /// A NUL-terminated name of at most max_len characters (OpenEXR's Xdr::read of a name reads
    /// max_len + 1 bytes at most and stops there, unterminated: such a name is refused here).
    std::string_view name(std::size_t max_len, const std::string& what) {
        const auto* begin = b.data() + p;
        const std::size_t avail = b.size() - p;
        const auto* end = begin + std::min(avail, max_len + 1);
        const auto* nul = std::find(begin, end, static_cast<unsigned char>(0));
        if (nul == end) {
            if (avail <= max_len) truncated(what);
            fail(what + " longer than " + std::to_string(max_len) + " characters");
        }
        p = std::size_t(nul - b.data()) + 1;
        return {reinterpret_cast<const char*>(begin), std::size_t(nul - begin)};
    }
};

/// Bytes that OpenEXR's reader of a fixed-size attribute type consumes whatever the declared size.
int exr_fixed_attribute_size(std::string_view type) {
    static constexpr std::pair<std::string_view, int> sizes[] = {
        {"box2i", 16}, {"box2f", 16}, {"int", 4}, {"float", 4}, {"double", 8}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16},
        {"v3i", 12}, {"v3f", 12}, {"v3d", 24}, {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128},
        {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1}, {"tiledesc", 9},
        {"chromaticities", 32}, {"rational", 8}, {"keycode", 28}, {"timecode", 8}};
    for (const auto& [t, n] : sizes)
        if (t == type) return n;
    return -1;
}

std::int64_t exr_level_size(std::int64_t size, int level, int rounding) {
    const std::int64_t b = std::int64_t(1) << level;
    std::int64_t s = size / b;
    if (rounding == 1 && s * b < size) ++s;
    return std::max<std::int64_t>(s, 1);
}

int exr_round_log2(std::int64_t x, int rounding) {
    int floor_log = 0;
    while ((std::int64_t(1) << (floor_log + 1)) <= x) ++floor_log;
    return (rounding == 1 && (std::int64_t(1) << floor_log) < x) ? floor_log + 1 : floor_log;
}

/// The number of chunks (entries of the offset table) of a part, as OpenEXR computes it.
std::uint64_t exr_chunk_count(const exr_part_scan& P) {
    const std::int64_t w = P.data.width(), h = P.data.height();
    if (!P.tiled) {
        const std::int64_t n = exr_lines_per_chunk[P.compression];
        return std::uint64_t((h + n - 1) / n);
    }
    const auto tiles = [&](int lx, int ly) {
        const std::int64_t lw = exr_level_size(w, lx, P.rounding_mode), lh = exr_level_size(h, ly, P.rounding_mode);
        return std::uint64_t((lw + P.tile_x - 1) / P.tile_x) * std::uint64_t((lh + P.tile_y - 1) / P.tile_y);
    };
    std::uint64_t n = 0;
    if (P.level_mode == 0) {
        n = tiles(0, 0);
    } else if (P.level_mode == 1) {
        const int levels = exr_round_log2(std::max(w, h), P.rounding_mode) + 1;
        for (int l = 0; l < levels; ++l) n += tiles(l, l);
    } else {
        const int nx = exr_round_log2(w, P.rounding_mode) + 1, ny = exr_round_log2(h, P.rounding_mode) + 1;
        for (int lx = 0; lx < nx; ++lx)
            for (int ly = 0; ly < ny; ++ly) n += tiles(lx, ly);
    }
    return n;
}

std::string exr_part_label(const exr_part_scan& P, std::size_t index) {
    return "part " + std::to_string(index) + (P.has_name ? " '" + printable(P.name, 64) + "'" : std::string());
}

/// The value checks of the attribute types OpenEXR allocates from (preview, string vectors,
/// float vectors, channel lists); a channel list adds to P's bytes per pixel.
void check_exr_attribute_value(const exr_reader& r, exr_reader& vr, std::span<const unsigned char> v, std::string_view attr,
                               std::string_view type, std::int32_t size, std::size_t max_name, const std::string& what,
                               exr_part_scan& P) {
    if (type == "preview") { // width, height, 4 w h bytes: OpenEXR allocates from the two fields
        if (size < 8) r.fail(what + " too short");
        const std::uint64_t pw = vr.u32(what), ph = vr.u32(what);
        if (8 + 4 * pw * ph != std::uint64_t(size) || pw > 65536 || ph > 65536)
            r.fail(what + " declares a " + std::to_string(pw) + " x " + std::to_string(ph) + " preview in " +
                   std::to_string(size) + " bytes");
    } else if (type == "stringvector") { // (int32 length, characters)*, exactly `size` bytes
        while (vr.p < v.size()) {
            const std::int32_t n = vr.i32(what);
            if (n < 0 || std::size_t(n) > v.size() - vr.p) r.fail(what + " has an entry beyond its size");
            vr.p += std::size_t(n);
        }
    } else if (type == "floatvector") {
        if (size % 4 != 0) r.fail(what + " has a size that is not a multiple of 4");
    } else if (type == "chlist") { // (name, int32 type, u8 linear, 3 reserved, int32 xs, int32 ys)*, ""
        std::size_t count = 0;
        for (;;) {
            const std::string_view ch = vr.name(max_name, what);
            if (ch.empty()) break;
            const std::int32_t pt = vr.i32(what);
            vr.need(4, what);
            vr.p += 4;
            (void)vr.i32(what);
            (void)vr.i32(what);
            if (pt < 0 || pt > 2) r.fail("channel '" + printable(ch) + "' has pixel type " + std::to_string(pt));
            P.bytes_per_pixel += pt == 1 ? 2 : 4; // HALF : UINT, FLOAT
            ++count;
        }
        if (vr.p != v.size()) r.fail(what + " does not end where its size says");
        if (attr == "channels") {
            if (count == 0) r.fail("no channels");
            P.has_channels = true;
        }
    }
}

/// The attributes the reader needs, stored in P.
void store_exr_attribute(const exr_reader& r, exr_reader& vr, std::span<const unsigned char> v, std::string_view attr,
                         std::string_view type, const std::string& what, const std::string& file, exr_part_scan& P) {
    const auto typed = [&](std::string_view want) {
        if (type != want) r.fail(what + " has type '" + printable(type) + "', not " + std::string(want));
    };
    const auto box = [&] {
        exr_box x;
        x.x0 = vr.i32(what);
        x.y0 = vr.i32(what);
        x.x1 = vr.i32(what);
        x.y1 = vr.i32(what);
        return x;
    };
    if (attr == "dataWindow") {
        typed("box2i");
        P.data = box();
        P.has_data = true;
    } else if (attr == "displayWindow") {
        typed("box2i");
        P.display = box();
        P.has_display = true;
    } else if (attr == "compression") {
        typed("compression");
        P.compression = v[0];
        if (P.compression >= int(std::size(exr_compression_names)))
            throw image_error(file, "unsupported OpenEXR compression (value " + std::to_string(P.compression) + ")");
    } else if (attr == "tiles") {
        typed("tiledesc");
        P.tile_x = vr.u32(what);
        P.tile_y = vr.u32(what);
        const std::uint8_t mode = vr.u8(what);
        P.level_mode = mode & 0x0f;
        P.rounding_mode = mode >> 4;
        if (P.level_mode > 2 || P.rounding_mode > 1) r.fail("unknown tile level mode " + std::to_string(mode));
        P.has_tiles = true;
    } else if (attr == "chunkCount") {
        typed("int");
        P.chunk_count = vr.i32(what);
        P.has_chunk_count = true;
    } else if (attr == "name") {
        typed("string");
        P.name.assign(reinterpret_cast<const char*>(v.data()), v.size());
        P.has_name = true;
    } else if (attr == "type") {
        typed("string");
        P.type.assign(reinterpret_cast<const char*>(v.data()), v.size());
        P.has_type = true;
    } else if (attr == "channels") {
        typed("chlist");
    }
}

/// Reads one attribute of a part's header (its name already read) into P; throws for anything
/// OpenEXR would misread.
void scan_exr_attribute(exr_reader& r, std::span<const unsigned char> b, std::string_view attr, std::size_t max_name,
                        exr_part_scan& P) {
    const std::string& file = r.file;
    const std::string what = "attribute '" + printable(attr) + "'";
    const std::string_view type = r.name(max_name, "the type name of " + what);
    const std::int32_t size = r.i32(what);
    if (size < 0) r.fail(what + " has a negative size");
    r.need(std::size_t(size), what);
    const std::span<const unsigned char> v = b.subspan(r.p, std::size_t(size));
    const int fixed = exr_fixed_attribute_size(type);
    if (fixed >= 0 && size != fixed)
        r.fail(what + " of type " + printable(type) + " has size " + std::to_string(size) + ", not " +
               std::to_string(fixed));
    exr_reader vr{v, 0, file};
    check_exr_attribute_value(r, vr, v, attr, type, size, max_name, what, P);
    store_exr_attribute(r, vr, v, attr, type, what, file, P);
    r.p += std::size_t(size);
}

image_error exr_header_error(const std::string& file, const std::string& label, const std::string& what) {
    return image_error(file, "corrupt OpenEXR header (" + label + ": " + what + ")");
}

/// Sets P.tiled and P.deep from the part's type (multi-part files) or the version's tiled flag
/// (single-part files, whose type attribute must agree); throws image_error.
void resolve_exr_layout(exr_part_scan& P, bool multipart, std::uint32_t flags, const std::string& file, const std::string& label) {
    if (multipart) {
        // Every part of a multi-part file names its type; the version's tiled flag is unused.
        if (!P.has_type) throw exr_header_error(file, label, "no type attribute");
        if (!P.has_name) throw exr_header_error(file, label, "no name attribute");
        if (!P.has_chunk_count) throw exr_header_error(file, label, "no chunkCount attribute");
        if (P.type == "scanlineimage" || P.type == "tiledimage") {
            P.tiled = P.type == "tiledimage";
        } else if (P.type == "deepscanline" || P.type == "deeptile") {
            P.tiled = P.type == "deeptile";
            P.deep = true;
        } else {
            throw image_error(file, "unsupported OpenEXR part type '" + printable(P.type) + "' (" + label + ")");
        }
    } else {
        // A single-part file's layout is its version's tiled flag; a `type` attribute must agree.
        P.tiled = flags & exr_tiled_flag;
        const char* expected = P.tiled ? "tiledimage" : "scanlineimage";
        if (P.has_type && P.type != expected)
            throw image_error(file, "OpenEXR type attribute '" + printable(P.type) + "' contradicts the file's " +
                                        (P.tiled ? "tiled" : "scanline") + " layout (expected '" + expected + "')");
    }
}

/// The windows, the tiles and the decoded sizes against the limits of `o`; throws image_error.
void check_exr_sizes(const exr_part_scan& P, const std::string& file, const std::string& label, const read_options& o) {
    const auto dims = [](const exr_box& x, std::int64_t& w, std::int64_t& h) {
        w = std::clamp<std::int64_t>(x.width(), -1, INT_MAX);
        h = std::clamp<std::int64_t>(x.height(), -1, INT_MAX);
    };
    std::int64_t w = 0, h = 0, dw = 0, dh = 0;
    dims(P.display, dw, dh);
    check_dimensions(int(dw), int(dh), o, file, ("OpenEXR display window of " + label).c_str());
    dims(P.data, w, h);
    check_dimensions(int(w), int(h), o, file, ("OpenEXR data window of " + label).c_str());
    if (P.tiled) {
        if (!P.has_tiles) throw exr_header_error(file, label, "tiled, but no tiles attribute");
        if (P.tile_x < 1 || P.tile_y < 1 || P.tile_x > std::uint32_t(o.max_dimension) ||
            P.tile_y > std::uint32_t(o.max_dimension))
            throw exr_header_error(file, label, "tile size " + std::to_string(P.tile_x) + " x " + std::to_string(P.tile_y) +
                                                    " outside [1, " + std::to_string(o.max_dimension) + "]");
    }
    if (P.deep) return;
    // OpenEXR allocates the decoded pixels of a chunk (a block of scanlines or a tile) up front,
    // and the reader the whole data window: both must fit max_decoded_bytes.
    const std::uint64_t chunk_pixels =
        P.tiled ? std::uint64_t(P.tile_x) * P.tile_y : std::uint64_t(w) * std::uint64_t(exr_lines_per_chunk[P.compression]);
    const std::uint64_t limit = o.max_decoded_bytes;
    for (const std::uint64_t pixels : {std::uint64_t(w) * std::uint64_t(h), chunk_pixels})
        if (P.bytes_per_pixel > limit || pixels > limit / P.bytes_per_pixel)
            throw image_error(file, "OpenEXR " + label + ": " + std::to_string(pixels) + " pixels of " +
                                        std::to_string(P.bytes_per_pixel) + " bytes exceed the decoding limit of " +
                                        std::to_string(limit) + " bytes");
}

/// Checks a part's header as a whole (required attributes, type, windows, tiles, decoded size,
/// chunk count); throws image_error.
void check_exr_part(exr_part_scan& P, std::size_t index, bool multipart, std::uint32_t flags, const std::string& file,
                    const read_options& o) {
    const std::string label = exr_part_label(P, index);
    if (!P.has_channels) throw exr_header_error(file, label, "no channels attribute");
    if (P.compression < 0) throw exr_header_error(file, label, "no compression attribute");
    if (!P.has_data || !P.has_display) throw exr_header_error(file, label, "no data or display window");
    resolve_exr_layout(P, multipart, flags, file, label);
    check_exr_sizes(P, file, label, o);
    const std::uint64_t chunks = exr_chunk_count(P);
    if (P.has_chunk_count && (P.chunk_count < 0 || std::uint64_t(P.chunk_count) != chunks))
        throw exr_header_error(file, label, "chunkCount " + std::to_string(P.chunk_count) + ", but the layout has " +
                                                std::to_string(chunks) + " chunks");
    P.chunk_count = std::int64_t(chunks);
}

/// Walks the headers of every part; throws image_error for anything OpenEXR would misread, any
/// size beyond the limits and any layout the reader does not support.
std::vector<exr_part_scan> scan_exr_headers(std::span<const unsigned char> b, const std::string& file,
                                            const read_options& o) {
    exr_reader r{b, 4, file};
    const std::uint32_t version = r.u32("the version field");
    if ((version & 0xff) != 2)
        throw image_error(file, "unsupported OpenEXR file format version " + std::to_string(version & 0xff) + " (only 2)");
    const std::uint32_t flags = version & ~0xffu;
    if (flags & ~(exr_tiled_flag | exr_long_names_flag | exr_non_image_flag | exr_multipart_flag))
        throw image_error(file, "unsupported OpenEXR version flags 0x" + [&] {
            char buf[16];
            std::snprintf(buf, sizeof buf, "%x", unsigned(flags));
            return std::string(buf);
        }());
    const bool multipart = flags & exr_multipart_flag;
    if (!multipart && (flags & exr_non_image_flag)) throw image_error(file, "deep OpenEXR images are not supported");
    const std::size_t max_name = (flags & exr_long_names_flag) ? 255 : 31;
    std::vector<exr_part_scan> parts;
    for (;;) {
        if (multipart && r.u8("the part list") == 0) break; // the empty header ending the list
        if (multipart) --r.p;
        if (parts.size() >= 4096) throw image_error(file, "corrupt OpenEXR header (more than 4096 parts)");
        exr_part_scan P;
        const std::string where = "the header of part " + std::to_string(parts.size());
        for (std::string_view attr = r.name(max_name, where); !attr.empty(); attr = r.name(max_name, where))
            scan_exr_attribute(r, b, attr, max_name, P);
        check_exr_part(P, parts.size(), multipart, flags, file, o);
        parts.push_back(std::move(P));
        if (!multipart) break;
    }
    if (parts.empty()) throw image_error(file, "corrupt OpenEXR header (a multi-part file without parts)");
    // The chunk offset tables (8 bytes a chunk) follow the headers; OpenEXR allocates them from the
    // counts, so they must be in the file.
    std::uint64_t chunks = 0;
    for (const exr_part_scan& P : parts) chunks += std::uint64_t(P.chunk_count);
    if (chunks > (b.size() - r.p) / 8)
        throw image_error(file, "truncated OpenEXR file (" + std::to_string(chunks) + " chunks need an offset table of " +
                                    std::to_string(8 * chunks) + " bytes; " + std::to_string(b.size() - r.p) +
                                    " bytes follow the header)");
    return parts;
}

/// An Imf::IStream over bytes in memory. Reading past the end throws (as OpenEXR expects) and is
/// remembered, so that the error can say "truncated".
class span_istream final : public Imf::IStream {
public:
    span_istream(std::span<const unsigned char> b, const std::string& file) : Imf::IStream(file.c_str()), b_(b) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ > b_.size() || std::size_t(n) > b_.size() - pos_) {
            past_end_ = true;
            throw Iex::InputExc("unexpected end of file");
        }
        if (n > 0) std::memcpy(c, b_.data() + pos_, std::size_t(n));
        pos_ += std::size_t(n);
        return pos_ < b_.size();
    }
    std::uint64_t tellg() override { return pos_; }
    void seekg(std::uint64_t pos) override { pos_ = pos > b_.size() ? b_.size() + 1 : std::size_t(pos); }
    bool past_end() const { return past_end_; }

private:
    std::span<const unsigned char> b_;
    std::size_t pos_ = 0;
    bool past_end_ = false;
};

/// An Imf::OStream into a byte vector.
class vector_ostream final : public Imf::OStream {
public:
    explicit vector_ostream(std::vector<unsigned char>& out) : Imf::OStream("<memory>"), out_(out) {}
    void write(const char c[], int n) override {
        if (n <= 0) return;
        if (out_.size() < pos_ + std::size_t(n)) out_.resize(pos_ + std::size_t(n));
        std::memcpy(out_.data() + pos_, c, std::size_t(n));
        pos_ += std::size_t(n);
    }
    std::uint64_t tellp() override { return pos_; }
    void seekp(std::uint64_t pos) override { pos_ = std::size_t(pos); }

private:
    std::vector<unsigned char>& out_;
    std::size_t pos_ = 0;
};

/// OpenEXR decodes in the calling thread: every OpenEXR object gets numThreads = 0, and the
/// global thread count (Imf::setGlobalThreadCount) is left alone.
constexpr int exr_threads = 0;

} // namespace

namespace {

std::string exr_part_names(Imf::MultiPartInputFile& file) {
    std::string s;
    for (int i = 0; i < file.parts(); ++i)
        s += (i ? ", " : "") + (file.header(i).hasName() ? "'" + printable(file.header(i).name(), 64) + "'" : "#" + std::to_string(i));
    return s;
}

std::string exr_channel_names(const Imf::ChannelList& channels) {
    std::string found;
    for (auto it = channels.begin(); it != channels.end(); ++it) found += (found.empty() ? "" : ", ") + printable(it.name(), 32);
    return found;
}

bool exr_has(Imf::MultiPartInputFile& file, int i, const char* ch) { return file.header(i).channels().findChannel(ch) != nullptr; }

bool exr_is_image(Imf::MultiPartInputFile& file, int i) {
    const Imf::Header& h = file.header(i);
    return !h.hasType() || h.type() == Imf::SCANLINEIMAGE || h.type() == Imf::TILEDIMAGE;
}

/// The part to read: the one named by o.part, else the first with R, G, B, else the first with Y.
int choose_exr_part(Imf::MultiPartInputFile& file, const std::string& name, const read_options& o) {
    const int parts = file.parts();
    int chosen = -1;
    if (!o.part.empty()) {
        for (int i = 0; i < parts && chosen < 0; ++i)
            if (file.header(i).hasName() && file.header(i).name() == o.part) chosen = i;
        if (chosen < 0)
            throw image_error(name, "OpenEXR has no part named '" + printable(o.part, 64) + "' (parts: " + exr_part_names(file) + ")");
        if (!exr_is_image(file, chosen))
            throw image_error(name, "OpenEXR part '" + printable(o.part, 64) + "' holds deep data (not supported)");
        return chosen;
    }
    for (int i = 0; i < parts && chosen < 0; ++i)
        if (exr_is_image(file, i) && exr_has(file, i, "R") && exr_has(file, i, "G") && exr_has(file, i, "B")) chosen = i;
    for (int i = 0; i < parts && chosen < 0; ++i)
        if (exr_is_image(file, i) && exr_has(file, i, "Y")) chosen = i;
    if (chosen < 0)
        throw image_error(name, parts == 1 ? "OpenEXR has no R, G, B or Y channels (channels: " +
                                                 exr_channel_names(file.header(0).channels()) + ")"
                                           : "OpenEXR has no part with R, G, B or Y channels (parts: " + exr_part_names(file) + ")");
    return chosen;
}

/// What the chosen part holds: RGB, Y alone, or Y/RY/BY (each channel at full resolution).
struct exr_channels_kind {
    bool rgb = false, luma = false, chroma = false;
};
exr_channels_kind exr_kind(Imf::MultiPartInputFile& file, int chosen, const std::string& name, const read_options& o) {
    exr_channels_kind k;
    const Imf::ChannelList& channels = file.header(chosen).channels();
    k.rgb = exr_has(file, chosen, "R") && exr_has(file, chosen, "G") && exr_has(file, chosen, "B");
    k.luma = !k.rgb && exr_has(file, chosen, "Y");
    k.chroma = k.luma && exr_has(file, chosen, "RY") && exr_has(file, chosen, "BY");
    if (!k.rgb && !k.luma)
        throw image_error(name, "OpenEXR part '" + printable(o.part, 64) + "' has no R, G, B or Y channels (channels: " +
                                    exr_channel_names(channels) + ")");
    static constexpr const char* rgb_names[3] = {"R", "G", "B"};
    static constexpr const char* y_name[1] = {"Y"};
    for (const char* ch : k.rgb ? std::span<const char* const>(rgb_names) : std::span<const char* const>(y_name)) {
        const Imf::Channel& c = *channels.findChannel(ch);
        if (c.xSampling != 1 || c.ySampling != 1)
            throw image_error(name, std::string("subsampled OpenEXR channel '") + ch + "' not supported");
    }
    return k;
}

/// The data window's RGB (or Y, copied to all three) pixels of a part, RGB interleaved.
void read_exr_rgb_or_y(Imf::MultiPartInputFile& file, int chosen, bool rgb, const Imath::Box2i& dwin, std::vector<float>& px) {
    const int dw = dwin.max.x - dwin.min.x + 1;
    Imf::InputPart part(file, chosen);
    Imf::FrameBuffer fb;
    for (int k = 0; k < (rgb ? 3 : 1); ++k)
        fb.insert(rgb ? (k == 0 ? "R" : k == 1 ? "G" : "B") : "Y",
                  Imf::Slice::Make(Imf::FLOAT, px.data() + k, dwin, 3 * sizeof(float), 3 * sizeof(float) * std::size_t(dw)));
    part.setFrameBuffer(fb);
    part.readPixels(dwin.min.y, dwin.max.y);
    if (!rgb)
        for (std::size_t t = 0; 3 * t < px.size(); ++t) px[3 * t + 1] = px[3 * t + 2] = px[3 * t];
}

/// Luminance/chroma: OpenEXR's RgbaInputFile does the conversion (chroma reconstruction and
/// YCA -> RGB with the file's chromaticities). It reads the first part of a file, so another part
/// is first copied, still compressed, into a single-part file in memory.
void read_exr_luma_chroma(Imf::MultiPartInputFile& file, int chosen, bool tiled, std::span<const unsigned char> bytes,
                          const std::string& name, const Imath::Box2i& dwin, std::vector<float>& px) {
    const int dw = dwin.max.x - dwin.min.x + 1;
    std::vector<unsigned char> single;
    std::span<const unsigned char> src = bytes;
    if (chosen != 0 || file.parts() > 1) {
        Imf::Header sh = file.header(chosen);
        vector_ostream os(single);
        if (tiled) {
            Imf::TiledInputPart tin(file, chosen);
            Imf::TiledOutputFile out(os, sh, exr_threads);
            out.copyPixels(tin);
        } else {
            Imf::InputPart pin(file, chosen);
            Imf::OutputFile out(os, sh, exr_threads);
            out.copyPixels(pin);
        }
        src = single;
    }
    span_istream in2(src, name);
    Imf::RgbaInputFile rin(in2, exr_threads);
    std::vector<Imf::Rgba> rgba(px.size() / 3);
    // Base address of pixel (0, 0) in the data window's coordinates, computed on integers (the
    // pointer itself may lie outside the buffer; OpenEXR only adds offsets back).
    const std::intptr_t base = reinterpret_cast<std::intptr_t>(rgba.data()) -
                               (std::intptr_t(dwin.min.x) + std::intptr_t(dwin.min.y) * std::intptr_t(dw)) * std::intptr_t(sizeof(Imf::Rgba));
    rin.setFrameBuffer(reinterpret_cast<Imf::Rgba*>(base), 1, std::size_t(dw));
    rin.readPixels(dwin.min.y, dwin.max.y);
    for (std::size_t t = 0; t < rgba.size(); ++t) {
        px[3 * t] = float(rgba[t].r);
        px[3 * t + 1] = float(rgba[t].g);
        px[3 * t + 2] = float(rgba[t].b);
    }
}

/// The display window is the image: its pixels outside the data window are 0, data outside it
/// is cropped.
image_rgb32f exr_display_image(std::vector<float>&& px, const Imath::Box2i& dwin, const Imath::Box2i& disp) {
    const int dw = dwin.max.x - dwin.min.x + 1;
    const int w = disp.max.x - disp.min.x + 1, h = disp.max.y - disp.min.y + 1;
    if (dwin == disp) {
        image_rgb32f img;
        img.width = w;
        img.height = h;
        img.rgb = std::move(px);
        return img;
    }
    image_rgb32f img(w, h);
    const int x0 = std::max(dwin.min.x, disp.min.x), x1 = std::min(dwin.max.x, disp.max.x);
    const int y0 = std::max(dwin.min.y, disp.min.y), y1 = std::min(dwin.max.y, disp.max.y);
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const float* s = px.data() + 3 * (std::size_t(y - dwin.min.y) * std::size_t(dw) + std::size_t(x - dwin.min.x));
            std::copy(s, s + 3, img.texel(x - disp.min.x, y - disp.min.y));
        }
    return img;
}

/// Reads the selected part's display window as RGB floats (see image_io.hpp for the rules).
image_rgb32f decode_exr_part(std::span<const unsigned char> bytes, const std::string& name, const read_options& o,
                             span_istream& in, std::string& detail) {
    Imf::MultiPartInputFile file(in, exr_threads, true);
    const int parts = file.parts();
    const int chosen = choose_exr_part(file, name, o);
    const exr_channels_kind kind = exr_kind(file, chosen, name, o);
    const Imf::Header& H = file.header(chosen);
    const Imath::Box2i dwin = H.dataWindow(), disp = H.displayWindow();
    const int dw = dwin.max.x - dwin.min.x + 1, dh = dwin.max.y - dwin.min.y + 1;
    check_dimensions(disp.max.x - disp.min.x + 1, disp.max.y - disp.min.y + 1, o, name, "OpenEXR display window"); // scanned already
    check_dimensions(dw, dh, o, name, "OpenEXR data window");
    const bool tiled = H.hasType() ? Imf::isTiled(H.type()) : Imf::isTiled(file.version());
    detail = (parts > 1 ? "part " + std::to_string(chosen) + (H.hasName() ? " '" + printable(H.name(), 64) + "'" : std::string()) +
                              " of " + std::to_string(parts) + ", "
                        : std::string()) +
             exr_compression_names[std::min<int>(H.compression(), int(std::size(exr_compression_names)) - 1)] +
             (tiled ? ", tiled" : ", scanline") + (kind.rgb ? ", RGB" : kind.chroma ? ", Y/RY/BY" : ", Y");
    std::vector<float> px(3 * std::size_t(dw) * std::size_t(dh), 0.0f);
    if (kind.chroma) read_exr_luma_chroma(file, chosen, tiled, bytes, name, dwin, px);
    else read_exr_rgb_or_y(file, chosen, kind.rgb, dwin, px);
    return exr_display_image(std::move(px), dwin, disp);
}

} // namespace

image_rgb32f read_exr_memory(std::span<const unsigned char> bytes, const std::string& name, const read_options& o,
                             read_report* report) {
    if (bytes.empty()) throw image_error(name, "empty file");
    if (bytes.size() < 8) throw image_error(name, "truncated OpenEXR file (no version header)");
    if (std::memcmp(bytes.data(), exr_magic, 4) != 0) throw image_error(name, "not an OpenEXR file (bad magic number)");
    (void)scan_exr_headers(bytes, name, o);
    span_istream in(bytes, name);
    read_report r;
    r.format = "OpenEXR";
    image_rgb32f img;
    try {
        img = decode_exr_part(bytes, name, o, in, r.detail);
    } catch (const image_error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw image_error(name, "out of memory decoding OpenEXR");
    } catch (const std::exception& e) {
        // OpenEXR's messages (Iex::BaseExc) often start with the stream's name: keep what follows.
        std::string msg = e.what();
        if (msg.starts_with(name)) msg.erase(0, name.size());
        while (!msg.empty() && (msg.front() == ':' || msg.front() == ' ' || msg.front() == '.')) msg.erase(0, 1);
        throw image_error(name, std::string(in.past_end() ? "truncated OpenEXR file" : "corrupt OpenEXR data") +
                                    " (OpenEXR: " + printable(msg, 200) + ")");
    }
    apply_texel_policy(img, o, r, name);
    if (report) *report = r;
    return img;
}

namespace {
void insert_attributes(Imf::Header& header, const exr_attributes& attributes) {
    for (const auto& [key, value] : attributes) header.insert(key, Imf::StringAttribute(value));
}
} // namespace

std::vector<unsigned char> encode_exr(const image_rgb32f& image, const std::string& name, const exr_attributes& attributes) {
    check_image(image, name);
    std::vector<unsigned char> out;
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        insert_attributes(header, attributes);
        for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
        vector_ostream os(out);
        Imf::OutputFile file(os, header, exr_threads);
        Imf::FrameBuffer fb;
        // OpenEXR only reads through the slices of an output file.
        char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgb.data()));
        const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(image.width);
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        throw image_error(name, std::string("OpenEXR encoding failed (") + printable(e.what(), 200) + ")");
    }
    return out;
}

void write_exr(const std::string& path, const image_rgb32f& image, const exr_attributes& attributes) {
    write_file_atomic(path, encode_exr(image, path, attributes));
}

exr_attributes read_exr_string_attributes(const std::string& path) {
    const std::vector<unsigned char> bytes = read_file(path);
    const std::span<const unsigned char> b(bytes);
    if (b.size() < 8 || std::memcmp(b.data(), exr_magic, 4) != 0) throw image_error(path, "not an OpenEXR file");
    (void)scan_exr_headers(b, path, read_options{});
    span_istream in(b, path);
    exr_attributes out;
    try {
        Imf::MultiPartInputFile file(in, exr_threads);
        const Imf::Header& h = file.header(0);
        for (auto it = h.begin(); it != h.end(); ++it)
            if (const auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) out.emplace_back(it.name(), a->value());
    } catch (const std::exception& e) {
        throw image_error(path, std::string(in.past_end() ? "truncated OpenEXR file" : "corrupt OpenEXR data") + " (OpenEXR: " +
                                    printable(e.what(), 200) + ")");
    }
    return out;
}

std::vector<unsigned char> encode_exr_rgba(const image_rgba32f& image, const std::string& name, const exr_attributes& attributes) {
    if (image.width < 1 || image.height < 1 || image.rgba.size() != std::size_t(image.width) * std::size_t(image.height) * 4)
        throw image_error(name, "RGBA image of " + std::to_string(image.rgba.size()) + " floats does not match its size");
    std::vector<unsigned char> out;
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        insert_attributes(header, attributes);
        const char* names[4] = {"R", "G", "B", "A"};
        for (const char* ch : names) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
        vector_ostream os(out);
        Imf::OutputFile file(os, header, exr_threads);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgba.data()));
        const std::size_t xs = 4 * sizeof(float), ys = xs * std::size_t(image.width);
        for (std::size_t c = 0; c < 4; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        throw image_error(name, std::string("OpenEXR encoding failed (") + printable(e.what(), 200) + ")");
    }
    return out;
}

void write_exr_rgba(const std::string& path, const image_rgba32f& image, const exr_attributes& attributes) {
    write_file_atomic(path, encode_exr_rgba(image, path, attributes));
}

image_rgba32f read_exr_rgba(const std::string& path) {
    const std::vector<unsigned char> bytes = read_file(path);
    const std::span<const unsigned char> b(bytes);
    if (b.size() < 8 || std::memcmp(b.data(), exr_magic, 4) != 0) throw image_error(path, "not an OpenEXR file");
    (void)scan_exr_headers(b, path, read_options{});
    span_istream in(b, path);
    image_rgba32f img;
    try {
        Imf::MultiPartInputFile file(in, exr_threads);
        Imf::InputPart part(file, 0);
        const Imath::Box2i dw = part.header().dataWindow();
        img.width = dw.max.x - dw.min.x + 1;
        img.height = dw.max.y - dw.min.y + 1;
        if (dw.min.x != 0 || dw.min.y != 0 || img.width < 1 || img.height < 1 || img.width > 4096 || img.height > 4096)
            throw image_error(path, "unexpected data window for an RGBA table");
        img.rgba.assign(std::size_t(img.width) * std::size_t(img.height) * 4, 0.0f);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(img.rgba.data());
        const std::size_t xs = 4 * sizeof(float), ys = xs * std::size_t(img.width);
        const char* names[4] = {"R", "G", "B", "A"};
        for (std::size_t c = 0; c < 4; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys, 1, 1, 0.0));
        part.setFrameBuffer(fb);
        part.readPixels(0, img.height - 1);
    } catch (const image_error&) {
        throw;
    } catch (const std::exception& e) {
        throw image_error(path, std::string(in.past_end() ? "truncated OpenEXR file" : "corrupt OpenEXR data") + " (OpenEXR: " +
                                    printable(e.what(), 200) + ")");
    }
    return img;
}
} // namespace ibl_bake
