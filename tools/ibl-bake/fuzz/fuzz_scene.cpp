// tools/ibl-bake/fuzz/fuzz_scene.cpp — libFuzzer harness over the scene reader of ibl-bake
// --scene: ibl_bake::parse_scene (JSON syntax, the scene's keys and values) and then, as the plan
// stage does, ibl::make_bake_plan and ibl::estimate_cost on the result.
// Contract under test: any text either gives a plan or throws ibl_bake::scene_error (parse_scene)
// or std::invalid_argument (make_bake_plan); anything else (a crash, a sanitizer report, another
// exception, a hang, a leak) is a finding. The first byte picks the plan settings (the virtual
// chain's level count 1..8 and base size) so that the planner's loops see several shapes.
//
// Build and run: scripts/fuzz_tool.sh (clang++ -fsanitize=fuzzer,address,undefined).

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <ibl/bake/plan.hpp>

#include "io/scene_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ibl::plan_settings set;
    if (size > 0) {
        set.levels = 1 + data[0] % 8;
        set.max_base_size = 1 << (data[0] / 8 % 12); // 1 .. 2048
        set.policy = (data[0] & 0x80) ? ibl::roughness_mip_policy::filament() : ibl::roughness_mip_policy::linear();
    }
    const std::string text(reinterpret_cast<const char*>(data), size);
    ibl::scene_description scene;
    try {
        scene = ibl_bake::parse_scene(text, "fuzz.json");
    } catch (const ibl_bake::scene_error&) {
        return 0;
    }
    try {
        const ibl::bake_plan plan = ibl::make_bake_plan(scene, set);
        (void)ibl::estimate_cost(plan, set.source_subsamples);
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
