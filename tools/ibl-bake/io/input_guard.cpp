// tools/ibl-bake/io/input_guard.cpp — input file checks and the radiance clamp (input_guard.hpp).

#include "io/input_guard.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <sys/stat.h>

namespace ibl_bake {

std::uint64_t input_byte_limit(std::uint64_t max_pixels) noexcept {
    constexpr std::uint64_t base = std::uint64_t(64) << 20, per_pixel = 32;
    const std::uint64_t cap = (~std::uint64_t(0) - base) / per_pixel;
    return base + std::min(max_pixels, cap) * per_pixel;
}

namespace {
const char* file_kind(mode_t m) noexcept {
    if (S_ISDIR(m)) return "a directory";
    if (S_ISFIFO(m)) return "a FIFO (named pipe)";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISSOCK(m)) return "a socket";
    return "not a regular file";
}
} // namespace

void check_input_file(const std::string& path, std::uint64_t max_bytes) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        const int e = errno;
        throw image_error(path, e == ENOENT ? std::string("no such file") : std::string("cannot access: ") + std::strerror(e));
    }
    if (!S_ISREG(st.st_mode))
        throw image_error(path, std::string("is ") + file_kind(st.st_mode) + ", not a regular file; only regular files are read");
    const auto size = std::uint64_t(st.st_size);
    if (size > max_bytes)
        throw image_error(path, "file of " + std::to_string(size) + " bytes is larger than the limit of " + std::to_string(max_bytes) +
                                    " bytes");
}

std::size_t clamp_radiance(image_rgb32f& image, read_report& report) noexcept {
    std::size_t n = 0;
    float max_value = 0.0f;
    for (float& v : image.rgb) {
        if (std::isfinite(v) && v > radiance_clamp_bound) {
            v = radiance_clamp_bound;
            ++n;
        }
        if (v > max_value) max_value = v;
    }
    report.max_value = max_value;
    return n;
}

} // namespace ibl_bake
