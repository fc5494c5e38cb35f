// tools/ibl-bake/main.cpp — ibl-bake: bakes image-based-lighting products from a lat-long HDR
// image (Radiance .hdr, OpenEXR) or the built-in sky + sun, with a preview and an error/time
// report; `--scene` bakes only what a scene needs. Usage and file formats: docs/ibl-bake.md,
// `ibl-bake --help`. `--probes` bakes a set of local reflection probes (stages/probe_bake.hpp).
//
// Exit status: 0 success; 1 a failure while baking (unreadable / truncated / LDR input, a bad
// scene file, a write error: the output directory is left as it was, see output_stage.hpp);
// 2 bad command line. --lookup: 0 when every query was answered, 1 otherwise (or when DIR
// cannot be loaded).

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "options/bake_options.hpp"
#include "stages/pipeline.hpp"
#include "query/lookup.hpp"
#include "query/probe_lookup.hpp"
#include "stages/probe_bake.hpp"
#include "stages/stages.hpp"

int main(int argc, char** argv) {
    using namespace ibl_bake;
    bake_options opt;
    try {
        opt = parse_options(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const usage_error& e) {
        std::fprintf(stderr, "ibl-bake: %s\n(ibl-bake --help lists the options)\n", e.what());
        return 2;
    }
    if (opt.help) {
        std::fputs(usage_text().c_str(), stdout);
        return 0;
    }
    if (opt.version) {
        std::printf("ibl-bake %s\n", version_string().c_str());
        return 0;
    }
    try {
        if (!opt.lookup.empty() && is_probe_set_folder(opt.lookup))
            return run_probe_lookup(load_probe_set(opt.lookup), std::cin, std::cout);
        if (!opt.lookup.empty()) return run_lookup(load_baked_folder(opt.lookup), std::cin, std::cout);
        if (!opt.probes.empty()) {
            run_probe_bake(opt, stdout);
            return 0;
        }
        run_bake(opt, stdout);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ibl-bake: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
