// raster.hpp — a tiny supersampled RGB canvas for bench_plot: rectangles, thick line segments,
// circles and convex polygons, bitmap text (font5x9.hpp) at any scale and rotated by 90 degrees.
// Geometry is in output-pixel coordinates (x right, y down; pixel (i, j) covers [i, i+1) x [j, j+1));
// every shape is evaluated at ss x ss sample centres per pixel and resolve() box-filters them
// down, which anti-aliases edges while axis-aligned shapes on pixel boundaries stay crisp.
#pragma once

#include "font5x9.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

namespace bench_plot {

struct rgb {
    std::uint8_t r = 0, g = 0, b = 0;
};

constexpr rgb hex_rgb(std::uint32_t h) {
    return {std::uint8_t((h >> 16) & 0xFF), std::uint8_t((h >> 8) & 0xFF), std::uint8_t(h & 0xFF)};
}

struct pt {
    double x = 0.0, y = 0.0;
};

struct rect {
    double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
    [[nodiscard]] double w() const { return x1 - x0; }
    [[nodiscard]] double h() const { return y1 - y0; }
    [[nodiscard]] bool contains(pt p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
    [[nodiscard]] bool intersects(const rect& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

class canvas {
public:
    canvas(int width, int height, int supersample, rgb background)
        : w_(width), h_(height), ss_(supersample), sw_(width * supersample), sh_(height * supersample),
          px_(std::size_t(sw_) * std::size_t(sh_), background), clip_{0.0, 0.0, double(width), double(height)} {}

    [[nodiscard]] int width() const { return w_; }
    [[nodiscard]] int height() const { return h_; }

    void set_clip(const rect& r) { clip_ = r; }
    void reset_clip() { clip_ = {0.0, 0.0, double(w_), double(h_)}; }

    /// Calls inside(x, y) at every sample centre of bounding box b (output-pixel coordinates) that
    /// lies in the clip rectangle, painting c where it returns true.
    template <class Inside> void fill(rect b, rgb c, Inside&& inside) {
        b.x0 = std::max(b.x0, clip_.x0);
        b.y0 = std::max(b.y0, clip_.y0);
        b.x1 = std::min(b.x1, clip_.x1);
        b.y1 = std::min(b.y1, clip_.y1);
        if (!(b.x0 < b.x1 && b.y0 < b.y1)) return;
        const double s = double(ss_);
        // sample (i, j) has its centre at ((i + 0.5) / ss, (j + 0.5) / ss)
        const int i0 = std::max(0, int(std::floor(b.x0 * s - 0.5))), i1 = std::min(sw_ - 1, int(std::ceil(b.x1 * s - 0.5)));
        const int j0 = std::max(0, int(std::floor(b.y0 * s - 0.5))), j1 = std::min(sh_ - 1, int(std::ceil(b.y1 * s - 0.5)));
        for (int j = j0; j <= j1; ++j) {
            const double y = (j + 0.5) / s;
            if (y < b.y0 || y >= b.y1) continue;
            for (int i = i0; i <= i1; ++i) {
                const double x = (i + 0.5) / s;
                if (x < b.x0 || x >= b.x1) continue;
                if (inside(x, y)) px_[std::size_t(j) * std::size_t(sw_) + std::size_t(i)] = c;
            }
        }
    }

    void fill_rect(const rect& r, rgb c) {
        fill(r, c, [](double, double) { return true; });
    }

    /// Outline of r with a line of the given width drawn inside r.
    void stroke_rect(const rect& r, double width, rgb c) {
        fill_rect({r.x0, r.y0, r.x1, r.y0 + width}, c);
        fill_rect({r.x0, r.y1 - width, r.x1, r.y1}, c);
        fill_rect({r.x0, r.y0, r.x0 + width, r.y1}, c);
        fill_rect({r.x1 - width, r.y0, r.x1, r.y1}, c);
    }

    /// Segment a-b of the given width with round caps (a capsule).
    void line(pt a, pt b, double width, rgb c) {
        const double r = 0.5 * width;
        const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
        const rect box{std::min(a.x, b.x) - r, std::min(a.y, b.y) - r, std::max(a.x, b.x) + r, std::max(a.y, b.y) + r};
        fill(box, c, [&](double x, double y) {
            double t = len2 > 0.0 ? ((x - a.x) * dx + (y - a.y) * dy) / len2 : 0.0;
            t = std::clamp(t, 0.0, 1.0);
            const double ex = x - (a.x + t * dx), ey = y - (a.y + t * dy);
            return ex * ex + ey * ey <= r * r;
        });
    }

    /// Polyline, optionally dashed (dash and gap lengths in pixels, pattern continued across vertices).
    void polyline(const std::vector<pt>& p, double width, rgb c, double dash = 0.0, double gap = 0.0) {
        if (p.size() == 1) return;
        double phase = 0.0; // distance along the current dash period
        for (std::size_t k = 0; k + 1 < p.size(); ++k) {
            const pt a = p[k], b = p[k + 1];
            const double len = std::hypot(b.x - a.x, b.y - a.y);
            if (dash <= 0.0 || len == 0.0) {
                line(a, b, width, c);
                continue;
            }
            double s = 0.0;
            while (s < len) {
                const double period = dash + gap;
                const bool on = phase < dash;
                const double step = std::min(len - s, on ? dash - phase : period - phase);
                if (on) {
                    const double t0 = s / len, t1 = (s + step) / len;
                    line({a.x + t0 * (b.x - a.x), a.y + t0 * (b.y - a.y)}, {a.x + t1 * (b.x - a.x), a.y + t1 * (b.y - a.y)}, width, c);
                }
                s += step;
                phase += step;
                if (phase >= period) phase -= period;
            }
        }
    }

    void disc(pt centre, double radius, rgb c) {
        const rect box{centre.x - radius, centre.y - radius, centre.x + radius, centre.y + radius};
        fill(box, c, [&](double x, double y) {
            const double dx = x - centre.x, dy = y - centre.y;
            return dx * dx + dy * dy <= radius * radius;
        });
    }

    /// Convex polygon (either winding).
    void convex(const std::vector<pt>& v, rgb c) {
        if (v.size() < 3) return;
        rect box{v[0].x, v[0].y, v[0].x, v[0].y};
        for (const pt& p : v) {
            box.x0 = std::min(box.x0, p.x);
            box.y0 = std::min(box.y0, p.y);
            box.x1 = std::max(box.x1, p.x);
            box.y1 = std::max(box.y1, p.y);
        }
        fill(box, c, [&](double x, double y) {
            bool pos = false, neg = false;
            for (std::size_t k = 0; k < v.size(); ++k) {
                const pt a = v[k], b = v[(k + 1) % v.size()];
                const double cr = (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
                pos = pos || cr > 0.0;
                neg = neg || cr < 0.0;
            }
            return !(pos && neg);
        });
    }

    /// Text with its top-left corner at (x, y); each font pixel is a scale x scale square. With
    /// rotated, the text runs bottom-to-top (rotated 90 degrees counter-clockwise) and (x, y) is
    /// the bottom-left corner of the rotated box. Returns the advance (text length) in pixels.
    double text(double x, double y, std::string_view s, double scale, rgb c, bool rotated = false) {
        double pen = 0.0;
        for (const char ch : s) {
            const auto& g = glyph(ch);
            for (int row = 0; row < font_h; ++row)
                for (int col = 0; col < font_w; ++col) {
                    if (!(g[std::size_t(row)] & (1u << (font_w - 1 - col)))) continue;
                    const double u = pen + col * scale, v = row * scale; // along / across the text
                    if (!rotated)
                        fill_rect({x + u, y + v, x + u + scale, y + v + scale}, c);
                    else
                        fill_rect({x + v, y - u - scale, x + v + scale, y - u}, c);
                }
            pen += font_advance * scale;
        }
        return pen;
    }

    /// Box-filtered output, 8-bit RGB rows top first.
    [[nodiscard]] std::vector<std::uint8_t> resolve() const {
        std::vector<std::uint8_t> out(std::size_t(w_) * std::size_t(h_) * 3);
        const unsigned n = unsigned(ss_ * ss_);
        for (int y = 0; y < h_; ++y)
            for (int x = 0; x < w_; ++x) {
                unsigned r = 0, g = 0, b = 0;
                for (int j = 0; j < ss_; ++j)
                    for (int i = 0; i < ss_; ++i) {
                        const rgb& p = px_[std::size_t(y * ss_ + j) * std::size_t(sw_) + std::size_t(x * ss_ + i)];
                        r += p.r;
                        g += p.g;
                        b += p.b;
                    }
                std::uint8_t* o = &out[(std::size_t(y) * std::size_t(w_) + std::size_t(x)) * 3];
                o[0] = std::uint8_t((r + n / 2) / n);
                o[1] = std::uint8_t((g + n / 2) / n);
                o[2] = std::uint8_t((b + n / 2) / n);
            }
        return out;
    }

private:
    int w_, h_, ss_, sw_, sh_;
    std::vector<rgb> px_;
    rect clip_;
};

/// Width of s in pixels at the given scale (no trailing gap).
inline double text_width(std::string_view s, double scale) {
    return s.empty() ? 0.0 : (double(s.size()) * font_advance - (font_advance - font_w)) * scale;
}

} // namespace bench_plot
