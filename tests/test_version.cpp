// core/config: the one version of the headers, and the package version CMake derives from it.
#include <doctest/doctest.h>

#include <ibl/core/config.hpp>

#include <fstream>
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
    const std::string key = "set(PACKAGE_VERSION \"";
    const std::size_t begin = s.find(key);
    REQUIRE(begin != std::string::npos);
    const std::size_t end = s.find('"', begin + key.size());
    REQUIRE(end != std::string::npos);
    CHECK(s.substr(begin + key.size(), end - begin - key.size()) == IBL_VERSION_STRING);
}
#endif
