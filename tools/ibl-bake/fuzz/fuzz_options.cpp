// tools/ibl-bake/fuzz/fuzz_options.cpp — libFuzzer harness over the command line parser of
// ibl-bake: the input bytes are split at NUL and newline characters into argv[1..] and handed to
// ibl_bake::parse_options; a result is then used as run_bake would start (settings_for,
// auto_levels).
// Contract under test: any argument list either parses or throws ibl_bake::usage_error; anything
// else (a crash, a sanitizer report, another exception, a hang, a leak) is a finding.
//
// Build and run: scripts/fuzz_tool.sh (clang++ -fsanitize=fuzzer,address,undefined).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "options/bake_options.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> args(1);
    for (std::size_t i = 0; i < size; ++i) {
        const char c = char(data[i]);
        if (c == '\0' || c == '\n') args.emplace_back();
        else args.back().push_back(c);
    }
    if (args.size() > 64) return 0; // argv length is not what is under test
    try {
        const ibl_bake::bake_options o = ibl_bake::parse_options(args);
        (void)ibl_bake::settings_for(o.q);
        (void)ibl_bake::auto_levels(o.size);
    } catch (const ibl_bake::usage_error&) {
    }
    return 0;
}
