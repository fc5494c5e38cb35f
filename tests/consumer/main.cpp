// Uses the ibl headers through a CMake package (find_package, tests/consumer) or through
// add_subdirectory (tests/consumer_subdir): a value from the library, and the version the build
// system reports (IBL_CONSUMER_PACKAGE_VERSION) must be the headers' own.
#include <ibl/ibl.hpp>

#include <cmath>
#include <cstdio>
#include <string_view>

#ifndef IBL_CONSUMER_PACKAGE_VERSION
#error "the consumer's CMakeLists.txt passes the package version as IBL_CONSUMER_PACKAGE_VERSION"
#endif
static_assert(std::string_view(IBL_VERSION_STRING) == IBL_CONSUMER_PACKAGE_VERSION,
              "the CMake package version differs from IBL_VERSION_STRING in ibl/core/config.hpp");

int main() {
    const float d = ibl::ndf_ggx(1.0f, 0.5f); // 1 / (pi alpha^2) at the peak
    const float expected = 1.0f / (3.14159265f * 0.25f);
    std::printf("ibl %s (package %s): D_ggx(n.h = 1, alpha = 0.5) = %.6f (expected %.6f)\n", IBL_VERSION_STRING,
                IBL_CONSUMER_PACKAGE_VERSION, d, expected);
    return std::fabs(d - expected) <= 1e-5f * expected ? 0 : 1;
}
