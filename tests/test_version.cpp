// core/config: the one version of the headers, and the package version CMake derives from it.
#include <doctest/doctest.h>

#include <ibl/core/config.hpp>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace {
// Compile-time: the constants and the string follow the three numbers.
static_assert(ibl::version_major == IBL_VERSION_MAJOR);
static_assert(ibl::version_minor == IBL_VERSION_MINOR);
static_assert(ibl::version_patch == IBL_VERSION_PATCH);
static_assert(IBL_VERSION == IBL_VERSION_MAJOR * 10000 + IBL_VERSION_MINOR * 100 + IBL_VERSION_PATCH);
#if IBL_VERSION_MAJOR < 0 || IBL_VERSION_MINOR < 0 || IBL_VERSION_MINOR > 99 || IBL_VERSION_PATCH < 0 ||             \
    IBL_VERSION_PATCH > 99
#error "IBL_VERSION packs minor and patch into two decimal digits each"
#endif
} // namespace

TEST_CASE("version: IBL_VERSION_STRING is major.minor.patch of the macros") {
    const std::string expected = std::to_string(IBL_VERSION_MAJOR) + "." + std::to_string(IBL_VERSION_MINOR) + "." +
                                 std::to_string(IBL_VERSION_PATCH);
    CHECK(std::string(IBL_VERSION_STRING) == expected);
}

#ifdef IBL_TEST_PACKAGE_VERSION_FILE
TEST_CASE("version: the package version file (iblConfigVersion.cmake) carries the header's version") {
    std::ifstream in(IBL_TEST_PACKAGE_VERSION_FILE);
    REQUIRE_MESSAGE(in.good(), "cannot read " IBL_TEST_PACKAGE_VERSION_FILE);
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    std::smatch m;
    REQUIRE(std::regex_search(s, m, std::regex("set\\(PACKAGE_VERSION \"([^\"]*)\"\\)")));
    CHECK(m[1].str() == IBL_VERSION_STRING);
}
#endif
