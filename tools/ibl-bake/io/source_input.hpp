#pragma once
// tools/ibl-bake/io/source_input.hpp — reading --input into a source environment.
//
//   a path containing {face}       six face files (px nx py ny pz nz), each square, equal sizes
//   a .ktx2 file                   level 0 of a KTX2 cubemap (any of the formats ibl-bake writes)
//   any other .hdr / .exr image    by its aspect ratio (--input-layout overrides): 2:1 lat-long,
//                                  4:3 horizontal cross, 3:4 vertical cross, 6:1 / 1:6 strips
// Faces are in the library's GL orientation (cube_layout.hpp has the cross diagrams). A cube input
// becomes an ibl::cubemap<float> with its full mip chain, which the source stage bakes to the
// plan's face size like any other environment (a copy when the sizes agree).

#include <memory>
#include <string>

#include <ibl/env/analytic.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>

#include "io/image_io.hpp"
#include "options/bake_options.hpp"

namespace ibl_bake {

/// The environment the products are baked from: the built-in sky + sun, a lat-long image or a
/// cube (a cross, six faces or a KTX2 cubemap: the rules above).
struct source_env {
    std::string name;
    bool analytic = true;
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    std::unique_ptr<ibl::latlong<float>> map;  ///< lat-long inputs
    std::unique_ptr<ibl::cubemap<float>> cube; ///< cube inputs (full mip chain)
    std::string layout;                        ///< latlong, hcross, vcross, hstrip, vstrip, faces, ktx2
    bool mirrored = false;                     ///< --mirror applied (x -> -x)
    read_report rr;
    std::size_t values_clamped = 0;            ///< values above radiance_clamp_bound (input_guard.hpp)
    int width = 0, height = 0;                 ///< of the input image (a cube input: its face size)

    /// Calls f with the environment (ibl::sky_environment<double>, ibl::latlong<float> or
    /// ibl::cubemap<float>).
    template <class F> auto visit(F&& f) const {
        if (analytic) return f(sky);
        if (cube) return f(*cube);
        return f(*map);
    }
};

/// Reads opt.input per the rules above into src (name, kind, image or cube, read report).
/// Throws image_error naming the file.
void read_source(const bake_options& opt, source_env& src);

/// Mirrors the environment x -> -x (--mirror): the sky's sun, a lat-long's columns (u -> 1.5 - u),
/// a cube input's texels (texel centres map onto texel centres). Exact: no resampling.
void mirror_source(source_env& src);

} // namespace ibl_bake
