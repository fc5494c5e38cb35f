// tools/ibl-bake/stages/stage_compression.cpp — check (block-compressed --ktx2-format only): what the
// compression does to the chain and to what is shaded with it. specular.ktx2 is encoded once by the
// specular stage and decoded here as a GPU decodes it; this stage compares it with the float chain:
//   per level  RMSLE (RMS over texels and channels of ln(1 + x') - ln(1 + x)), relative RMSE of
//              luminance (floor 1e-3 x the level's mean, as the bake's checks), and the seam step:
//              the mean luminance step across the 12 cube edges (each border texel against its
//              neighbour on the adjacent face) over the mean step from those border texels to
//              their inward neighbours, before and after compression;
//   shaded     the chain lookup (--specular-lookup) at roughness 0.05 .. 1 from the compressed chain
//              against the float chain, relative RMSE of luminance over the check directions; and
//              the preview grid (preview_render.hpp, one sample per pixel, sphere pixels) rendered from
//              the compressed files (chain and irradiance map) against the float products;
//   cost       file size, bits per texel, encode time (the encoder's effort and threads).

#include "stages/preview_render.hpp"
#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>

#include <ibl/core/color.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/reference/metrics.hpp>

#include "io/block_codec.hpp"
#include "io/cube_layout.hpp"

