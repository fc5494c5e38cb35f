// Uses the installed headers through find_package(ibl): a value from each layer.
#include <ibl/ibl.hpp>

#include <cmath>
#include <cstdio>

int main() {
    const float d = ibl::ndf_ggx(1.0f, 0.5f); // 1 / (pi alpha^2) at the peak
    const float expected = 1.0f / (3.14159265f * 0.25f);
    std::printf("ibl %d.%d.%d: D_ggx(n.h = 1, alpha = 0.5) = %.6f (expected %.6f)\n", ibl::version_major,
                ibl::version_minor, ibl::version_patch, d, expected);
    return std::fabs(d - expected) <= 1e-5f * expected ? 0 : 1;
}
