// tools/ibl-bake/fuzz/fuzz_image_readers.cpp — libFuzzer harness over the memory readers of
// the bake tool: format dispatch, Radiance HDR (header parser, structural walk, stb_image),
// OpenEXR (header pre-scan, OpenEXR's header and pixel decoding through the memory stream) and
// the KTX2 parser.
// Contract under test: any input either decodes or throws ibl_bake::image_error; anything else
// (a crash, a sanitizer report, another exception, a hang, a leak) is a finding.
//
// Build and run: scripts/fuzz.sh (clang++ -fsanitize=fuzzer,address,undefined; OpenEXR is Debian's
// uninstrumented library: coverage counts our code only, valgrind checks OpenEXR's accesses).

#include <cstddef>
#include <cstdint>
#include <span>

#include "io/image_io.hpp"
#include "io/ktx2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const unsigned char> bytes(data, size);
    ibl_bake::read_options options;
    options.max_dimension = 4096;     // keep allocations well below libFuzzer's RSS limit
    options.max_pixels = 1u << 20;
    options.max_decoded_bytes = std::uint64_t(1) << 26;
    options.part = (size % 3 == 0) ? "rgb" : ""; // the seeds' multi-part files name a part "rgb"
    options.nonfinite = (size % 2) ? ibl_bake::nonfinite_policy::reject : ibl_bake::nonfinite_policy::replace_with_zero;
    try {
        (void)ibl_bake::read_image_memory(bytes, "fuzz", options);
    } catch (const ibl_bake::image_error&) {
    }
    // The format-specific entry points skip the dispatch on magic bytes.
    try {
        (void)ibl_bake::read_hdr_memory(bytes, "fuzz.hdr", options);
    } catch (const ibl_bake::image_error&) {
    }
    try {
        (void)ibl_bake::read_exr_memory(bytes, "fuzz.exr", options);
    } catch (const ibl_bake::image_error&) {
    }
    try {
        (void)ibl_bake::decode_ktx2_cubemap(bytes, "fuzz.ktx2");
    } catch (const ibl_bake::image_error&) {
    }
    return 0;
}