namespace ibl_bake {

namespace {

double lum(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

/// The luminance of texel (face, x, y) of level l.
double lum_at(const ibl::cubemap<float>& c, int l, int face, int x, int y) {
    const fvec3 t = c.texel(face, x, y, l);
    const float rgb[3] = {t.x, t.y, t.z};
    return lum(rgb);
}

/// The seam step of level l: the mean luminance step across the 12 cube edges (each border texel
/// against the texel just across the edge, on the adjacent face) over the mean step from each of
/// those border texels to its inward neighbour (the variation next to the edges, inside the faces).
/// About 1 where the level is smooth across its edges; a block format whose blocks meet at an
/// edge with different endpoint rounding raises it. 0 for levels without an inward neighbour.
double seam_step(const ibl::cubemap<float>& c, int l) {
    const int n = c.size(l);
    if (n < 2) return 0.0;
    double edge = 0.0, inner = 0.0;
    const double step = 2.0 / n;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                if (x != 0 && y != 0 && x != n - 1 && y != n - 1) continue;
                const double a = lum_at(c, l, f, x, y);
                const double sc = 2.0 * (x + 0.5) / n - 1.0, tc = 2.0 * (y + 0.5) / n - 1.0;
                const auto across = [&](double s2, double t2, int ix, int iy) {
                    const ibl::cube_coord<double> q = ibl::cube_lookup(ibl::cube_face_point(f, s2, t2));
                    const int qx = std::clamp(int(q.s * n), 0, n - 1), qy = std::clamp(int(q.t * n), 0, n - 1);
                    edge += std::fabs(a - lum_at(c, l, q.face, qx, qy));
                    inner += std::fabs(a - lum_at(c, l, f, ix, iy));
                };
                if (x == 0) across(sc - step, tc, 1, y);
                if (x == n - 1) across(sc + step, tc, n - 2, y);
                if (y == 0) across(sc, tc - step, x, 1);
                if (y == n - 1) across(sc, tc + step, x, n - 2);
            }
    return inner > 0.0 ? edge / inner : 0.0;
}

struct level_row {
    int level = 0, size = 0;
    double rmsle = 0.0, rel_rmse = 0.0, seam_float = 0.0, seam_stored = 0.0;
};

struct lookup_row {
    double roughness = 0.0, rel_rmse = 0.0;
};

class compression_stage final : public stage {
public:
    const char* key() const override { return "compression"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override {
        return ctx.chain && ctx.specular_file && ktx2_block_compressed(ktx2_format_of(ctx.opt.ktx2_format)) &&
               ctx.opt.checks != check_mode::none;
    }
    double check_ms() const override { return ms_; }

    void run(bake_context& ctx) override {
        ctx.prog.begin("check compression");
        const auto t0 = std::chrono::steady_clock::now();
        format_ = ctx.opt.ktx2_format;
        quality_ = ctx.opt.ktx2_quality;
        zstd_ = ctx.opt.ktx2_zstd;
        const ibl::cubemap<float>& chain = *ctx.chain;
        const ibl::cubemap<float>& stored = ctx.specular_file->decoded;
        bytes_ = ctx.specular_file->bytes.size();
        encode_ms_ = ctx.specular_file->encode_ms;
        std::size_t texels = 0;
        for (int l = 0; l < chain.levels(); ++l) texels += 6 * std::size_t(chain.size(l)) * std::size_t(chain.size(l));
        texels_ = texels;
        for (int l = 0; l < chain.levels(); ++l) levels_.push_back(compare_level(chain, stored, l));
        // the shaded result: lookups and the preview grid from the compressed files
        product_view bp = baked_view(ctx);
        product_view bc = bp;
        bc.chain = &stored;
        diffuse_data diffuse_c = ctx.diffuse;
        if (ctx.diffuse.kind == ibl::diffuse_product::irradiance_map) {
            diffuse_c.map = cubemap_from_rgb32f(decode_ktx2_cubemap(
                encode_ktx2_cubemap(cubemap_to_rgb32f(ctx.diffuse.map), ktx2_format_of(format_), "check", "irradiance.ktx2", nullptr, {},
                                    ktx2_encoding_of(ctx.opt)),
                "irradiance.ktx2"));
            bc.diffuse = &diffuse_c;
        }
        lookups(ctx, bp, bc);
        if (ctx.lut && !ctx.scene_mode) preview(ctx, bp, bc);
        ms_ = ms_since(t0);
        ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        double worst_rmsle = 0.0, seam_f = 0.0, seam_s = 0.0;
        for (const auto& l : levels_) {
            worst_rmsle = std::max(worst_rmsle, l.rmsle);
            seam_f = std::max(seam_f, l.seam_float), seam_s = std::max(seam_s, l.seam_stored);
        }
        const std::string fmt_name = to_string(format_);
        std::vector<table_row> rows;
        rows.push_back(table_row{"  " + fmt_name + " specular.ktx2", std::string(to_string(quality_)) + " encoder" + (zstd_ ? fmt(", zstd %.0f", zstd_) : ""),
                                 fmt("%.3g bits/texel", bits_per_texel()) + fmt(", %.0f KiB", double(bytes_) / 1024.0), encode_ms_,
                                 fmt("worst level RMSLE %.3g", worst_rmsle) + fmt2(", seam step %.3g -> %.3g", seam_f, seam_s)}
                           .compact(fmt_name + " encode", fmt("RMSLE %.3g", worst_rmsle) + fmt(", %.3g bits/texel", bits_per_texel())));
        rows.push_back(table_row{"  " + fmt_name + " shaded", "lookups r >= 0.25; preview grid", "vs float products", -1.0,
                                 fmt2("lookup rel RMSE %.3g, preview %.3g", lookup_rough_, preview_rel_)}
                           .compact(fmt_name + " shaded", fmt2("rel RMSE %.3g (r>=0.25), preview %.3g", lookup_rough_, preview_rel_))
                           .alarm(lookup_rough_, 0.02, "the compressed chain moves glossy reflections by > 2%: --ktx2-quality exhaustive, "
                                                       "or rgba16f for this environment"));
        for (const auto& l : levels_) {
            table_row r{fmt2("    l%.0f %.0f^2", l.level, l.size), "compressed vs float", "", -1.0,
                        fmt2("RMSLE %.3g, rel RMSE %.3g", l.rmsle, l.rel_rmse) + fmt2(", seam %.3g -> %.3g", l.seam_float, l.seam_stored)};
            r.detail = true;
            rows.push_back(r);
        }
        return rows;
    }

    void report(json_writer& j) const override {
        j.begin_object();
        j.key("format").value(to_string(format_));
        j.key("quality").value(to_string(quality_));
        j.key("zstd_level").value(zstd_);
        j.key("file").value("specular.ktx2");
        j.key("file_bytes").value(bytes_);
        j.key("bits_per_texel").value(bits_per_texel());
        j.key("encode_ms").value(encode_ms_);
        j.key("decoded_as").value(format_ == ktx2_storage::bc6h ? "the library's BC6H decoder (bit-exact to the format's specification)"
                                                                : "astcenc's decompressor to half floats");
        j.key("levels").begin_array();
        for (const auto& l : levels_) {
            j.begin_object();
            j.key("level").value(l.level).key("size").value(l.size).key("rmsle").value(l.rmsle).key("rel_rmse_luminance").value(l.rel_rmse);
            j.key("seam_step_float").value(l.seam_float).key("seam_step_compressed").value(l.seam_stored);
            j.end_object();
        }
        j.end_array();
        j.key("seam_step").value("mean luminance step across the 12 cube edges / mean step from the same border texels to their "
                                 "inward neighbours (about 1 where the level is smooth across its edges)");
        j.key("lookup").begin_object();
        j.key("what").value("the chain lookup (--specular-lookup) from the compressed chain against the float chain, relative RMSE "
                            "of luminance over the check directions");
        j.key("rel_rmse_r_ge_0_25").value(lookup_rough_);
        j.key("per_roughness").begin_array();
        for (const auto& r : lookup_) j.begin_object().key("roughness").value(r.roughness).key("rel_rmse").value(r.rel_rmse).end_object();
        j.end_array();
        j.end_object();
        j.key("preview_rel_rmse").value(preview_rel_);
        j.key("preview").value("the preview grid's sphere pixels (1 sample each) shaded from the compressed chain and irradiance map "
                               "against the float products, relative RMSE of luminance");
        j.key("time_ms").value(ms_);
        j.end_object();
    }

private:
    double bits_per_texel() const { return texels_ ? 8.0 * double(bytes_) / double(texels_) : 0.0; }

    static level_row compare_level(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b, int l) {
        level_row r;
        r.level = l;
        r.size = a.size(l);
        const int n = r.size;
        double mean = 0.0, sq = 0.0;
        std::size_t count = 0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) mean += lum_at(a, l, f, x, y), ++count;
        mean /= double(count);
        ibl::error_accumulator acc(1e-3 * std::max(mean, 1e-30));
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const fvec3 ta = a.texel(f, x, y, l), tb = b.texel(f, x, y, l);
                    for (int c = 0; c < 3; ++c) {
                        const double d = std::log1p(std::max(0.0, double(tb[c]))) - std::log1p(std::max(0.0, double(ta[c])));
                        sq += d * d;
                    }
                    acc.add(lum_at(b, l, f, x, y), lum_at(a, l, f, x, y));
                }
        r.rmsle = std::sqrt(sq / double(3 * count));
        r.rel_rmse = acc.finish().rel_rmse;
        r.seam_float = seam_step(a, l);
        r.seam_stored = seam_step(b, l);
        return r;
    }

    void lookups(const bake_context& ctx, const product_view& bp, const product_view& bc) {
        const std::vector<dvec3> dirs = ibl::lookup_error_directions(ctx.qs.ref_grid, ctx.light);
        double sq_rough = 0.0;
        std::size_t n_rough = 0;
        for (int k = 1; k <= 20; ++k) {
            const double r = 0.05 * k;
            std::vector<dvec3> a(dirs.size()), b(dirs.size());
            ctx.ex(dirs.size(), [&](std::size_t lo, std::size_t hi) {
                for (std::size_t i = lo; i < hi; ++i) a[i] = bp.ld(dirs[i], r), b[i] = bc.ld(dirs[i], r);
            });
            double mean = 0.0;
            for (const auto& v : a) mean += ibl::luminance(v);
            mean /= double(std::max<std::size_t>(a.size(), 1));
            ibl::error_accumulator acc(1e-3 * std::max(mean, 1e-30));
            for (std::size_t i = 0; i < a.size(); ++i) acc.add(ibl::luminance(b[i]), ibl::luminance(a[i]));
            const double e = acc.finish().rel_rmse;
            lookup_.push_back({r, e});
            if (r >= 0.25 - 1e-9) sq_rough += e * e * double(a.size()), n_rough += a.size();
        }
        lookup_rough_ = n_rough ? std::sqrt(sq_rough / double(n_rough)) : 0.0;
    }

    void preview(const bake_context& ctx, const product_view& bp, const product_view& bc) {
        using preview::preview_renderer;
        const preview_renderer pa(bp, ctx.source, ctx.light), pb(bc, ctx.source, ctx.light);
        std::vector<double> ya(std::size_t(preview_renderer::w * preview_renderer::h), -1.0), yb(ya.size(), -1.0);
        ctx.ex(std::size_t(preview_renderer::h), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t py = lo; py < hi; ++py)
                for (int px = 0; px < preview_renderer::w; ++px) {
                    const double fx = px + 0.5, fy = double(py) + 0.5;
                    if (!preview_renderer::on_sphere(fx, fy)) continue;
                    const std::size_t i = py * std::size_t(preview_renderer::w) + std::size_t(px);
                    ya[i] = ibl::luminance(pa.at(fx, fy));
                    yb[i] = ibl::luminance(pb.at(fx, fy));
                }
        });
        double mean = 0.0;
        std::size_t n = 0;
        for (double y : ya)
            if (y >= 0.0) mean += y, ++n;
        mean /= double(std::max<std::size_t>(n, 1));
        ibl::error_accumulator acc(1e-3 * std::max(mean, 1e-30));
        for (std::size_t i = 0; i < ya.size(); ++i)
            if (ya[i] >= 0.0) acc.add(yb[i], ya[i]);
        preview_rel_ = acc.finish().rel_rmse;
    }

    ktx2_storage format_ = ktx2_storage::bc6h;
    block_quality quality_ = block_quality::normal;
    int zstd_ = 0;
    std::size_t bytes_ = 0, texels_ = 0;
    double encode_ms_ = 0.0, ms_ = 0.0, lookup_rough_ = 0.0, preview_rel_ = 0.0;
    std::vector<level_row> levels_;
    std::vector<lookup_row> lookup_;
};

} // namespace

std::unique_ptr<stage> make_compression_stage() { return std::make_unique<compression_stage>(); }

} // namespace ibl_bake
